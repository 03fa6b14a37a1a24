"""Frequency responses: the steer-to-lateral-acceleration transfer function of every unit
and the rearward amplification ``RA(f) = |G_N| / |G_1|``.

Examples
--------
>>> from lcvreport import load_preset
>>> round(float(rearward_amplification(load_preset("aucnat"), 24.4444)), 3)
5.377
"""
from __future__ import annotations

import numpy as np

from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..ranges import RANGES

#: the frequency of the RA measures [Hz]
RA_FREQUENCY_HZ = 0.4


def checked_frequency(f_hz):
    f = np.asarray(f_hz, dtype=float)
    RANGES["frequency"].check(float(f.min()) if f.size else 0.0, "frequency")
    RANGES["frequency"].check(float(f.max()) if f.size else 0.0, "frequency")
    return f


def steer_to_acceleration(vehicle: Vehicle, speed_mps: float, f_hz, tire_scale: float = 1.0,
                          model: str = "yaw_plane") -> np.ndarray:
    """``G_i(j 2 pi f)``: complex gain from the steer angle to the lateral acceleration of
    every unit's CG [m/s^2 per rad], shape (..., N) for frequencies of shape (...).

    Computed from ``x = (j w M - S)^-1 b_delta`` and ``a = (j w V + u R) x``, with no
    state-space conversion (the state-space form of :mod:`.statespace` is tested
    against it), on the linear model ``model`` (default the yaw plane).
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    f = checked_frequency(f_hz)
    co = linear_model(vehicle, model)
    M, S, b = co.M(speed_mps), co.S(speed_mps, tire_scale), co.B_delta(tire_scale)
    V, R = co.velocity_map(speed_mps), co.yaw_rate_map()
    w = 2 * np.pi * f[..., None, None]
    x = np.linalg.solve(1j * w * M - S, np.broadcast_to(b, f.shape + b.shape)[..., None])[..., 0]
    return x @ V.T * (1j * 2 * np.pi * f[..., None]) + speed_mps * (x @ R.T)


def rearward_amplification(vehicle: Vehicle, speed_mps: float, f_hz=RA_FREQUENCY_HZ, tire_scale: float = 1.0,
                           model: str = "yaw_plane"):
    """``RA(f) = |G_N| / |G_1|`` [-] at one or many frequencies [Hz] on the model ``model``.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    f_hz : float or array_like
        Steer frequency [Hz].
    tire_scale : float
        Factor on every tire coefficient [-].
    model : str
        A linear model (:data:`lcvreport.model.base.LINEAR_MODELS`).

    Returns
    -------
    float or numpy.ndarray
        ``|G_N| / |G_1|`` [-] of the CGs' lateral accelerations, one per frequency.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> round(float(rearward_amplification(load_preset("aucnat"), 24.4444)), 2)
    5.38
    """
    G = np.abs(steer_to_acceleration(vehicle, speed_mps, f_hz, tire_scale, model))
    ra = G[..., -1] / G[..., 0]
    return float(ra) if np.ndim(ra) == 0 else ra
