"""The ``lcv`` command-line contract: presets and vehicle files, every command, and every
hostile argument of issue 8 (no traceback, no inf/NaN with status 0, broken pipes,
closed and full outputs, streaming in constant memory)."""
from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
import time

import numpy as np
import pytest
from conftest import EXAMPLE_NAMES, EXAMPLES

from lcvreport.analysis.modes import eigenvalues
from lcvreport.analysis.steady import steady_state
from lcvreport.cli.main import EXIT_BROKEN_PIPE, run
from lcvreport.model.linear import linear_model
from lcvreport.model.presets import PRESETS, load_preset
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.model.yaw_plane.equations import system_matrices
from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule
from lcvreport.model.yaw_plane.outputs import rear_offsets
from lcvreport.ranges import RANGES
from lcvreport.units import THESIS
from helpers import with_default_sigint

MPS_PER_MPH = 0.44704       # typed here on purpose
WESTERN = str(EXAMPLES / "western_double.toml")


def lcv(*argv):
    out = io.StringIO()
    code = run(list(argv), out=out)
    return code, out.getvalue()


def lcv_json(*argv):
    code, text = lcv(*argv, "--json")
    assert code == 0
    return json.loads(text)


def lcv_process(*argv, **kw):
    """``lcv`` as users run it: the console script, a fresh process."""
    exe = shutil.which("lcv", path=os.path.dirname(sys.executable))
    assert exe, "the console script lcv is not installed next to the test interpreter"
    return subprocess.run([exe, *argv], capture_output=True, text=True, timeout=120, **kw)


# ---------------------------------------------------------------------------- the contract
def test_console_script_is_installed_and_answers():
    p = lcv_process("eig", "--preset", "aucnat", "--speed-mph", "50", "--json")
    assert p.returncode == 0 and len(json.loads(p.stdout)["eigenvalues"]) == 12


@pytest.mark.parametrize("preset", PRESETS)
def test_eig_json(preset):
    doc = lcv_json("eig", "--preset", preset, "--speed-mph", "45", "--tire-scale", "0.8")
    lam = np.array([complex(a, b) for a, b in doc["eigenvalues"]])
    # the CLI uses the generalized eigenproblem (S, M); eigenvalues() eig(M^-1 S): equal to rounding
    np.testing.assert_allclose(lam, eigenvalues(load_preset(preset), 45 * MPS_PER_MPH, 0.8), rtol=1e-10)
    k = doc["least_damped_mode"] - 1
    assert doc["damping_ratio"][k] == min(z for z, (_r, i) in zip(doc["damping_ratio"], doc["eigenvalues"]) if i > 0)


def test_eig_text_marks_the_least_damped_mode():
    code, text = lcv("eig", "--vehicle", WESTERN, "--speed-kph", "88")
    assert code == 0 and sum(line.endswith(" *") for line in text.splitlines()) == 2
    assert "western_double at 88 km/h" in text


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_every_command_works_on_every_example(name):
    path = str(EXAMPLES / f"{name}.toml")
    v = load_vehicle(path)
    last = v.unit_names[-1]
    eig = lcv_json("eig", "--vehicle", path, "--speed-kph", "88")
    assert len(eig["eigenvalues"]) == linear_model(v).n_states
    steady = lcv_json("steady", "--vehicle", path, "--speed-kph", "88", "--load", last)
    x = steady_state(v, 88 / 3.6, load_vector(v, one_percent_rule(v, [last])))
    assert steady["state"]["r1"] == pytest.approx(x[1], rel=1e-12)
    assert steady["y"][f"y{v.n_units}"] == pytest.approx(rear_offsets(v, x[v.n_units + 1:])[-1], rel=1e-12)
    code, csv = lcv("simulate", "--vehicle", path, "--speed-kph", "88", "--load", last, "--t-end", "2", "--dt", "0.5")
    rows = csv.strip().splitlines()
    assert code == 0 and len(rows) == 6
    header = rows[0].split(",")
    assert header[:3] == ["time_s", "delta_rad", "v1_m_per_s"] and header[-1] == f"y{v.n_units}_m"
    assert f"ay{v.n_units}_m_per_s2" in header and "psi1_rad" in header and "Y1_m" in header
    assert all(f"Y_{a.name}_m" in header for a in v.axles)
    mats = lcv_json("matrices", "--vehicle", path, "--speed-kph", "88")
    assert mats["units"].startswith("SI")
    np.testing.assert_allclose(mats["M"], system_matrices(v, 88 / 3.6)[0], rtol=1e-14)


def test_matrices_json_in_thesis_units_for_presets():
    doc = lcv_json("matrices", "--preset", "tractor_semitrailer", "--speed-mph", "50")
    assert doc["state"] == ["v1", "r1", "r2", "thetaA"] and "F" not in doc and doc["units"].startswith("thesis")
    M, S = system_matrices(load_preset("tractor_semitrailer"), 50 * MPS_PER_MPH, units=THESIS)
    np.testing.assert_allclose(doc["M"], M, rtol=1e-14)
    np.testing.assert_allclose(doc["S"], S, rtol=1e-14)
    doc_t = lcv_json("matrices", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,trailer3",
                     "--convention", "thesis")
    doc_c = lcv_json("matrices", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,trailer3")
    np.testing.assert_allclose(np.array(doc_c["F"])[1:7], 12 * np.array(doc_t["F"])[1:7], rtol=1e-12)
    si = lcv_json("matrices", "--preset", "aucnat", "--speed-mph", "50", "--units", "si")
    np.testing.assert_allclose(si["M"], system_matrices(load_preset("aucnat"), 50 * MPS_PER_MPH)[0], rtol=1e-14)


def test_steady_json_in_si():
    doc = lcv_json("steady", "--preset", "aucnat", "--speed-mph", "30", "--load", "trailer2,trailer3")
    v = load_preset("aucnat")
    x = steady_state(v, 30 * MPS_PER_MPH, load_vector(v, one_percent_rule(v, ["trailer2", "trailer3"])))
    assert doc["state"]["v1"] == pytest.approx(x[0], rel=1e-12)
    assert doc["state"]["thetaC"] == pytest.approx(x[9], rel=1e-12)
    assert doc["y"]["y6"] == pytest.approx(rear_offsets(v, x[7:])[-1], rel=1e-12)


def test_speed_in_kph_and_mph_agree():
    a = lcv_json("eig", "--preset", "aucnat", "--speed-kph", str(50 * 1.609344))
    b = lcv_json("eig", "--preset", "aucnat", "--speed-mph", "50")
    np.testing.assert_allclose(a["eigenvalues"], b["eigenvalues"], rtol=1e-10)


def test_simulate_json_is_honoured_and_equals_the_csv():
    code, text = lcv("simulate", "--preset", "tractor_semitrailer", "--speed-mph", "50", "--load", "trailer1",
                     "--t-end", "1", "--dt", "0.25", "--json")
    doc = json.loads(text)
    code2, csv = lcv("simulate", "--preset", "tractor_semitrailer", "--speed-mph", "50", "--load", "trailer1",
                     "--t-end", "1", "--dt", "0.25")
    rows = [list(map(float, r.split(","))) for r in csv.strip().splitlines()[1:]]
    assert code == code2 == 0 and doc["columns"] == csv.splitlines()[0].split(",")
    np.testing.assert_allclose(doc["rows"], rows, rtol=1e-9)


def test_presets_list():
    code, text = lcv("presets")
    assert code == 0 and [line.split()[0] for line in text.strip().splitlines()] == list(PRESETS)
    assert lcv_json("presets") == {"presets": list(PRESETS)}


# ---------------------------------------------------------------------------- bad arguments: exit 2, one line
BAD = [
    (["eig", "--speed-mph", "50"], "one of the arguments --preset --vehicle is required"),
    (["eig", "--preset", "aucnat"], "one of the arguments --speed-kph --speed-mph is required"),
    (["eig", "--preset", "aucnat", "--speed-mph", "50", "--speed-kph", "80"], "not allowed with argument"),
    (["eig", "--preset", "aucnat", "--vehicle", WESTERN, "--speed-mph", "50"], "not allowed with argument"),
    (["eig", "--preset", "nope", "--speed-mph", "50"], "unknown preset 'nope'"),
    (["eig", "--vehicle", "/nonexistent.toml", "--speed-mph", "50"], "cannot read"),
    (["eig", "--preset", "aucnat", "--speed-mph", "fast"], "must be a number"),
    (["eig", "--preset", "aucnat", "--speed-mph", "1e308"], "--speed-mph: must be in [0.2237, 156.6] mph"),
    (["eig", "--preset", "aucnat", "--speed-mph", "1e6"], "must be in [0.2237, 156.6] mph"),
    (["eig", "--preset", "aucnat", "--speed-mph", "1e300"], "must be in"),
    (["eig", "--preset", "aucnat", "--speed-mph", "1e-100"], "must be in"),
    (["eig", "--preset", "aucnat", "--speed-mph", "1e-300"], "must be in"),
    (["eig", "--preset", "aucnat", "--speed-mph", "-5"], "must be in"),
    (["eig", "--preset", "aucnat", "--speed-mph", "nan"], "must be in"),
    (["eig", "--preset", "aucnat", "--speed-kph", "inf"], "must be in [0.36, 252] km/h"),
    (["eig", "--preset", "aucnat", "--speed-mph", "50", "--tire-scale", "1e200"], "--tire-scale: must be in [0.01, 100]"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--tire-scale", "5e-324", "--load", "trailer3"],
     "--tire-scale: must be in"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50"], "the following arguments are required: --load"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer9"], "unknown unit 'trailer9'"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,trailer2"], "listed twice"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,"], "comma list"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2", "--convention", "x"], "invalid choice"),
    (["eig", "--preset", "empty", "--speed-mph", "50", "--masses", "unrounded"], "unrounded masses are known only"),
    (["eig", "--vehicle", WESTERN, "--speed-mph", "50", "--masses", "unrounded"], "only presets"),
    (["simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--t-end", "1e9"],
     "--t-end: must be in (0, 86400] s"),
    (["simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--dt", "1e-320"],
     "--dt: must be in [1e-06, 3600] s"),
    (["simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--t-end", "1", "--dt", "5"],
     "is longer than --t-end"),
    (["simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--t-end", "10", "--dt", "0.3"],
     "does not divide --t-end 10 s into whole steps"),
    (["simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--t-end", "80000", "--dt", "0.001"],
     "at most 10000000"),
    (["measures", "--preset", "aucnat", "--speed-kph", "88", "--load", "dolly9"], "unknown unit 'dolly9'"),
    (["frobnicate"], "invalid choice"),
    ([], "the following arguments are required: COMMAND"),
]


@pytest.mark.parametrize("argv, message", BAD, ids=[" ".join(a)[:70] for a, _m in BAD])
def test_bad_arguments_exit_2_with_one_line(argv, message, capsys):
    code, text = lcv(*argv)
    err = capsys.readouterr().err
    assert code == 2 and text == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lcv: error: ") and message in lines[0], err


def test_static_load_missing_for_the_1_percent_rule_is_named(tmp_path, capsys):
    text = (EXAMPLES / "b_double.toml").read_text()
    body = "\n".join(line for line in text.splitlines() if not line.strip().startswith("static_load_N"))
    f = tmp_path / "noload.toml"
    f.write_text(body + "\n")
    code, _ = lcv("steady", "--vehicle", str(f), "--speed-kph", "88", "--load", "rear_trailer")
    err = capsys.readouterr().err
    assert code == 2 and "static_load_N is needed by the 1 % rule" in err and 'unit "rear_trailer"' in err


# ---------------------------------------------------------------------------- outputs that cannot be written
def test_broken_pipe_ends_quietly():
    """A reader that has gone away: no message, status 141 (as SIGPIPE), for a short
    output (the pipe's reading end closed before lcv starts) and for a long one
    (`lcv simulate ... | head -1`)."""
    exe = shutil.which("lcv", path=os.path.dirname(sys.executable))
    r, w = os.pipe()
    os.close(r)
    try:
        p = subprocess.run([exe, "presets"], stdout=w, stderr=subprocess.PIPE, text=True, timeout=120)
    finally:
        os.close(w)
    assert p.stderr == "" and p.returncode == EXIT_BROKEN_PIPE, (p.returncode, p.stderr)
    cmd = f"{exe} simulate --preset aucnat --speed-mph 50 --load trailer3 --t-end 3600 --dt 0.001 | head -1"
    p = subprocess.run(["bash", "-c", f"set -o pipefail; {cmd}"], capture_output=True, text=True, timeout=120)
    assert p.stderr == "", p.stderr
    assert p.returncode == EXIT_BROKEN_PIPE and len(p.stdout.splitlines()) == 1


def test_full_disk_is_one_line_and_exit_1():
    for argv in (["presets"], ["eig", "--preset", "aucnat", "--speed-mph", "50", "--json"],
                 ["simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3"]):
        with open("/dev/full", "w") as full:
            p = subprocess.run([shutil.which("lcv", path=os.path.dirname(sys.executable)), *argv], stdout=full,
                               stderr=subprocess.PIPE, text=True, timeout=120)
        lines = p.stderr.strip().splitlines()
        assert p.returncode == 1 and len(lines) == 1, p.stderr
        assert "cannot write the output" in lines[0] and "No space left on device" in lines[0]


def test_closed_stdout_is_an_error_not_a_silent_success():
    exe = shutil.which("lcv", path=os.path.dirname(sys.executable))
    p = subprocess.run(["bash", "-c", f"{exe} presets >&-"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 1 and "standard output is closed" in p.stderr


def test_no_output_is_ever_not_finite():
    """A vehicle unstable at the speed grows without bound in a long run: refused, not printed."""
    code, text = lcv("simulate", "--preset", "empty", "--speed-kph", "150", "--tire-scale", "0.05", "--load",
                     "trailer3", "--t-end", "86400", "--dt", "60", "--json")
    assert code == 1
    assert "inf" not in text.lower() and "nan" not in text.lower()


def test_simulate_streams_its_first_row_at_once_in_constant_memory():
    """10^6 rows: the first arrives within seconds and memory stays flat (nothing is kept)."""
    exe = shutil.which("lcv", path=os.path.dirname(sys.executable))
    cmd = [exe, "simulate", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--t-end", "1000",
           "--dt", "0.001"]
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    header = proc.stdout.readline()
    first = proc.stdout.readline()
    latency = time.perf_counter() - t0
    count = 0
    for _line in proc.stdout:
        count += 1
        if count == 200_000:
            break
    # this process's own peak (RUSAGE_CHILDREN would count every child this test worker ever
    # had, e.g. another test's Dask workers)
    status = open(f"/proc/{proc.pid}/status").read()
    maxrss_mb = int(next(line for line in status.splitlines() if line.startswith("VmHWM:")).split()[1]) / 1024
    proc.kill()
    proc.wait()
    assert header.startswith("time_s,") and first.startswith("0,")
    assert latency < 10.0
    assert maxrss_mb < 400, maxrss_mb


def test_ranges_table_is_what_the_cli_enforces():
    assert RANGES["speed"].high == 70.0 and RANGES["output_rows"].high == 1e7


# ---------------------------------------------------------------------------- round three (issue 22)
def _variant(tmp_path, name, edit):
    text = edit(open(WESTERN).read())
    path = tmp_path / f"{name}.toml"
    path.write_text(text)
    return str(path)


def test_a_vehicle_without_a_steered_axle_has_its_steer_measures_null_with_the_reason(tmp_path):
    path = _variant(tmp_path, "nosteer", lambda t: t.replace("steered = true\n", ""))
    p = lcv_process("measures", "--vehicle", path, "--speed-kph", "88", "--load", "trailer2", "--json")
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["ra_frequency"] is None and doc["ra_single_sine"] is None and doc["trim"] is None
    assert doc["ay_gain_per_unit"] is None and 0 < doc["least_damping_ratio"] < 1
    p = lcv_process("measures", "--vehicle", path, "--speed-kph", "88")
    assert p.returncode == 0 and "no steered axle" in p.stdout


@pytest.mark.parametrize("name, edit, fragment", [
    ("kn_per_rad", lambda t: __import__("re").sub(r"cornering_stiffness_N_per_rad = [0-9.e+]+",
                                                   "cornering_stiffness_N_per_rad = 125.0", t), "kN/rad"),
    # (without the roll keys: unsprung masses above a mass in tonnes are refused before any warning)
    ("tonnes", lambda t: __import__("re").sub(r"mass_kg = [0-9.e+]+", "mass_kg = 33.0",
                                              __import__("re").sub(r"\n *unsprung_mass_kg = .*", "", t)), "tonnes"),
])
def test_unit_typos_give_plausibility_warnings_on_stderr(tmp_path, name, edit, fragment):
    path = _variant(tmp_path, name, edit)
    p = lcv_process("eig", "--vehicle", path, "--speed-kph", "88", "--json")
    warnings = [line for line in p.stderr.splitlines() if line.startswith("lcv: warning:")]
    assert warnings and all(fragment in w for w in warnings[:1]), p.stderr
    json.loads(p.stdout)                                    # the result still comes, on stdout


def test_no_warnings_for_the_shipped_vehicles():
    from lcvreport.model.plausibility import plausibility_warnings
    for v in [load_preset(p) for p in PRESETS] + [load_vehicle(EXAMPLES / f"{n}.toml") for n in EXAMPLE_NAMES]:
        assert plausibility_warnings(v) == [], v.name


def test_a_trim_steer_outside_the_ranges_table_is_refused(tmp_path):
    path = _variant(tmp_path, "kn", lambda t: __import__("re").sub(
        r"cornering_stiffness_N_per_rad = [0-9.e+]+", "cornering_stiffness_N_per_rad = 125.0", t))
    p = lcv_process("measures", "--vehicle", path, "--speed-kph", "88", "--load", "trailer2", "--json")
    assert p.returncode == 2 and p.stdout == "" and "trim steer angle" in p.stderr and "[-1, 1] rad" in p.stderr
    assert "Traceback" not in p.stderr


@pytest.mark.parametrize("name, make, fragment", [
    ("dotted", lambda t: "a" + ".b" * 40000 + " = 1\n" + t, "dotted parts"),
    ("nested", lambda t: "x = " + "[" * 5000 + "]" * 5000 + "\n" + t, "nests too deeply"),
    ("digits", lambda t: t.replace("mass_kg = ", "mass_kg = " + "1" * 5000 + "#", 1), "digits"),
    ("zeros", lambda t: t.replace("mass_kg = ", "mass_kg = 1" + "0" * 400 + "#", 1), "mass_kg"),
    ("control", lambda t: t.replace('description = "', 'description = "a\\u0001b', 1), "control character"),
    ("control_name", lambda t: t.replace('name = "tractor"', 'name = "trac\\u001btor"', 1), "name"),
    ("huge", lambda t: t + "#" * (2 << 20), "bytes"),
])
def test_pathological_vehicle_files_are_one_line_exit_2_and_quick(tmp_path, name, make, fragment):
    path = _variant(tmp_path, name, make)
    t0 = time.perf_counter()
    p = lcv_process("eig", "--vehicle", path, "--speed-kph", "88")
    assert time.perf_counter() - t0 < 10
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and fragment in p.stderr, p.stderr
    assert "internal error" not in p.stderr


@pytest.mark.parametrize("special", ["fifo", "/dev/zero", "folder"])
def test_a_vehicle_file_that_is_not_a_regular_file_is_refused_without_reading_it(tmp_path, special):
    path = special
    if special == "fifo":
        path = str(tmp_path / "fifo")
        os.mkfifo(path)
    elif special == "folder":
        path = str(tmp_path)
    p = lcv_process("eig", "--vehicle", path, "--speed-kph", "88")
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1, p.stderr


def test_the_number_of_units_is_bounded():
    from lcvreport.model.vehicle import Vehicle, VehicleError
    unit = load_vehicle(WESTERN).units[1]
    with pytest.raises(VehicleError, match="at most 50 units"):
        Vehicle("long", tuple(unit for _ in range(51)))


def test_version():
    p = lcv_process("--version")
    assert p.returncode == 0 and p.stdout.startswith("lcv (lcvreport) ")


def test_ctrl_c_is_one_line_and_status_130(tmp_path):
    import signal
    exe = shutil.which("lcv", path=os.path.dirname(sys.executable))
    out = tmp_path / "run.csv"
    with open(out, "w") as f:
        proc = subprocess.Popen(with_default_sigint([exe, "simulate", "--preset", "aucnat", "--speed-kph", "88",
                                                     "--load", "trailer3", "--t-end", "5000", "--dt", "0.001"]),
                                stdout=f, stderr=subprocess.PIPE, text=True)
        time.sleep(3.0)
        proc.send_signal(signal.SIGINT)
        _out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and err.strip().splitlines() == ["lcv: interrupted"], err
