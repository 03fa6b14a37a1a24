"""FMUs of the user's own vehicle (SPEC section 9), built by ``lcv fmu`` for every example
vehicle: the interface table in both XMLs, exactness of both kinds against the package with
tolerances from the measured conditioning, a closed loop with a driver FMU in ecos against
the package's closed-loop computation, and the C FMU's binary and shipped sources.
(The checker and fmusim on these FMUs are in test_fmu_tools.py.)"""
from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest

from lcvreport.analysis.closed_loop import steer_feedback
from lcvreport.fmu.build import build_native_fmu
from lcvreport.fmu.interface import vehicle_interface
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLES, ROOT
from fmu_support import Slave, host_values, run_host, run_schedule, unzip
from helpers import group_error, reference_outputs, schedule, schedule_condition, tolerance

KINDS = ("python", "native")


def _variables(path: Path) -> list[tuple]:
    root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    return [(sv.get("name"), int(sv.get("valueReference")), sv.get("causality"), sv.get("variability"),
             sv[0].get("unit"), sv[0].get("displayUnit"), sv[0].get("start"), sv.get("description"))
            for sv in root.iter("ScalarVariable") if sv.get("causality") != "local"]   # not the ME der(x)


def test_both_kinds_pass_fmpy_validate_and_hold_the_interface_table(example_fmus):
    name, fmus = example_fmus
    vehicle = load_vehicle(EXAMPLES / f"{name}.toml")
    itf = vehicle_interface(vehicle)
    expected = [(v.name, v.value_reference, v.causality, v.variability) for v in itf.variables]
    for kind in KINDS:
        p = subprocess.run([str(Path(sys.executable).with_name("fmpy")), "validate", str(fmus[kind])],
                           capture_output=True, text=True)
        assert p.returncode == 0 and "No problems found" in p.stdout, p.stdout + p.stderr
        got = _variables(fmus[kind])
        assert [g[:4] for g in got] == expected
        assert all(g[7] for g in got)                       # every variable described
    assert _variables(fmus["python"]) == _variables(fmus["native"])
    names = [v[0] for v in _variables(fmus["native"])]
    # SPEC 9: one P_ and T_ per axle, named after the file's axles; theta per joint; ay per unit
    assert [n for n in names if n.startswith("P_")] == [f"P_{a.name}" for u in vehicle.units for a in u.axles]
    assert [n for n in names if n.startswith("theta")] == [f"theta{j}" for j in range(1, vehicle.n_units)]
    assert [n for n in names if n.startswith("ay")] == [f"ay{i}" for i in range(1, vehicle.n_units + 1)]
    # the vehicle travels with the FMU, as its file
    shipped = zipfile.ZipFile(fmus["native"]).read("resources/vehicle.toml").decode()
    assert load_vehicle(EXAMPLES / f"{name}.toml") == vehicle
    from lcvreport.model.vehicle_file import loads_vehicle
    assert loads_vehicle(shipped) == vehicle


@pytest.mark.parametrize("kind", KINDS)
def test_exact_against_the_package_within_the_conditioning(example_fmus, kind):
    """A random schedule (speed incl. clamping, steer, every P and T changing, uneven steps):
    every output within 10 kappa eps of the package's exact response."""
    name, fmus = example_fmus
    itf = vehicle_interface(load_vehicle(EXAMPLES / f"{name}.toml"))
    axles = [v.name[2:] for v in itf.inputs if v.name.startswith("P_")]
    rng = np.random.default_rng(7)
    steps = schedule(rng, 120, [0.001, 0.01, 0.037, 0.25], axles, clamp=True, P="P_{}", T="T_{}")
    s = Slave(fmus[kind], tire_scale=0.9).init()
    got = run_schedule(s, steps)
    s.free()
    ref = reference_outputs(itf, steps, tire_scale=0.9)
    kappa = schedule_condition(itf, steps, tire_scale=0.9)
    err, worst = group_error(got, ref, itf)
    assert err <= tolerance(kappa), f"{worst}: {err:.2e} > {tolerance(kappa):.2e} (kappa {kappa:.3g})"
    assert np.all(np.isfinite(got))


# ---------------------------------------------------------------------------- closed loop in ecos
@pytest.fixture(scope="module")
def driver_fmu(tmp_path_factory) -> Path:
    """tests/driver_fmu as an FMU: driver.c compiled against the official FMI 2 headers
    that fmpy ships, zipped with its modelDescription.xml."""
    d = tmp_path_factory.mktemp("driver")
    so = d / "driver.so"
    headers = Path(fmpy.__file__).parent / "c-code"
    subprocess.run(["gcc", "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC", "-I", str(headers),
                    "-o", str(so), str(ROOT / "tests" / "driver_fmu" / "driver.c")], check=True)
    fmu = d / "driver.fmu"
    with zipfile.ZipFile(fmu, "w") as z:
        z.write(ROOT / "tests" / "driver_fmu" / "modelDescription.xml", "modelDescription.xml")
        z.write(so, "binaries/linux64/driver.so")
    return fmu


@pytest.mark.parametrize("kind", KINDS)
def test_closed_loop_with_a_driver_fmu_in_ecos_is_the_package_closed_loop(western_fmus, driver_fmu, kind):
    """steer = -k_Y Y1 - k_psi psi1 from a driver FMU of our own, coupled to the vehicle FMU
    in ecos, with a residual force on the steer axle.  ecos steps every model on the
    values transferred at the previous communication point (Jacobi order): the steer
    reaches the vehicle one step late, delay_steps=1 in the package's computation."""
    from ecospy import EcosSimulation, EcosSimulationStructure
    vehicle = load_vehicle(EXAMPLES / "western_double.toml")
    h, n, speed, gains, P = 0.02, 500, 24.0, (0.002, 0.2), 1000.0
    ss = EcosSimulationStructure()
    ss.add_model("lcv", str(western_fmus[kind]))
    ss.add_model("driver", str(driver_fmu))
    ss.make_real_connection("lcv::Y1", "driver::Y1")
    ss.make_real_connection("lcv::psi1", "driver::psi1")
    ss.make_real_connection("driver::delta", "lcv::delta")
    ss.add_parameter_set("init", {"lcv::u": speed, "lcv::P_steer": P, "driver::k_Y": gains[0],
                                  "driver::k_psi": gains[1]})
    names = ["Y1", "psi1", "v1", "r4", "theta3", "Y_rear", "ay4"]
    rows, steer = [], []
    with EcosSimulation(structure=ss, step_size=h) as sim:
        sim.init(parameter_set="init")
        for _ in range(n):
            sim.step(1)
            rows.append([sim.get_real(f"lcv::{k}") for k in names])
            steer.append(sim.get_real("driver::delta"))
    rows, steer = np.array(rows), np.array(steer)

    run = steer_feedback(vehicle, speed, gains, h, n, residual_P_N={"steer": P}, delay_steps=1)
    r = run.response
    ref = np.c_[r["Y1"], r["psi1"], r["v1"], r["r4"], r["thetaC"], r["Y_rear"], r["ay4"]][1:]
    assert np.abs(ref[:, 0]).max() > 0.5          # the loop holds a real offset (m), not a trivial zero
    scale = np.abs(ref).max(axis=0)
    err = (np.abs(rows - ref) / scale).max(axis=0)
    assert err.max() < 1e-9, dict(zip(names, err))
    # the driver's output follows the vehicle values it was last given
    np.testing.assert_allclose(steer, -(gains[0] * rows[:, 0] + gains[1] * rows[:, 1]), rtol=0, atol=1e-15)
    # and the loop is closed: without the delay the package gives a different answer
    other = steer_feedback(vehicle, speed, gains, h, n, residual_P_N={"steer": P}, delay_steps=0)
    assert np.abs(other.response["Y1"][1:] - rows[:, 0]).max() > 1e-3 * scale[0]


# ---------------------------------------------------------------------------- the C FMU's binary
def test_native_binaries_need_only_libc_and_libm(native_fmu, western_fmus, tmp_path):
    for fmu in (native_fmu, western_fmus["native"]):
        d, _g, _vr = unzip(fmu, tmp_path / fmu.stem)
        so = d / "binaries" / "linux64" / f"{fmu.stem}.so"
        needed = [line.split()[-1].strip("[]") for line in
                  subprocess.run(["readelf", "-d", str(so)], capture_output=True, text=True).stdout.splitlines()
                  if "(NEEDED)" in line]
        assert sorted(needed) == ["libc.so.6", "libm.so.6"], needed


def test_native_fmu_sources_rebuild_the_same_binary_behaviour(c_host, western_fmus, tmp_path):
    """The sources/ the FMU ships (README.txt there says how) compile, with the official FMI
    headers an importer has (fmpy's c-code; they are not shipped), into a binary that gives
    the same numbers as the shipped one."""
    fmu = western_fmus["native"]
    d, _guid, vr = unzip(fmu, tmp_path / "shipped")
    src = d / "sources"
    assert (src / "README.txt").exists()
    rebuilt = tmp_path / "rebuilt"
    zipfile.ZipFile(fmu).extractall(rebuilt)
    so = rebuilt / "binaries" / "linux64" / f"{fmu.stem}.so"
    so.unlink()
    from lcvreport.fmu.c_sources import fmi_header_dir
    subprocess.run(["gcc", "-std=c99", "-O2", "-shared", "-fPIC", "-I", str(src), "-I", str(fmi_header_dir()),
                    "-o", str(so),
                    *sorted(str(c) for c in src.glob("*.c")), "-lm"], check=True, capture_output=True)
    script = f"s {vr['P_steer']} 800\ns {vr['delta']} 0.001\ni\n" + "".join(
        f"d {k * 0.05!r} 0.05\ng {vr['Y_rear']} {vr['theta3']} {vr['ay4']}\n" for k in range(60))
    outs = []
    for folder in (d, rebuilt):
        p = run_host(c_host, (folder, _guid, vr), fmu.stem, script)
        assert p.returncode == 0, p.stderr
        outs.append(host_values(p.stdout))
    assert outs[0].shape == (60, 3) and np.abs(outs[0]).max() > 0
    np.testing.assert_array_equal(outs[0], outs[1])


def test_interface_only_stub_twin_has_the_same_interface(western_fmus, tmp_path):
    """The benchmark twin (model_stub.c: the FMI layer without the model) builds from the
    same interface table."""
    itf = vehicle_interface(load_vehicle(EXAMPLES / "western_double.toml"))
    stub = build_native_fmu(itf, tmp_path, "western_doubleStub", stub=True)
    assert [v[:7] for v in _variables(stub)] == [v[:7] for v in _variables(western_fmus["native"])]
    res = fmpy.simulate_fmu(str(stub), stop_time=0.1, step_size=0.01, output=["Y1"])
    assert res["time"][-1] == pytest.approx(0.1)


def test_the_start_speed_of_u_follows_lcv_fmu_speed(tmp_path):
    """The assessment report documents its FMUs at its own speed (before: 50 mph whatever
    the report's speed): ``lcv fmu --speed-kph V`` starts u at V, in both kinds."""
    from lcvreport.analysis.modes import modes
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "fmu", "--vehicle", str(EXAMPLES / "b_double.toml"),
                        "--speed-kph", "88", "--out", str(tmp_path)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    vehicle = load_vehicle(EXAMPLES / "b_double.toml")
    for fmu in (tmp_path / "b_double.fmu", tmp_path / "b_doubleNative.fmu"):
        starts = {v[0]: v[6] for v in _variables(fmu)}
        assert float(starts["u"]) == pytest.approx(88 / 3.6, rel=1e-15)
        res = fmpy.simulate_fmu(str(fmu), stop_time=0.02, step_size=0.01, output=["max_real_eig"])
        assert res["max_real_eig"][-1] == pytest.approx(modes(vehicle, 88 / 3.6).max_real, rel=1e-9)
