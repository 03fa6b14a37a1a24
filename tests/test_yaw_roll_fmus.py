"""``lcv fmu --model yaw-roll`` (SPEC 17, issue item 5): the FMUs of the yaw-roll model, Python and
native, FMI 2 and 3.  Every output after every step of a random schedule (speed with clamping,
steer, every P, T and misalignment changing, uneven steps, a crossfall, tire scale 0.9) against
the package's exact response computed independently -- ``analysis.exact.response`` of each held
segment from the state the last one ended in (scipy's expm of its own augmented matrix, the
model's own ``extra_signals``) -- within the schedule's measured conditioning; the rear end
against the last unit's axles; the interface's roll variables; the tools (fmpy validate, the
FMI Compliance Checker, fmusim in both interfaces) in test_fmu_tools' manner."""
from __future__ import annotations

import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

from lcvreport.analysis.exact import response
from lcvreport.fmu.build import build_vehicle_fmus
from lcvreport.fmu.interface import vehicle_interface
from lcvreport.manoeuvres.steer import step
from lcvreport.model.linear import linear_model
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLES, TOOLS
from fmu_support import Slave, run_schedule
from helpers import held_inputs, schedule_condition, tolerance

pytestmark = pytest.mark.xdist_group("yaw_roll_fmus")

NAMES = ("western_double", "b_double")
TIRE_SCALE, CROSSFALL = 0.9, 2.0


@pytest.fixture(scope="module")
def roll_fmus(tmp_path_factory) -> dict:
    """{(name, fmi): {"python": path, "native": path}} for the two roll examples."""
    out = {}
    for name in NAMES:
        v = load_vehicle(EXAMPLES / f"{name}.toml")
        for fmi in (2, 3):
            d = tmp_path_factory.mktemp(f"{name}{fmi}")
            paths = build_vehicle_fmus(v, d, fmi=fmi, model="yaw_roll")
            out[(name, fmi)] = {"python": paths[0], "native": paths[1]}
    return out


def _schedule(itf, seed: int):
    rng = np.random.default_rng(seed)
    axles = [v.name[2:] for v in itf.inputs if v.name.startswith("P_")]
    steps = []
    change_at = set(rng.choice(np.arange(1, 60), size=5, replace=False).tolist())
    for k in range(60):
        inputs = {}
        if k == 0 or k in change_at:
            inputs["u"] = float(rng.choice([22.352, 13.4112, 31.2928, 8.9408, 1.0]))   # 1.0: clamped
            inputs["delta"] = float(rng.normal(0, 2e-3))
            for a in axles:
                inputs[f"P_{a}"] = float(rng.normal(0, 500.0))
                inputs[f"T_{a}"] = float(rng.normal(0, 300.0))
                inputs[f"eps_{a}"] = float(rng.normal(0, 1e-3))
        steps.append((float(rng.choice([0.001, 0.01, 0.037, 0.25])), inputs))
    return steps


def _independent_reference(itf, steps) -> np.ndarray:
    """Every output but max_real_eig and Y_rear after every step, from the package's exact response
    of each held segment (its own augmented matrix and scipy's expm), chained by the state."""
    v = itf.vehicles[0]
    co = linear_model(v, "yaw_roll")
    names = [var.name for var in itf.inputs]
    cf = np.array([a.cornering_stiffness_axle_N_per_rad for a in v.axles])
    theta = {f"theta{k + 1}": n for k, n in enumerate(s for s in co.state_names if s.startswith("theta"))}
    keep = [o for o, var in enumerate(itf.outputs) if var.name not in ("max_real_eig", "Y_rear")]
    z, rows = None, []
    for (h, _), w in zip(steps, held_inputs(itf, steps)):
        P, T, E = (np.array([w[names.index(f"{k}_{a}")] for a in v.axle_names]) for k in ("P", "T", "eps"))
        F = (co.B_P @ P + co.B_T @ T + TIRE_SCALE * (co.B_eps @ E)
             + math.sin(math.atan(CROSSFALL / 100.0)) * co.B_crossfall)
        r = response(v, max(w[0], 2.2352), step(w[1]), h, h, F=F, tire_scale=TIRE_SCALE, state=z, model="yaw_roll",
                     axle_force_N=P + TIRE_SCALE * cf * E)
        z = np.array([r[n][-1] for n in list(co.state_names) + ["psi1", "Y1"]])
        rows.append([r[theta.get(itf.outputs[o].name, itf.outputs[o].name)][-1] for o in keep])
    return np.array(rows), keep


def test_the_interface_adds_the_roll_variables_after_every_yaw_plane_one():
    v = load_vehicle(EXAMPLES / "western_double.toml")
    plane, roll = vehicle_interface(v), vehicle_interface(v, model="yaw_roll")
    assert [(x.name, x.value_reference) for x in roll.variables[:len(plane.variables)]] == \
        [(x.name, x.value_reference) for x in plane.variables]
    added = [x.name for x in roll.variables[len(plane.variables):]]
    assert added == ([f"p{i}" for i in range(1, 5)] + [f"phi{i}" for i in range(1, 5)] + [f"as{i}" for i in range(1, 5)]
                     + [f"dFz_{a}" for a in v.axle_names] + ["ltr1", "ltr2"])
    assert [x.name for x in roll.continuous_states][-8:] == added[:8]      # roll rates and angles: ME states
    assert {x.unit for x in roll.variables if x.name.startswith("dFz_")} == {"N"}


def test_a_vehicle_without_roll_data_is_refused_in_one_line(tmp_path):
    err = subprocess.run([str(Path(sys.executable).with_name("lcv")), "fmu", "--preset", "aucnat", "--model",
                          "yaw-roll", "--out", str(tmp_path / "o")], capture_output=True, text=True)
    assert err.returncode == 2 and len(err.stderr.strip().splitlines()) == 1, err.stderr
    assert "cg_height_m" in err.stderr and "--preset aucnat" in err.stderr
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("kind", ("python", "native"))
def test_every_output_is_the_packages_exact_yaw_roll_response(roll_fmus, name, kind):
    itf = vehicle_interface(load_vehicle(EXAMPLES / f"{name}.toml"), model="yaw_roll")
    steps = _schedule(itf, 11)
    s = Slave(roll_fmus[(name, 2)][kind], tire_scale=TIRE_SCALE, crossfall=CROSSFALL).init()
    got = run_schedule(s, steps)
    s.free()
    ref, keep = _independent_reference(itf, steps)
    kappa = schedule_condition(itf, steps, tire_scale=TIRE_SCALE)
    # the coefficient-perturbation condition kappa does not see the rounding of the two exponentials
    # themselves (the C FMU's and numpy's scaling and squaring, each ~(squarings + Pade degree) eps,
    # amplified by the step matrix's norm): a floor of 512 eps, 1.1e-13 of each quantity's scale
    # (the western double with its loads by statics: 5.3e-14 at kappa 23)
    tol = max(tolerance(kappa), 512 * np.finfo(float).eps)
    by_quantity = {}
    for j, o in enumerate(keep):
        by_quantity.setdefault(itf.outputs[o].quantity, []).append(j)
    for q, cols in by_quantity.items():
        scale = np.abs(ref[:, cols]).max()
        assert scale > 0, q
        err = np.abs(got[:, keep][:, cols] - ref[:, cols]).max(axis=0) / scale
        worst = int(np.argmax(err))
        assert err[worst] <= tol, (f"{itf.outputs[keep[cols[worst]]].name}: {err[worst]:.2e} > {tol:.2e} "
                                   f"(kappa {kappa:.3g})")
    # the roll outputs are alive: every roll angle, load transfer and LTR moves
    for n in ("phi1", "phi3", "ltr1", "dFz_steer"):
        assert np.abs(got[:, itf.outputs.index(itf.by_name[n])]).max() > 0
    assert np.all(np.isfinite(got))


def test_the_rear_end_lies_on_the_line_of_the_last_units_axles(roll_fmus):
    """Y_rear (first order, roll offsets included) on the straight line through the b-trailer's
    first and last axle centres (Y_b1, Y_b3), extrapolated to the rear end."""
    v = load_vehicle(EXAMPLES / "b_double.toml")
    itf = vehicle_interface(v, model="yaw_roll")
    s = Slave(roll_fmus[("b_double", 2)]["native"], tire_scale=TIRE_SCALE).init()
    got = run_schedule(s, _schedule(itf, 5))
    s.free()
    col = {var.name: o for o, var in enumerate(itf.outputs)}
    last = v.units[-1]
    xa, xb, xr = last.axles[0].x_m, last.axles[-1].x_m, v.rear_end_x_m(v.n_units - 1)
    ya, yb = got[:, col[f"Y_{last.axles[0].name}"]], got[:, col[f"Y_{last.axles[-1].name}"]]
    line = ya + (yb - ya) * (xr - xa) / (xb - xa)
    scale = np.abs(got[:, col["Y_rear"]]).max()
    assert scale > 1e-3
    assert np.abs(got[:, col["Y_rear"]] - line).max() <= 1e-12 * scale


@pytest.mark.parametrize("kind", ("python", "native"))
def test_fmi3_is_fmi2_to_the_last_bit_or_the_conditioning(roll_fmus, kind):
    """The FMI 3 FMUs give the FMI 2 ones' outputs (fmpy's FMI 3 slave, same schedule)."""
    from fmpy import extract, read_model_description
    from fmpy.fmi3 import FMU3Slave
    name = "western_double"
    itf = vehicle_interface(load_vehicle(EXAMPLES / f"{name}.toml"), model="yaw_roll")
    steps = _schedule(itf, 3)
    s = Slave(roll_fmus[(name, 2)][kind], tire_scale=TIRE_SCALE).init()
    two = run_schedule(s, steps)
    s.free()
    path = str(roll_fmus[(name, 3)][kind])
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    f = FMU3Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="i")
    f.instantiate()
    f.enterInitializationMode()
    f.setFloat64([vr["tire_scale"]], [TIRE_SCALE])
    f.exitInitializationMode()
    t, rows = 0.0, []
    outs = [vr[v.name] for v in itf.outputs]
    for h, inputs in steps:
        if inputs:
            f.setFloat64([vr[k] for k in inputs], list(inputs.values()))
        f.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        rows.append(f.getFloat64(outs))
    f.terminate()
    f.freeInstance()
    three = np.array(rows)
    scale = np.maximum(np.abs(two).max(axis=0), 1e-300)
    assert (np.abs(three - two) / scale).max() <= 1e-12


def _tool(name: str) -> Path:
    """An independent FMI importer (conftest.TOOLS): a test that needs one fails without it, as
    test_fmu_tools' do."""
    p = TOOLS / name
    assert p.exists(), f"{p} is missing: the FMI tools (../shared/tools) are needed"
    return p


@pytest.mark.parametrize("fmi", (2, 3))
def test_the_native_fmu_passes_fmusim_in_both_interfaces_and_me_is_cs(roll_fmus, fmi, tmp_path):
    """fmusim (Reference-FMUs) runs the native yaw-roll FMU as Co-Simulation and as Model Exchange
    (CVODE) with a crossfall: the vehicle settles into its steady roll; Model Exchange's roll angles
    equal Co-Simulation's exact ones within the integrator's tolerance.  (fmusim's default explicit
    Euler at the output interval 0.01 s diverges on the roll modes, |lambda| = 83 1/s at 80 km/h:
    docs/fmu.md says so.)"""
    fmusim = _tool("fmusim")
    fmu = roll_fmus[("western_double", fmi)]["native"]
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    runs = {}
    for iface in ("cs", "me"):
        out = tmp_path / f"{iface}.csv"
        solver = ["--solver", "cvode", "--tolerance", "1e-9"] if iface == "me" else []
        p = subprocess.run([str(fmusim), "--interface-type", iface, *solver, "--stop-time", "4", "--output-interval",
                            "0.01", "--start-value", "crossfall", "3", "--output-file", str(out), str(fmu)],
                           capture_output=True, text=True, env=env, timeout=300)
        assert p.returncode == 0, p.stdout + p.stderr
        import csv
        with open(out, newline="") as f:
            rows = list(csv.reader(f))
        head = [h.strip('"') for h in rows[0]]
        data = np.array(rows[1:], dtype=float)
        runs[iface] = {h: data[:, j] for j, h in enumerate(head)}
    for k in ("phi1", "phi2", "phi3", "phi4"):
        cs, me = runs["cs"][k], runs["me"][k]
        assert np.abs(cs).max() > 1e-5, k                    # the crossfall rolls every unit
        # CVODE at rtol 1e-9 against the exact steps: the integrator's error, well above rounding
        assert np.abs(me - cs).max() <= 1e-6 * np.abs(cs).max(), (k, np.abs(me - cs).max() / np.abs(cs).max())


@pytest.mark.parametrize("kind", ("python", "native"))
def test_fmpy_validate_and_the_compliance_checker_pass(roll_fmus, kind, tmp_path):
    fmu = roll_fmus[("western_double", 2)][kind]
    p = subprocess.run([str(Path(sys.executable).with_name("fmpy")), "validate", str(fmu)], capture_output=True,
                       text=True)
    assert p.returncode == 0 and "No problems found" in p.stdout, p.stdout + p.stderr
    checker = _tool("fmuCheck.linux64")
    env = {k: v for k, v in os.environ.items() if k != "LD_PRELOAD"}
    p = subprocess.run([str(checker), "-h", "0.01", "-s", "2", "-l", "3", "-o", str(tmp_path / "o.csv"), str(fmu)],
                       capture_output=True, text=True, env=env, timeout=300)
    text = p.stdout + p.stderr
    assert p.returncode == 0, text[-3000:]
    assert "0 Warning(s)" in text and "0 Error(s)" in text, text[-3000:]


def test_the_modeldescription_declares_the_roll_outputs_dependencies(roll_fmus):
    """The load transfers and LTRs depend on the states and on the inputs (feedthrough), like ay."""
    fmu = roll_fmus[("western_double", 2)]["native"]
    root = ET.fromstring(zipfile.ZipFile(fmu).read("modelDescription.xml"))
    svs = list(root.iter("ScalarVariable"))
    index = {sv.get("name"): k + 1 for k, sv in enumerate(svs)}
    deps = {int(u.get("index")): u.get("dependencies") for u in root.find("ModelStructure/Outputs")}
    states = {index[n] for n in ("phi1", "p1", "v1")}
    for name in ("ltr1", "dFz_steer", "as2"):
        listed = set(int(k) for k in (deps[index[name]] or "").split())
        assert index["delta"] in listed and index["P_steer"] in listed, (name, listed)   # feedthrough
        assert states <= listed, (name, listed)                                          # and the state
    assert index["delta"] not in set(int(k) for k in deps[index["phi1"]].split())        # a state: none


@pytest.mark.parametrize("name", NAMES)
def test_the_native_fmus_terms_assemble_the_models_extra_signals(name):
    """extra_signal_terms (what vehicle_data.h holds) give extra_signals at any speed and tire
    scale: X = X0 + u X1 + (s/u) X2 + s X3, XD = XD0 + u XD1, D = s D1, O -- to rounding of the
    rows' largest entry (each entry is a sum of a few products)."""
    co = linear_model(load_vehicle(EXAMPLES / f"{name}.toml"), "yaw_roll")
    t = co.extra_signal_terms()
    for u, s in ((2.2352, 1.0), (13.0, 0.5), (24.0, 0.9), (40.0, 1.3)):
        names, X, XD, D, O = co.extra_signals(u, s)
        assert names == t["names"]
        for got, ref in ((t["X0"] + u * t["X1"] + (s / u) * t["X2"] + s * t["X3"], X),
                         (t["XD0"] + u * t["XD1"], XD), (s * t["D1"], D), (t["O"], O)):
            scale = np.abs(ref).max(axis=-1, keepdims=True) if ref.ndim == 2 else np.abs(ref).max()
            assert np.all(np.abs(got - ref) <= 8 * np.finfo(float).eps * np.maximum(scale, 1e-300))
