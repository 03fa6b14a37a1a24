"""The FMI 3.0 native FMUs (issue 20, SPEC section 15): build/LCVNative3.fmu and
``lcv fmu --fmi 3`` of every example vehicle -- fmpy validate, Co-Simulation exact within
10 kappa eps of the package, Model Exchange with CVode at rtol 1e-10, fmusim (CS and ME) with
no LD_PRELOAD, ``fmpy compile`` from sources/, and hostile calls of the FMI 3 API."""
from __future__ import annotations

import csv
import ctypes
import html
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi3 import FMU3Model, FMU3Slave, fmi3LogMessageCallback

from lcvreport.fmu.interface import preset_interface, preset_value
from lcvreport.model.presets import PRESETS

from conftest import BUILD, EXAMPLE_NAMES, EXAMPLES, ROOT, TOOLS
from fmu_support import host_env, interface_of
from helpers import group_error, reference_outputs, schedule, schedule_condition, tolerance

FMUSIM = TOOLS / "fmusim"
AXLES = ("11", "12", "13", "21", "31", "41", "51", "61")


@pytest.fixture(scope="session")
def native3_fmu(native_fmu):
    path = BUILD / "LCVNative3.fmu"
    if not path.exists():
        subprocess.run([sys.executable, "-m", "lcvreport.fmu.build", "--out", str(BUILD)], check=True, cwd=ROOT)
    return path


@pytest.fixture(scope="session")
def python3_fmu(native3_fmu):
    path = BUILD / "LCV3.fmu"
    if not path.exists():
        subprocess.run([sys.executable, "-m", "lcvreport.fmu.build", "--out", str(BUILD)], check=True, cwd=ROOT)
    return path


@pytest.fixture(scope="session")
def example3_all(tmp_path_factory):
    """``lcv fmu --vehicle X --fmi 3`` (both kinds) of every example vehicle."""
    out = tmp_path_factory.mktemp("fmi3")
    paths = {}
    for name in EXAMPLE_NAMES:
        p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "fmu", "--vehicle", str(EXAMPLES / f"{name}.toml"),
                            "--out", str(out), "--fmi", "3"], capture_output=True, text=True)
        assert p.returncode == 0, p.stderr
        paths[name] = {"native": out / f"{name}Native3.fmu", "python": out / f"{name}3.fmu"}
        assert all(f.exists() for f in paths[name].values()), p.stdout
    return paths


@pytest.fixture(scope="session")
def example3_fmus(example3_all):
    return {name: f["native"] for name, f in example3_all.items()}


@pytest.fixture(scope="session")
def example3_python_fmus(example3_all):
    return {name: f["python"] for name, f in example3_all.items()}


class Log:
    def __init__(self):
        self.records = []
        self.callback = fmi3LogMessageCallback(
            lambda env, status, category, message: self.records.append((status, (message or b"").decode())))

    def errors(self):
        return [m for s, m in self.records if s >= 3]


def _slave(fmu, log, preset=None, logging=True):
    md = read_model_description(str(fmu))
    s = FMU3Slave(guid=md.guid, unzipDirectory=extract(str(fmu)), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="s3")
    s.instantiate(loggingOn=logging, logMessage=log.callback)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    if preset:
        s.setInt64([vr["preset"]], [preset_value(preset)])
    return s, vr, md


def test_every_python_fmi3_fmu_validates(python3_fmu, example3_python_fmus):
    """The Python FMI 3.0 FMUs: fmpy validate clean, Co-Simulation only, needsExecutionTool,
    the loader beside pythonfmu3's library, preset an Enumeration in the preset FMU."""
    import xml.etree.ElementTree as ET
    for fmu in [python3_fmu, *example3_python_fmus.values()]:
        p = subprocess.run([str(Path(sys.executable).parent / "fmpy"), "validate", str(fmu)], capture_output=True,
                           text=True)
        assert p.returncode == 0 and "No problems found" in p.stdout, (fmu.name, p.stdout + p.stderr)
        root = ET.fromstring(zipfile.ZipFile(fmu).read("modelDescription.xml"))
        assert root.get("fmiVersion") == "3.0" and root.find("ModelExchange") is None
        cs = root.find("CoSimulation")
        assert cs.get("modelIdentifier") == fmu.stem and cs.get("needsExecutionTool") == "true"
        names = zipfile.ZipFile(fmu).namelist()
        assert {f"binaries/x86_64-linux/{fmu.stem}.so", "binaries/x86_64-linux/libpythonfmu3-export.so",
                "documentation/index.html", "documentation/licenses/license.txt"} <= set(names)
        assert (root.find("ModelVariables/Enumeration[@name='preset']") is not None) == (fmu == python3_fmu)
        doc = html.unescape(zipfile.ZipFile(fmu).read("documentation/index.html").decode())
        lic = zipfile.ZipFile(fmu).read("documentation/licenses/license.txt").decode()
        assert "FMI 3.0 Co-Simulation FMU" in doc and "pythonfmu3's export library" in doc
        assert "pythonfmu3 0.3.4 (resources/pythonfmu3, binaries/x86_64-linux/libpythonfmu3-export.so)" in lic


@pytest.mark.parametrize("preset", ["aucnat", "tractor_semitrailer"])
def test_python_fmi3_co_simulation_is_the_exact_response(python3_fmu, preset):
    """The Python FMI 3.0 FMU through fmpy: every output within 10 kappa eps of the package."""
    test_co_simulation_is_the_exact_response(python3_fmu, preset)


def test_python_fmi3_fmus_in_fmusim_with_no_ld_preload(python3_fmu, example3_python_fmus, tmp_path):
    """Reference-FMUs' fmusim (a plain C host) loads the Python FMI 3.0 FMUs with no LD_PRELOAD
    and no PYTHONPATH and gives the package's exact response (Co-Simulation, 1e-12)."""
    H, N = 0.05, 40
    for fmu, preset in [(python3_fmu, "legal_max")] + [(f, None) for f in example3_python_fmus.values()]:
        itf = interface_of_fmi3(fmu)
        inputs = _constant_case(itf)
        outs = [v.name for v in itf.outputs]
        names = outs[:outs.index("Y_rear") + 1]
        ref = reference_outputs(itf, [(H, inputs)] + [(H, {})] * (N - 1), preset)
        with open(tmp_path / "in.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["time", *inputs])
            for t in (0.0, N * H):
                w.writerow([t, *inputs.values()])
        args = [str(FMUSIM), "--interface-type", "cs", "--stop-time", str(N * H), "--output-interval", str(H),
                "--input-file", str(tmp_path / "in.csv"), "--output-file", str(tmp_path / "out.csv")]
        if preset:
            args += ["--start-value", "preset", str(preset_value(preset))]
        p = subprocess.run(args + [str(fmu)], capture_output=True, text=True, env=host_env(), timeout=300)
        assert p.returncode == 0, (fmu.name, (p.stdout + p.stderr)[-2000:])
        with open(tmp_path / "out.csv") as f:
            rows = list(csv.DictReader(f))
        got = np.array([[float(r[n]) for n in names] for r in rows[1:N + 1]])
        err, name = group_error(got, ref, itf)
        assert err <= 1e-12, (fmu.name, name, err)


def test_every_fmi3_fmu_validates(native3_fmu, example3_fmus):
    for fmu in [native3_fmu, *example3_fmus.values()]:
        p = subprocess.run([str(Path(sys.executable).parent / "fmpy"), "validate", str(fmu)], capture_output=True,
                           text=True)
        assert p.returncode == 0 and "No problems found" in p.stdout, (fmu.name, p.stdout + p.stderr)
        names = zipfile.ZipFile(fmu).namelist()
        assert f"binaries/x86_64-linux/{fmu.stem}.so" in names and "sources/buildDescription.xml" in names
        assert not [n for n in names if n.split("/")[-1].startswith(("fmi3Functions", "fmi3FunctionTypes",
                                                                      "fmi3PlatformTypes"))]


@pytest.mark.parametrize("preset", PRESETS)
def test_co_simulation_is_the_exact_response(native3_fmu, preset):
    """Random schedules (speed incl. clamping, steer, P/T changing, uneven steps) through the
    FMI 3 API: every output within 10 kappa eps of the package (as the FMI 2 FMUs)."""
    itf = preset_interface()
    rng = np.random.default_rng(300 + PRESETS.index(preset))
    steps = schedule(rng, 80, [0.001, 0.01, 0.037, 0.25], AXLES, clamp=True)
    log = Log()
    s, vr, _md = _slave(native3_fmu, log, preset)
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    outs = [v.name for v in itf.outputs]
    names = outs[:outs.index("Y_rear") + 1]
    t, rows = 0.0, []
    for h, inputs in steps:
        if inputs:
            s.setFloat64([vr[k] for k in inputs], list(inputs.values()))
        s.doStep(t, h)
        t += h
        rows.append(s.getFloat64([vr[n] for n in names]))
    s.terminate()
    s.freeInstance()
    ref = reference_outputs(itf, steps, preset)
    kappa = schedule_condition(itf, steps, preset)
    err, name = group_error(np.array(rows), ref, itf)
    assert err <= tolerance(kappa), f"{name}: {err:.2e} > {tolerance(kappa):.2e}"


def _constant_case(itf):
    p = [v.name for v in itf.inputs if v.source[0] == "P"][-1]
    return {"u": 24.0, "delta": 0.01, p: 200.0}


def test_model_exchange_with_cvode_and_fmusim(native3_fmu, example3_fmus, tmp_path):
    H, N = 0.05, 60
    for fmu, preset in [(native3_fmu, "aucnat")] + [(f, None) for f in example3_fmus.values()]:
        itf = interface_of_fmi3(fmu)
        inputs = _constant_case(itf)
        outs = [v.name for v in itf.outputs]
        names = outs[:outs.index("Y_rear") + 1]
        ref = reference_outputs(itf, [(H, inputs)] + [(H, {})] * (N - 1), preset)
        start = dict(inputs, **({"preset": preset_value(preset)} if preset else {}))
        res = simulate_fmu(str(fmu), fmi_type="ModelExchange", solver="CVode", relative_tolerance=1e-10,
                           stop_time=N * H, output_interval=H, start_values=start, output=names)
        got = np.array([[res[n][k] for n in names] for k in range(1, N + 1)])
        err, name = group_error(got, ref, itf)
        assert err <= 1e-6, (fmu.name, name, err)
        with open(tmp_path / "in.csv", "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["time", *inputs])
            for t in (0.0, N * H):
                w.writerow([t, *inputs.values()])
        for kind, tol in (("cs", 1e-12), ("me", 1e-6)):
            args = [str(FMUSIM), "--interface-type", kind, "--solver", "cvode", "--tolerance", "1e-10",
                    "--stop-time", str(N * H), "--output-interval", str(H), "--input-file", str(tmp_path / "in.csv"),
                    "--output-file", str(tmp_path / "out.csv")]
            if preset:
                args += ["--start-value", "preset", str(preset_value(preset))]
            p = subprocess.run(args + [str(fmu)], capture_output=True, text=True, env=host_env(), timeout=300)
            assert p.returncode == 0, (fmu.name, kind, (p.stdout + p.stderr)[-2000:])
            with open(tmp_path / "out.csv") as f:
                rows = list(csv.DictReader(f))
            got = np.array([[float(r[n]) for n in names] for r in rows[1:N + 1]])
            err, name = group_error(got, ref, itf)
            assert err <= tol, (fmu.name, kind, name, err)


def interface_of_fmi3(fmu):
    """The interface table an FMI 3 FMU was built from (its vehicle.toml, or the presets)."""
    names = zipfile.ZipFile(fmu).namelist()
    if "resources/vehicle.toml" in names:
        from lcvreport.fmu.interface import vehicle_interface
        from lcvreport.model.vehicle_file import loads_vehicle
        return vehicle_interface(loads_vehicle(zipfile.ZipFile(fmu).read("resources/vehicle.toml").decode()))
    return preset_interface()


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed (./build.sh setup installs it)")
def test_fmpy_compile_rebuilds_the_fmi3_fmu(example3_fmus, tmp_path):
    from fmpy import simulate_fmu
    original = example3_fmus["b_double"]
    rebuilt = tmp_path / original.name
    shutil.copy(original, rebuilt)
    p = subprocess.run([str(Path(sys.executable).parent / "fmpy"), "compile", str(rebuilt)], capture_output=True,
                       text=True, cwd=tmp_path, timeout=300)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    inputs = np.array([(0.0, 0.0, 150.0), (1.0, 0.02, 150.0), (4.0, 0.02, 150.0)],
                      dtype=[("time", float), ("delta", float), ("P_b3", float)])
    runs = [simulate_fmu(str(f), stop_time=4.0, output_interval=0.01, step_size=0.01, input=inputs)
            for f in (original, rebuilt)]
    for n in runs[0].dtype.names:
        assert np.array_equal(runs[0][n], runs[1][n]), n


@pytest.mark.parametrize("logging", [True, False])
def test_hostile_fmi3_calls_are_errors_with_a_message(native3_fmu, logging):
    log = Log()
    s, vr, md = _slave(native3_fmu, log, logging=logging)
    dll = s.dll

    def raw(name, argtypes, *args):
        f = getattr(dll, name)
        f.argtypes, f.restype = argtypes, ctypes.c_int
        return f(*args)

    inst = s.component
    V = ctypes.c_void_p
    vrs = (ctypes.c_uint * 2)(vr["u"], vr["delta"])
    vals = (ctypes.c_double * 2)()
    # two value references, one value: refused (every variable is a scalar)
    assert raw("fmi3GetFloat64", [V, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t],
               inst, vrs, 2, vals, 1) == 3
    # a step before initialization
    b = ctypes.c_bool()
    d = ctypes.c_double()
    assert raw("fmi3DoStep", [V, ctypes.c_double, ctypes.c_double, ctypes.c_bool, V, V, V, V], inst, 0.0, 0.1, True,
               ctypes.byref(b), ctypes.byref(b), ctypes.byref(b), ctypes.byref(d)) == 3
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    s.setFloat64([vr["delta"]], [5.0])                 # outside [-1, 1] rad: refused at the step
    assert raw("fmi3DoStep", [V, ctypes.c_double, ctypes.c_double, ctypes.c_bool, V, V, V, V], inst, 0.0, 0.1, True,
               ctypes.byref(b), ctypes.byref(b), ctypes.byref(b), ctypes.byref(d)) == 3
    assert raw("fmi3GetInt32", [V, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t],
               inst, vrs, 1, vals, 1) == 3
    assert raw("fmi3EnterContinuousTimeMode", [V], inst) == 3    # a co-simulation instance
    for fragment in ("values for 2 value references", "must not be called in phase Instantiated", "delta",
                     "no Int32 variables", "must not be called in phase StepComplete"):
        assert any(fragment in m for m in log.errors()), (fragment, log.errors())
    s.terminate()
    s.freeInstance()
    # a wrong instantiation token: NULL and a message, the host lives on
    md2 = read_model_description(str(native3_fmu))
    m = FMU3Model(guid="{not-the-token}", unzipDirectory=extract(str(native3_fmu)),
                  modelIdentifier=md2.modelExchange.modelIdentifier, instanceName="bad")
    log2 = Log()
    with pytest.raises(Exception):
        m.instantiate(logMessage=log2.callback)
    assert any("instantiation token mismatch" in msg for msg in log2.errors())


def test_preset_is_an_enumeration_in_fmi3(native3_fmu):
    """SPEC section 15: ``<EnumerationType name="Preset">`` with the presets as items 1..6, the
    variable an ``<Enumeration>`` starting at 1; fmi3SetInt64/GetInt64 pick and read it, a value
    outside 1..6 is refused with the range named; the name through fmi3SetString still works."""
    import xml.etree.ElementTree as ET
    root = ET.fromstring(zipfile.ZipFile(native3_fmu).read("modelDescription.xml"))
    enum = root.find("TypeDefinitions/EnumerationType[@name='Preset']")
    assert [(i.get("name"), int(i.get("value"))) for i in enum] == [(p, k) for k, p in enumerate(PRESETS, 1)]
    var = root.find("ModelVariables/Enumeration[@name='preset']")
    assert var.get("declaredType") == "Preset" and var.get("start") == "1" and var.get("causality") == "parameter"
    for value, expect_error in ((0, True), (7, True), (6, False)):
        log = Log()
        s, vr, _md = _slave(native3_fmu, log)
        with (pytest.raises(Exception) if expect_error else _nullcontext()):
            s.setInt64([vr["preset"]], [value])
        if expect_error:
            assert any(f"preset: {value} is not a preset; valid: 1 to 6" in m for m in log.errors()), log.errors()
            assert s.getInt64([vr["preset"]]) == [1]
        else:
            assert s.getInt64([vr["preset"]]) == [6] and s.getString([vr["preset"]]) == ["tractor_semitrailer"]
        s.freeInstance()
    log = Log()
    s, vr, _md = _slave(native3_fmu, log)
    s.setString([vr["preset"]], ["legal_max"])
    assert s.getInt64([vr["preset"]]) == [2]
    s.freeInstance()


def _nullcontext():
    import contextlib
    return contextlib.nullcontext()
