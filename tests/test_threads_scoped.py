"""A library caller's BLAS thread settings: the hot calls run with one thread and restore the
caller's count after (threadpoolctl), whatever the caller set."""
from __future__ import annotations

import json
import os
import subprocess
import sys

SCRIPT = r"""
import json
from threadpoolctl import threadpool_info
import lcvreport.measures.stability as stability
from lcvreport import load_preset
from lcvreport.measures.measure_set import measure_set

def blas():
    return sorted({i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"})

seen = {}
original = stability.least_damping
def spy(*args, **kwargs):
    seen.setdefault("during", blas())
    return original(*args, **kwargs)
stability.least_damping = spy
before = blas()
m = measure_set(load_preset("tractor_semitrailer"), 24.0)
print(json.dumps({"before": before, "during": seen["during"], "after": blas(), "zeta": m.least_damping_ratio}))
"""


def _run(extra_env):
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                                             "MKL_NUM_THREADS", "LCV_BLAS_THREADS")}
    env.update(extra_env)
    p = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def test_a_library_call_runs_one_blas_thread_and_restores_the_callers():
    got = _run({"OPENBLAS_NUM_THREADS": "2"})
    assert got["before"] == [2] and got["during"] == [1] and got["after"] == [2]


def test_lcv_blas_threads_sets_the_count_inside_and_the_numbers_do_not_change():
    one = _run({"OPENBLAS_NUM_THREADS": "2"})
    two = _run({"OPENBLAS_NUM_THREADS": "2", "LCV_BLAS_THREADS": "2"})
    assert two["during"] == [2] and two["after"] == [2]
    assert one["zeta"] == two["zeta"]
