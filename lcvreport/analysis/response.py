"""Forced response: exact for inputs held constant over each interval (zero-order hold).

:func:`simulate` steps ``z = [x, psi1, Y1]`` through the exact discretization of
:mod:`lcvreport.analysis.discretize` for any (also uneven) time grid, with the speed
changing between intervals; :func:`step_response` is the thesis' step input from
rest; :func:`iter_step_response` yields the samples one at a time (constant memory,
what ``lcv simulate`` streams).  :class:`TimeResponse` reads signals by name and
plots itself.  SI throughout.

Examples
--------
>>> from lcvreport import load_preset, one_percent_rule, load_vector, step_response
>>> v = load_preset("aucnat")
>>> r = step_response(v, 22.352, load_vector(v, one_percent_rule(v, ["trailer3"])), t_end=10.0)
>>> r["y6"].shape, round(float(r["y6"][-1]), 4)        # rear of trailer 3 [m]
((1001,), 0.0117)
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterator

import numpy as np

from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients
from ..model.yaw_plane.outputs import rear_end_global, rear_offsets
from ..ranges import RANGES, RangeError
from .discretize import GLOBAL_STATES, Discretizer


@dataclass(frozen=True)
class TimeResponse:
    """Time histories of one simulation, read by name (SI).

    Attributes
    ----------
    time : numpy.ndarray, shape (K,)
        [s]
    states : numpy.ndarray, shape (K, 2N+2)
        ``[v1 (m/s), r1..rN (rad/s), thetaA.. (rad), psi1 (rad), Y1 (m)]``.
    vehicle : Vehicle
    speed_mps : numpy.ndarray, shape (K,)
        Speed from each sample on (the last sample: the last interval's) [m/s].
    forces : numpy.ndarray, shape (K, 2N)
        Generalized force held from each sample on (SI), for the accelerations.
    tire_scale : float
    label : str
    """

    time: np.ndarray
    states: np.ndarray
    vehicle: Vehicle
    speed_mps: np.ndarray
    forces: np.ndarray
    tire_scale: float = 1.0
    label: str = ""

    @property
    def names(self) -> tuple[str, ...]:
        """State names, model order then psi1, Y1."""
        return linear_model(self.vehicle).state_names + GLOBAL_STATES

    @property
    def signal_names(self) -> tuple[str, ...]:
        """Every signal :meth:`__getitem__` knows."""
        n = self.vehicle.n_units
        return self.names + tuple(f"y{k}" for k in range(2, n + 1)) + ("Y_rear",) + tuple(
            f"ay{i}" for i in range(1, n + 1))

    def __getitem__(self, name: str) -> np.ndarray:
        """Signal by name: a state, ``y2``..``yN`` [m], ``Y_rear`` [m] or ``ay1``..``ayN`` [m/s^2]."""
        if name in self.names:
            return self.states[:, self.names.index(name)]
        n = self.vehicle.n_units
        if name.startswith("y") and name[1:].isdigit() and 2 <= int(name[1:]) <= n:
            return self.rear_offsets[:, int(name[1:]) - 2]
        if name == "Y_rear":
            return rear_end_global(self.vehicle, self["psi1"], self["Y1"], self.theta)
        if name.startswith("ay") and name[2:].isdigit() and 1 <= int(name[2:]) <= n:
            return self.lateral_acceleration[:, int(name[2:]) - 1]
        raise KeyError(f"unknown signal {name!r}; valid: {', '.join(self.signal_names)}")

    @property
    def theta(self) -> np.ndarray:
        """Articulation angles [rad], shape (K, N-1)."""
        n = self.vehicle.n_units
        return self.states[:, n + 1:2 * n]

    @property
    def rear_offsets(self) -> np.ndarray:
        """y2..yN [m] of eq. 4.42-4.46, shape (K, N-1)."""
        return rear_offsets(self.vehicle, self.theta)

    @property
    def lateral_acceleration(self) -> np.ndarray:
        """a_i = v_i' + u r_i of every unit's CG [m/s^2], shape (K, N) (docs/measures.md)."""
        co = system_coefficients(self.vehicle)
        n2 = linear_model(self.vehicle).n_states
        out = np.empty((self.time.size, self.vehicle.n_units))
        for u in np.unique(self.speed_mps):
            sel = self.speed_mps == u
            Ca, Da = co.acceleration_maps(float(u), self.tire_scale)
            out[sel] = self.states[sel, :n2] @ Ca.T + self.forces[sel] @ Da.T
        return out

    def to_rows(self, names: list[str] | None = None) -> list[dict]:
        """Rows ``{"time_s": t, name: value ...}`` for tables and CSV."""
        names = list(names or self.signal_names)
        cols = {n: self[n] for n in names}
        return [{"time_s": float(t), **{n: float(cols[n][k]) for n in names}} for k, t in enumerate(self.time)]

    def plot(self, signals: list[str] | None = None, ax=None, **style):
        """Plot signals against time (a :class:`matplotlib.figure.Figure`).

        Parameters
        ----------
        signals : list of str
            Signal names (default: the rear offsets y2..yN).
        ax : matplotlib Axes, optional
        style : keyword arguments for ``Axes.plot``.
        """
        from ..plotting.time import plot_time_response
        return plot_time_response(self, signals, ax=ax, **style)


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


def simulate(vehicle: Vehicle, time: np.ndarray, speed_mps: float | np.ndarray, forces: np.ndarray,
             tire_scale: float = 1.0, initial_state: np.ndarray | None = None,
             discretizer: Discretizer | None = None, label: str = "") -> TimeResponse:
    """Exact response to generalized forces held constant between time points.

    Parameters
    ----------
    vehicle : Vehicle
    time : numpy.ndarray, shape (K,)
        Increasing time points [s]; any spacing.
    speed_mps : float or numpy.ndarray, shape (K-1,)
        Forward speed on each interval [m/s].
    forces : numpy.ndarray, shape (2N,) or (K-1, 2N)
        Generalized force on each interval (zero-order hold), SI.  A steer angle delta
        enters as ``co.B_delta(tire_scale) * delta``.
    tire_scale : float
    initial_state : numpy.ndarray, shape (2N+2,), optional
        ``[x, psi1, Y1]`` at ``time[0]``; rest when omitted.
    discretizer : Discretizer, optional
        Reuse a cache across calls.
    label : str

    Returns
    -------
    TimeResponse
        States at every time point, exact for the held inputs.
    """
    t = _check_time(time)
    k = t.size - 1
    u = np.broadcast_to(np.asarray(speed_mps, dtype=float), (k,))
    check_speed(u)
    check_tire_scale(tire_scale)
    n = linear_model(vehicle).n_states
    f = np.broadcast_to(np.asarray(forces, dtype=float), (k, n))
    disc = discretizer or Discretizer(vehicle)
    z = np.zeros((t.size, n + 2))
    if initial_state is not None:
        z[0] = initial_state
    h = np.diff(t)
    for i in range(k):
        Ad, Gd = disc(u[i], h[i], tire_scale)
        z[i + 1] = Ad @ z[i] + Gd @ f[i]
    if not np.all(np.isfinite(z)):
        raise FloatingPointError("the response is not finite: the vehicle is unstable at this speed and the "
                                 "time span is too long for its growth")
    u_s = np.concatenate([u, u[-1:]]) if k else np.broadcast_to(np.asarray(speed_mps, dtype=float), (1,)).copy()
    f_s = np.concatenate([f, f[-1:]]) if k else np.broadcast_to(np.asarray(forces, dtype=float), (1, n)).copy()
    return TimeResponse(t, z, vehicle, u_s, f_s, float(tire_scale), label)


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
        raise FloatingPointError("the response is not finite: the vehicle is unstable at this speed and the "
                                 "time span is too long for its growth")
    u_s = np.full(t.size, float(speed_mps))
    return TimeResponse(t, z, vehicle, u_s, np.broadcast_to(f, (t.size, n)).copy(), float(tire_scale), label)


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
