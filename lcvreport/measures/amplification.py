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

import math
from dataclasses import dataclass, field

import numpy as np

from ..analysis.batch import VariantBatch
from ..analysis.frequency import RA_FREQUENCY_HZ, checked_frequency, steer_to_acceleration
from ..model.linear import check_speed, check_tire_scale, linear_model, stiffness
from ..model.vehicle import Vehicle
from .registry import MeasureCase

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
                step_s: float = SINGLE_SINE_STEP_S, tail_s: float = SINGLE_SINE_TAIL_S,
                model: str = "yaw_plane", options: dict | None = None) -> SingleSine:
    """The single-sine manoeuvre from rest (docs/measures.md, docs/manoeuvres.md): the continuous steer
    ``delta = delta0 sin(2 pi f t)`` for ``0 <= t <= 1/f``, then straight ahead for
    ``tail_s``; the exact response (:func:`lcvreport.analysis.exact.response`), sampled
    every ``step_s``, its peaks located on the continuous response; on the model ``model``
    (default the yaw plane; a model that is not linear integrated:
    :func:`lcvreport.analysis.respond.respond`, with its ``options``).

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    f_hz : float
        Steer frequency [Hz].
    delta0_rad : float
        Steer amplitude [rad].
    tire_scale : float
        Factor on every tire coefficient [-].
    step_s, tail_s : float
        Sampling step and the straight run after the sine [s].
    model : str
        Any model of :data:`lcvreport.model.base.MODELS`.
    options : dict, optional
        A nonlinear model's options (``tire``, ``friction_coefficient``, ``rtol``).

    Returns
    -------
    SingleSine
        The response's accelerations [m/s^2] and the rearward amplification [-].

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> s = single_sine(load_preset("aucnat"), 24.4444)
    >>> s.ay.shape, round(s.rearward_amplification, 2)
    ((5251, 6), 4.79)
    """
    from ..analysis.respond import respond
    from ..manoeuvres.steer import sine
    f = float(checked_frequency(f_hz))
    steer = sine(delta0_rad, f)
    t_end = round((1.0 / f + tail_s) / step_s) * step_s
    r = respond(vehicle, model, steer, speed_mps, t_end, step_s, tire_scale, options=options)
    peaks = r.peaks_abs([f"ay{i + 1}" for i in range(vehicle.n_units)])
    return SingleSine(r.time, f, float(delta0_rad), float(speed_mps), vehicle, peaks, r)


#: the RA(f) search band [Hz]
RA_BAND_HZ = (0.1, 2.0)


@dataclass(frozen=True)
class RAPeak:
    """Peak of the frequency-domain rearward amplification over :data:`RA_BAND_HZ`."""

    value: float
    frequency_hz: float


def ra_peak(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0, model: str = "yaw_plane") -> RAPeak:
    """max over 0.1-2 Hz of RA(f) = |G_N(j 2 pi f)| / |G_1(j 2 pi f)| and where it is
    (a 0.005 Hz scan, then the zero of d ln RA / df in the best bracket: the derivative
    exact from the same factorisation, ``dz/dw = -(jwM - S)^-1 jM z``, Brent's root finder
    to 1e-13 Hz; a maximum is flat, its zero-slope point is not); on the linear model ``model``.

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
    co = linear_model(vehicle, model)           # once: the search asks for ~10 single frequencies
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


def ra_peak_batched(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(max RA(f) over 0.1-2 Hz [-], where [Hz]) of every variant: see :func:`_ra_peak_batched`
    (groups of 256 variants)."""
    return batch.in_groups(_ra_peak_batched, speed_mps, tire_scale)


def _ra_slope(batch: VariantBatch, speed_mps: float, x_hz: np.ndarray, tire_scale: float,
              rows: np.ndarray) -> np.ndarray:
    """d ln RA / d omega of variant rows[k] at x_hz[k] [Hz] (its sign is that of dRA/df), exact:
    ``dz/dw = -(jwM - S)^-1 jM z``, as the one-variant ``ra_peak``."""
    co = linear_model(batch.vehicle, batch.model)
    c = {k: v[rows] for k, v in batch.coefficients.items()}
    u = float(speed_mps)
    M = c["M0"] + u * c["M1"]
    S = stiffness(c, u, tire_scale)
    w = 2 * np.pi * np.asarray(x_hz, dtype=float)
    A = 1j * w[:, None, None] * M - S
    z = np.linalg.solve(A, (tire_scale * c["Bdelta"])[..., None].astype(complex))
    dz = np.linalg.solve(A, -1j * (M @ z))
    # products per variant (stacks of 1-row matrices): a variant's numbers do not depend on
    # how many others share the call (a (K, n) @ (n, 2) product may round by K)
    z, dz = np.swapaxes(z, 1, 2), np.swapaxes(dz, 1, 2)                   # (K, 1, n)
    ends = np.array([0, batch.vehicle.n_units - 1])
    V, R = co.velocity_map(u)[ends].T, co.yaw_rate_map()[ends].T
    jw = (1j * w)[:, None, None]
    zV = z @ V
    G = (zV * jw + u * (z @ R))[:, 0]
    dG = (dz @ V * jw + 1j * zV + u * (dz @ R))[:, 0]
    g = (G.conj() * dG).real / (G.conj() * G).real
    return g[:, 1] - g[:, 0]


def _ra_peak_batched(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(max RA(f) over 0.1-2 Hz [-], where [Hz]) of every variant: the 0.005 Hz scan of
    :func:`ra_peak` (on the variants' modes, :meth:`~lcvreport.analysis.batch.VariantBatch.ra_scan`),
    then the zero of the exact slope d ln RA / d omega in each variant's best bracket (the
    Illinois variant of regula falsi, to 1e-13 Hz; the one-variant version uses Brent's root
    finder on the same slope), a golden-section search on RA's values where the slope does not
    change sign across the bracket.  Each variant's search stops on its own, so its result does
    not depend on the other variants of the batch."""
    lo, hi = RA_BAND_HZ
    f = np.linspace(lo, hi, 381)
    values = batch.ra_scan(speed_mps, f, tire_scale)
    k = np.argmax(values, axis=1)
    where = f[k].astype(float)
    best = batch.ra_at(speed_mps, where[:, None], tire_scale)[:, 0]          # exact at the scan's best
    idx = np.flatnonzero((k > 0) & (k < f.size - 1))
    if idx.size:
        a, c = f[k[idx] - 1].astype(float), f[k[idx] + 1].astype(float)
        ga = _ra_slope(batch, speed_mps, a, tire_scale, idx)
        gc = _ra_slope(batch, speed_mps, c, tire_scale, idx)
        root = (ga > 0) & (gc < 0)
        xm = np.empty(idx.size)
        if root.any():
            r = np.flatnonzero(root)
            xm[r] = _slope_zero(batch, speed_mps, tire_scale, idx[r], a[r], c[r], ga[r], gc[r])
        if (~root).any():
            r = np.flatnonzero(~root)
            xm[r] = _golden(batch, speed_mps, tire_scale, idx[r], a[r], c[r])
        xm = np.clip(xm, lo, hi)
        vm = batch.ra_at(speed_mps, xm[:, None], tire_scale, idx)[:, 0]
        better = vm >= best[idx]
        best[idx] = np.where(better, vm, best[idx])
        where[idx] = np.where(better, xm, where[idx])
    return best, where


def _slope_zero(batch: VariantBatch, speed_mps, tire_scale, rows, a, c, ga, gc) -> np.ndarray:
    """The zero of :func:`_ra_slope` in [a, c] (ga > 0 > gc) of each variant of ``rows``:
    Illinois regula falsi, each variant stopping when its iterate moves less than 1e-13 Hz."""
    a, c, ga, gc = a.copy(), c.copy(), ga.copy(), gc.copy()
    x = c - gc * (c - a) / (gc - ga)                 # the secant's zero (gc < 0 < ga: no 0 / 0)
    side = np.zeros(a.size, int)                     # which end was kept last time (Illinois)
    active = np.arange(a.size)
    for _ in range(100):
        if not active.size:
            break
        xa = x[active]
        g = _ra_slope(batch, speed_mps, xa, tire_scale, rows[active])
        pos = g > 0
        # replace the end with the same sign; halve the other end's slope when kept twice
        a[active] = np.where(pos, xa, a[active])
        ga[active] = np.where(pos, g, np.where(side[active] == -1, 0.5 * ga[active], ga[active]))
        c[active] = np.where(pos, c[active], xa)
        gc[active] = np.where(pos, np.where(side[active] == 1, 0.5 * gc[active], gc[active]), g)
        side[active] = np.where(pos, 1, -1)
        aa, cc, gaa, gcc = a[active], c[active], ga[active], gc[active]
        with np.errstate(divide="ignore", invalid="ignore"):
            new = cc - gcc * (cc - aa) / (gcc - gaa)
        new = np.where((new > aa) & (new < cc), new, 0.5 * (aa + cc))
        done = (np.abs(new - xa) <= 1e-13) | (g == 0) | (cc - aa <= 1e-13)
        x[active] = np.where(g == 0, xa, new)
        active = active[~done]
    return x


def _golden(batch: VariantBatch, speed_mps, tire_scale, idx, a, c) -> np.ndarray:
    """The golden-section search of RA's values over [a, c] of each variant of ``idx``, to 1e-12 Hz."""
    a, c = a.copy(), c.copy()
    g = (math.sqrt(5.0) - 1.0) / 2.0
    x1, x2 = c - g * (c - a), a + g * (c - a)
    both = batch.ra_at(speed_mps, np.stack([x1, x2], axis=1), tire_scale, idx)
    f1, f2 = both[:, 0], both[:, 1]
    active = np.flatnonzero(c - a > 1e-12)
    while active.size:
        left = f1[active] > f2[active]                 # the maximum is in [a, x2], else in [x1, c]
        aa, cc = a[active], c[active]
        aa, cc = np.where(left, aa, x1[active]), np.where(left, x2[active], cc)
        new = np.where(left, cc - g * (cc - aa), aa + g * (cc - aa))
        f_new = batch.ra_at(speed_mps, new[:, None], tire_scale, idx[active])[:, 0]
        x1n = np.where(left, new, x2[active])
        x2n = np.where(left, x1[active], new)
        f1n = np.where(left, f_new, f2[active])
        f2n = np.where(left, f1[active], f_new)
        a[active], c[active], x1[active], x2[active], f1[active], f2[active] = aa, cc, x1n, x2n, f1n, f2n
        active = active[cc - aa > 1e-12]
    return 0.5 * (a + c)


def single_sine_peaks(batch: VariantBatch, speed_mps: float, f_hz: float | None = None, tire_scale: float = 1.0,
                      extra=()) -> np.ndarray:
    """The peaks over the single sine (continuous, exact) of every variant, shape (B, 4 + k):
    max|a_1|, max|a_N|, max|r_1|, max|r_N| and of each of the ``k`` signals of ``extra``, each a
    triple ``(X, XD, D)`` of the variants' rows ``y = X x + XD x' + D delta`` (shapes (B, n), (B, n),
    (B,)): a yaw-roll model's sprung-CG acceleration, the steered axle's."""
    from ..analysis.batch import RESPONSE_GROUP
    from ..analysis.frequency import RA_FREQUENCY_HZ, checked_frequency
    from ..manoeuvres.steer import sine
    f = float(checked_frequency(RA_FREQUENCY_HZ if f_hz is None else f_hz))
    steer = sine(SINGLE_SINE_DELTA0_RAD, f)
    t_end = round((1.0 / f + SINGLE_SINE_TAIL_S) / SINGLE_SINE_STEP_S) * SINGLE_SINE_STEP_S
    last = batch.vehicle.n_units - 1
    ay_rows = batch.ay_rows(speed_mps, [0, last])
    r_map = linear_model(batch.vehicle, batch.model).yaw_rate_map()[[0, last]]

    def signals_of(rows):
        def signals(Mz, d_row, ctx):
            n = ctx[3]
            C = np.zeros((Mz.shape[0], 4 + len(extra), Mz.shape[-1]))
            C[:, :2] = ay_rows(Mz, d_row, ctx)                    # a_1, a_N
            C[:, 2:4, :n] = r_map                                 # r_1, r_N
            for k, rows_k in enumerate(extra):                    # X x + XD x' + D delta
                X, XD, D = (np.asarray(a)[rows] for a in rows_k)
                C[:, 4 + k, :n] = X
                C[:, 4 + k] += np.einsum("bn,bnd->bd", XD, Mz[:, :n])
                C[:, 4 + k] += D[:, None] * d_row
            return C
        return signals
    peaks = []
    for g in range(0, batch.size, RESPONSE_GROUP):
        rows = np.arange(g, min(batch.size, g + RESPONSE_GROUP))
        hi, lo = batch.extremes(speed_mps, steer, t_end, SINGLE_SINE_STEP_S, signals_of(rows), tire_scale, rows,
                                positions=False)
        peaks.append(np.maximum(np.abs(hi), np.abs(lo)))
    return np.concatenate(peaks)


def single_sine_batched(batch: VariantBatch, speed_mps: float, f_hz: float | None = None,
                        tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(RA, yaw-rate RA) of the single sine [-] of every variant: max|a_N| / max|a_1| and
    max|r_N| / max|r_1| on the continuous exact response
    (:func:`lcvreport.measures.amplification.single_sine`: ``delta0 sin(2 pi f t)`` for one
    period, then the tail)."""
    peaks = single_sine_peaks(batch, speed_mps, f_hz, tire_scale)
    return peaks[:, 1] / peaks[:, 0], peaks[:, 3] / peaks[:, 2]


def frequency_response_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``frequency_response`` family of one case: RA at ``case.f_hz`` and every
    unit's gain |G_i| [m/s^2 per rad]."""
    gains = np.abs(steer_to_acceleration(case.vehicle, case.speed_mps, case.f_hz, case.tire_scale, case.model))
    return {"ra_frequency": float(gains[-1] / gains[0]), "ay_gain_per_unit": [float(g) for g in gains]}, {}


def ra_frequency_batched(batch: VariantBatch, speed_mps: float, f_hz: float, tire_scale: float = 1.0) -> np.ndarray:
    """RA(f_hz) [-] of every variant (:meth:`~lcvreport.analysis.batch.VariantBatch.rearward_amplification`)."""
    return batch.rearward_amplification(speed_mps, f_hz, tire_scale)


def single_sine_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``single_sine`` family of one case."""
    ss = single_sine(case.vehicle, case.speed_mps, case.f_hz, tire_scale=case.tire_scale, model=case.model,
                     options=case.model_options())
    r = ss.response.peaks_abs([f"r{i + 1}" for i in (0, case.vehicle.n_units - 1)])
    ra = ss.rearward_amplification
    if case.model == "yaw_roll":                 # the yaw-roll RA between its reference points
        from .ra_points import ra_points, rearward_amplification
        points = ra_points(case.conditions.get("ra_numerator"), case.conditions.get("ra_denominator"),
                           "ra_single_sine_roll")
        ra = rearward_amplification(ss.response, case.vehicle.n_units, *points)
    return {"ra_single_sine": ra, "ra_yaw_rate_single_sine": float(r[1] / r[0])}, {}


def ra_peak_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``ra_peak`` family of one case."""
    p = ra_peak(case.vehicle, case.speed_mps, case.tire_scale, case.model)
    return {"ra_peak": p.value, "ra_peak_frequency_hz": p.frequency_hz}, {}
