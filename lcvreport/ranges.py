"""Physical ranges: the one table of valid values for every parameter and input.

A linear yaw-plane model of a truck has no business at 1e20 m/s, a tire scale of
1e300 or a step of 1e-320 s: outside these ranges the numbers stop meaning anything
(or stop being finite), so every boundary refuses them with a message that names
the variable, the value and the range.  The command line, both FMUs (the C FMU
through constants generated from this table), the notebooks and the vehicle-file
schema read this table and nothing else.

=====================  =============  ==================  ==============================
key                    unit           valid               why
=====================  =============  ==================  ==============================
speed                  m/s            [0.1, 70]           0.36-252 km/h: a road vehicle;
                                                          the critical-speed search
                                                          stops at 200 km/h
u_min                  m/s            [0.1, 30]           lowest speed the FMUs run at
tire_scale             1              [0.01, 100]         chapter V used 0.1-1.4
step_size              s              [1e-9, 3600]        one FMU communication step
t_end                  s              (0, 86400]          one simulated day at most
output_step            s              [1e-6, 3600]        the CLI's --dt
output_rows            1              [1, 1e7]            rows of one ``lcv simulate``
steer_angle            rad            [-1, 1]             +-57 deg: far beyond small angles
residual_force         N              [-1e6, 1e6]         P per axle (1 % rule: ~1e3 N)
residual_moment        N*m            [-1e6, 1e6]         T per axle
frequency              Hz             [0.01, 10]          RA and gain frequency
pulse_duration         s              [0.01, 10]          a half-sine steer pulse
lateral_acceleration   m/s^2          [-20, 20]           a lane change's A0 (2 g)
misalignment           rad            [-0.05, 0.05]       thrust angle of an axle (2.9 deg;
                                                          real ones are below 0.5 deg)
crossfall              %              [-20, 20]           road crossfall (crown ~2 %)
lane_change_ay         g              (0, 2]              a measure's lane change A0
steady_turn_radius     m              [20, 10000]         the HSSO turn (393 m by default)
driver_gain            rad/m          (0, 1]              the preview driver's gain
driver_preview         s              [0, 5]              its look-ahead time
=====================  =============  ==================  ==============================

The vehicle-file limits (:data:`VEHICLE`) are as generous: they exist so that a
typo (a mass in grams, a stiffness with three extra zeros) is named instead of
producing matrices whose products overflow.

Examples
--------
>>> RANGES["speed"].check(22.352)
22.352
>>> RANGES["tire_scale"].check(1e300)
Traceback (most recent call last):
...
lcvreport.ranges.RangeError: tire_scale must be in [0.01, 100], got 1e+300
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from numbers import Real


def _num(x: float) -> str:
    """A limit as people write it: 86400, 0.01, 1e-06, 156.6."""
    if x == 0 or 1e-3 <= abs(x) < 1e6:
        return f"{x:.4g}" if abs(x) < 100 or x != round(x) else f"{x:.0f}"
    return f"{x:.4g}"


class RangeError(ValueError):
    """A value outside its valid range (or not a finite number).

    Attributes
    ----------
    variable : str
        The name of the parameter or input, as the user wrote it.
    """

    def __init__(self, variable: str, message: str):
        super().__init__(message)
        self.variable = variable


@dataclass(frozen=True)
class Range:
    """A closed (or left-open) interval of valid values of one quantity.

    Attributes
    ----------
    name : str
        The name used in messages.
    unit : str
        The SI unit of ``low`` and ``high`` (``"1"`` for dimensionless).
    low, high : float
        Limits, SI.
    low_open : bool
        True when ``low`` itself is not valid.
    description : str
        What the quantity is.
    """

    name: str
    unit: str
    low: float
    high: float
    low_open: bool = False
    description: str = ""

    def contains(self, value: float) -> bool:
        """True when ``value`` is a finite number in the range."""
        if not math.isfinite(value):
            return False
        above = value > self.low if self.low_open else value >= self.low
        return above and value <= self.high

    def text(self, factor: float = 1.0, unit: str | None = None) -> str:
        """The range as text, e.g. ``"[0.1, 70] m/s"``; ``factor`` converts to a display unit."""
        unit = self.unit if unit is None else unit
        lo, hi = self.low * factor, self.high * factor
        left = "(" if self.low_open else "["
        suffix = "" if unit in ("", "1") else f" {unit}"
        return f"{left}{_num(lo)}, {_num(hi)}]{suffix}"

    def check(self, value, name: str | None = None, factor: float = 1.0, unit: str | None = None) -> float:
        """Return ``value`` as a float if it is a finite number in range, else raise :class:`RangeError`.

        Parameters
        ----------
        value
            The value in the display unit (SI when ``factor`` is 1).
        name : str, optional
            Name for the message (default: the range's name).
        factor : float
            Display units per SI unit (e.g. 3.6 for a speed in km/h).
        unit : str, optional
            Display unit for the message.
        """
        name = name or self.name
        if isinstance(value, bool) or not isinstance(value, Real):
            raise RangeError(name, f"{name} must be a number in {self.text(factor, unit)}, got {value!r}")
        v = float(value)
        if not (math.isfinite(v) and self.contains(v / factor)):
            raise RangeError(name, f"{name} must be in {self.text(factor, unit)}, got {given(v)}")
        return v


#: the table: every parameter and input of the CLI, the FMUs and the notebooks
RANGES: dict[str, Range] = dict([
    ("speed", Range("speed", "m/s", 0.1, 70.0, description="forward speed u of every unit")),
    ("u_min", Range("u_min", "m/s", 0.1, 30.0, description="lowest speed the FMU runs at; lower u is clamped")),
    ("tire_scale", Range("tire_scale", "1", 0.01, 100.0, description="factor on every tire coefficient")),
    ("step_size", Range("communication step size", "s", 1e-9, 3600.0, description="FMU communication step")),
    ("t_end", Range("t_end", "s", 0.0, 86400.0, low_open=True, description="end time of a simulation")),
    ("output_step", Range("dt", "s", 1e-6, 3600.0, description="output step of a simulation")),
    ("output_rows", Range("rows", "1", 1.0, 1e7, description="output rows of one simulation")),
    ("steer_angle", Range("delta", "rad", -1.0, 1.0, description="steer angle of the steered axles")),
    ("residual_force", Range("P", "N", -1e6, 1e6, description="residual lateral force of one axle")),
    ("residual_moment", Range("T", "N*m", -1e6, 1e6, description="residual aligning moment of one axle")),
    ("frequency", Range("frequency", "Hz", 0.01, 10.0, description="steer frequency of RA and gains")),
    ("pulse_duration", Range("pulse duration", "s", 0.01, 10.0, description="duration of a half-sine steer pulse")),
    ("lateral_acceleration", Range("lateral acceleration", "m/s^2", -20.0, 20.0,
                                   description="prescribed lateral acceleration of a lane change (2 g)")),
    ("misalignment", Range("misalignment", "rad", -0.05, 0.05,
                           description="axle misalignment (thrust angle), nose-right positive (2.9 deg)")),
    ("crossfall", Range("crossfall", "%", -20.0, 20.0, description="road crossfall, positive falling toward +y")),
    ("lane_change_ay", Range("lane change A0", "g", 0.0, 2.0, low_open=True,
                             description="amplitude of the steered axle's lateral acceleration in a lane change")),
    ("driver_gain", Range("driver gain", "rad/m", 0.0, 1.0, low_open=True,
                          description="the preview driver's steer per metre of lateral error")),
    ("driver_preview", Range("driver preview", "s", 0.0, 5.0,
                             description="the preview driver's look-ahead time")),
    ("steady_turn_radius", Range("steady turn radius", "m", 20.0, 10000.0,
                                 description="radius of the high-speed steady turn (u/R the tractor's yaw rate)")),
    ("turn_radius", Range("turn radius", "m", 2.0, 100.0,
                          description="radius of the outside steer wheel's path in the low-speed turn")),
    ("turn_angle", Range("turn angle", "deg", 0.0, 3600.0, low_open=True,
                         description="angle of the low-speed turn (ten laps at most)")),
    ("payload", Range("payload", "kg", 0.0, 1e5, description="a payload added to one unit in a study")),
    ("friction", Range("friction coefficient", "1", 0.0, 2.0, low_open=True,
                       description="tire-road friction coefficient mu of the nonlinear model")),
    ("path_gain", Range("path gain", "rad/m", 0.0, 20.0, low_open=True,
                        description="steer per metre of path error in the nonlinear model's low-speed turn")),
    ("turn_speed", Range("turn speed", "km/h", 0.0, 30.0, low_open=True,
                         description="unit 1's speed in the nonlinear model's low-speed turn")),
])

#: vehicle-file limits (SI, per tire where the file is per tire)
VEHICLE: dict[str, Range] = {
    "mass_kg": Range("mass_kg", "kg", 0.0, 1e6, low_open=True, description="unit mass"),
    "yaw_inertia_kg_m2": Range("yaw_inertia_kg_m2", "kg*m^2", 0.0, 1e8, low_open=True,
                               description="yaw moment of inertia about the CG"),
    "position_m": Range("position", "m", -50.0, 50.0, description="signed x of a coupling, axle or rear end"),
    "tires": Range("tires", "1", 1.0, 64.0, description="tires on one axle"),
    "cornering_stiffness_N_per_rad": Range("cornering_stiffness_N_per_rad", "N/rad", 0.0, 1e7, low_open=True,
                                           description="C_F per tire"),
    "aligning_stiffness_Nm_per_rad": Range("aligning_stiffness_Nm_per_rad", "N*m/rad", 0.0, 1e6,
                                           description="C_M per tire"),
    "longitudinal_stiffness_N": Range("longitudinal_stiffness_N", "N", 0.0, 1e7, description="C_S per tire"),
    "dual_spacing_m": Range("dual_spacing_m", "m", 0.0, 2.0, description="D of a dual set"),
    "static_load_N": Range("static_load_N", "N", 0.0, 1e7, description="static vertical axle load"),
    "body_width_m": Range("body_width_m", "m", 0.0, 5.0, low_open=True, description="width of a unit's body"),
    "track_width_m": Range("track_width_m", "m", 0.0, 4.0, low_open=True,
                           description="centre of the outermost tire to centre of the other"),
    # roll (docs/roll.md): only the yaw-roll model and the rollover threshold read them
    "cg_height_m": Range("cg_height_m", "m", 0.0, 5.0, low_open=True,
                         description="sprung-mass CG above ground"),
    "roll_axis_height_m": Range("roll_axis_height_m", "m", 0.0, 5.0,
                                description="roll axis above ground, below the CG"),
    "roll_inertia_kg_m2": Range("roll_inertia_kg_m2", "kg*m^2", 0.0, 1e8, low_open=True,
                                description="roll inertia of the sprung mass about its CG"),
    "yaw_roll_product_kg_m2": Range("yaw_roll_product_kg_m2", "kg*m^2", -1e8, 1e8,
                                    description="product of inertia I_xz of the sprung mass (x forward, z down)"),
    "rear_coupling_height_m": Range("rear_coupling_height_m", "m", 0.0, 5.0, low_open=True,
                                    description="rear coupling above ground"),
    "rear_coupling_roll_stiffness_Nm_per_rad": Range("rear_coupling_roll_stiffness_Nm_per_rad", "N*m/rad", 0.0,
                                                     1e10, description="roll stiffness of a coupling (0: roll-free)"),
    "roll_stiffness_Nm_per_rad": Range("roll_stiffness_Nm_per_rad", "N*m/rad", 0.0, 1e10,
                                       description="roll stiffness of an axle's suspension"),
    "roll_damping_Nms_per_rad": Range("roll_damping_Nms_per_rad", "N*m*s/rad", 0.0, 1e9,
                                      description="roll damping of an axle's suspension"),
    "unsprung_mass_kg": Range("unsprung_mass_kg", "kg", 0.0, 1e5, description="unsprung mass of an axle"),
    "units": Range("units", "1", 1.0, 50.0, description="units in one vehicle (a road train has a few dozen at most)"),
}


#: the smallest radius of gyration sqrt(I/m) of a unit, as a fraction of the reach of its axles and
#: couplings from its CG (a real body's is 0.05-2 of its length).  Below it the model's fast yaw
#: mode is (reach/k)^2 > 10^6 times its slow modes and the eigenvalues lose digits: at 10^-3 they
#: are still right to 4e-11 (mpmath), at 10^-9 a stable truck reads unstable.  A unit below it
#: is refused (an inertia in the wrong unit), not computed.
GYRATION_PER_REACH_MIN = 1e-3


def given(value: float) -> str:
    """A refused number as the message prints it: as given, to every digit that tells it from the
    limit (20.000001 is not "20"), compact when it is long.

    Examples
    --------
    >>> given(20.000001), given(1e300), given(250.0), given(-0.0501)
    ('20.000001', '1e+300', '250', '-0.0501')
    """
    text = repr(float(value))
    return text[:-2] if text.endswith(".0") else text


def check(key: str, value, name: str | None = None, factor: float = 1.0, unit: str | None = None) -> float:
    """Check ``value`` against ``RANGES[key]``; see :meth:`Range.check`."""
    return RANGES[key].check(value, name, factor, unit)


def check_array(key: str, values, name: str | None = None):
    """Check every element of an array-like against ``RANGES[key]``; return a float array."""
    import numpy as np
    arr = np.asarray(values, dtype=float)
    r = RANGES[key]
    flat = arr.ravel()
    ok = np.isfinite(flat) & (flat <= r.high) & ((flat > r.low) if r.low_open else (flat >= r.low))
    if not np.all(ok):
        bad = flat[~ok][0]
        name = name or r.name
        raise RangeError(name, f"{name} must be in {r.text()}, got {given(bad)}")
    return arr


def markdown_table() -> str:
    """Both tables (:data:`RANGES`, :data:`VEHICLE`) as Markdown, as the README shows them.

    Examples
    --------
    >>> markdown_table().splitlines()[2]
    '| `speed` | [0.1, 70] m/s | forward speed u of every unit |'
    """
    rows = ["| quantity | valid (SI) | what |", "|---|---|---|"]
    for key, r in list(RANGES.items()) + list(VEHICLE.items()):
        rows.append(f"| `{key}` | {r.text()} | {r.description} |")
    return "\n".join(rows)
