"""The factors of a study file: what each may be, its values or distribution, a payload's
placement, and the checks of each (docs/studies.md).  :mod:`lcvreport.study.spec` reads a study
file with them."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..model.vehicle import Vehicle
from ..ranges import RANGES

#: a unit's payload [kg] (docs/studies.md#payloads): placed at x_m, height_m, length_m of the factor
PAYLOAD = "payload_kg"
UNIT_SCALES = {"mass_scale": "mass_kg", "yaw_inertia_scale": "yaw_inertia_kg_m2",
               # roll (docs/roll.md): on a vehicle with the roll keys
               "cg_height_scale": "cg_height_m", "roll_inertia_scale": "roll_inertia_kg_m2",
               "coupling_roll_stiffness_scale": "rear_coupling_roll_stiffness_Nm_per_rad"}
AXLE_SCALES = {"cornering_stiffness_scale": "cornering_stiffness_N_per_rad",
               "aligning_stiffness_scale": "aligning_stiffness_Nm_per_rad",
               "longitudinal_stiffness_scale": "longitudinal_stiffness_N",
               "roll_stiffness_scale": "roll_stiffness_Nm_per_rad", "roll_damping_scale": "roll_damping_Nms_per_rad"}
#: the scaled parameters only the roll measures read (the yaw-plane batch leaves them out)
ROLL_PARAMETERS = ("cg_height_m", "roll_inertia_kg_m2", "rear_coupling_roll_stiffness_Nm_per_rad",
                   "roll_stiffness_Nm_per_rad", "roll_damping_Nms_per_rad")
PLAIN_FACTORS = ("speed_kph", "speed_mps", "tire_scale", "crossfall_percent", "load_units")
#: residual-source factors: name prefix and suffix -> (ranges key, what)
RESIDUALS = {("P_", "_N"): "residual_force", ("T_", "_Nm"): "residual_moment", ("eps_", "_rad"): "misalignment"}


class StudyError(ValueError):
    """A study file that cannot be run; the message names the key, the value and what is valid."""


@dataclass(frozen=True)
class Factor:
    """One factor: ``values`` (a tuple) or a ``distribution`` with its parameters."""

    name: str
    values: tuple = ()
    distribution: str = ""
    low: float = math.nan
    high: float = math.nan
    mean: float = math.nan
    sd: float = math.nan
    #: a payload's placement (``<unit>.payload_kg``): x from the unit's CG [m], height above
    #: ground [m] (NaN: the unit's CG height), length of a uniform block [m] (0: a point mass)
    x_m: float = 0.0
    height_m: float = math.nan
    length_m: float = 0.0

    def describe(self) -> str:
        if self.values and self.name == "load_units":
            return f"{self.name}: values {', '.join(load_label(u) for u in self.values)}"
        if self.values:
            return f"{self.name}: values {list(self.values)}"
        if self.distribution == "uniform":
            return f"{self.name}: uniform on [{self.low:g}, {self.high:g}]"
        return f"{self.name}: normal, mean {self.mean:g}, sd {self.sd:g}"



def factor_scales(vehicle: Vehicle, factor: str, pname: str) -> bool:
    """True when the factor ``factor`` scales the parameter ``pname`` (``owner.key``)."""
    if "." not in factor:
        return False
    owner, key = factor.split(".", 1)
    powner, pkey = pname.split(".", 1)
    if UNIT_SCALES.get(key) == pkey:
        return owner == powner
    if AXLE_SCALES.get(key) == pkey:
        unit = next((u for u in vehicle.units if u.name == owner), None)
        return owner == powner or (unit is not None and any(a.name == powner for a in unit.axles))
    return False


def factor_values(f: Factor) -> np.ndarray:
    """A factor's values as an array to index: numbers, or the load cases' labels."""
    if f.name == "load_units":
        return np.array([load_label(u) for u in f.values], dtype=object)
    return np.asarray(f.values, dtype=float)


def factor_number(where: str, value, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or \
            (positive and value <= 0):
        raise StudyError(f"{where} must be a finite number{' > 0' if positive else ''}, got {value!r}")
    return float(value)


def residual_key(name: str) -> str | None:
    """The ranges key of a residual-source factor (``P_<axle>_N`` ... ``crossfall_percent``), else None."""
    if name == "crossfall_percent":
        return "crossfall"
    for (pre, post), key in RESIDUALS.items():
        if name.startswith(pre) and name.endswith(post) and len(name) > len(pre) + len(post):
            return key
    return None


def residual_axle(name: str) -> str:
    """The axle of ``P_<axle>_N``, ``T_<axle>_Nm``, ``eps_<axle>_rad``."""
    for pre, post in RESIDUALS:
        if name.startswith(pre) and name.endswith(post):
            return name[len(pre):-len(post)]
    raise KeyError(name)


def load_label(units) -> str:
    """The table's text of a load case: ``trailer2+trailer3``, ``none``."""
    return "+".join(units) or "none"


def _load_units_factor(vehicle: Vehicle, where: str, spec) -> Factor:
    vals = spec.get("values") if isinstance(spec, dict) else None
    if set(spec if isinstance(spec, dict) else {}) - {"values"} or not isinstance(vals, list) or not vals:
        raise StudyError(f"{where} must be {{ values = [[\"unit\", ...], ...] }}: lists of the units carrying the 1 % "
                         f"rule ([] for none), got {spec!r}")
    out = []
    for k, units in enumerate(vals):
        if not isinstance(units, list) or any(u not in vehicle.unit_names for u in units) or \
                len(set(units)) != len(units):
            raise StudyError(f"{where}.values[{k}] must be a list of distinct units of {vehicle.name} "
                             f"({', '.join(vehicle.unit_names)}), got {units!r}")
        out.append(tuple(units))
    return Factor("load_units", tuple(out))


def _payload_factor(vehicle: Vehicle, name: str, spec) -> Factor:
    """``<unit>.payload_kg``: values or a distribution of the payload [kg] (>= 0, in the ranges
    table's ``payload``), placed at ``x_m`` (from the unit's CG, default 0), ``height_m`` (above
    ground, default the unit's CG height) and ``length_m`` (a uniform block; default 0, a point)."""
    from ..model.statics import has_static_loads
    where = f"factors.{name}"
    owner = name.split(".", 1)[0]
    if owner not in vehicle.unit_names:
        raise StudyError(f"{where}: {vehicle.name} has no unit {owner!r}; units: {', '.join(vehicle.unit_names)}")
    if not isinstance(spec, dict):
        raise StudyError(f"{where} must be a table with values = [...] or distribution = ..., got {spec!r}")
    placement = {k: spec[k] for k in ("x_m", "height_m", "length_m") if k in spec}
    rest = {k: v for k, v in spec.items() if k not in placement}
    unit = vehicle.units[vehicle.unit_names.index(owner)]
    place = {}
    for key, value in placement.items():
        from ..ranges import VEHICLE
        x = factor_number(f"{where}.{key}", value)
        if key == "x_m":
            VEHICLE["position_m"].check(x, f"{where}.x_m")
        elif key == "height_m":
            VEHICLE["cg_height_m"].check(x, f"{where}.height_m")
        elif not 0.0 <= x <= VEHICLE["position_m"].high:
            raise StudyError(f"{where}.length_m must be in [0, {VEHICLE['position_m'].high:g}] m, got {x!r}")
        place[key] = x
    if "height_m" in place and unit.cg_height_m is None:
        raise StudyError(f"{where}.height_m: {owner} has no cg_height_m (a roll key) for a payload height to move")
    if not has_static_loads(vehicle):
        missing = next(a.name for a in vehicle.axles if a.static_load_N is None)
        raise StudyError(f"{where}: a payload moves the static axle loads, and axle {missing} has no static_load_N")
    f = _factor_values(where, rest, lambda k, v: RANGES["payload"].check(factor_number(f"{where}.{k}", v), f"{where}.{k}"))
    return replace(f, name=name, **place)


def _factor_values(where: str, spec: dict, number) -> Factor:
    """The values or the distribution of a factor (name left empty), each number through ``number``."""
    unknown = set(spec) - {"values", "distribution", "low", "high", "mean", "sd"}
    if unknown:
        raise StudyError(f"{where}: unknown key {sorted(unknown)[0]!r}; valid: values, distribution, low, high, "
                         "mean, sd")
    if "values" in spec:
        vals = spec["values"]
        if not isinstance(vals, list) or not vals:
            raise StudyError(f"{where}.values must be a non-empty list of numbers, got {vals!r}")
        return Factor("", tuple(number(f"values[{k}]", x) for k, x in enumerate(vals)))
    dist = spec.get("distribution")
    if dist == "uniform":
        lo, hi = number("low", spec.get("low")), number("high", spec.get("high"))
        if not lo < hi:
            raise StudyError(f"{where}: low must be below high, got low {lo:g}, high {hi:g}")
        return Factor("", distribution="uniform", low=lo, high=hi)
    if dist == "normal":
        mean, sd = number("mean", spec.get("mean")), factor_number(f"{where}.sd", spec.get("sd"), True)
        return Factor("", distribution="normal", mean=mean, sd=sd)
    raise StudyError(f"{where}.distribution must be uniform or normal (or give values = [...]), got {dist!r}")


def parse_factor(vehicle: Vehicle, name: str, spec) -> Factor:
    where = f"factors.{name}"
    if name == "load_units":
        return _load_units_factor(vehicle, where, spec)
    if name.endswith("." + PAYLOAD):
        return _payload_factor(vehicle, name, spec)
    signed = residual_key(name)
    if signed and name != "crossfall_percent" and residual_axle(name) not in {a.name for a in vehicle.axles}:
        raise StudyError(f"{where}: {vehicle.name} has no axle {residual_axle(name)!r}; axles: "
                         f"{', '.join(a.name for a in vehicle.axles)}")
    if name not in PLAIN_FACTORS and not signed:
        owner, _, key = name.partition(".")
        units = {u.name for u in vehicle.units}
        axles = {a.name for a in vehicle.axles}
        if key in UNIT_SCALES and owner not in units or key in AXLE_SCALES and owner not in units | axles or \
                key not in UNIT_SCALES and key not in AXLE_SCALES:
            raise StudyError(f"{where}: unknown factor; valid: {', '.join(PLAIN_FACTORS)}, P_<axle>_N, "
                             f"T_<axle>_Nm, eps_<axle>_rad, <unit>.{{{','.join([*UNIT_SCALES, PAYLOAD])}}} (units: "
                             f"{', '.join(sorted(units))}), <unit or axle>.{{{','.join(AXLE_SCALES)}}} (axles: "
                             f"{', '.join(sorted(axles))})")
    if name not in PLAIN_FACTORS and not signed:
        owner, _, key = name.partition(".")
        pkey = UNIT_SCALES.get(key) or AXLE_SCALES[key]
        targets = [u for u in vehicle.units if u.name == owner] if key in UNIT_SCALES else \
            [a for u in vehicle.units for a in (u.axles if u.name == owner else [a for a in u.axles
                                                                                 if a.name == owner])]
        if pkey in ROLL_PARAMETERS:
            missing = [t.name for t in targets if getattr(t, pkey) is None]
            if missing:
                raise StudyError(f"{where}: {', '.join(missing)} has no {pkey} (a roll key, docs/roll.md) to scale")
    if not isinstance(spec, dict):
        raise StudyError(f"{where} must be a table with values = [...] or distribution = ..., got {spec!r}")
    positive = not signed                      # scales and speeds > 0; residual sources any sign, in range

    def number(key, value):
        x = factor_number(f"{where}.{key}", value, positive)
        if signed:
            RANGES[signed].check(x, f"{where}.{key}")
        return x
    return replace(_factor_values(where, spec, number), name=name)
