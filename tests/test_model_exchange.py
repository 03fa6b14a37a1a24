"""Model Exchange of the native FMUs (issue 20, SPEC section 15): the same binary as the
co-simulation one, integrated by the importer.  Against the package's exact response:
CVode at rtol 1e-10, fmpy's Euler converging at first order, Reference-FMUs' fmusim; the
state machine and hostile calls of the new entry points."""
from __future__ import annotations

import csv
import math
import subprocess
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi2 import FMU2Model
from fmpy.fmi3 import FMU3Model

from conftest import TOOLS
from fmu_support import LogCapture, host_env, interface_of
from helpers import group_error, reference_outputs
from lcvreport.fmu.interface import preset_value

FMUSIM = TOOLS / "fmusim"
H = 0.05
N = 60


def _case(itf):
    p = [v.name for v in itf.inputs if v.source[0] == "P"][-1]
    t = [v.name for v in itf.inputs if v.source[0] == "T"][0]
    return {"u": 24.0, "delta": 0.01, p: 200.0, t: -50.0}


@pytest.fixture(scope="module", params=["LCVNative"] + [f"{n}:native" for n in ("western_double", "b_double",
                                                                                   "truck_full_trailer")])
def native(request, native_fmu, all_example_fmus):
    if request.param == "LCVNative":
        return native_fmu, "aucnat"
    return all_example_fmus[request.param.split(":")[0]]["native"], None


def _names(itf):
    """The outputs up to Y_rear, in interface order (the columns of helpers.reference_outputs)."""
    outs = [v.name for v in itf.outputs]
    return outs[:outs.index("Y_rear") + 1]


def _run(fmu, preset, inputs, **kw):
    itf = interface_of(fmu)
    names = _names(itf)
    start = dict(inputs, **({"preset": preset_value(preset)} if preset else {}))
    res = simulate_fmu(str(fmu), fmi_type="ModelExchange", stop_time=N * H, start_values=start, output=names, **kw)
    return itf, names, res


def _reference(itf, preset, inputs):
    return reference_outputs(itf, [(H, inputs)] + [(H, {})] * (N - 1), preset)


def test_cvode_at_rtol_1e_10_is_the_exact_response(native):
    """A step of steer, a residual force and moment from rest: every output within 1e-6 of its
    group's peak (CVode's global error at rtol 1e-10; the co-simulation reaches 10 kappa eps)."""
    fmu, preset = native
    itf = interface_of(fmu)
    inputs = _case(itf)
    itf, names, res = _run(fmu, preset, inputs, solver="CVode", relative_tolerance=1e-10, output_interval=H)
    got = np.array([[res[n][k] for n in names] for k in range(1, N + 1)])
    err, name = group_error(got, _reference(itf, preset, inputs), itf)
    assert err <= 1e-6, (fmu.name, name, err)


def test_euler_converges_at_first_order(native_fmu):
    """fmpy's explicit Euler: the error halves with the step (first order), toward the exact response."""
    itf = interface_of(native_fmu)
    inputs = _case(itf)
    ref = _reference(itf, "aucnat", inputs)
    errs = []
    for h in (1e-3, 5e-4, 2.5e-4):
        _itf, names, res = _run(native_fmu, "aucnat", inputs, solver="Euler", step_size=h, output_interval=h)
        idx = [int(round(H * k / h)) for k in range(1, N + 1)]
        got = np.array([[res[n][i] for n in names] for i in idx])
        errs.append(group_error(got, ref, itf)[0])
    assert errs[2] <= 3e-3
    for a, b in zip(errs, errs[1:]):
        assert 1.8 <= a / b <= 2.2, errs


def test_fmusim_model_exchange_with_no_ld_preload(native, tmp_path):
    fmu, preset = native
    itf = interface_of(fmu)
    inputs = _case(itf)
    with open(tmp_path / "in.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["time", *inputs])
        for t in (0.0, N * H):
            w.writerow([t, *inputs.values()])
    args = [str(FMUSIM), "--interface-type", "me", "--solver", "cvode", "--tolerance", "1e-10", "--stop-time", str(N * H),
            "--output-interval", str(H), "--input-file", str(tmp_path / "in.csv"), "--output-file",
            str(tmp_path / "out.csv")]
    if preset:
        args += ["--start-value", "preset", str(preset_value(preset))]
    p = subprocess.run(args + [str(fmu)], capture_output=True, text=True, env=host_env(), timeout=300)
    assert p.returncode == 0, (p.stdout + p.stderr)[-3000:]
    with open(tmp_path / "out.csv") as f:
        rows = list(csv.DictReader(f))
    names = _names(itf)
    got = np.array([[float(r[n]) for n in names] for r in rows[1:N + 1]])
    err, name = group_error(got, _reference(itf, preset, inputs), itf)
    assert err <= 1e-6, (name, err)               # fmusim's CVODE at rtol 1e-10, as fmpy's above


class _ME:
    """An FMU2Model instance with a log capture."""

    def __init__(self, fmu, logging=True):
        md = read_model_description(str(fmu))
        self.md = md
        self.log = LogCapture()
        self.m = FMU2Model(guid=md.guid, unzipDirectory=extract(str(fmu)),
                           modelIdentifier=md.modelExchange.modelIdentifier, instanceName="me")
        self.m.instantiate(callbacks=self.log.callbacks, loggingOn=logging)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.nx = md.numberOfContinuousStates

    def init(self):
        self.m.setupExperiment(startTime=0.0)
        self.m.enterInitializationMode()
        self.m.exitInitializationMode()
        self.m.newDiscreteStates()
        self.m.enterContinuousTimeMode()
        return self


def _status(f, *args):
    try:
        f(*args)
        return 0
    except Exception as exc:  # noqa: BLE001 (fmpy raises for statuses above warning)
        return int(getattr(exc, "status", 99))


@pytest.mark.parametrize("logging", [True, False])
def test_hostile_model_exchange_calls_are_errors_with_a_message(native_fmu, logging):
    from ctypes import c_double
    me = _ME(native_fmu, logging).init()
    m, nx = me.m, me.nx
    assert nx == 14                                                  # v1, r1..r6, thetaA..E, psi1, Y1
    x = (c_double * nx)()
    dx = (c_double * nx)()
    assert _status(m.getDerivatives, dx, nx) == 0
    assert _status(m.fmi2SetContinuousStates, m.component, x, nx - 1) == 3
    x[3] = math.nan
    assert _status(m.fmi2SetContinuousStates, m.component, x, nx) == 3
    m.setReal([me.vr["delta"]], [5.0])                             # outside [-1, 1] rad: refused where used
    assert _status(m.getDerivatives, dx, nx) == 3
    m.setReal([me.vr["delta"]], [0.0])
    import ctypes
    do_step = m.dll.fmi2DoStep
    do_step.argtypes, do_step.restype = [ctypes.c_void_p, c_double, c_double, ctypes.c_int], ctypes.c_int
    assert do_step(m.component, 0.0, 0.1, 1) == 3                  # a co-simulation call on a ME instance
    indicators = m.dll.fmi2GetEventIndicators
    indicators.argtypes, indicators.restype = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t], ctypes.c_int
    assert indicators(m.component, ctypes.cast(dx, ctypes.c_void_p), 1) == 3
    m.setReal([me.vr["u"]], [1e3])                                 # above 70 m/s: refused by the derivatives
    assert _status(m.getDerivatives, dx, nx) == 3
    messages = me.log.messages(3)
    for fragment in ("states given, this FMU has 14", "is not finite", "delta", "must not be called in phase",
                     "no event indicators", "above 70"):
        assert any(fragment in msg for msg in messages), (fragment, messages)
    m.terminate()
    m.freeInstance()


def test_derivative_variables_are_the_derivatives(native_fmu):
    me = _ME(native_fmu).init()
    m = me.m
    m.setReal([me.vr["delta"], me.vr["P61"]], [0.02, 500.0])
    from ctypes import c_double
    x = (c_double * me.nx)(*np.linspace(0.01, 0.14, me.nx))
    m.setContinuousStates(x, me.nx)
    dx = (c_double * me.nx)()
    m.getDerivatives(dx, me.nx)
    der_vr = [me.vr[f"der({v.name})"] for v in interface_of(native_fmu).continuous_states]
    assert np.array_equal(np.array(m.getReal(der_vr)), np.array(dx[:]))
    back = (c_double * me.nx)()
    m.getContinuousStates(back, me.nx)
    assert back[:] == x[:]
    assert np.any(np.array(dx[:]) != 0)
    m.terminate()
    m.freeInstance()


@pytest.mark.parametrize("which", ["fmi2", "fmi3"])
def test_directional_derivatives_are_the_models_matrices(native_fmu, which):
    """Unit seeds on every state and on delta and one force: the Jacobian of der(x) equals the
    package's A_aug and G Bw (scipy-free numpy, lcvreport.analysis.discretize) to 1e-12 of
    their size; outputs' directional derivatives equal central differences of the outputs."""
    import ctypes
    from lcvreport.analysis.discretize import augmented_state_matrix
    from lcvreport.fmu.engine import LCVEngine
    from lcvreport.fmu.interface import preset_interface
    from lcvreport.model.presets import load_preset
    itf = preset_interface()
    vr = {v.name: v.value_reference for v in itf.variables}
    states = itf.continuous_states
    der = [len(itf.variables) + k for k in range(len(states))]
    preset, u = "tractor_semitrailer", 20.0
    v = load_preset(preset)
    eng = LCVEngine(itf, preset)
    A, G = augmented_state_matrix(eng.co, u)
    Bw = eng.maps()["Bw"]
    names = [sv.name for sv in states]
    z_of = {sv.name: itf.state_index(sv, v) for sv in states}
    if which == "fmi2":
        me = _ME(native_fmu)
        m = me.m
        m.setInteger([vr["preset"]], [preset_value(preset)])
        me.init()
        m.setReal([vr["u"]], [u])
        dd = m.dll.fmi2GetDirectionalDerivative
        dd.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t,
                       ctypes.c_void_p, ctypes.c_void_p]
        dd.restype = ctypes.c_int

        def directional(unknowns, knowns, seed):
            out = (ctypes.c_double * len(unknowns))()
            status = dd(m.component, (ctypes.c_uint * len(unknowns))(*unknowns), len(unknowns),
                        (ctypes.c_uint * len(knowns))(*knowns), len(knowns), (ctypes.c_double * len(seed))(*seed), out)
            return status, np.array(out[:])
    else:
        from lcvreport.fmu.build import build_native_fmu3
        import tempfile
        fmu3 = build_native_fmu3(itf, Path(tempfile.mkdtemp()), "LCVNative3")
        md = read_model_description(str(fmu3))
        m = FMU3Model(guid=md.guid, unzipDirectory=extract(str(fmu3)), modelIdentifier="LCVNative3",
                      instanceName="dd3")
        m.instantiate()
        m.setInt64([vr["preset"]], [preset_value(preset)])
        m.enterInitializationMode()
        m.exitInitializationMode()
        m.setFloat64([vr["u"]], [u])
        dd = m.dll.fmi3GetDirectionalDerivative
        dd.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t,
                       ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t]
        dd.restype = ctypes.c_int

        def directional(unknowns, knowns, seed):
            out = (ctypes.c_double * len(unknowns))()
            status = dd(m.component, (ctypes.c_uint * len(unknowns))(*unknowns), len(unknowns),
                        (ctypes.c_uint * len(knowns))(*knowns), len(knowns), (ctypes.c_double * len(seed))(*seed),
                        len(seed), out, len(unknowns))
            return status, np.array(out[:])
    present = [k for k, n in enumerate(names) if z_of[n] >= 0]
    for k in present:                                     # d der(x) / d x_k
        status, col = directional(der, [states[k].value_reference], [1.0])
        assert status == 0
        expect = np.array([A[z_of[n], z_of[names[k]]] if z_of[n] >= 0 else 0.0 for n in names])
        assert np.max(np.abs(col - expect)) <= 1e-12 * max(np.abs(A).max(), 1.0), names[k]
    for name in ("delta", "P21", "T21"):                   # d der(x) / d input
        status, col = directional(der, [vr[name]], [1.0])
        assert status == 0
        j = [w.name for w in itf.inputs].index(name)
        gb = G @ Bw[:, j]
        expect = np.array([gb[z_of[n]] if z_of[n] >= 0 else 0.0 for n in names])
        assert np.max(np.abs(col - expect)) <= 1e-12 * max(np.abs(gb).max(), 1.0), name
    status, _ = directional(der, [vr["u"]], [1.0])      # nonlinear in u: refused
    assert status == 3
    status, _ = directional([vr["max_real_eig"]], [states[0].value_reference], [1.0])
    assert status == 3
    if which == "fmi3":
        m.terminate()
        m.freeInstance()
