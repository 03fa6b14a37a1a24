"""High-speed offtracking (``docs/measures.md``): the transient one of the lane change and
the steady one of the 393 m turn.

========================  ==========================================================
``hsto_m``                high-speed transient offtracking in ``lane-change:0.15g:0.4``
``ra_lane_change``        max|a_N| / max|a_s| in that lane change
``hsso_m``                high-speed steady-state offtracking in a 393 m turn
``steady_turn_delta_rad`` the steer angle of that turn
========================  ==========================================================

Each function takes the vehicle and the speed and returns a small named result; the
null cases carry the reason (``why``).

Examples
--------
>>> from lcvreport import load_preset
>>> t = steady_turn(load_preset("aucnat"), 24.4444)
>>> round(t.hsso_m, 3)
0.551
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.batch import RESPONSE_GROUP, VariantBatch
from ..analysis.exact import ManoeuvreError, ManoeuvreResponse, check_lane_change_steer
from ..analysis.steady import check_trim, steady_with_yaw_rate, trim
from ..manoeuvres.steer import G_MPS2, lane_change, lane_change_offset_m
from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients
from ..ranges import RANGES
from ..util.numerics import rowwise
from .registry import MeasureCase

#: the lane change of HSTO: A0 [g], F [Hz], time after it [s]
LANE_CHANGE = (0.15, 0.4)


LANE_CHANGE_TAIL_S = 8.0


#: the steady turn of HSSO: radius of the tractor's yaw rate u/R [m] (0.2 g at 100 km/h)
HSSO_RADIUS_M = 393.0


#: output step of the manoeuvres [s] (the YDC window is long and its extrema are located
#: between samples by Hermite interpolation, whose error goes as the step to the 4th power)
DT_S = 0.002


@dataclass(frozen=True)
class LaneChangeMeasures:
    """HSTO and the lane-change RA (docs/measures.md)."""

    hsto_m: float
    ra_lane_change: float
    final_offset_m: float
    response: ManoeuvreResponse
    rear_axle: str
    steered_axle: str


def lane_change_measures(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0,
                         accel_g: float = LANE_CHANGE[0], f_hz: float = LANE_CHANGE[1],
                         model: str = "yaw_plane") -> LaneChangeMeasures:
    """The path-following lane change ``lane-change:0.15g:0.4``: the largest overshoot of
    the last unit's rearmost axle beyond the steered axle's final offset A0/(2 pi F^2)
    over 0 <= t <= 1/F + 8 s (0 if none), and max|a_N| / max|a_s|; on the linear model
    ``model`` (default the yaw plane).

    Raises
    ------
    ManoeuvreError
        No steered axle, an unstable inverse system, or a steer beyond [-1, 1] rad.
    """
    steer = lane_change(accel_g * G_MPS2, f_hz)
    return _lane_change_of(vehicle, speed_mps, steer, 1.0 / f_hz, tire_scale, model)


def _lane_change_of(vehicle: Vehicle, speed_mps: float, steer, until_s: float, tire_scale: float,
                    model: str, options: dict | None = None) -> LaneChangeMeasures:
    """HSTO and RA of a lane change ``steer`` (open or closed loop) over 0 <= t <= until_s + 8 s,
    on the model ``model`` (:func:`lcvreport.analysis.respond.respond`)."""
    from ..analysis.integrate import IntegrationError
    from ..analysis.respond import respond
    t_end = round((until_s + LANE_CHANGE_TAIL_S) / DT_S) * DT_S
    try:
        r = respond(vehicle, model, steer, speed_mps, t_end, DT_S, tire_scale, options=options)
    except IntegrationError as exc:
        raise ManoeuvreError(str(exc)) from None
    offset = lane_change_offset_m(steer)
    rear = vehicle.units[-1].rearmost_axle.name
    steered = max(vehicle.steered_axles, key=lambda a: a.x_m).name
    sign = 1.0 if offset >= 0 else -1.0
    (_t, Y), (_ta, a_n), (_ts, a_s), (_td, d) = r.extrema_many([f"Y_{rear}", f"ay{vehicle.n_units}", "a_steer",
                                                                 "delta"])
    check_lane_change_steer(r, float(np.abs(d).max()))
    hsto = max(0.0, float(np.max(sign * (Y - offset))))
    ra = float(np.abs(a_n).max()) / float(np.abs(a_s).max())
    return LaneChangeMeasures(hsto, float(ra), offset, r, rear, steered)


def driver_lane_change_measures(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0,
                                accel_g: float = LANE_CHANGE[0], f_hz: float = LANE_CHANGE[1],
                                gain_rad_per_m: float | None = None, preview_s: float | None = None,
                                model: str = "yaw_plane", options: dict | None = None) -> LaneChangeMeasures:
    """HSTO and RA in the closed-loop lane change ``driver:A0:F:K:T`` (docs/measures.md): the
    preview driver steers the tractor along the lane change's path; over 0 <= t <= T + 1/F +
    8 s, the largest overshoot of the last unit's rearmost axle beyond the path's final offset
    A0/(2 pi F^2) (0 if none) and max|a_N| / max|a_s|.

    Raises
    ------
    ManoeuvreError
        No steered axle, a closed loop that is unstable, or a steer beyond [-1, 1] rad.
    """
    from ..manoeuvres.steer import DRIVER_GAIN_RAD_PER_M, DRIVER_PREVIEW_S, driver_lane_change
    K = DRIVER_GAIN_RAD_PER_M if gain_rad_per_m is None else float(gain_rad_per_m)
    T = DRIVER_PREVIEW_S if preview_s is None else float(preview_s)
    steer = driver_lane_change(accel_g * G_MPS2, f_hz, K, T)
    return _lane_change_of(vehicle, speed_mps, steer, T + 1.0 / f_hz, tire_scale, model, options)


@dataclass(frozen=True)
class SteadyTurn:
    """The steady turn of HSSO (docs/measures.md#high-speed-steady-state-offtracking).

    Attributes
    ----------
    hsso_m : float
        Path radius of the last unit's rearmost axle minus that of the frontmost steered axle [m]
        (positive: the rear tracks outside).
    delta_rad : float
        The steer that holds the turn [rad].
    radius_m : float
        R: the tractor's yaw rate is u/R [m].
    state : numpy.ndarray
        The steady state x.
    path_radius_m : dict
        Axle name -> the radius of its centre's path about the turn centre [m].
    sideslip_rad : numpy.ndarray, shape (N,)
        beta_i = v_i/u of every unit's CG.
    axis_distance_m : numpy.ndarray, shape (N,)
        d_i: the distance from the turn centre to every unit's axis line [m] (d_1 = R).
    """

    hsso_m: float
    delta_rad: float
    radius_m: float
    state: np.ndarray
    path_radius_m: dict
    sideslip_rad: np.ndarray = None
    axis_distance_m: np.ndarray = None


def chain_on_circle(vehicle: Vehicle, beta, radius_m: float) -> np.ndarray:
    r"""Distances d_i [m] from the turn centre O to every unit's axis line, for units turning
    about one centre with CG sideslips ``beta`` (shape (..., N)): in unit i's frame O lies at
    (-beta_i d_i, d_i); d_1 = R; the coupling k (x = rear_coupling_m on unit k, front_coupling_m
    on unit k+1) is one point, so it has one radius,

    .. math:: (x_{r,k} + \beta_k d_k)^2 + d_k^2 = (x_{f,k+1} + \beta_{k+1} d_{k+1})^2 + d_{k+1}^2,

    which gives d_(k+1) (the positive root).  Broadcasts over a leading axis (variants).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> import numpy as np
    >>> v = load_preset("tractor_semitrailer")
    >>> d = chain_on_circle(v, np.zeros(2), 393.0)      # no sideslip: the fifth wheel has one radius
    >>> xr, xf = v.units[0].rear_coupling_m, v.units[1].front_coupling_m
    >>> bool(abs(np.hypot(xr, d[0]) - np.hypot(xf, d[1])) < 1e-9)
    True
    """
    beta = np.asarray(beta, dtype=float)
    d = np.empty(beta.shape)
    d[..., 0] = radius_m
    for k in range(vehicle.n_units - 1):
        xr, xf = vehicle.units[k].rear_coupling_m, vehicle.units[k + 1].front_coupling_m
        rho2 = (xr + beta[..., k] * d[..., k]) ** 2 + d[..., k] ** 2
        b = beta[..., k + 1]
        d[..., k + 1] = (-xf * b + np.sqrt((1.0 + b * b) * rho2 - xf * xf)) / (1.0 + b * b)
    return d


def steady_turn(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0,
                radius_m: float = HSSO_RADIUS_M) -> SteadyTurn:
    """The steady turn with the tractor's yaw rate u/R (docs/measures.md: the
    steady state of ``M x' = S x + b delta`` with r1 = u/R gives every unit's CG sideslip
    beta_i = v_i/u; every unit turns at Omega = u/R about one centre O, the units' geometry
    chained through their shared couplings (:func:`chain_on_circle`); a point at x on unit i runs
    on R_P = sqrt((x + beta_i d_i)^2 + d_i^2).  hsso_m = R_P of the last unit's rearmost axle
    minus R_P of the frontmost steered axle (positive: the rear tracks outside).  As u -> 0 it is
    the kinematic offtracking -(sum L_i^2 - sum k_i^2 - e_N^2) / (2R) to first order in 1/R.

    Raises
    ------
    ManoeuvreError
        No steered axle.
    lcvreport.ranges.RangeError
        A speed, tire scale or radius out of range (the radius: the ranges table's
        ``steady_turn_radius``, [20, 10000] m).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> t = steady_turn(load_preset("tractor_semitrailer"), 0.5)      # walking pace: kinematic
    >>> bool(-1.0 < t.hsso_m < 0.0)                                  # the trailer tracks inside
    True
    """
    from .registry import CONDITIONS
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    radius_m = CONDITIONS["steady_turn_radius_m"].check(radius_m, "radius_m")
    if not vehicle.steered_axles:
        raise ManoeuvreError(f"{vehicle.name} has no steered axle: no steer holds a turn")
    co = system_coefficients(vehicle)
    u = float(speed_mps)
    omega = u / radius_m
    x, delta = steady_with_yaw_rate(vehicle, u, np.zeros(linear_model(vehicle).n_states), omega, tire_scale)
    beta = (co.velocity_map(u) @ x) / u             # CG sideslip of every unit
    d = chain_on_circle(vehicle, beta, radius_m)

    def radius(unit, xp):
        return math.hypot(xp + beta[unit] * d[unit], d[unit])

    steered = max(vehicle.steered_axles, key=lambda a: a.x_m)
    rear = vehicle.units[-1].rearmost_axle
    paths = {a.name: radius(i, a.x_m) for i, a in zip(vehicle.axle_units, vehicle.axles)}
    hsso = radius(vehicle.n_units - 1, rear.x_m) - radius(0, steered.x_m)
    return SteadyTurn(float(hsso), delta, float(radius_m), x, paths, beta, d)


def lane_change_batched(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0,
                        lane_change_ay_g: float | None = None,
                        lane_change_frequency_hz: float | None = None, extra: dict | None = None) -> dict:
    """``{"hsto_m": HSTO [m], "ra_lane_change": the lane change's RA [-]}`` of every variant, as
    :func:`lcvreport.measures.offtracking.lane_change_measures` (the path-following lane
    change through each variant's inverse system, on the batch's model): the last unit's rearmost
    axle's largest overshoot beyond the steered axle's final offset (0 if none), and max|a_N| /
    max|a_s|.  NaN where the inverse system is unstable or does not exist, or the steer leaves
    [-1, 1] rad (measure_set's null).  ``lane_change_ay_g`` [g] and ``lane_change_frequency_hz``
    [Hz]: A0 and F (default :data:`LANE_CHANGE`).  ``extra``: ``{name: (X, XD, D)}``, each
    variant's row of one more signal ``y = X x + XD x' + D delta`` (shapes (B, n), (B, n), (B,)),
    whose peaks |y| are then returned under ``name`` beside the two (the yaw-roll model's load
    transfer ratio, its sprung CG's acceleration, a reference point of RA)."""
    from ..analysis.exact import steered_point
    from ..manoeuvres.steer import G_MPS2, lane_change, lane_change_offset_m
    v = batch.vehicle
    co = linear_model(v, batch.model)
    B, nu, n = batch.size, v.n_units, co.n_states
    accel_g = LANE_CHANGE[0] if lane_change_ay_g is None else float(lane_change_ay_g)
    f_hz = LANE_CHANGE[1] if lane_change_frequency_hz is None else float(lane_change_frequency_hz)
    steer = lane_change(accel_g * G_MPS2, f_hz)
    t_end = round((1.0 / f_hz + LANE_CHANGE_TAIL_S) / DT_S) * DT_S
    offset = lane_change_offset_m(steer)
    sign = 1.0 if offset >= 0 else -1.0
    u = float(speed_mps)
    xs = steered_point(v)
    y_row = co.point_lateral_row(nu - 1, v.units[-1].rearmost_axle.x_m)     # Y of the rear axle over [x, psi1, Y1]
    ay_rows = batch.ay_rows(u, [nu - 1])

    def signals_of(rows):
        def signals(Mz, d_row, ctx):
            C = np.zeros((Mz.shape[0], 4 + len(extra or ()), Mz.shape[-1]))
            C[:, 0, :n + 2] = y_row                                         # Y of the rear axle
            C[:, 1] = ay_rows(Mz, d_row, ctx)[:, 0]                         # a_N
            C[:, 2] = Mz[:, 0] + xs * Mz[:, 1]                              # a_s = v1' + x_s r1' + u r1
            C[:, 2, 1] += u
            C[:, 3] = d_row                                                 # the steer (within [-1, 1] rad)
            for k, rows_k in enumerate((extra or {}).values()):            # X x + XD x' + D delta
                X, XD, D = (np.asarray(a)[rows] for a in rows_k)
                C[:, 4 + k, :n] = X
                C[:, 4 + k] += np.einsum("bn,bnd->bd", XD, Mz[:, :n])
                C[:, 4 + k] += D[:, None] * d_row
            return C
        return signals
    hsto, ra = np.full(B, np.nan), np.full(B, np.nan)
    peak_extra = np.full((B, len(extra or ())), np.nan)
    for g in range(0, B, RESPONSE_GROUP):
        rows = np.arange(g, min(B, g + RESPONSE_GROUP))
        ok = batch.inverse_stable(u, tire_scale, rows)
        rows = rows[ok]
        if not rows.size:
            continue
        hi, lo = batch.extremes(u, steer, t_end, DT_S, signals_of(rows), tire_scale, rows)
        over = (hi[:, 0] - offset) if sign > 0 else -(lo[:, 0] - offset)
        peak = np.maximum(np.abs(hi), np.abs(lo))
        steer_ok = peak[:, 3] <= RANGES["steer_angle"].high                # else refused (measure_set's null)
        hsto[rows[steer_ok]] = np.maximum(0.0, over[steer_ok])
        ra[rows[steer_ok]] = peak[steer_ok, 1] / peak[steer_ok, 2]
        peak_extra[rows[steer_ok]] = peak[steer_ok, 4:]
    return {"hsto_m": hsto, "ra_lane_change": ra, **dict(zip(extra or {}, peak_extra.T))}


def steady_turn_batched(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0,
                        steady_turn_radius_m: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(hsso_m, steer [rad]) of every variant in the steady turn of
    :func:`lcvreport.measures.offtracking.steady_turn` (tractor yaw rate u/R, R =
    ``steady_turn_radius_m``, default :data:`HSSO_RADIUS_M`)."""
    R = HSSO_RADIUS_M if steady_turn_radius_m is None else float(steady_turn_radius_m)
    u = float(speed_mps)
    omega = u / R
    v = batch.vehicle
    x, delta = batch.steady(u, np.zeros(linear_model(v, batch.model).n_states), omega, tire_scale)
    beta = rowwise(x, linear_model(v, batch.model).velocity_map(u).T) / u      # (B, N) CG sideslips, per variant
    d = chain_on_circle(v, beta, R)                                     # (B, N) the chain on the circle
    steered = max(v.steered_axles, key=lambda a: a.x_m)
    rear = v.units[-1].rearmost_axle
    radius = lambda unit, xp: np.hypot(xp + beta[:, unit] * d[:, unit], d[:, unit])  # noqa: E731
    return radius(v.n_units - 1, rear.x_m) - radius(0, steered.x_m), delta


def lane_change_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``lane_change`` family of one case (null, with the reason, where the
    manoeuvre cannot be followed)."""
    keys = ("hsto_m", "ra_lane_change")
    try:
        lc = lane_change_measures(case.vehicle, case.speed_mps, case.tire_scale,
                                  case.condition("lane_change_ay_g"), case.condition("lane_change_frequency_hz"),
                                  model=case.model)
    except ManoeuvreError as exc:
        return dict.fromkeys(keys), dict.fromkeys(keys, f"undefined: {exc}")
    return {"hsto_m": lc.hsto_m, "ra_lane_change": _ra(case, lc, "ra_lane_change_roll")}, {}


def _ra(case: MeasureCase, lc: LaneChangeMeasures, roll_measure: str) -> float:
    """A lane change's RA: max|a_N| / max|a_s| -- on the yaw-roll model between its reference
    points (the conditions ``ra_numerator``, ``ra_denominator``; ``roll_measure``'s defaults)."""
    if case.model != "yaw_roll":
        return lc.ra_lane_change
    from .ra_points import ra_points, rearward_amplification
    points = ra_points(case.conditions.get("ra_numerator"), case.conditions.get("ra_denominator"), roll_measure)
    return rearward_amplification(lc.response, case.vehicle.n_units, *points)


def driver_lane_change_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``driver_lane_change`` family of one case (null, with the reason, where
    the closed loop is unstable or the steer leaves its range)."""
    keys = ("hsto_driver_m", "ra_lane_change_driver")
    try:
        lc = driver_lane_change_measures(case.vehicle, case.speed_mps, case.tire_scale,
                                         case.condition("lane_change_ay_g"), case.condition("lane_change_frequency_hz"),
                                         case.condition("driver_gain_rad_per_m"), case.condition("driver_preview_s"),
                                         model=case.model, options=case.model_options())
    except ManoeuvreError as exc:
        return dict.fromkeys(keys), dict.fromkeys(keys, f"undefined: {exc}")
    return {"hsto_driver_m": lc.hsto_m, "ra_lane_change_driver": _ra(case, lc, "ra_lane_change_roll")}, {}


def steady_turn_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``steady_turn`` family of one case."""
    turn = steady_turn(case.vehicle, case.speed_mps, case.tire_scale, case.condition("steady_turn_radius_m"))
    return {"hsso_m": turn.hsso_m, "steady_turn_delta_rad": turn.delta_rad}, {}


@dataclass(frozen=True)
class StraightPath:
    """Tracking ability on a straight path (docs/measures.md#tracking-ability-on-a-straight-path):
    the combination trimmed straight against its residual sources, every body's outline at its
    steady offset and heading.

    Attributes
    ----------
    tasp_m : float
        Width of the band the bodies sweep, across the direction of travel [m].
    left_m, right_m : numpy.ndarray, shape (N,)
        Every unit's outermost body point to the left (+y) and right of the steered axle's
        path [m] (the band is ``max(left_m) - min(right_m)``).
    trim : Trim
    """

    tasp_m: float
    left_m: np.ndarray
    right_m: np.ndarray
    trim: object


def straight_path(vehicle: Vehicle, speed_mps: float, F=None, tire_scale: float = 1.0) -> StraightPath:
    """The straight-path band of ``vehicle`` at ``speed_mps`` [m/s] under the generalized force
    ``F`` [SI] (None: no residual source; the band is then the widest body): the trim
    (:func:`lcvreport.analysis.steady.trim`) puts every unit at a constant articulation and
    crab; a body point at signed x on unit k lies ``Y_k(x) - (X_k(x) - X_s) v_1/u`` from the
    steered axle's path (first order in the angles), each side ``body_width_m / 2`` beyond it.

    Raises
    ------
    lcvreport.model.body.TurnError
        A unit without ``body_front_m``, ``body_rear_m`` or ``body_width_m``.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> round(straight_path(load_preset("aucnat"), 24.4444).tasp_m, 4)       # no source: the widest body
    2.5908
    """
    from ..analysis.steady import reference_points
    from ..model.body import need_bodies
    from ..model.yaw_plane.outputs import point_longitudinal, point_lateral_map
    need_bodies(vehicle)
    n = linear_model(vehicle).n_states
    tr = trim(vehicle, speed_mps, np.zeros(n) if F is None else np.asarray(F, dtype=float), tire_scale)
    check_trim(tr)
    x = tr.state
    nu = vehicle.n_units
    Theta = np.cumsum(x[nu + 1:])
    (uq, xq), _ = reference_points(vehicle)
    Xq = point_longitudinal(vehicle, uq, xq)
    yq = float(point_lateral_map(vehicle, uq, xq)[2:] @ Theta)
    crab = x[0] / float(speed_mps)
    left, right = np.empty(nu), np.empty(nu)
    for k, unit in enumerate(vehicle.units):
        ys = [float(point_lateral_map(vehicle, k, xb)[2:] @ Theta) - yq - (point_longitudinal(vehicle, k, xb) - Xq) * crab
              for xb in (unit.body_front_m, unit.body_rear_m)]
        left[k], right[k] = max(ys) + unit.body_width_m / 2, min(ys) - unit.body_width_m / 2
    return StraightPath(float(left.max() - right.min()), left, right, tr)


def straight_path_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``straight_path`` family of one case (null, with the key missing, where a
    unit has no body dimensions)."""
    from ..model.body import TurnError
    try:
        sp = straight_path(case.vehicle, case.speed_mps, case.F, case.tire_scale)
    except TurnError as exc:
        return {"tasp_m": None}, {"tasp_m": f"undefined: {str(exc).replace('the low-speed turn', 'the straight path')}"}
    return {"tasp_m": sp.tasp_m}, {}


def trim_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``trim`` family of one case under its residual force ``case.F``."""
    tr = trim(case.vehicle, case.speed_mps, case.F, case.tire_scale)
    check_trim(tr)
    case.shared["trim"] = tr
    return {"trim.delta_rad": tr.delta_rad, "trim.offtracking_m": tr.offtracking_m}, {}


def trim_batched(batch: VariantBatch, speed_mps: float, F=None, tire_scale: float = 1.0) -> tuple:
    """(trim steer [rad], trimmed offtracking [m]) of every variant under its row of ``F``
    ((B, 2N) generalized forces [SI]; NaN rows: no source, NaN results).  A batch of one
    variant under several forces gives one row per force."""
    if F is None:
        return np.full(batch.size, np.nan), np.full(batch.size, np.nan)
    F = np.asarray(F, dtype=float)
    out = (np.full(len(F), np.nan), np.full(len(F), np.nan))
    has = np.isfinite(F[:, 0])
    if has.any():
        rows = np.flatnonzero(has) if batch.size > 1 else np.zeros(int(has.sum()), int)
        out[0][has], out[1][has] = batch.subset(rows).trim(speed_mps, F[has], tire_scale)
    return out
