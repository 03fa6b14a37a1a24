"""Every measure once: its key, label, unit, definition, where it is defined, the model it is
computed on, the kind of limit a standard puts on it, and the functions that compute it --
for one vehicle and over a batch of variants.

``lcv measures`` (text, CSV, JSON), ``--criteria``, studies, the report tables and
:func:`~lcvreport.measures.measure_set.measure_set` read these tables; criteria files and
studies accept exactly their keys (one spelling each: the JSON's, with a dot for a nested key
such as ``trim.offtracking_m``).

Measures computed together (one manoeuvre, one analysis) form a **family**
(:data:`FAMILIES`): its ``scalar`` function maps a :class:`MeasureCase` to the values of its
keys and the reason of every null; its ``batched`` function gives the family's scalar keys
over the variants of a :class:`~lcvreport.analysis.batch.VariantBatch`, one array per key, in
order (keyword arguments taken from the case by name: ``speed_mps``, ``tire_scale``,
``f_hz``, ``F``).  Adding a measure is its function, one entry here and its test; a
measure of another model (``model="yaw_roll"``) registers the same way.

=============================  ==========  ==========================================
field of :class:`Measure`      example     what
=============================  ==========  ==========================================
``key``                        ``hsso_m``  the key of ``lcv measures --json`` (and criteria, studies)
``label``                                  the row label of the text and report tables
``unit``                       ``m``       SI unit (``-``: dimensionless)
``definition``                             one line: what it is
``doc``                                    the section of ``docs/measures.md`` that defines it
``family``                     steady_turn the family that computes it (None: a condition)
``limit``                      ``max``     the kind of limit a standard sets (None: none)
``shape``                      scalar      ``scalar`` or ``per_unit`` (a list, front to rear)
=============================  ==========  ==========================================

Examples
--------
>>> MEASURES["hsso_m"].unit, MEASURES["hsso_m"].limit, MEASURES["hsso_m"].model
('m', 'max', 'yaw_plane')
>>> "trim.offtracking_m" in CRITERIA_KEYS, "speed_mps" in CRITERIA_KEYS
(True, False)
>>> FAMILIES["steady_turn"].keys
('hsso_m', 'steady_turn_delta_rad')
"""
from __future__ import annotations

import importlib
import inspect
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:                                # annotations only: the registry imports no model
    from ..model.vehicle import Vehicle

#: why a measure that needs a steer input is null on a vehicle without a steered axle
NO_STEER = "undefined: the vehicle has no steered axle, so no steer input to respond to or trim with"


@dataclass
class MeasureCase:
    """What the families are computed from: ``vehicle``, ``speed_mps`` [m/s], ``tire_scale``
    [-], the frequency of the RA measures ``f_hz`` [Hz], ``F`` the generalized force of the
    residual sources [SI] (None: no source was given; over a batch, one row per variant, NaN
    rows: none), and ``shared`` results one family hands to another (the least damping ratio
    the yaw damping coefficient compares with, the trim's full state)."""

    vehicle: "Vehicle"
    speed_mps: float
    tire_scale: float
    f_hz: float
    F: Any = None
    shared: dict = field(default_factory=dict)


def _resolve(ref: str):
    module, _, name = ref.partition(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), name)


@dataclass(frozen=True)
class Family:
    """Measures computed together: ``scalar`` and ``batched`` are ``"module:function"`` of
    :mod:`lcvreport.measures` (loaded on first use, so reading the registry loads no model);
    ``needs`` is what the vehicle or the call must have: ``steer`` (a steered axle),
    ``sources`` (a residual source), ``geometry`` (the body keys the turn checks itself)."""

    name: str
    scalar: str
    batched: str | None = None
    model: str = "yaw_plane"
    needs: str = ""

    @property
    def keys(self) -> tuple[str, ...]:
        """The family's measures, in the registry's order."""
        return tuple(k for k, m in MEASURES.items() if m.family == self.name)

    @property
    def batched_keys(self) -> tuple[str, ...]:
        """The keys the batched function gives (the scalar ones), in order."""
        return tuple(k for k in self.keys if MEASURES[k].shape == "scalar") if self.batched else ()

    def applies(self, case: MeasureCase) -> bool:
        """Whether the family is computed at all (a trim only with a residual source)."""
        return self.needs != "sources" or case.F is not None

    def compute(self, case: MeasureCase) -> tuple[dict, dict]:
        """({key: value or None}, {key: why it is null}) of one vehicle."""
        if self.needs in ("steer", "sources") and not case.vehicle.steered_axles:
            if self.needs == "sources":
                return {k: None for k in self.keys}, {"trim": NO_STEER}
            return {k: None for k in self.keys}, {k: NO_STEER for k in self.keys}
        return _resolve(self.scalar)(case)

    def compute_batched(self, batch, case: MeasureCase) -> tuple:
        """One array (B,) per key of :attr:`batched_keys`, NaN where undefined."""
        fn = _resolve(self.batched)
        names = inspect.signature(fn).parameters
        kwargs = {k: getattr(case, k) for k in ("speed_mps", "tire_scale", "f_hz", "F") if k in names}
        out = fn(batch, **kwargs)
        return out if isinstance(out, tuple) else (out,)


@dataclass(frozen=True)
class Measure:
    """One measure (see the module docstring for the fields)."""

    key: str
    label: str
    unit: str
    definition: str
    doc: str
    family: str | None = None
    limit: str | None = None
    shape: str = "scalar"

    @property
    def model(self) -> str:
        """The model it is computed on (its family's)."""
        return FAMILIES[self.family].model if self.family else "yaw_plane"

    @property
    def needs(self) -> str:
        return FAMILIES[self.family].needs if self.family else ""

    @property
    def batched(self) -> str | None:
        """The batched family that gives it over variants, or None."""
        return self.family if self.family and self.key in FAMILIES[self.family].batched_keys else None

    @property
    def doc_url(self) -> str:
        """Where a reader of the repository finds the definition."""
        return f"docs/measures.md#{self.doc}"


#: the families, in the order measure_set computes them
FAMILIES: dict[str, Family] = {f.name: f for f in (
    Family("least_damping", "stability:least_damping_family", "stability:least_damping_batched"),
    Family("critical_speed", "stability:critical_speed_family", "stability:critical_speed_batched"),
    Family("frequency_response", "amplification:frequency_response_family", "amplification:ra_frequency_batched",
           needs="steer"),
    Family("single_sine", "amplification:single_sine_family", "amplification:single_sine_batched", needs="steer"),
    Family("ra_peak", "amplification:ra_peak_family", "amplification:ra_peak_batched", needs="steer"),
    Family("yaw_damping", "yaw_damping:yaw_damping_family", "yaw_damping:yaw_damping_family_batched", needs="steer"),
    Family("lane_change", "offtracking:lane_change_family", "offtracking:lane_change_batched", needs="steer"),
    Family("steady_turn", "offtracking:steady_turn_family", "offtracking:steady_turn_batched", needs="steer"),
    Family("low_speed_turn", "low_speed:low_speed_family", None, model="low_speed", needs="geometry"),
    Family("trim", "offtracking:trim_family", "offtracking:trim_batched", needs="sources"),
)}


def _m(key, label, unit, definition, doc, **kw) -> Measure:
    return Measure(key, label, unit, definition, doc, **kw)


#: the measures, in the order of ``lcv measures --json``
MEASURES: dict[str, Measure] = {m.key: m for m in (
    _m("speed_mps", "speed", "m/s", "the forward speed of every unit", "conditions"),
    _m("least_damping_ratio", "least damping ratio", "-", "min −Re λ/|λ| over the oscillatory modes",
       "least-damping-ratio", family="least_damping", limit="min"),
    _m("least_damped_frequency_hz", "least damped frequency", "Hz", "Im λ/2π of that mode", "least-damping-ratio",
       family="least_damping"),
    _m("critical_speed_kph", "critical speed", "km/h", "lowest unstable speed up to 200 km/h (none: stable)",
       "critical-speed", family="critical_speed", limit="min"),
    _m("ra_frequency", "rearward amplification, 0.4 Hz", "-", "|G_N| / |G_1| at 0.4 Hz, frequency domain",
       "rearward-amplification", family="frequency_response", limit="max"),
    _m("ra_single_sine", "rearward amplification, single sine", "-", "max|a_N| / max|a_1|, 0.4 Hz single sine",
       "rearward-amplification", family="single_sine", limit="max"),
    _m("ay_gain_per_unit", "lateral acceleration gain", "m/s²/rad", "|G_i(j2π·0.4 Hz)| of every unit",
       "rearward-amplification", family="frequency_response", shape="per_unit"),
    _m("ra_peak", "rearward amplification, peak", "-", "max RA(f) over 0.1-2 Hz", "rearward-amplification",
       family="ra_peak", limit="max"),
    _m("ra_peak_frequency_hz", "frequency of the RA peak", "Hz", "where RA(f) is largest", "rearward-amplification",
       family="ra_peak"),
    _m("yaw_damping_coefficient", "yaw damping coefficient", "-",
       "ratio method on the free decay after pulse 0.01 rad 0.5 s, 40 s", "yaw-damping-coefficient",
       family="yaw_damping", limit="min"),
    _m("yaw_damping_lower_bound", "yaw damping coefficient, lower bound", "-",
       "0.6901 when every joint is heavily damped (YDC null), else none", "yaw-damping-coefficient",
       family="yaw_damping"),
    _m("hsto_m", "high-speed transient offtracking", "m", "lane change 0.15 g 0.4 Hz, rear axle overshoot",
       "high-speed-transient-offtracking", family="lane_change", limit="max"),
    _m("ra_lane_change", "rearward amplification, lane change", "-", "max|a_N| / max|a_s| in that lane change",
       "high-speed-transient-offtracking", family="lane_change", limit="max"),
    _m("hsso_m", "high-speed steady-state offtracking", "m",
       "393 m turn: rear axle path radius − steered axle path radius", "high-speed-steady-state-offtracking",
       family="steady_turn", limit="max"),
    _m("steady_turn_delta_rad", "steer angle of the 393 m turn", "rad", "the steady turn of HSSO",
       "high-speed-steady-state-offtracking", family="steady_turn"),
    _m("lssp_m", "low-speed swept path (swept width)", "m", "90° turn, outside steer wheel on R 12.5 m",
       "low-speed-turn", family="low_speed_turn", limit="max"),
    _m("low_speed_offtracking_m", "low-speed offtracking", "m", "steered axle path radius − last rear axle radius",
       "low-speed-turn", family="low_speed_turn", limit="max"),
    _m("max_tail_swing_m", "tail swing, largest", "m", "rear outer corner beyond its approach line",
       "low-speed-turn", family="low_speed_turn", limit="max"),
    _m("frontal_swing_m", "frontal swing", "m", "front outer corner outside the outside steer wheel's path",
       "low-speed-turn", family="low_speed_turn", limit="max"),
    _m("trim.delta_rad", "trim steer angle", "rad", "the steer holding the tractor straight against the sources",
       "trimmed-straight-running", family="trim"),
    _m("trim.offtracking_m", "trimmed offtracking", "m", "rearmost axle path − steered axle path, +y",
       "trimmed-straight-running", family="trim", limit="max"),
)}

#: the keys a criteria file or a study may name: every scalar measure (not the speed, a condition)
CRITERIA_KEYS = tuple(k for k, m in MEASURES.items() if m.shape == "scalar" and m.family is not None)
#: the batched families and the keys each gives, in order (studies compute these over cases)
BATCHED = {name: f.batched_keys for name, f in FAMILIES.items() if f.batched}
#: spellings of other versions and names that are not measures: the key to use instead
ALIASES = {"trim_delta_rad": "trim.delta_rad", "trim_offtracking_m": "trim.offtracking_m",
           "tail_swing_m": "max_tail_swing_m"}


def unknown_key_message(key: str, valid=CRITERIA_KEYS) -> str:
    """The one line for a key that is not a measure: the key to use, if it is a known misspelling."""
    hint = ALIASES.get(key)
    if hint is not None:
        return f"{key!r} is not a measure key; the key is {hint!r}"
    return f"unknown measure {key!r}; valid: {', '.join(valid)}"


def unit_of(key: str, default: str = "1") -> str:
    """The SI unit of a measure or condition column (``default`` for a factor, a scale)."""
    if key in MEASURES:
        return MEASURES[key].unit
    return {"speed_kph": "km/h", "speed_mps": "m/s"}.get(key, default)
