"""The reference points of the yaw-roll model's rearward amplification (docs/measures.md
#the-reference-points-of-the-yaw-roll-ra): which signal of a response each point is, the
points of a measure (given or its defaults), and the RA between two of them -- for the roll
measures and for the measures of the model axis taken on the yaw-roll model.

Examples
--------
>>> ra_points(None, None, "ra_lane_change_roll")
('sprung_cg', 'steer_axle')
"""
from __future__ import annotations


#: the signal of each RA reference point in a yaw-roll response (docs/measures.md#roll-measures):
#: the rearmost unit's sprung CG ``as<N>`` or roll-axis point ``ay<N>``; the hauling unit's
#: steered axle ``a_steer`` or CG ``ay1``
RA_POINTS = {"sprung_cg": "as{n}", "roll_axis": "ay{n}", "steer_axle": "a_steer", "cg": "ay1"}


def ra_points(numerator: str | None, denominator: str | None, measure: str) -> tuple[str, str]:
    """(numerator, denominator) of an RA measure: the points given, each missing one at the
    measure's default (:func:`~lcvreport.measures.registry.default_condition`)."""
    from .registry import default_condition
    return (numerator or default_condition("ra_numerator", measure),
            denominator or default_condition("ra_denominator", measure))


def rearward_amplification(response, n_units: int, numerator: str, denominator: str) -> float:
    """max|numerator| / max|denominator| over a yaw-roll ``response`` (the points' signals
    located on the continuous response: :data:`RA_POINTS`)."""
    top, bottom = (RA_POINTS[p].format(n=n_units) for p in (numerator, denominator))
    peaks = response.peaks_abs([top, bottom])
    return float(peaks[0] / peaks[1])


