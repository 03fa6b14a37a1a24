"""Numerics that need numpy only: the co-simulation engine runs inside an FMU whose
embedded interpreter imports numpy and nothing heavier.

* :func:`solve_scaled` solves ``M X = B`` after a symmetric diagonal scaling by powers
  of two (exact in floating point).  The mass matrix mixes force rows (N) and moment
  rows (N*m) with velocity and yaw-rate columns; its 2-norm condition number is ~5e6
  in SI (5e8 in the thesis' inches) but ~2e2 once scaled, and partial-pivoting LU is
  not scaling invariant, so the scaling is what keeps ``M^-1 S`` accurate at low speed.
* :func:`expm` is the matrix exponential by scaling and squaring with a Pade
  approximant, the degree and the number of squarings chosen as in Al-Mohy and
  Higham, SIAM J. Matrix Anal. Appl. 31 (2009), Algorithm 5.1 -- the algorithm of
  ``scipy.linalg.expm`` (which the analysis layer uses), with the 1-norms of
  ``|A|^(2m+1)`` computed exactly instead of estimated.  The C FMU implements the same
  algorithm (``fmu_src/c/vehicle/linalg.c``); the tests hold both against scipy and a 40-digit
  reference.

Examples
--------
>>> import numpy as np
>>> float(expm(np.array([[0.0, 1.0], [0.0, 0.0]]))[0, 1])
1.0
"""
from __future__ import annotations

import math

import numpy as np

#: Pade coefficients b_0..b_m for m = 3, 5, 7, 9, 13 (Higham 2005, Table 2.3)
PADE = {
    3: (120., 60., 12., 1.),
    5: (30240., 15120., 3360., 420., 30., 1.),
    7: (17297280., 8648640., 1995840., 277200., 25200., 1512., 56., 1.),
    9: (17643225600., 8821612800., 2075673600., 302702400., 30270240., 2162160., 110880., 3960., 90., 1.),
    13: (64764752532480000., 32382376266240000., 7771770303897600., 1187353796428800., 129060195264000.,
         10559470521600., 670442572800., 33522128640., 1323241920., 40840800., 960960., 16380., 182., 1.),
}
#: theta_m: largest ||A||_1 for which degree m is accurate to unit roundoff (Al-Mohy & Higham 2009, Table 3.1)
THETA = {3: 1.495585217958292e-2, 5: 2.539398330063230e-1, 7: 9.504178996162932e-1,
         9: 2.097847961257068e0}
#: |c_(2m+1)| / ... constants of ell(A, m) (Al-Mohy & Higham 2009, eq. 5.1 and scipy's _ell)
_ELL_C = {3: 100800., 5: 10059033600., 7: 4487938430976000., 9: 5914384781877411840000.,
          13: 113250775606021113483283660800000000.}
#: theta_13 used for the scaling (Al-Mohy & Higham 2009, Algorithm 5.1)
THETA13 = 5.371920351148152


def power_of_two_scaling(M: np.ndarray) -> np.ndarray:
    """Diagonal d (powers of two) with ``d_i d_i |M_ii| ~ 1``: symmetric equilibration."""
    diag = np.abs(np.diagonal(M, axis1=-2, axis2=-1))
    rows = np.abs(M).max(axis=-1)
    base = np.where(diag > 0, diag, np.where(rows > 0, rows, 1.0))
    return np.exp2(-np.round(0.5 * np.log2(base)))


def solve_scaled(M: np.ndarray, B: np.ndarray) -> np.ndarray:
    """Solve ``M X = B`` (batched over leading axes) after symmetric power-of-two scaling.

    Parameters
    ----------
    M : numpy.ndarray, shape (..., n, n)
    B : numpy.ndarray, shape (..., n, k) or (..., n)

    Returns
    -------
    numpy.ndarray
        ``X`` with the shape of ``B``.
    """
    M = np.asarray(M, dtype=float)
    B = np.asarray(B, dtype=float)
    vector = B.ndim == M.ndim - 1
    if vector:
        B = B[..., None]
    d = power_of_two_scaling(M)
    Ms = d[..., :, None] * M * d[..., None, :]
    X = d[..., :, None] * np.linalg.solve(Ms, d[..., :, None] * B)
    return X[..., 0] if vector else X


def rowwise(X: np.ndarray, M: np.ndarray) -> np.ndarray:
    """``X @ M`` with every row of ``X`` (its last axis) multiplied on its own: a row's numbers
    never depend on the rows beside it.

    A (B, n) @ (n, k) product is one BLAS call, and BLAS may round a row by B (its blocking; a
    matrix-vector product with fused multiply-adds where a dot product has none: seen with
    OpenBLAS's AVX-512 and Sandy Bridge kernels), so a variant's numbers in a batch would depend on
    how many variants share the call.  As a stack of one-row products they do not.

    Parameters
    ----------
    X : numpy.ndarray, shape (..., n)
    M : numpy.ndarray, shape (n, k) or (n,)

    Returns
    -------
    numpy.ndarray
        Shape (..., k), or (...) for a vector ``M``.

    Examples
    --------
    >>> import numpy as np
    >>> X, M = np.arange(6.0).reshape(3, 2), np.array([[1.0, 2.0], [3.0, 4.0]])
    >>> np.array_equal(rowwise(X, M), X @ M), np.array_equal(rowwise(X[1:2], M), rowwise(X, M)[1:2])
    (True, True)
    """
    X = np.asarray(X)
    out = X[..., None, :] @ M
    return out[..., 0] if np.ndim(M) == 1 else out[..., 0, :]


def _onenorm(A: np.ndarray) -> float:
    return float(np.abs(A).sum(axis=0).max())


def _ell(A: np.ndarray, m: int) -> int:
    """Extra squarings so that the Pade backward error stays at unit roundoff (Al-Mohy & Higham 2009)."""
    nrm = _onenorm(A)
    if nrm == 0.0:
        return 0
    absA = np.abs(A)
    r = np.ones(A.shape[0])
    for _ in range(2 * m + 1):       # r <- r |A|: column sums of |A|^(2m+1), exactly
        r = r @ absA
    abs_pow = float(r.max())
    if abs_pow == 0.0:
        return 0
    alpha = abs_pow / (nrm * _ELL_C[m])
    return max(int(math.ceil(math.log2(alpha / 2.0 ** -53) / (2 * m))), 0)


def expm(A: np.ndarray) -> np.ndarray:
    """Matrix exponential of a real square matrix (Al-Mohy & Higham 2009, Algorithm 5.1).

    Parameters
    ----------
    A : numpy.ndarray, shape (n, n)

    Returns
    -------
    numpy.ndarray, shape (n, n)

    Raises
    ------
    FloatingPointError
        If ``A`` or the result is not finite.
    """
    A = np.asarray(A, dtype=float)
    if not np.all(np.isfinite(A)):
        raise FloatingPointError("expm: the matrix is not finite")
    n = A.shape[0]
    ident = np.eye(n)
    A2 = A @ A
    A4 = A2 @ A2
    A6 = A4 @ A2
    d4 = _onenorm(A4) ** 0.25
    d6 = _onenorm(A6) ** (1 / 6)
    eta1 = max(d4, d6)
    s = 0
    m = None
    if eta1 <= THETA[3] and _ell(A, 3) == 0:
        m = 3
    elif eta1 <= THETA[5] and _ell(A, 5) == 0:
        m = 5
    else:
        A8 = A4 @ A4
        d8 = _onenorm(A8) ** 0.125
        eta3 = max(d6, d8)
        if eta3 <= THETA[7] and _ell(A, 7) == 0:
            m = 7
        elif eta3 <= THETA[9] and _ell(A, 9) == 0:
            m = 9
        else:
            d10 = _onenorm(A4 @ A6) ** 0.1
            eta5 = min(eta3, max(d8, d10))
            s = max(int(math.ceil(math.log2(eta5 / THETA13))), 0) if eta5 > 0 else 0
            s += _ell(A * 2.0 ** -s, 13)
            m = 13
            if s > 0:
                f = 2.0 ** -s
                A, A2, A4, A6 = A * f, A2 * f ** 2, A4 * f ** 4, A6 * f ** 6
    b = PADE[m]
    if m <= 9:
        powers = {2: A2, 4: A4, 6: A6}
        if m == 9:
            powers[8] = A4 @ A4
        U = b[1] * ident
        V = b[0] * ident
        for k in range(2, m, 2):
            U = U + b[k + 1] * powers[k]
            V = V + b[k] * powers[k]
        U = A @ U
    else:
        U = A @ (A6 @ (b[13] * A6 + b[11] * A4 + b[9] * A2) + b[7] * A6 + b[5] * A4 + b[3] * A2 + b[1] * ident)
        V = A6 @ (b[12] * A6 + b[10] * A4 + b[8] * A2) + b[6] * A6 + b[4] * A4 + b[2] * A2 + b[0] * ident
    E = np.linalg.solve(V - U, V + U)
    for _ in range(s):
        E = E @ E
    if not np.all(np.isfinite(E)):
        raise FloatingPointError("expm: the exponential is not finite (overflow)")
    return E
