"""Vehicle and driver in a closed loop (issue 20, SPEC section 15): the driver FMU built from
this repository's sources, with working start values; Model Exchange of both FMUs solved
by one integrator equals the package's continuous closed loop; Co-Simulation approaches it
at first order in the communication step (the coupling error of a Jacobi master)."""
from __future__ import annotations

import ctypes
import subprocess
import sys

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Model, FMU2Slave

from lcvreport.manoeuvres.drivers import DEFAULT, PreviewDriver
from lcvreport.analysis.closed_loop import closed_loop
from lcvreport.fmu.driver import build_driver_fmu
from lcvreport.fmu.interface import preset_value
from lcvreport.model.presets import load_preset

from conftest import TOOLS
from fmu_support import host_env

PRESET, U, T_END = "tractor_semitrailer", 24.0, 8.0


@pytest.fixture(scope="module")
def driver_fmu(tmp_path_factory):
    return build_driver_fmu(tmp_path_factory.mktemp("driver"))


def _open(fmu, cls, kind):
    md = read_model_description(str(fmu))
    ident = (md.modelExchange if kind == "me" else md.coSimulation).modelIdentifier
    m = cls(guid=md.guid, unzipDirectory=extract(str(fmu)), modelIdentifier=ident, instanceName=fmu.stem)
    m.instantiate()
    return m, {v.name: v.valueReference for v in md.modelVariables}, md


def test_the_driver_fmu_has_working_start_values(driver_fmu, tmp_path):
    """Nothing set: the driver's own start values make a lane change (fmuCheck: 0 warnings)."""
    md = read_model_description(str(driver_fmu))
    starts = {v.name: float(v.start) for v in md.modelVariables if v.causality == "parameter"}
    assert starts == {"gain_rad_per_m": DEFAULT.gain_rad_per_m, "preview_m": DEFAULT.preview_m,
                      "target_offset_m": DEFAULT.target_offset_m, "start_s": DEFAULT.start_s,
                      "duration_s": DEFAULT.duration_s}
    m, vr, _ = _open(driver_fmu, FMU2Slave, "cs")
    m.setupExperiment(startTime=0.0)
    m.enterInitializationMode()
    m.exitInitializationMode()
    for k in range(500):                             # past the end of the lane change (4 s)
        m.doStep(0.01 * k, 0.01)
    assert m.getReal([vr["delta"]])[0] == pytest.approx(DEFAULT.gain_rad_per_m * DEFAULT.target_offset_m, rel=1e-15)
    m.terminate()
    m.freeInstance()
    p = subprocess.run([str(TOOLS / "fmuCheck.linux64"), "-h", "0.01", "-s", "5", "-t", str(tmp_path),
                        str(driver_fmu)], capture_output=True, text=True, env=host_env(), timeout=120)
    assert p.returncode == 0 and "0 Warning(s)" in p.stdout + p.stderr and "0 Error(s)" in p.stdout + p.stderr


def _init(m, vr, preset=True):
    if preset:
        m.setInteger([vr["preset"]], [preset_value(PRESET)])
    m.setupExperiment(startTime=0.0)
    m.enterInitializationMode()
    m.exitInitializationMode()


def test_model_exchange_closed_loop_is_the_packages(native_fmu, driver_fmu):
    from scipy.integrate import solve_ivp
    veh, vv, md = _open(native_fmu, FMU2Model, "me")
    drv, dv, _ = _open(driver_fmu, FMU2Model, "me")
    _init(veh, vv)
    _init(drv, dv, preset=False)
    for m in (veh, drv):
        m.newDiscreteStates()
        m.enterContinuousTimeMode()
    veh.setReal([vv["u"]], [U])
    nx = md.numberOfContinuousStates
    x_c, dx_c = (ctypes.c_double * nx)(), (ctypes.c_double * nx)()

    def rhs(t, x):
        veh.setTime(t)
        drv.setTime(t)
        x_c[:] = list(x)
        veh.setContinuousStates(x_c, nx)
        Y1, psi1 = veh.getReal([vv["Y1"], vv["psi1"]])
        drv.setReal([dv["Y1"], dv["psi1"]], [Y1, psi1])
        veh.setReal([vv["delta"]], drv.getReal([dv["delta"]]))
        veh.getDerivatives(dx_c, nx)
        return np.array(dx_c[:])

    t_eval = np.arange(0.0, T_END + 1e-9, 0.1)
    breaks = [0.0, DEFAULT.start_s, DEFAULT.start_s + DEFAULT.duration_s, T_END]
    ys, x = [], np.zeros(nx)
    for lo, hi in zip(breaks[:-1], breaks[1:]):
        sel = t_eval[(t_eval >= lo) & (t_eval < hi)] if hi < T_END else t_eval[t_eval >= lo]
        sol = solve_ivp(rhs, (lo, hi), x, method="DOP853", rtol=1e-11, atol=1e-13, t_eval=sel, dense_output=True)
        ys.append(sol.y.T)
        x = sol.sol(hi)
    got = np.concatenate(ys)
    ref = closed_loop(load_preset(PRESET), U, DEFAULT, T_END, 0.1)
    order = ["v1", "r1", "r2", "thetaA", "psi1", "Y1"]
    ders = [v for v in md.modelVariables if v.name.startswith("der(")]
    state_of = [d.derivative.name for d in ders]
    cols = [state_of.index(n) for n in order]
    err = np.abs(got[:, cols] - ref.states).max(axis=0) / np.maximum(np.abs(ref.states).max(axis=0), 1e-12)
    assert err.max() <= 1e-6, dict(zip(order, err))
    assert ref.Y1_m[-1] > 1.0                                    # a real lane change happened


def _cosim(native_fmu, driver_fmu, h):
    veh, vv, _ = _open(native_fmu, FMU2Slave, "cs")
    drv, dv, _ = _open(driver_fmu, FMU2Slave, "cs")
    _init(veh, vv)
    _init(drv, dv, preset=False)
    veh.setReal([vv["u"]], [U])
    n = int(round(T_END / h))
    Y = np.empty(n + 1)
    Y[0] = 0.0
    for k in range(n):                              # Jacobi: exchange, then both step
        Y1, psi1 = veh.getReal([vv["Y1"], vv["psi1"]])
        drv.setReal([dv["Y1"], dv["psi1"]], [Y1, psi1])
        veh.setReal([vv["delta"]], drv.getReal([dv["delta"]]))
        veh.doStep(k * h, h)
        drv.doStep(k * h, h)
        Y[k + 1] = veh.getReal([vv["Y1"]])[0]
    for m in (veh, drv):
        m.terminate()
        m.freeInstance()
    return Y


def test_co_simulation_shows_its_first_order_coupling_error(native_fmu, driver_fmu):
    ref = closed_loop(load_preset(PRESET), U, DEFAULT, T_END, 0.1)
    errs = []
    for h in (0.05, 0.025, 0.0125):
        Y = _cosim(native_fmu, driver_fmu, h)[:: int(round(0.1 / h))]
        errs.append(np.abs(Y - ref.Y1_m).max())
    assert errs[0] > 1e-4                           # visible at 0.05 s
    for a, b in zip(errs, errs[1:]):
        assert 1.7 <= a / b <= 2.3, errs            # first order in the step
