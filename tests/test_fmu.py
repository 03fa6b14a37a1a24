"""Both FMUs, build/LCV.fmu (pythonfmu) and build/LCVNative.fmu (C): validation,
exactness against the package, state, reset, several instances, bad input, and the
same results in libcosim and ecos.  Native-only checks are in test_native.py."""
from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu
from fmpy.fmi1 import FMICallException

from lcvreport.cosim import INPUT_NAMES, OUTPUT_NAMES
from lcvreport.linear import eigenvalues
from lcvreport.presets import PRESETS, load_preset

from fmu_support import (Slave, assert_outputs_close, fmu_path, held_inputs, reference_outputs, run_schedule,
                         schedule)


@pytest.fixture(scope="module", params=["LCV", "LCVNative"])
def fmu(request):
    return fmu_path(request.param)


def test_fmpy_validate_finds_no_problem(fmu):
    fmpy_cli = Path(sys.executable).with_name("fmpy")  # the console script of the pinned fmpy
    p = subprocess.run([str(fmpy_cli), "validate", str(fmu)], capture_output=True, text=True)
    assert p.returncode == 0 and "No problems found" in p.stdout, p.stdout + p.stderr


def test_model_description_is_complete(fmu):
    root = ET.fromstring(zipfile.ZipFile(fmu).read("modelDescription.xml"))
    assert root.get("modelName") == fmu.stem and root.find("CoSimulation").get("modelIdentifier") == fmu.stem
    assert root.find("DefaultExperiment") is not None
    units = {u.get("name"): {d.get("name"): float(d.get("factor")) for d in u.findall("DisplayUnit")}
             for u in root.find("UnitDefinitions")}
    assert units["m/s"]["mph"] == pytest.approx(1 / 0.44704, rel=1e-12)
    assert units["m"]["in"] == pytest.approx(1 / 0.0254, rel=1e-12)
    assert units["rad"]["deg"] == pytest.approx(180 / np.pi, rel=1e-12)
    svs = root.find("ModelVariables").findall("ScalarVariable")
    names = [sv.get("name") for sv in svs]
    assert names == ["preset", "tire_scale", "u_min"] + list(INPUT_NAMES) + list(OUTPUT_NAMES)
    for sv in svs:
        assert sv.get("description"), sv.get("name")
        assert sv.get("causality") and sv.get("variability"), sv.get("name")
        real = sv.find("Real")
        if real is not None:
            assert real.get("unit"), sv.get("name")
    byname = {sv.get("name"): sv for sv in svs}
    assert byname["u"].find("Real").get("start") == "22.352"
    assert byname["u"].find("Real").get("displayUnit") == "mph"
    assert byname["u_min"].find("Real").get("start") == "2.2352"
    assert byname["preset"].find("String").get("start") == "aucnat"
    assert byname["y6"].find("Real").get("displayUnit") == "in"
    ms = root.find("ModelStructure")
    out_idx = [int(u.get("index")) for u in ms.find("Outputs")]
    init_idx = [int(u.get("index")) for u in ms.find("InitialUnknowns")]
    expected = [names.index(n) + 1 for n in OUTPUT_NAMES]
    assert out_idx == expected and init_idx == expected


def _input_table(steps_per_phase: list[tuple[float, dict]], h: float):
    """fmpy input table with step changes between grid points (duplicate time rows)."""
    dtype = [("time", float)] + [(n, float) for n in INPUT_NAMES]
    rows, current = [], {n: 0.0 for n in INPUT_NAMES}
    current["u"] = 22.352
    t = 0.0
    for duration, change in steps_per_phase:
        if rows:
            rows.append(tuple([t - h / 2] + [current[n] for n in INPUT_NAMES]))
        current.update(change)
        rows.append(tuple([t - h / 2 if rows else 0.0] + [current[n] for n in INPUT_NAMES]))
        t += duration
    rows.append(tuple([t + 1.0] + [current[n] for n in INPUT_NAMES]))
    return np.array(rows, dtype=dtype)


PHASES = [(1.0, {"P61": 800.0, "T61": 300.0, "P41": -500.0, "P21": 400.0}),
          (1.5, {"u": 13.4112, "delta": 0.002, "T11": -150.0}),
          (1.0, {"u": 31.2928, "delta": -0.001, "P12": 250.0, "T31": 120.0, "P51": -90.0}),
          (1.5, {"u": 8.9408, "delta": 0.0, "P13": -300.0})]


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("h", [0.01, 0.025])
def test_simulate_fmu_matches_the_exact_response(fmu, preset, h):
    """fmpy.simulate_fmu with inputs changing speed, steer and P/T mid-run."""
    stop = sum(d for d, _ in PHASES)
    table = _input_table(PHASES, h)
    res = simulate_fmu(str(fmu), start_values={"preset": preset}, stop_time=stop, step_size=h,
                       output_interval=h, input=table, output=list(OUTPUT_NAMES))
    got = np.column_stack([res[n] for n in OUTPUT_NAMES])
    # fmpy steps to the input discontinuities too; the inputs held over each step are
    # the table's values at the step's start (the new value from a change time on)
    t = res["time"]
    changes = np.cumsum([0.0] + [d for d, _ in PHASES])[:-1] - h / 2
    changes[0] = 0.0
    steps, current_phase = [], -1
    for t0, t1 in zip(t[:-1], t[1:]):
        k = int(np.searchsorted(changes, t0 + 1e-12, side="right") - 1)
        steps.append((t1 - t0, PHASES[k][1] if k != current_phase else {}))
        current_phase = k
    assert t[-1] == pytest.approx(stop) and len(steps) >= round(stop / h)
    ref = reference_outputs(preset, steps)
    assert_outputs_close(got, ref)


@pytest.mark.parametrize("preset", PRESETS)
def test_hand_driven_variable_step_sizes(fmu, preset):
    """FMU2Slave loop, variable communication steps, speed/steer/P/T changes mid-run."""
    steps = schedule(np.random.default_rng(PRESETS.index(preset)), 150, [0.001, 0.013, 0.05, 0.2])
    s = Slave(fmu, preset=preset).init()
    got = run_schedule(s, steps)
    s.free()
    assert_outputs_close(got, reference_outputs(preset, steps))


@pytest.mark.parametrize("preset", PRESETS)
def test_max_real_eig_output(fmu, preset):
    s = Slave(fmu, preset=preset, tire_scale=0.8).init()
    for mph in (5.0, 18.5, 30.0, 50.0, 90.0):
        s.set(u=mph * 0.44704)
        lam = eigenvalues(load_preset(preset), mph * 17.6, 0.8)
        assert s.get(["max_real_eig"])[0] == pytest.approx(lam.real.max(), rel=1e-9)
    s.free()


def test_state_get_set_and_serialization(fmu):
    steps = schedule(np.random.default_rng(11), 80, [0.01, 0.03])
    s = Slave(fmu, preset="aucnat").init()
    run_schedule(s, steps[:30])
    state = s.fmu.getFMUstate()
    blob = s.fmu.serializeFMUstate(state)
    first = run_schedule(s, steps[30:], t0=1.0)
    s.fmu.setFMUstate(state)
    again = run_schedule(s, steps[30:], t0=1.0)
    np.testing.assert_array_equal(first, again)
    restored = s.fmu.deSerializeFMUstate(blob)
    s.fmu.setFMUstate(restored)
    third = run_schedule(s, steps[30:], t0=1.0)
    np.testing.assert_array_equal(first, third)
    s.fmu.freeFMUstate(state)
    s.fmu.freeFMUstate(restored)
    s.free()


def test_reset_returns_to_rest(fmu):
    steps = schedule(np.random.default_rng(3), 40, [0.02])
    s = Slave(fmu, preset="empty").init()
    first = run_schedule(s, steps)
    s.fmu.reset()
    s.fmu.setupExperiment(startTime=0.0)
    s.fmu.enterInitializationMode()
    s.fmu.setString([s.vr["preset"]], ["empty"])
    s.fmu.exitInitializationMode()
    assert np.all(s.get()[:-1] == 0.0)
    second = run_schedule(s, steps)
    np.testing.assert_array_equal(first, second)
    s.free()


def test_instances_side_by_side_with_different_presets(fmu):
    presets = ["aucnat", "tractor_semitrailer", "empty_empty_loaded"]
    steps = schedule(np.random.default_rng(5), 60, [0.01, 0.04])
    slaves = [Slave(fmu, instance=f"lcv{i}", preset=p).init() for i, p in enumerate(presets)]
    outs = [[s.get()] for s in slaves]
    t = 0.0
    for h, inputs in steps:  # interleaved: one step of each instance in turn
        for s, o in zip(slaves, outs):
            if inputs:
                s.set(**inputs)
            s.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            o.append(s.get())
        t += h
    for p, s, o in zip(presets, slaves, outs):
        assert_outputs_close(np.array(o), reference_outputs(p, steps))
        s.free()


# ------------------------------------------------------------------ bad input
BAD_PARAMETERS = [("preset", "aucant"), ("preset", ""), ("tire_scale", 0.0), ("tire_scale", -1.0),
                  ("tire_scale", float("nan")), ("tire_scale", float("inf")), ("u_min", 0.0),
                  ("u_min", float("nan")), ("u_min", -2.0)]


@pytest.mark.parametrize("name, value", BAD_PARAMETERS)
def test_bad_parameter_is_logged_and_every_step_refused(fmu, name, value):
    """LCVNative fails fmi2ExitInitializationMode with fmi2Error; pythonfmu cannot fail it
    safely (see fmu_src/LCV.py), so LCV logs the error there. Both name the parameter in
    the log and refuse every fmi2DoStep."""
    s = Slave(fmu, **{name: value})
    if fmu.stem == "LCVNative":
        with pytest.raises(FMICallException):
            s.fmu.exitInitializationMode()
    else:
        s.fmu.exitInitializationMode()
    assert any(name in m for m in s.log.messages(min_status=3)), s.log.records
    n_logged = len(s.log.messages(min_status=3))
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.01)
    assert len(s.log.messages(min_status=3)) > n_logged and name in s.log.messages(min_status=3)[-1]
    assert np.all(np.isfinite(s.get()))
    s.free()


@pytest.mark.parametrize("name", ["u", "delta", "P61", "T11", "P21"])
@pytest.mark.parametrize("value", [float("nan"), float("inf"), float("-inf")])
def test_non_finite_input_is_refused_and_the_state_kept(fmu, name, value):
    s = Slave(fmu, preset="aucnat").init()
    good = [(0.05, {"P61": 500.0, "delta": 0.001})] * 4
    run_schedule(s, good)
    before = s.get()
    s.set(**{name: value})
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.2, communicationStepSize=0.05)
    after = s.get()
    assert np.all(np.isfinite(after))
    np.testing.assert_array_equal(after[:-1], before[:-1])
    assert any(name in m for m in s.log.messages(min_status=3)), s.log.records
    s.set(**{name: 0.0 if name != "u" else 22.352})  # the host fixes the input and goes on
    s.fmu.doStep(currentCommunicationPoint=0.2, communicationStepSize=0.05)
    assert np.all(np.isfinite(s.get()))
    s.free()


@pytest.mark.parametrize("h", [0.0, -0.01, float("nan")])
def test_bad_step_size_is_refused(fmu, h):
    s = Slave(fmu).init()
    with pytest.raises(FMICallException):
        s.fmu.doStep(currentCommunicationPoint=0.0, communicationStepSize=h)
    assert any("step size" in m for m in s.log.messages(min_status=3))
    assert np.all(np.isfinite(s.get()))
    s.free()


def test_zero_speed_runs_clamped_with_one_warning(fmu):
    steps = [(0.02, {"u": 0.0, "P61": 700.0, "T61": 200.0})] + [(0.02, {})] * 49 + \
            [(0.02, {"u": 22.352})] * 10 + [(0.02, {"u": -3.0})] + [(0.02, {})] * 9
    s = Slave(fmu, preset="aucnat").init()
    got = run_schedule(s, steps)
    warnings = [m for st, _c, m in s.log.records if st == 1 and "u_min" in m]
    assert len(warnings) == 2  # once per entry into the clamped range
    assert np.all(np.isfinite(got))
    assert_outputs_close(got, reference_outputs("aucnat", steps))
    s.free()


# ------------------------------------------------------------- other masters
# Inputs change between phases; outputs are read after every step.  libcosim passes
# step sizes computed from its nanosecond clock (0.01 +- 1 ulp), so its results differ
# from fmpy's by rounding: compared to 1e-12 of each output's peak.
COSIM_PHASES = [(100, {"P61": 1000.0, "T61": 300.0, "P41": -400.0}),
                (100, {"u": 13.4112, "delta": 0.001}),
                (100, {"u": 1.0, "T11": -200.0, "delta": 0.0})]


def _fmpy_series(fmu, preset, h):
    s = Slave(fmu, preset=preset).init()
    rows, t = [], 0.0
    for n, inputs in COSIM_PHASES:
        s.set(**inputs)
        for _ in range(n):
            s.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
            t += h
            rows.append(s.get())
    s.free()
    return np.array(rows)


def _ecos_series(fmu, preset, h):
    from ecospy import EcosSimulation, EcosSimulationStructure
    ss = EcosSimulationStructure()
    ss.add_model("lcv", str(fmu))
    ss.add_parameter_set("init", {"lcv::preset": preset})
    rows = []
    with EcosSimulation(structure=ss, step_size=h) as sim:
        sim.init(parameter_set="init")
        for n, inputs in COSIM_PHASES:
            for k, v in inputs.items():
                sim.set_real(f"lcv::{k}", v)
            for _ in range(n):
                sim.step(1)
                rows.append([sim.get_real(f"lcv::{o}") for o in OUTPUT_NAMES])
    return np.array(rows)


def _libcosim_series(fmu, preset, h):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    ex = CosimExecution.from_step_size(step_size=int(round(h * 1e9)))  # nanoseconds
    idx = ex.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="lcv"))
    vr = {(v.name.decode() if isinstance(v.name, bytes) else v.name): v.reference for v in ex.slave_variables(idx)}
    ex.string_initial_value(idx, vr["preset"], preset)
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    manip = CosimManipulator.create_override()
    ex.add_manipulator(manip)
    rows = []
    for n, inputs in COSIM_PHASES:
        for k, v in inputs.items():
            manip.slave_real_values(idx, [vr[k]], [v])
        for _ in range(n):
            ex.step(1)
            rows.append(obs.last_real_values(idx, [vr[o] for o in OUTPUT_NAMES]))
    return np.array(rows)


@pytest.mark.parametrize("preset", ["aucnat", "tractor_semitrailer"])
def test_ecos_gives_the_fmpy_outputs(fmu, preset):
    assert_outputs_close(_ecos_series(fmu, preset, 0.01), _fmpy_series(fmu, preset, 0.01), rtol=1e-12)


@pytest.mark.parametrize("preset", ["aucnat", "tractor_semitrailer"])
def test_libcosim_gives_the_fmpy_outputs(fmu, preset):
    assert_outputs_close(_libcosim_series(fmu, preset, 0.01), _fmpy_series(fmu, preset, 0.01), rtol=1e-12)
