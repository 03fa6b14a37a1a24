"""Benchmark: the whole measure set (SPEC sections 8 and 12) per (vehicle, speed).

For every preset and example vehicle at 88 km/h: ``measure_set`` (least damping,
critical speed, RA in the frequency domain, the continuous single sine, the gains, the
RA peak, the yaw damping of a pulse, HSTO and RA in the lane change, HSSO, the trim under
the 1 % rule on the rearmost unit), timed beside the bare eigenvalue call
(``numpy.linalg.eigvals``) of the same state matrix, and the time of each part, to say
which one dominates.  Best of ``REPEATS``.  Targets (issue 17): <= 30 ms per (vehicle,
speed) for the 6-unit trains; the lane change, the pulse (YDC) and the steady turn each
<= 5 ms.

    python benchmarks/measures.py

Timed with one BLAS thread (``OPENBLAS_NUM_THREADS=1`` unless set): on 12x12 matrices a
second thread buys nothing and, with two threads on two cores, the pulse's long
exponential scan ran at 8.9 ms instead of 2.0 (issue 21 makes one thread the package's
default at its entry points).
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")    # before numpy is imported

import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from lcvreport import load_preset, load_vehicle  # noqa: E402
from lcvreport.analysis.frequency import RA_FREQUENCY_HZ, steer_to_acceleration
from lcvreport.analysis.modes import state_matrix  # noqa: E402
from lcvreport.analysis.steady import trim
from lcvreport.measures.amplification import ra_peak, single_sine
from lcvreport.measures.measure_set import measure_set
from lcvreport.measures.offtracking import lane_change_measures, steady_turn
from lcvreport.measures.stability import critical_speed, least_damping
from lcvreport.measures.yaw_damping import yaw_damping_coefficient
from lcvreport.model.linear import linear_model
from lcvreport.model.presets import PRESETS  # noqa: E402
from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule  # noqa: E402
from lcvreport.units import kph_to_mps  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SPEED_MPS = kph_to_mps(88.0)
REPEATS = 7


def best(fn, repeats: int = REPEATS) -> float:
    """Best wall time of ``fn()`` [s]."""
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def main() -> None:
    vehicles = [load_preset(p) for p in PRESETS] + [load_vehicle(p) for p in
                                                    sorted((ROOT / "examples" / "vehicles").glob("*.toml"))]
    print(f"measure set at 88 km/h, best of {REPEATS} [ms]")
    header = (f"{'vehicle':22s} {'units':>5s} {'states':>6s} {'bare eig':>9s} {'measures':>9s} {'ratio':>6s}  "
              f"{'damping':>8s} {'critical':>8s} {'RA(f)':>7s} {'1-sine':>7s} {'trim':>7s} {'RApeak':>7s} "
              f"{'pulse':>7s} {'lane':>7s} {'turn':>7s}  dominant")
    print(header)
    worst_six = 0.0
    worst_part = {"pulse": 0.0, "lane": 0.0, "turn": 0.0}
    for v in vehicles:
        load = [v.unit_names[-1]]
        A = state_matrix(v, SPEED_MPS)
        F = load_vector(v, one_percent_rule(v, load))
        t_bare = best(lambda: np.linalg.eigvals(A))
        t_all = best(lambda: measure_set(v, SPEED_MPS, load_units=load))
        parts = {
            "damping": best(lambda: least_damping(v, SPEED_MPS)),
            "critical": best(lambda: critical_speed(v)),
            "RA(f)": best(lambda: steer_to_acceleration(v, SPEED_MPS, RA_FREQUENCY_HZ)),
            "1-sine": best(lambda: single_sine(v, SPEED_MPS)),
            "trim": best(lambda: trim(v, SPEED_MPS, F)),
            "RApeak": best(lambda: ra_peak(v, SPEED_MPS)),
            "pulse": best(lambda: yaw_damping_coefficient(v, SPEED_MPS)),
            "lane": best(lambda: lane_change_measures(v, SPEED_MPS)),
            "turn": best(lambda: steady_turn(v, SPEED_MPS)),
        }
        for k in ("pulse", "lane", "turn"):
            worst_part[k] = max(worst_part[k], parts[k])
        dominant = max(parts, key=parts.get)
        if v.n_units == 6:
            worst_six = max(worst_six, t_all)
        print(f"{v.name:22s} {v.n_units:5d} {linear_model(v).n_states:6d} {t_bare * 1e3:9.3f} {t_all * 1e3:9.2f} "
              f"{t_all / t_bare:6.0f}  " + " ".join(f"{parts[k] * 1e3:{8 if i < 2 else 7}.2f}"
                                                   for i, k in enumerate(parts)) + f"  {dominant}")
    print(f"slowest 6-unit vehicle: {worst_six * 1e3:.2f} ms per (vehicle, speed)  (target <= 30 ms)")
    print("slowest over all vehicles: " + ", ".join(f"{k} {t * 1e3:.2f} ms" for k, t in worst_part.items())
          + "  (target <= 5 ms each)")


PRIMITIVES = (("numpy.linalg", ("eig", "eigvals", "solve", "inv", "lstsq")),
              ("scipy.linalg", ("expm", "solve", "eig", "eigvals", "lu_factor", "lu_solve", "schur", "hessenberg")))


def lapack_replay(fn) -> tuple[float, float, int]:
    """(time of ``fn()``, the sum of the times of the linear-algebra calls it makes, replayed
    alone with the same arguments, the number of those calls).  The calls are recorded by
    wrapping numpy.linalg's and scipy.linalg's functions for one run of ``fn``."""
    import copy
    import importlib
    recorded = []
    saved = []
    for mod_name, names in PRIMITIVES:
        mod = importlib.import_module(mod_name)
        for name in names:
            orig = getattr(mod, name, None)
            if orig is None:
                continue

            def wrapper(*args, __orig=orig, **kw):
                recorded.append((__orig, copy.deepcopy(args), copy.deepcopy(kw)))
                return __orig(*args, **kw)
            saved.append((mod, name, orig))
            setattr(mod, name, wrapper)
    try:
        fn()
    finally:
        for mod, name, orig in saved:
            setattr(mod, name, orig)

    def replay():
        for f, a, k in recorded:
            f(*a, **k)
    return best(fn), best(replay), len(recorded)


def busy_core():
    """A process that keeps the other core busy (pure Python, no BLAS)."""
    import subprocess
    import sys
    return subprocess.Popen([sys.executable, "-c", "while True: pass"])


def part2() -> None:
    v = load_preset("aucnat")
    load = [v.unit_names[-1]]
    fn = lambda: measure_set(v, SPEED_MPS, load_units=load)  # noqa: E731
    t_all, t_lapack, calls = lapack_replay(fn)
    print(f"measure_set of aucnat (6 units) at 88 km/h: {t_all * 1e3:.2f} ms; its {calls} linear-algebra calls "
          f"replayed alone: {t_lapack * 1e3:.2f} ms; ratio {t_all / t_lapack:.2f}  (target <= 3)")
    idle, busy = [], []
    for _ in range(3):                               # interleaved
        idle.append(best(fn, 5))
        p = busy_core()
        try:
            time.sleep(0.3)
            busy.append(best(fn, 5))
        finally:
            p.kill()
            p.wait()
    print(f"  with the other core busy: {min(busy) * 1e3:.2f} ms, idle {min(idle) * 1e3:.2f} ms, ratio "
          f"{min(busy) / min(idle):.2f}  (target <= 1.3; one BLAS thread: "
          f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS')})")


def part3() -> None:
    """The critical speed (issue 32): the lazy scan against the whole-grid scan it replaces
    (tests/legacy_critical_speed.py, verbatim: the baseline the code under test cannot change),
    interleaved, one vehicle (every preset and example at six tire scales) and batched (3 x 256
    random variants of three presets at three tire scales); the answers are compared too."""
    import sys
    sys.path.insert(0, str(ROOT / "tests"))
    import legacy_critical_speed as legacy
    from lcvreport.analysis.batch import VariantBatch
    from lcvreport.measures.stability import critical_speed_batched
    legacy.VariantBatch = VariantBatch
    vehicles = [load_preset(p) for p in PRESETS] + [load_vehicle(p) for p in
                                                    sorted((ROOT / "examples" / "vehicles").glob("*.toml"))]
    cases = [(v, s) for v in vehicles for s in (1.0, 0.5, 0.3, 0.2, 0.15, 0.1)]
    old = new = 0.0
    same = 0
    for rnd in range(3):
        t0 = time.perf_counter()
        a = [legacy.legacy_critical_speed(v, s) for v, s in cases]
        t1 = time.perf_counter()
        b = [critical_speed(v, s) for v, s in cases]
        t2 = time.perf_counter()
        old, new = (t1 - t0, t2 - t1) if rnd == 0 else (min(old, t1 - t0), min(new, t2 - t1))
        same = sum(x == y for x, y in zip(a, b))
    print(f"critical speed, one vehicle ({len(cases)} cases): whole-grid scan {old / len(cases) * 1e3:.2f} ms, "
          f"lazy scan {new / len(cases) * 1e3:.2f} ms per case: {old / new:.2f}x (target >= 1.5); "
          f"same answer in {same} of {len(cases)}")
    rng = np.random.default_rng(3)
    t_old = t_new = 0.0
    n = differ = 0
    for name in ("empty", "legal_max", "aucnat"):
        v = load_preset(name)
        keys = [f"{u.name}.mass_kg" for u in v.units] + [f"{x.name}.cornering_stiffness_N_per_rad" for x in v.axles]
        nominal = {f"{u.name}.mass_kg": u.mass_kg for u in v.units}
        nominal.update({f"{x.name}.cornering_stiffness_N_per_rad": x.cornering_stiffness_N_per_rad for x in v.axles})
        batch = VariantBatch(v, {k: nominal[k] * rng.uniform(0.6, 1.4, 256) for k in keys})
        for s in (1.0, 0.3, 0.15):
            t0 = time.perf_counter()
            a = legacy.legacy_critical_speed_batched(batch, s)
            t1 = time.perf_counter()
            b = critical_speed_batched(batch, s)
            t2 = time.perf_counter()
            t_old, t_new = t_old + t1 - t0, t_new + t2 - t1
            n += a.size
            differ += int((np.nan_to_num(a, nan=-1.0) != np.nan_to_num(b, nan=-1.0)).sum())
    print(f"critical speed, batched ({n} variants): whole-grid scan {t_old:.2f} s, lazy scan {t_new:.2f} s: "
          f"{t_old / t_new:.2f}x (target >= 1.8); answers differing: {differ}")


if __name__ == "__main__":
    main()
    part2()
    part3()
