"""The nonlinear model's equations compiled (``equations.c`` beside this module): the same
arithmetic as :meth:`NonlinearModel._solve <lcvreport.model.nonlinear.model.NonlinearModel>` one
state at a time: a call ~6x cheaper than numpy's (what is left is the call's own Python), so
that an integration's cost is its steps, not the interpreter (docs/nonlinear.md#integration).

The library is compiled and cached by :mod:`lcvreport.util.compiled` (the machine's C compiler,
the user's cache, ``./build.sh`` at set-up).  Where it cannot be had, or ``LCV_NATIVE=0``, the
numpy equations are used (:func:`status` says which and why): the same equations, numbers that
differ in rounding only (tests/test_native.py holds the two to 8 eps times the mass matrix's
condition number).

Examples
--------
>>> ok, why = status()
>>> isinstance(ok, bool) and isinstance(why, str)
True
"""
from __future__ import annotations

import ctypes
from pathlib import Path

import numpy as np

from ...util.compiled import command_line, load

SOURCE = Path(__file__).with_name("equations.c")
#: the model sizes the compiled equations take (units, axles)
NMAX, AMAX = 16, 64


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


def library():
    """The compiled equations (a ctypes library), compiled if needed; None where they cannot be
    (:func:`status`)."""
    return load(SOURCE, {"lcv_nonlinear_derivatives": (ctypes.c_int, [
        ctypes.POINTER(_Model), ctypes.POINTER(_Params), ctypes.c_longlong, ctypes.c_void_p, ctypes.c_void_p,
        ctypes.c_double, ctypes.c_double, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
        ctypes.POINTER(_Failure)])})[0]


def status() -> tuple[bool, str]:
    """(whether the compiled equations are used, where they are or why not)."""
    lib = library()
    return lib is not None, load(SOURCE)[1]


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
        self._param_structs: dict = {}

    def _params(self, p) -> "_Params":
        """The C structure of the parameters ``p``, made once per :class:`Parameters` object (an
        integration calls the equations with the same few hundreds of times; the object is kept
        with it, so that its id is not reused)."""
        hit = self._param_structs.get(id(p))
        if hit is not None and hit[0] is p:
            return hit[2]
        arrays = [np.ascontiguousarray(a, dtype=float) for a in (p.m, p.I, p.CF, p.CM, p.tires_CSD2, p.Fz_tire, p.mu_Fz)]
        if len(self._param_structs) >= 64:
            self._param_structs.clear()
        struct = _Params(*(a.ctypes.data for a in arrays))
        self._param_structs[id(p)] = (p, arrays, struct)
        return struct

    def derivatives(self, x: np.ndarray, w: np.ndarray, speed_mps: float, tire_scale: float, p,
                    forces: bool = False):
        """(x' (B, n), D (B,), None) or (None, None, (row, axle, needed, available)) of the states
        ``x`` (B, n), inputs ``w`` (B, n_w), parameters ``p`` (one row per state); with ``forces``
        (x', D, (F_x, F_y)): each axle's forces in its wheels' axes (B, n_axles) [N] besides."""
        x = np.ascontiguousarray(x, dtype=float)
        w = np.ascontiguousarray(w, dtype=float)
        B = x.shape[0]
        params = self._params(p)
        n = self.n_states
        buf = np.empty(B * (n + 1))                      # x' (B, n), then D (B,): one allocation
        dx, D = buf[:B * n].reshape(B, n), buf[B * n:]
        at = buf.ctypes.data
        F = np.empty((B, 2, self.n_axles)) if forces else None
        fail = _Failure()
        code = self._lib.lcv_nonlinear_derivatives(ctypes.byref(self._model), ctypes.byref(params), B, x.ctypes.data,
                                                   w.ctypes.data, float(speed_mps), float(tire_scale), at,
                                                   at + 8 * B * n, None if F is None else F.ctypes.data,
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


def main(argv=None) -> int:
    """``python -m lcvreport.model.nonlinear.native``: compile (if needed) and say where, or why not.
    Takes no argument (``--help``: this)."""
    status_ = command_line("lcvreport.model.nonlinear.native", main.__doc__ or "", argv)
    if status_ is not None:
        return status_
    ok, why = status()
    print(("compiled equations: " if ok else "numpy equations: ") + why)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
