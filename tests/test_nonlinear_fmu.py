"""The Python FMU of the nonlinear planar model (issue 42 item 5, SPEC 18): ``lcv fmu --model
nonlinear``.  Every output after every step of a schedule (speed with clamping, steer, residual
forces, moments and misalignments changing, uneven steps, a crossfall, tire scale 0.9, mu 0.6)
against an independent stepping of the model's equations -- scipy's explicit DOP853 at rtol 1e-12
over each held step, chained by the state, the outputs from the model's ``outputs`` -- where the
FMU integrates by Radau at rtol 1e-8; fmpy validate and the FMI Compliance Checker; bad input
refused in one line."""
from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lcvreport.fmu.build import build_vehicle_fmus
from lcvreport.fmu.interface import vehicle_interface
from lcvreport.model.nonlinear.model import nonlinear_model
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLES, TOOLS
from fmu_support import Slave, run_schedule

pytestmark = pytest.mark.xdist_group("nonlinear_fmu")

TIRE_SCALE, CROSSFALL, MU, U_MIN = 0.9, 2.0, 0.6, 2.2352


@pytest.fixture(scope="module")
def fmu(tmp_path_factory) -> Path:
    v = load_vehicle(EXAMPLES / "b_double.toml")
    (path,) = build_vehicle_fmus(v, tmp_path_factory.mktemp("nl"), kind="python", model="nonlinear")
    return path


def _schedule(itf, seed: int):
    rng = np.random.default_rng(seed)
    axles = [v.name[2:] for v in itf.inputs if v.name.startswith("P_")]
    steps = []
    for k in range(24):
        inputs = {}
        if k in (0, 6, 12, 18):
            inputs["u"] = float(rng.choice([22.352, 13.4112, 1.0]) if k else 22.352)    # 1.0: clamped to u_min
            inputs["delta"] = float(rng.normal(0, 0.02))                               # up to ~0.04 rad: past linear
            for a in axles:
                inputs[f"P_{a}"] = float(rng.normal(0, 500.0))
                inputs[f"T_{a}"] = float(rng.normal(0, 300.0))
                inputs[f"eps_{a}"] = float(rng.normal(0, 1e-3))
        steps.append((float(rng.choice([0.01, 0.05, 0.2])), inputs))
    return steps


def _reference(itf, steps) -> np.ndarray:
    """Every output after every step: DOP853 (explicit, rtol 1e-12) over each held step."""
    v = itf.vehicles[0]
    m = nonlinear_model(v, "saturating", MU)
    names = [x.name for x in itf.inputs]
    w = np.array([float(x.start) for x in itf.inputs])
    a_c = 9.80665 * math.sin(math.atan(CROSSFALL / 100.0))
    x = np.zeros(m.n_states)
    keys = [o.source[1] for o in itf.outputs]
    rows = []
    for h, inputs in steps:
        for k, val in inputs.items():
            w[names.index(k)] = val
        u = max(w[0], U_MIN)
        wm = np.concatenate([w[1:], [a_c]])
        sol = solve_ivp(lambda t, z: m.derivatives(t, z, wm, u, TIRE_SCALE), (0.0, h), x, method="DOP853",
                        rtol=1e-12, atol=1e-14)
        x = sol.y[:, -1]
        got = m.outputs(0.0, x, wm, u, TIRE_SCALE)
        rows.append([got[k] for k in keys])
    return np.array(rows)


def test_every_output_is_the_models_response_integrated_independently(fmu):
    itf = vehicle_interface(load_vehicle(EXAMPLES / "b_double.toml"), model="nonlinear")
    steps = _schedule(itf, 3)
    s = Slave(fmu, tire_scale=TIRE_SCALE, crossfall=CROSSFALL, friction_coefficient=MU).init()
    got = run_schedule(s, steps)
    warnings = s.log.messages(1)
    s.free()
    ref = _reference(itf, steps)
    assert any("u_min" in m for m in warnings), warnings                  # the clamp said once
    by_quantity = {}
    for o, var in enumerate(itf.outputs):
        by_quantity.setdefault(var.quantity, []).append(o)
    for q, cols in by_quantity.items():
        scale = np.abs(ref[:, cols]).max()
        assert scale > 0, q
        err = np.abs(got[:, cols] - ref[:, cols]).max(axis=0) / scale
        worst = int(np.argmax(err))
        # Radau at rtol 1e-8 against DOP853 at 1e-12: the FMU's integration error, at most rtol per
        # step over 24 chained steps of a stable system (measured 5.6e-10, the lateral velocities)
        assert err[worst] <= 1e-7, f"{itf.outputs[cols[worst]].name}: {err[worst]:.2e}"
    fd = [o for o, var in enumerate(itf.outputs) if var.name.startswith("fd_")]
    assert np.abs(got[:, fd]).max() > 0.05                               # the tires work: not a linear stand-in


def test_fmpy_validate_and_the_compliance_checker_pass(fmu, tmp_path):
    p = subprocess.run([str(Path(sys.executable).with_name("fmpy")), "validate", str(fmu)], capture_output=True,
                       text=True)
    assert p.returncode == 0 and "No problems found" in p.stdout, p.stdout + p.stderr
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    p = subprocess.run([str(TOOLS / "fmuCheck.linux64"), "-h", "0.01", "-s", "2", "-l", "3", "-o",
                        str(tmp_path / "o.csv"), str(fmu)], capture_output=True, text=True, env=env, timeout=600)
    text = p.stdout + p.stderr
    assert p.returncode == 0, text[-3000:]
    assert "0 Warning(s)" in text and "0 Error(s)" in text, text[-3000:]
    rows = (tmp_path / "o.csv").read_text().splitlines()
    assert len(rows) > 100                                              # 2 s at 0.01 s, every step computed


def test_bad_input_is_refused_in_one_line_with_the_state_unchanged(fmu):
    from fmpy.fmi1 import FMICallException
    s = Slave(fmu, friction_coefficient=0.8).init()
    s.set(delta=0.01)
    s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.1)
    before = s.get()
    s.set(delta=float("nan"))
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.1, communicationStepSize=0.1)
    assert any("input delta is not finite" in m for m in s.log.messages(3)), s.log.messages()
    s.set(delta=0.01)
    np.testing.assert_array_equal(s.get(), before)              # the state unchanged, the outputs finite
    s.free()
    s = Slave(fmu, friction_coefficient=2.5)
    with pytest.raises(FMICallException):
        s.fmu.exitInitializationMode()
    errors = s.log.messages(3)
    assert len(errors) == 1 and "friction_coefficient" in errors[0] and "2.5" in errors[0], errors
    s.fmu.freeInstance()


def test_lcv_fmu_builds_the_python_fmi2_fmu_only_and_says_so_in_one_line(tmp_path):
    lcv = str(Path(sys.executable).with_name("lcv"))
    for extra in (["--kind", "native"], ["--fmi", "3"]):
        p = subprocess.run([lcv, "fmu", "--vehicle", str(EXAMPLES / "b_double.toml"), "--model", "nonlinear",
                            "--out", str(tmp_path / "o"), *extra], capture_output=True, text=True)
        assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr
        assert "nonlinear" in p.stderr and not (tmp_path / "o").exists()
