r"""One implicit integration of any model of a vehicle (:class:`~lcvreport.model.base.VehicleModel`):
a steer input, residual sources and a speed in, a :class:`~lcvreport.analysis.sampled.SampledResponse`
out (docs/nonlinear.md#integration).

The integrator is scipy's ``Radau`` (implicit, order 5, stiff-stable: at walking pace the tires'
lateral dynamics are much faster than the vehicle's), restarted at every breakpoint of the steer
(a sine's end, a table's samples) so that no step straddles a kink; each stretch's dense output
is kept, the samples are read from it, and extrema are located on it between the samples.  The
steer is one of :mod:`lcvreport.manoeuvres.steer` (open loop), the preview driver of ``driver:``
(closed loop, on the model's own position), or any callable ``steer(t, x) -> delta`` (a
path-following law).  A linear model integrated so equals its exact response to the integration's
tolerance (tests/test_integrate.py: rtol 1e-8 gives every signal within 1e-6 of its peak, for
every steer input of docs/manoeuvres.md).

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.model.base import build_model
>>> from lcvreport.manoeuvres.steer import sine
>>> r = integrate(build_model(load_preset("tractor_semitrailer")), sine(0.01, 0.4), 24.4444, 10.0, 0.01)
>>> round(r.peak_abs("ay2"), 4)
0.4268
"""
from __future__ import annotations

import math

import numpy as np

from ..model.base import check_speed, check_tire_scale
from ..ranges import RANGES
from ..util.threads import one_blas_thread
from .time_response import SampledResponse

#: the integration's default relative tolerance (docs/nonlinear.md#integration)
RTOL = 1e-8
#: and absolute tolerance, in the states' SI units (a thousandth of a micro-radian, of a micrometre
#: per second: far below what any measure reads, and loose enough that the step is set by RTOL)
ATOL = 1e-10


#: the most evaluations of a model's equations one run may take (a 90-degree turn at walking pace
#: takes about 4 000, a 12 s single sine at 88 km/h about 1 000)
MAX_EVALUATIONS = 60_000


class IntegrationError(RuntimeError):
    """A run that could not be integrated: the model's own refusal (a driven axle out of friction)
    at a time, or the integrator's failure; the message names the time."""


def _breakpoints(steer, t_end: float) -> list[float]:
    """Where the steer's derivative may jump, inside (0, t_end): its pieces' starts."""
    pts = sorted({float(p.t0) for p in getattr(steer, "pieces", ()) if 0.0 < p.t0 < t_end})
    return pts


def input_vector(model, delta: float, sources=None, tire_scale: float = 1.0) -> np.ndarray:
    """``w`` of ``model`` (its :attr:`input_names`): the steer ``delta`` [rad] and the constant
    residual sources (:class:`~lcvreport.model.yaw_plane.loads.ResidualSources`: each axle's P, T
    and misalignment, the crossfall as its lateral acceleration g sin(atan(c/100)))."""
    v = model.vehicle
    w = np.zeros(len(model.input_names))
    w[0] = delta
    if sources is not None:
        na = len(v.axles)
        P, T = sources.loads.vectors(v)
        eps = sources._misalignments(v)
        w[1:1 + na], w[1 + na:1 + 2 * na], w[1 + 2 * na:1 + 3 * na] = P, T, eps
        w[-1] = 9.80665 * math.sin(math.atan(sources.crossfall_percent / 100.0))
    return w


@one_blas_thread
def integrate(model, steer, speed_mps: float, t_end: float, dt: float, tire_scale: float = 1.0, sources=None,
              x0: np.ndarray | None = None, rtol: float = RTOL, atol: float | None = None,
              label: str = "", stop=None, max_evaluations: int = MAX_EVALUATIONS) -> SampledResponse:
    """The response of ``model`` from ``x0`` (default rest, straight running) to ``steer`` at the
    held forward speed ``speed_mps`` [m/s], sampled every ``dt`` [s] to ``t_end`` [s].

    Parameters
    ----------
    model : VehicleModel
    steer : SteerInput or callable
        Open loop (:mod:`lcvreport.manoeuvres.steer`), the preview driver (``driver:``), or a
        law ``steer(t, x) -> delta`` [rad] of the time and the model's state (with an attribute
        ``vectorized = True``: of the states as columns ``x`` (n, k) at once, returning (k,)).
    speed_mps : float
    t_end, dt : float
        [s]; ``dt`` divides ``t_end``.
    tire_scale : float
    sources : ResidualSources, optional
        Constant residual sources (docs/manoeuvres.md#residual-sources).
    x0 : numpy.ndarray, optional
        The start state (the model's :attr:`state_names`; a linear model's with psi1, Y1 after).
    rtol, atol : float
        The integrator's tolerances (default :data:`RTOL` 1e-8, :data:`ATOL` 1e-10 in SI).
    label : str
    stop : callable, optional
        ``stop(t, z) -> float``: the run ends where it first falls through zero (a run that has
        left what it was meant to do: the low-speed turn's lost path); the response then ends at
        the last sample before, with :attr:`~SampledResponse.stopped_at` the time [s].
    max_evaluations : int
        The most evaluations of the model's equations the run may take (default
        :data:`MAX_EVALUATIONS`): a count, not a clock, so that a run that can no longer be
        integrated (a vehicle spinning on saturated tires) ends with the same message on any
        machine, never hangs.

    Returns
    -------
    SampledResponse

    Raises
    ------
    IntegrationError
        A driven axle out of friction (naming the axle and the time), a lane change of the
        inverse system (linear models only: their exact response), a failed integration.

    Examples
    --------
    >>> from lcvreport import build_model, load_vehicle
    >>> from lcvreport.manoeuvres.steer import sine
    >>> m = build_model(load_vehicle("examples/vehicles/b_double.toml"), "nonlinear")
    >>> r = integrate(m, sine(0.01, 0.4), 24.4, 6.0, 0.05)
    >>> float(r.time[-1]), 0.0 < r.peak_abs("fd_steer") < 0.2          # the steer tires' friction demand
    (6.0, True)
    """
    from scipy.integrate import solve_ivp
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    RANGES["t_end"].check(t_end, "t_end")
    n_steps = int(round(t_end / dt))
    if n_steps < 1 or abs(n_steps * dt - t_end) > 1e-9 * max(t_end, 1.0):
        raise ValueError(f"dt = {dt:g} s must divide t_end = {t_end:g} s")
    if getattr(steer, "prescribes_acceleration", False):
        raise IntegrationError("a lane change prescribes the steered axle's acceleration through the inverse system, "
                               "which only a linear model has (its exact response); use driver:A0:F, the closed loop")
    u = float(speed_mps)
    linear = model.kind == "linear"
    n = len(model.state_names) + (2 if linear else 0)            # a linear model: [x, psi1, Y1]
    w0 = input_vector(model, 0.0, sources, tire_scale)
    B = model.input_matrix_full(tire_scale) if linear else None
    if linear:
        A, G = model.state_derivative_maps(u, tire_scale)
        Bw_const = G @ (B[:, 1:] @ w0[1:])
        Gd = G @ B[:, 0]

    driver = getattr(steer, "driver", None)
    vectorized = bool(getattr(steer, "vectorized", False))
    if callable(steer) and not hasattr(steer, "pieces"):
        delta_of = steer
    elif driver is not None:
        K, T_p = driver

        def delta_of(t, x):                                      # the preview point's lateral error
            y, psi = _position(model, x, linear)
            return K * (float(steer.delta(t)[0]) - (y + u * T_p * (psi if linear else math.sin(psi))))
    else:
        def delta_of(t, x):
            return float(steer.delta(t)[0])

    count = [0]

    def rhs(t, z):
        """z' at time t; ``z`` one state (n,) or, for the integrator's Jacobian, columns (n, k)."""
        count[0] += 1
        if count[0] > max_evaluations:
            raise _Budget(t)
        cols = z if z.ndim == 2 else z[:, None]
        if vectorized:                                            # a law of many states at once
            d = np.asarray(delta_of(t, cols), dtype=float).reshape(cols.shape[1])
        else:
            d = np.array([delta_of(t, cols[:, k]) for k in range(cols.shape[1])])
        if linear:
            x = cols[:-2]
            dx = A @ x + Bw_const[:, None] + Gd[:, None] * d
            out = np.vstack([dx, x[1], x[0] + u * cols[-2]])
        else:
            w = np.tile(w0, (cols.shape[1], 1))
            w[:, 0] = d
            out = _derivatives(model, t, cols, w, u, tire_scale, f"at t = {t:.3f} s")
        return out if z.ndim == 2 else out[:, 0]

    z0 = np.zeros(n) if x0 is None else np.asarray(x0, dtype=float).copy()
    edges = [0.0, *_breakpoints(steer, t_end), float(t_end)]
    scale = ATOL if atol is None else atol
    events = None
    if stop is not None:
        def event(t, z):
            return float(stop(t, z))
        event.terminal, event.direction = True, -1.0
        events = [event]
    pieces = []
    stopped_at = None
    for a, b in zip(edges[:-1], edges[1:]):
        try:
            sol = solve_ivp(rhs, (a, b), z0, method="Radau", rtol=rtol, atol=scale, dense_output=True,
                            vectorized=True, events=events)
        except _Budget as exc:
            raise IntegrationError(f"the integration stopped at t = {exc.args[0]:.3f} s after {max_evaluations} "
                                   "evaluations of the model's equations (the run cannot be integrated further: "
                                   "a vehicle out of control?)") from None
        if not sol.success:
            raise IntegrationError(f"the integration failed between t = {a:g} and {b:g} s: {sol.message}")
        if sol.status == 1:                                       # the stop condition
            stopped_at = float(sol.t[-1])
            pieces.append((a, stopped_at, sol.sol))
            break
        pieces.append((a, b, sol.sol))
        z0 = sol.y[:, -1]
    time = np.linspace(0.0, n_steps * dt, n_steps + 1)
    if stopped_at is not None:
        time = time[time <= stopped_at]
    r = SampledResponse(model, time, pieces, u, tire_scale, delta_of, w0, label or getattr(steer, "spec", ""))
    r.stopped_at = stopped_at
    r.evaluations = count[0]
    r.steer = steer
    return r


def _derivatives(model, t, cols, w, u, tire_scale, when: str) -> np.ndarray:
    """The model's derivatives of the states ``cols`` (columns); its refusal of a driven axle out of
    friction as an :class:`IntegrationError` saying ``when``."""
    try:
        return model.derivatives(t, cols.T, w, u, tire_scale).T
    except Exception as exc:                                      # the model's refusal, with the time
        if type(exc).__name__ == "TractionError":
            raise IntegrationError(f"{when}: {exc}") from None
        raise


class _Budget(Exception):
    """The evaluation budget spent (at the time in args[0])."""


def _position(model, x, linear: bool) -> tuple[float, float]:
    """(Y1 [m], psi1 [rad]) of the state ``x`` (a linear model's: its last two entries)."""
    if linear:
        return float(x[-1]), float(x[-2])
    return float(x[1]), float(x[2])


@one_blas_thread
def integrate_step(model, x0, w, speed_mps: float, h: float, tire_scale: float = 1.0, rtol: float = RTOL,
                   atol: float | None = None, max_evaluations: int = MAX_EVALUATIONS) -> np.ndarray:
    """The state of ``model`` (not linear: its :attr:`state_names`) ``h`` [s] after ``x0`` with
    the inputs ``w`` (the model's :attr:`input_names`) and the forward speed ``speed_mps`` [m/s]
    held: one step of a co-simulation (the nonlinear FMU's), integrated as :func:`integrate`
    integrates a run (Radau, ``rtol``, ``atol``, the same evaluation budget).

    Raises
    ------
    IntegrationError
        A driven axle out of friction (naming the axle), a failed integration.

    Examples
    --------
    >>> from lcvreport.model.base import build_model
    >>> from lcvreport.model.vehicle_file import load_vehicle
    >>> m = build_model(load_vehicle("examples/vehicles/b_double.toml"), "nonlinear")
    >>> w = m.zero_input(); w[0] = 0.01
    >>> x = integrate_step(m, np.zeros(m.n_states), w, 25.0, 0.5)
    >>> bool(x[m.state_names.index("r1")] > 0)                # 0.01 rad nose right: turning right
    True
    """
    from scipy.integrate import solve_ivp
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    u, w = float(speed_mps), np.asarray(w, dtype=float)
    count = [0]

    def rhs(t, z):
        count[0] += 1
        if count[0] > max_evaluations:
            raise _Budget(t)
        cols = z if z.ndim == 2 else z[:, None]
        out = _derivatives(model, t, cols, w, u, tire_scale, f"at {t:.3f} s into the step")
        return out if z.ndim == 2 else out[:, 0]

    try:
        sol = solve_ivp(rhs, (0.0, float(h)), np.asarray(x0, dtype=float), method="Radau", rtol=rtol,
                        atol=ATOL if atol is None else atol, vectorized=True)
    except _Budget:
        raise IntegrationError(f"the step took more than {max_evaluations} evaluations of the model's equations "
                               "(the run cannot be integrated further: a vehicle out of control?)") from None
    if not sol.success:
        raise IntegrationError(f"the integration failed: {sol.message}")
    return sol.y[:, -1].copy()
