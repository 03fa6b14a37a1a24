"""Every measure once: its key, label, unit, definition, where it is defined, the model it is
computed on, the kind of limit a standard puts on it, and how it is computed over variants.

``lcv measures`` (text, CSV, JSON), ``--criteria``, studies, the report tables and
:class:`~lcvreport.measures.measure_set.MeasureSet` read this table; criteria files and studies
accept exactly its keys (one spelling each: the JSON's, with a dot for a nested key such as
``trim.offtracking_m``).  Adding a measure is its function, one entry here and its test.

=============================  ==========  ==========================================
field                          example     what
=============================  ==========  ==========================================
``key``                        ``hsso_m``  the key of ``lcv measures --json`` (and criteria, studies)
``label``                                  the row label of the text and report tables
``unit``                       ``m``       SI unit (``-``: dimensionless)
``definition``                             one line: what it is
``doc``                                    the section of ``docs/measures.md`` that defines it
``model``                      yaw_plane   the model it is computed on
``limit``                      ``max``     the kind of limit a standard sets (None: none)
``shape``                      scalar      ``scalar`` or ``per_unit`` (a list, front to rear)
``batched``                    steady_turn the VariantBatch method that gives it over variants, or None
``needs``                      steer       what the vehicle or the call must have: steer, sources, geometry
=============================  ==========  ==========================================

Examples
--------
>>> MEASURES["hsso_m"].unit, MEASURES["hsso_m"].limit
('m', 'max')
>>> "trim.offtracking_m" in CRITERIA_KEYS, "speed_mps" in CRITERIA_KEYS
(True, False)
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Measure:
    """One measure (see the module docstring for the fields)."""

    key: str
    label: str
    unit: str
    definition: str
    doc: str
    model: str = "yaw_plane"
    limit: str | None = None
    shape: str = "scalar"
    batched: str | None = None
    needs: str = ""

    @property
    def doc_url(self) -> str:
        """Where a reader of the repository finds the definition."""
        return f"docs/measures.md#{self.doc}"


def _m(key, label, unit, definition, doc, **kw) -> Measure:
    return Measure(key, label, unit, definition, doc, **kw)


#: the measures, in the order of ``lcv measures --json``
MEASURES: dict[str, Measure] = {m.key: m for m in (
    _m("speed_mps", "speed", "m/s", "the forward speed of every unit", "conditions"),
    _m("least_damping_ratio", "least damping ratio", "-", "min −Re λ/|λ| over the oscillatory modes",
       "least-damping-ratio", limit="min", batched="least_damping"),
    _m("least_damped_frequency_hz", "least damped frequency", "Hz", "Im λ/2π of that mode", "least-damping-ratio",
       batched="least_damping"),
    _m("critical_speed_kph", "critical speed", "km/h", "lowest unstable speed up to 200 km/h (none: stable)",
       "critical-speed", limit="min", batched="critical_speed"),
    _m("ra_frequency", "rearward amplification, 0.4 Hz", "-", "|G_N| / |G_1| at 0.4 Hz, frequency domain",
       "rearward-amplification", limit="max", batched="rearward_amplification", needs="steer"),
    _m("ra_single_sine", "rearward amplification, single sine", "-", "max|a_N| / max|a_1|, 0.4 Hz single sine",
       "rearward-amplification", limit="max", batched="single_sine", needs="steer"),
    _m("ay_gain_per_unit", "lateral acceleration gain", "m/s²/rad", "|G_i(j2π·0.4 Hz)| of every unit",
       "rearward-amplification", shape="per_unit", needs="steer"),
    _m("ra_peak", "rearward amplification, peak", "-", "max RA(f) over 0.1-2 Hz", "rearward-amplification",
       limit="max", batched="ra_peak", needs="steer"),
    _m("ra_peak_frequency_hz", "frequency of the RA peak", "Hz", "where RA(f) is largest", "rearward-amplification",
       batched="ra_peak", needs="steer"),
    _m("yaw_damping_coefficient", "yaw damping coefficient", "-",
       "ratio method on the free decay after pulse 0.01 rad 0.5 s, 40 s", "yaw-damping-coefficient", limit="min",
       batched="yaw_damping", needs="steer"),
    _m("yaw_damping_lower_bound", "yaw damping coefficient, lower bound", "-",
       "0.6901 when every joint is heavily damped (YDC null), else none", "yaw-damping-coefficient",
       batched="yaw_damping", needs="steer"),
    _m("hsto_m", "high-speed transient offtracking", "m", "lane change 0.15 g 0.4 Hz, rear axle overshoot",
       "high-speed-transient-offtracking", limit="max", batched="lane_change", needs="steer"),
    _m("ra_lane_change", "rearward amplification, lane change", "-", "max|a_N| / max|a_s| in that lane change",
       "high-speed-transient-offtracking", limit="max", batched="lane_change", needs="steer"),
    _m("hsso_m", "high-speed steady-state offtracking", "m",
       "393 m turn: rear axle path radius − steered axle path radius", "high-speed-steady-state-offtracking",
       limit="max", batched="steady_turn", needs="steer"),
    _m("steady_turn_delta_rad", "steer angle of the 393 m turn", "rad", "the steady turn of HSSO",
       "high-speed-steady-state-offtracking", batched="steady_turn", needs="steer"),
    _m("lssp_m", "low-speed swept path (swept width)", "m", "90° turn, outside steer wheel on R 12.5 m",
       "low-speed-turn", model="low_speed", limit="max", needs="geometry"),
    _m("low_speed_offtracking_m", "low-speed offtracking", "m", "steered axle path radius − last rear axle radius",
       "low-speed-turn", model="low_speed", limit="max", needs="geometry"),
    _m("max_tail_swing_m", "tail swing, largest", "m", "rear outer corner beyond its approach line",
       "low-speed-turn", model="low_speed", limit="max", needs="geometry"),
    _m("frontal_swing_m", "frontal swing", "m", "front outer corner outside the outside steer wheel's path",
       "low-speed-turn", model="low_speed", limit="max", needs="geometry"),
    _m("trim.delta_rad", "trim steer angle", "rad", "the steer holding the tractor straight against the sources",
       "trimmed-straight-running", batched="trim", needs="sources"),
    _m("trim.offtracking_m", "trimmed offtracking", "m", "rearmost axle path − steered axle path, +y",
       "trimmed-straight-running", limit="max", batched="trim", needs="sources"),
)}

#: the keys a criteria file or a study may name: every scalar measure (not the speed, a condition)
CRITERIA_KEYS = tuple(k for k, m in MEASURES.items() if m.shape == "scalar" and k != "speed_mps")
#: the VariantBatch methods and the keys each gives, in order (studies compute these over cases)
BATCHED = {"least_damping": ("least_damping_ratio", "least_damped_frequency_hz"),
           "critical_speed": ("critical_speed_kph",),
           "rearward_amplification": ("ra_frequency",),
           "single_sine": ("ra_single_sine",),
           "ra_peak": ("ra_peak", "ra_peak_frequency_hz"),
           "yaw_damping": ("yaw_damping_coefficient", "yaw_damping_lower_bound"),
           "lane_change": ("hsto_m", "ra_lane_change"),
           "steady_turn": ("hsso_m", "steady_turn_delta_rad"),
           "trim": ("trim.delta_rad", "trim.offtracking_m")}
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
