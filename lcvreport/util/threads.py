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

A library caller keeps its own settings, but the hot calls (:func:`one_blas_thread`:
``measure_set``, ``batch_measures``, the exact response, the critical speed, ``roll_summary``)
run with ``LCV_BLAS_THREADS`` (default 1) BLAS threads for their duration and restore the
caller's count after, through threadpoolctl: as fast from a notebook as from ``lcv``.

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

import functools
import os
import sys
import threading
from contextlib import contextmanager

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


def _threads_wanted() -> int:
    n = str(os.environ.get("LCV_BLAS_THREADS", "1")).strip()
    return int(n) if n.isdigit() and int(n) >= 1 else 1


_inside = threading.local()
_controllers: dict = {}


def _controller():
    """A threadpoolctl controller of the BLAS libraries, scipy's own OpenBLAS loaded first (it
    loads with scipy.linalg: a block entered before it loaded left it unlimited, and a first
    computation inside a block -- solve_ivp imports scipy.linalg -- differed from the second in
    its last bits)."""
    c = _controllers.get(True)
    if c is None:
        import scipy.linalg  # noqa: F401  (its BLAS among those limited)
        from threadpoolctl import ThreadpoolController
        c = _controllers[True] = ThreadpoolController()
    return c


#: the process-wide limit: how many threads are inside a block, and what restores the caller's
#: counts when the last leaves (BLAS's thread count is one setting of the process, not of a thread:
#: a block that restored it while another thread was still computing gave that thread's products
#: another summation order, and its last bits differed from a serial run's)
_active = {"count": 0, "limit": None}
_active_lock = threading.Lock()


@contextmanager
def blas_threads_limited():
    """Within the block, every loaded BLAS library runs ``LCV_BLAS_THREADS`` (default 1) threads;
    the caller's counts are restored after the last block of any thread ends (so a thread's
    numbers never depend on another's timing).  Nested blocks limit once."""
    if getattr(_inside, "depth", 0):
        yield
        return
    _inside.depth = 1
    with _active_lock:
        if _active["count"] == 0:
            limit = _controller().limit(limits=_threads_wanted(), user_api="blas")
            limit.__enter__()
            _active["limit"] = limit
        _active["count"] += 1
    try:
        yield
    finally:
        with _active_lock:
            _active["count"] -= 1
            if _active["count"] == 0:
                _active["limit"].__exit__(None, None, None)
                _active["limit"] = None
        _inside.depth = 0


def one_blas_thread(fn):
    """Decorator: ``fn`` runs inside :func:`blas_threads_limited`."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with blas_threads_limited():
            return fn(*args, **kwargs)
    return wrapper

