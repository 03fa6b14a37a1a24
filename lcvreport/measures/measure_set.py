"""Every measure of one vehicle at one speed: :func:`measure_set` computes the registry's
measures (:mod:`lcvreport.measures.registry`) and :class:`MeasureSet` holds them, by key,
with the reason for every one that is undefined.

The families are computed by their own modules (stability, amplification, yaw damping,
offtracking, the low-speed turn, the trim of :mod:`lcvreport.analysis.steady`); the
definitions are in ``docs/measures.md``.  Lateral acceleration of unit i's CG:
``a_i = v_i' + u r_i``, SI throughout.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.units import kph_to_mps
>>> m = measure_set(load_preset("aucnat"), kph_to_mps(88.0), load_units=["trailer2", "trailer3"])
>>> sorted(m.to_dict())[:5]
['ay_gain_per_unit', 'critical_speed_kph', 'friction_demand_drive', 'frontal_swing_m', 'hsso_m']
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.batch import VariantBatch
from ..analysis.frequency import RA_FREQUENCY_HZ
from ..analysis.steady import Trim
from ..model.linear import linear_model
from ..model.vehicle import Vehicle, check_vehicle
from ..model.yaw_plane.loads import load_vector, one_percent_rule
from ..units import mps_to_kph
from ..util.threads import one_blas_thread
from .registry import CONDITIONS, FAMILIES, MEASURES, ON_REQUEST, MeasureCase


@dataclass(frozen=True)
class MeasureSet:
    """Every measure of :data:`lcvreport.measures.registry.MEASURES` for one vehicle at one
    speed: ``values`` maps the registry's keys to numbers (None: undefined, the reason in
    ``undefined``), and each key reads as an attribute (``m.hsso_m``); ``trim`` is the full
    trimmed state when a residual source was given.  ``to_dict()`` gives the JSON of
    ``lcv measures``, in the registry's order, with ``reasons`` for every null; ``rows()`` the
    text and report table."""

    vehicle: Vehicle
    speed_mps: float
    tire_scale: float = 1.0
    f_hz: float = RA_FREQUENCY_HZ
    load_units: tuple[str, ...] = ()
    sources: object = None
    values: dict = field(default_factory=dict)
    #: measure key -> why it is null (e.g. no steered axle: no steer input to respond to)
    undefined: dict = field(default_factory=dict)
    trim: Trim | None = None
    #: the conditions given other than the speed and f_hz (the rest at their defaults)
    conditions: dict = field(default_factory=dict)
    #: the model of the model-axis families (docs/model.md#the-model-object): the yaw plane by default
    model: str = "yaw_plane"

    def __getattr__(self, name: str):
        if not name.startswith("_") and name in MEASURES:
            return self.value(name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def value(self, key: str):
        """The value of the registry key ``key`` (None where undefined)."""
        if key == "speed_mps":
            return self.speed_mps
        value = self.values.get(key)
        return list(value) if isinstance(value, (list, tuple)) else value

    def reason(self, key: str) -> str | None:
        """Why the measure ``key`` is null (None when it has a value)."""
        if self.value(key) is not None:
            return None
        if key.startswith("trim."):
            return self.undefined.get("trim", "no residual source was given (--load, --residual, "
                                              "--misalignment, --crossfall-percent, --tires)")
        return self.undefined.get(key, "undefined")

    def to_dict(self) -> dict:
        """The JSON of ``lcv measures`` (``docs/measures.md``): the registry's keys in its order
        (a dotted key nested: ``trim`` holds ``delta_rad`` and ``offtracking_m``, present with a
        residual source), and ``reasons``: {key: why it is null} for every null."""
        doc, reasons = {}, {}
        for key in MEASURES:
            if key.startswith("trim."):
                if "trim.delta_rad" not in self.values and "trim" not in self.undefined:
                    continue                         # no residual source: no trim
                doc["trim"] = None if self.trim is None else {"delta_rad": self.trim.delta_rad,
                                                              "offtracking_m": self.trim.offtracking_m}
                if self.trim is None:
                    reasons["trim"] = self.reason(key)
                continue
            doc[key] = self.value(key)
            if doc[key] is None:
                reasons[key] = self.reason(key)
        if self.model != "yaw_plane":                 # the default's JSON as it always was
            doc = {"model": self.model, **doc}
        doc["reasons"] = reasons
        return doc

    def rows(self) -> list[dict]:
        """The measures as table rows: name, value, unit, definition (or why it is null), and
        the key of the same number in :meth:`to_dict` (``ay_gain_per_unit[0]`` for list items)."""
        f = f"{self.f_hz:g} Hz"
        rows = []
        for key, m in MEASURES.items():
            value = self.value(key)
            if key == "speed_mps":
                rows.append({"measure": m.label, "value": value, "unit": m.unit,
                             "note": f"{mps_to_kph(self.speed_mps):.1f} km/h", "json_key": key})
            elif m.shape in ("per_unit", "per_group"):
                if value is None:
                    rows.append({"measure": m.label + "s", "value": "none", "unit": m.unit,
                                 "note": self.reason(key), "json_key": key})
                names = self.vehicle.unit_names if m.shape == "per_unit" else [
                    f"group {g + 1}" for g in range(len(value or ()))]
                for k, (name, g) in enumerate(zip(names, value or ())):
                    note = f"|G_{k + 1}(j2π·{f})|" if key == "ay_gain_per_unit" else m.definition
                    rows.append({"measure": f"{m.label}, {name}", "value": g, "unit": m.unit,
                                 "note": note, "json_key": f"{key}[{k}]"})
            elif key.startswith("trim."):
                if self.trim is not None:
                    what = "; ".join(x for x in (f"1 % rule on {', '.join(self.load_units)}" if self.load_units
                                                 else "", self.sources.describe() if self.sources else "") if x)
                    rows.append({"measure": m.label, "value": value, "unit": m.unit,
                                 "note": what if key == "trim.delta_rad" else m.definition, "json_key": key})
                elif "trim" in self.undefined and key == "trim.delta_rad":
                    rows.append({"measure": "trim", "value": "none", "unit": "", "note": self.undefined["trim"],
                                 "json_key": "trim"})
            else:
                note = m.definition if value is not None else self.reason(key)
                if key in ("ra_frequency", "ra_single_sine", "ra_yaw_rate_single_sine"):
                    note = note.replace("0.4 Hz", f)
                given = [f"{k} = {self.conditions[k]:g}" for k in m.conditions if k in self.conditions]
                if given and value is not None:
                    note = f"{note}; here {', '.join(given)}"
                rows.append({"measure": m.label.replace("0.4 Hz", f), "value": "none" if value is None else value,
                             "unit": m.unit, "note": note, "json_key": key})
        return rows


def _load_units(vehicle: Vehicle, load_units) -> tuple:
    """``load_units`` as a tuple of names; a string (one name, not a list of them) refused in one
    line naming the units there are (:func:`~lcvreport.model.yaw_plane.loads.check_unit_names`)."""
    if isinstance(load_units, str):
        from ..model.yaw_plane.loads import check_unit_names
        check_unit_names(vehicle, load_units)
    return tuple(load_units) if load_units else ()


def residual_force(vehicle: Vehicle, load_units=None, sources=None, tire_scale: float = 1.0) -> np.ndarray | None:
    """The generalized force [SI] of the 1 % rule on ``load_units`` and of ``sources`` (None if
    neither is given): what the trim is computed against."""
    units = _load_units(vehicle, load_units)
    if not units and not sources:
        return None
    F = np.zeros(linear_model(vehicle).n_states)
    if units:
        F = F + load_vector(vehicle, one_percent_rule(vehicle, list(units)))
    if sources:
        F = F + sources.vector(vehicle, tire_scale)
    return F


def model_case(vehicle, model: str | None) -> tuple[Vehicle, str, dict]:
    """(vehicle, model name, model options) of ``vehicle`` -- a :class:`Vehicle` (the model
    ``model``, default the yaw plane) or a model object
    (:class:`~lcvreport.model.base.VehicleModel`: its vehicle, name and options)."""
    from ..model.base import MODELS, check_model
    if hasattr(vehicle, "derivatives") and hasattr(vehicle, "vehicle"):
        name = getattr(vehicle, "name", "yaw_plane")
        if model is not None and check_model(model) != name:
            raise ValueError(f"model must be the model object's own ({name!r}) or None, got {model!r}")
        options = {"tire": vehicle.tire} if name == "nonlinear" else {}
        return vehicle.vehicle, name, options
    return vehicle, ("yaw_plane" if model is None else check_model(model, MODELS)), {}


def _family_values(family, case: MeasureCase, model: str, asked: bool) -> tuple[dict, dict]:
    """(values, reasons) of ``family`` for ``case`` on the model axis ``model``: computed on the
    model :meth:`~lcvreport.measures.registry.Family.model_for` gives, or null with its reason;
    a family computed on request only when ``asked``."""
    import dataclasses
    if family.on_request and not asked:
        return dict.fromkeys(family.keys), dict.fromkeys(family.keys, ON_REQUEST)
    on, why = family.model_for(model)
    if on is None:
        return dict.fromkeys(family.keys), ({"trim": why} if family.needs == "sources" else dict.fromkeys(family.keys, why))
    if not family.applies(case):
        return {}, {}
    sub = case if on == case.model else dataclasses.replace(case, model=on)
    try:
        values, why = family.compute(sub)
    except KeyError as exc:
        from ..model.base import MODELS
        text = str(exc.args[0]) if exc.args else ""
        if not (callable(MODELS.get(on)) and text.startswith("no signal")):
            raise
        # a model registered from outside that gives no signal this family reads (docs/model.md#the-model-object)
        why = f"undefined: the {on} model gives {text.split(';')[0]} (docs/model.md: what the families read)"
        return dict.fromkeys(family.keys), dict.fromkeys(family.keys, why)
    if sub is not case:
        case.shared.update(sub.shared)
    return values, why


@one_blas_thread
def measure_set(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0, load_units=None,
                f_hz: float = RA_FREQUENCY_HZ, sources=None, conditions: dict | None = None,
                model: str | None = None) -> MeasureSet:
    """Every measure of the registry (``docs/measures.md``) of ``vehicle`` at ``speed_mps`` [m/s]:
    each family of :data:`lcvreport.measures.registry.FAMILIES` in turn.

    Parameters
    ----------
    vehicle : Vehicle or VehicleModel
        A vehicle (its model ``model``) or a model object (:func:`lcvreport.model.base.build_model`).
    speed_mps : float
    tire_scale : float
    load_units : list of str, optional
        Units carrying the 1 % rule (P along +y, T about +z) for the trim.
    f_hz : float
        Frequency of the RA measures and gains [Hz].
    sources : lcvreport.model.yaw_plane.loads.ResidualSources, optional
        Further residual sources for the trim (per-axle P and T, misalignment, crossfall);
        with ``load_units`` the 1 % rule adds to them.
    conditions : dict, optional
        The manoeuvres' conditions by :data:`~lcvreport.measures.registry.CONDITIONS` key (the
        lane change's ``lane_change_ay_g`` and ``lane_change_frequency_hz``, the steady turn's
        ``steady_turn_radius_m``, the low-speed turn's ``turn_radius_m`` and ``turn_angle_deg``);
        each one not given at its default.  (The speed is ``speed_mps``, the RA frequency
        ``f_hz``, the crossfall a residual source.)
    model : str, optional
        The model of the model-axis families (a key of :data:`lcvreport.model.base.MODELS`;
        default the yaw plane): their keys are model-neutral, each family computed on what it
        requires of the model (:func:`lcvreport.measures.registry.model_of_family`) --
        ``model="yaw_roll"`` gives ``hsto_m`` equal to the default's ``hsto_m_roll``;
        ``"nonlinear"`` the response families of the nonlinear model, its linearization's
        eigenvalues, and its friction demand (docs/model.md#the-model-object).  The families of a
        fixed model (the low-speed turn, the roll measures) are the same whatever ``model``.

    Returns
    -------
    MeasureSet
        Every key's value (None where undefined, with the reason in :meth:`MeasureSet.reason`);
        ``to_dict()`` is ``lcv measures --json``.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> m = measure_set(load_preset("tractor_semitrailer"), 24.4444)
    >>> sorted(m.to_dict())[:4]
    ['ay_gain_per_unit', 'critical_speed_kph', 'friction_demand_drive', 'frontal_swing_m']
    >>> round(m.hsso_m, 4) == round(m.values["hsso_m"], 4)
    True
    """
    vehicle, model, options = model_case(vehicle, model)
    check_vehicle(vehicle)
    units = _load_units(vehicle, load_units)
    conditions = check_conditions(conditions)
    case = MeasureCase(vehicle, float(speed_mps), float(tire_scale), float(f_hz),
                       residual_force(vehicle, units, sources, tire_scale), conditions=conditions, model=model,
                       options=options)
    values, undefined = {}, {}
    # each family keeps only its numbers: a manoeuvre's response (up to a megabyte of samples) is
    # freed before the next one is computed (a smaller heap, which malloc does not hand back)
    for family in FAMILIES.values():
        v, why = _family_values(family, case, model, asked=family.model == model)
        values.update(v)
        undefined.update(why)
    return MeasureSet(vehicle=vehicle, speed_mps=float(speed_mps), tire_scale=float(tire_scale), f_hz=float(f_hz),
                      load_units=units, sources=sources, values=values, undefined=undefined,
                      trim=case.shared.get("trim"), conditions=conditions, model=model)


@one_blas_thread
def measure_values(vehicle: Vehicle, speed_mps: float, keys, tire_scale: float = 1.0, load_units=None,
                   f_hz: float = RA_FREQUENCY_HZ, sources=None, conditions: dict | None = None,
                   reasons: dict | None = None, model: str | None = None) -> dict:
    """The values of the registry keys ``keys`` only, as :func:`measure_set` gives them (None
    where undefined), computing just their families (and those they take a result from: the yaw
    damping compares with the least damping ratio) -- what a study computes case by case and
    an assessment per set of conditions.  ``conditions`` and ``model`` as :func:`measure_set`'s
    (a family computed on request is computed when one of its keys is asked for); ``reasons``, a
    dict, receives why each null is null.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> v = load_preset("tractor_semitrailer")
    >>> measure_values(v, 24.4, ["hsso_m"])["hsso_m"] == measure_set(v, 24.4).hsso_m
    True
    """
    vehicle, model, options = model_case(vehicle, model)
    check_vehicle(vehicle)
    units = _load_units(vehicle, load_units)
    case = MeasureCase(vehicle, float(speed_mps), float(tire_scale), float(f_hz),
                       residual_force(vehicle, units, sources, tire_scale), conditions=check_conditions(conditions),
                       model=model, options=options)
    needed = {MEASURES[k].family for k in keys if MEASURES[k].family}
    if "yaw_damping" in needed:
        needed.add("least_damping")
    values, why = {}, {}
    for name, family in FAMILIES.items():
        if name in needed:
            v, w = _family_values(family, case, model, asked=True)
            values.update(v)
            why.update(w)
    if reasons is not None:
        probe = MeasureSet(vehicle=vehicle, speed_mps=float(speed_mps), values=values, undefined=why, model=model)
        reasons.update({k: probe.reason(k) for k in keys if values.get(k) is None})
    return {k: values.get(k) for k in keys}


def check_conditions(conditions: dict | None) -> dict:
    """``conditions`` checked against the registry (known keys other than the speed, the RA
    frequency and the crossfall, which have their own arguments) and the ranges table.

    Raises
    ------
    KeyError, lcvreport.ranges.RangeError
    """
    out = {}
    for key, value in (conditions or {}).items():
        if key not in CONDITIONS or key in ("speed_kph", "ra_frequency_hz", "crossfall_percent"):
            valid = [k for k in CONDITIONS if k not in ("speed_kph", "ra_frequency_hz", "crossfall_percent")]
            raise KeyError(f"unknown condition {key!r}; valid: {', '.join(valid)}")
        out[key] = CONDITIONS[key].check(value)
    return out


@one_blas_thread
def batch_measures(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0, f_hz: float | None = None,
                   F=None) -> dict:
    """The batched measures of every variant of ``batch`` as columns (a dict of arrays of length
    B, ready for ``pandas.DataFrame``): a ``case_id``, one column per varied parameter, the
    speed, and every key of :data:`lcvreport.measures.registry.BATCHED` (the trim's,
    ``trim.delta_rad`` and ``trim.offtracking_m``, with ``F``: (B, 2N) generalized forces [SI]);
    NaN where a measure is undefined (no oscillatory mode, stable to 200 km/h).

    Examples
    --------
    >>> import numpy as np
    >>> from lcvreport import load_preset
    >>> v = load_preset("aucnat")
    >>> b = VariantBatch(v, {"trailer3.mass_kg": v.units[5].mass_kg * np.array([0.8, 1.0])})
    >>> t = batch_measures(b, 24.4444)
    >>> bool(abs(t["hsso_m"][1] - measure_set(v, 24.4444).hsso_m) < 1e-12)
    True
    """
    f_hz = RA_FREQUENCY_HZ if f_hz is None else f_hz
    table = {"case_id": np.arange(batch.size)}
    table.update({name: np.asarray(arr, dtype=float) for name, arr in batch.values.items()})
    table["speed_mps"] = np.full(batch.size, float(speed_mps))
    case = MeasureCase(batch.vehicle, float(speed_mps), float(tire_scale), float(f_hz), F)
    for family in FAMILIES.values():
        if family.batched and family.applies(case):
            for key, arr in family.compute_batched(batch, case).items():
                table[key] = np.asarray(arr, dtype=float)
    return table
