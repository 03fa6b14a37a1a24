"""The nonlinear model's equations compiled (``equations.c`` beside this module): the same
arithmetic as :meth:`NonlinearModel._solve <lcvreport.model.nonlinear.model.NonlinearModel>` one
state at a time, ~100x faster than numpy's per call, so that an integration's cost is its steps,
not the interpreter (docs/nonlinear.md#integration).

The library is compiled with the machine's C compiler (``cc``, else ``gcc``) the first time it is
needed and kept in the user's cache (``$LCV_CACHE_DIR``, else ``$XDG_CACHE_HOME/lcvreport``, else
``~/.cache/lcvreport``), named by the hash of its source and flags: a changed source is a new
library, never a stale one.  ``./build.sh`` compiles it at set-up.  Where no compiler or no
writable cache is found, or ``LCV_NATIVE=0``, the numpy equations are used (:func:`status` says
which and why): the same equations, numbers that differ in rounding only (tests/test_native.py
holds the two to 1e-12).

Examples
--------
>>> ok, why = status()
>>> isinstance(ok, bool) and isinstance(why, str)
True
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("equations.c")
#: the compiler's flags: optimized, no fused multiply-add (the source's rounding), position-independent
FLAGS = ("-O2", "-ffp-contract=off", "-fno-fast-math", "-shared", "-fPIC")
#: the model sizes the compiled equations take (units, axles)
NMAX, AMAX = 16, 64

_state: dict = {}


class _Model(ctypes.Structure):
    _fields_ = [("N", ctypes.c_int), ("na", ctypes.c_int), ("linear", ctypes.c_int), ("iterations", ctypes.c_int),
                ("mu", ctypes.c_double), ("drive_tires", ctypes.c_double), ("rtol", ctypes.c_double),
                ("c", ctypes.c_void_p), ("au", ctypes.c_void_p), ("x", ctypes.c_void_p), ("tires", ctypes.c_void_p),
                ("steered", ctypes.c_void_p), ("driven", ctypes.c_void_p), ("drive_share", ctypes.c_void_p)]


class _Params(ctypes.Structure):
    _fields_ = [(name, ctypes.c_void_p) for name in ("m", "I", "CF", "CM", "CSD2", "Fz", "muFz")]


class _Failure(ctypes.Structure):
    _fields_ = [("row", ctypes.c_longlong), ("axle", ctypes.c_longlong), ("needed", ctypes.c_double),
                ("available", ctypes.c_double)]


def cache_dir() -> Path:
    """Where the compiled library is kept (see the module docstring)."""
    if os.environ.get("LCV_CACHE_DIR"):
        return Path(os.environ["LCV_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "lcvreport"


def _compiler() -> str | None:
    for name in (os.environ.get("CC"), "cc", "gcc"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def _library_path() -> Path:
    digest = hashlib.sha256(SOURCE.read_bytes() + " ".join(FLAGS).encode()).hexdigest()[:16]
    return cache_dir() / f"lcv_nonlinear_{digest}.so"


def _build(target: Path) -> str | None:
    """Compile the source to ``target`` (atomically: a concurrent process finds a whole library or
    none); the reason it could not, or None."""
    cc = _compiler()
    if cc is None:
        return "no C compiler (cc, gcc) on PATH"
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(suffix=".so", dir=target.parent)
        os.close(fd)
    except OSError as exc:
        return f"the cache {target.parent} is not writable ({exc.strerror})"
    try:
        done = subprocess.run([cc, *FLAGS, "-o", tmp, str(SOURCE), "-lm"], capture_output=True, text=True,
                              timeout=120)
        if done.returncode != 0:
            return f"{cc} failed: {done.stderr.strip().splitlines()[-1] if done.stderr.strip() else done.returncode}"
        os.replace(tmp, target)
        return None
    except (OSError, subprocess.SubprocessError) as exc:
        return f"{cc} could not run ({exc})"
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def library():
    """The compiled equations (a ctypes library), compiled if needed; None where they cannot be
    (:func:`status`)."""
    if "lib" in _state:
        return _state["lib"]
    lib, why = None, None
    if os.environ.get("LCV_NATIVE", "1") == "0":
        why = "LCV_NATIVE=0"
    else:
        path = _library_path()
        if not path.exists():
            why = _build(path)
        if why is None:
            try:
                lib = ctypes.CDLL(str(path))
                f = lib.lcv_nonlinear_derivatives
                f.restype = ctypes.c_int
                f.argtypes = [ctypes.POINTER(_Model), ctypes.POINTER(_Params), ctypes.c_longlong, ctypes.c_void_p,
                              ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_void_p, ctypes.c_void_p,
                              ctypes.c_void_p, ctypes.POINTER(_Failure)]
            except OSError as exc:
                lib, why = None, f"{path} could not be loaded ({exc})"
    _state["lib"], _state["why"] = lib, why or f"compiled: {_library_path()}"
    return lib


def status() -> tuple[bool, str]:
    """(whether the compiled equations are used, where they are or why not)."""
    lib = library()
    return lib is not None, _state["why"]


class CompiledEquations:
    """The compiled equations of one :class:`~lcvreport.model.nonlinear.model.NonlinearModel`
    (its geometry's constants held as C structures); :meth:`derivatives` of a batch of states."""

    def __init__(self, model, lib, iterations: int, rtol: float):
        self._lib = lib
        keep = dict(c=np.ascontiguousarray(model._c, dtype=float), au=np.ascontiguousarray(model._au, dtype=np.int64),
                    x=np.ascontiguousarray(model._x, dtype=float), tires=np.ascontiguousarray(model._tires, dtype=float),
                    steered=np.ascontiguousarray(model._steered, dtype=float),
                    driven=np.ascontiguousarray(model._driven, dtype=float),
                    drive_share=np.ascontiguousarray(model._drive_share, dtype=float))
        self._keep = keep
        self._model = _Model(model._N, model._x.size, int(model._linear_tires), int(iterations), float(model.mu),
                             float(model._drive_tires), float(rtol), *(keep[k].ctypes.data for k in
                                                                       ("c", "au", "x", "tires", "steered", "driven",
                                                                        "drive_share")))
        self.n_states, self.n_axles = 2 * model._N + 3, model._x.size

    def derivatives(self, x: np.ndarray, w: np.ndarray, speed_mps: float, tire_scale: float, p,
                    forces: bool = False):
        """(x' (B, n), D (B,), None) or (None, None, (row, axle, needed, available)) of the states
        ``x`` (B, n), inputs ``w`` (B, n_w), parameters ``p`` (one row per state); with ``forces``
        (x', D, (F_x, F_y)): each axle's forces in its wheels' axes (B, n_axles) [N] besides."""
        x = np.ascontiguousarray(x, dtype=float)
        w = np.ascontiguousarray(w, dtype=float)
        B = x.shape[0]
        arrays = [np.ascontiguousarray(a, dtype=float) for a in (p.m, p.I, p.CF, p.CM, p.tires_CSD2, p.Fz_tire, p.mu_Fz)]
        params = _Params(*(a.ctypes.data for a in arrays))
        dx = np.empty((B, self.n_states))
        D = np.empty(B)
        F = np.empty((B, 2, self.n_axles)) if forces else None
        fail = _Failure()
        code = self._lib.lcv_nonlinear_derivatives(ctypes.byref(self._model), ctypes.byref(params), B, x.ctypes.data,
                                                   w.ctypes.data, float(speed_mps), float(tire_scale), dx.ctypes.data,
                                                   D.ctypes.data, None if F is None else F.ctypes.data,
                                                   ctypes.byref(fail))
        if code:
            return None, None, (int(fail.row), int(fail.axle), float(fail.needed), float(fail.available))
        return dx, D, (None if F is None else (F[:, 0], F[:, 1]))


def compiled(model, iterations: int, rtol: float) -> CompiledEquations | None:
    """The compiled equations of ``model`` (the drive force's fixed point: at most ``iterations``
    passes, to the relative tolerance ``rtol``), or None (no library, or a model larger than
    :data:`NMAX` units or :data:`AMAX` axles: the numpy equations then)."""
    if model._N > NMAX or model._x.size > AMAX:
        return None
    lib = library()
    return None if lib is None else CompiledEquations(model, lib, iterations, rtol)


def main() -> int:
    """``python -m lcvreport.model.nonlinear.native``: compile (if needed) and say where, or why not."""
    ok, why = status()
    print(("compiled equations: " if ok else "numpy equations: ") + why)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
