"""The nonlinear planar model stepped through an FMU interface (docs/fmu.md#the-nonlinear-model):
what the Python FMU of ``lcv fmu --model nonlinear`` computes.

Each communication step integrates the model (:func:`lcvreport.analysis.integrate.integrate_step`:
the implicit integration of ``lcv simulate --model nonlinear``, rtol 1e-8) over the step with
the inputs held (zero-order hold: speed, steer, residual forces, moments and misalignments) and
the crossfall and the friction coefficient as fixed parameters.  The same calls as the linear
models' :class:`~lcvreport.fmu.engine.LCVEngine` answer, so that the slave
(:class:`~lcvreport.fmu.slave_core.SlaveCore`) runs either.

Examples
--------
>>> from lcvreport.model.vehicle_file import load_vehicle
>>> from lcvreport.fmu.interface import vehicle_interface
>>> itf = vehicle_interface(load_vehicle("examples/vehicles/b_double.toml"), 25.0, model="nonlinear")
>>> e = NonlinearEngine(itf)
>>> w = e.start_inputs(); w[1] = 0.01                     # 0.01 rad of steer, held
>>> e.step(0.1, w) is None, round(float(e.stepped_outputs[e.output_names.index("r1")]), 5) > 0
(True, True)
"""
from __future__ import annotations

import math

import numpy as np

from ..analysis.integrate import IntegrationError, integrate_step
from ..model.nonlinear.model import nonlinear_model
from ..ranges import RANGES, RangeError
from .engine import CosimError, LCVEngine
from .interface import Interface


class NonlinearEngine:
    """One vehicle's nonlinear planar model stepped by integration (SI).

    Parameters
    ----------
    interface : Interface
        A ``nonlinear`` interface (:func:`~lcvreport.fmu.interface.vehicle_interface`).
    tire_scale : float
        Factor on every tire coefficient [-].
    u_min : float
        Lowest speed the model is run at [m/s].
    crossfall : float
        Road crossfall [%].
    friction_coefficient : float
        mu, in (0, 2].

    Raises
    ------
    CosimError
        A bad parameter (the message names it and its range).
    """

    #: the engine steps by integration: no output matrices (the slave asks :meth:`outputs`)
    linear = False
    preset = None

    def __init__(self, interface: Interface, preset: str | None = None, tire_scale: float = 1.0,
                 u_min: float = 2.2352, crossfall: float = 0.0, friction_coefficient: float = 0.8):
        self.interface = interface
        self.vehicle = interface.vehicles[0]
        for name, value in (("tire_scale", tire_scale), ("u_min", u_min), ("crossfall", crossfall),
                            ("friction", friction_coefficient)):
            try:
                RANGES[name].check(value, "friction_coefficient" if name == "friction" else name)
            except RangeError as exc:
                raise CosimError("friction_coefficient" if name == "friction" else name, str(exc)) from None
        self.tire_scale, self.u_min = float(tire_scale), float(u_min)
        self.crossfall, self.friction_coefficient = float(crossfall), float(friction_coefficient)
        self.model = nonlinear_model(self.vehicle, "saturating", self.friction_coefficient)
        self.a_crossfall = 9.80665 * math.sin(math.atan(self.crossfall / 100.0))
        self.input_names = tuple(v.name for v in interface.inputs)
        self.output_names = tuple(v.name for v in interface.outputs)
        self._model_key = tuple(v.source[1] for v in interface.outputs)
        self._feedthrough = np.array([v.source[0] in ("ay", "extra") for v in interface.outputs])
        lo = [-math.inf if v.minimum is None else v.minimum for v in interface.inputs]
        hi = [math.inf if v.maximum is None else v.maximum for v in interface.inputs]
        self._range_lo, self._range_hi = np.array(lo), np.array(hi)
        self.output_error = None
        self.reset()

    def start_inputs(self) -> np.ndarray:
        """The inputs' start values (interface order), SI."""
        return np.array([float(v.start) for v in self.interface.inputs])

    def reset(self) -> None:
        """Back to rest, straight running, at time 0."""
        self.x = np.zeros(self.model.n_states)
        self.stepped_outputs = None
        self.time = 0.0
        self.clamped = False
        self.last_speed_mps = self.effective_speed(float(self.interface.by_name["u"].start))

    def effective_speed(self, u: float) -> float:
        """The speed the model runs at for an input ``u`` [m/s] (clamped to u_min)."""
        return max(u, self.u_min)

    def input_problem(self, w, speed: bool = True) -> CosimError | None:
        """The first input that is not finite or out of range, as an error; None if all are valid."""
        w = np.asarray(w, dtype=float)
        ok = np.isfinite(w) & (w >= self._range_lo) & (w <= self._range_hi)
        if not speed:
            ok[0] = True
        if ok.all():
            return None
        k = int(np.argmin(ok))
        name, val = self.input_names[k], w[k]
        if not math.isfinite(val):
            return CosimError(name, f"input {name} is not finite ({val!r}); the step is refused and the state is "
                                    "unchanged")
        lo, hi = self._range_lo[k], self._range_hi[k]
        valid = f"[{lo:g}, {hi:g}]" if math.isfinite(lo) else f"at most {hi:g}"
        return CosimError(name, f"input {name} = {val:.6g} is outside {valid} ({self.interface.inputs[k].unit}); "
                                "the step is refused and the state is unchanged")

    def _model_input(self, w) -> np.ndarray:
        """The model's inputs (:attr:`NonlinearModel.input_names`) of the FMU's ``w``."""
        return np.concatenate([np.asarray(w, dtype=float)[1:], [self.a_crossfall]])

    def step(self, h: float, w, checked: bool = False) -> str | None:
        """Advance by ``h`` [s] with the SI inputs ``w`` (interface order) held.

        Returns
        -------
        str or None
            A warning to log (speed clamped), else None.

        Raises
        ------
        CosimError
            A bad step size or input, a run that cannot be integrated (a driven axle out of
            friction: the time and the axle named); the state is left unchanged.
        """
        r = RANGES["step_size"]
        if not (isinstance(h, float) and math.isfinite(h) and r.low <= h <= r.high):
            raise CosimError("communicationStepSize", f"communication step size must be in {r.text()}, got {h!r}; "
                                                      "the step is refused")
        w = np.asarray(w, dtype=float)
        if not checked:
            problem = self.input_problem(w)
            if problem is not None:
                raise problem
        u = float(w[0])
        warning = None
        clamped = u < self.u_min
        if clamped:
            if not self.clamped:
                warning = (f"u = {u:.6g} m/s is below u_min = {self.u_min:.6g} m/s; the model runs at u_min until u "
                           "rises again")
            u = self.u_min
        wm = self._model_input(w)
        try:
            x = integrate_step(self.model, self.x, wm, u, h, self.tire_scale)
        except IntegrationError as exc:
            raise CosimError("state", f"the step to t = {self.time + h:.6g} s is refused: {exc}; the state is "
                                      "unchanged") from None
        out = self._outputs_at(x, wm, u)
        if not np.all(np.isfinite(out)):
            raise CosimError("state", f"the step to t = {self.time + h:.6g} s is refused: its result is not finite; "
                                      "the state is unchanged")
        self.x = x
        self.stepped_outputs = out
        self.time += h
        self.clamped = clamped
        self.last_speed_mps = u
        return warning

    def _outputs_at(self, x, wm, u) -> np.ndarray:
        got = self.model.outputs(self.time, x, wm, u, self.tire_scale)
        return np.array([got[k] for k in self._model_key], dtype=float)

    def output_speed(self, w) -> float:
        """The speed the outputs are evaluated at: ``u`` clamped to u_min, or the last speed
        stepped with when ``u`` is not a valid speed."""
        u = float(w[0])
        if math.isfinite(u) and 0.0 < u <= RANGES["speed"].high:
            return self.effective_speed(u)
        return self.last_speed_mps

    def outputs(self, w, problem: CosimError | None | bool = False) -> np.ndarray:
        """Every output (interface order), SI, at the current state and inputs ``w``; while an
        input is not valid the outputs that depend on the inputs (accelerations, tire forces,
        friction demand) are NaN and :attr:`output_error` says which input."""
        w = np.asarray(w, dtype=float)
        self.output_error = None
        if problem is False:
            problem = self.input_problem(w, speed=False)
        u = self.output_speed(w)
        if problem is None:
            return self._outputs_at(self.x, self._model_input(w), u)
        out = self._outputs_at(self.x, self._model_input(self.start_inputs()), u)
        out[self._feedthrough] = np.nan
        self.output_error = (f"the accelerations and tire forces depend on the inputs and {problem.variable} is not "
                             f"valid: {problem}")
        return out

    # the FMU state: the linear engine's snapshot (``z``, the time, the clamping, the last speed),
    # over this engine's state vector
    @property
    def z(self) -> np.ndarray:
        """The model's state (SI)."""
        return self.x

    @z.setter
    def z(self, value) -> None:
        self.x = np.array(value, dtype=float)

    @property
    def m(self) -> int:
        return self.model.n_states

    get_state = LCVEngine.get_state
    set_state = LCVEngine.set_state


__all__ = ["NonlinearEngine"]
