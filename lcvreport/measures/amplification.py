"""Rearward amplification: the single sine and the peak of RA(f)
(``docs/measures.md#rearward-amplification``).

* **Single sine**: ``delta(t) = delta0 sin(2 pi f t)`` for one period, then 0, from rest;
  ``RA = max|a_N| / max|a_1|`` over the period and 8 s after, on the exact continuous
  response (the extrema located between the 2 ms samples).
* **RA peak**: the largest ``RA(f) = |G_N(j 2 pi f)| / |G_1(j 2 pi f)|`` over 0.1-2 Hz and
  where (the frequency to 1e-6 Hz).

Examples
--------
>>> from lcvreport import load_preset
>>> round(single_sine(load_preset("aucnat"), 24.4444).rearward_amplification, 3)
4.789
>>> p = ra_peak(load_preset("aucnat"), 24.4444)
>>> round(p.value, 3), round(p.frequency_hz, 3)
(9.928, 0.564)
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.frequency import RA_FREQUENCY_HZ, _freq
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import check_speed, check_tire_scale, system_coefficients

#: single sine: step [s], time after the sine [s], default amplitude [rad]
SINGLE_SINE_STEP_S = 2e-3


SINGLE_SINE_TAIL_S = 8.0


SINGLE_SINE_DELTA0_RAD = 0.01


@dataclass(frozen=True)
class SingleSine:
    """A single-sine steer manoeuvre and the lateral accelerations it produces.

    Attributes
    ----------
    time : numpy.ndarray, shape (K,)
        Sample times from the start of the steer [s].
    delta : numpy.ndarray, shape (K,)
        Steer angle (the continuous sine) at the samples [rad] (computed on access).
    ay : numpy.ndarray, shape (K, N)
        Lateral acceleration of every unit's CG at the samples [m/s^2] (computed on access).
    frequency_hz, delta0_rad, speed_mps : float
    vehicle : Vehicle
    peaks : numpy.ndarray, shape (N,)
        max|a_i| per unit on the continuous response [m/s^2] (between the samples).
    response : lcvreport.analysis.exact.ManoeuvreResponse
        The exact response the samples come from.
    """

    time: np.ndarray
    frequency_hz: float
    delta0_rad: float
    speed_mps: float
    vehicle: Vehicle = field(repr=False, default=None)
    peaks: np.ndarray = None
    response: object = field(repr=False, default=None)

    @property
    def delta(self) -> np.ndarray:
        """Steer angle at the samples [rad]."""
        return self.response["delta"]

    @property
    def ay(self) -> np.ndarray:
        """Lateral acceleration of every unit's CG at the samples, shape (K, N) [m/s^2]."""
        return np.column_stack([self.response[f"ay{i + 1}"] for i in range(self.vehicle.n_units)])

    @property
    def rearward_amplification(self) -> float:
        """max|a_N| / max|a_1| [-] on the continuous response."""
        return float(self.peaks[-1] / self.peaks[0])

    def plot(self, ax=None):
        """Time histories of every unit's a_i (a :class:`matplotlib.figure.Figure`)."""
        from ..plotting.time import plot_single_sine
        return plot_single_sine(self, ax=ax)


def single_sine(vehicle: Vehicle, speed_mps: float, f_hz: float = RA_FREQUENCY_HZ,
                delta0_rad: float = SINGLE_SINE_DELTA0_RAD, tire_scale: float = 1.0,
                step_s: float = SINGLE_SINE_STEP_S, tail_s: float = SINGLE_SINE_TAIL_S) -> SingleSine:
    """The single-sine manoeuvre from rest (SPEC sections 8 and 11): the continuous steer
    ``delta = delta0 sin(2 pi f t)`` for ``0 <= t <= 1/f``, then straight ahead for
    ``tail_s``; the exact response (:func:`lcvreport.analysis.exact.response`), sampled
    every ``step_s``, its peaks located on the continuous response.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> s = single_sine(load_preset("aucnat"), 24.4444)
    >>> s.ay.shape, round(s.rearward_amplification, 2)
    ((5251, 6), 4.79)
    """
    from ..analysis.exact import response
    from ..manoeuvres.steer import sine
    f = float(_freq(f_hz))
    steer = sine(delta0_rad, f)
    t_end = round((1.0 / f + tail_s) / step_s) * step_s
    r = response(vehicle, speed_mps, steer, t_end, step_s, tire_scale=tire_scale)
    peaks = r.peaks_abs([f"ay{i + 1}" for i in range(vehicle.n_units)])
    return SingleSine(r.time, f, float(delta0_rad), float(speed_mps), vehicle, peaks, r)


#: the RA(f) search band [Hz]
RA_BAND_HZ = (0.1, 2.0)


@dataclass(frozen=True)
class RAPeak:
    """Peak of the frequency-domain rearward amplification over :data:`RA_BAND_HZ`."""

    value: float
    frequency_hz: float


def ra_peak(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> RAPeak:
    """max over 0.1-2 Hz of RA(f) = |G_N(j 2 pi f)| / |G_1(j 2 pi f)| and where it is
    (a 0.005 Hz scan, then the zero of d ln RA / df in the best bracket: the derivative
    exact from the same factorisation, ``dz/dw = -(jwM - S)^-1 jM z``, Brent's root finder
    to 1e-13 Hz; a maximum is flat, its zero-slope point is not).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> p = ra_peak(load_preset("aucnat"), 24.4444)
    >>> round(p.value, 3) > 5.0
    True
    """
    from scipy.linalg import lu_factor, lu_solve
    from scipy.optimize import brentq, minimize_scalar
    lo, hi = RA_BAND_HZ
    f = np.linspace(lo, hi, 381)
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle)           # once: the search asks for ~10 single frequencies
    u = float(speed_mps)
    M, S, b = co.M(u), co.S(u, tire_scale), co.B_delta(tire_scale)
    ends = np.array([0, vehicle.n_units - 1])
    V, R = co.velocity_map(u)[ends], co.yaw_rate_map()[ends]

    def ra(x):
        """RA at the frequencies x [Hz]: as steer_to_acceleration (first and last unit only)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        w = 2 * np.pi * x[..., None, None]
        z = np.linalg.solve(1j * w * M - S, np.broadcast_to(b, x.shape + b.shape)[..., None])[..., 0]
        G = np.abs(z @ V.T * (1j * 2 * np.pi * x[..., None]) + u * (z @ R.T))
        return G[..., -1] / G[..., 0]

    def ra1(x: float) -> float:
        """RA at one frequency x [Hz] (the peak's value, the fallback search): the same solve
        without the stacking."""
        w = 2 * np.pi * x
        z = np.linalg.solve(1j * w * M - S, b)
        G = np.abs(V @ z * (1j * w) + u * (R @ z))
        return float(G[1] / G[0])

    # in blocks of 64 frequencies: each solve independent (the same numbers as one call), and no
    # temporaries of a megabyte that malloc would hand back to the system and fault in again
    values = np.concatenate([ra(f[i:i + 64]) for i in range(0, f.size, 64)])
    k = int(np.argmax(values))
    if k in (0, f.size - 1):
        return RAPeak(float(values[k]), float(f[k]))

    def slope(x: float) -> float:
        """d ln RA / d omega at x [Hz] (the sign of dRA/df)."""
        w = 2 * np.pi * x
        lu = lu_factor(1j * w * M - S)
        z = lu_solve(lu, b)
        dz = lu_solve(lu, -1j * (M @ z))
        G = V @ z * (1j * w) + u * (R @ z)
        dG = V @ dz * (1j * w) + 1j * (V @ z) + u * (R @ dz)
        g = (G.conj() * dG).real / (G.conj() * G).real
        return float(g[1] - g[0])

    a, c = float(f[k - 1]), float(f[k + 1])
    sa, sc = slope(a), slope(c)
    if sa > 0 > sc:
        x = brentq(slope, a, c, xtol=1e-13, rtol=4 * np.finfo(float).eps)
    else:                           # no sign change across the bracket (flat to rounding): search the value
        res = minimize_scalar(lambda x: -ra1(x), bracket=(f[k - 1], f[k], f[k + 1]),
                              bounds=None, method="brent", options={"xtol": 1e-9})
        x = float(min(max(res.x, lo), hi))
    return RAPeak(ra1(x), x)
