"""Runs with inputs held over each interval (zero-order hold), exact: :func:`simulate` (any time
grid, the speed changing between intervals, a steer angle optionally), :func:`step_response`
(the thesis' step input from rest) and :func:`iter_step_response` (the samples one at a time,
constant memory); :class:`OutputMap`, the rows of every signal over a piece's state, which the
manoeuvres of :mod:`lcvreport.analysis.exact` share.  Each returns the package's one
:class:`~lcvreport.analysis.time_response.TimeResponse`.  SI throughout.

Examples
--------
>>> from lcvreport import load_preset, one_percent_rule, load_vector, step_response
>>> v = load_preset("aucnat")
>>> r = step_response(v, 22.352, load_vector(v, one_percent_rule(v, ["trailer3"])), t_end=10.0)
>>> r["y6"].shape, round(float(r["y6"][-1]), 4)        # rear of trailer 3 [m]
((1001,), 0.0117)
>>> r.units()["ay2"], r.columns()[:3]
('m/s^2', ['time_s', 'v1_m_per_s', 'r1_rad_per_s'])
"""
from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..ranges import RANGES, RangeError
from .discretize import GLOBAL_STATES, Discretizer, augmented_state_matrix
from .time_response import Segment, TimeResponse


class OutputMap:
    """Every signal of a response of ``model`` at one speed as a row over ``z = [x, psi1, Y1, xi,
    1]``: the steer (when known), the states, psi1, Y1, every unit's ``ay`` (its CG), ``a_steer``
    (the frontmost steered axle's centre), ``Y_<axle>`` (every axle centre's global lateral
    position), ``Y_rear`` (the last unit's rear end), the model's further outputs
    (:meth:`~lcvreport.model.linear.LinearModel.extra_signals`), and hidden rows for the rear
    offsets ``y2..yN``.

    Parameters
    ----------
    co : LinearModel
    speed_mps, tire_scale : float
    axle_force_N : numpy.ndarray, optional
        Each axle's constant lateral tire force of the residual sources [N] (the load transfers).
    steer_known : bool
        Whether the pieces give the steer as a row (``d_row``); without it the response has no
        ``delta`` signal and F is the whole forcing.
    """

    def __init__(self, co, speed_mps: float, tire_scale: float, axle_force_N: np.ndarray | None = None,
                 steer_known: bool = True):
        vehicle = co.vehicle
        u = float(speed_mps)
        n, nu = co.n_states, vehicle.n_units
        self.n, self.nu, self.m, self.u = n, nu, n + 2, u
        self.steer_known = steer_known
        Ca, Da = co.acceleration_maps(u, tire_scale)
        self.V_ay = np.zeros((nu, n + 2))
        self.V_ay[:, :n] = Ca
        self.Da = Da
        self.da = Da @ co.B_delta(tire_scale)
        self.xs = steered_point(vehicle) if vehicle.steered_axles else None
        Y_rows, Y_names = [], []
        for i, unit in enumerate(vehicle.units):
            for a in unit.axles:
                Y_rows.append(co.point_lateral_row(i, a.x_m))
                Y_names.append(f"Y_{a.name}")
        Y_rows.append(co.point_lateral_row(nu - 1, vehicle.rear_end_x_m(nu - 1)))
        Y_names.append("Y_rear")
        self.Y_rows = np.array(Y_rows)
        ex_names, self.EX, self.EXD, self.ED, EO = co.extra_signals(u, tire_scale)
        self.ex_const = EO @ (np.zeros(len(vehicle.axles)) if axle_force_N is None
                              else np.asarray(axle_force_N, float))
        self.cum = co.heading_rows()
        roll_rows = co.roll_offset_rows()
        self.roll_rows = roll_rows
        hidden_roll = [] if roll_rows is None else [f"Roff{k + 2}" for k in range(nu - 1)]
        self.names = tuple((["delta"] if steer_known else []) + list(co.state_names) + list(GLOBAL_STATES) +
                           [f"ay{i + 1}" for i in range(nu)] + ["a_steer"] + Y_names + list(ex_names) +
                           [f"Theta{k + 2}" for k in range(nu - 1)] + hidden_roll)

    def rows(self, Mz: np.ndarray, d_row: np.ndarray | None, F: np.ndarray) -> np.ndarray:
        """The rows of every signal (``names``) for a piece with dynamics ``Mz``, steer row
        ``d_row`` (delta = d_row . z) and constant generalized force ``F`` beside the steer (SI)."""
        n, nu, m = self.n, self.nu, self.m
        dim = Mz.shape[0]
        C = np.zeros((len(self.names), dim))
        r0 = 0
        if self.steer_known:
            C[0] = d_row
            r0 = 1
        C[r0:r0 + m, :m] = np.eye(m)
        r0 += m
        C[r0:r0 + nu, :m] = self.V_ay
        if self.steer_known:
            C[r0:r0 + nu] += np.outer(self.da, d_row)
        C[r0:r0 + nu, -1] += self.Da @ F
        r0 += nu
        if self.xs is not None:
            # a_s = v1' + x_s r1' + u r1: from the state derivative
            C[r0] = Mz[0] + self.xs * Mz[1]
            C[r0, 1] += self.u
        r0 += 1
        ny = len(self.Y_rows)
        C[r0:r0 + ny, :m] = self.Y_rows
        r0 += ny
        ne = len(self.ex_const)
        if ne:
            # y = X x + XD x' + D delta + O F_y0, x' from the augmented dynamics' first n rows
            C[r0:r0 + ne, :n] = self.EX
            C[r0:r0 + ne] += self.EXD @ Mz[:n]
            if self.steer_known:
                C[r0:r0 + ne] += np.outer(self.ED, d_row)
            C[r0:r0 + ne, -1] += self.ex_const
        r0 += ne
        C[r0:r0 + nu - 1, :m] = self.cum
        if self.roll_rows is not None:
            C[r0 + nu - 1:r0 + 2 * (nu - 1), :n] = self.roll_rows
        return C

class ManoeuvreError(ValueError):
    """A manoeuvre the vehicle cannot perform (no steered axle; an unstable inverse system)."""


def steered_point(vehicle: Vehicle) -> float:
    """Signed x [m] of the frontmost steered axle on the first unit."""
    if not vehicle.steered_axles:
        raise ManoeuvreError(f"{vehicle.name} has no steered axle: no steer input to apply")
    return max(a.x_m for a in vehicle.steered_axles)

# ---------------------------------------------------------------------------- held inputs
def held_response(vehicle: Vehicle, time: np.ndarray, Z: np.ndarray, speed_mps: np.ndarray, forces: np.ndarray,
                  tire_scale: float = 1.0, delta_rad: np.ndarray | None = None, model: str = "yaw_plane",
                  axle_force_N: np.ndarray | None = None, label: str = "") -> TimeResponse:
    """The :class:`TimeResponse` of a run whose inputs are held from each sample on, from its
    samples ``Z`` (``[x, psi1, Y1]`` at every time point, computed by the caller exactly): the
    samples with the same speed, force, steer and step make one piece each.

    Parameters
    ----------
    vehicle : Vehicle
    time : numpy.ndarray, shape (K,)
        [s]
    Z : numpy.ndarray, shape (K, n + 2)
    speed_mps : numpy.ndarray, shape (K,)
        Forward speed held from each sample on [m/s] (the last: at the last sample).
    forces : numpy.ndarray, shape (K, n)
        Generalized force held from each sample on, beside the steer, SI.
    tire_scale : float
    delta_rad : numpy.ndarray, shape (K,), optional
        The steer held from each sample on [rad] (it enters as ``B_delta * delta``); without it
        the response has no ``delta`` signal and ``forces`` are the whole forcing.  The outputs
        with a direct feed-through (``ay``, ``a_steer``, the load transfers) at a sample take the
        input held from it on.
    model : str
    axle_force_N : numpy.ndarray, optional
        Each axle's constant lateral tire force of the residual sources [N].
    label : str
    """
    co = linear_model(vehicle, model)
    n = co.n_states
    m = n + 2
    t = np.asarray(time, dtype=float)
    u = np.asarray(speed_mps, dtype=float)
    f = np.asarray(forces, dtype=float)
    d = None if delta_rad is None else np.asarray(delta_rad, dtype=float)
    K = t.size
    h = np.diff(t)
    # pieces: maximal runs of samples with the same speed, force, steer and step (to rounding)
    new = (u[1:] != u[:-1]) | np.any(f[1:] != f[:-1], axis=1)
    if d is not None:
        new |= d[1:] != d[:-1]
    if K > 2:
        new[:-1] |= np.abs(h[1:] - h[:-1]) > 1e-9 * h[:-1]           # the last sample has no step of its own
    starts = [0, *(np.flatnonzero(new) + 1).tolist(), K]
    maps = {}
    segments = []
    Zaug = np.column_stack([Z, np.ones(K)])
    row_names = None
    for i0, i1 in zip(starts[:-1], starts[1:]):                       # samples i0..i1-1
        if float(u[i0]) not in maps:
            maps[float(u[i0])] = (augmented_state_matrix(co, u[i0], tire_scale),
                                  OutputMap(co, u[i0], tire_scale, axle_force_N, steer_known=d is not None))
        (Aa, Ga), omap = maps[float(u[i0])]
        total = f[i0] if d is None else f[i0] + co.B_delta(tire_scale) * d[i0]
        Mz = np.zeros((m + 1, m + 1))
        Mz[:m, :m] = Aa
        Mz[:m, -1] = Ga @ total
        d_row = None
        if d is not None:
            d_row = np.zeros(m + 1)
            d_row[-1] = d[i0]
        C = omap.rows(Mz, d_row, f[i0])
        row_names = omap.names
        end = i1 < K
        seg = Segment(Mz, C, i0, Zaug[i0:i1], float(t[i0]), Zaug[i0], Zaug[i1] if end else None,
                      float(t[i1]) if end else math.inf)
        segments.append(seg)
    speed = float(u[0]) if np.all(u == u[0]) else u.copy()
    return TimeResponse(vehicle, t, row_names, segments, speed, model, float(tire_scale), None, label)


def _check_time(time: np.ndarray) -> np.ndarray:
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 1 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise ValueError("time must be a 1-D, finite, strictly increasing array [s]")
    h = np.diff(t)
    r = RANGES["step_size"]
    if h.size and (h.min() < r.low or h.max() > r.high):
        bad = h.min() if h.min() < r.low else h.max()
        raise RangeError("time", f"time steps must be in {r.text()}, got {bad:.6g}")
    return t


def _not_finite() -> FloatingPointError:
    return FloatingPointError("the response is not finite: the vehicle is unstable at this speed and the "
                              "time span is too long for its growth")


def simulate(vehicle: Vehicle, time: np.ndarray, speed_mps: float | np.ndarray, forces: np.ndarray,
             tire_scale: float = 1.0, initial_state: np.ndarray | None = None,
             discretizer: Discretizer | None = None, label: str = "", delta_rad: np.ndarray | None = None,
             model: str = "yaw_plane", axle_force_N: np.ndarray | None = None) -> TimeResponse:
    """Exact response to generalized forces held constant between time points.

    Parameters
    ----------
    vehicle : Vehicle
    time : numpy.ndarray, shape (K,)
        Increasing time points [s]; any spacing.
    speed_mps : float or numpy.ndarray, shape (K-1,)
        Forward speed on each interval [m/s].
    forces : numpy.ndarray, shape (n,) or (K-1, n)
        Generalized force on each interval (zero-order hold), SI.  A steer angle enters either
        here as ``co.B_delta(tire_scale) * delta`` or through ``delta_rad``.
    tire_scale : float
    initial_state : numpy.ndarray, shape (n+2,), optional
        ``[x, psi1, Y1]`` at ``time[0]``; rest when omitted.
    discretizer : Discretizer, optional
        Reuse a cache across calls.
    label : str
    delta_rad : float or numpy.ndarray, shape (K-1,), optional
        The steer angle held on each interval [rad]: the response then has the ``delta``
        signal, and the model's further outputs (the yaw-roll model's load transfers) count it.
    model : str
        The linear model (default the yaw plane).
    axle_force_N : numpy.ndarray, optional
        Each axle's constant lateral tire force of the residual sources [N] (load transfers).

    Returns
    -------
    TimeResponse
        Exact at every time point and between them for the held inputs.

    Raises
    ------
    FloatingPointError
        A response that overflows (an unstable vehicle over a long time span).

    Examples
    --------
    >>> import numpy as np
    >>> from lcvreport import load_preset, simulate, steady_state, system_coefficients
    >>> v = load_preset("tractor_semitrailer")
    >>> r = simulate(v, np.linspace(0.0, 20.0, 201), 24.4444, np.zeros(4), delta_rad=0.01)
    >>> x_ss = steady_state(v, 24.4444, system_coefficients(v).B_delta() * 0.01)
    >>> round(float(r["ay1"][-1]), 6), round(24.4444 * float(x_ss[1]), 6)   # the steady turn: a1 = u r1 [m/s^2]
    (0.467021, 0.467021)
    """
    t = _check_time(time)
    k = t.size - 1
    u = np.broadcast_to(np.asarray(speed_mps, dtype=float), (k,))
    check_speed(u)
    check_tire_scale(tire_scale)
    n = linear_model(vehicle, model).n_states
    f = np.broadcast_to(np.asarray(forces, dtype=float), (k, n))
    d = None if delta_rad is None else np.broadcast_to(np.asarray(delta_rad, dtype=float), (k,))
    ftot = f if d is None else f + linear_model(vehicle, model).B_delta(tire_scale)[None, :] * d[:, None]
    disc = discretizer or Discretizer(vehicle, model=model)
    z = np.zeros((t.size, n + 2))
    if initial_state is not None:
        z[0] = initial_state
    h = np.diff(t)
    for i in range(k):
        Ad, Gd = disc(u[i], h[i], tire_scale)
        z[i + 1] = Ad @ z[i] + Gd @ ftot[i]
    if not np.all(np.isfinite(z)):
        raise _not_finite()
    if k:      # the inputs from each sample on: the last sample's are the last interval's
        u, f = np.r_[u, u[-1:]], np.concatenate([f, f[-1:]])
        d = None if d is None else np.r_[d, d[-1:]]
    else:
        u = np.broadcast_to(np.asarray(speed_mps, dtype=float), (1,))
        f = np.broadcast_to(np.asarray(forces, dtype=float), (1, n))
        d = None if d is None else np.broadcast_to(np.asarray(delta_rad, dtype=float), (1,))
    return held_response(vehicle, t, z, u, f, tire_scale, d, model, axle_force_N, label)


def step_response(vehicle: Vehicle, speed_mps: float, F: np.ndarray, t_end: float, n_points: int = 1001,
                  tire_scale: float = 1.0, label: str = "") -> TimeResponse:
    """Exact response from rest to a constant generalized force F (the thesis' step input).

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    F : numpy.ndarray, shape (2N,)
        Generalized force, SI.
    t_end : float
        End time [s].
    n_points : int
        Number of evenly spaced output points including t = 0.
    tire_scale : float
    label : str

    Returns
    -------
    TimeResponse
        The states and outputs at ``n_points`` times, SI.

    Raises
    ------
    FloatingPointError
        A response that overflows (an unstable vehicle over a long time span).

    Examples
    --------
    >>> import numpy as np
    >>> from lcvreport import load_preset
    >>> F = np.zeros(12); F[0] = 1000.0
    >>> r = step_response(load_preset("aucnat"), 24.4, F, t_end=5.0, n_points=51)
    >>> r["y6"].shape
    (51,)
    """
    RANGES["t_end"].check(t_end, "t_end")
    t = np.linspace(0.0, float(t_end), int(n_points))
    if t.size < 2:
        return simulate(vehicle, t, speed_mps, F, tire_scale=tire_scale, label=label)
    # one matrix exponential for the one step t_end / (n - 1): the differences of the linspace
    # points differ in their last bits (12 distinct step sizes at 1001 points), each of which
    # would cost an exponential of its own; the states are those at k * h, which the time
    # points equal to rounding
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    n = linear_model(vehicle).n_states
    f = np.broadcast_to(np.asarray(F, dtype=float), (n,))
    Ad, Gd = Discretizer(vehicle, maxsize=1)(float(speed_mps), float(t_end) / (t.size - 1), tire_scale)
    b = Gd @ f
    z = np.zeros((t.size, n + 2))
    for i in range(t.size - 1):
        z[i + 1] = Ad @ z[i] + b
    if not np.all(np.isfinite(z)):
        raise _not_finite()
    return held_response(vehicle, t, z, np.full(t.size, float(speed_mps)), np.broadcast_to(f, (t.size, n)),
                         tire_scale, label=label)


def iter_step_response(vehicle: Vehicle, speed_mps: float, F: np.ndarray, dt: float, n_steps: int,
                       tire_scale: float = 1.0) -> Iterator[tuple[float, np.ndarray]]:
    """Yield ``(t [s], z)`` at t = 0, dt, ..., n_steps*dt of the exact step response from
    rest, one sample at a time (constant memory).

    Raises
    ------
    FloatingPointError
        When the state stops being finite (an unstable vehicle over a long span).
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    Ad, Gd = Discretizer(vehicle, maxsize=1)(speed_mps, dt, tire_scale)
    b = Gd @ np.asarray(F, dtype=float)
    z = np.zeros(linear_model(vehicle).n_states + 2)
    yield 0.0, z
    for k in range(1, int(n_steps) + 1):
        with np.errstate(over="ignore", invalid="ignore"):   # checked just below
            z = Ad @ z + b
        if not np.all(np.isfinite(z)):
            raise FloatingPointError(f"the response is not finite after {k * dt:g} s: the vehicle is unstable at "
                                     "this speed and grows without bound")
        yield k * dt, z
