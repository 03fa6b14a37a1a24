"""Benchmark: eigenvalues + steady state of 10,000 (vehicle, speed) configurations.

Compares, in the same run, the package's batched calls (build M and S from the cached
affine coefficients, A = M^-1 S with the equilibrated solve, eigenvalues in mode order,
steady state -S^-1 F) with numpy's bare batched ``eigvals`` on the same 10,000 matrices
A (built beforehand, not timed).  Best of several alternated repetitions.
Target (issue "Core"): sweep / bare eigvals <= 2.

    python benchmarks/sweep.py
"""
from __future__ import annotations

import time

import numpy as np

from lcvreport import eigenvalues, load_preset, load_vector, one_percent_rule, steady_state
from lcvreport.analysis.modes import state_matrix
from lcvreport.units import mph_to_mps

PRESETS = ("aucnat", "legal_max", "loaded_loaded_empty", "empty_empty_loaded", "empty")
N_PER_VEHICLE = 2000          # 5 vehicles x 2000 speeds = 10,000 configurations
REPEATS = 7


def main() -> None:
    vehicles = [load_preset(p) for p in PRESETS]
    speeds = mph_to_mps(np.linspace(5.0, 80.0, N_PER_VEHICLE))        # [m/s]
    forces = [load_vector(v, one_percent_rule(v, ["trailer2", "trailer3"])) for v in vehicles]
    A_all = np.concatenate([state_matrix(v, speeds) for v in vehicles])   # (10000, 12, 12), not timed

    def sweep():
        return [(eigenvalues(v, speeds), steady_state(v, speeds, f)) for v, f in zip(vehicles, forces)]

    def bare():
        return np.linalg.eigvals(A_all)

    sweep(), bare()  # warm up (caches, BLAS threads)
    t_sweep, t_bare = [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter(); bare(); t_bare.append(time.perf_counter() - t0)
        t0 = time.perf_counter(); sweep(); t_sweep.append(time.perf_counter() - t0)
    b, s = min(t_bare), min(t_sweep)
    n = A_all.shape[0]
    print(f"configurations                  : {n} (5 presets x {N_PER_VEHICLE} speeds, 12 states)")
    print(f"numpy batched eigvals (bare)    : {b * 1e3:8.1f} ms  ({b / n * 1e6:.2f} us/config)")
    print(f"lcvreport sweep (eig + steady)  : {s * 1e3:8.1f} ms  ({s / n * 1e6:.2f} us/config)")
    print(f"ratio sweep / bare              : {s / b:8.2f}   (target <= 2)")


if __name__ == "__main__":
    main()
