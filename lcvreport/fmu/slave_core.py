"""What the Python FMUs compute, whatever their FMI version: FMI calls mapped onto the engine.

:class:`SlaveCore` holds the variables, parameters, inputs and the
:class:`lcvreport.fmu.engine.LCVEngine` of one instance and answers the calls by value
reference; the adapters put it behind pythonfmu (FMI 2.0, :mod:`lcvreport.fmu.slave_fmi2`) and
pythonfmu3 (FMI 3.0, :mod:`lcvreport.fmu.slave_fmi3`) and say how a message is logged and how the
FMI functions are spelled.  ``resources/lcv_fmu.json`` says which interface: the six presets
(docs/fmu.md) or one vehicle built in (docs/fmu.md).

No exception may leave a callback: pythonfmu turns one into a Fatal status after releasing the
Python instance, which freeInstance then releases again (a use-after-free that crashes the
host).  Every callback catches, logs an error and returns something harmless; the FMU's loader
(``fmu_src/c/python/loader.c``, ``loader3.c``) turns a call that logged an error into the Error status
the standard asks for.
"""
import json
import math
import os

import numpy as np

from ..model.vehicle_file import load_vehicle
from .engine import CosimError, LCVEngine, state_from_bytes, state_to_bytes
from .interface import U_START, preset_interface, vehicle_interface


def _interface(resources: str):
    """The interface of the FMU whose resources folder is ``resources``."""
    with open(os.path.join(resources, "lcv_fmu.json"), encoding="utf-8") as f:
        cfg = json.load(f)
    if cfg["mode"] == "presets":
        return preset_interface()
    if cfg.get("model") == "nonlinear":
        from .interface import nonlinear_interface
        return nonlinear_interface(load_vehicle(os.path.join(resources, cfg["vehicle_file"])),
                                   cfg.get("u_start_mps", U_START))
    return vehicle_interface(load_vehicle(os.path.join(resources, cfg["vehicle_file"])),
                             cfg.get("u_start_mps", U_START), cfg.get("model", "yaw_plane"))


def _engine(itf, params: dict):
    """The engine of an interface's model with the parameters ``params``: the linear models' exact
    stepping (:class:`LCVEngine`) or the nonlinear model's integration
    (:class:`~lcvreport.fmu.nonlinear_engine.NonlinearEngine`)."""
    if itf.model == "nonlinear":
        from .nonlinear_engine import NonlinearEngine
        return NonlinearEngine(itf, None, params["tire_scale"], params["u_min"], params.get("crossfall", 0.0),
                               params["friction_coefficient"])
    return LCVEngine(itf, params.get("preset"), params["tire_scale"], params["u_min"],
                     crossfall=params.get("crossfall", 0.0))


def _quietly(method):
    """The FMI call with numpy's floating-point warnings and Python's warnings kept inside the FMU:
    a host's stderr gets no RuntimeWarning naming the FMU's temporary files (what is wrong is the
    call's status and logged message), and the host's own warning settings are left as they were."""
    import functools
    import warnings

    @functools.wraps(method)
    def call(self, *args):
        with warnings.catch_warnings(), np.errstate(all="ignore"):
            warnings.simplefilter("ignore")
            return method(self, *args)
    return call


class SlaveCore:
    """One instance: one vehicle (or the six presets) through the interface table."""

    #: prefix of the FMI function names in messages, and the names that differ from FMI 2's
    FMI_PREFIX = "fmi2"
    FMI_FUNCTIONS: dict = {}

    def _setup(self, resources: str) -> None:
        """Read the interface from ``resources`` and set every field (the adapters' __init__ calls it)."""
        self.itf = _interface(resources)
        self.modelName = self.itf.model_name
        self.description = self.itf.description
        self.params = {v.name: v.start for v in self.itf.parameters}
        self.inputs = np.array([float(v.start) for v in self.itf.inputs])
        self.input_slot = {v.value_reference: k for k, v in enumerate(self.itf.inputs)}
        self.output_slot = {v.value_reference: k for k, v in enumerate(self.itf.outputs)}
        self.engine = None
        self.init_error = None
        self.initialized = False
        # per-call guards once, not per value: the inputs are checked once after they change
        # (``_problem``), every value is computed once per step or change of the inputs and
        # kept as a list indexed by value reference (``_values``)
        self._problem = False                 # False: not checked since the inputs changed
        self._feed_problem = False            # the same for the outputs that feed inputs through (ay)
        self._values = None
        self._stepped = False
        self._input_vrs = np.array([v.value_reference for v in self.itf.inputs], dtype=int)
        self._output_vrs = np.array([v.value_reference for v in self.itf.outputs], dtype=int)
        self._values_speed = None             # the speed _values_V and _values_c are for
        # value references: parameters, then the inputs, then the outputs, each in a block
        n_in, n_out = len(self._input_vrs), len(self._output_vrs)
        first = int(self._input_vrs[0]) if n_in else len(self.itf.variables)
        self._contiguous = (self._input_vrs.tolist() == list(range(first, first + n_in)) and
                            self._output_vrs.tolist() == list(range(first + n_in, first + n_in + n_out)) and
                            first + n_in + n_out == len(self.itf.variables))
        self._first_input = first
        self._bad_vrs = frozenset()
        self._real_vrs = frozenset(v.value_reference for v in self.itf.variables if v.type == "Real")
        self._last_get, self._last_slice, self._out_slice = None, None, None   # the last all-Real GetReal
        self._template = self._parameter_values()

    # ---------------------------------------------------------------- errors
    def _error(self, text):
        """Log ``text`` with the error status (the loader turns the call's status into Error)."""
        raise NotImplementedError

    def _warning(self, text):
        """Log ``text`` with the warning status."""
        raise NotImplementedError

    def _fn(self, name: str) -> str:
        """The FMI function ``name`` (FMI 2 spelling: GetReal, SetInteger, DoStep ...) as this FMI version has it."""
        return self.FMI_FUNCTIONS.get(name, self.FMI_PREFIX + name)

    # ---------------------------------------------------------------- FMI calls
    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        pass

    def enter_initialization_mode(self):
        pass

    @_quietly
    def exit_initialization_mode(self):
        try:
            if self.initialized:
                self._error(f"{self._fn('ExitInitializationMode')} called twice; call {self._fn('Reset')} to start again")
                return
            self.engine = _engine(self.itf, self.params)
            self.init_error = None
            self.initialized = True
            self._values = None
            self._stepped = False
            self._values_speed = None
        except CosimError as exc:
            self.engine = None
            self.init_error = str(exc)
            self._error(f"{exc}; every doStep will be refused")
        except Exception as exc:  # noqa: BLE001
            self.engine = None
            self.init_error = f"initialization failed: {type(exc).__name__}: {exc}"
            self._error(self.init_error)

    @_quietly
    def do_step(self, current_time, step_size):
        try:
            if not math.isfinite(current_time):
                self._error(f"{self._fn('DoStep')}: currentCommunicationPoint is not finite ({current_time!r})")
                return False
            if self.engine is None:
                self._error(self.init_error and f"{self.init_error}; every doStep will be refused"
                            or f"{self._fn('DoStep')} called before initialization completed")
                return False
            if self._problem is False:          # the inputs changed: check them, list them once
                self._problem = self.engine.input_problem(self.inputs)
                self._prefix_inputs = self._prefix + self.inputs.tolist()
            if self._problem is not None:
                raise self._problem
            warning = self.engine.step(float(step_size), self.inputs, checked=True)
            # the values are the parameters, the inputs held and the outputs the step gave: listed
            # when a host asks (a host reading the outputs gets them as one slice)
            self._values = None
            self._stepped = self._contiguous
            self._bad_vrs = frozenset()
            if warning:
                self._warning(warning)
            return True
        except CosimError as exc:
            self._error(str(exc))
            return False
        except Exception as exc:  # noqa: BLE001
            self._error(f"doStep failed: {type(exc).__name__}: {exc}; the state is unchanged")
            return False

    def terminate(self):
        pass

    # ---------------------------------------------------------------- values
    def _parameter_values(self) -> np.ndarray:
        """Every variable's slot, the Real parameters filled in (the rest filled per call);
        also ``_prefix``, the slots before the first input as a list."""
        values = np.zeros(len(self.itf.variables))
        for v in self.itf.variables:
            if v.causality == "parameter" and v.type == "Real":
                values[v.value_reference] = float(self.params[v.name])
        first = getattr(self, "_first_input", len(values))
        self._prefix = values[:first].tolist()
        return values

    @_quietly
    def get_real(self, vrs):
        try:
            same = type(vrs) is list and vrs == self._last_get   # (a list: an array would compare elementwise)
            if same and self._stepped and self._out_slice is not None:
                return self.engine.stepped_outputs[self._out_slice].tolist()     # outputs only, after a step
            values = self._values if self._values is not None else self._current_values()
            if same:                            # the host asks for what it asked for last time
                if self._bad_vrs and not self._bad_vrs.isdisjoint(vrs):
                    self._error(self.engine.output_error or "an output is not finite")
                return values[self._last_slice] if self._last_slice is not None else [values[vr] for vr in vrs]
            if self._real_vrs.issuperset(vrs):
                self._remember_get(vrs)
                if self._bad_vrs and not self._bad_vrs.isdisjoint(vrs):
                    self._error(self.engine.output_error or "an output is not finite")
                return [values[vr] for vr in vrs]
            for vr in vrs:
                if vr not in self._real_vrs:
                    self._error(f"{self._fn('GetReal')}: {vr} is not the value reference of a Real variable")
            return [values[vr] if vr in self._real_vrs else 0.0 for vr in vrs]
        except Exception as exc:  # noqa: BLE001
            self._error(f"{self._fn('GetReal')} failed: {type(exc).__name__}: {exc}")
            return [0.0] * len(vrs)

    def _remember_get(self, vrs) -> None:
        """Keep ``vrs`` (all Real) for the next call, with the slice of the values they are when
        they are consecutive (a host reading every output reads one slice)."""
        vrs = list(vrs)
        n = len(vrs)
        self._last_get = vrs
        consecutive = bool(n) and vrs == list(range(vrs[0], vrs[0] + n))
        self._last_slice = slice(vrs[0], vrs[0] + n) if consecutive else None
        first = int(self._output_vrs[0]) if len(self._output_vrs) else -1
        self._out_slice = (slice(vrs[0] - first, vrs[0] - first + n)
                           if consecutive and self._contiguous and first <= vrs[0] and vrs[-1] < first + len(
                               self._output_vrs) else None)

    def _current_values(self) -> list:
        """Every Real value by value reference: after a step the parameters, the inputs and the
        stepped outputs; else :meth:`_all_values`."""
        if self._stepped:
            self._values = self._prefix_inputs + self.engine.stepped_outputs.tolist()
            return self._values
        return self._all_values()

    def _all_values(self) -> list:
        """Every Real value by value reference (0.0 for non-finite outputs, whose value
        references go to ``_bad_vrs``); computed once per step or change of the inputs:
        one product ``V [z, w] + c`` (+ the rear-end offsets' sines) with ``V`` and ``c``
        kept per speed."""
        e = self.engine
        if e is not None and not e.linear:      # an integrated model: its outputs, not output matrices
            return self._all_values_checked()
        if e is not None and self._feed_problem is False:
            self._feed_problem = e.input_problem(self.inputs, speed=False)
        if e is None or self._feed_problem is not None:
            return self._all_values_checked()
        u = e.output_speed(self.inputs)
        if u != self._values_speed:
            O = e.output_matrix(u)
            V = np.zeros((len(self.itf.variables), O.shape[1]))
            V[self._input_vrs, e.m + np.arange(len(self._input_vrs))] = 1.0
            V[self._output_vrs] = O
            const = self._template.copy()
            if e.eig_output >= 0:
                const[self._output_vrs[e.eig_output]] = e.max_real_eig(u)
            self._values_speed, self._values_V, self._values_c = u, V, const
        values = self._values_V @ e.stacked(self.inputs) + self._values_c
        if e.has_y:
            values[self._output_vrs] += e.rear_offsets()
        if not math.isfinite(values.sum()):     # finite exactly when every value is (see the engine)
            return self._all_values_checked()
        self._bad_vrs = frozenset()
        self._values = values.tolist()
        return self._values

    def _all_values_checked(self) -> list:
        """:meth:`_all_values` value by value: before initialization, with an invalid
        input, or when a value is not finite."""
        values = self._template.copy()
        values[self._input_vrs] = self.inputs
        bad = ()
        if self.engine is not None:
            out = self.engine.outputs(self.inputs, self._feed_problem)
            finite = np.isfinite(out)
            if not finite.all():
                bad = self._output_vrs[~finite].tolist()
                out = np.where(finite, out, 0.0)
            values[self._output_vrs] = out
        self._bad_vrs = frozenset(bad)
        self._values = values.tolist()
        return self._values

    def set_real(self, vrs, values):
        try:
            for vr, value in zip(vrs, values):
                if vr in self.input_slot:
                    self.inputs[self.input_slot[vr]] = float(value)
                elif 0 <= vr < len(self.itf.variables) and self.itf.variables[vr].causality == "parameter" \
                        and self.itf.variables[vr].type == "Real":
                    self._set_parameter(self.itf.variables[vr].name, float(value))
                else:
                    self._error(f"{self._fn('SetReal')}: {vr} is not the value reference of an input or a Real parameter")
        except Exception as exc:  # noqa: BLE001
            self._error(f"{self._fn('SetReal')} failed: {type(exc).__name__}: {exc}")
        finally:
            self._problem = self._feed_problem = False
            self._values = None
            self._stepped = False

    def _set_parameter(self, name: str, value) -> None:
        """A fixed parameter takes a value before initialization ends, never after."""
        if self.initialized or self.init_error is not None:
            self._error(f"{name} is a fixed parameter: it cannot change after initialization")
        else:
            self.params[name] = value
            self._problem = False                  # the values' prefix is listed again
            self._values = None
            self._stepped = False
            self._values_speed = None
            self._template = self._parameter_values()

    def _enumeration(self, vr):
        """The Enumeration variable of value reference ``vr`` (``preset``), or None."""
        if isinstance(vr, int) and 0 <= vr < len(self.itf.variables) and \
                self.itf.variables[vr].type == "Enumeration":
            return self.itf.variables[vr]
        return None

    def get_string(self, vrs):
        out = [""] * len(vrs)
        for i, vr in enumerate(vrs):
            var = self._enumeration(vr)
            if var is not None:
                out[i] = str(self.params[var.name])
            else:
                self._error(f"{self._fn('GetString')}: {vr} is not the value reference of preset (the Enumeration, also by "
                            "name)")
        return out

    def set_string(self, vrs, values):
        try:
            for vr, value in zip(vrs, values):
                var = self._enumeration(vr)
                if var is not None:
                    self._set_parameter(var.name, str(value))
                else:
                    self._error(f"{self._fn('SetString')}: {vr} is not the value reference of preset (the Enumeration, also "
                                "by name)")
        except Exception as exc:  # noqa: BLE001
            self._error(f"{self._fn('SetString')} failed: {type(exc).__name__}: {exc}")

    def get_integer(self, vrs):
        out = [0] * len(vrs)
        for i, vr in enumerate(vrs):
            var = self._enumeration(vr)
            if var is None:
                self._error(f"{self._fn('GetInteger')}: {vr} is not the value reference of an Enumeration variable")
            else:   # 0: a name set through SetString that is no preset
                name = self.params[var.name]
                out[i] = var.items.index(name) + 1 if name in var.items else 0
        return out

    def set_integer(self, vrs, values):
        try:
            for vr, value in zip(vrs, values):
                var = self._enumeration(vr)
                if var is None:
                    self._error(f"{self._fn('SetInteger')}: {vr} is not the value reference of an Enumeration variable")
                elif not 1 <= int(value) <= len(var.items):
                    self._error(f"{self._fn('SetInteger')}: {var.name}: {int(value)} is not a {var.name}; valid: 1 to "
                                f"{len(var.items)} ({', '.join(var.items)})")
                else:
                    self._set_parameter(var.name, var.items[int(value) - 1])
        except Exception as exc:  # noqa: BLE001
            self._error(f"{self._fn('SetInteger')} failed: {type(exc).__name__}: {exc}")

    def get_boolean(self, vrs):
        if len(vrs):
            self._error(f"{self._fn('GetBoolean')}: this FMU has no Boolean variables")
        return [False] * len(vrs)

    def set_boolean(self, vrs, values):
        if len(vrs):
            self._error(f"{self._fn('SetBoolean')}: this FMU has no Boolean variables")

    # ---------------------------------------------------------------- FMU state
    def _get_fmu_state(self):
        try:
            return {"model": self.itf.model_name, "params": dict(self.params), "inputs": self.inputs.tolist(),
                    "initialized": self.initialized, "init_error": self.init_error,
                    "engine": None if self.engine is None else self.engine.get_state()}
        except Exception as exc:  # noqa: BLE001
            self._error(f"{self._fn('GetFMUstate')} failed: {type(exc).__name__}: {exc}")
            return {"invalid": str(exc)}

    def _set_fmu_state(self, state):
        try:
            if not isinstance(state, dict) or "invalid" in state or state.get("model") != self.itf.model_name:
                reason = state.get("invalid") if isinstance(state, dict) and "invalid" in state else \
                    "it was not written by this FMU"
                self._error(f"{self._fn('SetFMUstate')}: the FMU state is refused: {reason}; the instance is unchanged")
                return
            inputs = [float(x) for x in state["inputs"]]
            if len(inputs) != len(self.inputs):
                self._error(f"{self._fn('SetFMUstate')}: the FMU state does not fit this FMU; the instance is unchanged")
                return
            params = dict(state["params"])
            engine = None
            if state["engine"] is not None:
                engine = self.engine
                if engine is None or (engine.preset, engine.tire_scale, engine.u_min, engine.crossfall,
                                      getattr(engine, "friction_coefficient", None)) != \
                        (params.get("preset"), params["tire_scale"], params["u_min"], params.get("crossfall", 0.0),
                         params.get("friction_coefficient")):
                    engine = _engine(self.itf, params)
                engine.set_state(state["engine"])
            self.params, self.inputs, self.engine = params, np.array(inputs, dtype=float), engine
            self._problem = self._feed_problem = False
            self._values = None
            self._stepped = False
            self._values_speed = None
            self._template = self._parameter_values()
            self.initialized, self.init_error = bool(state["initialized"]), state["init_error"]
        except CosimError as exc:
            self._error(f"{self._fn('SetFMUstate')}: {exc}; the instance is unchanged")
        except Exception as exc:  # noqa: BLE001
            self._error(f"{self._fn('SetFMUstate')}: the FMU state is refused ({type(exc).__name__}: {exc}); "
                        "the instance is unchanged")

    @staticmethod
    def _fmu_state_to_bytes(state):
        try:
            return state_to_bytes(state)
        except Exception as exc:  # noqa: BLE001
            return state_to_bytes({"invalid": f"{type(exc).__name__}: {exc}"})

    @staticmethod
    def _fmu_state_from_bytes(data):
        try:
            return state_from_bytes(data)
        except Exception as exc:  # noqa: BLE001
            return {"invalid": f"the serialized FMU state cannot be read ({type(exc).__name__}: {exc})"}
