r"""Geometry of the chain: where points of the units are, to scale and to first order.

* Lateral offsets of the rear ends of units 2..N from the tractor axis, eq. 3.43 and
  4.42-4.46 generalized to signed couplings and rear ends::

      y_k = sum_(j=2)^(k-1) (fc_j - rc_j) sin(Theta_j) + (fc_k - re_k) sin(Theta_k),
      Theta_j = theta_1 + ... + theta_(j-1)

  (fc, rc, re: signed x of a unit's front coupling, rear coupling and reported rear end).
* Global lateral positions (small angles): a point at signed x on unit k is at
  ``Y1 + rc_1 psi_1 + sum_(j=2)^(k-1) (rc_j - fc_j) psi_j + (x - fc_k) psi_k`` with
  ``psi_j = psi_1 - Theta_j``.

Lengths in m (SI vehicles).
"""
from __future__ import annotations

import numpy as np

from ..vehicle import Vehicle


def rear_end_weights(vehicle: Vehicle) -> np.ndarray:
    """W with ``y = W sin(Theta)`` [m]: row k-2 gives y_k from the relative headings
    Theta_2..Theta_N of units 2..N; shape (N-1, N-1), lower triangular."""
    n = vehicle.n_units
    W = np.zeros((n - 1, n - 1))
    for k in range(1, n):          # unit index k (0-based) = unit k+1
        u = vehicle.units[k]
        for j in range(1, k):
            uj = vehicle.units[j]
            W[k - 1, j - 1] = uj.front_coupling_m - uj.rear_coupling_m
        W[k - 1, k - 1] = u.front_coupling_m - vehicle.rear_end_x_m(k)
    return W


def relative_headings(theta: np.ndarray) -> np.ndarray:
    """Theta_k = theta_1 + ... + theta_(k-1) of units 2..N [rad], shape (..., N-1)."""
    return np.cumsum(np.asarray(theta, dtype=float), axis=-1)


def rear_offsets(vehicle: Vehicle, theta: np.ndarray) -> np.ndarray:
    """Lateral offsets y_2..y_N of the rear ends from the tractor axis [m] (eq. 4.42-4.46).

    Parameters
    ----------
    vehicle : Vehicle
    theta : numpy.ndarray, shape (..., N-1)
        Articulation angles [rad].

    Returns
    -------
    numpy.ndarray, shape (..., N-1)
    """
    return np.sin(relative_headings(theta)) @ rear_end_weights(vehicle).T


def point_longitudinal(vehicle: Vehicle, unit: int, x_m: float) -> float:
    """Longitudinal position [m] of the point at signed x on unit ``unit`` (0-based) in
    the tractor frame, the chain straight (zeroth order)."""
    if unit == 0:
        return float(x_m)
    X = vehicle.units[0].rear_coupling_m
    for j in range(1, unit):
        uj = vehicle.units[j]
        X += uj.rear_coupling_m - uj.front_coupling_m
    return float(X + x_m - vehicle.units[unit].front_coupling_m)


def point_lateral_map(vehicle: Vehicle, unit: int, x_m: float) -> np.ndarray:
    """c with ``Y_point = c . [psi1, Y1, Theta_2..Theta_N]`` to first order [m per rad, -]:
    the global lateral position of the point at signed x on unit ``unit`` (0-based)."""
    n = vehicle.n_units
    c = np.zeros(n + 1)
    c[1] = 1.0
    if unit == 0:
        c[0] = x_m
        return c
    lengths = [vehicle.units[0].rear_coupling_m]
    for j in range(1, unit):
        uj = vehicle.units[j]
        lengths.append(uj.rear_coupling_m - uj.front_coupling_m)
    lengths.append(x_m - vehicle.units[unit].front_coupling_m)
    # psi_j = psi1 - Theta_j (Theta_1 = 0)
    c[0] = sum(lengths)
    for j in range(1, unit + 1):
        c[2 + j - 1] -= lengths[j]
    return c


def global_lateral(vehicle: Vehicle, unit: int, x_m: float, psi1, Y1, theta) -> np.ndarray:
    """Global lateral position [m] of the point at signed x on unit ``unit`` (0-based),
    first order in the angles; broadcasts over samples (theta shape (..., N-1))."""
    c = point_lateral_map(vehicle, unit, x_m)
    Theta = relative_headings(theta)
    return c[0] * np.asarray(psi1) + c[1] * np.asarray(Y1) + Theta @ c[2:]


def rear_end_global(vehicle: Vehicle, psi1, Y1, theta) -> np.ndarray:
    """Global lateral position of the rear end of the last unit [m] (small angles)."""
    k = vehicle.n_units - 1
    return global_lateral(vehicle, k, vehicle.rear_end_x_m(k), psi1, Y1, theta)
