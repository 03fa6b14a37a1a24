"""The field's yaw-plane measures beyond SPEC section 8 (SPEC section 12), at one speed.

========================  ==========================================================
``ra_peak``               max of RA(f) over 0.1-2 Hz, and where (f to 1e-6 Hz)
``yaw_damping_coefficient``  PBS-style ratio method on a ``pulse:0.01:0.5`` steer
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
>>> ra = ra_peak(load_preset("tractor_semitrailer"), 24.4444)
>>> 0.1 <= ra.frequency_hz <= 2.0
True
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.builder import check_speed, check_tire_scale, system_coefficients
from ..model.vehicle import Vehicle
from .exact import ManoeuvreError, ManoeuvreResponse, check_lane_change_steer, response
from .geometry import point_lateral_map
from .manoeuvres import G_MPS2, lane_change, lane_change_offset_m, pulse
from .measures import steady_with_yaw_rate

#: the RA(f) search band [Hz]
RA_BAND_HZ = (0.1, 2.0)
#: the YDC pulse: amplitude [rad], duration [s]; the window after it [s]
YDC_PULSE = (0.01, 0.5)
YDC_WINDOW_S = 40.0
#: amplitudes kept: at least this fraction of the joint's largest, the first this many
YDC_MIN_FRACTION = 0.05
YDC_MAX_AMPLITUDES = 6
#: a joint with fewer than two kept amplitudes decays faster than 1/YDC_MIN_FRACTION per half
#: cycle: its zeta is at least this (ln 20 / sqrt(pi^2 + ln^2 20) = 0.6901), the YDC's lower bound
#: when every joint is so (SPEC 12)
YDC_HEAVY_ZETA = math.log(1.0 / YDC_MIN_FRACTION) / math.sqrt(math.pi ** 2 + math.log(1.0 / YDC_MIN_FRACTION) ** 2)
#: the lane change of HSTO: A0 [g], F [Hz], time after it [s]
LANE_CHANGE = (0.15, 0.4)
LANE_CHANGE_TAIL_S = 8.0
#: the steady turn of HSSO: radius of the tractor's yaw rate u/R [m] (0.2 g at 100 km/h)
HSSO_RADIUS_M = 393.0
#: output step of the manoeuvres [s] (the YDC window is long and its extrema are located
#: between samples by Hermite interpolation, whose error goes as the step to the 4th power)
DT_S = 0.002
YDC_DT_S = 0.005


@dataclass(frozen=True)
class RAPeak:
    """Peak of the frequency-domain rearward amplification over :data:`RA_BAND_HZ`."""

    value: float
    frequency_hz: float


def ra_peak(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> RAPeak:
    """max over 0.1-2 Hz of RA(f) = |G_N(j 2 pi f)| / |G_1(j 2 pi f)| and where it is
    (a 0.005 Hz scan, then the zero of d ln RA / df in the best bracket: the derivative
    exact from the same factorisation, ``dz/dw = -(jwM - S)^-1 jM z``, Brent's root finder
    to 1e-13 Hz; a maximum is flat, its zero-slope point is not).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> p = ra_peak(load_preset("aucnat"), 24.4444)
    >>> round(p.value, 3) > 5.0
    True
    """
    from scipy.linalg import lu_factor, lu_solve
    from scipy.optimize import brentq, minimize_scalar
    lo, hi = RA_BAND_HZ
    f = np.linspace(lo, hi, 381)
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle)           # once: the search asks for ~10 single frequencies
    u = float(speed_mps)
    M, S, b = co.M(u), co.S(u, tire_scale), co.B_delta(tire_scale)
    ends = np.array([0, vehicle.n_units - 1])
    V, R = co.velocity_map(u)[ends], co.yaw_rate_map()[ends]

    def ra(x):
        """RA at the frequencies x [Hz]: as steer_to_acceleration (first and last unit only)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        w = 2 * np.pi * x[..., None, None]
        z = np.linalg.solve(1j * w * M - S, np.broadcast_to(b, x.shape + b.shape)[..., None])[..., 0]
        G = np.abs(z @ V.T * (1j * 2 * np.pi * x[..., None]) + u * (z @ R.T))
        return G[..., -1] / G[..., 0]

    def ra1(x: float) -> float:
        """RA at one frequency x [Hz] (the peak's value, the fallback search): the same solve
        without the stacking."""
        w = 2 * np.pi * x
        z = np.linalg.solve(1j * w * M - S, b)
        G = np.abs(V @ z * (1j * w) + u * (R @ z))
        return float(G[1] / G[0])

    # in blocks of 64 frequencies: each solve independent (the same numbers as one call), and no
    # temporaries of a megabyte that malloc would hand back to the system and fault in again
    values = np.concatenate([ra(f[i:i + 64]) for i in range(0, f.size, 64)])
    k = int(np.argmax(values))
    if k in (0, f.size - 1):
        return RAPeak(float(values[k]), float(f[k]))

    def slope(x: float) -> float:
        """d ln RA / d omega at x [Hz] (the sign of dRA/df)."""
        w = 2 * np.pi * x
        lu = lu_factor(1j * w * M - S)
        z = lu_solve(lu, b)
        dz = lu_solve(lu, -1j * (M @ z))
        G = V @ z * (1j * w) + u * (R @ z)
        dG = V @ dz * (1j * w) + 1j * (V @ z) + u * (R @ dz)
        g = (G.conj() * dG).real / (G.conj() * G).real
        return float(g[1] - g[0])

    a, c = float(f[k - 1]), float(f[k + 1])
    sa, sc = slope(a), slope(c)
    if sa > 0 > sc:
        x = brentq(slope, a, c, xtol=1e-13, rtol=4 * np.finfo(float).eps)
    else:                           # no sign change across the bracket (flat to rounding): search the value
        res = minimize_scalar(lambda x: -ra1(x), bracket=(f[k - 1], f[k], f[k + 1]),
                              bounds=None, method="brent", options={"xtol": 1e-9})
        x = float(min(max(res.x, lo), hi))
    return RAPeak(ra1(x), x)


@dataclass(frozen=True)
class YawDamping:
    """The ratio-method yaw damping of a pulse steer (SPEC section 12).

    Attributes
    ----------
    value : float or None
        The smallest per-joint value (None if no joint has two amplitudes).
    per_joint : list of (float or None)
        Each joint's mean ratio damping.
    amplitudes : list of numpy.ndarray
        The kept peak-to-peak amplitudes P_i of each joint [rad].
    extrema : list of (numpy.ndarray, numpy.ndarray)
        Times [s] and values [rad] of each joint's extrema after the pulse.
    modal_least_damping_ratio : float or None
        The modal zeta_min beside it (several modes of near frequency make the ratio
        method read low).
    response : ManoeuvreResponse
    why : str
        Why ``value`` is None.
    lower_bound : float or None
        When every joint is heavily damped (fewer than two kept amplitudes: a decay faster
        than x20 per half cycle), the bound ``YDC_HEAVY_ZETA`` = 0.6901 its value is at least;
        None otherwise.
    """

    value: float | None
    per_joint: list
    amplitudes: list
    extrema: list
    modal_least_damping_ratio: float | None
    response: ManoeuvreResponse
    why: str = ""
    lower_bound: float | None = None


def ratio_damping(extrema_values) -> tuple[float | None, np.ndarray]:
    """The ratio method on a signal's successive extrema (time order): the peak-to-peak
    amplitudes P_i = |A_(i+1) - A_i|; the free decay starts at the largest (the amplitudes
    before it are the forced response); from it on, those >= 5 % of it (a smaller one is
    skipped, later ones still count), the first six; the mean over consecutive pairs of kept
    amplitudes of zeta = d / sqrt(pi^2 + d^2), d = ln(P_i/P_(i+1)); None when fewer than two are
    kept (SPEC 12, corrected 2026-12).  For one damped mode ``exp(sigma t) sin(omega t)`` it is
    exactly -sigma / |lambda|.

    Examples
    --------
    >>> import numpy as np
    >>> lam = -0.3 + 2.0j                     # extrema of exp(-0.3 t) sin(2 t + phi) are pi/2 apart
    >>> A = np.exp(lam.real * np.pi / 2 * np.arange(8)) * (-1.0) ** np.arange(8)
    >>> round(ratio_damping(A)[0], 12) == round(-lam.real / abs(lam), 12)
    True
    """
    v = np.asarray(extrema_values, dtype=float)
    P = np.abs(np.diff(v))
    if P.size:
        P = P[int(np.argmax(P)):]                  # the free decay starts at the largest amplitude
        P = P[P >= YDC_MIN_FRACTION * P[0]][:YDC_MAX_AMPLITUDES]
    if P.size < 2:
        return None, P
    d = np.log(P[:-1] / P[1:])
    return float(np.mean(d / np.sqrt(np.pi ** 2 + d ** 2))), P


def yaw_damping_coefficient(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> YawDamping:
    """PBS-style yaw damping: the pulse ``pulse:0.01:0.5``; for each joint the extrema of
    its articulation angle from the end of the pulse to 40 s after (zeros of theta',
    located on the continuous response), their peak-to-peak amplitudes P_i = |A_(i+1) -
    A_i|, the first six of those >= 5 % of the joint's largest; each consecutive pair
    gives zeta = d / sqrt(pi^2 + d^2), d = ln(P_i / P_(i+1)); a joint's value is the mean
    of its pairs; the coefficient the smallest over joints with two amplitudes or more.
    """
    from .measures import least_damping
    return _yaw_damping(vehicle, speed_mps, tire_scale, least_damping(vehicle, speed_mps, tire_scale)[0])


def _yaw_damping(vehicle: Vehicle, speed_mps: float, tire_scale: float, zeta_modal: float | None) -> YawDamping:
    """:func:`yaw_damping_coefficient` with the modal least damping ratio already known."""
    A, D = YDC_PULSE
    steer = pulse(A, D)
    t_end = round((D + YDC_WINDOW_S) / YDC_DT_S) * YDC_DT_S
    r = response(vehicle, speed_mps, steer, t_end, YDC_DT_S, tire_scale=tire_scale)
    if vehicle.n_units < 2:
        return YawDamping(None, [], [], [], zeta_modal, r, "no joint: a single unit has no articulation angle")
    per_joint, amps, ext = [], [], []
    for t, v in r.extrema_many(vehicle.state_names[vehicle.n_units + 1:], D, D + YDC_WINDOW_S):
        inner = (t > D + 1e-12) & (t < D + YDC_WINDOW_S - 1e-12)     # the window's ends are not extrema
        t, v = t[inner], v[inner]
        ext.append((t, v))
        zeta, P = ratio_damping(v)
        amps.append(P)
        per_joint.append(zeta)
    defined = [z for z in per_joint if z is not None]
    if not defined:
        return YawDamping(None, per_joint, amps, ext, zeta_modal, r,
                          f"heavily damped: no joint has two peak-to-peak amplitudes of at least 5 % of its "
                          f"largest after the pulse (a decay faster than x20 per half cycle), so YDC >= "
                          f"{YDC_HEAVY_ZETA:.4f}", YDC_HEAVY_ZETA)
    return YawDamping(min(defined), per_joint, amps, ext, zeta_modal, r)


@dataclass(frozen=True)
class LaneChangeMeasures:
    """HSTO and the lane-change RA (SPEC section 12)."""

    hsto_m: float
    ra_lane_change: float
    final_offset_m: float
    response: ManoeuvreResponse
    rear_axle: str
    steered_axle: str


def lane_change_measures(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0,
                         accel_g: float = LANE_CHANGE[0], f_hz: float = LANE_CHANGE[1]) -> LaneChangeMeasures:
    """The path-following lane change ``lane-change:0.15g:0.4``: the largest overshoot of
    the last unit's rearmost axle beyond the steered axle's final offset A0/(2 pi F^2)
    over 0 <= t <= 1/F + 8 s (0 if none), and max|a_N| / max|a_s|.

    Raises
    ------
    ManoeuvreError
        No steered axle, an unstable inverse system, or a steer beyond [-1, 1] rad.
    """
    steer = lane_change(accel_g * G_MPS2, f_hz)
    t_end = round((1.0 / f_hz + LANE_CHANGE_TAIL_S) / DT_S) * DT_S
    r = response(vehicle, speed_mps, steer, t_end, DT_S, tire_scale=tire_scale)
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


@dataclass(frozen=True)
class SteadyTurn:
    """The steady turn of HSSO (SPEC section 12, as corrected 2026-12).

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
    """The steady turn with the tractor's yaw rate u/R (SPEC section 12, corrected 2026-12): the
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

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> t = steady_turn(load_preset("tractor_semitrailer"), 0.5)      # walking pace: kinematic
    >>> bool(-1.0 < t.hsso_m < 0.0)                                  # the trailer tracks inside
    True
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    if not vehicle.steered_axles:
        raise ManoeuvreError(f"{vehicle.name} has no steered axle: no steer holds a turn")
    co = system_coefficients(vehicle)
    u = float(speed_mps)
    omega = u / radius_m
    x, delta = steady_with_yaw_rate(vehicle, u, np.zeros(vehicle.n_states), omega, tire_scale)
    beta = (co.velocity_map(u) @ x) / u             # CG sideslip of every unit
    d = chain_on_circle(vehicle, beta, radius_m)

    def radius(unit, xp):
        return math.hypot(xp + beta[unit] * d[unit], d[unit])

    steered = max(vehicle.steered_axles, key=lambda a: a.x_m)
    rear = vehicle.units[-1].rearmost_axle
    paths = {a.name: radius(i, a.x_m) for i, a in zip(vehicle.axle_units, vehicle.axles)}
    hsso = radius(vehicle.n_units - 1, rear.x_m) - radius(0, steered.x_m)
    return SteadyTurn(float(hsso), delta, float(radius_m), x, paths, beta, d)


def point_path(vehicle: Vehicle, response: ManoeuvreResponse, unit: int, x_m: float) -> np.ndarray:
    """Global lateral position [m] of any point of any unit in a manoeuvre (first order)."""
    c = point_lateral_map(vehicle, unit, x_m)
    Theta = np.column_stack([response[f"Theta{k + 2}"] for k in range(vehicle.n_units - 1)]) \
        if vehicle.n_units > 1 else np.zeros((response.time.size, 0))
    return c[0] * response["psi1"] + c[1] * response["Y1"] + Theta @ c[2:]
