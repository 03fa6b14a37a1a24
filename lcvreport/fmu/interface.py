"""The FMU interface table: every variable of an FMU, declared once.

One :class:`FmuVariable` per variable (name, value reference, causality,
variability, type, unit, display unit, start, description, and the *source* the
engine reads it from).  Both modelDescription.xml files
(:mod:`lcvreport.fmu.description_fmi2`), the C header's ``ValueReference`` enum
(:mod:`lcvreport.fmu.build`), the pythonfmu slave's registration and the engine's
output addressing (:mod:`lcvreport.fmu.engine`) are generated from this table,
the way FMPy's ``ModelVariable`` has one writer and Reference-FMUs' ``config.h``
one enum.

Two interfaces (docs/fmu.md):

* :func:`preset_interface`: ``LCV`` / ``LCVNative`` -- a ``preset`` parameter picks one
  of the six thesis vehicles; parameters ``tire_scale``, ``u_min``, ``crossfall``; inputs
  ``P11 .. P61``, ``T11 .. T61``, ``eps11 .. eps61`` of the thesis axles; outputs for six
  units (0 where the preset has fewer), joints lettered ``thetaA .. thetaE``, and ``ay1
  .. ay6`` after the preset FMU's original outputs (docs/fmu.md).
* :func:`vehicle_interface`: the vehicle built in; inputs ``P_<axle>``, ``T_<axle>``,
  ``eps_<axle>``; outputs ``v1, r1..rN, theta1..theta(N-1), ay1..ayN, y2..yN, psi1, Y1,
  Y_rear, max_real_eig, Y_<axle>`` (every axle centre's global lateral position).

Value references are the table's order: parameters, inputs, outputs, each a block
(address variables by name, as modelDescription.xml gives them).

Examples
--------
>>> itf = preset_interface()
>>> itf.by_name["y6"].value_reference, itf.by_name["ay1"].value_reference
(46, 51)
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.linear import linear_model
from ..model.presets import PRESETS
from ..model.vehicle import Vehicle
from ..model.yaw_plane.states import joint_letter
from ..ranges import RANGES

#: default forward speed [m/s] (50 mph = 22.352 m/s exactly)
#: the models an FMU is built of (``lcv fmu --model``): the linear ones (Python and native, FMI 2 and 3) and
#: the nonlinear planar model (Python, FMI 2.0 Co-Simulation)
FMU_MODELS = ("yaw_plane", "yaw_roll", "nonlinear")

U_START = 22.352
#: default lowest speed the model is run at [m/s] (5 mph = 2.2352 m/s exactly)
U_MIN_DEFAULT = 2.2352
#: the thesis' axle names of the preset FMU's P/T inputs (unit, axle)
PRESET_AXLES = ("11", "12", "13", "21", "31", "41", "51", "61")
#: units and joints of the preset FMU's outputs (the triple)
PRESET_UNITS = 6
#: FMI unit name of each quantity kind (SI)
UNITS = {"speed": "m/s", "angle": "rad", "rate": "rad/s", "force": "N", "moment": "N.m", "length": "m",
         "accel": "m/s2", "per_s": "1/s", "factor": "1", "percent": "%", "none": ""}
#: display unit of each quantity kind: the preset FMU keeps the thesis' (docs/fmu.md),
#: vehicle FMUs show km/h, degrees and SI
DISPLAY_UNITS = {
    "thesis": {"speed": "mph", "angle": "deg", "rate": "deg/s", "force": "lbf", "moment": "lbf.ft", "length": "in"},
    "si": {"speed": "km/h", "angle": "deg", "rate": "deg/s", "accel": "g", "per_s": "1/min", "force": "kN",
           "moment": "kN.m", "length": "mm"},
}
#: the physical quantity of each kind (modelDescription ``<TypeDefinitions>``)
QUANTITIES = {"speed": "Velocity", "angle": "Angle", "rate": "AngularVelocity", "force": "Force", "moment": "Torque",
              "length": "Length", "accel": "Acceleration", "per_s": "Rate", "factor": "Factor", "percent": "Slope"}


@dataclass(frozen=True)
class FmuVariable:
    """One FMU variable.

    Attributes
    ----------
    name : str
    value_reference : int
    causality : {"parameter", "input", "output"}
    variability : {"fixed", "continuous"}
    type : {"Real", "Enumeration"}
        ``preset`` is an Enumeration (FMI 2: ``fmi2Get/SetInteger``; FMI 3: ``fmi3Get/SetInt64``)
        whose items are ``items`` numbered from 1; its name is also accepted through
        ``fmi2SetString``/``fmi3SetString`` (what FMUs before the enumeration took).
    quantity : str
        Key of :data:`UNITS` (the FMI unit and display unit follow from it).
    start : float, str or None
        Start value (parameters and inputs).
    description : str
    source : tuple
        What the engine reads or writes: ``("parameter", name)``, ``("speed",)``,
        ``("steer",)``, ``("P", axle)``, ``("T", axle)``, ``("state", state_name)``,
        ``("ay", unit)``, ``("y", unit)``, ``("psi1",)``, ``("Y1",)``, ``("Y_rear",)``, ``("Y_axle", axle)``,
        ``("max_real_eig",)``; units 1-based.
    minimum, maximum : float or None
        Valid range (from :data:`lcvreport.ranges.RANGES`), written as min/max.
    display_unit : str
        Display unit ('' for none).
    items : tuple of str
        The Enumeration's items (value k+1 is ``items[k]``); empty for Real variables.
    """

    name: str
    value_reference: int
    causality: str
    variability: str
    type: str
    quantity: str
    start: float | str | None
    description: str
    source: tuple
    minimum: float | None = None
    maximum: float | None = None
    display_unit: str = ""
    items: tuple = ()

    @property
    def unit(self) -> str:
        """FMI unit name ('' for none)."""
        return UNITS[self.quantity]


@dataclass(frozen=True)
class Interface:
    """The variables of one FMU and the vehicles it can run.

    Attributes
    ----------
    model_name : str
        The FMU's model name and (for the pythonfmu FMU) model identifier.
    variables : tuple of FmuVariable
        In value-reference order (vr = index).
    vehicles : tuple of Vehicle
        The vehicle built in, or the six presets (``preset`` parameter picks one).
    preset_mode : bool
        True for the preset FMUs' interface (a ``preset`` parameter; docs/fmu.md).
    description : str
    model : str
        The linear model the FMU runs (:data:`lcvreport.model.linear.MODELS`): ``yaw_plane``, or
        ``yaw_roll`` with the roll states and outputs (docs/fmu.md).
    """

    model_name: str
    variables: tuple[FmuVariable, ...]
    vehicles: tuple[Vehicle, ...]
    preset_mode: bool
    description: str = ""
    model: str = "yaw_plane"
    by_name: dict = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        object.__setattr__(self, "by_name", {v.name: v for v in self.variables})
        for i, v in enumerate(self.variables):
            assert v.value_reference == i, "value references must be the table index"

    def of(self, causality: str) -> tuple[FmuVariable, ...]:
        """The variables of one causality, in value-reference order."""
        return tuple(v for v in self.variables if v.causality == causality)

    @property
    def inputs(self) -> tuple[FmuVariable, ...]:
        return self.of("input")

    @property
    def outputs(self) -> tuple[FmuVariable, ...]:
        return self.of("output")

    @property
    def parameters(self) -> tuple[FmuVariable, ...]:
        return self.of("parameter")

    @property
    def continuous_states(self) -> tuple[FmuVariable, ...]:
        """The Model Exchange states: the outputs v1, r1..rN, the articulation angles, psi1, Y1
        (and the yaw-roll model's p1..pN, phi1..phiN; docs/fmu.md), in value-reference order."""
        return tuple(v for v in self.outputs if v.source[0] in ("state", "psi1", "Y1"))

    def state_nominals(self) -> tuple[float, ...]:
        """The nominal of every Model Exchange state (:attr:`continuous_states` order): its
        physical scale, the peak |state| of the field's standard manoeuvre -- the single sine
        0.01 rad at 0.4 Hz from rest, at the start speed of ``u``, over 1/f + 8 s -- over the
        vehicles of this FMU (a vehicle with no steered axle: a 1 kN residual force on its
        rearmost axle for 10 s).  A host's integrator scales its absolute tolerance by it
        (fmusim's CVODE: atol = rtol x nominal), so states of a few milliradians are resolved.
        Computed at build time (the FMU's runtime does not compute it)."""
        from ..analysis.exact import response
        from ..manoeuvres.steer import sine, step
        u = float(self.by_name["u"].start)
        peaks = np.zeros(len(self.continuous_states))
        for v in self.vehicles:
            names = []
            for var in self.continuous_states:
                i = self.state_index(var, v)
                names.append(None if i < 0 else (list(linear_model(v, self.model).state_names) + ["psi1", "Y1"])[i])
            if v.steered_axles:
                r = response(v, u, sine(0.01, 0.4), 10.5, 0.01, model=self.model)
            else:
                co = linear_model(v, self.model)
                force = np.zeros(len(v.axles))
                force[-1] = 1e3
                r = response(v, u, step(0.0), 10.0, 0.01, F=1e3 * co.B_P[:, -1], model=self.model,
                             axle_force_N=force)
            got = r.peaks_abs([n for n in names if n is not None])
            k = 0
            for j, n in enumerate(names):
                if n is not None:
                    peaks[j] = max(peaks[j], float(got[k]))
                    k += 1
        return tuple(float(max(p, 1e-6)) for p in peaks)

    def state_index(self, variable: FmuVariable, vehicle: Vehicle) -> int:
        """Index of a continuous state in the model's z = [x, psi1, Y1] of ``vehicle``; -1 for a
        state the vehicle lacks (a preset with fewer units)."""
        kind = variable.source[0]
        model = linear_model(vehicle, self.model)
        if kind == "psi1":
            return model.n_states
        if kind == "Y1":
            return model.n_states + 1
        names = model.state_names
        return names.index(variable.source[1]) if variable.source[1] in names else -1

    def vehicle(self, preset: str | None = None) -> Vehicle:
        """The vehicle of this FMU (in preset mode, the preset named ``preset``)."""
        if not self.preset_mode:
            return self.vehicles[0]
        for v in self.vehicles:
            if v.name == preset:
                return v
        raise KeyError(f"preset: unknown preset {preset!r}; valid: {', '.join(v.name for v in self.vehicles)}")

    def rows(self) -> list[dict]:
        """The table as rows (name, value reference, causality, variability, unit, display unit,
        start, description), for documentation and reports."""
        return [{"name": v.name, "value_reference": v.value_reference, "causality": v.causality,
                 "variability": v.variability, "unit": v.unit, "display_unit": v.display_unit,
                 "start": "" if v.start is None else v.start, "description": v.description} for v in self.variables]


class _Table:
    def __init__(self, display: str):
        self.vars: list[FmuVariable] = []
        self.display = DISPLAY_UNITS[display]

    def add(self, name, causality, variability, quantity, start, description, source, type_="Real", range_key=None,
            maximum=None, items=()):
        lo = hi = None
        if range_key is not None:
            r = RANGES[range_key]
            lo, hi = r.low, r.high
        if maximum is not None:
            hi = maximum
        self.vars.append(FmuVariable(name, len(self.vars), causality, variability, type_, quantity, start,
                                     description, source, lo, hi, self.display.get(quantity, ""), tuple(items)))


def _parameters(t: _Table) -> None:
    t.add("tire_scale", "parameter", "fixed", "factor", 1.0,
          f"Factor on every tire coefficient C_F, C_M, C_S (chapter V), in {RANGES['tire_scale'].text()}",
          ("parameter", "tire_scale"), range_key="tire_scale")
    t.add("u_min", "parameter", "fixed", "speed", U_MIN_DEFAULT,
          "Lowest forward speed the linear model is run at; a lower input u is clamped to it "
          f"(one warning), in {RANGES['u_min'].text()}", ("parameter", "u_min"), range_key="u_min")
    t.add("crossfall", "parameter", "fixed", "percent", 0.0,
          "Road crossfall, positive when the road falls toward +y: m_i g sin(atan(crossfall/100)) along +y at every "
          f"unit's CG, in {RANGES['crossfall'].text()}", ("parameter", "crossfall"), range_key="crossfall")


def _speed_and_steer(t: _Table, steer_text: str, u_start: float = U_START) -> None:
    t.add("u", "input", "continuous", "speed", u_start,
          f"Forward speed of every unit, held over each communication step; at most {RANGES['speed'].high:g} m/s",
          ("speed",), maximum=RANGES["speed"].high)
    t.add("delta", "input", "continuous", "angle", 0.0,
          f"Steer angle of {steer_text}, positive nose-right (toward +y), in {RANGES['steer_angle'].text()}",
          ("steer",), range_key="steer_angle")


def _tail_outputs(t: _Table, last: str) -> None:
    t.add("psi1", "output", "continuous", "angle", None, "Tractor heading (yaw angle) from the start, nose-right "
          "positive", ("psi1",))
    t.add("Y1", "output", "continuous", "length", None, "Global lateral position of the tractor CG from the start, +y",
          ("Y1",))
    t.add("Y_rear", "output", "continuous", "length", None,
          f"Global lateral position of the rear end of {last} from the start, +y (first order)", ("Y_rear",))
    t.add("max_real_eig", "output", "continuous", "per_s", None,
          "Largest real part of the eigenvalues at the current (clamped) speed: negative = stable", ("max_real_eig",))


def preset_value(name: str) -> int:
    """The value of the preset FMU's Enumeration parameter ``preset`` that picks the preset ``name``.

    >>> preset_value("aucnat"), preset_value("tractor_semitrailer")
    (1, 6)
    """
    if name not in PRESETS:
        raise KeyError(f"preset: unknown preset {name!r}; valid: {', '.join(PRESETS)}")
    return PRESETS.index(name) + 1


def preset_interface() -> Interface:
    """The preset FMUs' interface (``LCV``/``LCVNative``, docs/fmu.md), with ``ay1 .. ay6`` appended."""
    from ..model.presets import load_preset
    t = _Table("thesis")
    t.add("preset", "parameter", "fixed", "none", PRESETS[0],
          "Vehicle preset (Enumeration: " + ", ".join(f"{k} {p}" for k, p in enumerate(PRESETS, 1))
          + "; the name through SetString is accepted too)", ("parameter", "preset"), type_="Enumeration",
          items=PRESETS)
    _parameters(t)
    _speed_and_steer(t, "the tractor steer axle 11")
    for a in PRESET_AXLES:
        t.add(f"P{a}", "input", "continuous", "force", 0.0, f"Residual lateral force (conicity, ply steer) of axle "
              f"{a} (axle {a[1]} of unit {a[0]}), along +y (curb side); ignored if the preset lacks the axle",
              ("P", a), range_key="residual_force")
    for a in PRESET_AXLES:
        t.add(f"T{a}", "input", "continuous", "moment", 0.0, f"Residual aligning moment of axle {a} (axle {a[1]} of "
              f"unit {a[0]}), about +z (down), positive nose-right; ignored if the preset lacks the axle",
              ("T", a), range_key="residual_moment")
    for a in PRESET_AXLES:
        t.add(f"eps{a}", "input", "continuous", "angle", 0.0, f"Misalignment (thrust angle) of axle {a} (axle {a[1]} "
              f"of unit {a[0]}), nose-right positive: the axle's slip angle gains it; in "
              f"{RANGES['misalignment'].text()}; ignored if the preset lacks the axle", ("eps", a),
              range_key="misalignment")
    t.add("v1", "output", "continuous", "speed", None, "Tractor lateral velocity at the CG, +y", ("state", "v1"))
    for i in range(1, PRESET_UNITS + 1):
        t.add(f"r{i}", "output", "continuous", "rate", None, f"Yaw rate of unit {i} (1 tractor, 2 trailer 1, 3 dolly 1, "
              "4 trailer 2, 5 dolly 2, 6 trailer 3), nose-right positive; 0 if the preset lacks the unit",
              ("state", f"r{i}"))
    for k in range(PRESET_UNITS - 1):
        j = joint_letter(k)
        t.add(f"theta{j}", "output", "continuous", "angle", None, f"Articulation angle at joint {j} (heading of the "
              "unit ahead minus the unit behind); 0 if the preset lacks the joint", ("state", f"theta{j}"))
    for k in range(2, PRESET_UNITS + 1):
        t.add(f"y{k}", "output", "continuous", "length", None, f"Lateral displacement of the rear end of unit {k} "
              "relative to the tractor axis (eq. 4.42-4.46); 0 if the preset lacks the unit", ("y", k))
    _tail_outputs(t, "the last unit")
    for i in range(1, PRESET_UNITS + 1):
        t.add(f"ay{i}", "output", "continuous", "accel", None, f"Lateral acceleration of the CG of unit {i}, "
              "a = v' + u r, at the current state and inputs; 0 if the preset lacks the unit", ("ay", i))
    return Interface("LCV", tuple(t.vars), tuple(load_preset(p) for p in PRESETS), True,
                     "Linear yaw-plane model of a long combination vehicle (tractor, semitrailers, converter "
                     "dollies) with residual tire forces (conicity, ply steer); Patterson (2011). Exact "
                     "zero-order-hold stepping for any communication step size.")


def fmu_base_name(vehicle_name: str, model: str = "yaw_plane") -> str:
    """The stem of a vehicle's FMUs of ``model``: the vehicle's name for the yaw plane, with the
    model's name appended for any other (``b_double_yaw_roll``).

    Examples
    --------
    >>> fmu_base_name("b_double"), fmu_base_name("b_double", "yaw_roll")
    ('b_double', 'b_double_yaw_roll')
    """
    return vehicle_name if model == "yaw_plane" else f"{vehicle_name}_{model}"


def vehicle_interface(vehicle: Vehicle, u_start_mps: float = U_START, model: str = "yaw_plane") -> Interface:
    """The interface of an FMU with ``vehicle`` built in (docs/fmu.md); the input ``u``
    starts at ``u_start_mps`` [m/s] (default 50 mph).

    ``model``: ``yaw_plane`` (default) or ``yaw_roll``, which appends (after every yaw-plane
    variable, so their value references do not move) the roll rates ``p<i>`` [rad/s] and roll
    angles ``phi<i>`` [rad] of the sprung masses, the sprung CGs' lateral accelerations
    ``as<i>`` [m/s2], every axle's load transfer ``dFz_<axle>`` [N] and the load transfer ratio
    ``ltr<g>`` [-] of every roll-coupled group; ``nonlinear``, the nonlinear planar model's
    (:func:`nonlinear_interface`).

    Raises
    ------
    lcvreport.model.linear.ModelError
        An unknown model.
    lcvreport.model.vehicle.VehicleError
        ``yaw_roll`` for a vehicle without (valid) roll data: the message names the key.

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> itf = vehicle_interface(load_vehicle("examples/vehicles/western_double.toml"), model="yaw_roll")
    >>> [v.name for v in itf.outputs][-4:]
    ['dFz_dolly_axle', 'dFz_trailer2_axle', 'ltr1', 'ltr2']
    """
    from ..model.base import check_model as check_any_model
    if check_any_model(model) == "nonlinear":
        return nonlinear_interface(vehicle, u_start_mps)
    from ..model.linear import check_model
    RANGES["speed"].check(u_start_mps, "start speed")
    model = check_model(model)
    co = linear_model(vehicle, model)               # the roll data checked: one line naming the key
    t = _Table("si")
    _parameters(t)
    steered = vehicle.steered_axles
    steer_text = ("axles " + ", ".join(a.name for a in steered)) if steered else "no axle (none is steered)"
    _speed_and_steer(t, steer_text, float(u_start_mps))
    for i, u in enumerate(vehicle.units):
        for a in u.axles:
            t.add(f"P_{a.name}", "input", "continuous", "force", 0.0, f"Residual lateral force (conicity, ply steer) "
                  f"of axle {a.name} of {u.name} (unit {i + 1}), along +y", ("P", a.name), range_key="residual_force")
    for i, u in enumerate(vehicle.units):
        for a in u.axles:
            t.add(f"T_{a.name}", "input", "continuous", "moment", 0.0, f"Residual aligning moment of axle {a.name} of "
                  f"{u.name} (unit {i + 1}), about +z (down), positive nose-right", ("T", a.name),
                  range_key="residual_moment")
    for i, u in enumerate(vehicle.units):
        for a in u.axles:
            t.add(f"eps_{a.name}", "input", "continuous", "angle", 0.0, f"Misalignment (thrust angle) of axle {a.name} "
                  f"of {u.name} (unit {i + 1}), nose-right positive: the axle's slip angle gains it; in "
                  f"{RANGES['misalignment'].text()}", ("eps", a.name), range_key="misalignment")
    n = vehicle.n_units
    t.add("v1", "output", "continuous", "speed", None, f"Lateral velocity of the CG of {vehicle.units[0].name}, +y",
          ("state", "v1"))
    for i, u in enumerate(vehicle.units):
        t.add(f"r{i + 1}", "output", "continuous", "rate", None, f"Yaw rate of {u.name} (unit {i + 1}), nose-right "
              "positive", ("state", f"r{i + 1}"))
    for k in range(n - 1):
        t.add(f"theta{k + 1}", "output", "continuous", "angle", None, f"Articulation angle at joint {k + 1} "
              f"({vehicle.units[k].name} - {vehicle.units[k + 1].name}, heading of the unit ahead minus the unit "
              "behind)", ("state", f"theta{joint_letter(k)}"))
    for i, u in enumerate(vehicle.units):
        t.add(f"ay{i + 1}", "output", "continuous", "accel", None, f"Lateral acceleration of the CG of {u.name} "
              f"(unit {i + 1}), a = v' + u r, at the current state and inputs", ("ay", i + 1))
    for k in range(2, n + 1):
        t.add(f"y{k}", "output", "continuous", "length", None, f"Lateral offset of the rear end of "
              f"{vehicle.units[k - 1].name} (unit {k}) from the axis of {vehicle.units[0].name}", ("y", k))
    _tail_outputs(t, vehicle.units[-1].name)
    for i, u in enumerate(vehicle.units):            # after the others: their value references stay as they were
        for a in u.axles:
            t.add(f"Y_{a.name}", "output", "continuous", "length", None, f"Global lateral position of the centre of "
                  f"axle {a.name} of {u.name} (unit {i + 1}) from the start, +y (first order; HSTO is the rearmost "
                  "axle's overshoot in a lane change)", ("Y_axle", a.name))
    if model == "yaw_roll":
        for i, u in enumerate(vehicle.units):
            t.add(f"p{i + 1}", "output", "continuous", "rate", None, f"Roll rate of the sprung mass of {u.name} "
                  f"(unit {i + 1}), right side down positive", ("state", f"p{i + 1}"))
        for i, u in enumerate(vehicle.units):
            t.add(f"phi{i + 1}", "output", "continuous", "angle", None, f"Roll angle of the sprung mass of {u.name} "
                  f"(unit {i + 1}), right side down positive", ("state", f"phi{i + 1}"))
        for i, u in enumerate(vehicle.units):
            t.add(f"as{i + 1}", "output", "continuous", "accel", None, f"Lateral acceleration of the sprung mass's "
                  f"CG of {u.name} (unit {i + 1}), a_i + e_i p_i', at the current state and inputs", ("extra", f"as{i + 1}"))
        for i, u in enumerate(vehicle.units):
            for a in u.axles:
                t.add(f"dFz_{a.name}", "output", "continuous", "force", None, f"Load transfer of axle {a.name} of "
                      f"{u.name} (unit {i + 1}): (F_z,right - F_z,left)/2, at the current state and inputs",
                      ("extra", f"dFz_{a.name}"))
        for g, group in enumerate(co.roll.groups):
            t.add(f"ltr{g + 1}", "output", "continuous", "factor", None, f"Load transfer ratio of roll-coupled group "
                  f"{g + 1} ({', '.join(vehicle.units[i].name for i in group)}): sum dF_z / sum F_z0 over its axles, "
                  "at the current state and inputs", ("extra", f"ltr{g + 1}"))
    kind = "yaw-roll" if model == "yaw_roll" else "yaw-plane"
    desc = (f"Linear {kind} model of {vehicle.name} ({n} units: {', '.join(vehicle.unit_names)}) with residual "
            "tire forces (conicity, ply steer). Exact zero-order-hold stepping for any communication step size."
            + (f" {vehicle.description}" if vehicle.description else ""))
    return Interface(fmu_base_name(vehicle.name, model), tuple(t.vars), (vehicle,), False, desc, model)


def nonlinear_interface(vehicle: Vehicle, u_start_mps: float = U_START) -> Interface:
    """The interface of a vehicle's nonlinear-model FMU (``lcv fmu --model nonlinear``,
    docs/fmu.md#the-nonlinear-model): the linear FMUs' parameters and the friction coefficient,
    their inputs, and section 18's signals as outputs -- every CG's position, heading, lateral
    velocity, yaw rate and lateral acceleration, the articulation angles, every axle's tire
    forces, friction demand and lateral position, the rear end's.

    Raises
    ------
    lcvreport.model.vehicle.VehicleError
        An axle without ``static_load_N`` (the model needs the axle loads).

    Examples
    --------
    >>> from lcvreport.model.vehicle_file import load_vehicle
    >>> itf = nonlinear_interface(load_vehicle("examples/vehicles/b_double.toml"))
    >>> itf.model_name, [v.name for v in itf.parameters]
    ('b_double_nonlinear', ['tire_scale', 'u_min', 'crossfall', 'friction_coefficient'])
    """
    from ..model.nonlinear.model import nonlinear_model
    RANGES["speed"].check(u_start_mps, "start speed")
    nonlinear_model(vehicle)                          # the axle loads checked: one line naming the axle
    t = _Table("si")
    _parameters(t)
    t.add("friction_coefficient", "parameter", "fixed", "factor", 0.8,
          f"Tire-road friction coefficient mu of every tire (the brush tire's), in {RANGES['friction'].text()}",
          ("parameter", "friction_coefficient"), range_key="friction")
    steered = vehicle.steered_axles
    steer_text = ("axles " + ", ".join(a.name for a in steered)) if steered else "no axle (none is steered)"
    _speed_and_steer(t, steer_text, float(u_start_mps))
    for kind, what, quantity, rng in (("P", "Residual lateral force (conicity, ply steer)", "force", "residual_force"),
                                      ("T", "Residual aligning moment, about +z (down)", "moment", "residual_moment"),
                                      ("eps", "Misalignment (thrust angle), nose-right positive", "angle",
                                       "misalignment")):
        for i, u in enumerate(vehicle.units):
            for a in u.axles:
                t.add(f"{kind}_{a.name}", "input", "continuous", quantity, 0.0,
                      f"{what} of axle {a.name} of {u.name} (unit {i + 1})", (kind, a.name), range_key=rng)
    units = list(enumerate(vehicle.units))
    for sym, quantity, text in (("X", "length", "Ground position of the CG of {u} along the start heading"),
                                ("Y", "length", "Ground position of the CG of {u} to the right of the start heading"),
                                ("psi", "angle", "Heading of {u} from the start heading, nose-right positive"),
                                ("v", "speed", "Lateral velocity of the CG of {u} in its own axes, +y"),
                                ("r", "rate", "Yaw rate of {u}, nose-right positive")):
        for i, u in units:
            t.add(f"{sym}{i + 1}", "output", "continuous", quantity, None, text.format(u=f"{u.name} (unit {i + 1})"),
                  ("pose", f"{sym}{i + 1}"))
    for k in range(vehicle.n_units - 1):
        t.add(f"theta{k + 1}", "output", "continuous", "angle", None, f"Articulation angle at joint {k + 1} "
              f"({vehicle.units[k].name} - {vehicle.units[k + 1].name}, heading of the unit ahead minus the unit "
              "behind, any angle)", ("pose", f"theta{vehicle.joint_letters[k]}"))
    for i, u in units:
        t.add(f"ay{i + 1}", "output", "continuous", "accel", None, f"Lateral acceleration of the CG of {u.name} "
              f"(unit {i + 1}) in its own axes, at the current state and inputs", ("ay", f"ay{i + 1}"))
    for sym, quantity, text in (("Fx", "force", "Longitudinal tire force of axle {a} (all its tires, wheel axes): the "
                                                "drive force that holds the speed on a driven axle, 0 elsewhere"),
                                ("Fy", "force", "Lateral tire force of axle {a} (all its tires, wheel axes), +y"),
                                ("fd", "factor", "Friction demand of axle {a}: sqrt(Fx^2 + Fy^2) / (mu Fz0), "
                                                 "1 = saturated")):
        for i, u in units:
            for a in u.axles:
                t.add(f"{sym}_{a.name}", "output", "continuous", quantity, None,
                      text.format(a=f"{a.name} of {u.name} (unit {i + 1})") + ", at the current state and inputs",
                      ("extra", f"{sym}_{a.name}"))
    for i, u in units:
        for a in u.axles:
            t.add(f"Y_{a.name}", "output", "continuous", "length", None, f"Ground lateral position of the centre of "
                  f"axle {a.name} of {u.name} (unit {i + 1}), +y", ("pose", f"Y_{a.name}"))
    t.add("Y_rear", "output", "continuous", "length", None, f"Ground lateral position of the rear end of "
          f"{vehicle.units[-1].name}, +y", ("pose", "Y_rear"))
    n = vehicle.n_units
    desc = (f"Nonlinear planar model of {vehicle.name} ({n} units: {', '.join(vehicle.unit_names)}): any articulation "
            "angle, brush tires saturating at the friction coefficient, unit 1's speed held by its driven axles; "
            "each communication step integrated (Radau, rtol 1e-8) with the inputs held."
            + (f" {vehicle.description}" if vehicle.description else ""))
    return Interface(fmu_base_name(vehicle.name, "nonlinear"), tuple(t.vars), (vehicle,), False, desc, "nonlinear")
