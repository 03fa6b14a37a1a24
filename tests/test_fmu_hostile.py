"""Hostile input against both FMUs (issue 8): every case in a process of its own, in fmpy
and in a plain C host; the status, the message, finite outputs, and that the host
survives (no fmi2Fatal, no hang, no crash); valgrind over the bad-input script of the
C FMU; memory per instantiate/free cycle."""
from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from fmpy import simulate_fmu

from fmu_support import host_env, host_statuses, host_values, run_host, unzip

HERE = Path(__file__).resolve().parent
ERROR = 3

# case -> (statuses of the calls, a fragment every FMU's messages must contain)
CASES = {
    "unknown_vr": ([ERROR], "9999 is not the value reference"),
    "set_output": ([ERROR], "is not the value reference of an input or a Real parameter"),
    "u_1e308": ([0, ERROR, 0, 0, 0], "u = 1e+308 m/s is above 70 m/s"),
    "u_1e20": ([0, ERROR, 0, 0, 0], "u = 1e+20 m/s is above 70 m/s"),
    "u_nan": ([0, ERROR, 0, 0, 0], "input u is not finite"),
    "u_inf": ([0, ERROR, 0, 0, 0], "input u is not finite"),
    "delta_1e308": ([0, ERROR, 0, 0, 0], "input delta = 1e+308 is outside [-1, 1]"),
    "force_nan": ([0, ERROR, ERROR], "is not finite"),
    "step_zero": ([ERROR, 0, 0], "communication step size must be in [1e-09, 3600] s"),
    "step_nan": ([ERROR, 0, 0], "communication step size must be in"),
    "step_negative": ([ERROR, 0, 0], "communication step size must be in"),
    "step_huge": ([ERROR, 0, 0], "communication step size must be in"),
    "bad_preset": ([ERROR, ERROR, 0], "preset: unknown preset 'AUCNAT'"),
    "tire_scale_huge": ([ERROR, ERROR, 0], "tire_scale must be in [0.01, 100]"),
    "tire_scale_tiny": ([ERROR, ERROR, 0], "tire_scale must be in [0.01, 100]"),
    "tire_scale_nan": ([ERROR, ERROR, 0], "tire_scale must be in"),
    "u_min_huge": ([ERROR, ERROR, 0], "u_min must be in [0.1, 30] m/s"),
    "deserialize_garbage": ([ERROR, 0], "FMU state"),
    "deserialize_empty": ([ERROR, 0], "FMU state"),
    "deserialize_null": ([ERROR], "null"),
    "state_with_nan": (None, "not finite"),
    "state_of_another_fmu": ([ERROR, 0], "not written by this FMU"),
    "exit_init_twice": ([0, ERROR], "ExitInitializationMode"),
    "fixed_parameter_after_init": ([ERROR], "tire_scale is a fixed parameter"),
    "get_integer": ([ERROR], "not the value reference of an Enumeration variable"),
    "set_integer_real": ([ERROR, 0, 0, 0], "not the value reference of an Enumeration variable"),
    "set_integer_range_0": ([ERROR, 0, 0, 0], "preset: 0 is not a preset; valid: 1 to 6"),
    "set_integer_range_7": ([ERROR, 0, 0, 0], "preset: 7 is not a preset; valid: 1 to 6"),
    "set_integer_after_init": ([ERROR], "fmi2SetInteger must not be called in phase StepComplete"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_hostile_call_in_fmpy(preset_fmu, western_fmus, case):
    other = western_fmus["native" if "Native" in preset_fmu.stem else "python"]
    p = subprocess.run([sys.executable, str(HERE / "hostile_driver.py"), str(preset_fmu), case, str(other)],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("survived"), (p.returncode, p.stdout[-2000:],
                                                                          p.stderr[-3000:])
    doc = json.loads(p.stdout.splitlines()[-2])
    statuses, fragment = CASES[case]
    assert 4 not in doc["status"], doc            # never fmi2Fatal
    if statuses is None:
        assert ERROR in doc["status"], doc
    else:
        assert doc["status"] == statuses, doc
    assert any(fragment in m for m in doc["messages"]), doc["messages"]
    assert doc["finite"]


@pytest.mark.parametrize("value", [0, 7, -1])
def test_a_bad_preset_makes_simulate_fmu_raise(preset_fmu, value):
    """Not two rows of zeros: fmpy raises on the error status of fmi2SetInteger (preset is an
    Enumeration of 1 to 6)."""
    with pytest.raises(Exception, match="fmi2SetInteger|status"):
        simulate_fmu(str(preset_fmu), start_values={"preset": value}, stop_time=1.0, step_size=0.01)


@pytest.mark.parametrize("value", [1, 6])
def test_every_preset_value_runs_in_simulate_fmu(preset_fmu, value):
    """The Enumeration's ends pick aucnat and tractor_semitrailer (3 and 2 units: y4 is 0 only for the latter)."""
    res = simulate_fmu(str(preset_fmu), start_values={"preset": value, "delta": 0.01}, stop_time=0.5,
                       step_size=0.01, output=["y2", "y4"])
    assert res["y2"][-1] != 0.0 and ((res["y4"][-1] != 0.0) == (value == 1))


def test_a_nan_input_makes_simulate_fmu_raise(preset_fmu):
    """Not a silently truncated result."""
    signal = np.array([(0.0, 100.0), (0.5, np.nan)], dtype=[("time", float), ("P61", float)])
    with pytest.raises(Exception, match="fmi2DoStep|status"):
        simulate_fmu(str(preset_fmu), start_values={"preset": 1}, stop_time=1.0, step_size=0.01, input=signal)


# ---------------------------------------------------------------------------- the C host
@pytest.fixture(scope="module")
def unzipped_fmus(lcv_fmu, native_fmu, tmp_path_factory):
    return {name: unzip(path, tmp_path_factory.mktemp(name)) for name, path in
            (("LCV", lcv_fmu), ("LCVNative", native_fmu))}


HOST_CASES = [
    ("S {preset} nonsense\ni\nd 0 0.01\n", "preset: unknown preset", [0, 3, 3]),
    ("s {tire_scale} 0\ni\nd 0 0.01\n", "tire_scale must be in", [0, 3, 3]),
    ("s {tire_scale} 1e300\ni\nd 0 0.01\n", "tire_scale must be in", [0, 3, 3]),
    ("s {u_min} -1\ni\nd 0 0.01\n", "u_min must be in", [0, 3, 3]),
    ("i\ns {P61} nan\nd 0 0.01\n", "P61", [0, 0, 3]),
    ("i\ns {u} inf\nd 0 0.01\n", "input u is not finite", [0, 0, 3]),
    ("i\ns {delta} 1e308\nd 0 0.01\ns {delta} 0\nd 0.01 0.01\n", "delta = 1e+308", [0, 0, 3, 0, 0]),
    ("i\nd 0 0\n", "communication step size", [0, 3]),
    ("i\nd 0 nan\n", "communication step size", [0, 3]),
    ("i\nZ 100\nZ 0\n0\n", "FMU state", [0, 3, 3, 3]),
    ("i\nd 0 0.01\nG\nB\nP\n", None, [0, 0, 0, 0, 0]),
    ("i\nd 0 0.01\ni\n", "ExitInitializationMode", [0, 0, 3]),
    ("i\ns {tire_scale} 2\n", "fixed parameter", [0, 3]),
]


@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
@pytest.mark.parametrize("script, fragment, expected", HOST_CASES, ids=[c[0].replace("\n", ";")[:40] for c in HOST_CASES])
def test_hostile_calls_in_a_plain_c_host(c_host, unzipped_fmus, identifier, script, fragment, expected):
    d, _guid, vr = unzipped = unzipped_fmus[identifier]
    outputs = [n for n in vr if n.startswith(("y", "theta", "r", "v1", "ay", "max_real_eig"))]
    text = script.format(**vr) + "g " + " ".join(str(vr[o]) for o in outputs) + "\n"
    p = run_host(c_host, unzipped, identifier, text)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.stdout[-2000:], p.stderr[-2000:])
    assert host_statuses(p.stdout) == expected
    if fragment:
        assert any(line.startswith("log 3") and fragment in line for line in p.stdout.splitlines()), p.stdout
    assert np.all(np.isfinite(host_values(p.stdout)))


def test_nan_in_a_serialized_state_is_refused_with_a_message_by_the_c_fmu(c_host, unzipped_fmus):
    d, _guid, vr = unzipped = unzipped_fmus["LCVNative"]
    from lcvreport.fmu.interface import preset_interface
    n_inputs = len(preset_interface().inputs)
    offset = 4 + 4 + 64 + 64 + 16 + 8 * n_inputs  # z[0] of the snapshot (see fmi2_api.c, model.h)
    p = run_host(c_host, unzipped, "LCVNative", f"i\nd 0 0.01\nG\nN {offset}\nF\n")
    assert host_statuses(p.stdout) == [0, 0, 0, 3, 0]
    assert any(line.startswith("log 3") and "not finite" in line for line in p.stdout.splitlines()), p.stdout


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is installed by ./build.sh setup")
def test_valgrind_over_the_bad_input_script_of_the_c_fmu(c_host, unzipped_fmus):
    d, _guid, vr = unzipped = unzipped_fmus["LCVNative"]
    script = "".join(case[0] for case in HOST_CASES[4:]).format(**vr)
    script = script.replace("i\n", "r\ni\n")          # every case from a fresh initialization
    p = run_host(c_host, unzipped, "LCVNative", "G\n" + script + "F\n", wrapper=[
        "valgrind", "--tool=memcheck", "--leak-check=full", "--errors-for-leak-kinds=all", "--error-exitcode=99"])
    assert p.returncode == 0, p.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors" in p.stderr
    assert "All heap blocks were freed" in p.stderr


@pytest.mark.parametrize("identifier, limit_kb", [("LCVNative", 0.05), ("LCV", 1.5)])
def test_memory_per_instantiate_free_cycle(c_host, unzipped_fmus, identifier, limit_kb):
    """RSS growth per cycle (instantiate, initialize, 10 steps, free) after a warm-up.

    LCVNative: 0.002 KB.  LCV.fmu: 0.85-1.17 KB per cycle over 2,000-cycle windows (steady
    over 8,000 cycles), upstream in pythonfmu 0.7.0's findClass, which runs on every
    fmi2Instantiate and never releases the MRO list, the repr strings and the UTF-8 bytes it
    builds for the slave class (replaying its calls under tracemalloc: 660 B per call; in the
    embedded interpreter the only container the garbage collector sees growing is that list,
    one per instantiation), nor the copy of the resources path it puts on sys.path (the slave
    drops it).  The class defined in fmu_src/LCV.py itself cost 46 KB per cycle: see there."""
    p = run_host(c_host, unzipped_fmus[identifier], identifier, "c 300\nm\nc 2000\nm\n", timeout=900)
    rss = [int(x) for x in re.findall(r"rss_kb (\d+)", p.stdout)]
    per_cycle = (rss[1] - rss[0]) / 2000
    assert p.returncode == 0 and per_cycle <= limit_kb, (per_cycle, p.stdout[-500:])


# ---------------------------------------------------------------------------- round three (issue 22)
@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
@pytest.mark.parametrize("script, expected", [
    ("S {preset} nonsense\ni\n", [0, 3]),                 # a bad parameter at ExitInitializationMode
    ("i\ns {tire_scale} 2\n", [0, 3]),                    # a fixed parameter after initialization
    ("i\ni\n", [0, 3]),                                   # ExitInitializationMode twice
    ("i\nd 0 0.01\nt\nd 0.01 0.01\ns {u} 10\ni\n", [0, 0, 0, 3, 3, 3]),   # calls after fmi2Terminate
    ("D 0\nS {preset} nonsense\ni\nD 1\nd 0 0.01\n", [0, 0, 3, 0, 3]),  # fmi2SetDebugLogging off, then on
], ids=["bad_parameter", "fixed_after_init", "exit_init_twice", "after_terminate", "debug_logging_toggled"])
@pytest.mark.parametrize("logging", ["1", "0"])
def test_statuses_do_not_depend_on_the_logging_flag(c_host, unzipped_fmus, identifier, script, expected, logging):
    """With loggingOn false (fmpy's default) every refused call is still fmi2Error, and its
    error message still reaches the host, as the C FMU has always done."""
    d, _guid, vr = unzipped = unzipped_fmus[identifier]
    if "{preset}" in script and "preset" not in vr:
        pytest.skip("vehicle FMUs have no preset")
    env = {**host_env(), "LCV_HOST_LOGGING": logging}
    p = run_host(c_host, unzipped, identifier, script.format(**vr), env=env)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.stdout[-2000:], p.stderr[-2000:])
    assert host_statuses(p.stdout) == expected, p.stdout
    assert any(line.startswith("log 3") for line in p.stdout.splitlines()), p.stdout


@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
def test_a_percent_sign_in_a_logged_value_does_not_reach_printf_as_a_format(c_host, unzipped_fmus, identifier):
    """The host formats the message (FMIL and this host use vsnprintf): '%s%s%n' from a
    preset string must come back as text, not be read as conversions."""
    d, _guid, vr = unzipped = unzipped_fmus[identifier]
    p = run_host(c_host, unzipped, identifier, f"S {vr['preset']} %s%s%s%n%s\ni\n")
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.returncode, p.stdout[-2000:], p.stderr[-2000:])
    assert host_statuses(p.stdout) == [0, 3]
    assert any("unknown preset '%s%s%s%n%s'" in line for line in p.stdout.splitlines()), p.stdout


@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
def test_getting_the_fmu_state_into_the_same_slot_does_not_grow_memory(c_host, unzipped_fmus, identifier):
    """FMI 2: a non-NULL slot is updated, not leaked (1.5 kB per call before)."""
    p = run_host(c_host, unzipped_fmus[identifier], identifier, "i\nd 0 0.01\nL 500\nm\nL 5000\nm\n", timeout=600)
    rss = [int(x) for x in re.findall(r"rss_kb (\d+)", p.stdout)]
    assert p.returncode == 0 and host_statuses(p.stdout) == [0, 0, 0, 0], p.stdout[-2000:]
    assert (rss[1] - rss[0]) / 5000 < 0.05, rss


def test_a_crafted_state_stepping_without_a_vehicle_is_refused_by_the_c_fmu(c_host, unzipped_fmus):
    """Phase 'step complete' with no vehicle built (taken before initialization, phase
    field rewritten) used to pass the checks and segfault the next doStep."""
    unzipped = unzipped_fmus["LCVNative"]
    from lcvreport.fmu.interface import preset_interface
    n_inputs, max_m = len(preset_interface().inputs), 14     # the preset FMU: 12 states + psi1, Y1
    phase_offset = 4 + 4 + 64 + 64 + 16 + 8 * n_inputs + 8 * max_m + 16 + 4   # see fmi2_api.c, model.h
    p = run_host(c_host, unzipped, "LCVNative", f"G\nK {phase_offset} 4\nP\nd 0 0.01\nF\n")
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.stdout[-2000:], p.stderr[-2000:])
    assert host_statuses(p.stdout) == [0, 3, 0, 3, 0], p.stdout
    assert "was not written by this FMU" in p.stdout


def _run_located(c_host, unzipped, identifier, uri=None, name=None, extra_env=None, script="i\nd 0 0.01\n"):
    env = {**host_env(), **(extra_env or {})}
    if uri is not None:
        env["LCV_HOST_URI"] = uri
    if name is not None:
        env["LCV_HOST_NAME"] = name
    return run_host(c_host, unzipped, identifier, script, env=env)


@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
@pytest.mark.parametrize("form", ["file:///{d}/resources", "file:{d}/resources", "file://localhost{d}/resources",
                                  "file://{d}/resources/", "FILE://{d}/resources"])
def test_every_form_of_a_file_uri_works(c_host, unzipped_fmus, identifier, form):
    d, _guid, _vr = unzipped = unzipped_fmus[identifier]
    uri = form.format(d=str(d)).replace("///" + str(d), "//" + str(d))
    p = _run_located(c_host, unzipped, identifier, uri=uri)
    assert p.returncode == 0 and host_statuses(p.stdout) == [0, 0], (uri, p.stdout[-2000:], p.stderr[-2000:])


@pytest.mark.parametrize("identifier", ["LCV"])
@pytest.mark.parametrize("uri, fragment", [
    ("NULL", "fmuResourceLocation is NULL"),
    ("file:///nonexistent/folder", "does not exist"),
    ("http://example.invalid/resources", "not a file: URI"),
    ("file://otherhost/tmp", "another host"),
    ("file:///tmp/%zz", "bad %-escape"),
    ("file:///tmp/%ff%fe", "not UTF-8"),
    ("relative/folder", "not a file: URI"),
])
def test_a_bad_resource_location_fails_instantiate_with_a_message(c_host, unzipped_fmus, identifier, uri, fragment):
    """Not a SIGSEGV or SIGABRT inside pythonfmu: fmi2Instantiate returns NULL and says why."""
    p = _run_located(c_host, unzipped_fmus[identifier], identifier, uri=uri)
    assert p.returncode == 4 and "instantiate failed" in p.stdout, (p.returncode, p.stdout[-2000:], p.stderr[-2000:])
    assert any(line.startswith("log 3") and fragment in line for line in p.stdout.splitlines()), p.stdout


@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
@pytest.mark.parametrize("encoded", [True, False])
def test_an_fmu_unzipped_under_a_non_ascii_folder_works(c_host, unzipped_fmus, tmp_path, identifier, encoded):
    from urllib.parse import quote
    d, guid, vr = unzipped_fmus[identifier]
    target = tmp_path / "ü dir ñ"
    shutil.copytree(d, target)
    uri = "file://" + (quote(str(target)) if encoded else str(target)) + "/resources"
    p = _run_located(c_host, (target, guid, vr), identifier, uri=uri)
    assert p.returncode == 0 and host_statuses(p.stdout) == [0, 0], (uri, p.stdout[-2000:], p.stderr[-2000:])


@pytest.mark.parametrize("identifier", ["LCV", "LCVNative"])
def test_a_null_instance_name_works(c_host, unzipped_fmus, identifier):
    p = _run_located(c_host, unzipped_fmus[identifier], identifier, name="NULL", script="S 999999 x\ni\nd 0 0.01\n")
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.returncode, p.stdout[-2000:], p.stderr[-2000:])
    assert host_statuses(p.stdout)[1:] == [0, 0]


def _python_paths():
    import sysconfig
    import numpy
    lib = Path(sysconfig.get_config_var("LIBDIR")) / sysconfig.get_config_var("INSTSONAME")
    return str(lib), sys.base_prefix, str(Path(numpy.__file__).resolve().parents[1])


def test_the_readme_recipe_for_another_machine_works_without_a_python_home(c_host, tmp_path):
    """An FMU built elsewhere (its recorded libpython, home and site-packages do not exist
    here), run as the README says: LCV_FMU_LIBPYTHON and LCV_FMU_SITE_PACKAGES set,
    LCV_FMU_PYTHONHOME not (optional).  The home is found from the library; before, the
    host exited in fmi2Instantiate ("Fatal Python error: init_fs_encoding")."""
    from lcvreport.fmu.build import build_python_fmu
    from lcvreport.fmu.interface import preset_interface
    lib, _home, site = _python_paths()
    elsewhere = {"libpython": "/elsewhere/lib/libpython3.11.so.1.0", "home": "/elsewhere",
                 "site_packages": "/elsewhere/lib/python3.11/site-packages", "version": "3.11"}
    fmu = build_python_fmu(preset_interface(), tmp_path / "built", "LCV", env=elsewhere)
    unzipped = unzip(fmu, tmp_path / "LCV")
    p = run_host(c_host, unzipped, "LCV", "i\nd 0 0.01\n")
    assert p.returncode == 4 and "cannot load the Python library /elsewhere" in p.stdout, p.stdout[-2000:]
    p = _run_located(c_host, unzipped, "LCV", extra_env={"LCV_FMU_LIBPYTHON": lib, "LCV_FMU_SITE_PACKAGES": site})
    assert p.returncode == 0 and host_statuses(p.stdout) == [0, 0], (p.returncode, p.stdout[-2000:], p.stderr[-2000:])


@pytest.mark.parametrize("variable, value, fragment", [
    ("LCV_FMU_PYTHONHOME", "/nonexistent/python", "has no standard library"),
    ("LCV_FMU_PYTHONHOME", "/tmp", "has no standard library"),
    ("LCV_FMU_LIBPYTHON", "/nonexistent/libpython3.11.so", "cannot load the Python library"),
    ("LCV_FMU_LIBPYTHON", "/lib/x86_64-linux-gnu/libm.so.6", "is not a Python library"),
    ("LCV_FMU_SITE_PACKAGES", "/nonexistent/site-packages", "does not exist"),
])
def test_a_wrong_python_setting_fails_instantiate_with_a_message(c_host, unzipped_fmus, variable, value, fragment):
    p = _run_located(c_host, unzipped_fmus["LCV"], "LCV", extra_env={variable: value})
    assert p.returncode == 4 and "instantiate failed" in p.stdout, (p.returncode, p.stdout[-2000:], p.stderr[-2000:])
    assert any(line.startswith("log 3") and fragment in line for line in p.stdout.splitlines()), p.stdout


def test_the_hosts_own_pythonhome_does_not_reach_the_fmus_interpreter(c_host, unzipped_fmus):
    """The interpreter the FMU starts is isolated: a PYTHONHOME meant for something else
    in the host's environment neither breaks it nor changes it."""
    p = _run_located(c_host, unzipped_fmus["LCV"], "LCV", extra_env={"PYTHONHOME": "/nonexistent",
                                                                      "PYTHONPATH": "/nonexistent"})
    assert p.returncode == 0 and host_statuses(p.stdout) == [0, 0], (p.returncode, p.stdout[-2000:], p.stderr[-2000:])


def test_a_site_packages_path_is_never_run_as_code(c_host, unzipped_fmus, tmp_path):
    evil = tmp_path / "x''');import os;os._exit(7);r'''"     # pasted into r'''...''' it would exit the host
    evil.mkdir()
    p = _run_located(c_host, unzipped_fmus["LCV"], "LCV", extra_env={"LCV_FMU_SITE_PACKAGES": str(evil)})
    # numpy may or may not be importable without the venv's site-packages (it is when the
    # base Python has one); either way the host lives on
    assert p.returncode in (0, 4) and p.stdout.rstrip().endswith(("done", "instantiate failed")), \
        (p.returncode, p.stdout[-2000:], p.stderr[-2000:])
