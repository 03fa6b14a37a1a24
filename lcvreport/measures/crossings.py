r"""Every speed where the linear model's stability can change, exactly: the check that the
critical-speed scan (:func:`lcvreport.measures.stability.critical_speed`) missed no
instability band (docs/measures.md#critical-speed).

An eigenvalue of ``M(u) x' = S(u) x`` crosses the imaginary axis at speed u either through 0
(``det S(u) = 0``) or as a pair ``+-i w``; with ``P(u) = u S(u) = s Sinv + u (s S0 + Skin) + u^2 Su``
the pencil ``(P(u), M(u))`` has the eigenvalues ``u lambda``, and a pair ``lambda_i + lambda_j = 0``
makes its bialternate product singular: ``det(P(u) (.) M(u)) = 0`` (``(.)`` the bialternate
product, order n(n-1)/2, Govaerts 2000, *Numerical methods for bifurcations of dynamical
equilibria*, ch. 4).  Both are polynomial eigenvalue problems in u (degree 2 of order n, degree 3
of order n(n-1)/2), solved by QZ on their companion linearizations: their real roots in the range
are every speed where the stability can change (the roots of ``lambda_i = -lambda_j`` real are
kept too; they change nothing).  Between two consecutive roots the count of unstable eigenvalues
is constant, so ``max Re(lambda)`` at each interval's midpoint says which intervals are unstable:
no band is missed, however narrow.  The cost grows as n^6 (0.1-0.3 s at 6 units): a check, not
the scan.

Examples
--------
>>> from lcvreport import load_preset
>>> c = stability_crossings(load_preset("empty"), tire_scale=0.2)
>>> round(c.critical_speed_kph, 2), len(c.unstable_kph)
(73.9, 1)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ..model.linear import check_tire_scale, linear_model, stiffness
from ..model.vehicle import Vehicle
from ..ranges import RANGES
from ..units import kph_to_mps, mps_to_kph
from ..util.numerics import solve_scaled
from .stability import CRITICAL_SPEED_MAX_KPH, U_MIN_DEFAULT_MPS


@dataclass(frozen=True)
class StabilityCrossings:
    """The speeds where the stability can change and the unstable speed ranges.

    Attributes
    ----------
    crossings_kph : numpy.ndarray
        Every root in the range [km/h], ascending.
    unstable_kph : list of (float, float)
        The ranges [km/h] where ``max Re(lambda) >= 0``, ascending.
    critical_speed_kph : float or None
        The start of the first unstable range (the range's lower end if unstable there), None if
        stable throughout.
    """

    crossings_kph: np.ndarray
    unstable_kph: list
    critical_speed_kph: float | None


def bialternate(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """The bialternate product ``A (.) B`` of two n x n matrices, order n(n-1)/2 (pairs p > q):
    ``1/2 (a_pr b_qs - a_ps b_qr + b_pr a_qs - b_ps a_qr)``; ``2 A (.) I`` has the eigenvalues
    ``lambda_i + lambda_j`` (i < j) of A."""
    n = A.shape[0]
    p, q = np.tril_indices(n, -1)
    Ap_r, Aq_s = A[np.ix_(p, p)], A[np.ix_(q, q)]
    Ap_s, Aq_r = A[np.ix_(p, q)], A[np.ix_(q, p)]
    Bp_r, Bq_s = B[np.ix_(p, p)], B[np.ix_(q, q)]
    Bp_s, Bq_r = B[np.ix_(p, q)], B[np.ix_(q, p)]
    return 0.5 * (Ap_r * Bq_s - Ap_s * Bq_r + Bp_r * Aq_s - Bp_s * Aq_r)


def _polynomial_roots(coefficients: list[np.ndarray]) -> np.ndarray:
    """The finite eigenvalues u of ``sum_k u^k C_k`` (C_k order N), by QZ of the first companion
    linearization."""
    d = len(coefficients) - 1
    N = coefficients[0].shape[0]
    L = np.zeros((d * N, d * N))
    R = np.eye(d * N)
    for k in range(d - 1):
        L[k * N:(k + 1) * N, (k + 1) * N:(k + 2) * N] = np.eye(N)
    for k in range(d):
        L[(d - 1) * N:, k * N:(k + 1) * N] = -coefficients[k]
    R[(d - 1) * N:, (d - 1) * N:] = coefficients[d]
    w = scipy.linalg.eig(L, R, right=False, overwrite_a=True, overwrite_b=True, check_finite=False)
    return w[np.isfinite(w)]


def _near(u: float, roots: np.ndarray, window_mps: float = 2.0) -> bool:
    return bool(roots.size) and float(np.abs(roots - u).min()) <= window_mps


def _polish_all(co, s: float, u: float, tries: int = 4) -> list[float]:
    """The roots Newton reaches from ``u`` [m/s] starting on each of the ``tries`` eigenvalues
    nearest the imaginary axis there (the root QZ gave may sit a few km/h off its crossing, where
    another mode is nearer the axis)."""
    S = stiffness(co, u, s)
    w = scipy.linalg.eigvals(S, co.M0 + u * co.M1)
    order = np.argsort(np.abs(w.real) / np.maximum(1.0, np.abs(w)))
    out = []
    for k in order[:tries]:
        r = _polish(co, s, u, start=w[k])
        if r is not None and not any(abs(r - x) <= 1e-9 * r for x in out):
            out.append(r)
    return out


def _polish(co, s: float, u: float, steps: int = 30, start=None) -> float | None:
    """Newton on ``Re lambda(u) = 0`` for the eigenvalue of ``S(u) x = lambda M(u) x`` nearest the
    imaginary axis at the start ``u`` [m/s], with ``d lambda / du = y^H (S' - lambda M') x / y^H M x``
    (left and right eigenvectors y, x); the speed [m/s], or None where it does not converge."""
    target = start
    for _ in range(steps):
        if not u > 0.0:
            return None
        S = stiffness(co, u, s)
        M = co.M0 + u * co.M1
        w, vl, vr = scipy.linalg.eig(S, M, left=True, right=True)
        if target is None:                      # the eigenvalue this root makes cross
            k = int(np.argmin(np.abs(w.real) / np.maximum(1.0, np.abs(w))))
        else:                                   # the one continuing it
            k = int(np.argmin(np.abs(w - target)))
        lam, x, y = w[k], vr[:, k], vl[:, k]
        dS = -s * co.Sinv / u**2 + co.Su
        with np.errstate(invalid="ignore", divide="ignore"):   # y^H M x = 0: an infinite eigenvalue
            dlam = (y.conj() @ (dS - lam * co.M1) @ x) / (y.conj() @ M @ x)
        if dlam.real == 0.0 or not np.isfinite(dlam):
            return None
        step = -lam.real / dlam.real
        u, target = u + step, lam + dlam * step
        if abs(step) <= 1e-10 * u:
            return u
    return None


def stability_crossings(vehicle: Vehicle, tire_scale: float = 1.0, model: str = "yaw_plane",
                        u_min_mps: float = U_MIN_DEFAULT_MPS,
                        u_max_kph: float = CRITICAL_SPEED_MAX_KPH) -> StabilityCrossings:
    """Every speed in ``[u_min, u_max]`` where an eigenvalue of the linear model ``model`` can cross
    the imaginary axis, and the unstable ranges between them (see the module docstring).

    Parameters
    ----------
    vehicle : Vehicle
    tire_scale : float
        Factor on every tire coefficient [-].
    model : str
        The linear model (:data:`lcvreport.model.linear.MODELS`).
    u_min_mps, u_max_kph : float
        The range: the critical-speed scan's (u_min [m/s], u_max [km/h]).

    Returns
    -------
    StabilityCrossings
    """
    check_tire_scale(tire_scale)
    lo = RANGES["u_min"].check(u_min_mps, "u_min")
    return crossings_of(linear_model(vehicle, model), float(tire_scale), lo, kph_to_mps(u_max_kph))


def max_real(co, s: float, u_mps) -> np.ndarray:
    """``max Re(lambda)`` [1/s] of ``M(u)^-1 S(u, s)`` from the coefficients of ``co`` at the speeds ``u_mps``."""
    u = np.asarray(u_mps, dtype=float)[..., None, None]
    M = co.M0 + u * co.M1
    S = stiffness(co, u, s)
    return np.linalg.eigvals(solve_scaled(M, S)).real.max(axis=-1)


def crossings_of(co, s: float, lo: float, hi: float) -> StabilityCrossings:
    """:func:`stability_crossings` of any coefficients ``co`` (attributes ``M0, M1, S0, Sinv, Su,
    Skin``, n x n, SI) at tire scale ``s`` over the speeds ``[lo, hi]`` [m/s]."""
    n = co.M0.shape[0]
    P = [s * co.Sinv, s * co.S0 + co.Skin, co.Su]                 # u S(u) = P0 + u P1 + u^2 P2
    M = [co.M0, co.M1]
    roots = [_polynomial_roots(P)]                                 # a real eigenvalue through 0
    N = n * (n - 1) // 2
    C = [np.zeros((N, N)) for _ in range(4)]                      # P(u) (.) M(u), degree 3 in u
    for a in range(3):
        for b in range(2):
            C[a + b] += bialternate(P[a], M[b])
    if N:
        roots.append(_polynomial_roots(C))                         # a pair lambda_i + lambda_j = 0
    u = np.concatenate(roots)
    real = u[np.abs(u.imag) <= 1e-3 * np.maximum(1.0, np.abs(u))].real   # loose: an extra root costs one evaluation
    real = real[(real > 0.5 * lo) & (real < 2.0 * hi)]
    # QZ's roots are backward stable, not accurate (the coefficients mix units over many decades):
    # each is polished by Newton on the real part of the eigenvalue it makes cross
    polished = [x for r in real for x in _polish_all(co, s, float(r))]
    inside = np.unique(np.array([r for r in polished if lo < r < hi]))
    # a root that would not polish is kept as it is: an interval edge more costs nothing
    inside = np.union1d(inside, [r for r in real if lo < r < hi and not _near(r, inside)])
    edges = np.r_[lo, inside, hi]
    sigma = max_real(co, s, 0.5 * (edges[:-1] + edges[1:]))
    unstable = []
    for k in np.flatnonzero(sigma >= 0.0):
        start, end = float(edges[k]), float(edges[k + 1])
        if unstable and math.isclose(unstable[-1][1], start):
            unstable[-1] = (unstable[-1][0], end)
        else:
            unstable.append((start, end))
    if float(max_real(co, s, lo)) >= 0.0 and (not unstable or unstable[0][0] > lo):
        unstable.insert(0, (lo, float(edges[1])))
    ranges_kph = [(mps_to_kph(a), mps_to_kph(b)) for a, b in unstable]
    return StabilityCrossings(mps_to_kph(inside), ranges_kph, ranges_kph[0][0] if ranges_kph else None)
