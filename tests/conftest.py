"""Shared fixtures: presets, example vehicles, the FMUs (built once per test worker)."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from lcvreport.model.presets import load_preset
from lcvreport.model.vehicle_file import load_vehicle

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
EXAMPLES = ROOT / "examples" / "vehicles"


def _fmi_tools() -> Path:
    """The independent FMI importers: ``$LCV_FMI_TOOLS``, else ``../shared/tools`` beside the
    checkout (where CI has them), else ``/work/shared/tools`` (a clone made elsewhere on this
    machine). The tests that use them fail, not skip, when none of these holds them."""
    candidates = [Path(os.environ["LCV_FMI_TOOLS"])] if os.environ.get("LCV_FMI_TOOLS") else []
    candidates += [ROOT.parent / "shared" / "tools", Path("/work/shared/tools")]
    for path in candidates:
        if (path / "fmuCheck.linux64").exists():
            return path
    return candidates[0]


TOOLS = _fmi_tools()
EXAMPLE_NAMES = ("western_double", "b_double", "truck_full_trailer")

# Scripts run by hand (the snapshot maker runs at commit 7c31b7f), not test modules.
collect_ignore = ["data", "hostile_driver.py"]


# ---------------------------------------------------------------------------- reports built once
# Session fixtures (a module fixture is torn down and built again whenever xdist interleaves
# another module's test); every test using one carries the fixture's xdist group, so that a run
# under --dist loadgroup builds each report once.
def build_thesis_report(build_dir: Path, *extra: str) -> subprocess.CompletedProcess:
    """``python -m lcvreport.report.build --fast`` into ``build_dir``."""
    return subprocess.run([sys.executable, "-m", "lcvreport.report.build", "--build-dir", str(build_dir), "--fast",
                           *extra], capture_output=True, text=True, cwd=ROOT, timeout=900)


@pytest.fixture(scope="session")
def thesis_report(tmp_path_factory):
    """The thesis report (fast, with its PDF): xdist group ``thesis_report``."""
    d = tmp_path_factory.mktemp("report1")
    p = build_thesis_report(d)
    assert p.returncode == 0, p.stderr[-4000:]
    return d


TRACKING_STATS = "conicity=normal:0:120,ply_steer=normal:40:60,mounting=random,draws=200000,seed=7"
MOUNTED = EXAMPLES.parent / "tires" / "aucnat_rear_trailers_mounted.csv"
#: the vehicle reports (lcv report): an example file, and a preset with loads and the tracking chapter
ASSESSMENTS = {"western_double": ["--vehicle", str(EXAMPLES / "western_double.toml")],
               "aucnat": ["--preset", "aucnat", "--load", "trailer2,trailer3", "--tires", str(MOUNTED),
                          "--tracking-stats", TRACKING_STATS]}


@pytest.fixture(scope="session", params=sorted(ASSESSMENTS))
def assessment(request, tmp_path_factory):
    """(name, folder, completed process) of ``lcv report`` of :data:`ASSESSMENTS`: xdist group ``assessment``."""
    out = tmp_path_factory.mktemp(f"assess_{request.param}")
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "report", *ASSESSMENTS[request.param], "--speed-kph",
                        "88", "--out", str(out)], capture_output=True, text=True, timeout=600, cwd=out.parent)
    assert p.returncode == 0, (p.stdout + p.stderr)[-4000:]
    return request.param, out, p


SCHEME_TEMPLATE = ROOT / "examples" / "schemes" / "template.toml"


@pytest.fixture(scope="session")
def scheme_report(tmp_path_factory):
    """(folder, vehicle file, --json document) of ``lcv assess --out`` of the b-double against the
    template scheme: xdist group ``scheme_report``."""
    import json
    out = tmp_path_factory.mktemp("assess") / "report"
    vehicle = EXAMPLES / "b_double.toml"
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "assess", "--vehicle", str(vehicle), "--scheme",
                        str(SCHEME_TEMPLATE), "--out", str(out), "--json"], capture_output=True, text=True,
                       timeout=600)
    assert p.returncode == 0, p.stderr
    return out, vehicle, json.loads(p.stdout)


@pytest.fixture(scope="session")
def aucnat():
    return load_preset("aucnat")


@pytest.fixture(scope="session")
def semi():
    return load_preset("tractor_semitrailer")


@pytest.fixture(scope="session", params=EXAMPLE_NAMES)
def example(request):
    return load_vehicle(EXAMPLES / f"{request.param}.toml")


def _preset_fmu(name: str) -> Path:
    path = BUILD / f"{name}.fmu"
    if not path.exists():
        subprocess.run([sys.executable, "-m", "lcvreport.fmu.build", "--out", str(BUILD)], check=True, cwd=ROOT)
    assert path.exists(), f"{path} missing: run ./build.sh fmu"
    return path


@pytest.fixture(scope="session")
def lcv_fmu():
    """build/LCV.fmu (pythonfmu, SPEC section 5)."""
    return _preset_fmu("LCV")


@pytest.fixture(scope="session")
def native_fmu():
    """build/LCVNative.fmu (C99, SPEC section 5)."""
    return _preset_fmu("LCVNative")


@pytest.fixture(scope="session", params=["LCV", "LCVNative"])
def preset_fmu(request):
    return _preset_fmu(request.param)


def _vehicle_fmus(out: Path, name: str) -> dict:
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "fmu", "--vehicle", str(EXAMPLES / f"{name}.toml"),
                        "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return {"python": out / f"{name}.fmu", "native": out / f"{name}Native.fmu"}


@pytest.fixture(scope="session")
def western_fmus(tmp_path_factory):
    """Both FMUs of examples/vehicles/western_double.toml, built by lcv fmu."""
    return _vehicle_fmus(tmp_path_factory.mktemp("western_fmus"), "western_double")


@pytest.fixture(scope="session")
def all_example_fmus(tmp_path_factory, western_fmus):
    """Both FMUs of every example vehicle, built by lcv fmu: {name: {"python": ..., "native": ...}}."""
    return {name: western_fmus if name == "western_double" else _vehicle_fmus(tmp_path_factory.mktemp(name), name)
            for name in EXAMPLE_NAMES}


@pytest.fixture(scope="session", params=EXAMPLE_NAMES)
def example_fmus(request, all_example_fmus):
    """(name, {"python": ..., "native": ...}) for each example vehicle."""
    return request.param, all_example_fmus[request.param]


@pytest.fixture(scope="session")
def c_host(tmp_path_factory):
    """tests/c_host.c compiled: a plain C FMI host (no Python in the process)."""
    exe = tmp_path_factory.mktemp("host") / "c_host"
    subprocess.run(["gcc", "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(exe),
                    str(ROOT / "tests" / "c_host.c"), "-ldl"], check=True)
    return exe
