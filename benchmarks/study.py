"""Benchmark: variants in a batch and ``lcv study`` (issue 21, SPEC section 14).

1. The batched measures of B variants of aucnat at 88 km/h, +-20 % on every unit's mass and
   yaw inertia and every axle's C_F, C_M, C_S (every nonzero parameter):
   - the core (least damping ratio and frequency, critical speed, RA at 0.5 Hz, the RA peak over
     0.1-2 Hz, HSSO) against (a) a straightforward vectorised numpy implementation of the same
     measures written here, from the variants' own coefficient stacks (built per variant with
     the package's model builder, untimed; the algorithms are this file's: eigenvalues, solves,
     a coarse speed scan and bisection, a frequency scan and golden section), and (b) the loop
     of the one-variant calls (least_damping, critical_speed, rearward_amplification,
     field_measures.ra_peak, field_measures.steady_turn);
   - the whole measure set (``VariantBatch.measures``: the core, the single sine, the yaw
     damping coefficient, HSTO and RA of the lane change) against (a) the twin's whole set (the
     time responses by exact discretisation, scipy's expm, and a time-stepping loop vectorised
     over the variants; peaks from the samples and a parabola) and (b) the loop of
     ``measure_set``.
   Targets: batched measure set <= 1.2x (a) per variant, <= 0.4x (b); 10^4 variants <= 25 s on one core.
2. ``lcv study examples/studies/aucnat_loads.toml`` (10^4 cases) in process and on 2 local
   workers, interleaved; the results equal bit for bit.  Target: >= 1.6x on 2 workers.

    python benchmarks/study.py [--quick]

One BLAS thread (OPENBLAS_NUM_THREADS=1 unless set), as the package's entry points.
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")    # before numpy is imported

import math  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from lcvreport import load_preset  # noqa: E402
from lcvreport.measures.amplification import ra_peak
from lcvreport.measures.offtracking import steady_turn
from lcvreport.measures.stability import critical_speed, least_damping
from lcvreport.measures.low_speed import low_speed_measures
from lcvreport.measures.measure_set import measure_set
from lcvreport.analysis.frequency import rearward_amplification
from lcvreport.analysis.batch import VariantBatch  # noqa: E402
from lcvreport.measures.amplification import ra_peak_batched
from lcvreport.measures.measure_set import batch_measures as measure_table
from lcvreport.measures.offtracking import steady_turn_batched
from lcvreport.measures.stability import critical_speed_batched, least_damping_batched
from lcvreport.model.yaw_plane.equations import system_coefficients  # noqa: E402
from lcvreport.units import kph_to_mps  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
U = kph_to_mps(88.0)
F_RA = 0.5


def variants(v, B, seed=1):
    rng = np.random.default_rng(seed)
    vals = {}
    for u in v.units:
        vals[f"{u.name}.mass_kg"] = u.mass_kg * rng.uniform(0.8, 1.2, B)
        vals[f"{u.name}.yaw_inertia_kg_m2"] = u.yaw_inertia_kg_m2 * rng.uniform(0.8, 1.2, B)
    for a in v.axles:
        for k in ("cornering_stiffness_N_per_rad", "aligning_stiffness_Nm_per_rad", "longitudinal_stiffness_N"):
            if getattr(a, k) > 0:                # (C_S is 0 where the thesis gives none)
                vals[f"{a.name}.{k}"] = getattr(a, k) * rng.uniform(0.8, 1.2, B)
    return vals


def one_vehicle(v, vals, i):
    units = list(v.units)
    for name, arr in vals.items():
        owner, key = name.split(".", 1)
        for k, u in enumerate(units):
            if u.name == owner:
                units[k] = replace(u, **{key: float(arr[i])})
            for j, a in enumerate(u.axles):
                if a.name == owner:
                    axles = list(units[k].axles)
                    axles[j] = replace(axles[j], **{key: float(arr[i])})
                    units[k] = replace(units[k], axles=tuple(axles))
    return replace(v, units=tuple(units))


# ---------------------------------------------------------------------------- (a) the twin, written here
class Twin:
    """The same measures, vectorised over the variants, from coefficient stacks."""

    def __init__(self, vehicles):
        cos = [system_coefficients(x) for x in vehicles]
        self.c = {k: np.stack([getattr(co, k) for co in cos]) for k in ("M0", "M1", "S0", "Sinv", "Su", "Skin",
                                                                         "Bdelta")}
        self.V = cos[0].velocity_map(U)          # geometry: the same for every variant
        self.R = cos[0].yaw_rate_map()
        self.v = vehicles[0]

    def MS(self, u):
        c = self.c
        u = np.asarray(u, dtype=float)[..., None, None]
        return c["M0"] + u * c["M1"], c["S0"] + c["Sinv"] / u + c["Skin"] + u * c["Su"]

    def damping(self):
        M, S = self.MS(U)
        lam = np.linalg.eigvals(np.linalg.solve(M, S))
        osc = lam.imag > 1e-9
        z = np.where(osc, -lam.real / np.abs(lam), np.inf)
        k = z.argmin(1)
        r = np.arange(len(k))
        return z[r, k], lam[r, k].imag / (2 * np.pi)

    def sigma(self, kph, rows=None):
        c = {k: (a if rows is None else a[rows]) for k, a in self.c.items()}
        u = kph_to_mps(np.asarray(kph, dtype=float))[..., None, None]
        M = c["M0"] + u * c["M1"]
        S = c["S0"] + c["Sinv"] / u + c["Skin"] + u * c["Su"]
        return np.linalg.eigvals(np.linalg.solve(M, S)).real.max(-1)

    def critical(self):
        grid = np.arange(8.0, 200.0 + 1e-9, 4.0)
        B = self.c["M0"].shape[0]
        s = np.stack([self.sigma(np.full(B, g)) for g in grid], 1)
        unstable = s >= 0
        out = np.full(B, np.nan)
        has = unstable.any(1)
        first = unstable.argmax(1)
        idx = np.flatnonzero(has & (first > 0))
        lo, hi = grid[first[idx] - 1], grid[first[idx]]
        while idx.size and np.max(hi - lo) > 0.01:
            mid = 0.5 * (lo + hi)
            un = self.sigma(mid, idx) >= 0
            hi, lo = np.where(un, mid, hi), np.where(un, lo, mid)
        out[idx] = np.round(0.5 * (lo + hi), 1)
        out[has & (first == 0)] = grid[0]
        return out

    def ra(self, f, rows=None):
        c = {k: (a if rows is None else a[rows]) for k, a in self.c.items()}
        M = c["M0"] + U * c["M1"]
        S = c["S0"] + c["Sinv"] / U + c["Skin"] + U * c["Su"]
        f = np.atleast_2d(f)                             # (B or 1, J)
        out = np.empty(np.broadcast_shapes(f.shape, (M.shape[0], 1)))
        for j0 in range(0, out.shape[1], 32):
            w = 2 * np.pi * np.broadcast_to(f, out.shape)[:, j0:j0 + 32]
            Z = 1j * w[..., None, None] * M[:, None] - S[:, None]
            x = np.linalg.solve(Z, np.broadcast_to(c["Bdelta"][:, None, :, None], Z.shape[:-1] + (1,)))[..., 0]
            G = np.abs(1j * w[..., None] * (x @ self.V.T) + U * (x @ self.R.T))
            out[:, j0:j0 + 32] = G[..., -1] / G[..., 0]
        return out

    def ra_peak(self):
        f = np.linspace(0.1, 2.0, 381)
        vals = self.ra(f[None, :])
        k = vals.argmax(1)
        B = len(k)
        a, c = f[np.clip(k - 1, 0, 380)], f[np.clip(k + 1, 0, 380)]
        g = (math.sqrt(5) - 1) / 2
        rows = np.arange(B)
        for _ in range(60):                           # golden section to ~1e-12 Hz
            x1, x2 = c - g * (c - a), a + g * (c - a)
            r = self.ra(np.stack([x1, x2], 1), rows)
            left = r[:, 0] > r[:, 1]
            a, c = np.where(left, a, x1), np.where(left, x2, c)
        xm = 0.5 * (a + c)
        return self.ra(xm[:, None])[:, 0], xm

    def hsso(self, R=393.0):
        c = self.c
        n = c["M0"].shape[-1]
        B = c["M0"].shape[0]
        K = np.zeros((B, n + 1, n + 1))
        K[:, :n, :n] = c["S0"] + c["Sinv"] / U + c["Skin"] + U * c["Su"]
        K[:, :n, n] = c["Bdelta"]
        K[:, n, 1] = 1.0
        rhs = np.zeros((B, n + 1))
        rhs[:, n] = U / R
        x = np.linalg.solve(K, rhs[..., None])[..., 0]
        vel = x[:, :n] @ self.V.T
        om = U / R
        v = self.v
        front = max(v.steered_axles, key=lambda a: a.x_m).x_m
        rear = v.units[-1].rearmost_axle.x_m
        return np.hypot(rear + vel[:, -1] / om, U / om) - np.hypot(front + vel[:, 0] / om, U / om)

    def measures(self):
        return (self.damping(), self.critical(), self.ra(np.array([[F_RA]]))[:, 0], self.ra_peak(), self.hsso())

    # -- the time-response measures: exact discretisation (scipy's expm of each variant's augmented
    # matrix), a time-stepping loop over the samples vectorised over the variants, peaks and
    # extrema from the samples refined by the parabola through the three around each
    def _AB(self):
        M, S = self.MS(U)
        A = np.linalg.solve(M, S)
        b = np.linalg.solve(M, self.c["Bdelta"][..., None])[..., 0]
        return A, b

    @staticmethod
    def _step(Phi, steps, z0, C):
        """``z <- Phi z`` ``steps`` times: the outputs ``C`` (B, K, d) at every sample (samples, B, K)
        and the last state."""
        out = [np.einsum("bkd,bd->bk", C, z0)]
        z = z0[..., None]
        for _ in range(steps):
            z = Phi @ z                                    # (a batched product: faster than einsum here)
            out.append(np.einsum("bkd,bd->bk", C, z[..., 0]))
        return np.array(out), z[..., 0]

    def single_sine(self, f_hz=0.4, delta0=0.01, dt=2e-3, tail=8.0):
        from scipy.linalg import expm
        A, b = self._AB()
        B, n = b.shape
        w = 2 * np.pi * f_hz
        d = n + 2                                         # z = [x, sin wt, cos wt]
        Mz = np.zeros((B, d, d))
        Mz[:, :n, :n] = A
        Mz[:, :n, n] = b * delta0
        Mz[:, n, n + 1], Mz[:, n + 1, n] = w, -w
        Phi1 = expm(Mz * dt)
        Mz0 = np.zeros_like(Mz)
        Mz0[:, :n, :n] = A
        Phi2 = expm(Mz0 * dt)
        V, R = self.V[[0, -1]], self.R[[0, -1]]
        C = np.zeros((B, 2, d))                           # a = V x' + u R x, x' = A x + b delta
        C[:, :, :n] = np.einsum("kn,bnj->bkj", V, A) + U * R
        C[:, :, n] = np.einsum("kn,bn->bk", V, b) * delta0
        z0 = np.zeros((B, d))
        z0[:, n + 1] = 1.0
        y1, z1 = self._step(Phi1, int(round(1 / f_hz / dt)), z0, C)
        z = np.zeros((B, d))                               # at 1/f (a sample): x carries on, the input stops
        z[:, :n] = z1[:, :n]
        y2, _ = self._step(Phi2, int(round(tail / dt)), z, C)
        y = np.concatenate([y1, y2[1:]])
        peak = np.maximum(self._refined(y), self._refined(-y))
        return peak[:, 1] / peak[:, 0]

    def _refined(self, y):
        """max of y over the samples, refined by the parabola at the largest sample: (B, K)."""
        k = np.clip(y.argmax(0), 1, y.shape[0] - 2)
        bi, ki = np.indices(k.shape)
        return np.maximum(y[k, bi, ki], self._vertex_at(y, k, bi, ki))

    @staticmethod
    def _vertex_at(y, k, bi, ki):
        a, b, c = y[k - 1, bi, ki], y[k, bi, ki], y[k + 1, bi, ki]
        den = a - 2 * b + c
        return np.where(den != 0, b - (c - a) ** 2 / (8 * np.where(den != 0, den, 1.0)), b)

    def yaw_damping(self, amp=0.01, width=0.5, window=40.0, dt=5e-3):
        """The half-sine pulse amp sin(pi t / width); each joint's sampled extrema (a sign change of
        the sample differences, refined by the parabola) after the pulse; the ratio method on the
        peak-to-peak amplitudes from the largest on (the free decay; docs/measures.md), those of at
        least 5 % of it, the first six; the smallest over the joints."""
        from scipy.linalg import expm
        A, b = self._AB()
        B, n = b.shape
        N = self.v.n_units
        w = np.pi / width
        d = n + 2                                          # z = [x, sin wt, cos wt] during the pulse
        Mz = np.zeros((B, d, d))
        Mz[:, :n, :n] = A
        Mz[:, :n, n] = b * amp
        Mz[:, n, n + 1], Mz[:, n + 1, n] = w, -w
        C = np.zeros((B, N - 1, d))
        C[:, np.arange(N - 1), N + 1 + np.arange(N - 1)] = 1.0      # the articulation angles
        z0 = np.zeros((B, d))
        z0[:, n + 1] = 1.0
        _y, z1 = self._step(expm(Mz * dt), int(round(width / dt)), z0, C)
        Mz[:, :n, n] = 0.0
        Mz[:, n:, n:] = 0.0
        z = z1.copy()
        z[:, n:] = 0.0
        y, _ = self._step(expm(Mz * dt), int(round(window / dt)), z, C)
        dy = np.diff(y, axis=0)
        turn = (dy[:-1] * dy[1:] < 0)                      # sample k+1 is a local extremum
        out = np.full(B, np.nan)
        for bi in range(B):
            for j in range(N - 1):
                k = np.flatnonzero(turn[:, bi, j]) + 1
                if k.size < 2:
                    continue
                a_, b_, c_ = y[k - 1, bi, j], y[k, bi, j], y[k + 1, bi, j]
                den = a_ - 2 * b_ + c_
                vals = b_ - (c_ - a_) ** 2 / (8 * den)
                P = np.abs(np.diff(vals))
                P = P[int(np.argmax(P)):]                      # the free decay starts at the largest
                P = P[P >= 0.05 * P[0]][:6]
                if P.size < 2:
                    continue
                dd = np.log(P[:-1] / P[1:])
                zeta = float(np.mean(dd / np.sqrt(np.pi ** 2 + dd ** 2)))
                out[bi] = zeta if np.isnan(out[bi]) else min(out[bi], zeta)
        return out

    def lane_change(self, accel=0.15 * 9.80665, f_hz=0.4, tail=8.0, dt=2e-3):
        """The steered axle's lateral acceleration accel sin(2 pi f t) for one period, through each
        variant's inverse system; HSTO (the rear axle beyond the final offset) and max|a_N| / max|a_s|."""
        from scipy.linalg import expm
        from lcvreport.model.yaw_plane.outputs import point_lateral_map
        A, b = self._AB()
        B, n = b.shape
        v = self.v
        N = v.n_units
        xs = max(a.x_m for a in v.steered_axles)
        Js = np.zeros(n)
        Js[0], Js[1] = 1.0, xs
        Cs = np.einsum("k,bkj->bj", Js, A)
        Cs[:, 1] += U
        Ds = b @ Js
        w = 2 * np.pi * f_hz
        d = n + 4                                          # z = [x, psi1, Y1, sin wt, cos wt]
        Mz = np.zeros((B, d, d))
        Mz[:, :n, :n] = A - b[:, :, None] * Cs[:, None, :] / Ds[:, None, None]
        Mz[:, :n, n + 2] = b * accel / Ds[:, None]
        Mz[:, n, 1] = 1.0                                  # psi1' = r1
        Mz[:, n + 1, 0], Mz[:, n + 1, n] = 1.0, U          # Y1' = v1 + u psi1
        Mz[:, n + 2, n + 3], Mz[:, n + 3, n + 2] = w, -w
        rear = v.units[-1].rearmost_axle.x_m
        c = point_lateral_map(v, N - 1, rear)              # Y = c0 psi1 + c1 Y1 + sum c_k Theta_k
        C = np.zeros((B, 3, d))
        C[:, 0, n], C[:, 0, n + 1] = c[0], c[1]
        for k in range(N - 1):                             # Theta_k = theta_2 + ... + theta_(k+2)
            C[:, 0, N + 1:N + 2 + k] += c[2 + k]
        delta = np.zeros((B, d))                           # the steer: (a_s - Cs x) / Ds
        delta[:, :n] = -Cs / Ds[:, None]
        delta[:, n + 2] = accel / Ds
        xdot = Mz[:, :n] + 0.0                             # x' rows over z (the inverse system)
        aN = np.einsum("n,bnd->bd", self.V[-1], xdot) + U * np.pad(self.R[-1], (0, d - n))[None]
        C[:, 1] = aN
        C[:, 2, n + 2] = accel                             # a_s itself
        z0 = np.zeros((B, d))
        z0[:, n + 3] = 1.0
        y1, z1 = self._step(expm(Mz * dt), int(round(1 / f_hz / dt)), z0, C)
        Mz[:, :n, n + 2] = 0.0
        Mz[:, n + 2:, n + 2:] = 0.0
        C[:, 1] = np.einsum("n,bnd->bd", self.V[-1], Mz[:, :n]) + U * np.pad(self.R[-1], (0, d - n))[None]
        C[:, 2] = 0.0
        z = z1.copy()
        z[:, n + 2:] = 0.0
        y2, _ = self._step(expm(Mz * dt), int(round(tail / dt)), z, C)
        y = np.concatenate([y1, y2[1:]])
        offset = accel / (2 * np.pi * f_hz ** 2)
        hsto = np.maximum(0.0, self._refined(y[:, :, :1] - offset)[:, 0])
        peak = np.maximum(self._refined(y[:, :, 1:]), self._refined(-y[:, :, 1:]))
        return hsto, peak[:, 0] / peak[:, 1]

    def full(self):
        """Every measure of the batch's whole set (the trim aside)."""
        return self.measures() + (self.single_sine(), self.yaw_damping(), self.lane_change())


def batch_measures(b):
    return (least_damping_batched(b, U), critical_speed_batched(b), b.rearward_amplification(U, F_RA),
            ra_peak_batched(b, U), steady_turn_batched(b, U))


def full_batch(b):
    return measure_table(b, U)


def full_loop(vehicles):
    """Today's loop: measure_set per variant (its low-speed turn, a second model that a batch
    does not compute, taken out: cached per vehicle by a first call)."""
    for x in vehicles:
        measure_set(x, U)


def loop_measures(vehicles):
    for x in vehicles:
        least_damping(x, U)
        critical_speed(x)
        rearward_amplification(x, U, F_RA)
        ra_peak(x, U)
        steady_turn(x, U)


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def part1(B, n_loop, rounds):
    v = load_preset("aucnat")
    vals = variants(v, B)
    vehicles = [one_vehicle(v, vals, i) for i in range(B)]
    twin = Twin(vehicles)
    batch = VariantBatch(v, vals)
    tb, tt, tl = [], [], []
    for _ in range(rounds):                      # interleaved
        tb.append(timed(lambda: batch_measures(batch))[0] / B)
        tt.append(timed(twin.measures)[0] / B)
        tl.append(timed(lambda: loop_measures(vehicles[:n_loop]))[0] / n_loop)
    b, t, lp = min(tb), min(tt), min(tl)
    (zb, _), cb = least_damping_batched(batch, U), critical_speed_batched(batch)
    (zt, _), ct = twin.damping(), twin.critical()
    print(f"1. {B} variants of aucnat at 88 km/h, every nonzero parameter, best of {rounds} interleaved rounds [ms per variant]")
    print(f"   batched (package)            {b * 1e3:7.3f}")
    print(f"   vectorised twin (this file)  {t * 1e3:7.3f}   batch/twin {b / t:5.2f}  (target <= 1.2)")
    print(f"   loop of one-variant calls    {lp * 1e3:7.3f}   batch/loop {b / lp:5.2f}  (the critical speed's 49 "
          "eigenvalue calls, ~0.8 ms, in both)")
    print(f"   agreement: damping ratio {np.max(np.abs(zb - zt)):.1e}; critical speeds equal where the twin's "
          f"plain scan finds them: {np.array_equal(np.isnan(cb), np.isnan(ct))}")
    few = vehicles[:n_loop]
    for x in few:                                 # the low-speed turn once per vehicle (cached)
        low_speed_measures(x)
    fb, ft, fl = [], [], []
    for _ in range(rounds):
        fb.append(timed(lambda: full_batch(batch))[0] / B)
        ft.append(timed(twin.full)[0] / B)
        fl.append(timed(lambda: full_loop(few))[0] / n_loop)
    table = full_batch(batch)
    ss, ydc, (hsto, ra_lc) = twin.single_sine(), twin.yaw_damping(), twin.lane_change()
    agree = {k: np.abs(x - table[k]) / np.abs(table[k])
             for k, x in (("ra_single_sine", ss), ("yaw_damping_coefficient", ydc), ("hsto_m", hsto),
                          ("ra_lane_change", ra_lc))}
    print("   the whole measure set (+ single sine, YDC, HSTO, lane-change RA; the trim aside):")
    print(f"   batch_measures (registry)    {min(fb) * 1e3:7.3f}")
    b_, t_, l_ = min(fb), min(ft), min(fl)
    print(f"   vectorised twin (this file)  {t_ * 1e3:7.3f}   batch/twin {b_ / t_:5.2f}  (target <= 1.2)")
    print(f"   loop of measure_set          {l_ * 1e3:7.3f}   batch/loop {b_ / l_:5.2f}  (target <= 0.4)")
    print("   agreement with the twin's sampled peaks (parabola through three samples), relative, median / "
          "largest: " + ", ".join(f"{k} {np.nanmedian(x):.0e} / {np.nanmax(x):.0e}" for k, x in agree.items()))
    return min(fb)


def part2(rounds):
    study = ROOT / "examples" / "studies" / "aucnat_loads.toml"
    lcv = [sys.executable, "-m", "lcvreport.cli", "study", str(study)]
    times = {"in-process": [], "2 workers": []}
    tmp = Path(tempfile.mkdtemp())
    outs = {}
    try:
        for r in range(rounds):                 # interleaved
            for name, extra in (("in-process", []), ("2 workers", ["--workers", "2"])):
                out = tmp / f"{name.replace(' ', '_')}_{r}"
                t0 = time.perf_counter()
                subprocess.run(lcv + ["--out", str(out), "--json"] + extra, check=True, capture_output=True)
                times[name].append(time.perf_counter() - t0)
                outs[name] = out
        from lcvreport import read_study
        same = read_study(outs["in-process"]).equals(read_study(outs["2 workers"]))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    a, b = min(times["in-process"]), min(times["2 workers"])
    print(f"2. lcv study {study.name} (10^4 cases), best of {rounds} interleaved runs, whole command [s]")
    print(f"   in process {a:6.1f}   2 local workers {b:6.1f}   speed-up {a / b:4.2f}  (target >= 1.6)   "
          f"results equal bit for bit: {same}")


def main() -> None:
    from machine import machine_line       # (benchmarks/machine.py: a time is read with its machine)
    print(machine_line())
    quick = "--quick" in sys.argv
    per = part1(500 if quick else 2000, 20 if quick else 60, 2 if quick else 3)
    v = load_preset("aucnat")
    t, _ = timed(lambda: full_batch(VariantBatch(v, variants(v, 10_000, seed=2))))
    print(f"   10^4 variants, the whole measure set in one batch: {t:.1f} s (target <= 25 s; "
          f"{per * 1e4:.1f} s from the per-variant time)")
    part2(1 if quick else 2)


if __name__ == "__main__":
    main()
