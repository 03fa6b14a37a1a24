"""One BLAS thread at the entry points (issue 21): the ``lcv`` console script and
``python -m lcvreport.cli`` start numpy's OpenBLAS with one thread unless LCV_BLAS_THREADS
(or a standard variable) says otherwise; importing the package as a library changes nothing."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

PROBE = r"""
import ctypes, sys
{entry}
import numpy
lib = sorted(set(l.split()[-1] for l in open('/proc/self/maps') if 'openblas' in l))
f = next((getattr(ctypes.CDLL(p), n) for p in lib for n in ('scipy_openblas_get_num_threads64_',
          'openblas_get_num_threads64_', 'openblas_get_num_threads') if hasattr(ctypes.CDLL(p), n)), None)
print(f() if f else -1)
"""
ENTRY = """
sys.argv = ["lcv", "presets"]
from lcvreport._entry import main
try:
    main()
except SystemExit:
    pass
"""
LIBRARY = "import lcvreport.cli"


def _threads(code: str, **env) -> int:
    clean = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                                               "MKL_NUM_THREADS", "LCV_BLAS_THREADS")}
    p = subprocess.run([sys.executable, "-c", PROBE.format(entry=code)], capture_output=True, text=True,
                       env=dict(clean, **env), timeout=120)
    assert p.returncode == 0, p.stderr
    n = int(p.stdout.strip().splitlines()[-1])
    if n < 0:
        pytest.skip("numpy's BLAS is not OpenBLAS here")
    return n


def test_the_console_script_runs_one_blas_thread():
    assert _threads(ENTRY) == 1
    assert _threads(ENTRY, LCV_BLAS_THREADS="2") == 2
    assert _threads(ENTRY, OPENBLAS_NUM_THREADS="2") == 2              # a standard variable wins


def test_importing_the_package_changes_nothing():
    """The library leaves the host's threads alone (OpenBLAS' own default: the cores, here 2)."""
    assert _threads(LIBRARY, OPENBLAS_NUM_THREADS="1") == 1
    assert _threads(LIBRARY) != 1 or (os.cpu_count() or 1) == 1
