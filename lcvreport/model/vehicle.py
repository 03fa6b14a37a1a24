"""A vehicle: a chain of rigid units coupled by pin joints, in SI (docs/vehicle_files.md).

Units are numbered from the front (1 = the tractor or truck).  Joint k couples unit
k to unit k+1; the thesis letters its joints A, B, C ... (Table 3-2) and so does this
package (:func:`joint_letter`), in state names such as ``thetaA``.  Positions are
signed x from the unit's CG, forward positive: a kingpin ahead of a trailer's CG has
``front_coupling_m > 0``, a tractor's fifth wheel behind its CG ``rear_coupling_m < 0``.
A converter dolly, a B-train lead trailer (a fifth wheel over its axles) and a full
trailer's drawbar are all just units with a front and a rear coupling.

What is checked, and why
------------------------
* Types and finiteness of every number, names ([A-Za-z0-9_] for axles: they become FMU
  variable names ``P_<axle>``), unique unit and axle names.
* Positive mass and yaw inertia (the mass matrix is then positive definite and the
  model has a unique motion), at least one axle per unit and one tire per axle,
  ``C_F > 0`` and ``C_M, C_S, D >= 0`` per tire (a negative stiffness is a sign error,
  not a tire), the limits of :data:`lcvreport.ranges.VEHICLE` (typos of 1000x).
* Couplings present exactly where the chain needs them: ``rear_coupling_m`` on every
  unit but the last, ``front_coupling_m`` on every unit but the first.
* The steer angle acts only on axles of the first unit (``steered``).

Not checked: plausibility of geometry.  An axle ahead of a kingpin, a hitch behind the
rear axle (every truck of a truck and full trailer has one), a coupling at the CG --
all are legal chains, and the model is valid for them.

Examples
--------
>>> from lcvreport.model.vehicle import Axle, Unit, Vehicle
>>> ax = Axle("front", 1.5, 2, 2.0e5, 0.0, 0.0, 0.0, steered=True)
>>> truck = Vehicle("truck", (Unit("truck", 9000.0, 3.0e4, (ax, Axle("rear", -3.5, 4, 1.5e5, 0.0, 0.0, 0.0))),))
>>> truck.n_units, truck.unit_names, truck.axle_names
(1, ('truck',), ('front', 'rear'))
>>> Unit("dolly", 0.0, 1.0, (ax,))
Traceback (most recent call last):
...
lcvreport.model.vehicle.VehicleError: mass_kg must be in (0, 1e+06] kg, got 0
"""
from __future__ import annotations

import math
import re
import unicodedata
from dataclasses import dataclass, field, replace
from numbers import Integral, Real

from ..ranges import GYRATION_PER_REACH_MIN, VEHICLE, RangeError
from .yaw_plane.states import joint_letter

#: the roll keys of a unit and of an axle (docs/roll.md), each its own range in VEHICLE
UNIT_ROLL_KEYS = ("cg_height_m", "roll_axis_height_m", "roll_inertia_kg_m2", "yaw_roll_product_kg_m2",
                  "rear_coupling_height_m", "rear_coupling_roll_stiffness_Nm_per_rad")
AXLE_ROLL_KEYS = ("roll_stiffness_Nm_per_rad", "roll_damping_Nms_per_rad", "unsprung_mass_kg")

#: names the vehicle itself may have (it is also the FMU's model name)
VEHICLE_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")


#: unit names: no commas or spaces (they are listed as --load trailer1,dolly1)
UNIT_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*\Z")


#: axle names: they become FMU variable names P_<axle>, T_<axle>
AXLE_NAME = re.compile(r"[A-Za-z0-9_]+\Z")


class VehicleError(ValueError):
    """An invalid vehicle: the message names where (unit, axle) and the key.

    Attributes
    ----------
    key : str
        The offending key (``mass_kg``, ``tires`` ...).
    where : str
        ``units[2] "dolly1" axles[0] "d1"`` or empty.

    Examples
    --------
    >>> from dataclasses import replace
    >>> from lcvreport import load_preset
    >>> v = load_preset("aucnat")
    >>> try:
    ...     replace(v.units[0], mass_kg=-1.0)
    ... except VehicleError as exc:
    ...     exc.key
    'mass_kg'
    """

    def __init__(self, key: str, message: str, where: str = ""):
        self.key = key
        self.where = where
        self.bare = message
        super().__init__(f"{where}: {message}" if where else message)

    def at(self, where: str) -> "VehicleError":
        """The same error located at ``where`` (prefixed to any location it has)."""
        return VehicleError(self.key, self.bare, f"{where} {self.where}".strip())


def _number(key: str, value, rng_key: str | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, Real):
        raise VehicleError(key, f"{key} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise VehicleError(key, f"{key} must be finite, got {v!r}")
    if rng_key is not None:
        try:
            VEHICLE[rng_key].check(v, key)
        except RangeError as exc:
            raise VehicleError(key, str(exc)) from None
    return v


def _name(key: str, value, pattern: re.Pattern, what: str) -> str:
    if not isinstance(value, str) or not pattern.match(value):
        raise VehicleError(key, f"{key} must be {what}, got {value!r}")
    return value


@dataclass(frozen=True)
class Axle:
    """One axle: position, tires and per-tire coefficients (SI, docs/vehicle_files.md).

    Attributes
    ----------
    name : str
        Unique in the vehicle, ``[A-Za-z0-9_]+`` (thesis: ``"11"`` is the steer axle).
    x_m : float
        Signed longitudinal position from the unit's CG [m], forward positive.
    tires : int
        Tires on the axle (2 singles, 4 for two duals); every coefficient is per tire.
    cornering_stiffness_N_per_rad : float
        C_F per tire [N/rad], > 0: lateral force F = C_F * alpha.
    aligning_stiffness_Nm_per_rad : float
        C_M per tire [N*m/rad], >= 0: aligning moment M = -C_M * alpha (restoring).
    longitudinal_stiffness_N : float
        C_S per tire [N], >= 0: with the dual spacing, yaw moment -C_S * D^2 * r / u per tire.
    dual_spacing_m : float
        D [m], >= 0 (0 for single tires).
    steered : bool
        The steer angle delta acts on this axle (first unit only).
    static_load_N : float or None
        Static vertical load [N]; needed only by the 1 % rule.
    track_width_m : float or None
        Lateral distance between the centres of the outermost tires [m]; needed only by
        the low-speed turn (docs/low_speed_turn.md) and roll (docs/roll.md).
    roll_stiffness_Nm_per_rad, roll_damping_Nms_per_rad : float or None
        The suspension's roll stiffness K [N*m/rad] and damping C [N*m*s/rad], >= 0, sprung
        mass relative to the axle; roll only (docs/roll.md).
    unsprung_mass_kg : float or None
        The axle's unsprung mass [kg], >= 0, part of its unit's ``mass_kg``; roll only.
    driven : bool or None
        The axle drives (first unit only): the nonlinear model's driven axles share the
        longitudinal force that holds unit 1's speed (docs/nonlinear.md); None: the default, every
        non-steered axle of unit 1.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> a = load_preset("aucnat").units[0].axles[0]
    >>> a.name, a.steered, a.tires
    ('11', True, 2)
    """

    name: str
    x_m: float
    tires: int
    cornering_stiffness_N_per_rad: float
    aligning_stiffness_Nm_per_rad: float
    longitudinal_stiffness_N: float
    dual_spacing_m: float
    steered: bool = False
    static_load_N: float | None = None
    track_width_m: float | None = None
    roll_stiffness_Nm_per_rad: float | None = None
    roll_damping_Nms_per_rad: float | None = None
    unsprung_mass_kg: float | None = None
    driven: bool | None = None

    def __post_init__(self):
        _name("name", self.name, AXLE_NAME, "a name of letters, digits and _")
        if self.driven is not None and not isinstance(self.driven, bool):
            raise VehicleError("driven", f"driven must be true or false, got {self.driven!r}")
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731 (frozen dataclass)
        set_("x_m", _number("x_m", self.x_m, "position_m"))
        if isinstance(self.tires, bool) or not isinstance(self.tires, Integral) or not 1 <= self.tires <= 64:
            raise VehicleError("tires", f"tires must be an integer >= 1 (at most 64), got {self.tires!r}")
        set_("tires", int(self.tires))
        for key in ("cornering_stiffness_N_per_rad", "aligning_stiffness_Nm_per_rad", "longitudinal_stiffness_N",
                    "dual_spacing_m"):
            set_(key, _number(key, getattr(self, key), key))
        if not isinstance(self.steered, bool):
            raise VehicleError("steered", f"steered must be true or false, got {self.steered!r}")
        if self.static_load_N is not None:
            set_("static_load_N", _number("static_load_N", self.static_load_N, "static_load_N"))
        for key in ("track_width_m",) + AXLE_ROLL_KEYS:
            if getattr(self, key) is not None:
                set_(key, _number(key, getattr(self, key), key))

    # per-axle sums (tires x per-tire coefficient)
    @property
    def cornering_stiffness_axle_N_per_rad(self) -> float:
        """C_F of the whole axle [N/rad] (tires x per tire)."""
        return self.tires * self.cornering_stiffness_N_per_rad

    @property
    def aligning_stiffness_axle_Nm_per_rad(self) -> float:
        """C_M of the whole axle [N*m/rad]."""
        return self.tires * self.aligning_stiffness_Nm_per_rad

    @property
    def dual_yaw_damping_axle_N_m2(self) -> float:
        """tires * C_S * D^2 of the whole axle [N*m^2]: the yaw moment is this times -r/u."""
        return self.tires * self.longitudinal_stiffness_N * self.dual_spacing_m ** 2


@dataclass(frozen=True)
class Unit:
    """One rigid unit (tractor, truck, semitrailer, dolly, full trailer ...), SI.

    Attributes
    ----------
    name : str
        Unique in the vehicle; no commas or spaces.
    mass_kg : float
        Mass [kg], > 0.
    yaw_inertia_kg_m2 : float
        Yaw moment of inertia about the CG [kg*m^2], > 0.
    axles : tuple of Axle
        At least one.
    front_coupling_m : float or None
        Signed x of the front coupling (kingpin, drawbar eye) [m]; None on the first unit.
    rear_coupling_m : float or None
        Signed x of the rear coupling (fifth wheel, hitch) [m]; None on the last unit.
    rear_end_m : float or None
        Signed x of the point whose lateral offset is reported as y_k [m]; None for
        the default (the rear coupling, or the rearmost axle on the last unit).
    body_front_m, body_rear_m : float or None
        Signed x of the body's front and rear faces [m] (given together, rear < front);
        needed only by the low-speed turn and the drawings (docs/low_speed_turn.md).
    body_width_m : float or None
        Width of the body [m], symmetric about the unit's axis.
    cg_height_m, roll_axis_height_m : float or None
        Heights above ground [m] of the sprung mass's CG (h, in (0, 5]) and of the unit's
        roll axis (h_r, in [0, h)); roll only (docs/roll.md).
    roll_inertia_kg_m2 : float or None
        I_x of the sprung mass about a longitudinal axis through its CG [kg*m^2], > 0.
    yaw_roll_product_kg_m2 : float or None
        I_xz of the sprung mass about its CG, x forward and z down [kg*m^2] (None: 0).
    rear_coupling_height_m : float or None
        Height of the rear coupling above ground [m] (units with a rear coupling).
    rear_coupling_roll_stiffness_Nm_per_rad : float or None
        Roll stiffness of the rear coupling [N*m/rad]: 0 roll-free (a drawbar eye), > 0
        roll-coupled (a fifth wheel).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> u = load_preset("aucnat").units[1]
    >>> u.name, len(u.axles) > 0
    ('trailer1', True)
    """

    name: str
    mass_kg: float
    yaw_inertia_kg_m2: float
    axles: tuple[Axle, ...]
    front_coupling_m: float | None = None
    rear_coupling_m: float | None = None
    rear_end_m: float | None = None
    body_front_m: float | None = None
    body_rear_m: float | None = None
    body_width_m: float | None = None
    cg_height_m: float | None = None
    roll_axis_height_m: float | None = None
    roll_inertia_kg_m2: float | None = None
    yaw_roll_product_kg_m2: float | None = None
    rear_coupling_height_m: float | None = None
    rear_coupling_roll_stiffness_Nm_per_rad: float | None = None

    def __post_init__(self):
        _name("name", self.name, UNIT_NAME, "a name of letters, digits, _ . - (no commas or spaces)")
        set_ = lambda k, v: object.__setattr__(self, k, v)  # noqa: E731
        set_("mass_kg", _number("mass_kg", self.mass_kg, "mass_kg"))
        set_("yaw_inertia_kg_m2", _number("yaw_inertia_kg_m2", self.yaw_inertia_kg_m2, "yaw_inertia_kg_m2"))
        for key in ("front_coupling_m", "rear_coupling_m", "rear_end_m", "body_front_m", "body_rear_m"):
            if getattr(self, key) is not None:
                set_(key, _number(key, getattr(self, key), "position_m"))
        for key in ("body_width_m",) + UNIT_ROLL_KEYS:
            if getattr(self, key) is not None:
                set_(key, _number(key, getattr(self, key), key))
        if self.cg_height_m is not None and self.roll_axis_height_m is not None and \
                self.roll_axis_height_m >= self.cg_height_m:
            raise VehicleError("roll_axis_height_m", f"roll_axis_height_m must be below cg_height_m "
                               f"({self.cg_height_m:g} m), got {self.roll_axis_height_m:g} m")
        if (self.body_front_m is None) != (self.body_rear_m is None):
            given, missing = ("body_front_m", "body_rear_m") if self.body_rear_m is None else \
                ("body_rear_m", "body_front_m")
            raise VehicleError(missing, f"{missing} is needed with {given}: a body has a front and a rear face")
        if self.body_front_m is not None and self.body_rear_m >= self.body_front_m:
            raise VehicleError("body_rear_m", f"body_rear_m must be behind body_front_m ({self.body_front_m:g} m), "
                                              f"got {self.body_rear_m:g} m")
        axles = tuple(self.axles) if isinstance(self.axles, (list, tuple)) else self.axles
        if not isinstance(axles, tuple) or not all(isinstance(a, Axle) for a in axles):
            raise VehicleError("axles", f"axles must be a list of Axle, got {self.axles!r}")
        if not axles:
            raise VehicleError("axles", "a unit needs at least one axle, got none")
        set_("axles", axles)
        unsprung = [a.unsprung_mass_kg for a in axles]
        if None not in unsprung and sum(unsprung) >= self.mass_kg:
            raise VehicleError("unsprung_mass_kg", f"unsprung_mass_kg of the axles sum to {sum(unsprung):.6g} kg, "
                               f"at or above the unit's mass_kg {self.mass_kg:.6g} kg (they are part of it)")
        reach = max(abs(x) for x in [a.x_m for a in axles] + [self.front_coupling_m, self.rear_coupling_m]
                    if x is not None)
        k = math.sqrt(self.yaw_inertia_kg_m2 / self.mass_kg)
        if k < GYRATION_PER_REACH_MIN * reach:
            raise VehicleError("yaw_inertia_kg_m2", f"yaw_inertia_kg_m2 {self.yaw_inertia_kg_m2:.4g} kg*m^2 of a "
                               f"{self.mass_kg:.4g} kg unit is a radius of gyration sqrt(I/m) of {k:.3g} m, "
                               f"{k / reach:.2g} of the {reach:.3g} m from its CG to its farthest axle or coupling; "
                               f"below {GYRATION_PER_REACH_MIN:g} the model's eigenvalues are not reliable (a real "
                               "body's is 0.05-2 of its length): the inertia or the mass is in another unit")
        ixz = self.yaw_roll_product_kg_m2
        if ixz is not None and self.roll_inertia_kg_m2 is not None and ixz * ixz >= \
                self.roll_inertia_kg_m2 * self.yaw_inertia_kg_m2:
            raise VehicleError("yaw_roll_product_kg_m2", f"yaw_roll_product_kg_m2 {ixz:.6g} kg*m^2 with "
                               f"roll_inertia_kg_m2 {self.roll_inertia_kg_m2:.6g} and yaw_inertia_kg_m2 "
                               f"{self.yaw_inertia_kg_m2:.6g} is no body's: I_xz^2 must be below I_x I_z (the "
                               "inertia matrix is positive definite)")

    @property
    def rearmost_axle(self) -> Axle:
        """The axle with the smallest (most rearward) x."""
        return min(self.axles, key=lambda a: a.x_m)


def check_vehicle(vehicle, name: str = "vehicle") -> "Vehicle":
    """``vehicle`` if it is a :class:`Vehicle`, else one :class:`TypeError` line saying how to
    get one (a preset's name or a file's path is not one).

    Examples
    --------
    >>> check_vehicle("aucnat")
    Traceback (most recent call last):
    ...
    TypeError: vehicle must be a Vehicle (lcvreport.load_preset("aucnat") or lcvreport.load_vehicle(path)), got the str 'aucnat'
    """
    if isinstance(vehicle, Vehicle):
        return vehicle
    shown = repr(vehicle)
    shown = shown if len(shown) <= 60 else shown[:57] + "..."
    raise TypeError(f'{name} must be a Vehicle (lcvreport.load_preset("aucnat") or lcvreport.load_vehicle(path)), '
                    f"got the {type(vehicle).__name__} {shown}")


@dataclass(frozen=True)
class Vehicle:
    """A chain of N >= 1 units coupled by pin joints, SI (docs/vehicle_files.md).

    Attributes
    ----------
    name : str
        ``[A-Za-z][A-Za-z0-9_]*``: also the model name of its FMUs.
    units : tuple of Unit
        Front to back.
    description : str
        Free text (where the numbers come from).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> v = load_vehicle("examples/vehicles/b_double.toml")
    >>> v.name, v.unit_names
    ('b_double', ('prime_mover', 'lead_trailer', 'rear_trailer'))
    """

    name: str
    units: tuple[Unit, ...]
    description: str = ""
    source: str = field(default="", compare=False, hash=False)

    def __hash__(self) -> int:
        # the caches keyed by vehicle (system_coefficients) hash it on every call: a 6-unit
        # vehicle's fields hash in ~9 us, so the hash is kept (the vehicle is immutable)
        h = self.__dict__.get("_hash")
        if h is None:
            h = hash((self.name, self.units, self.description))
            object.__setattr__(self, "_hash", h)
        return h

    def __getstate__(self):
        # str hashes differ between processes (hash randomisation): a pickled vehicle
        # recomputes its hash where it is loaded
        return {k: v for k, v in self.__dict__.items() if k != "_hash"}

    def __post_init__(self):
        _name("name", self.name, VEHICLE_NAME, "a name that starts with a letter (letters, digits, _)")
        units = tuple(self.units) if isinstance(self.units, (list, tuple)) else self.units
        if not isinstance(units, tuple) or not all(isinstance(u, Unit) for u in units):
            raise VehicleError("units", f"units must be a list of Unit, got {self.units!r}")
        if not units:
            raise VehicleError("units", "a vehicle needs at least one unit, got none")
        if len(units) > VEHICLE["units"].high:
            raise VehicleError("units", f"a vehicle has at most {VEHICLE['units'].high:.0f} units "
                                        f"({VEHICLE['units'].description}), got {len(units)}")
        object.__setattr__(self, "units", units)
        if not isinstance(self.description, str):
            raise VehicleError("description", f"description must be text, got {self.description!r}")
        bad = [ch for ch in self.description if unicodedata.category(ch) in ("Cc", "Cs", "Co", "Cn")]
        if bad:
            raise VehicleError("description", f"description must be printable text (it goes into XML, C and "
                                              f"reports), got the control character U+{ord(bad[0]):04X}")
        seen_units: set[str] = set()
        seen_axles: set[str] = set()
        n = len(units)
        for i, u in enumerate(units):
            where = f'units[{i}] "{u.name}"'
            if u.name in seen_units:
                raise VehicleError("name", f"unit name {u.name!r} is used twice", where)
            seen_units.add(u.name)
            if i < n - 1 and u.rear_coupling_m is None:
                raise VehicleError("rear_coupling_m", "rear_coupling_m is required on every unit but the last "
                                   f"(unit {i + 1} of {n} couples to the next)", where)
            for key in ("rear_coupling_height_m", "rear_coupling_roll_stiffness_Nm_per_rad"):
                if u.rear_coupling_m is None and getattr(u, key) is not None:
                    raise VehicleError(key, f"{key} must be absent on a unit without a rear coupling", where)
            if i == n - 1 and u.rear_coupling_m is not None:
                raise VehicleError("rear_coupling_m", "rear_coupling_m must be absent on the last unit "
                                   "(nothing is coupled behind it)", where)
            if i > 0 and u.front_coupling_m is None:
                raise VehicleError("front_coupling_m", "front_coupling_m is required on every unit but the "
                                   f"first (unit {i + 1} is coupled to the unit ahead)", where)
            if i == 0 and u.front_coupling_m is not None:
                raise VehicleError("front_coupling_m", "front_coupling_m must be absent on the first unit "
                                   "(nothing is coupled ahead of it)", where)
            for j, a in enumerate(u.axles):
                awhere = f'{where} axles[{j}] "{a.name}"'
                if a.name in seen_axles:
                    raise VehicleError("name", f"axle name {a.name!r} is used twice", awhere)
                seen_axles.add(a.name)
                if a.steered and i > 0:
                    raise VehicleError("steered", "steered axles must be on the first unit (the steer "
                                       "input acts on the towing unit)", awhere)
                if a.driven and i > 0:
                    raise VehicleError("driven", "driven axles must be on the first unit (it hauls the "
                                       "combination)", awhere)

    # ------------------------------------------------------------------ chain
    @property
    def n_units(self) -> int:
        """Number of units N."""
        return len(self.units)

    @property
    def unit_names(self) -> tuple[str, ...]:
        """Unit names, front to back."""
        return tuple(u.name for u in self.units)

    @property
    def axles(self) -> tuple[Axle, ...]:
        """All axles, front to back in file order."""
        return tuple(a for u in self.units for a in u.axles)

    @property
    def axle_names(self) -> tuple[str, ...]:
        """Names of all axles, in :attr:`axles` order."""
        return tuple(a.name for a in self.axles)

    @property
    def axle_units(self) -> tuple[int, ...]:
        """0-based unit index of every axle, in :attr:`axles` order."""
        return tuple(i for i, u in enumerate(self.units) for _a in u.axles)

    @property
    def joint_letters(self) -> tuple[str, ...]:
        """Letters of the N-1 joints (A, B, ...)."""
        return tuple(joint_letter(k) for k in range(self.n_units - 1))

    @property
    def steered_axles(self) -> tuple[Axle, ...]:
        """Axles the steer angle acts on."""
        return tuple(a for a in self.units[0].axles if a.steered)

    def rear_end_x_m(self, k: int) -> float:
        """Signed x [m] of the reported rear end of unit ``k`` (0-based): ``rear_end_m``
        if given, else the rear coupling, else (last unit) the rearmost axle."""
        u = self.units[k]
        if u.rear_end_m is not None:
            return u.rear_end_m
        if u.rear_coupling_m is not None:
            return u.rear_coupling_m
        return u.rearmost_axle.x_m

    @property
    def gross_load_N(self) -> float | None:
        """Sum of the static axle loads [N], None if any is missing."""
        loads = [a.static_load_N for a in self.axles]
        return None if any(v is None for v in loads) else float(sum(loads))

    def unit(self, name: str) -> Unit:
        """The unit called ``name``."""
        for u in self.units:
            if u.name == name:
                return u
        raise KeyError(f"unknown unit {name!r}; {self.name} has: {', '.join(self.unit_names)}")

    def unit_index(self, name: str) -> int:
        """0-based index of the unit called ``name``."""
        return self.unit_names.index(self.unit(name).name)

    # ------------------------------------------------------------------ variants
    def with_masses(self, masses_kg, inertias_kg_m2=None, name: str | None = None) -> "Vehicle":
        """Copy with the unit masses [kg] (and optionally inertias [kg*m^2]) replaced, front to back."""
        if len(masses_kg) != self.n_units:
            raise ValueError(f"masses_kg: expected {self.n_units} values, got {len(masses_kg)}")
        inertias = [u.yaw_inertia_kg_m2 for u in self.units] if inertias_kg_m2 is None else inertias_kg_m2
        units = tuple(replace(u, mass_kg=float(m), yaw_inertia_kg_m2=float(i))
                      for u, m, i in zip(self.units, masses_kg, inertias))
        return replace(self, units=units, name=name or self.name)

    def scaled_mass(self, factor: float, name: str | None = None) -> "Vehicle":
        """Copy with every mass, yaw inertia and static axle load multiplied by ``factor``."""
        units = tuple(replace(u, mass_kg=u.mass_kg * factor, yaw_inertia_kg_m2=u.yaw_inertia_kg_m2 * factor,
                              axles=tuple(replace(a, static_load_N=None if a.static_load_N is None
                                                  else a.static_load_N * factor) for a in u.axles))
                      for u in self.units)
        return replace(self, units=units, name=name or self.name)

    def truncated(self, n_units: int, name: str | None = None) -> "Vehicle":
        """The first ``n_units`` units as a vehicle of their own (the last one's rear
        coupling becomes its rear end)."""
        if not 1 <= n_units <= self.n_units:
            raise ValueError(f"n_units must be in [1, {self.n_units}], got {n_units}")
        units = list(self.units[:n_units])
        last = units[-1]
        if last.rear_coupling_m is not None:
            units[-1] = replace(last, rear_coupling_m=None, rear_coupling_height_m=None,
                                rear_coupling_roll_stiffness_Nm_per_rad=None,
                                rear_end_m=last.rear_end_m if last.rear_end_m is not None else last.rear_coupling_m)
        return replace(self, units=tuple(units), name=name or self.name)
