"""Benchmark: variants in a batch and ``lcv study`` (issue 21, SPEC section 14).

1. The batched measures (least damping ratio and frequency, critical speed, RA at 0.5 Hz, the
   RA peak over 0.1-2 Hz, HSSO) of B variants of aucnat at 88 km/h, +-20 % on every unit's
   mass and yaw inertia and every axle's C_F, C_M, C_S (every nonzero parameter), against
   (a) a straightforward vectorised numpy implementation of the same measures written here,
       from the variants' own coefficient stacks (built per variant with the package's model
       builder, untimed; the measures' algorithms are this file's: eigenvalues, solves, a
       coarse speed scan and bisection, a frequency scan and golden section),
   (b) the loop of today's one-variant calls (least_damping, critical_speed,
       rearward_amplification, field_measures.ra_peak, field_measures.steady_turn).
   Targets: batch <= 1.2x (a) per variant, <= 0.4x (b); 10^4 variants <= 25 s on one core.
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
from lcvreport.analysis import field_measures, measures  # noqa: E402
from lcvreport.analysis.batch import VariantBatch  # noqa: E402
from lcvreport.model.builder import system_coefficients  # noqa: E402
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


def batch_measures(b):
    return (b.least_damping(U), b.critical_speed(), b.rearward_amplification(U, F_RA), b.ra_peak(U),
            b.steady_turn(U))


def full_batch(b):
    return b.measures(U)


def full_loop(vehicles):
    """Today's loop: measure_set per variant (its low-speed turn, a second model that a batch
    does not compute, taken out: cached per vehicle by a first call)."""
    for x in vehicles:
        measures.measure_set(x, U)


def loop_measures(vehicles):
    for x in vehicles:
        measures.least_damping(x, U)
        measures.critical_speed(x)
        measures.rearward_amplification(x, U, F_RA)
        field_measures.ra_peak(x, U)
        field_measures.steady_turn(x, U)


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
    (zb, _), cb = batch.least_damping(U), batch.critical_speed()
    (zt, _), ct = twin.damping(), twin.critical()
    print(f"1. {B} variants of aucnat at 88 km/h, every nonzero parameter, best of {rounds} interleaved rounds [ms per variant]")
    print(f"   batched (package)            {b * 1e3:7.3f}")
    print(f"   vectorised twin (this file)  {t * 1e3:7.3f}   batch/twin {b / t:5.2f}  (target <= 1.2)")
    print(f"   loop of one-variant calls    {lp * 1e3:7.3f}   batch/loop {b / lp:5.2f}  (target <= 0.4)")
    print(f"   agreement: damping ratio {np.max(np.abs(zb - zt)):.1e}; critical speeds equal where the twin's "
          f"plain scan finds them: {np.array_equal(np.isnan(cb), np.isnan(ct))}")
    few = vehicles[:n_loop]
    for x in few:                                 # the low-speed turn once per vehicle (cached)
        measures.low_speed_measures(x)
    fb, fl = [], []
    for _ in range(rounds):
        fb.append(timed(lambda: full_batch(batch))[0] / B)
        fl.append(timed(lambda: full_loop(few))[0] / n_loop)
    print("   the whole measure set (+ single sine, YDC, HSTO, lane-change RA, trim-free):")
    print(f"   VariantBatch.measures        {min(fb) * 1e3:7.3f}   loop of measure_set {min(fl) * 1e3:7.3f}   "
          f"ratio {min(fb) / min(fl):5.2f}  (target <= 0.4)")
    return b


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
    quick = "--quick" in sys.argv
    per = part1(500 if quick else 2000, 20 if quick else 60, 2 if quick else 3)
    v = load_preset("aucnat")
    t, _ = timed(lambda: batch_measures(VariantBatch(v, variants(v, 10_000, seed=2))))
    print(f"   10^4 variants in one batch: {t:.1f} s (target <= 25 s; {per * 1e4:.1f} s from the per-variant time)")
    part2(1 if quick else 2)


if __name__ == "__main__":
    main()
