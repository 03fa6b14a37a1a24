"""Steady state under constant loads: ``x_ss = -S^-1 F`` (thesis section 4.4, SPEC erratum 4).

Examples
--------
>>> from lcvreport import load_preset, one_percent_rule, load_vector, steady_state
>>> v = load_preset("aucnat")
>>> x = steady_state(v, 22.352, load_vector(v, one_percent_rule(v, ["trailer2", "trailer3"])))
>>> x.shape
(12,)
"""
from __future__ import annotations

import numpy as np

from ..model.builder import check_speed, check_tire_scale, system_coefficients
from ..model.vehicle import Vehicle


def steady_state(vehicle: Vehicle, speed_mps: float | np.ndarray, F: np.ndarray,
                 tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
    """Steady state ``x_ss = -S^-1 F`` under a constant generalized force (SI).

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float or array
        Forward speed [m/s]; broadcasts.
    F : numpy.ndarray, shape (..., 2N)
        Generalized force, SI (row 1 N, rows 2..N+1 N*m; see :func:`lcvreport.load_vector`).
    tire_scale : float or array

    Returns
    -------
    numpy.ndarray, shape (..., 2N)
        v1 [m/s], r [rad/s], theta [rad].
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    S = system_coefficients(vehicle).S(speed_mps, tire_scale)
    Fb = np.broadcast_to(np.asarray(F, dtype=float), S.shape[:-1])
    return -np.linalg.solve(S, Fb[..., None])[..., 0]
