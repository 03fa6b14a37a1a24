"""A sampled-data steering controller around the exact model: what a co-simulation master
computes when it couples the vehicle to a driver model.

The driver steers ``delta = -k_Y Y1 - k_psi psi1`` (a lateral-position and heading
feedback on the tractor; gains in rad/m and rad/rad), sampled at the communication
points and held over each step (zero-order hold).  ``delay_steps`` is how many
communication steps the measurement reaches the steer angle late: 0 when the master
updates the driver's inputs and reads its output within a communication point
(Gauss-Seidel order), 1 when every model steps on the values of the previous point
(Jacobi order).

Examples
--------
>>> from lcvreport import load_preset
>>> run = steer_feedback(load_preset("tractor_semitrailer"), 22.352, (0.002, 0.2), 0.05, 200,
...                      residual_P_N={"11": 1000.0})
>>> float(run.response.time[-1]), run.delta.shape
(10.0, (201,))
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..manoeuvres.drivers import DEFAULT, PreviewDriver
from ..model.linear import check_speed, linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients
from ..model.yaw_plane.loads import ResidualLoads, load_vector
from .discretize import Discretizer, augmented_state_matrix
from .response import held_response
from .time_response import TimeResponse


@dataclass(frozen=True)
class SteerFeedback:
    """A closed-loop run: the response and the steer angle held from each sample [rad]."""

    response: TimeResponse
    delta: np.ndarray


def steer_feedback(vehicle: Vehicle, speed_mps: float, gains: tuple[float, float], h: float, n_steps: int,
                   residual_P_N: dict | None = None, residual_T_Nm: dict | None = None, delay_steps: int = 1,
                   tire_scale: float = 1.0) -> SteerFeedback:
    """The exact response of the vehicle under sampled steering feedback.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    gains : (k_Y [rad/m], k_psi [rad/rad])
    h : float
        Communication step [s].
    n_steps : int
    residual_P_N, residual_T_Nm : dict, optional
        Residual loads per axle [N], [N*m], held constant.
    delay_steps : int
        Communication steps between a measurement and the steer it causes (0 or more).
    tire_scale : float

    Returns
    -------
    SteerFeedback
    """
    check_speed(speed_mps)
    co = system_coefficients(vehicle)
    F = load_vector(vehicle, ResidualLoads(residual_P_N or {}, residual_T_Nm or {}))
    b = co.B_delta(tire_scale)
    Ad, Gd = Discretizer(vehicle, maxsize=1)(speed_mps, h, tire_scale)
    n = linear_model(vehicle).n_states
    k_y, k_psi = gains
    z = np.zeros((n_steps + 1, n + 2))
    delta = np.zeros(n_steps + 1)

    def steer(k: int) -> float:
        j = k - delay_steps
        return -(k_y * z[j, n + 1] + k_psi * z[j, n]) if j >= 0 else 0.0

    for k in range(n_steps):
        delta[k] = steer(k)
        z[k + 1] = Ad @ z[k] + Gd @ (F + b * delta[k])
    delta[n_steps] = steer(n_steps)
    t = np.arange(n_steps + 1) * h
    response = held_response(vehicle, t, z, np.full(t.size, float(speed_mps)), np.broadcast_to(F, (t.size, n)),
                             tire_scale, delta_rad=delta, label="steer feedback")
    return SteerFeedback(response, delta)


@dataclass(frozen=True)
class ClosedLoop:
    """Time histories of the closed loop (SI): time [s], states z = [x, psi1, Y1], steer [rad]."""

    time_s: np.ndarray
    states: np.ndarray
    steer_rad: np.ndarray

    @property
    def Y1_m(self) -> np.ndarray:
        return self.states[:, -1]

    @property
    def psi1_rad(self) -> np.ndarray:
        return self.states[:, -2]


def closed_loop(vehicle: Vehicle, speed_mps: float, driver: PreviewDriver = DEFAULT, t_end: float = 10.0,
                dt: float = 0.01, tire_scale: float = 1.0, rtol: float = 1e-12, atol: float = 1e-14) -> ClosedLoop:
    """The continuous closed loop of ``vehicle`` at ``speed_mps`` [m/s] and ``driver`` from rest,
    sampled every ``dt`` [s] to ``t_end`` [s]: z' = A_aug z + G b_delta delta(t, z), integrated
    by :func:`scipy.integrate.solve_ivp` (DOP853) segment by segment of the reference (its
    second derivative jumps at the ramp's ends).

    Returns
    -------
    ClosedLoop
    """
    from scipy.integrate import solve_ivp
    co = system_coefficients(vehicle)
    A, G = augmented_state_matrix(co, speed_mps, tire_scale)
    b = G @ co.B_delta(tire_scale)
    n = co.n_states

    def f(t, z):
        return A @ z + b * driver.steer_rad(t, z[n + 1], z[n])

    t_eval = np.round(np.arange(0.0, t_end + 0.5 * dt, dt) / dt) * dt
    breaks = sorted({0.0, t_end, *(x for x in (driver.start_s, driver.start_s + driver.duration_s) if 0 < x < t_end)})
    z = np.zeros(n + 2)
    out = np.empty((t_eval.size, n + 2))
    for lo, hi in zip(breaks[:-1], breaks[1:]):
        sel = (t_eval >= lo) & (t_eval <= hi)
        sol = solve_ivp(f, (lo, hi), z, method="DOP853", rtol=rtol, atol=atol, t_eval=t_eval[sel], dense_output=True)
        out[sel] = sol.y.T
        z = sol.sol(hi)
    return ClosedLoop(t_eval, out, driver.steer_rad(t_eval, out[:, n + 1], out[:, n]))
