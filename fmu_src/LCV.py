"""FMI 2.0 co-simulation slave of the linear LCV yaw-plane model (SPEC section 5).

A thin layer: FMI variables are mapped onto :class:`lcvreport.cosim.LCVEngine`,
which does every computation (exact zero-order-hold stepping in SI units).
Built by ``./build.sh fmu`` into ``build/LCV.fmu``.
"""
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, String
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from fmi_xml import UnitReal, finish_model_description
from lcvreport.cosim import INPUTS, OUTPUTS, CosimError, LCVEngine, PARAMETERS


class LCV(Fmi2Slave):
    author = "lcvreport"
    description = ("Linear yaw-plane model of a long combination vehicle (tractor, semitrailers, converter "
                   "dollies) with residual tire forces (conicity, ply steer); Patterson (2011). Exact "
                   "zero-order-hold stepping for any communication step size.")
    version = "0.1.0"
    license = "MIT"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=0.001)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.modelName = "LCV"
        self.preset = PARAMETERS[0].start
        self.tire_scale = PARAMETERS[1].start
        self.u_min = PARAMETERS[2].start
        self._in = [v.start for v in INPUTS]
        self._out = [v.start for v in OUTPUTS]
        self.engine = None

        p_kw = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed)
        self.register_variable(String("preset", description=PARAMETERS[0].description, **p_kw))
        for v in PARAMETERS[1:]:
            self.register_variable(UnitReal(v.name, unit=v.unit, description=v.description, **p_kw))
        for i, v in enumerate(INPUTS):
            self.register_variable(UnitReal(
                v.name, unit=v.unit, description=v.description, causality=Fmi2Causality.input,
                variability=Fmi2Variability.continuous, getter=lambda i=i: self._in[i],
                setter=lambda x, i=i: self._in.__setitem__(i, x)))
        for i, v in enumerate(OUTPUTS):
            getter = (lambda: self._max_real_eig()) if v.name == "max_real_eig" else (lambda i=i: self._out[i])
            self.register_variable(UnitReal(
                v.name, unit=v.unit, description=v.description, causality=Fmi2Causality.output,
                variability=Fmi2Variability.continuous, initial=Fmi2Initial.calculated, getter=getter))

    # ---------------------------------------------------------------- FMI calls
    # Never raise out of a callback: pythonfmu 0.7.0 turns an exception into fmi2Fatal
    # after releasing the Python instance, which it releases again in fmi2FreeInstance
    # (a use-after-free that crashes the host at the next garbage collection).  Errors
    # are logged with fmi2Error and reported by fmi2DoStep's status instead.
    def exit_initialization_mode(self):
        self._init_error = None
        try:
            self.engine = LCVEngine(self.preset, self.tire_scale, self.u_min)
        except CosimError as exc:
            self.engine = None
            self._init_error = str(exc)
            self.log(f"{exc}; every doStep will be refused", Fmi2Status.error)
            return
        self._out = self.engine.outputs(self._in[0])

    def do_step(self, current_time, step_size):
        if self.engine is None:
            self.log(getattr(self, "_init_error", None) or "doStep called before initialization completed",
                     Fmi2Status.error)
            return False
        try:
            warning = self.engine.step(step_size, self._in)
        except CosimError as exc:
            self.log(str(exc), Fmi2Status.error)
            return False
        if warning:
            self.log(warning, Fmi2Status.warning)
        self._out = self.engine.outputs()
        return True

    def _max_real_eig(self):
        return 0.0 if self.engine is None else self.engine.max_real_eig_at_input(self._in[0])

    # ---------------------------------------------------------------- FMU state
    def _get_fmu_state(self):
        return {"preset": self.preset, "tire_scale": self.tire_scale, "u_min": self.u_min,
                "inputs": list(self._in), "outputs": list(self._out),
                "engine": None if self.engine is None else self.engine.get_state()}

    def _set_fmu_state(self, state):
        self.preset, self.tire_scale, self.u_min = state["preset"], state["tire_scale"], state["u_min"]
        self._in = list(state["inputs"])
        self._out = list(state["outputs"])
        if state["engine"] is None:
            self.engine = None
        else:
            if self.engine is None or (self.engine.preset, self.engine.tire_scale, self.engine.u_min) != \
                    (self.preset, self.tire_scale, self.u_min):
                self.engine = LCVEngine(self.preset, self.tire_scale, self.u_min)
            self.engine.set_state(state["engine"])

    # ---------------------------------------------------------------- XML
    def to_xml(self, model_options=dict()):
        root = super().to_xml(model_options)
        variables = list(self.vars.values())
        feedthrough = {"max_real_eig": ["u"]}
        at_init = {"max_real_eig": ["u", "preset", "tire_scale", "u_min"]}
        return finish_model_description(root, variables, feedthrough, at_init)
