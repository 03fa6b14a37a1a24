"""Extrema between samples: the roots of a cubic Hermite interpolant's derivative, a quintic
Hermite value, and the doubling scan of an exact discretization (used by the exact
responses and the batch).
"""
from __future__ import annotations

import math

import numpy as np



def hermite_roots(f0, d0, f1, d1, h) -> np.ndarray:
    """The roots in [0, 1] of cubic Hermite interpolants of f (values f0, f1 of opposite
    sign, slopes d0, d1 per unit time over a step h, one for all or one each), vectorized:
    Newton from the secant root, kept inside a bracket that shrinks with every iterate
    (safeguarded).  Each root stops when its own iterate settles, as :func:`_hermite_root` does
    on one: the same arithmetic, so every root equals that function's bit for bit, whatever
    the other roots of the call (a batch's values do not depend on the variants beside them),
    and the iteration works on the unsettled roots only."""
    f0, d0, f1, d1 = (np.asarray(a, dtype=float) for a in (f0, d0, f1, d1))
    if f0.ndim == 1 and f0.size <= 16:     # the usual few roots: the same iteration on floats, no array overhead
        hs = np.broadcast_to(np.asarray(h, dtype=float), f0.shape).tolist()
        return np.array([_hermite_root(*args) for args in zip(f0.tolist(), d0.tolist(), f1.tolist(),
                                                              d1.tolist(), hs)])
    shape = np.broadcast_shapes(f0.shape, d0.shape, f1.shape, d1.shape, np.shape(h))
    f0, d0, f1, d1, h = (np.broadcast_to(a, shape).ravel() for a in (f0, d0, f1, d1, np.asarray(h, dtype=float)))
    d0, d1 = d0 * h, d1 * h
    a = 2 * f0 - 2 * f1 + d0 + d1
    b = -3 * f0 + 3 * f1 - 2 * d0 - d1
    denom = f0 - f1
    tau = np.where(denom != 0, f0 / np.where(denom != 0, denom, 1.0), 0.0).clip(0.0, 1.0)
    tau = np.where(f0 == 0, 0.0, np.where(f1 == 0, 1.0, tau))
    k = np.flatnonzero((f0 != 0) & (f1 != 0))          # the roots still iterating
    a, b, d0, f0, t = a[k], b[k], d0[k], f0[k], tau[k]
    s0 = np.sign(f0)
    lo, hi = np.zeros(k.size), np.ones(k.size)
    for _ in range(40):
        if not k.size:
            break
        p = ((a * t + b) * t + d0) * t + f0
        dp = (3 * a * t + 2 * b) * t + d0
        same = np.sign(p) == s0
        lo = np.where(same, t, lo)
        hi = np.where(same, hi, t)
        step = np.where(dp != 0, p / np.where(dp != 0, dp, 1.0), 0.0)
        new = t - step
        bad = (new < lo) | (new > hi) | ~np.isfinite(new)
        new = np.where(bad, 0.5 * (lo + hi), new)
        tau[k] = new
        go = ~(np.abs(new - t) <= 1e-13)                 # settled: this root's value is final
        k, a, b, d0, f0, s0, lo, hi, t = (x[go] for x in (k, a, b, d0, f0, s0, lo, hi, new))
    return tau.reshape(shape)


def _hermite_root(f0: float, d0: float, f1: float, d1: float, h: float) -> float:
    """:func:`hermite_roots` of one interval, on Python floats: the same safeguarded Newton
    iteration, stopped when this interval's own iterate settles (the array version stops when
    all have; the roots agree to rounding)."""
    d0, d1 = d0 * h, d1 * h
    a = 2 * f0 - 2 * f1 + d0 + d1
    b = -3 * f0 + 3 * f1 - 2 * d0 - d1
    if f0 == 0:
        return 0.0
    if f1 == 0:
        return 1.0
    denom = f0 - f1
    tau = min(max(f0 / denom, 0.0), 1.0) if denom != 0 else 0.0
    lo, hi = 0.0, 1.0
    s0 = (f0 > 0) - (f0 < 0)
    for _ in range(40):
        p = ((a * tau + b) * tau + d0) * tau + f0
        dp = (3 * a * tau + 2 * b) * tau + d0
        if ((p > 0) - (p < 0)) == s0:
            lo = tau
        else:
            hi = tau
        new = tau - (p / dp if dp != 0 else 0.0)
        if new < lo or new > hi or not math.isfinite(new):
            new = 0.5 * (lo + hi)
        if abs(new - tau) <= 1e-13:
            return new
        tau = new
    return tau


def quintic_hermite(y0, d0, s0, y1, d1, s1, h, tau) -> float:
    """Quintic Hermite interpolation of y at ``tau`` in [0, 1] from values, first and
    second derivatives (per unit time) at both ends of a step h."""
    d0, d1, s0, s1 = d0 * h, d1 * h, s0 * h * h, s1 * h * h
    t, t2, t3, t4, t5 = tau, tau ** 2, tau ** 3, tau ** 4, tau ** 5
    h00 = 1 - 10 * t3 + 15 * t4 - 6 * t5
    h10 = t - 6 * t3 + 8 * t4 - 3 * t5
    h20 = 0.5 * (t2 - 3 * t3 + 3 * t4 - t5)
    h01 = 10 * t3 - 15 * t4 + 6 * t5
    h11 = -4 * t3 + 7 * t4 - 3 * t5
    h21 = 0.5 * (t3 - 2 * t4 + t5)
    return h00 * y0 + h10 * d0 + h20 * s0 + h01 * y1 + h11 * d1 + h21 * s1


def power_scan(Phi: np.ndarray, z0: np.ndarray, count: int) -> np.ndarray:
    """``Z[k] = Phi^k z0`` for k < count by doubling (log2 count products)."""
    Z = np.empty((count, z0.size))
    Z[0] = z0
    filled, P = 1, Phi
    # an unstable vehicle run long enough overflows: the callers refuse non-finite results
    with np.errstate(over="ignore", invalid="ignore"):
        while filled < count:
            take = min(filled, count - filled)
            Z[filled:filled + take] = Z[:take] @ P.T
            filled += take
            if filled < count:
                P = P @ P
    return Z
