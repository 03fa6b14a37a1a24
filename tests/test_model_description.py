"""modelDescription.xml as FMI 2.0.4 and Reference-FMUs have it (issue 20): one test per
deviation that was found, on the preset FMUs and on the FMUs of every example vehicle."""
from __future__ import annotations

import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

from lcvreport.fmu.interface import QUANTITIES
from lcvreport.ranges import RANGES

from fmu_support import interface_of


def _xml(path):
    return ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))


@pytest.fixture(scope="module")
def every_fmu(lcv_fmu, native_fmu, all_example_fmus):
    out = [("LCV", lcv_fmu, False), ("LCVNative", native_fmu, True)]
    for name, fmus in all_example_fmus.items():
        out += [(name, fmus["python"], False), (f"{name}Native", fmus["native"], True)]
    return out


def test_dependencies_are_in_ascending_order(every_fmu):
    for name, path, _native in every_fmu:
        for unknown in _xml(path).iter("Unknown"):
            deps = [int(d) for d in (unknown.get("dependencies") or "").split()]
            assert deps == sorted(deps) and len(set(deps)) == len(deps), (name, unknown.attrib)


def test_sources_are_listed_and_the_official_headers_not_shipped(every_fmu):
    for name, path, native in every_fmu:
        names = zipfile.ZipFile(path).namelist()
        official = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
        assert not [n for n in names if n.split("/")[-1] in official], name
        root = _xml(path)
        if native:
            for kind in ("ModelExchange", "CoSimulation"):
                files = [f.get("name") for f in root.find(kind).iter("File")]
                assert files == ["fmi2_api.c", "fmu_common.c", "model.c", "linalg.c"], (name, kind)
            assert all(f"sources/{f}" in names for f in files), name


@pytest.mark.skipif(shutil.which("cmake") is None, reason="cmake is not installed (./build.sh setup installs it)")
def test_fmpy_compile_rebuilds_the_native_fmu_with_identical_results(tmp_path, all_example_fmus):
    """`fmpy compile` (its CMake project and its copy of the official headers) from sources/
    alone: the rebuilt binary gives the same numbers, bit for bit."""
    from fmpy import simulate_fmu
    original = all_example_fmus["b_double"]["native"]
    rebuilt = tmp_path / original.name
    shutil.copy(original, rebuilt)
    with zipfile.ZipFile(rebuilt) as zf:
        before = zf.read(f"binaries/linux64/{original.stem}.so")
    p = subprocess.run([str(Path(sys.executable).parent / "fmpy"), "compile", str(rebuilt)], capture_output=True,
                       text=True, cwd=tmp_path, timeout=300)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    with zipfile.ZipFile(rebuilt) as zf:
        assert zf.read(f"binaries/linux64/{original.stem}.so") != before          # it really was rebuilt
    inputs = np.array([(0.0, 0.0, 150.0), (1.0, 0.02, 150.0), (4.0, 0.02, 150.0)],
                      dtype=[("time", float), ("delta", float), ("P_b3", float)])
    runs = [simulate_fmu(str(f), stop_time=4.0, output_interval=0.01, step_size=0.01, input=inputs,
                         fmi_call_logger=None) for f in (original, rebuilt)]
    for n in runs[0].dtype.names:
        assert np.array_equal(runs[0][n], runs[1][n]), n


def test_every_input_and_parameter_has_the_range_the_fmu_enforces(every_fmu):
    expect = {"tire_scale": RANGES["tire_scale"], "u_min": RANGES["u_min"], "crossfall": RANGES["crossfall"],
              "delta": RANGES["steer_angle"]}
    prefix = {"P": RANGES["residual_force"], "T": RANGES["residual_moment"], "eps": RANGES["misalignment"]}
    for name, path, _native in every_fmu:
        for sv in _xml(path).iter("ScalarVariable"):
            if sv.get("causality") not in ("input", "parameter") or sv[0].tag != "Real":
                continue
            real, vname = sv[0], sv.get("name")
            if vname == "u":                           # clamped below u_min, refused above 70 m/s
                assert real.get("min") is None and float(real.get("max")) == RANGES["speed"].high
                continue
            r = expect.get(vname) or next(r for p, r in prefix.items() if vname.startswith(p) and
                                          vname[len(p):].lstrip("_")[:1].isalnum())
            assert (float(real.get("min")), float(real.get("max"))) == (r.low, r.high), (name, vname)


def test_python_fmus_say_they_need_a_python(every_fmu):
    for name, path, native in every_fmu:
        cs = _xml(path).find("CoSimulation")
        assert cs.get("needsExecutionTool") == ("false" if native else "true"), name


def test_documentation_with_dependencies_and_licenses(every_fmu):
    for name, path, native in every_fmu:
        zf = zipfile.ZipFile(path)
        index = zf.read("documentation/index.html").decode()
        lic = zf.read("documentation/licenses/license.txt").decode()
        assert "MIT License" in lic
        if native:
            assert "C library and libm" in index
            assert "FMI 2.0 Co-Simulation and Model Exchange FMU" in index, name     # both interfaces
        else:
            assert "CPython 3.11" in index and "numpy" in index and "pythonfmu 0.7.0" in lic
            assert "FMI 2.0 Co-Simulation FMU" in index, name


def test_display_units_and_quantities(every_fmu, all_example_fmus):
    """Every Real has a declared type with a quantity; in the vehicle FMUs m/s2, 1/s, N, N.m
    and m have a display unit, each defined under its unit."""
    vehicle_fmus = {str(f["native"]) for f in all_example_fmus.values()} | \
        {str(f["python"]) for f in all_example_fmus.values()}
    for name, path, _native in every_fmu:
        root = _xml(path)
        displays = {(u.get("name"), d.get("name")) for u in root.iter("Unit") for d in u.iter("DisplayUnit")}
        types = {t.get("name"): t[0] for t in root.find("TypeDefinitions") if t[0].tag == "Real"}
        assert {t.get("quantity") for t in types.values()} <= set(QUANTITIES.values())
        for sv in root.iter("ScalarVariable"):
            real = sv[0]
            if real.tag != "Real":
                continue
            if sv.get("causality") == "local":             # der(x): the unit of the state's derivative
                assert real.get("derivative") and real.get("unit"), (name, sv.get("name"))
                continue
            declared = types[real.get("declaredType")]
            assert declared.get("quantity") and declared.get("unit") == real.get("unit"), (name, sv.get("name"))
            if real.get("displayUnit"):
                assert (real.get("unit"), real.get("displayUnit")) in displays, (name, sv.get("name"))
            if str(path) in vehicle_fmus and real.get("unit") in ("m/s2", "1/s", "N", "N.m", "m"):
                assert real.get("displayUnit"), (name, sv.get("name"))


def test_the_interface_table_and_the_xml_agree(every_fmu):
    for name, path, native in every_fmu:
        itf = interface_of(path)
        svs = list(_xml(path).iter("ScalarVariable"))
        assert [sv.get("name") for sv in svs if sv.get("causality") != "local"] == [v.name for v in itf.variables]
        ders = [sv for sv in svs if sv.get("causality") == "local"]
        if native:                                         # der(x) of every Model Exchange state, in order
            index = {sv.get("name"): k + 1 for k, sv in enumerate(svs)}
            assert [sv.get("name") for sv in ders] == [f"der({v.name})" for v in itf.continuous_states], name
            assert [int(sv[0].get("derivative")) for sv in ders] == [index[v.name] for v in itf.continuous_states]
        else:
            assert ders == [], name


def test_the_fmus_carry_the_package_version(every_fmu):
    """modelDescription.xml's version is the package's (0.2.0 was written into 0.3.0's FMUs)."""
    import lcvreport
    for name, path, _native in every_fmu:
        assert _xml(path).get("version") == lcvreport.__version__, name
