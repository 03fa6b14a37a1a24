"""FMI importers nobody on this project wrote (../shared/tools): the FMI Compliance Checker
and Reference-FMUs' fmusim, on every FMU kind, with no LD_PRELOAD and no PYTHONPATH;
their results against the package; LCV.fmu in a plain C host and under valgrind."""
from __future__ import annotations

import csv
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from conftest import EXAMPLE_NAMES, TOOLS
from fmu_support import host_env, host_statuses, host_values, interface_of, run_host, unzip
from helpers import group_error, reference_outputs, schedule_condition, tolerance

CHECKER = TOOLS / "fmuCheck.linux64"
FMUSIM = TOOLS / "fmusim"
T_END = 3.0
H = 0.01


FMUS = ["LCV", "LCVNative"] + [f"{name}:{kind}" for name in EXAMPLE_NAMES for kind in ("python", "native")]


@pytest.fixture(scope="module", params=FMUS)
def any_fmu(request, lcv_fmu, native_fmu, all_example_fmus):
    if ":" in request.param:
        name, kind = request.param.split(":")
        return all_example_fmus[name][kind]
    return {"LCV": lcv_fmu, "LCVNative": native_fmu}[request.param]


def _inputs(itf) -> dict:
    """A residual force on the last axle of the last unit and a moment on the first, held."""
    p = [v.name for v in itf.inputs if v.source[0] == "P"][-1]
    t = [v.name for v in itf.inputs if v.source[0] == "T"][0]
    return {p: 1500.0, t: -300.0, "delta": 0.002}


def _write_inputs(path: Path, inputs: dict) -> None:
    names = list(inputs)
    rows = ["time," + ",".join(names)] + [f"{t}," + ",".join(repr(inputs[n]) for n in names) for t in (0.0, T_END)]
    path.write_text("\n".join(rows) + "\n")


def _read(path: Path, itf) -> tuple[np.ndarray, np.ndarray]:
    with open(path) as f:
        rows = list(csv.reader(f))
    header = [h.strip().strip('"') for h in rows[0]]
    data = np.array([[float(x) for x in r] for r in rows[1:] if r])
    names = [v.name for v in itf.outputs]
    return data[:, 0], data[:, [header.index(n) for n in names]]


def _reference(itf, inputs, times):
    steps = [(H, dict(inputs))] + [(H, {})] * (int(round(T_END / H)) - 1)
    ref = reference_outputs(itf, steps, itf.vehicles[0].name if itf.preset_mode else None)
    kappa = schedule_condition(itf, steps, itf.vehicles[0].name if itf.preset_mode else None, samples=2)
    k = np.rint(times / H).astype(int)
    keep = k >= 1
    return ref[k[keep] - 1], keep, kappa


def _assert_matches_package(path, itf, times, out, inputs):
    ref, keep, kappa = _reference(itf, inputs, times)
    err, name = group_error(out[keep], ref, itf)
    # the tools print 16-17 significant digits
    assert err <= max(tolerance(kappa), 1e-14), f"{name}: {err:.2e} (kappa {kappa:.3g})"
    assert np.all(np.isfinite(out))


def test_fmi_compliance_checker_passes_and_simulates_exactly(any_fmu, tmp_path):
    itf = interface_of(any_fmu)
    inputs = _inputs(itf)
    _write_inputs(tmp_path / "in.csv", inputs)
    (tmp_path / "tmp").mkdir()
    # every interface the FMU has (XML, Model Exchange where offered, Co-Simulation): 0 warnings 0 errors
    p = subprocess.run([str(CHECKER), "-h", str(H), "-s", str(T_END), "-l", "3", "-t", str(tmp_path / "tmp"),
                        "-i", str(tmp_path / "in.csv"), str(any_fmu)],
                       capture_output=True, text=True, env=host_env(), timeout=300)
    text = p.stdout + p.stderr
    assert p.returncode == 0, text[-3000:]
    assert "0 Warning(s)" in text and "0 Error(s)" in text, text[-3000:]
    # its co-simulation run (its ME run uses its own fixed-step Euler: test_model_exchange.py)
    p = subprocess.run([str(CHECKER), "-k", "cs", "-h", str(H), "-s", str(T_END), "-l", "3", "-t",
                        str(tmp_path / "tmp"), "-o", str(tmp_path / "out.csv"), "-i", str(tmp_path / "in.csv"),
                        str(any_fmu)], capture_output=True, text=True, env=host_env(), timeout=300)
    assert p.returncode == 0, (p.stdout + p.stderr)[-3000:]
    times, out = _read(tmp_path / "out.csv", itf)
    _assert_matches_package(any_fmu, itf, times, out, inputs)


def test_fmusim_runs_it_and_agrees_with_the_package(any_fmu, tmp_path):
    itf = interface_of(any_fmu)
    inputs = _inputs(itf)
    _write_inputs(tmp_path / "in.csv", inputs)
    p = subprocess.run([str(FMUSIM), "--interface-type", "cs", "--stop-time", str(T_END), "--output-interval", str(H),
                        "--input-file", str(tmp_path / "in.csv"), "--output-file", str(tmp_path / "out.csv"),
                        str(any_fmu)], capture_output=True, text=True, env=host_env(), timeout=300)
    assert p.returncode == 0, (p.stdout + p.stderr)[-3000:]
    times, out = _read(tmp_path / "out.csv", itf)
    _assert_matches_package(any_fmu, itf, times, out, inputs)


def test_the_tools_outputs_are_the_same_for_both_kinds(lcv_fmu, native_fmu, tmp_path):
    itf = interface_of(native_fmu)
    _write_inputs(tmp_path / "in.csv", _inputs(itf))
    outs = []
    for fmu in (lcv_fmu, native_fmu):
        out = tmp_path / f"{fmu.stem}.csv"
        subprocess.run([str(FMUSIM), "--interface-type", "cs", "--stop-time", str(T_END), "--output-interval", str(H),
                        "--input-file", str(tmp_path / "in.csv"), "--output-file", str(out), str(fmu)],
                       capture_output=True, env=host_env(), timeout=300, check=True)
        outs.append(_read(out, itf)[1])
    err, name = group_error(outs[0], outs[1], itf)
    assert err < 1e-10, (name, err)


# ---------------------------------------------------------------------------- LCV.fmu in a plain C host
def test_lcv_fmu_runs_in_a_c_host_without_python_set_up(c_host, lcv_fmu, tmp_path):
    """No LD_PRELOAD, no PYTHONPATH: the loader finds the Python it was built with; the
    host exits 0 (no crash at exit) and the results are the package's."""
    unz = unzip(lcv_fmu, tmp_path / "lcv")
    _d, _g, vr = unz
    ldd = subprocess.run(["ldd", str(c_host)], capture_output=True, text=True).stdout
    assert "python" not in ldd
    script = f"s {vr['P61']} 1000\ni\n" + "".join(f"d {k * H!r} {H!r}\ng {vr['y6']} {vr['thetaE']}\n"
                                                  for k in range(100))
    p = run_host(c_host, unz, "LCV", script)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.stdout[-1000:], p.stderr[-2000:])
    assert set(host_statuses(p.stdout)) == {0}
    itf = interface_of(lcv_fmu)
    ref = reference_outputs(itf, [(H, {"P61": 1000.0})] + [(H, {})] * 99, "aucnat")
    names = [v.name for v in itf.outputs]
    got = host_values(p.stdout)
    np.testing.assert_allclose(got[:, 0], ref[:, names.index("y6")], rtol=0, atol=1e-12 * np.abs(ref).max())


def test_lcv_fmu_says_which_python_it_looked_for(c_host, lcv_fmu, tmp_path):
    unz = unzip(lcv_fmu, tmp_path / "lcv")
    env = host_env()
    env["LCV_FMU_LIBPYTHON"] = "/nonexistent/libpython3.11.so"
    p = run_host(c_host, unz, "LCV", "i\n", env=env)
    assert p.returncode == 4 and "instantiate failed" in p.stdout
    assert "/nonexistent/libpython3.11.so" in p.stdout and "LCV_FMU_LIBPYTHON" in p.stdout


def valgrind_reports(stderr: str) -> list[str]:
    """memcheck's error reports (the kind line and its stack), one string each."""
    reports, current = [], None
    for line in stderr.splitlines():
        body = line.split("== ", 1)[1] if line.startswith("==") and "== " in line else line
        if any(k in body for k in ("Invalid ", "uninitialised", "Conditional jump", "Mismatched free")):
            current = [body]
            reports.append(current)
        elif current is not None and body.strip():
            current.append(body)
        else:
            current = None
    return ["\n".join(r) for r in reports]


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is installed by ./build.sh setup")
def test_lcv_fmu_in_a_c_host_under_valgrind(c_host, lcv_fmu, tmp_path):
    """Exit 0 under memcheck; the only reports are glibc's dynamic loader reading rpath
    strings word-wise (strncmp in dl-load.c), none in the FMU's libraries."""
    unz = unzip(lcv_fmu, tmp_path / "lcv")
    _d, _g, vr = unz
    script = f"s {vr['P61']} 1000\ni\n" + "".join(f"d {k * H!r} {H!r}\n" for k in range(50)) + f"g {vr['y6']}\n"
    p = run_host(c_host, unz, "LCV", script, wrapper=["valgrind", "--num-callers=30"], timeout=900)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), (p.stdout[-2000:], p.stderr[-3000:])
    assert "ERROR SUMMARY" in p.stderr
    for report in valgrind_reports(p.stderr):
        assert "dl-load.c" in report and "LCV.so" not in report and "pythonfmu-export" not in report, report


# ---------------------------------------------------------------------------- the C FMU in a plain C host
def test_c_fmu_in_a_c_host_gives_exactly_what_fmpy_gives(c_host, native_fmu, tmp_path):
    """Same binary, two hosts (one without Python in the process): identical numbers."""
    from fmu_support import Slave, run_schedule
    from helpers import schedule
    unz = unzip(native_fmu, tmp_path / "native")
    vr = unz[2]
    steps = schedule(np.random.default_rng(21), 80, [0.002, 0.02, 0.1], ("11", "21", "61"), clamp=True)
    itf = interface_of(native_fmu)
    outs = [v.name for v in itf.outputs]
    lines, t = ["S {} legal_max".format(vr["preset"]), "i"], 0.0
    for h, inputs in steps:
        lines += [f"s {vr[k]} {v!r}" for k, v in inputs.items()]
        lines += [f"d {t!r} {h!r}", "g " + " ".join(str(vr[o]) for o in outs)]
        t += h
    p = run_host(c_host, unz, "LCVNative", "\n".join(lines) + "\n")
    assert p.returncode == 0 and p.stdout.rstrip().endswith("done"), p.stderr
    assert set(host_statuses(p.stdout)) == {0, 1}        # fmi2Warning where u first falls below u_min (clamp)
    s = Slave(native_fmu, preset="legal_max").init()
    ref = run_schedule(s, steps)
    s.free()
    np.testing.assert_array_equal(host_values(p.stdout), ref)


@pytest.mark.slow
def test_valgrind_memcheck_one_million_steps_of_the_c_fmu(c_host, native_fmu, tmp_path):
    d, guid, vr = unzip(native_fmu, tmp_path / "native")
    assert shutil.which("valgrind"), "valgrind is not installed (./build.sh setup installs it)"
    p = subprocess.run(["valgrind", "--tool=memcheck", "--leak-check=full", "--show-leak-kinds=all",
                        "--errors-for-leak-kinds=all", "--error-exitcode=99", str(c_host), str(d), "LCVNative",
                        guid, "bench", "1000000", "0.001", str(vr["P61"]), str(vr["y6"])],
                       capture_output=True, text=True, timeout=3000)
    assert p.returncode == 0, p.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors" in p.stderr and "All heap blocks were freed" in p.stderr


def _threads_of_a_c_host_running(c_host, fmu_dir, guid, vr, env) -> int:
    """The number of threads of a plain C host that has initialized LCV.fmu and taken a step."""
    import os
    p = subprocess.Popen([str(c_host), str(fmu_dir), "LCV", guid, "script"], stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        p.stdin.write(f"s {vr['delta']} 0.01\ni\nd 0 0.01\n")
        p.stdin.flush()
        for _ in range(3):
            assert p.stdout.readline().startswith("status 0")
        return len(os.listdir(f"/proc/{p.pid}/task"))
    finally:
        p.stdin.close()
        p.kill()
        p.wait()


def test_the_python_fmus_own_interpreter_runs_one_blas_thread(c_host, lcv_fmu, tmp_path):
    """In a C host the FMU starts its own Python, whose numpy loads OpenBLAS with one thread by
    default: a host with LCV_BLAS_THREADS=2 has exactly one thread more (OpenBLAS's second)."""
    fmu_dir, guid, vr = unzip(lcv_fmu, tmp_path / "lcv")
    clean = {k: v for k, v in host_env().items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS",
                                                              "MKL_NUM_THREADS", "LCV_BLAS_THREADS")}
    default = _threads_of_a_c_host_running(c_host, fmu_dir, guid, vr, clean)
    two = _threads_of_a_c_host_running(c_host, fmu_dir, guid, vr, dict(clean, LCV_BLAS_THREADS="2"))
    assert two == default + 1, (default, two)
