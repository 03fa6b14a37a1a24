"""Exact response to continuous steer inputs and constant residual sources (docs/manoeuvres.md).

On each piece of the input (:mod:`lcvreport.manoeuvres.steer`) the model, the global
position (psi1, Y1), the input's generator ``xi' = E xi`` and a constant 1 form one
homogeneous linear system ``z' = Mz z``::

    z = [x, psi1, Y1, xi, 1],   Mz = [[A_aug, b h, g], [0, E, 0], [0, 0, 0]]

so ``z(t + s) = exp(Mz s) z(t)`` exactly, for any s.  Samples on a uniform grid take one
exponential per piece and a doubling scan (``Z[k:2k] = Z[0:k] Phi^k``, log2 K products).
The result is the package's one :class:`~lcvreport.analysis.time_response.TimeResponse`:
every output a row over z, its extrema located between the samples.

The lane change prescribes the steered axle's lateral acceleration ``a_s`` instead of
the steer: ``a_s = C_s x + D_s delta + f_s`` (``D_s != 0``: direct feed-through), so
``delta = (a_s - C_s x - f_s) / D_s`` and the model is driven by ``a_s`` through
``A - b C_s / D_s`` (the inverse system).  Its eigenvalues are the zeros of the
transfer function from the steer to ``a_s``; one in the right half plane makes the
manoeuvre impossible for a driver to follow, and it is refused.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.manoeuvres.steer import sine
>>> r = response(load_preset("tractor_semitrailer"), 24.4444, sine(0.01, 0.4), t_end=10.0, dt=0.01)
>>> r.time.shape, r["ay2"].shape
((1001,), (1001,))
"""
from __future__ import annotations

import math

import numpy as np

from ..manoeuvres.steer import SteerInput
from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from .discretize import augmented_state_matrix
from .extrema import power_scan
from .response import ManoeuvreError, OutputMap, steered_point
from .time_response import Segment, TimeResponse, expm

#: the response of a manoeuvre is the package's one time response
ManoeuvreResponse = TimeResponse

__all__ = ["ManoeuvreError", "ManoeuvreResponse", "check_lane_change_steer", "expm", "final_state", "response",
           "steered_point"]


def _steer_axle_maps(vehicle, speed_mps, tire_scale, model: str = "yaw_plane"):
    """x' = A x + b delta (+ G F); a_s = Cs x + Ds delta (+ Js G F)."""
    co = linear_model(vehicle, model)
    A, G = co.state_derivative_maps(speed_mps, tire_scale)
    b = G @ co.B_delta(tire_scale)
    xs = steered_point(vehicle)
    Js = np.zeros(A.shape[0])
    Js[0], Js[1] = 1.0, xs                      # v_s = v1 + x_s r1
    Cs = Js @ A
    Cs[1] += float(speed_mps)                   # a_s = v_s' + u r1
    return A, b, Cs, float(Js @ b)


def response(vehicle: Vehicle, speed_mps: float, steer: SteerInput, t_end: float, dt: float,
             F: np.ndarray | None = None, tire_scale: float = 1.0, t_start: float = 0.0,
             state: np.ndarray | None = None, model: str = "yaw_plane",
             axle_force_N: np.ndarray | None = None) -> TimeResponse:
    """The exact response from rest to ``steer`` (continuous) and the constant
    generalized force ``F`` (residual sources, SI), sampled every ``dt`` to ``t_end``.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    steer : SteerInput
        See :mod:`lcvreport.manoeuvres.steer`; a lane change is solved through the
        inverse system.
    t_end, dt : float
        End time and output step [s]; ``dt`` must divide ``t_end``.
    F : numpy.ndarray, optional
        Constant generalized force (n,) of the residual sources, SI: :func:`lcvreport.load_vector` or
        :meth:`lcvreport.model.yaw_plane.loads.ResidualSources.vector`.
    tire_scale : float
    t_start, state : float, numpy.ndarray, optional
        Start later than 0 from ``state`` = [x, psi1, Y1] at ``t_start`` (a run in
        chunks); the samples are then ``t_start + k dt``.
    model : str
        The linear model (:data:`lcvreport.model.linear.MODELS`; default the yaw plane):
        its states, and the positions, accelerations and further outputs it defines
        (:meth:`~lcvreport.model.linear.LinearModel.extra_signals`: the yaw-roll model's
        ``as<i>``, ``dFz_<axle>``, ``ltr<g>``).
    axle_force_N : numpy.ndarray, optional
        Each axle's constant lateral tire force of the residual sources [N] (P plus the
        misalignment's ``s C_F eps``): the load transfer outputs include it.

    Raises
    ------
    ManoeuvreError
        No steered axle; a lane change whose inverse system is unstable.
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    u = float(speed_mps)
    span = t_end - t_start
    n_steps = int(round(span / dt))
    if n_steps < 1 or abs(n_steps * dt - span) > 1e-9 * max(span, 1.0):
        raise ValueError(f"dt = {dt:g} s must divide t_end - t_start = {span:g} s")
    co = linear_model(vehicle, model)
    n = co.n_states
    m = n + 2
    Aa, Ga = augmented_state_matrix(co, u, tire_scale)
    F = np.zeros(n) if F is None else np.asarray(F, dtype=float)
    gF = Ga @ F                                           # constant forcing of [x, psi1, Y1]
    bd_x = Ga @ co.B_delta(tire_scale)
    lane = steer.prescribes_acceleration
    if lane:
        A_x, b, Cs, Ds = _steer_axle_maps(vehicle, u, tire_scale, model)
        if abs(Ds) < 1e-12 * max(1.0, np.abs(Cs).max()):
            raise ManoeuvreError("lane change: the steer does not reach the steered axle's lateral acceleration "
                                 "directly; the inverse system does not exist")
        zeros = np.linalg.eigvals(A_x - np.outer(b, Cs) / Ds)
        if zeros.real.max() > 1e-9 * max(1.0, np.abs(zeros).max()):
            worst = zeros[np.argmax(zeros.real)]
            raise ManoeuvreError(f"lane change at {u * 3.6:.1f} km/h: the inverse system is unstable (a right-half-"
                                 f"plane zero of the steer-to-axle-acceleration transfer function at "
                                 f"{worst.real:.4g}{worst.imag:+.4g}j 1/s): no steer makes the steered axle "
                                 "follow the path; the manoeuvre is refused")
        fs = float(np.r_[1.0, steered_point(vehicle)] @ (co.state_derivative_maps(u, tire_scale)[1] @ F)[:2])
    driver = steer.driver
    if driver is not None:
        if not vehicle.steered_axles:
            raise ManoeuvreError(f"{steer.spec}: the vehicle has no steered axle for the driver to steer")
        closed = Aa.copy()
        closed[:, n + 1] -= driver[0] * bd_x
        closed[:, n] -= driver[0] * u * driver[1] * bd_x
        poles = np.linalg.eigvals(closed)
        if poles.real.max() > 1e-9 * max(1.0, np.abs(poles).max()):
            worst = poles[np.argmax(poles.real)]
            raise ManoeuvreError(f"{steer.spec} at {u * 3.6:.1f} km/h: the driver's closed loop is unstable (a pole at "
                                 f"{worst.real:.4g}{worst.imag:+.4g}j 1/s): lower the gain K or lengthen the preview "
                                 "T; the manoeuvre is refused")
    omap = OutputMap(co, u, tire_scale, axle_force_N, steer_known=True)
    segments = []
    t_grid = t_start + np.arange(n_steps + 1) * dt
    z_state = np.zeros(m) if state is None else np.asarray(state, dtype=float)   # [x, psi1, Y1]
    for piece in steer.pieces:
        if piece.t0 > t_end + 1e-12:
            break
        if piece.t1 <= t_start + 1e-12 * max(1.0, t_start):
            continue
        if piece.t0 < t_start:                     # the piece began before this run: move its generator on
            piece = type(piece)(t_start, piece.t1, piece.E, piece.h, expm(piece.E * (t_start - piece.t0)) @ piece.xi0)
        p = piece.E.shape[0]
        dim = m + p + 1
        Mz = np.zeros((dim, dim))
        if lane:
            # x' = (A - b Cs/Ds) x + b (a_s - fs)/Ds + G F; psi1, Y1 as before
            Mz[:m, :m] = Aa
            Mz[:n, :n] = A_x - np.outer(b, Cs) / Ds
            Mz[:n, m:m + p] = np.outer(b, piece.h) / Ds
            Mz[:m, -1] = gF
            Mz[:n, -1] -= b * fs / Ds
        elif driver is not None:
            # the preview driver: delta = K (path - Y1 - u T psi1), the path generated by the piece
            d_row = np.zeros(dim)
            d_row[m:m + p] = driver[0] * piece.h
            d_row[n + 1] = -driver[0]
            d_row[n] = -driver[0] * u * driver[1]
            Mz[:m, :m] = Aa
            Mz[:m] += np.outer(bd_x, d_row)
            Mz[:m, -1] = gF
        else:
            Mz[:m, :m] = Aa
            Mz[:m, m:m + p] = np.outer(bd_x, piece.h)
            Mz[:m, -1] = gF
        Mz[m:m + p, m:m + p] = piece.E
        # output rows over z = [x, psi1, Y1, xi, 1]
        if lane:
            d_row = np.zeros(dim)
            d_row[:n] = -Cs / Ds
            d_row[m:m + p] = piece.h / Ds
            d_row[-1] = -fs / Ds
        elif driver is None:
            d_row = np.zeros(dim)
            d_row[m:m + p] = piece.h
        C = omap.rows(Mz, d_row, F)
        z0 = np.r_[z_state, piece.xi0, 1.0]
        t1 = min(piece.t1, math.inf)
        ka = int(math.ceil((piece.t0 - t_start) / dt - 1e-9))
        kb = n_steps if t1 > t_end + 1e-12 else int(math.ceil((t1 - t_start) / dt - 1e-9)) - 1
        count = kb - ka + 1
        if count > 0:
            ta = t_start + ka * dt
            za = z0 if abs(ta - piece.t0) <= 1e-12 * max(1.0, piece.t0) else expm(Mz * (ta - piece.t0)) @ z0
            Phi = expm(Mz * dt)
            Z = power_scan(Phi, za, count)
            z_end = expm(Mz * (t1 - (t_start + kb * dt))) @ Z[-1] \
                if math.isfinite(t1) and t1 <= t_end + 1e-12 else None
        else:
            Z = np.zeros((0, dim))
            z_end = expm(Mz * (t1 - piece.t0)) @ z0 if math.isfinite(t1) else None
        segments.append(Segment(Mz, C, ka, Z, piece.t0, z0, z_end, t1))
        if z_end is None:
            break
        z_state = z_end[:m]
    return TimeResponse(vehicle, t_grid, omap.names, segments, u, model, float(tire_scale), steer)


def check_lane_change_steer(r: TimeResponse, peak_rad: float | None = None) -> None:
    """Refuse a lane change whose steer -- the output of the inverse system, not an input the
    user gave -- leaves the steer range of the ranges table ([-1, 1] rad: far beyond the small
    angles of the linear model), naming the peak steer it would need.  ``peak_rad`` is max|delta|
    when the caller has it (else it is located on the continuous response).

    Raises
    ------
    ManoeuvreError
    """
    from ..ranges import RANGES
    steer = getattr(r, "steer", None)
    if not getattr(steer, "prescribes_acceleration", False) and getattr(steer, "driver", None) is None:
        return
    peak = float(r.peaks_abs(["delta"])[0]) if peak_rad is None else float(peak_rad)
    rng = RANGES["steer_angle"]
    if not peak <= rng.high:
        raise ManoeuvreError(f"{r.steer.spec} at {r.speed_mps * 3.6:.4g} km/h needs a peak steer of {peak:.4g} rad, "
                             f"outside the steer range {rng.text()} (the linear model's small angles): lower A0 or "
                             "the frequency, or raise the speed; the manoeuvre is refused")


def final_state(r: TimeResponse) -> np.ndarray:
    """[x, psi1, Y1] at the last sample of ``r`` (to continue a run in chunks)."""
    return r.final_state()
