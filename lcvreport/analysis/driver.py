"""A path-following driver and the closed loop of vehicle and driver (SPEC section 15).

The driver steers so that a preview point ``preview_m`` ahead of the tractor's CG follows a
lane change of ``target_offset_m`` (a half-cosine from ``start_s`` over ``duration_s``):

    delta = K (Y_ref(t) - (Y1 + L psi1))

SI; +y to the right, steer and heading nose-right positive.  The same law is the driver FMU
(``fmu_src/c/driver.c``; :func:`lcvreport.fmu.driver.build_driver_fmu`), whose parameters
start at :data:`DEFAULT`'s values.  :func:`closed_loop` is the package's continuous closed
loop -- vehicle and driver solved by one integrator -- that a Model Exchange co-simulation
must reproduce and a Co-Simulation one approaches at first order in its step.

Examples
--------
>>> from lcvreport import load_preset
>>> r = closed_loop(load_preset("tractor_semitrailer"), 24.0,
...                 PreviewDriver(), t_end=20.0)
>>> round(float(r.Y1_m[-1]), 2)              # the lane change is done: Y1 at the target offset
1.5
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.builder import system_coefficients
from ..model.vehicle import Vehicle
from .discretize import augmented_state_matrix


@dataclass(frozen=True)
class PreviewDriver:
    """Gain [rad/m], preview distance [m], lane change offset [m], start [s] and duration [s]."""

    gain_rad_per_m: float = 0.02
    preview_m: float = 30.0
    target_offset_m: float = 1.5
    start_s: float = 1.0
    duration_s: float = 3.0

    def reference_m(self, t):
        """Y_ref(t) [m]: 0 before the start, the half-cosine ramp, the offset after."""
        x = np.clip((np.asarray(t, dtype=float) - self.start_s) / self.duration_s, 0.0, 1.0)
        return self.target_offset_m * 0.5 * (1.0 - np.cos(math.pi * x))

    def steer_rad(self, t, Y1_m, psi1_rad):
        """delta = K (Y_ref(t) - (Y1 + L psi1)) [rad]."""
        return self.gain_rad_per_m * (self.reference_m(t) - (Y1_m + self.preview_m * psi1_rad))


#: the driver FMU's start values
DEFAULT = PreviewDriver()


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
