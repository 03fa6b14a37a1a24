"""BLAS threads at the entry points: one by default (docs/studies.md).

On the 12x12 matrices of this model a second BLAS thread buys nothing when the machine is
idle and costs several times when the other core is busy (measured: ``measure_set`` 3.3x,
the single sine 6.7x slower with two OpenBLAS threads under load).  Parallelism comes from
processes -- pytest workers, report kernels, Dask workers -- so the entry points (the
``lcv`` command, ``python -m lcvreport.cli``, ``python -m lcvreport.report.build`` and the
kernels they start, ``./build.sh test``, the Python FMU's own interpreter) run BLAS with
one thread, set through the environment before numpy is imported.  Importing the package
as a library changes nothing.

To change it: ``LCV_BLAS_THREADS=N`` (an integer >= 1), or any of the standard variables
(``OPENBLAS_NUM_THREADS``, ``OMP_NUM_THREADS``, ``MKL_NUM_THREADS``), which win where set.

Examples
--------
>>> env = {}
>>> single_thread_environment(env)
'1'
>>> env["OPENBLAS_NUM_THREADS"], env["OMP_NUM_THREADS"]
('1', '1')
>>> single_thread_environment({"LCV_BLAS_THREADS": "2", "OMP_NUM_THREADS": "4"})
'2'
"""
from __future__ import annotations

import os
import sys

#: the variables the BLAS libraries numpy and scipy ship read when they load
BLAS_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")


def single_thread_environment(env=None) -> str:
    """Set every BLAS thread variable not already set in ``env`` (default ``os.environ``) to
    ``LCV_BLAS_THREADS`` (default 1); return that number (as text).  A value of
    ``LCV_BLAS_THREADS`` that is not an integer >= 1 counts as 1."""
    env = os.environ if env is None else env
    n = str(env.get("LCV_BLAS_THREADS", "1")).strip()
    if not (n.isdigit() and int(n) >= 1):
        n = "1"
    for var in BLAS_VARIABLES:
        env.setdefault(var, n)
    return n


def configure_entry_point() -> bool:
    """At an entry point, before numpy is imported: one BLAS thread unless told otherwise.
    Returns False (and changes nothing) if numpy is already imported -- its BLAS has read
    the environment already."""
    if "numpy" in sys.modules:
        return False
    single_thread_environment()
    return True
