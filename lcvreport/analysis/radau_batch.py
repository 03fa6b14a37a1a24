r"""Many runs of one model integrated side by side: scipy's Radau IIA (order 5) method, step for
step, for B variants at once, each with its own steps (docs/nonlinear.md#integration).

Every variant takes the steps it would take alone: its step sizes, Newton iterations, Jacobians
and error estimates depend on its own states only, and the equations are evaluated row by row
(one row per state: the 3 collocation points of every variant in one call; no BLAS call,
whose kernels differ with the number of rows), so that a variant's
run is the same, bit for bit, in a batch of one and in a batch of a hundred
(tests/test_radau_batch.py).  What the batch saves is the cost of a call of the equations, which
at these sizes is mostly the interpreter's: a hundred variants' stages cost a few times one's.

The method is :class:`scipy.integrate.Radau`'s (its Butcher tableau, its simplified Newton
iteration on the transformed collocation system, its error estimate and step-size controller,
its dense output), rewritten over a leading batch axis; the Jacobian is a forward difference
(the iteration's own: it only sets the convergence rate), the linear systems solved with the
inverses of ``MU/h - J`` (real and complex).  Each run's result is tested against
``scipy.integrate.solve_ivp(method="Radau")`` of the same equations (tests/test_radau_batch.py).

Examples
--------
>>> import numpy as np
>>> k = np.array([1.0, 10.0, 1000.0])                     # y' = -k y, three variants
>>> runs = radau_batch(lambda t, y, rows: -k[rows, None] * y, 0.0, np.ones((3, 1)), 1.0, rtol=1e-8, atol=1e-12)
>>> [bool(abs(r.sol(1.0)[0] - np.exp(-kk)) < 1e-7) for r, kk in zip(runs, k)]
[True, True, True]
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# scipy.integrate._ivp.radau's constants (Hairer & Wanner's RADAU5)
S6 = 6 ** 0.5
C = np.array([(4 - S6) / 10, (4 + S6) / 10, 1])
E = np.array([-13 - 7 * S6, -13 + 7 * S6, -1]) / 3
MU_REAL = 3 + 3 ** (2 / 3) - 3 ** (1 / 3)
MU_COMPLEX = (3 + 0.5 * (3 ** (1 / 3) - 3 ** (2 / 3)) - 0.5j * (3 ** (5 / 6) + 3 ** (7 / 6)))
T = np.array([[0.09443876248897524, -0.14125529502095421, 0.03002919410514742],
              [0.25021312296533332, 0.20412935229379994, -0.38294211275726192],
              [1, 1, 0]])
TI = np.array([[4.17871859155190428, 0.32768282076106237, 0.52337644549944951],
               [-4.17871859155190428, -0.32768282076106237, 0.47662355450055044],
               [0.50287263494578682, -2.57192694985560522, 0.59603920482822492]])
TI_REAL = TI[0]
TI_COMPLEX = TI[1] + 1j * TI[2]
P = np.array([[13 / 3 + 7 * S6 / 3, -23 / 3 - 22 * S6 / 3, 10 / 3 + 5 * S6],
              [13 / 3 - 7 * S6 / 3, -23 / 3 + 22 * S6 / 3, 10 / 3 - 5 * S6],
              [1 / 3, -8 / 3, 10 / 3]])
NEWTON_MAXITER = 6
MIN_FACTOR = 0.2
MAX_FACTOR = 10
EPS = np.finfo(float).eps
#: the forward difference's relative step of the Jacobian (of max(|y|, 1) in the state's unit)
JAC_STEP = EPS ** 0.5


class RowFailure(Exception):
    """Raised by the equations for one row of a call: ``row`` (its index in the call) and the
    message the variant's run ends with; the other rows are evaluated again without it."""

    def __init__(self, row: int, message: str):
        self.row = int(row)
        super().__init__(message)


@dataclass
class BatchDense:
    """The dense output of one variant's run: Radau's collocation polynomial on every step
    (``t_old``, ``h``, ``y_old``, ``Q``: scipy's ``RadauDenseOutput`` per step).  Called as an
    ``OdeSolution``: ``sol(t)`` is (n,) for a scalar ``t``, (n, k) for k times."""

    t_old: np.ndarray
    h: np.ndarray
    y_old: np.ndarray
    Q: np.ndarray

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        ts = np.atleast_1d(t)
        ends = self.t_old + self.h
        k = np.clip(np.searchsorted(ends, ts, side="left"), 0, self.h.size - 1)
        x = (ts - self.t_old[k]) / self.h[k]
        p = np.stack([x, x * x, x * x * x], axis=1)                       # scipy's cumprod of x
        y = np.einsum("knj,kj->kn", self.Q[k], p) + self.y_old[k]
        return y[0] if t.ndim == 0 else y.T


@dataclass
class BatchRun:
    """One variant's run: ``status`` 0 (reached ``t_end``), 1 (the stop condition: ``stopped_at``
    [s]) or -1 (failed: ``message``), its dense output ``sol`` (None if it took no step), the
    number of evaluations of its equations ``nfev`` and its steps ``t`` (the ends)."""

    status: int = 0
    message: str = ""
    stopped_at: float | None = None
    nfev: int = 0
    sol: BatchDense | None = None
    t: list = field(default_factory=list)


def _rms(x: np.ndarray) -> np.ndarray:
    """scipy's RMS norm of every row's entries (axes after the first)."""
    flat = x.reshape(x.shape[0], -1)
    return np.sqrt(np.einsum("ij,ij->i", flat.real, flat.real)) / flat.shape[1] ** 0.5


def _predict_factor(h_abs, h_abs_old, error_norm, error_norm_old):
    """scipy's Radau step-size factor, per variant (NaN for scipy's None)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        two_step = ~np.isnan(error_norm_old) & ~np.isnan(h_abs_old) & (error_norm != 0)
        multiplier = np.where(two_step, h_abs / np.where(two_step, h_abs_old, 1.0)
                              * (np.where(two_step, error_norm_old, 1.0) / np.where(two_step, error_norm, 1.0)) ** 0.25,
                              1.0)
        return np.minimum(1.0, multiplier) * error_norm ** -0.25


def radau_batch(fun, t0: float, y0: np.ndarray, t_end: float, rtol: float, atol: float, stop=None,
                max_evaluations: int = 60_000) -> list[BatchRun]:
    """Integrate ``y' = fun(t, y)`` for every variant (row of ``y0``, (B, n)) from ``t0`` to
    ``t_end`` [s], each as scipy's ``Radau`` would with ``rtol``, ``atol`` (see the module
    docstring).

    Parameters
    ----------
    fun : callable
        ``fun(t, Y, rows) -> (k, n)``: the derivatives of the states ``Y`` (k, n) at the times
        ``t`` (k,) of the variants ``rows`` (k,) (indices of ``y0``'s rows); may raise
        :class:`RowFailure` for a row whose variant cannot go on.
    t0, t_end : float
    y0 : numpy.ndarray
        (B, n) start states.
    rtol, atol : float
    stop : callable, optional
        ``stop(t, Y, rows) -> (k,)`` of the states ``Y`` (k, n) at the times ``t`` (k,) of the
        variants ``rows``: a variant's run ends where its value first falls through zero (located
        on the dense output to 4 eps, as solve_ivp's events).
    max_evaluations : int
        The most evaluations of a variant's equations (a count: the same on any machine).

    Returns
    -------
    list of BatchRun
        One per variant, in ``y0``'s order.
    """
    from scipy.optimize import brentq
    y0 = np.atleast_2d(np.asarray(y0, dtype=float))
    B, n = y0.shape
    runs = [BatchRun() for _ in range(B)]
    alive = np.ones(B, dtype=bool)
    count = np.zeros(B, dtype=np.int64)
    I = np.eye(n)

    def fail(b: int, message: str) -> None:
        alive[b] = False
        runs[b].status, runs[b].message = -1, message

    def evaluate(t, Y, rows):
        """fun over the rows of living variants; a failing row's variant dies and its rows are NaN."""
        rows = np.asarray(rows)
        keep = alive[rows]
        called = np.unique(rows[keep])
        count[called] += 1                                 # one call of each variant's equations
        for b in called[count[called] > max_evaluations]:
            fail(int(b), f"the integration stopped at t = {float(t[rows == b][0]):.3f} s after {max_evaluations} "
                         "evaluations of the model's equations (the run cannot be integrated further: a vehicle "
                         "out of control?)")
        keep = alive[rows]
        if keep.all():                                     # the usual call: every row's variant alive
            try:
                return np.asarray(fun(t, Y, rows), dtype=float)
            except RowFailure:
                pass                                       # the rows again, one failure at a time, below
        out = np.full(Y.shape, np.nan)
        while keep.any():
            sel = np.flatnonzero(keep)
            try:
                out[sel] = fun(t[sel], Y[sel], rows[sel])
                break
            except RowFailure as exc:
                b = int(rows[sel[exc.row]])
                fail(b, f"at t = {float(t[sel[exc.row]]):.3f} s: {exc}")
                keep &= rows != b
        return out

    def jacobian(idx, t, y, f):
        """Forward-difference Jacobians (k, n, n) of the variants ``idx`` at (t, y) with f = fun(t, y)."""
        k = idx.size
        step = JAC_STEP * np.maximum(np.abs(y), 1.0)                            # (k, n)
        Y = np.repeat(y[:, None, :], n, axis=1) + step[:, :, None] * I          # (k, n cols, n)
        h = (Y - y[:, None, :])[:, np.arange(n), np.arange(n)]                 # the steps as taken
        F = evaluate(np.repeat(t, n), Y.reshape(k * n, n), np.repeat(idx, n)).reshape(k, n, n)
        return np.transpose((F - f[:, None, :]) / h[:, :, None], (0, 2, 1))

    t = np.full(B, float(t0))
    y = y0.copy()
    f = evaluate(t, y, np.arange(B))
    # the first step: scipy's select_initial_step, order 3
    scale = atol + np.abs(y) * rtol
    d0, d1 = _rms(y / scale), _rms(f / scale)
    h0 = np.where((d0 < 1e-5) | (d1 < 1e-5), 1e-6, 0.01 * d0 / np.where(d1 > 0, d1, 1.0))
    h0 = np.minimum(h0, abs(t_end - t0))
    f1 = evaluate(t + h0, y + h0[:, None] * f, np.arange(B))
    d2 = _rms((f1 - f) / scale) / h0
    with np.errstate(divide="ignore"):
        h1 = np.where((d1 <= 1e-15) & (d2 <= 1e-15), np.maximum(1e-6, h0 * 1e-3),
                      (0.01 / np.maximum(d1, d2)) ** (1 / 4))
    h_abs = np.minimum.reduce([100 * h0, h1, np.full(B, abs(t_end - t0))])
    h_abs_old = np.full(B, np.nan)
    error_norm_old = np.full(B, np.nan)
    newton_tol = max(10 * EPS / rtol, min(0.03, rtol ** 0.5))
    J = np.full((B, n, n), np.nan)
    live = np.flatnonzero(alive)
    if live.size:
        J[live] = jacobian(live, t[live], y[live], f[live])
    current_jac = np.ones(B, dtype=bool)
    inv_real = np.full((B, n, n), np.nan)
    inv_complex = np.full((B, n, n), np.nan, dtype=complex)
    have_inv = np.zeros(B, dtype=bool)
    rejected = np.zeros(B, dtype=bool)
    step_start = np.ones(B, dtype=bool)                  # the next attempt begins a step
    h_start = h_abs.copy()                               # self.h_abs at the step's start (scipy's h_abs_old next)
    # the last step's dense output (the Newton iteration's starting guess)
    Q_last = np.full((B, n, 3), np.nan)
    t_last = np.full(B, np.nan)
    h_last = np.full(B, np.nan)
    y_last = np.full((B, n), np.nan)
    pieces = [[] for _ in range(B)]
    stop_prev = np.full(B, np.nan)
    if stop is not None and alive.any():
        live = np.flatnonzero(alive)
        stop_prev[live] = stop(t[live], y[live], live)
    hold_h_old = h_abs_old.copy()
    hold_err_old = error_norm_old.copy()

    def newton(idx, h, Z0, scale):
        """The collocation system of the variants ``idx`` (scipy's solve_collocation_system)."""
        k = idx.size
        M_real = MU_REAL / h
        M_complex = MU_COMPLEX / h
        W = np.einsum("ij,kjn->kin", TI, Z0)
        Z = Z0.copy()
        ch = h[:, None] * C
        dW_norm_old = np.full(k, np.nan)
        rate = np.full(k, np.nan)
        converged = np.zeros(k, dtype=bool)
        going = np.ones(k, dtype=bool)
        n_iter = np.zeros(k, dtype=np.int64)
        t_i, y_i, inv_r, inv_c = t[idx][:, None], y[idx][:, None, :], inv_real[idx], inv_complex[idx]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            return _newton_iterations(idx, k, W, Z, ch, dW_norm_old, rate, converged, going, n_iter, t_i, y_i,
                                      inv_r, inv_c, M_real, M_complex, scale)

    def _newton_iterations(idx, k, W, Z, ch, dW_norm_old, rate, converged, going, n_iter, t_i, y_i, inv_r, inv_c,
                           M_real, M_complex, scale):
        for it in range(NEWTON_MAXITER):
            g = np.flatnonzero(going & alive[idx])
            if g.size == 0:
                break
            n_iter[g] = it + 1
            G = slice(None) if g.size == k else g          # all of them (the usual case): views, not copies
            F = evaluate((t_i[G] + ch[G]).ravel(), (y_i[G] + Z[G]).reshape(-1, n),
                         np.repeat(idx[G], 3)).reshape(g.size, 3, n)
            if not np.isfinite(F).all():
                finite = np.isfinite(F).all(axis=(1, 2))
                going[g[~finite]] = False
                g, F = g[finite], F[finite]
                if g.size == 0:
                    continue
                G = g
            f_real = np.einsum("kin,i->kn", F, TI_REAL) - M_real[G, None] * W[G, 0]
            f_complex = np.einsum("kin,i->kn", F, TI_COMPLEX) - M_complex[G, None] * (W[G, 1] + 1j * W[G, 2])
            dW_real = np.einsum("kij,kj->ki", inv_r[G], f_real)
            dW_complex = np.einsum("kij,kj->ki", inv_c[G], f_complex)
            dW = np.stack([dW_real, dW_complex.real, dW_complex.imag], axis=1)
            dW_norm = _rms(dW / scale[G, None, :])
            if it == 0:                                    # no rate yet (NaN): none diverges
                gg, GG = g, G
                done = dW_norm == 0
            else:
                norm_old = dW_norm_old[G]
                has_old = ~np.isnan(norm_old)
                if has_old.all():
                    rate[G] = dW_norm / norm_old
                else:
                    rate[G] = np.where(has_old, dW_norm / np.where(has_old, norm_old, 1.0), rate[G])
                r = rate[G]
                diverge = ~np.isnan(r) & ((r >= 1) | (r ** (NEWTON_MAXITER - it) / (1 - r) * dW_norm > newton_tol))
                if diverge.any():
                    going[g[diverge]] = False
                    ok = ~diverge
                    gg = g[ok]
                    GG, dW, dW_norm, r = gg, dW[ok], dW_norm[ok], r[ok]
                else:
                    gg, GG = g, G
                done = (dW_norm == 0) | (~np.isnan(r) & (r / (1 - r) * dW_norm < newton_tol))
            W[GG] += dW
            Z[GG] = np.einsum("ij,kjn->kin", T, W[GG])
            converged[gg[done]] = True
            going[gg[done]] = False
            dW_norm_old[GG] = dW_norm
        return converged & alive[idx], n_iter, Z, rate

    while True:
        A = np.flatnonzero(alive & (t < t_end))
        if A.size == 0:
            break
        # a step's start: scipy's _step_impl preamble
        s = A[step_start[A]]
        if s.size:
            min_step = 10 * np.abs(np.nextafter(t[s], np.inf) - t[s])
            small = h_abs[s] < min_step
            h_abs[s[small]] = min_step[small]
            hold_h_old[s] = np.where(small, np.nan, h_abs_old[s])
            hold_err_old[s] = np.where(small, np.nan, error_norm_old[s])
            rejected[s] = False
            step_start[s] = False
        min_step = 10 * np.abs(np.nextafter(t[A], np.inf) - t[A])
        tiny = h_abs[A] < min_step
        for b in A[tiny]:
            fail(int(b), f"the integration failed at t = {t[b]:g} s: the step size fell below its smallest value")
        A = A[~tiny]
        if A.size == 0:
            continue
        t_new = np.minimum(t[A] + h_abs[A], t_end)
        h = t_new - t[A]
        h_abs[A] = np.abs(h)
        Z0 = np.zeros((A.size, 3, n))
        had = ~np.isnan(t_last[A])
        if had.any():
            a = A[had]
            x = ((t[a][:, None] + h[had][:, None] * C) - t_last[a][:, None]) / h_last[a][:, None]     # (k, 3)
            p = np.stack([x, x * x, x * x * x], axis=2)                                              # (k, 3, 3)
            Z0[had] = np.einsum("knj,kij->kin", Q_last[a], p) + y_last[a][:, None, :] - y[a][:, None, :]
        scale = atol + np.abs(y[A]) * rtol
        # the LU (here: inverses) where missing
        need = A[~have_inv[A]]
        if need.size:
            hn = h[np.searchsorted(A, need)]
            inv_real[need] = np.linalg.inv(MU_REAL / hn[:, None, None] * I - J[need])
            inv_complex[need] = np.linalg.inv(MU_COMPLEX / hn[:, None, None] * I - J[need])
            have_inv[need] = True
        converged, n_iter, Z, rate = newton(A, h, Z0, scale)
        retry = np.flatnonzero(~converged & ~current_jac[A] & alive[A])
        if retry.size:                                    # a fresh Jacobian, and once more
            R = A[retry]
            J[R] = jacobian(R, t[R], y[R], f[R])
            current_jac[R] = True
            inv_real[R] = np.linalg.inv(MU_REAL / h[retry][:, None, None] * I - J[R])
            inv_complex[R] = np.linalg.inv(MU_COMPLEX / h[retry][:, None, None] * I - J[R])
            c2, n2, Z2, r2 = newton(R, h[retry], Z0[retry], scale[retry])
            converged[retry], n_iter[retry], Z[retry], rate[retry] = c2, n2, Z2, r2
        # not converged: halve the step
        bad = ~converged & alive[A]
        h_abs[A[bad]] *= 0.5
        have_inv[A[bad]] = False
        ok = np.flatnonzero(converged)
        if ok.size == 0:
            continue
        a, hk, Zk = A[ok], h[ok], Z[ok]
        y_new = y[a] + Zk[:, -1]
        ZE = np.einsum("kin,i->kn", Zk, E) / hk[:, None]
        error = np.einsum("kij,kj->ki", inv_real[a], f[a] + ZE)
        sc = atol + np.maximum(np.abs(y[a]), np.abs(y_new)) * rtol
        error_norm = _rms(error / sc)
        safety = 0.9 * (2 * NEWTON_MAXITER + 1) / (2 * NEWTON_MAXITER + n_iter[ok])
        again = np.flatnonzero(rejected[a] & (error_norm > 1))
        if again.size:
            b2 = a[again]
            fe = evaluate(t[b2], y[b2] + error[again], b2)
            error[again] = np.einsum("kij,kj->ki", inv_real[b2], fe + ZE[again])
            error_norm[again] = _rms(error[again] / sc[again])
        still = alive[a]
        reject = (error_norm > 1) & still
        if reject.any():
            r = a[reject]
            factor = _predict_factor(h_abs[r], hold_h_old[r], error_norm[reject], hold_err_old[r])
            h_abs[r] *= np.maximum(MIN_FACTOR, safety[reject] * factor)
            have_inv[r] = False
            rejected[r] = True
        acc = ~reject & still
        if not acc.any():
            continue
        a, hk, Zk, y_new = a[acc], hk[acc], Zk[acc], y_new[acc]
        err, saf, ni, rt = error_norm[acc], safety[acc], n_iter[ok][acc], rate[ok][acc]
        recompute_jac = (ni > 2) & (rt > 1e-3)
        factor = _predict_factor(h_abs[a], hold_h_old[a], err, hold_err_old[a])
        factor = np.minimum(MAX_FACTOR, saf * factor)
        keep_h = ~recompute_jac & (factor < 1.2)
        factor = np.where(keep_h, 1.0, factor)
        have_inv[a[~keep_h]] = False
        tn = t_new[ok][acc]
        f_new = evaluate(tn, y_new, a)
        rj = a[recompute_jac & alive[a]]
        if rj.size:
            sel = np.searchsorted(a, rj)
            J[rj] = jacobian(rj, tn[sel], y_new[sel], f_new[sel])
        current_jac[a] = recompute_jac
        h_abs_old[a] = h_start[a]
        error_norm_old[a] = err
        h_abs[a] = h_abs[a] * factor
        h_start[a] = h_abs[a]
        Q = np.einsum("kin,ij->knj", Zk, P)                                     # (k, n, 3)
        for j, b in enumerate(a):
            if not alive[b]:
                continue
            pieces[b].append((t[b], hk[j], y[b].copy(), Q[j]))
            runs[b].t.append(float(tn[j]))
        t_last[a], h_last[a], y_last[a], Q_last[a] = t[a], hk, y[a], Q
        t[a], y[a], f[a] = tn, y_new, f_new
        step_start[a] = True
        live = a[alive[a]]
        if stop is not None and live.size:
            g_new = stop(t[live], y[live], live)
            for b, g in zip(live[(stop_prev[live] >= 0) & (g_new <= 0)], g_new[(stop_prev[live] >= 0) & (g_new <= 0)]):
                t_a, h_b, y_b, Q_b = pieces[b][-1]                 # solve_ivp's event falling through zero
                dense = BatchDense(np.array([t_a]), np.array([h_b]), y_b[None], Q_b[None])
                root = brentq(lambda s, b=b, dense=dense: float(stop(np.array([s]), dense(s)[None], np.array([b]))[0]),
                              t_a, t[b], xtol=4 * EPS, rtol=4 * EPS)
                runs[b].status, runs[b].stopped_at = 1, float(root)
                alive[b] = False
            stop_prev[live] = g_new
    for b, run in enumerate(runs):
        run.nfev = int(count[b])
        if pieces[b]:
            ta, hs, ys, Qs = zip(*pieces[b])
            run.sol = BatchDense(np.array(ta), np.array(hs), np.array(ys), np.array(Qs))
    return runs


__all__ = ["radau_batch", "BatchRun", "BatchDense", "RowFailure", "math"]
