"""Steady state under constant loads: ``x_ss = -S^-1 F`` (thesis section 4.4, docs/thesis.md, erratum 4).

Examples
--------
>>> from lcvreport import load_preset, one_percent_rule, load_vector, steady_state
>>> v = load_preset("aucnat")
>>> x = steady_state(v, 22.352, load_vector(v, one_percent_rule(v, ["trailer2", "trailer3"])))
>>> x.shape
(12,)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.outputs import point_lateral_map, point_longitudinal
from ..ranges import RANGES, RangeError


def steady_state(vehicle: Vehicle, speed_mps: float | np.ndarray, F: np.ndarray,
                 tire_scale: float | np.ndarray = 1.0, model: str = "yaw_plane") -> np.ndarray:
    """Steady state ``x_ss = -S^-1 F`` under a constant generalized force (SI).

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float or array
        Forward speed [m/s]; broadcasts.
    F : numpy.ndarray, shape (..., 2N)
        Generalized force, SI (row 1 N, rows 2..N+1 N*m; see :func:`lcvreport.load_vector`).
    tire_scale : float or array
    model : str
        The linear model (default the yaw plane); F has its state count.

    Returns
    -------
    numpy.ndarray, shape (..., n)
        The steady state (yaw plane: v1 [m/s], r [rad/s], theta [rad]).

    Examples
    --------
    >>> import numpy as np
    >>> from lcvreport import load_preset
    >>> v = load_preset("aucnat")
    >>> F = np.zeros(12); F[0] = 1000.0                    # 1 kN lateral on the tractor
    >>> steady_state(v, 24.4, F).shape
    (12,)
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    S = linear_model(vehicle, model).S(speed_mps, tire_scale)
    Fb = np.broadcast_to(np.asarray(F, dtype=float), S.shape[:-1])
    return -np.linalg.solve(S, Fb[..., None])[..., 0]


@dataclass(frozen=True)
class Trim:
    """Trimmed straight running under residual loads.

    Attributes
    ----------
    delta_rad : float
        Steer angle that holds the tractor straight (r1 = 0) [rad].
    offtracking_m : float
        Lateral offset of the rearmost axle's path from the steered axle's path [m], +y positive.
    state : numpy.ndarray, shape (2N,)
        The trimmed state (v1 m/s, r = 0, theta rad).
    """

    delta_rad: float
    offtracking_m: float
    state: np.ndarray


def reference_points(vehicle: Vehicle) -> tuple[tuple[int, float], tuple[int, float]]:
    """((unit, x) of the frontmost steered axle (or frontmost axle of unit 1),
    (unit, x) of the rearmost axle of the last unit), 0-based units, x [m]."""
    first = vehicle.steered_axles or vehicle.units[0].axles
    q = max(first, key=lambda a: a.x_m)
    last = vehicle.n_units - 1
    return (0, q.x_m), (last, vehicle.units[last].rearmost_axle.x_m)


def steady_with_yaw_rate(vehicle: Vehicle, speed_mps: float, F, r1: float, tire_scale: float = 1.0,
                         model: str = "yaw_plane") -> tuple[np.ndarray, float]:
    """The steady state and steer angle with the tractor's yaw rate held at ``r1`` [rad/s]:
    ``S x + b delta + F = 0`` with ``x[1] = r1`` (the trim: r1 = 0; a steady turn: u/R).

    Returns
    -------
    x : numpy.ndarray, shape (2N,)
    delta : float
        [rad]
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = linear_model(vehicle, model)
    S, b = co.S(speed_mps, tire_scale), co.B_delta(tire_scale)
    n = co.n_states
    K = np.zeros((n + 1, n + 1))
    K[:n, :n] = S
    K[:n, n] = b
    K[n, 1] = 1.0
    rhs = np.concatenate([-np.asarray(F, dtype=float), [float(r1)]])
    sol = np.linalg.solve(K, rhs)
    return sol[:n], float(sol[n])


def trim(vehicle: Vehicle, speed_mps: float, F: np.ndarray, tire_scale: float = 1.0) -> Trim:
    """Trimmed straight running under a constant generalized force F (SI).

    Solves ``S x + b delta + F = 0`` with ``r1 = 0`` for ``x`` and ``delta``.
    

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    F : numpy.ndarray, shape (2N,)
        Generalized force, SI (:func:`lcvreport.load_vector`).
    tire_scale : float
        Factor on every tire coefficient [-].

    Returns
    -------
    Trim
        The trim steer [rad], the states and the trimmed offtracking [m].

    Examples
    --------
    >>> from lcvreport import load_preset, load_vector, one_percent_rule
    >>> v = load_preset("aucnat")
    >>> t = trim(v, 24.4, load_vector(v, one_percent_rule(v, ["trailer2", "trailer3"])))
    >>> abs(t.delta_rad) < 0.01
    True
    """
    x, delta = steady_with_yaw_rate(vehicle, speed_mps, F, 0.0, tire_scale)
    (uq, xq), (up, xp) = reference_points(vehicle)
    nu = vehicle.n_units
    Theta = np.cumsum(x[nu + 1:])
    lateral = lambda unit, xx: float(point_lateral_map(vehicle, unit, xx)[2:] @ Theta)  # noqa: E731 (psi1 = Y1 = 0)
    dX = point_longitudinal(vehicle, up, xp) - point_longitudinal(vehicle, uq, xq)
    offtracking = lateral(up, xp) - lateral(uq, xq) - dX * x[0] / speed_mps
    return Trim(delta, float(offtracking), x)


def check_trim(tr: Trim) -> None:
    """Refuse a trim outside the ranges table: a trim steer beyond [-1, 1] rad is no longer
    a small angle, and the linear model's answer means nothing (a unit typo, such as a
    cornering stiffness in kN/rad, is the usual cause).

    Raises
    ------
    RangeError
    """
    r = RANGES["steer_angle"]
    if not r.contains(tr.delta_rad):
        raise RangeError("trim.delta_rad", f"the trim steer angle {tr.delta_rad:.4g} rad is outside {r.text()}: the "
                                           "linear model does not hold there; check the vehicle file's units "
                                           "(cornering stiffness per tire in N/rad, masses in kg)")
