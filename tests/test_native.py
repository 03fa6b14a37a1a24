"""build/LCVNative.fmu (C99) beyond what test_fmu.py checks for both FMUs: the same
interface and results as LCV.fmu, no Python at run time, a C host, bad input in the C
host, ecos' command-line runner, memory (valgrind, marked slow)."""
from __future__ import annotations

import csv
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

from lcvreport.cosim import INPUT_NAMES, OUTPUT_NAMES
from lcvreport.linear import eigenvalues
from lcvreport.presets import PRESETS, load_preset

from fmu_support import Slave, assert_outputs_close, fmu_path, reference_outputs, run_schedule, schedule

HERE = Path(__file__).resolve().parent


@pytest.fixture(scope="module")
def native():
    return fmu_path("LCVNative")


@pytest.fixture(scope="module")
def lcv():
    return fmu_path("LCV")


@pytest.fixture(scope="module")
def unzipped(native, tmp_path_factory):
    d = tmp_path_factory.mktemp("native")
    zipfile.ZipFile(native).extractall(d)
    root = ET.parse(d / "modelDescription.xml").getroot()
    vr = {sv.get("name"): int(sv.get("valueReference")) for sv in root.iter("ScalarVariable")}
    return d, root.get("guid"), vr


@pytest.fixture(scope="module")
def c_host(tmp_path_factory):
    exe = tmp_path_factory.mktemp("host") / "c_host"
    subprocess.run(["gcc", "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(exe),
                    str(HERE / "c_host.c"), "-ldl"], check=True)
    return exe


def test_fmpy_validate_finds_no_problem(native):
    p = subprocess.run([str(Path(sys.executable).with_name("fmpy")), "validate", str(native)],
                       capture_output=True, text=True)
    assert p.returncode == 0 and "No problems found" in p.stdout, p.stdout + p.stderr


def test_same_interface_as_lcv_fmu(native, lcv):
    def variables(path):
        root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
        out = []
        for sv in root.iter("ScalarVariable"):
            typ = sv[0]
            out.append((sv.get("name"), sv.get("valueReference"), sv.get("causality"), sv.get("variability"),
                        sv.get("initial"), sv.get("description"), typ.tag, typ.get("unit"), typ.get("displayUnit"),
                        typ.get("start")))
        units = ET.canonicalize(ET.tostring(root.find("UnitDefinitions")), strip_text=True)
        structure = ET.canonicalize(ET.tostring(root.find("ModelStructure")), strip_text=True)
        return out, units, structure, root
    a, b = variables(native), variables(lcv)
    assert a[0] == b[0] and a[1] == b[1] and a[2] == b[2]
    cs = a[3].find("CoSimulation")
    assert cs.get("modelIdentifier") == "LCVNative" and cs.get("needsExecutionTool") == "false"
    names = zipfile.ZipFile(native).namelist()
    assert {"sources/lcv_native.c", "sources/lcv_data.h", "sources/README.txt",
            "binaries/linux64/LCVNative.so"} <= set(names)


def test_binary_needs_only_libc_and_libm(unzipped):
    d, _, _ = unzipped
    so = d / "binaries" / "linux64" / "LCVNative.so"
    needed = subprocess.run(["objdump", "-p", str(so)], capture_output=True, text=True, check=True).stdout
    libs = sorted(line.split()[1] for line in needed.splitlines() if line.strip().startswith("NEEDED"))
    assert set(libs) <= {"libc.so.6", "libm.so.6"}, libs
    undefined = subprocess.run(["nm", "-D", "--undefined-only", str(so)], capture_output=True, text=True).stdout
    assert "Py" not in undefined


@pytest.mark.parametrize("preset", PRESETS)
@pytest.mark.parametrize("steps_seed", [1, 2])
def test_native_and_python_fmus_agree(native, lcv, preset, steps_seed):
    """Same schedules (speed changes incl. clamping, steer, P/T, variable steps) through both FMUs."""
    steps = schedule(np.random.default_rng(100 * steps_seed + PRESETS.index(preset)), 120,
                     [0.001, 0.01, 0.037, 0.25], clamp=True)
    outs = []
    for path in (native, lcv):
        s = Slave(path, preset=preset, tire_scale=0.9).init()
        outs.append(run_schedule(s, steps))
        s.free()
    assert_outputs_close(outs[0], outs[1][:, :], rtol=1e-9)
    assert_outputs_close(outs[0], reference_outputs(preset, steps, tire_scale=0.9), rtol=1e-9)
    np.testing.assert_allclose(outs[0][:, -1], outs[1][:, -1], rtol=1e-9)  # max_real_eig


# ------------------------------------------------------------------ the C host
def _run_host(c_host, unzipped, script: str, env_extra: dict | None = None):
    d, guid, _ = unzipped
    env = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "PYTHONPATH", "PYTHONHOME")}
    env.update(env_extra or {})
    p = subprocess.run([str(c_host), str(d), "LCVNative", guid, "script"], input=script, capture_output=True,
                       text=True, env=env, timeout=120)
    return p


def _script(vr, preset, steps, outputs=OUTPUT_NAMES):
    lines = [f"S {vr['preset']} {preset}", "i", "g " + " ".join(str(vr[o]) for o in outputs)]
    t = 0.0
    for h, inputs in steps:
        for k, v in inputs.items():
            lines.append(f"s {vr[k]} {v!r}")
        lines.append(f"d {t!r} {h!r}")
        lines.append("g " + " ".join(str(vr[o]) for o in outputs))
        t += h
    return "\n".join(lines) + "\n"


def _values(stdout: str) -> np.ndarray:
    rows = [line.split()[2:] for line in stdout.splitlines() if line.startswith("values")]
    return np.array(rows, dtype=float)


@pytest.mark.parametrize("preset", ["aucnat", "tractor_semitrailer", "empty"])
def test_c_host_without_python_matches_fmpy(native, c_host, unzipped, preset):
    steps = schedule(np.random.default_rng(21), 80, [0.002, 0.02, 0.1], clamp=True)
    p = _run_host(c_host, unzipped, _script(unzipped[2], preset, steps))
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), p.stderr
    statuses = [int(line.split()[1]) for line in p.stdout.splitlines() if line.startswith("status")]
    assert all(st == 0 for st in statuses)
    s = Slave(native, preset=preset).init()
    ref = run_schedule(s, steps)
    s.free()
    np.testing.assert_array_equal(_values(p.stdout), ref)


def test_c_host_process_has_no_python(c_host, unzipped):
    """The host maps no libpython: the FMU runs in a process Python never entered."""
    d, guid, vr = unzipped
    script = f"i\ng {vr['y6']}\n"
    p = subprocess.run(["ldd", str(c_host)], capture_output=True, text=True)
    assert "python" not in p.stdout
    p = _run_host(c_host, unzipped, script)
    assert p.returncode == 0 and "done" in p.stdout


BAD_HOST_CASES = [
    ("S {preset} nonsense\ni\nd 0 0.01\n", "preset", [0, 3, 3]),
    ("s {tire_scale} 0\ni\nd 0 0.01\n", "tire_scale", [0, 3, 3]),
    ("s {tire_scale} nan\ni\nd 0 0.01\n", "tire_scale", [0, 3, 3]),
    ("s {u_min} -1\ni\nd 0 0.01\n", "u_min", [0, 3, 3]),
    ("i\ns {P61} nan\nd 0 0.01\n", "P61", [0, 0, 3]),
    ("i\ns {u} inf\nd 0 0.01\n", "u", [0, 0, 3]),
    ("i\ns {delta} -inf\nd 0 0.01\n", "delta", [0, 0, 3]),
    ("i\nd 0 0\n", "step size", [0, 3]),
    ("i\nd 0 nan\n", "step size", [0, 3]),
]


@pytest.mark.parametrize("script, name, expected", BAD_HOST_CASES)
def test_bad_input_in_the_c_host_gives_error_status_and_no_crash(c_host, unzipped, script, name, expected):
    _, _, vr = unzipped
    script = script.format(**vr) + "g " + " ".join(str(vr[o]) for o in OUTPUT_NAMES) + "\n"
    p = _run_host(c_host, unzipped, script)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.stdout, p.stderr)
    statuses = [int(line.split()[1]) for line in p.stdout.splitlines() if line.startswith("status")]
    assert statuses == expected
    assert any(line.startswith("log 3") and name in line for line in p.stdout.splitlines()), p.stdout
    assert np.all(np.isfinite(_values(p.stdout)))


def test_zero_speed_clamps_with_a_warning_in_the_c_host(c_host, unzipped):
    _, _, vr = unzipped
    script = f"i\ns {vr['u']} 0\ns {vr['P61']} 500\n" + f"d 0 0.01\n" * 20 + f"g {vr['y6']} {vr['max_real_eig']}\n"
    p = _run_host(c_host, unzipped, script)
    warnings = [line for line in p.stdout.splitlines() if line.startswith("log 1") and "u_min" in line]
    assert p.returncode == 0 and len(warnings) == 1
    assert np.all(np.isfinite(_values(p.stdout)))


# ------------------------------------------------------------- other masters
def test_ecos_command_line_runner(native, tmp_path):
    import ecospy
    ecos = Path(ecospy.__file__).parent / "binaries" / "ecos"
    os.chmod(ecos, 0o755)
    ssp = tmp_path / "ssp"
    (ssp / "resources").mkdir(parents=True)
    shutil.copy(native, ssp / "resources" / "LCVNative.fmu")
    (ssp / "SystemStructure.ssd").write_text(f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
  xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
  xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues" version="1.0" name="lcv">
  <ssd:System name="lcv"><ssd:Elements>
    <ssd:Component name="truck" source="resources/LCVNative.fmu"><ssd:ParameterBindings><ssd:ParameterBinding>
      <ssd:ParameterValues><ssv:ParameterSet version="1.0" name="init"><ssv:Parameters>
        <ssv:Parameter name="preset"><ssv:String value="tractor_semitrailer"/></ssv:Parameter>
        <ssv:Parameter name="P21"><ssv:Real value="2000"/></ssv:Parameter>
        <ssv:Parameter name="T21"><ssv:Real value="-500"/></ssv:Parameter>
      </ssv:Parameters></ssv:ParameterSet></ssd:ParameterValues>
    </ssd:ParameterBinding></ssd:ParameterBindings></ssd:Component>
  </ssd:Elements></ssd:System>
</ssd:SystemStructureDescription>
""")
    p = subprocess.run([str(ecos), "simulate", "--path", str(ssp), "--stopTime", "2", "--stepSize", "0.01",
                        "--noParallel", "--parameterSet", "init"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    rows = list(csv.reader(open(tmp_path / "ssp.csv")))
    header = [h.strip() for h in rows[0]]
    data = {h: np.array([float(r[i]) for r in rows[1:]]) for i, h in enumerate(header) if h == "time" or h.endswith("[REAL]")}
    steps = [(0.01, {"P21": 2000.0, "T21": -500.0})] + [(0.01, {})] * 199
    ref = reference_outputs("tractor_semitrailer", steps)
    k = [round(t / 0.01) for t in data["time"]]
    for name in ("y2", "thetaA", "Y_rear"):
        col = OUTPUT_NAMES.index(name)
        # the CSV prints 6 decimals
        np.testing.assert_allclose(data[f"truck::{name}[REAL]"], ref[k, col], rtol=0, atol=6e-7)
    assert abs(ref[k[-1], OUTPUT_NAMES.index("y2")]) > 1e-3  # a real response, not zeros


# ------------------------------------------------------------------ memory
@pytest.mark.slow
def test_valgrind_memcheck_one_million_steps(c_host, unzipped):
    d, guid, vr = unzipped
    if shutil.which("valgrind") is None:
        pytest.fail("valgrind is not installed (./build.sh setup installs it)")
    p = subprocess.run(["valgrind", "--tool=memcheck", "--leak-check=full", "--show-leak-kinds=all",
                        "--errors-for-leak-kinds=all", "--error-exitcode=99", str(c_host), str(d), "LCVNative",
                        guid, "bench", "1000000", "0.001", str(vr["P61"]), str(vr["y6"])], capture_output=True, text=True, timeout=3000)
    assert p.returncode == 0, p.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors" in p.stderr
    assert "All heap blocks were freed" in p.stderr
