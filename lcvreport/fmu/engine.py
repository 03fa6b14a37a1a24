"""The co-simulation engine behind the pythonfmu FMUs (docs/fmu.md), SI, numpy only.

:class:`LCVEngine` holds one vehicle, its state ``z = [x, psi1, Y1]`` and caches of
exact zero-order-hold discretizations keyed by (speed, step size) and of the
speed-dependent output maps.  It addresses inputs and outputs through the interface
table (:mod:`lcvreport.fmu.interface`): the slave in ``fmu_src/LCV.py`` only maps FMI
calls onto it.  The C FMU implements the same semantics on data generated from the
same table.  Runs inside the FMU's embedded interpreter, so it imports numpy and
the numpy-only model core, never scipy.

Semantics (both FMUs):

* inputs are held over a step; ``u`` below ``u_min`` runs at ``u_min`` with one
  warning each time it enters that range; a non-finite input, an input outside
  :data:`lcvreport.ranges.RANGES` or a bad step size refuses the step
  (:class:`CosimError`, the state is kept);
* a step whose result is not finite is refused with the state kept;
* outputs: the state's linear functions, the rear offsets (eq. 4.42-4.46, with the
  sine), the feedthrough outputs at the current state and inputs (``ay_i``; the yaw-roll
  model's ``as_i``, ``dFz_<axle>``, ``ltr<g>``), ``max_real_eig`` at the current (clamped)
  input speed; units a preset lacks give 0.

The model is the interface's (:attr:`Interface.model`): the yaw plane or the yaw-roll model,
whose state ``x`` adds the roll rates and roll angles.

Examples
--------
>>> from lcvreport.fmu.interface import preset_interface
>>> e = LCVEngine(preset_interface(), preset="tractor_semitrailer")
>>> w = e.start_inputs()
>>> w[e.input_index["P21"]] = 1000.0
>>> e.step(0.01, w) is None
True
"""
from __future__ import annotations

import json
import math

import numpy as np

from ..analysis.discretize import augmented_state_matrix
from ..model.linear import linear_model
from ..model.yaw_plane.outputs import rear_end_weights
from ..ranges import RANGES, RangeError
from ..util.cache import LRUCache
from ..util.numerics import expm
from .interface import Interface


#: the step's numpy calls, bound once (a global name, not an attribute chain, per step)
_matmul, _add_reduce, _sin, _isfinite = np.matmul, np.add.reduce, np.sin, math.isfinite


class CosimError(ValueError):
    """A bad parameter, input or call; ``variable`` names it."""

    def __init__(self, variable: str, message: str):
        super().__init__(message)
        self.variable = variable


#: magic prefix of a serialized engine state
STATE_MAGIC = "lcv-fmu-state/1"


#: the range of each kind of residual input
_INPUT_RANGE = {"P": "residual_force", "T": "residual_moment", "eps": "misalignment"}


class LCVEngine:
    """Exact zero-order-hold stepping of one vehicle through an FMU interface (SI).

    Parameters
    ----------
    interface : Interface
    preset : str, optional
        In preset mode, the preset to run.
    tire_scale : float
        Factor on every tire coefficient [-].
    u_min : float
        Lowest speed the model is run at [m/s].
    cache_size : int
        Number of (speed, step) discretizations kept.

    Raises
    ------
    CosimError
        For a bad parameter (the message names it and its range).
    """

    #: exact steps of a linear model: outputs from output matrices (the slave's fast path)
    linear = True

    def __init__(self, interface: Interface, preset: str | None = None, tire_scale: float = 1.0,
                 u_min: float = 2.2352, cache_size: int = 128, crossfall: float = 0.0):
        self.interface = interface
        try:
            vehicle = interface.vehicle(preset)
        except KeyError as exc:
            raise CosimError("preset", str(exc.args[0])) from None
        for name, value in (("tire_scale", tire_scale), ("u_min", u_min), ("crossfall", crossfall)):
            try:
                RANGES[name].check(value, name)
            except RangeError as exc:
                raise CosimError(name, str(exc)) from None
        self.preset = preset
        self.vehicle = vehicle
        self.tire_scale = float(tire_scale)
        self.u_min = float(u_min)
        self.crossfall = float(crossfall)
        self.co = linear_model(vehicle, interface.model)
        # the crossfall's constant generalized force: one more input column, always 1
        self._Fc = math.sin(math.atan(self.crossfall / 100.0)) * self.co.B_crossfall
        self.n = self.co.n_states
        self.m = self.n + 2
        self.input_names = tuple(v.name for v in interface.inputs)
        self.input_index = {name: k for k, name in enumerate(self.input_names)}
        self.output_names = tuple(v.name for v in interface.outputs)
        self._build_maps()
        self._steps = LRUCache(cache_size)
        self._speeds = LRUCache(1024)
        self._steps_out = LRUCache(cache_size)
        # [z, w, 1]: the state lives in this buffer (``z`` is a view of it), the inputs are copied in
        self._zw = np.zeros(self.m + len(self.input_names) + 1)
        self._zw[-1] = 1.0
        self._z = self._zw[:self.m]
        self._w_at = slice(self.m, -1)
        self.stepped_outputs = None
        self._last_h = None
        self._last_u = self._last_step_h = None
        self._last_K = None
        self.reset()

    # ------------------------------------------------------------------ set-up
    def _build_maps(self) -> None:
        """Input matrix and output maps from the interface table."""
        v, co, n, m = self.vehicle, self.co, self.n, self.m
        axles = v.axle_names
        nu = v.n_units
        self._Bw = np.zeros((n, len(self.input_names)))
        self._ranges = []
        for k, var in enumerate(self.interface.inputs):
            kind = var.source[0]
            if kind == "steer":
                self._Bw[:, k] = co.B_delta(self.tire_scale)
                self._ranges.append(RANGES["steer_angle"])
            elif kind in ("P", "T", "eps") and var.source[1] in axles:
                col = axles.index(var.source[1])
                self._Bw[:, k] = {"P": co.B_P, "T": co.B_T}[kind][:, col] if kind != "eps" else \
                    self.tire_scale * co.B_eps[:, col]       # a misalignment acts like a steer of that axle
                self._ranges.append(RANGES[_INPUT_RANGE[kind]])
            elif kind in ("P", "T", "eps"):  # an axle the preset lacks: ignored
                self._ranges.append(RANGES[_INPUT_RANGE[kind]])
            else:
                self._ranges.append(None)
        # each axle's constant tire force from the inputs (the load transfer's F_y0): P + s C_F eps
        self._Fy_w = np.zeros((len(axles), len(self.input_names)))
        for k, var in enumerate(self.interface.inputs):
            if var.source[0] in ("P", "eps") and var.source[1] in axles:
                j = axles.index(var.source[1])
                self._Fy_w[j, k] = 1.0 if var.source[0] == "P" else \
                    self.tire_scale * v.axles[j].cornering_stiffness_axle_N_per_rad
        self._range_lo = np.array([-np.inf if r is None else r.low for r in self._ranges])
        self._range_hi = np.array([np.inf if r is None else r.high for r in self._ranges])
        n_out = len(self.output_names)
        self._C = np.zeros((n_out, m))           # linear outputs of z
        self._W = np.zeros((n_out, nu - 1))      # y outputs: W sin(Theta)
        self._fd_row = np.full(n_out, -1)        # row of a feedthrough output: ay_1..ay_N, then the extras
        self._eig_out = -1
        self._H = co.heading_rows()              # Theta = H z
        W_all = rear_end_weights(v)
        rear_row = co.point_lateral_row(nu - 1, v.rear_end_x_m(nu - 1))
        roll_rows = co.roll_offset_rows()        # the yaw-roll model's roll offsets of units 2..N
        extra_names = co.extra_signal_terms()["names"]
        states = co.state_names
        for o, var in enumerate(self.interface.outputs):
            kind = var.source[0]
            if kind == "state" and var.source[1] in states:
                self._C[o, states.index(var.source[1])] = 1.0
            elif kind == "psi1":
                self._C[o, n] = 1.0
            elif kind == "Y1":
                self._C[o, n + 1] = 1.0
            elif kind == "Y_rear":
                self._C[o] = rear_row
            elif kind == "Y_axle":                            # an axle centre
                j = v.axle_names.index(var.source[1])
                self._C[o] = co.point_lateral_row(v.axle_units[j], v.axles[j].x_m)
            elif kind == "y" and var.source[1] <= nu:
                self._W[o] = W_all[var.source[1] - 2]
                if roll_rows is not None:
                    self._C[o, :n] = roll_rows[var.source[1] - 2]
            elif kind == "ay" and var.source[1] <= nu:
                self._fd_row[o] = var.source[1] - 1
            elif kind == "extra":
                self._fd_row[o] = nu + extra_names.index(var.source[1])
            elif kind == "max_real_eig":
                self._eig_out = o
        self._has_y = bool(np.any(self._W))
        # the step's buffers: its product [z, linear outputs, Theta] and views of it, the outputs
        n_out = len(self.output_names)
        rows = m + n_out + (nu - 1 if self._has_y else 0)
        self._res = np.zeros(rows)
        self._res_z, self._res_outputs, self._res_angles = self._res[:m], self._res[m:m + n_out], self._res[m + n_out:]
        self._out = np.zeros(n_out)
        self._F = np.zeros((n_out, rows))
        self._F[:, m:m + n_out] = np.eye(n_out)
        if self._has_y:
            self._F[:, m + n_out:] = self._W

    def maps(self) -> dict:
        """The engine's input and output maps (what the C FMU's generated data holds):
        ``Bw`` (n x inputs, steer and misalignment columns at tire scale 1), ``C`` (outputs x n+2),
        ``H`` (N-1 x n+2), ``W`` (outputs x N-1), ``fd_row`` (outputs: the feedthrough row
        -- ``ay_i`` is row i-1, the model's extra signals follow --, -1: not one), ``Fy_w``
        (axles x inputs: each axle's constant tire force, misalignment columns at tire scale 1),
        ``eig_out`` (index of max_real_eig or -1)."""
        Bw, Fy_w = self._Bw.copy(), self._Fy_w.copy()
        if self.tire_scale != 1.0:
            for k, var in enumerate(self.interface.inputs):
                if var.source[0] == "steer":
                    Bw[:, k] = self.co.B_delta(1.0)
                elif var.source[0] == "eps":
                    Bw[:, k] /= self.tire_scale
                    Fy_w[:, k] /= self.tire_scale
        return {"Bw": Bw, "C": self._C.copy(), "H": self._H.copy(), "W": self._W.copy(),
                "fd_row": self._fd_row.copy(), "Fy_w": Fy_w, "eig_out": self._eig_out}

    def start_inputs(self) -> np.ndarray:
        """The inputs' start values (interface order), SI."""
        return np.array([float(v.start) for v in self.interface.inputs])

    @property
    def z(self) -> np.ndarray:
        """The state ``[x, psi1, Y1]`` (SI; a view of the engine's buffer: copy it to keep it)."""
        return self._z

    @z.setter
    def z(self, value) -> None:
        self._z[:] = value

    def reset(self) -> None:
        """Back to rest at time 0 (keeps the caches)."""
        self.z = np.zeros(self.m)
        self.stepped_outputs = None
        self.time = 0.0
        self.clamped = False
        self.last_speed_mps = self.effective_speed(float(self.interface.by_name["u"].start))

    # ------------------------------------------------------------------ checks
    def effective_speed(self, u: float) -> float:
        """The speed the model runs at for an input ``u`` [m/s] (clamped to u_min)."""
        return max(u, self.u_min)

    def input_problem(self, w, speed: bool = True) -> CosimError | None:
        """The first input that is not finite or out of range (``speed``: u above its
        maximum counts), as an error to raise or log; None if all are valid."""
        w = np.asarray(w, dtype=float)
        ok = np.isfinite(w) & (w >= self._range_lo) & (w <= self._range_hi)
        u = w[0]
        speed_ok = not speed or (math.isfinite(u) and u <= RANGES["speed"].high)
        if ok.all() and speed_ok:
            return None
        for k, name in enumerate(self.input_names):
            val = w[k]
            if not math.isfinite(val):
                return CosimError(name, f"input {name} is not finite ({val!r}); the step is refused and the state "
                                        "is unchanged")
            if k == 0 and not speed_ok:
                return CosimError(name, f"input u = {val:.6g} m/s is above {RANGES['speed'].high:g} m/s, the fastest "
                                        "speed the model is run at; the step is refused and the state is unchanged")
            if not ok[k]:
                return CosimError(name, f"input {name} = {val:.6g} is outside {self._ranges[k].text()}; the step is "
                                        "refused and the state is unchanged")
        return None  # pragma: no cover

    def check_inputs(self, w) -> None:
        """Raise :class:`CosimError` naming the first input that is not finite or out of range."""
        problem = self.input_problem(w)
        if problem is not None:
            raise problem

    # ------------------------------------------------------------------ caches
    def _step_matrix(self, u: float, h: float) -> np.ndarray:
        """``[Ad, Gd Bw]``: the new z from ``[z, w]`` (cached per speed and step)."""
        def compute():
            A, G = augmented_state_matrix(self.co, u, self.tire_scale)
            nb = self.m + self.n
            big = np.zeros((nb, nb))
            big[:self.m, :self.m] = A * h
            big[:self.m, self.m:] = G * h
            E = expm(big)
            K = np.hstack([E[:self.m, :self.m], E[:self.m, self.m:] @ self._Bw, E[:self.m, self.m:] @ self._Fc[:, None]])
            K.setflags(write=False)
            return K
        return self._steps.get((u, h), compute)

    def _step_output_matrix(self, u: float, h: float) -> np.ndarray:
        """``[K; O P; H K]``: from ``[z, w]`` the new state ``K [z, w]``, the linear
        outputs at it with ``w`` held (``P [z, w] = [K [z, w], w]``) and the cumulative
        articulation angles of the rear-end offsets (cached per speed and step)."""
        def compute():
            K = self._step_matrix(u, h)
            nw = len(self.input_names) + 1                       # the inputs and the constant 1
            P = np.vstack([K, np.hstack([np.zeros((nw, self.m)), np.eye(nw)])])
            rows = [K, self.output_matrix(u) @ P]
            if self._has_y:
                rows.append(self._H @ K)
            out = np.vstack(rows)
            if self._eig_out >= 0:                               # a constant at this speed
                out[self.m + self._eig_out] = 0.0
                out[self.m + self._eig_out, -1] = self.max_real_eig(u)
            out.setflags(write=False)
            return out
        return self._steps_out.get((u, h), compute)

    def _speed_maps(self, u: float) -> dict:
        """Output maps that depend on the speed: the feedthrough rows ``fd = Ca x + DaB w + daF``
        (ay, then the model's extra signals ``X x + XD x' + D delta + O F_y0``); max_real_eig (lazy)."""
        def compute():
            co, s = self.co, self.tire_scale
            Ca, Da = co.acceleration_maps(u, s)
            DaB, daF = Da @ self._Bw, Da @ self._Fc
            names, X, XD, D, O = co.extra_signals(u, s)
            if names:
                A, G = co.state_derivative_maps(u, s)
                steer = np.array([var.source[0] == "steer" for var in self.interface.inputs], dtype=float)
                Ca = np.vstack([Ca, X + XD @ A])
                DaB = np.vstack([DaB, XD @ G @ self._Bw + np.outer(D, steer) + O @ self._Fy_w])
                daF = np.r_[daF, XD @ G @ self._Fc]
            return {"Ca": Ca, "DaB": DaB, "daF": daF, "eig": None}
        return self._speeds.get(u, compute)

    def max_real_eig(self, u: float) -> float:
        """Largest real part of the eigenvalues at speed ``u`` [m/s] (cached)."""
        maps = self._speed_maps(u)
        if maps["eig"] is None:
            A, _ = self.co.state_derivative_maps(u, self.tire_scale)
            maps["eig"] = float(np.linalg.eigvals(A).real.max())
        return maps["eig"]

    # ------------------------------------------------------------------ stepping
    def step(self, h: float, w, checked: bool = False) -> str | None:
        """Advance by ``h`` [s] with the SI inputs ``w`` (interface order) held.

        ``checked``: the caller has checked ``w`` with :meth:`input_problem` since it last
        changed (the FMU slave checks once per change of the inputs, not per step).

        Returns
        -------
        str or None
            A warning to log (speed clamped), else None.

        Raises
        ------
        CosimError
            A bad step size or input, or a step whose result is not finite; the state
            is left unchanged.
        """
        if h != self._last_h:                       # one check per new step size, not per step
            r = RANGES["step_size"]
            if not (isinstance(h, float) and math.isfinite(h) and r.low <= h <= r.high):
                raise CosimError("communicationStepSize", f"communication step size must be in {r.text()}, got "
                                                          f"{h!r}; the step is refused")
            self._last_h = h
        if not checked:
            w = np.asarray(w, dtype=float)
            self.check_inputs(w)
        u = float(w[0])
        warning = None
        clamped = u < self.u_min
        if clamped:
            if not self.clamped:
                warning = (f"u = {u:.6g} m/s is below u_min = {self.u_min:.6g} m/s; the model runs at u_min "
                           "until u rises again (the linear model needs a forward speed)")
            u = self.u_min
        if u != self._last_u or h != self._last_step_h:
            self._last_K = self._step_output_matrix(u, h)
            self._last_u, self._last_step_h = u, h
        # one product gives the new state, the outputs at it (inputs held), max_real_eig (its
        # constant column) and the angles whose sines the rear-end offsets need; buffers and their
        # views are made once (_build_maps)
        zw, res = self._zw, self._res
        zw[self._w_at] = w                         # the state is in place already
        _matmul(self._last_K, zw, out=res)
        # the sum is finite exactly when every element is (an inf or a NaN propagates), unless
        # finite elements overflow it, i.e. above 1e307: refused too, as no state can be that large
        if not _isfinite(_add_reduce(res)):
            raise CosimError("state", f"the step to t = {self.time + h:.6g} s is refused: its result is not finite "
                                      f"(the vehicle is unstable at u = {u:.6g} m/s, max Re(lambda) = "
                                      f"{self.max_real_eig(u):.4g} 1/s); the state is unchanged")
        out = self._out
        if self._has_y:                            # outputs = [0 I W] [z, linear outputs, sin(Theta)]
            angles = self._res_angles
            _sin(angles, out=angles)
            _matmul(self._F, res, out=out)
        else:
            out[...] = self._res_outputs
        self.stepped_outputs = out
        self._z[...] = self._res_z
        self.time += h
        self.clamped = clamped
        self.last_speed_mps = u
        return warning

    # ------------------------------------------------------------------ outputs
    def output_speed(self, w) -> float:
        """The speed the feedthrough outputs are evaluated at: the input u clamped to
        u_min, or the last speed stepped with when u is not a valid speed."""
        u = float(w[0])
        if math.isfinite(u) and u <= RANGES["speed"].high:
            return self.effective_speed(u)
        return self.last_speed_mps

    @property
    def eig_output(self) -> int:
        """Index of ``max_real_eig`` among the outputs, -1 if none."""
        return self._eig_out

    @property
    def has_y(self) -> bool:
        """True when some output is a rear-end offset (nonlinear in the state: sines)."""
        return self._has_y

    def stacked(self, w) -> np.ndarray:
        """``[z, w]`` in a buffer of the engine (valid until the next call)."""
        zw = self._zw
        zw[self.m:-1] = w
        return zw

    def rear_offsets(self) -> np.ndarray:
        """The outputs' rear-end offset terms ``W sin(H z)`` (zero rows elsewhere)."""
        return self._W @ np.sin(self._H @ self.z)

    def output_matrix(self, u: float) -> np.ndarray:
        """``O`` with ``outputs = O [z, w] (+ W sin(H z))`` at speed ``u``: the linear
        outputs and the lateral accelerations in one matrix (cached per speed)."""
        maps = self._speed_maps(u)
        O = maps.get("O")
        if O is None:
            O = np.hstack([self._C, np.zeros((self._C.shape[0], len(self.input_names) + 1))])
            sel = np.flatnonzero(self._fd_row >= 0)
            if sel.size:
                O[sel, :self.n] = maps["Ca"][self._fd_row[sel]]
                O[sel, self.m:-1] = maps["DaB"][self._fd_row[sel]]
                O[sel, -1] = maps["daF"][self._fd_row[sel]]
            O.setflags(write=False)
            maps["O"] = O
        return O

    def outputs(self, w, problem: CosimError | None | bool = False) -> np.ndarray:
        """Every output (interface order), SI, at the current state and inputs ``w``.

        The lateral accelerations depend on the inputs directly: while an input is not
        finite or out of range they are NaN and :attr:`output_error` says which input.
        ``problem``: the result of :meth:`input_problem(w, speed=False)` when the caller
        has it (False: check here)."""
        w = np.asarray(w, dtype=float)
        self.output_error = None
        if problem is False:
            problem = self.input_problem(w, speed=False)
        u = self.output_speed(w)
        if problem is None:
            out = self.output_matrix(u) @ self.stacked(w)
        else:
            out = self._C @ self.z
            sel = self._fd_row >= 0
            out[sel] = np.nan
            self.output_error = (f"the lateral accelerations depend on the inputs and {problem.variable} is "
                                 f"not valid: {problem}")
        if self._has_y:
            out += self._W @ np.sin(self._H @ self.z)
        if self._eig_out >= 0:
            out[self._eig_out] = self.max_real_eig(u)
        return out

    # ------------------------------------------------------------------ FMU state
    def get_state(self) -> dict:
        """JSON-serializable snapshot of everything that evolves (floats round-trip exactly)."""
        return {"z": self.z.tolist(), "time": self.time, "clamped": self.clamped,
                "last_speed_mps": self.last_speed_mps}

    def set_state(self, state: dict) -> None:
        """Restore a snapshot of :meth:`get_state`.

        Raises
        ------
        CosimError
            A snapshot of another size or with non-finite numbers.
        """
        try:
            z = np.array(state["z"], dtype=float)
            t = float(state["time"])
            clamped = bool(state["clamped"])
            last = float(state["last_speed_mps"])
        except (KeyError, TypeError, ValueError):
            raise CosimError("FMUstate", "the FMU state is not one this FMU wrote") from None
        if z.shape != self.z.shape:
            raise CosimError("FMUstate", f"the FMU state holds {z.size} values; {self.vehicle.name} needs {self.m}")
        if not (np.all(np.isfinite(z)) and math.isfinite(t) and math.isfinite(last)):
            raise CosimError("FMUstate", "the FMU state holds numbers that are not finite")
        self.z = z
        self.time, self.clamped, self.last_speed_mps = t, clamped, last
        self.stepped_outputs = None


def state_to_bytes(state: dict) -> bytes:
    """Serialize a slave state: a magic line, then JSON."""
    return (STATE_MAGIC + "\n" + json.dumps(state, allow_nan=False)).encode("utf-8")


def state_from_bytes(data: bytes) -> dict:
    """Parse :func:`state_to_bytes`; raise ``ValueError`` for anything else."""
    text = bytes(data).decode("utf-8")
    magic, _, body = text.partition("\n")
    if magic != STATE_MAGIC:
        raise ValueError("not an FMU state written by this FMU")
    state = json.loads(body)
    if not isinstance(state, dict):
        raise ValueError("not an FMU state written by this FMU")
    return state
