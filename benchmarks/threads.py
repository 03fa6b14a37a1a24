"""Benchmark: ``measure_set`` called from Python with numpy's default BLAS threads against the
same call with one BLAS thread set before numpy loads (what ``lcv`` does) -- the hot calls
limit the threads themselves (``lcvreport.util.threads.one_blas_thread``), so the two should
match.  aucnat at 88 km/h with the 1 % rule on trailer3, best of 30 in each of four processes per kind,
interleaved.
Target (issue 32): the library call as fast as the CLI's.

    python benchmarks/threads.py
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

SCRIPT = r"""
import json, time
from lcvreport import load_preset
from lcvreport.measures.measure_set import measure_set
from threadpoolctl import threadpool_info
v = load_preset("aucnat")
measure_set(v, 24.4444, load_units=["trailer3"])
best = 1e9
for k in range(30):
    t = time.perf_counter()
    measure_set(v, 24.4444, load_units=["trailer3"])       # as a user repeats it (the low-speed turn is cached)
    best = min(best, time.perf_counter() - t)
print(json.dumps({"ms": best * 1e3, "threads": [i["num_threads"] for i in threadpool_info()]}))
"""


def run(env_extra: dict) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                                             "MKL_NUM_THREADS")}
    env.update(env_extra)
    out = subprocess.run([sys.executable, "-c", SCRIPT], check=True, capture_output=True, text=True, env=env)
    return json.loads(out.stdout)


def main() -> None:
    # interleaved, four processes each, the best of each kind (the machine's speed drifts between runs)
    runs = [(run({}), run({"OPENBLAS_NUM_THREADS": "1"})) for _ in range(4)]
    library = min((r[0] for r in runs), key=lambda r: r["ms"])
    cli = min((r[1] for r in runs), key=lambda r: r["ms"])
    print(f"measure_set, library defaults (BLAS threads {library['threads']} outside the call): {library['ms']:.2f} ms; "
          f"one thread set before numpy (the CLI): {cli['ms']:.2f} ms; ratio {library['ms'] / cli['ms']:.2f} "
          "(target ~1)")


if __name__ == "__main__":
    main()
