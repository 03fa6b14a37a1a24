"""The evidence of an assessment: for each measure of a scheme, what it was read from, computed
again at the measure's conditions -- the manoeuvre's time history, the turn's swept path, the
tilt curve -- so that a report can draw it with the limits on it (docs/assessment.md).

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.measures.scheme import loads_scheme
>>> from lcvreport.measures.assess import assess
>>> s = loads_scheme('scheme = "e"\\nlevels = ["L1"]\\n[measures.hsto_m]\\nspeed_kph = 88.0\\nsource = "p"\\n'
...                  'levels = { L1 = { max = 1.0 } }')
>>> a = assess(load_preset("tractor_semitrailer"), s)
>>> e = evidence(a, a.measures[0])
>>> e.kind, round(e.result.hsto_m, 4) == round(a.measures[0].value, 4)
('lane_change', True)
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..units import kph_to_mps
from .registry import CONDITIONS, MEASURES

#: what each family's evidence is
KINDS = {"lane_change": "lane_change", "single_sine": "single_sine", "yaw_damping": "pulse",
         "low_speed_turn": "swept_path", "rollover": "tilt", "straight_path": "straight_path",
         "friction_demand": "friction_demand"}
#: the roll family's measures read from its lane change, and from its single sine
ROLL_LANE_CHANGE = ("ra_lane_change_roll", "hsto_m_roll", "rltr_lane_change")
ROLL_SINGLE_SINE = ("ra_single_sine_roll",)


@dataclass(frozen=True)
class Evidence:
    """What one measure was read from: ``kind`` (``lane_change``, ``single_sine``, ``pulse``,
    ``swept_path``, ``tilt``, ``straight_path``, ``friction_demand`` (the turn with tire forces); ``value`` for a measure drawn as its value
    against the limits), the ``result`` object (None for ``value``), the ``verdict`` and the
    scheme's ``levels``.  ``plot()`` draws it with the limits on it."""

    kind: str
    result: object
    verdict: object
    levels: tuple
    model: str = "yaw_plane"
    #: a ratio measure's (rearward amplification's) signals of its response: (numerator,
    #: denominator), the reference points the measure was computed between
    ratio: tuple = ()

    @property
    def drawing(self) -> str:
        """How it is drawn: the registry's ``evidence`` of the measure (measures.toml), ``value``
        where it names none or where nothing was computed."""
        return "value" if self.kind == "value" else MEASURES[self.verdict.key].evidence

    def plot(self):
        """The evidence with every level's limit drawn (a :class:`matplotlib.figure.Figure`)."""
        from ..plotting.assessment import fig_evidence
        return fig_evidence(self)


def evidence(assessment, verdict) -> Evidence:
    """The evidence of ``verdict`` (one measure of ``assessment``), recomputed at its conditions.

    Parameters
    ----------
    assessment : lcvreport.measures.assess.SchemeAssessment
    verdict : lcvreport.measures.assess.MeasureVerdict
    """
    v, c, s = assessment.vehicle, verdict.conditions, assessment.tire_scale
    key = verdict.key
    family = MEASURES[key].family
    speed = kph_to_mps(c.get("speed_kph", 88.0))
    levels = assessment.scheme.levels
    if verdict.value is None and not (family == "yaw_damping" and verdict.lower_bound is not None):
        return Evidence("value", None, verdict, levels)       # (a heavily damped YDC: its decay is the evidence)
    if MEASURES[key].evidence == "value":                     # the registry names no drawing: its value
        return Evidence("value", None, verdict, levels)
    lane = (c.get("lane_change_ay_g", CONDITIONS["lane_change_ay_g"].default),
            c.get("lane_change_frequency_hz", CONDITIONS["lane_change_frequency_hz"].default))
    f_hz = c.get("ra_frequency_hz", CONDITIONS["ra_frequency_hz"].default)
    n = v.n_units
    axis = getattr(verdict, "model", "yaw_plane")           # the scheme entry's model (the model axis)
    if family == "lane_change" or key in ROLL_LANE_CHANGE:
        from .offtracking import lane_change_measures
        model = "yaw_roll" if key in ROLL_LANE_CHANGE else axis
        return Evidence("lane_change", lane_change_measures(v, speed, s, *lane, model=model), verdict, levels, model,
                        _ratio(key, c, n, (f"ay{n}", "a_steer")))
    if family == "driver_lane_change":
        from .offtracking import driver_lane_change_measures
        K = c.get("driver_gain_rad_per_m", CONDITIONS["driver_gain_rad_per_m"].default)
        T = c.get("driver_preview_s", CONDITIONS["driver_preview_s"].default)
        return Evidence("lane_change", driver_lane_change_measures(v, speed, s, *lane, K, T, model=axis,
                                                                   options=_options(axis, c)),
                        verdict, levels, axis, _ratio(key, c, n, (f"ay{n}", "a_steer"), axis))
    if family == "single_sine" or key in ROLL_SINGLE_SINE:
        from .amplification import single_sine
        model = "yaw_roll" if key in ROLL_SINGLE_SINE else axis
        plain = (f"r{n}", "r1") if key == "ra_yaw_rate_single_sine" else (f"ay{n}", "ay1")
        return Evidence("single_sine", single_sine(v, speed, f_hz, tire_scale=s, model=model,
                                                   options=_options(model, c)), verdict, levels, model,
                        _ratio(key, c, n, plain))
    if family == "yaw_damping":
        from .yaw_damping import yaw_damping_coefficient
        return Evidence("pulse", yaw_damping_coefficient(v, speed, s, axis, _options(axis, c)), verdict, levels, axis)
    if family == "low_speed_turn":
        from .low_speed import low_speed_turn
        return Evidence("swept_path", low_speed_turn(v, c["turn_radius_m"], c["turn_angle_deg"]), verdict, levels)
    if family == "friction_demand":
        from .friction_demand import turn_with_tire_forces
        turn = turn_with_tire_forces(v, *(c.get(k, CONDITIONS[k].default) for k in (
            "turn_radius_m", "turn_angle_deg", "turn_speed_kph", "friction_coefficient", "path_gain_rad_per_m")),
            tire_scale=s)
        return Evidence("friction_demand", turn, verdict, levels, "nonlinear")
    if family == "rollover":
        from .rollover import rollover_threshold
        return Evidence("tilt", rollover_threshold(v), verdict, levels, "yaw_roll")
    if family == "straight_path":
        from ..model.yaw_plane.loads import ResidualSources
        from .measure_set import residual_force
        from .offtracking import straight_path
        src = dataclasses.replace(assessment.sources or ResidualSources(),
                                  crossfall_percent=c.get("crossfall_percent", 0.0))
        F = residual_force(v, assessment.load_units, src if src else None, s)
        return Evidence("straight_path", straight_path(v, speed, F, s), verdict, levels)
    return Evidence("value", None, verdict, levels)


def _options(model: str, conditions: dict) -> dict | None:
    """The model options of a measure's manoeuvre on ``model`` (the nonlinear model's tire law,
    friction coefficient and integration tolerance, as the measure was computed with)."""
    if model != "nonlinear":
        return None
    from .registry import MEASURE_RTOL
    return {"tire": "saturating", "rtol": MEASURE_RTOL,
            "friction_coefficient": conditions.get("friction_coefficient", CONDITIONS["friction_coefficient"].default)}


def _ratio(key: str, conditions: dict, n_units: int, plain: tuple, model: str = "yaw_plane") -> tuple:
    """The (numerator, denominator) signals of a ratio measure: a yaw-roll RA's from its
    reference points (:data:`lcvreport.measures.roll.RA_POINTS`; a lane change's RA on the
    yaw-roll model axis as ``ra_lane_change_roll``'s), the others' ``plain``; () for a measure
    that is no ratio."""
    if not key.startswith("ra_"):
        return ()
    roll = key if key in ("ra_single_sine_roll", "ra_lane_change_roll") else (
        "ra_lane_change_roll" if model == "yaw_roll" and key == "ra_lane_change_driver" else None)
    if roll is not None:
        from .ra_points import RA_POINTS, ra_points
        num, den = ra_points(conditions.get("ra_numerator"), conditions.get("ra_denominator"), roll)
        return RA_POINTS[num].format(n=n_units), RA_POINTS[den].format(n=n_units)
    return plain
