"""Hostile calls against both FMI 3.0 FMUs (issue 20): build/LCVNative3.fmu and build/LCV3.fmu
(the Python FMU behind pythonfmu3 and loader3.c), every case in a process of its own through the
raw API (tests/hostile_driver3.py), with logging on and off: no abort, no fmi3Fatal, the error
status and a message naming what was wrong whatever the logging flag, finite values; and the
Python FMU leaves a Python host's sys.path and meta-path finders as it found them, running its
own bundled package when the host imported another lcvreport first."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import BUILD, ROOT

HERE = Path(__file__).resolve().parent
E = 3          # fmi3Error
ANY = None     # status not checked (the two FMUs differ, both allowed by the standard)

# case -> (statuses or None, message fragment or None), per kind where they differ
CASES = {
    "bad_token": ([E], "instantiation token mismatch"),
    "step_before_init": ([E], "must not be called in phase Instantiated"),
    "count_mismatch": ([E], "values for 2 value references"),
    "null_arrays": ([E, E], "null array"),
    "unknown_vr": ([E], "99999 is not the value reference"),
    "types_it_has_none_of": ([E] * 18, "this FMU has no Float32 variables"),
    "enumeration_range": ([E, 0, 0, 0, 0], "preset: 7 is not a preset; valid: 1 to 6"),
    "enumeration_after_init": ([0, 0, E], "fmi3SetInt64 must not be called in phase"),
    "set_output": ([0, 0, E], "is not the value reference of an input"),
    "u_nan": ([0, 0, 0, E, 0, 0, 0], "input u is not finite"),
    "u_huge": ([0, 0, 0, E, 0, 0, 0], "u = 1e+308 m/s is above 70 m/s"),
    "delta_huge": ([0, 0, 0, E, 0, 0, 0], "input delta = 1e+308 is outside [-1, 1]"),
    "step_negative": ([0, 0, E, 0, 0], "communication step size must be in"),
    "step_nan": ([0, 0, E, 0, 0], "communication step size must be in"),
    "tire_scale_nan": (None, "tire_scale must be in"),
    "deserialize_garbage": ([0, 0, E, E, E, 0], "null pointer"),
    "state_round_trip": ([0] * 13, None),
    "events_and_clocks": ([0, 0, E, ANY, E, E, E, E, E, 0, 0], None),
    "terminate_then_step": ([0, 0, 0, E, 0, 0, 0, 0, 0], "must not be called in phase Terminated"),
    # issue 28 (round four): time that is not a number, the time an FMU state keeps, calls of Event
    # Mode in Step Mode, derivatives the README says are refused, one status for a clamped step
    "start_time_not_finite": ([E, E, 0, 0, 0, 0], "startTime is not finite"),
    "communication_point_not_finite": ([0, 0, E, E, 0, 0, 0], "currentCommunicationPoint is not finite"),
    "set_state_restores_time": ([0] * 20, "times=[0.05, 0.02, 0.02]"),
    "step_mode_calls": ([0, 0, E, E, 0], None),
    "directional_in_init": ([0, E, E, E, 0], "not a continuous state or an input other than u"),
    "clamped_step_status": ([0, 0, 0, 1, 0, 0], "is below u_min"),
}
# what only one of the two does (the native FMU has Model Exchange and needs no resources)
PER_KIND = {
    "python": {"bad_resources": ([E], "is not this FMU's resources folder"),
               "null_resources": ([E], "resourcePath is NULL"),
               "event_mode": ([E], "has no event mode"),
               "model_exchange_of_cs_only": ([E], "is a Co-Simulation FMU"),
               "deserialize_garbage": ([0, 0, E, E, E, 0], "not an FMU state written by this FMU"),
               "instance_name_not_utf8": ([E], "the instanceName is not UTF-8 text"),
               "directional_in_init": ([0, E, E, E, E], None)},      # it provides no directional derivative
    "native": {"model_exchange_of_cs_only": ([0, 0, 0, E], None),
               "model_exchange_calls": ([0, 0, 0, 0, 0, E, E, E, E, E, E, 0, E, 0, 0, 0], "states given, this FMU has 14"),
               "deserialize_garbage": ([0, 0, E, E, E, 0], "serialized FMU state of 1024 bytes: expected"),
               "instance_name_not_utf8": ([0, 0, 0, 0, 0], None),   # the name is only copied and logged
               "me_state_round_trip": ([0] * 12, "restored=True"),
               "cs_state_into_me": ([0, 0, 0, 0, 0, 0, E, E, 0], "written by a Co-Simulation instance"),
               "event_mode_twice": ([0, 0, E, 0, 0], "must not be called in phase")},
}


@pytest.fixture(scope="session")
def fmi3_fmus(native_fmu):
    paths = {"native": BUILD / "LCVNative3.fmu", "python": BUILD / "LCV3.fmu"}
    if not all(p.exists() for p in paths.values()):
        subprocess.run([sys.executable, "-m", "lcvreport.fmu.build", "--out", str(BUILD)], check=True, cwd=ROOT)
    return paths


def _drive(fmu: Path, case: str, logging: bool, *extra: str) -> dict:
    p = subprocess.run([sys.executable, str(HERE / "hostile_driver3.py"), str(fmu), case, "1" if logging else "0",
                        *extra], capture_output=True, text=True, timeout=180)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("survived"), (p.returncode, p.stdout[-2000:],
                                                                          p.stderr[-3000:])
    return json.loads(p.stdout.splitlines()[-2])


ALL = [(k, c) for k in ("native", "python") for c in sorted(set(CASES) | set(PER_KIND[k]))]


@pytest.mark.parametrize("logging", [True, False], ids=["logging", "quiet"])
@pytest.mark.parametrize("kind,case", ALL, ids=[f"{k}-{c}" for k, c in ALL])
def test_hostile_fmi3_call(fmi3_fmus, kind, case, logging):
    statuses, fragment = PER_KIND[kind].get(case) or CASES[case]
    doc = _drive(fmi3_fmus[kind], case, logging)
    assert not doc["fatal"], doc                       # never fmi3Fatal
    if statuses is None:
        assert E in doc["status"], doc
    else:
        assert len(doc["status"]) == len(statuses), doc
        assert all(s is ANY or s == g for s, g in zip(statuses, doc["status"])), doc
    if fragment:                                       # errors are logged whatever the flag
        assert any(fragment in m for m in doc["messages"]), doc["messages"]
    assert doc["finite"], doc


@pytest.mark.parametrize("fake", [False, True], ids=["plain", "other-lcvreport-first"])
def test_python_fmi3_fmu_leaves_a_python_host_as_it_found_it(fmi3_fmus, tmp_path, fake):
    """sys.path and sys.meta_path unchanged after fmi3FreeInstance; with a stand-in lcvreport
    imported first, the FMU still runs its own bundled package (r1 equals the native FMU's)."""
    extra = ()
    if fake:
        pkg = tmp_path / "fake" / "lcvreport"
        pkg.mkdir(parents=True)
        (pkg / "__init__.py").write_text("raise_if_used = True\n")
        extra = (str(tmp_path / "fake"),)
    got = _drive(fmi3_fmus["python"], "host_hygiene", True, *extra)
    ref = _drive(fmi3_fmus["native"], "host_hygiene", True)
    assert got["changed"] == {"path": [], "meta": []}, got["changed"]
    r1 = [float(m[3:]) for m in got["messages"] if m.startswith("r1=")]
    r1_ref = [float(m[3:]) for m in ref["messages"] if m.startswith("r1=")]
    # the two FMUs compute the same exact step in different code (numpy, C): to rounding
    assert len(r1) == len(r1_ref) == 1 and r1_ref[0] != 0.0 and abs(r1[0] - r1_ref[0]) <= 1e-12 * abs(r1_ref[0])
