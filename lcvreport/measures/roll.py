r"""The roll measures (docs/roll.md#measures): the yaw-roll model's damping, critical speed,
rearward amplification, transient offtracking, load transfer ratios and roll gains, and the
static rollover threshold of every roll-coupled group.

A vehicle without roll data has every roll measure null, with the missing key named.

Examples
--------
>>> from lcvreport import load_vehicle
>>> s = roll_summary(load_vehicle("examples/vehicles/b_double.toml"), 25.0)
>>> round(s.threshold.srt_min_g, 3), len(s.ltr_lane_change)
(0.48, 1)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..analysis.exact import ManoeuvreError
from ..model.linear import linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_roll.parameters import G_MPS2, missing_roll_data
from ..util.threads import one_blas_thread
from .amplification import single_sine
from .offtracking import LANE_CHANGE, lane_change_measures
from .ra_points import RA_POINTS, ra_points, rearward_amplification  # noqa: F401 (their home before)
from .registry import NO_STEER, MeasureCase
from .rollover import RolloverThreshold, rollover_threshold
from .stability import CRITICAL_SPEED_MAX_KPH, critical_speed, least_damping

MODEL = "yaw_roll"
#: the single sine of ltr_single_sine is scaled to this max|a_1| [g]
LTR_SINGLE_SINE_G = 0.15

ROLLOVER_KEYS = ("srt_g", "srt_rrcu_g", "srt_min_g")
ROLL_KEYS = ("roll_least_damping_ratio", "roll_critical_speed_kph", "ra_single_sine_roll", "ltr_single_sine",
             "ra_lane_change_roll", "hsto_m_roll", "ltr_lane_change", "rltr_lane_change", "roll_gain_deg_per_g")


def roll_gains(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
    """Steady-turn roll gain of every unit, signed ``phi_i / (a_1 / g)`` [deg/g] (negative when
    the unit rolls out of the turn), on the yaw-roll model at ``speed_mps`` [m/s]."""
    co = linear_model(vehicle, MODEL)
    A, G = co.state_derivative_maps(speed_mps, tire_scale)
    x = -np.linalg.solve(A, G @ co.B_delta(tire_scale))          # per radian of steer
    a1 = float(speed_mps) * x[1]                                  # a_1 = u r_1 at rest in the turn
    phi = x[co.phi_index:co.phi_index + vehicle.n_units]
    return np.degrees(phi) / (a1 / G_MPS2)


def ltr_peaks(response, n_groups: int) -> list[float]:
    """max over the response of |LTR| of every group, front to rear [-]."""
    return [float(x) for x in response.peaks_abs([f"ltr{g + 1}" for g in range(n_groups)])]


def ltr_single_sine(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0, f_hz: float = LANE_CHANGE[1],
                    numerator: str | None = None, denominator: str | None = None):
    """(RA, |LTR| peaks per group) of the 0.4 Hz single sine on the yaw-roll model, the RA between
    the points given (default the measure's: the rearmost unit's sprung CG over unit 1's CG), the
    LTR scaled to ``max|a_1| = 0.15 g`` (the model is linear)."""
    s = single_sine(vehicle, speed_mps, f_hz, tire_scale=tire_scale, model=MODEL)
    scale = LTR_SINGLE_SINE_G * G_MPS2 / float(s.peaks[0])
    groups = len(linear_model(vehicle, MODEL).roll.groups)
    points = ra_points(numerator, denominator, "ra_single_sine_roll")
    return (rearward_amplification(s.response, vehicle.n_units, *points),
            [scale * x for x in ltr_peaks(s.response, groups)])


@dataclass(frozen=True)
class RollSummary:
    """What ``lcv roll`` shows (docs/roll.md#cli): the threshold of every group, the roll gains,
    the load transfer ratios and the roll modes' damping at one speed."""

    vehicle: Vehicle
    speed_mps: float
    threshold: RolloverThreshold
    roll_gain_deg_per_g: list | None
    ltr_lane_change: list | None
    ltr_single_sine: list | None
    roll_least_damping_ratio: float | None
    roll_critical_speed_kph: float | None
    reasons: dict

    def to_dict(self) -> dict:
        """The JSON of ``lcv roll`` (docs/roll.md#cli)."""
        t = self.threshold
        return {"speed_mps": self.speed_mps, "groups": t.to_dict(), "srt_min_g": t.srt_min_g,
                "srt_rrcu_g": t.srt_rrcu_g,
                "roll_gain_deg_per_g": None if self.roll_gain_deg_per_g is None else dict(
                    zip(self.vehicle.unit_names, self.roll_gain_deg_per_g)),
                "ltr_lane_change": self.ltr_lane_change,
                "rltr_lane_change": None if self.ltr_lane_change is None else self.ltr_lane_change[-1],
                "ltr_single_sine": self.ltr_single_sine, "roll_least_damping_ratio": self.roll_least_damping_ratio,
                "roll_critical_speed_kph": self.roll_critical_speed_kph, "reasons": dict(self.reasons)}

    def plot(self, ax=None):
        """The a_y - phi curve of every group with each lift-off marked."""
        return self.threshold.plot(ax)


@one_blas_thread
def roll_summary(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> RollSummary:
    """The roll summary of ``vehicle`` at ``speed_mps`` [m/s] (see :class:`RollSummary`): what
    ``lcv roll`` prints (``lcvreport.roll``).

    Parameters
    ----------
    vehicle : Vehicle
        With its roll keys (docs/roll.md).
    speed_mps : float
        Forward speed [m/s] of the dynamic roll measures.
    tire_scale : float
        Factor on every tire coefficient [-].

    Returns
    -------
    RollSummary

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> s = roll_summary(load_vehicle("examples/vehicles/b_double.toml"), 24.4)
    >>> 0.3 < s.to_dict()["srt_min_g"] < 0.6
    True

    Raises
    ------
    VehicleError
        Missing or invalid roll data (naming the unit, the axle and the key).
    """
    threshold = rollover_threshold(vehicle)
    values, reasons = _dynamic(vehicle, float(speed_mps), float(tire_scale))
    return RollSummary(vehicle, float(speed_mps), threshold, values["roll_gain_deg_per_g"],
                       values["ltr_lane_change"], values["ltr_single_sine"], values["roll_least_damping_ratio"],
                       values["roll_critical_speed_kph"], reasons)


#: the roll measures read from a manoeuvre or a steady turn: undefined when the roll mode is
#: unstable at rest (the response grows without bound from any start)
RESPONSE_KEYS = ("ra_single_sine_roll", "ltr_single_sine", "ra_lane_change_roll", "hsto_m_roll", "ltr_lane_change",
                 "rltr_lane_change", "roll_gain_deg_per_g")


def unstable_at_rest(vehicle: Vehicle) -> str | None:
    """Why the roll responses of ``vehicle`` are undefined -- a roll-coupled group whose roll
    stiffness cannot hold its sprung weight (its stiffness matrix at rest is not positive
    definite: SRT 0, a roll mode unstable at any speed) -- or None."""
    weak = [", ".join(g.units) for g in rollover_threshold(vehicle).groups if not g.stable_at_rest]
    if not weak:
        return None
    return (f"undefined: the roll mode is unstable at rest ({'; '.join(weak)}: the roll stiffness cannot hold the "
            "sprung weight, SRT 0): every response grows without bound")


def _dynamic(vehicle: Vehicle, u: float, s: float, f_hz: float = LANE_CHANGE[1],
             lane_change: tuple[float, float] = LANE_CHANGE, numerator: str | None = None,
             denominator: str | None = None) -> tuple[dict, dict]:
    """The roll family's values and reasons (roll data present): the single sine at ``f_hz``
    [Hz], the lane change of ``lane_change`` (A0 [g], F [Hz]), the RA between ``numerator`` and
    ``denominator`` (:data:`RA_POINTS`; None: each RA measure's default)."""
    values, reasons = dict.fromkeys(ROLL_KEYS), {}
    zeta, _f = least_damping(vehicle, u, s, model=MODEL)
    values["roll_least_damping_ratio"] = zeta
    if zeta is None:
        reasons["roll_least_damping_ratio"] = "no mode oscillates"
    crit = critical_speed(vehicle, s, model=MODEL)
    values["roll_critical_speed_kph"] = crit
    if crit is None:
        reasons["roll_critical_speed_kph"] = f"stable at every speed up to {CRITICAL_SPEED_MAX_KPH:g} km/h"
    unstable = unstable_at_rest(vehicle)
    if unstable is not None:
        reasons.update(dict.fromkeys(RESPONSE_KEYS, unstable))
        return values, reasons
    if not vehicle.steered_axles:
        for k in ("ra_single_sine_roll", "ltr_single_sine", "ra_lane_change_roll", "hsto_m_roll", "ltr_lane_change",
                  "rltr_lane_change", "roll_gain_deg_per_g"):
            reasons[k] = NO_STEER
        return values, reasons
    values["ra_single_sine_roll"], values["ltr_single_sine"] = ltr_single_sine(vehicle, u, s, f_hz, numerator,
                                                                              denominator)
    groups = len(linear_model(vehicle, MODEL).roll.groups)
    try:
        lc = lane_change_measures(vehicle, u, s, *lane_change, model=MODEL)
    except ManoeuvreError as exc:
        for k in ("ra_lane_change_roll", "hsto_m_roll", "ltr_lane_change", "rltr_lane_change"):
            reasons[k] = f"undefined: {exc}"
    else:
        points = ra_points(numerator, denominator, "ra_lane_change_roll")
        values["ra_lane_change_roll"] = rearward_amplification(lc.response, vehicle.n_units, *points)
        values["hsto_m_roll"] = lc.hsto_m
        values["ltr_lane_change"] = ltr_peaks(lc.response, groups)
        values["rltr_lane_change"] = values["ltr_lane_change"][-1]
    gains = roll_gains(vehicle, u, s)
    values["roll_gain_deg_per_g"] = [float(x) for x in gains] if np.all(np.isfinite(gains)) else None
    if values["roll_gain_deg_per_g"] is None:
        reasons["roll_gain_deg_per_g"] = "undefined: the steady turn has no lateral acceleration"
    return values, reasons


#: the keys :func:`roll_batched` gives (the registry's roll family's batched keys)
BATCHED_KEYS = ("roll_least_damping_ratio", "roll_critical_speed_kph", "ra_single_sine_roll", "ra_lane_change_roll",
                "hsto_m_roll", "rltr_lane_change")


def roll_batched(batch, speed_mps: float, tire_scale: float = 1.0, f_hz: float = LANE_CHANGE[1],
                 lane_change_ay_g: float = LANE_CHANGE[0], lane_change_frequency_hz: float = LANE_CHANGE[1],
                 ra_numerator: str | None = None, ra_denominator: str | None = None) -> dict:
    """The roll family's scalar measures over the variants of ``batch`` (any model: its variants
    are taken to the yaw-roll model, each one's coefficients built exactly), one array each in the
    registry's order: ``roll_least_damping_ratio``, ``roll_critical_speed_kph``,
    ``ra_single_sine_roll``, ``ra_lane_change_roll``, ``hsto_m_roll``, ``rltr_lane_change`` -- the
    numbers of :func:`roll_family` case by case (the batched least damping, critical speed, single
    sine and lane change of the yaw plane, run on the yaw-roll model; the lane change also tracks
    the rearmost group's load transfer ratio, each variant's own row).  NaN where undefined.

    Examples
    --------
    >>> import numpy as np
    >>> from lcvreport import load_vehicle
    >>> from lcvreport.analysis.batch import VariantBatch
    >>> v = load_vehicle("examples/vehicles/b_double.toml")
    >>> b = VariantBatch(v, {"rear_trailer.mass_kg": v.units[-1].mass_kg * np.array([0.9, 1.0])})
    >>> got = roll_batched(b, 25.0)
    >>> bool(abs(got["rltr_lane_change"][1] - roll_summary(v, 25.0).ltr_lane_change[-1]) < 1e-12)
    True
    """
    from .amplification import single_sine_peaks
    from .offtracking import lane_change_batched
    from .stability import critical_speed_batched, least_damping_batched
    if missing_roll_data(batch.vehicle) is not None:
        return {key: np.full(batch.size, np.nan) for key in BATCHED_KEYS}
    rb = batch.on_model(MODEL)
    u, s = float(speed_mps), float(tire_scale)
    zeta = least_damping_batched(rb, u, s)[0]
    crit = critical_speed_batched(rb, s)
    nan = np.full(rb.size, np.nan)
    if not rb.vehicle.steered_axles:
        return {"roll_least_damping_ratio": zeta, "roll_critical_speed_kph": crit,
                **{key: nan.copy() for key in BATCHED_KEYS[2:]}}
    unstable = np.array([unstable_at_rest(v) is not None for v in rb.vehicles()])
    co = linear_model(rb.vehicle, MODEL)
    nu = rb.vehicle.n_units
    last = f"ltr{len(co.roll.groups)}"
    ltr_rows, as_rows = [], []
    for v in rb.vehicles():                               # each variant's own rows
        names, X, XD, D, _O = linear_model(v, MODEL).extra_signals(u, s)
        for rows, name in ((ltr_rows, last), (as_rows, f"as{nu}")):
            k = names.index(name)
            rows.append((X[k], XD[k], D[k]))
    stack = lambda rows: tuple(np.array([r[i] for r in rows]) for i in range(3))   # noqa: E731
    # the other points, the same rows for every variant (the batch shares one geometry): the
    # rearmost unit's roll-axis point a_N = v_N' + u r_N, unit 1's CG a_1 = v1' + u r1 and the
    # steered axle's a_s = v1' + x_s r1' + u r1
    from ..analysis.exact import steered_point
    V, R = co.velocity_map(u), co.yaw_rate_map()
    a_n = (u * R[nu - 1], V[nu - 1], 0.0)
    a_1 = (u * R[0], V[0], 0.0)
    a_s = (u * R[0], V[0] + steered_point(rb.vehicle) * R[0], 0.0)
    same = lambda row: tuple(np.broadcast_to(np.asarray(a, dtype=float), (rb.size,) + np.shape(a)) for a in row)  # noqa: E731
    points = [stack(as_rows), same(a_n), same(a_1), same(a_s)]
    names = ("sprung_cg", "roll_axis", "cg", "steer_axle")
    num_ss, den_ss = ra_points(ra_numerator, ra_denominator, "ra_single_sine_roll")
    num_lc, den_lc = ra_points(ra_numerator, ra_denominator, "ra_lane_change_roll")
    ss = dict(zip(names, single_sine_peaks(rb, u, f_hz, s, extra=points)[:, 4:].T))
    ra_ss = ss[num_ss] / ss[den_ss]
    lc = lane_change_batched(rb, u, s, lane_change_ay_g, lane_change_frequency_hz,
                             extra={"rltr": stack(ltr_rows), **dict(zip(names, points))})
    ra_lc = lc[num_lc] / lc[den_lc]
    responses = {key: np.where(unstable, np.nan, a)                                   # as roll_family: undefined
                 for key, a in (("ra_single_sine_roll", ra_ss), ("ra_lane_change_roll", ra_lc),
                                ("hsto_m_roll", lc["hsto_m"]), ("rltr_lane_change", lc["rltr"]))}
    return {"roll_least_damping_ratio": zeta, "roll_critical_speed_kph": crit, **responses}


def rollover_batched(batch) -> dict:
    """``srt_rrcu_g`` and ``srt_min_g`` [g] of every variant of ``batch`` (:func:`rollover_family`
    variant by variant: the threshold's events are exact, one short search per variant); NaN
    without roll data."""
    if missing_roll_data(batch.vehicle) is not None:
        return {"srt_rrcu_g": np.full(batch.size, np.nan), "srt_min_g": np.full(batch.size, np.nan)}
    out = np.array([[t.srt_rrcu_g, t.srt_min_g] for t in map(rollover_threshold, batch.vehicles())], dtype=float)
    return {"srt_rrcu_g": out[:, 0], "srt_min_g": out[:, 1]}


def _no_roll(keys, vehicle: Vehicle):
    why = missing_roll_data(vehicle)
    if why is None:
        return None
    return dict.fromkeys(keys), dict.fromkeys(keys, f"undefined: no roll data: {why}")


def roll_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``roll`` family: the yaw-roll model's dynamic measures at the case's speed."""
    missing = _no_roll(ROLL_KEYS, case.vehicle)
    if missing is not None:
        return missing
    return _dynamic(case.vehicle, case.speed_mps, case.tire_scale, case.f_hz,
                    (case.condition("lane_change_ay_g"), case.condition("lane_change_frequency_hz")),
                    case.conditions.get("ra_numerator"), case.conditions.get("ra_denominator"))


def rollover_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``rollover`` family: the static rollover threshold of every group."""
    missing = _no_roll(ROLLOVER_KEYS, case.vehicle)
    if missing is not None:
        return missing
    t = rollover_threshold(case.vehicle)
    return {"srt_g": [g.srt_g for g in t.groups], "srt_rrcu_g": t.srt_rrcu_g, "srt_min_g": t.srt_min_g}, {}


def unstable_at_rest_note(threshold: RolloverThreshold) -> str | None:
    """The line saying which groups cannot hold their sprung weight at rest (SRT 0), or None."""
    weak = [", ".join(g.units) for g in threshold.groups if not g.stable_at_rest]
    if not weak:
        return None
    return (f"note: the roll stiffness of ({'; '.join(weak)}) cannot hold its sprung weight at rest (the group's "
            "roll stiffness matrix is not positive definite): SRT 0 and an unstable roll mode")
