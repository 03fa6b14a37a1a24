"""Hostile input, round four (issue 28): every file option on a FIFO or a device, studies
whose cases leave the ranges table, study folders that were tampered with, schedulers that
do not answer, and the smaller refusals.  Each case runs in a process of its own with a
time limit that only a hang reaches (the commands answer in about a second)."""
from __future__ import annotations

import errno
import json
import os
import shutil
import socket
import struct
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

from lcvreport.study.run import run_study
from lcvreport.study.results import read_study
from lcvreport.study.spec import StudyError, study_from_dict
from helpers import with_default_sigint

ROOT = Path(__file__).resolve().parents[1]
LCV = [sys.executable, "-m", "lcvreport.cli"]
#: a hang guard, not a timing: every command here answers in seconds
HANG_S = 120


def lcv(*args, cwd=None, env=None):
    return subprocess.run(LCV + [str(a) for a in args], capture_output=True, text=True, timeout=HANG_S, cwd=cwd,
                          env=env)


def one_line(p, status=2):
    lines = p.stderr.strip().splitlines()
    assert p.returncode == status and len(lines) == 1 and lines[0].startswith("lcv: error: "), p.stderr
    assert "Traceback" not in p.stderr and "internal error" not in p.stderr
    return lines[0]


# ---------------------------------------------------------------------------- 6: FIFOs and devices
@pytest.fixture
def fifo(tmp_path):
    path = tmp_path / "pipe.csv"
    os.mkfifo(path)
    return path


def _file_options(path):
    """Every command-line option that reads a file a user names."""
    p = str(path)
    vehicle = ROOT / "examples" / "vehicles" / "b_double.toml"
    return [
        ["eig", "--vehicle", p, "--speed-kph", "88"],
        ["simulate", "--preset", "aucnat", "--speed-kph", "88", "--steer", f"csv:{p}"],
        ["simulate", "--preset", "aucnat", "--speed-kph", "88", "--tires", p],
        ["measures", "--preset", "aucnat", "--speed-kph", "88", "--tires", p],
        ["measures", "--preset", "aucnat", "--speed-kph", "88", "--criteria", p],
        ["report", "--vehicle", vehicle, "--criteria", p, "--out", Path(p).parent / "r1"],
        ["report", "--vehicle", vehicle, "--tires", p, "--out", Path(p).parent / "r2"],
        ["tracking", "place", "--preset", "aucnat", "--speed-kph", "88", "--tires", p],
        ["study", p, "--out", Path(p).parent / "s1"],
    ]


@pytest.mark.parametrize("k", range(9))
def test_every_file_option_refuses_a_fifo_in_one_line(fifo, k):
    line = one_line(lcv(*_file_options(fifo)[k]))
    assert "FIFO" in line and str(fifo) in line


@pytest.mark.parametrize("device, kind", [("/dev/zero", "character device"), ("/tmp", "folder")])
def test_a_steer_table_on_a_device_or_a_folder_is_refused_at_once(device, kind):
    line = one_line(lcv("simulate", "--preset", "aucnat", "--speed-kph", "88", "--steer", f"csv:{device}"))
    assert kind in line


def test_every_reader_refuses_a_file_above_its_limit(tmp_path):
    """A sparse file of 2 GiB (nothing is written) is refused from its size alone."""
    big = tmp_path / "big.csv"
    with open(big, "wb") as f:
        f.truncate(2 << 30)
    for args in _file_options(big):
        line = one_line(lcv(*args))
        assert "at most" in line and "2147483648 bytes" in line, line


def test_the_guarded_reader_reads_a_file_with_a_byte_order_mark(tmp_path):
    steer = tmp_path / "steer.csv"
    steer.write_text("\ufefftime_s,delta_rad\n0,0\n1,0.01\n", encoding="utf-8")
    p = lcv("simulate", "--preset", "tractor_semitrailer", "--speed-kph", "88", "--steer", f"csv:{steer}",
            "--t-end", "1", "--dt", "0.5")
    assert p.returncode == 0, p.stderr
    tires = tmp_path / "measured.csv"
    tires.write_text("\ufeffid,conicity_N,ply_steer_N\nA,10,5\nB,-10,5\n", encoding="utf-8")
    from lcvreport.tracking.placement import read_measured_tires
    assert [t["id"] for t in read_measured_tires(tires)] == ["A", "B"]


# ---------------------------------------------------------------------------- 10: CSV headers and duplicates
@pytest.mark.parametrize("text, fragment", [
    ("id,conicity_N,ply_steer_N,conicity_N\nA,1,2,3\n", "names column 'conicity_N' twice"),
    ("id,conicity_N,ply_steer_N\nA,1,2,3\n", "line 2 has 4 values"),
    ("id,conicity_N,ply_steer_N,mass\nA,1,2,3\n", "unknown column 'mass'"),
])
def test_measured_tire_headers_are_checked(tmp_path, text, fragment):
    path = tmp_path / "t.csv"
    path.write_text(text)
    assert fragment in one_line(lcv("tracking", "place", "--preset", "aucnat", "--speed-kph", "88", "--tires", path))


@pytest.mark.parametrize("text, fragment", [
    ("position,conicity_N,ply_steer_N,serial_side,ply_steer_N\n21:left_outer,1,2,out,3\n",
     "names column 'ply_steer_N' twice"),
    ("position,conicity_N,ply_steer_N,serial_side,mass\n21:left_outer,1,2,out,3,4\n", "unknown column 'mass'"),
    ("position,conicity_N,ply_steer_N,serial_side\n21:left_outer,1,2,out,3\n", "line 2 has 5 values"),
])
def test_mounted_tire_headers_are_checked(tmp_path, text, fragment):
    path = tmp_path / "t.csv"
    path.write_text(text)
    assert fragment in one_line(lcv("measures", "--preset", "aucnat", "--speed-kph", "88", "--tires", path))


# ---------------------------------------------------------------------------- 7: study cases in range
def _study_file(tmp_path, factors: str, design: str = "") -> Path:
    path = tmp_path / "study.toml"
    path.write_text(f'vehicle = "aucnat"\nspeed_kph = 88.0\nmeasures = ["hsso_m"]\n{design}\n[factors]\n{factors}\n')
    return path


@pytest.mark.parametrize("factors, design, fragment", [
    ("speed_kph = {values = [80.0, 1000.0]}", "", "factors.speed_kph: case 1 has 1000"),
    ("tire_scale = {values = [1e6]}", "", "factors.tire_scale: case 0 has 1e+06"),
    ('"trailer1.mass_scale" = {values = [1.0, 1e12]}', "", "factors.trailer1.mass_scale: case 1 makes "
                                                           "trailer1.mass_kg"),
    ('"trailer1.yaw_inertia_scale" = {distribution = "uniform", low = 1.0, high = 1e9}',
     '[design]\nkind = "random"\ncount = 100\nseed = 1', "factors.trailer1.yaw_inertia_scale: case 0 makes"),
    ('"21.cornering_stiffness_scale" = {distribution = "normal", mean = 300.0, sd = 10.0}',
     '[design]\nkind = "random"\ncount = 100\nseed = 1', "21.cornering_stiffness_N_per_rad"),
])
def test_a_study_with_a_case_outside_the_ranges_is_refused_before_computing(tmp_path, factors, design, fragment):
    out = tmp_path / "out"
    line = one_line(lcv("study", _study_file(tmp_path, factors, design), "--out", out))
    assert fragment in line and "must be in" in line, line
    assert not out.exists()                     # refused before the folder is set up


def test_a_study_whose_vehicle_is_not_a_vehicle_file_is_one_line(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text('vehicle = "/etc/passwd"\nspeed_kph = 88.0\n[factors]\nspeed_kph = {values = [80.0]}\n')
    assert "vehicle '/etc/passwd'" in one_line(lcv("study", path, "--out", tmp_path / "o"))
    bad = tmp_path / "neg.toml"
    bad.write_text((ROOT / "examples" / "vehicles" / "b_double.toml").read_text().replace("mass_kg = ", "mass_kg = -",
                                                                                          1))
    path.write_text('vehicle = "neg.toml"\nspeed_kph = 88.0\n[factors]\nspeed_kph = {values = [80.0]}\n')
    assert "mass_kg must be in" in one_line(lcv("study", path, "--out", tmp_path / "o"))


# ---------------------------------------------------------------------------- 8: study integrity
def _small(chunk=4, count=12):
    return study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m"],
                            "design": {"kind": "random", "count": count, "seed": 3}, "chunk_size": chunk,
                            "factors": {"trailer1.mass_scale": {"distribution": "uniform", "low": 0.8,
                                                                "high": 1.2}}})


def test_a_chunk_copied_over_another_is_named_and_recomputed(tmp_path, capfd):
    s, out = _small(), tmp_path / "out"
    run_study(s, out)
    good = read_study(out)
    chunks = out / "chunks"
    shutil.copy(chunks / "chunk-000000.parquet", chunks / "chunk-000002.parquet")
    with pytest.raises(StudyError, match=r"chunk-000002.parquet holds chunk 0 \(cases 0:4\), not chunk 2"):
        read_study(out)
    summary = run_study(s, out)
    assert (summary.n_computed, summary.n_repaired) == (1, 1)
    assert "chunk-000002.parquet holds chunk 0" in capfd.readouterr().err
    again = read_study(out)
    assert again["case_id"].tolist() == list(range(12)) and again.equals(good)


def test_an_edited_manifest_is_refused(tmp_path):
    s, out = _small(), tmp_path / "out"
    run_study(s, out)
    man = json.loads((out / "manifest.json").read_text())
    man["n_chunks"] = 1
    (out / "manifest.json").write_text(json.dumps(man))
    with pytest.raises(StudyError, match="n_chunks is 1 but the study has 3"):
        read_study(out)
    with pytest.raises(StudyError, match="was changed"):
        run_study(s, out)


def test_a_truncated_chunk_is_found_and_recomputed_and_csv_works(tmp_path):
    s, out = _small(), tmp_path / "out"
    run_study(s, out)
    victim = out / "chunks" / "chunk-000001.parquet"
    data = victim.read_bytes()
    victim.write_bytes(data[: len(data) // 2])
    with pytest.raises(StudyError, match="chunk-000001.parquet cannot be read"):
        read_study(out)
    study_file = tmp_path / "s.toml"
    study_file.write_text('vehicle = "tractor_semitrailer"\nspeed_kph = 88.0\nmeasures = ["hsso_m"]\nchunk_size = 4\n'
                          '[design]\nkind = "random"\ncount = 12\nseed = 3\n[factors]\n'
                          '"trailer1.mass_scale" = {distribution = "uniform", low = 0.8, high = 1.2}\n')
    out2 = tmp_path / "out2"
    assert lcv("study", study_file, "--out", out2).returncode == 0
    v2 = out2 / "chunks" / "chunk-000001.parquet"
    v2.write_bytes(v2.read_bytes()[:100])
    p = lcv("study", study_file, "--out", out2, "--csv")
    assert p.returncode == 0 and "chunk-000001.parquet cannot be read" in p.stderr, p.stderr
    assert len((out2 / "results.csv").read_text().splitlines()) == 13


def test_a_flipped_byte_in_a_chunk_is_caught_by_its_page_checksum(tmp_path):
    s, out = _small(chunk=12), tmp_path / "out"
    run_study(s, out)
    victim = out / "chunks" / "chunk-000000.parquet"
    data = bytearray(victim.read_bytes())
    value = float(read_study(out)["hsso_m"][5])
    at = bytes(data).find(struct.pack("<d", value))           # the number's bytes in its data page
    assert at > 0
    data[at] ^= 0x01                                          # its last mantissa bit: a plausible number
    victim.write_bytes(bytes(data))
    with pytest.raises(StudyError, match="chunk-000000.parquet is damaged"):
        read_study(out)


def test_a_full_disk_while_the_folder_is_set_up_leaves_nothing_the_rerun_refuses(tmp_path, monkeypatch):
    from lcvreport.study.run import run_study
    s, out = _small(), tmp_path / "out"
    real = Path.write_text

    def full(self, text, *a, **k):
        if self.name == ".manifest.json.tmp":
            real(self, text[: len(text) // 2], *a, **k)
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, text, *a, **k)
    monkeypatch.setattr(Path, "write_text", full)
    with pytest.raises(OSError):
        run_study(s, out)
    monkeypatch.setattr(Path, "write_text", real)
    assert not list(out.glob(".*.tmp")) and not (out / "manifest.json").exists()
    assert run_study(s, out).n_computed == 3
    assert len(read_study(out)) == 12


# ---------------------------------------------------------------------------- 5: schedulers that do not answer
def _silent_server(reply: bytes | None):
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    conns = []

    def serve():
        while True:
            try:
                c, _ = srv.accept()
            except OSError:
                return
            conns.append(c)
            if reply is not None:
                try:
                    c.recv(1 << 16)
                    c.sendall(reply)
                except OSError:
                    pass
    threading.Thread(target=serve, daemon=True).start()
    return srv, conns


@pytest.mark.parametrize("reply", [None, b"HTTP/1.0 200 OK\r\nContent-Length: 2\r\n\r\nhi"])
def test_a_scheduler_port_that_never_answers_as_dask_is_refused_in_time(tmp_path, reply):
    srv, conns = _silent_server(reply)
    try:
        addr = f"tcp://127.0.0.1:{srv.getsockname()[1]}"
        study = _study_file(tmp_path, "speed_kph = {values = [80.0]}")
        line = one_line(lcv("study", study, "--out", tmp_path / "o", "--scheduler", addr))
        assert addr in line and ("no Dask scheduler answers there" in line or "not a Dask scheduler" in line), line
        assert not (tmp_path / "o").exists()
    finally:
        srv.close()
        for c in conns:
            c.close()


@pytest.mark.parametrize("address", ["garbage://x", "", "tcp://[::1", "tcp://host", "inproc://x"])
def test_a_malformed_scheduler_address_is_one_line(tmp_path, address):
    study = _study_file(tmp_path, "speed_kph = {values = [80.0]}")
    p = lcv("study", study, "--out", tmp_path / "o", "--scheduler", address)
    assert "--scheduler" in one_line(p) and p.stdout == ""


def test_the_scheduler_help_says_to_trust_the_cluster():
    p = lcv("study", "--help")
    assert p.returncode == 0 and "trust" in p.stdout and "pickles" in p.stdout
    assert "Connect only to a cluster you trust" in (ROOT / "README.md").read_text()


# ---------------------------------------------------------------------------- 1, 2: reports
HOSTILE = "<img src=x onerror=alert(1)> <script>alert(2)</script> [link](javascript:alert(3)) $\\href{javascript:x}{m}$"


class _Tags:
    """Every start tag of an HTML document and its attributes (html.parser)."""

    def __init__(self, text):
        from html.parser import HTMLParser
        self.tags = []
        outer = self

        class P(HTMLParser):
            def handle_starttag(self, tag, attrs):
                outer.tags.append((tag, dict(attrs)))
        P().feed(text)

    def handlers(self):
        return [(t, a) for t, a in self.tags for k in a if k.lower().startswith("on")]

    def scripts(self):
        return [a.get("src", "") for t, a in self.tags if t == "script"]


def _pdf_text(path):
    return subprocess.run(["pdftotext", str(path), "-"], capture_output=True, text=True, check=True).stdout


def test_a_hostile_vehicle_file_runs_no_script_and_discloses_no_file(tmp_path):
    """The description, the file's path and the criteria file's path and source, each holding
    HTML, a javascript: link, MathJax and LaTeX that would read a token file: the HTML has
    no event handler and no script beyond MathJax's, the PDF shows the text and not the token."""
    token = tmp_path / "token.txt"
    token.write_text("LCVSECRETTOKEN4711\n")
    folder = tmp_path / "<img src=y onerror=alert(9)> $x$"
    folder.mkdir()
    text = (ROOT / "examples" / "vehicles" / "b_double.toml").read_text()
    line = next(x for x in text.splitlines() if x.startswith("description = "))
    hostile = f"{HOSTILE} \\input{{{token}}} \\include{{{token}}} % \\\\ # & _ ^ ~"
    vehicle = folder / "v.toml"
    vehicle.write_text(text.replace(line, "description = " + json.dumps(hostile)))
    criteria = folder / "c.toml"
    criteria.write_text("[limits]\nhsto_m = { max = 0.6, source = " + json.dumps(f"{HOSTILE} \\input{{{token}}}")
                        + " }\n")
    out = tmp_path / "r"
    p = lcv("report", "--vehicle", vehicle, "--criteria", criteria, "--out", out)
    assert p.returncode == 0, p.stderr[-3000:]
    html = (out / "index.html").read_text(encoding="utf-8")
    tags = _Tags(html)
    assert not tags.handlers(), tags.handlers()
    assert all(src.startswith("mathjax/") for src in tags.scripts() if src), tags.scripts()
    assert "javascript:" not in " ".join(a.get("href", "") for _t, a in tags.tags)
    assert "&lt;img src=x onerror=alert(1)&gt;" in html           # shown, as text
    assert "<script>alert(2)" not in html
    pdf = _pdf_text(out / "report.pdf")
    assert "LCVSECRETTOKEN4711" not in pdf
    assert "\\input{" in pdf and "onerror=alert(1)" in pdf          # the text itself is printed


def test_a_hostile_criteria_source_runs_no_script_in_the_study_report(tmp_path):
    from lcvreport.report.build import build_study_report
    token = tmp_path / "token.txt"
    token.write_text("LCVSECRETTOKEN4712\n")
    s = study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m", "hsto_m"],
                         "factors": {"trailer1.mass_scale": {"values": [0.9, 1.0, 1.1]}}})
    out = tmp_path / "<b onmouseover=alert(5)>study"
    run_study(s, out)
    criteria = tmp_path / "$c$ <i>.toml"
    criteria.write_text("[limits]\nhsto_m = { max = 0.6, source = " + json.dumps(f"{HOSTILE} \\input{{{token}}}")
                        + " }\n")
    res = build_study_report(out, tmp_path / "rep", criteria_file=str(criteria), fast=True)
    html = Path(res["html"]).read_text(encoding="utf-8")
    tags = _Tags(html)
    assert not tags.handlers(), tags.handlers()
    assert all(src.startswith("mathjax/") for src in tags.scripts() if src), tags.scripts()
    assert "&lt;img src=x onerror=alert(1)&gt;" in html
    pdf = _pdf_text(res["pdf"])
    assert "LCVSECRETTOKEN4712" not in pdf and "\\input{" in pdf


# ---------------------------------------------------------------------------- 4, 11: FMI 2 round four
FMI2_CASES = {
    # case -> {kind: (statuses, fragment)}
    "instance_name_not_utf8": {"LCV": ([3], "the instanceName is not UTF-8 text"),
                               "LCVNative": ([0, 0, 0, 0, 0], None)},
    "me_state_round_trip": {"LCVNative": ([0] * 10, "restored=True")},
    "cs_state_into_me": {"LCVNative": ([0, 0, 0, 0, 0, 0, 0, 0, 3, 3, 0], "written by a Co-Simulation instance")},
    "directional_in_init": {"LCVNative": ([0, 0, 3, 3, 3, 0], "not a continuous state or an input other than u")},
    "clamped_step_status": {"LCV": ([0, 0, 0, 0, 1, 0], "is below u_min"),
                            "LCVNative": ([0, 0, 0, 0, 1, 0], "is below u_min")},
}
FMI2_ALL = [(k, c) for c, kinds in FMI2_CASES.items() for k in kinds]


@pytest.mark.parametrize("kind,case", FMI2_ALL, ids=[f"{k}-{c}" for k, c in FMI2_ALL])
def test_round_four_fmi2_call(kind, case):
    from conftest import _preset_fmu
    fmu = _preset_fmu(kind)
    p = subprocess.run([sys.executable, str(ROOT / "tests" / "hostile_driver2_round4.py"), str(fmu), case],
                       capture_output=True, text=True, timeout=HANG_S)
    assert p.returncode == 0 and p.stdout.rstrip().endswith("survived"), (p.returncode, p.stdout[-2000:],
                                                                          p.stderr[-3000:])
    doc = json.loads(p.stdout.splitlines()[-2])
    statuses, fragment = FMI2_CASES[case][kind]
    assert doc["status"] == statuses and not doc["fatal"], doc
    if fragment:
        assert any(fragment in m for m in doc["messages"]), doc["messages"]


@pytest.mark.parametrize("name", ["LCV", "LCV3"])
def test_a_python_fmu_unzipped_under_a_folder_named_with_percent_20_runs(tmp_path, name):
    """pythonfmu and pythonfmu3 turn "%20" in the resources path into a space: the loaders hand
    them an alias of the folder, so the FMU runs wherever it is unzipped, and leaves nothing."""
    from conftest import _preset_fmu
    fmu = _preset_fmu(name)
    folder = tmp_path / "models%20v2 file:" / "x"
    folder.mkdir(parents=True)
    import zipfile
    zipfile.ZipFile(fmu).extractall(folder)
    code = ("import sys, os, json; from fmpy import simulate_fmu; before = set(os.listdir('/tmp'))\n"
            f"r = simulate_fmu({str(folder)!r}, stop_time=0.1, output_interval=0.05, start_values={{'delta': 0.01}})\n"
            "print(json.dumps({'r1': float(r[-1]['r1']), 'left': sorted(set(os.listdir('/tmp')) - before), "
            "'path': [p for p in sys.path if 'lcv-fmu' in p]}))")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_S)
    assert p.returncode == 0, p.stderr[-3000:]
    doc = json.loads(p.stdout.splitlines()[-1])
    assert doc["r1"] > 0 and doc["left"] == [] and doc["path"] == [], doc


# ---------------------------------------------------------------------------- 12: Ctrl-C on a study with workers
@pytest.mark.parametrize("after_chunks", [0, 2])
def test_ctrl_c_on_a_study_with_workers_prints_one_line(tmp_path, after_chunks):
    """Ctrl-C reaches the whole foreground group; the workers ignore it and only lcv acts on it:
    one line, status 130, no worker's traceback -- as the cluster starts and while chunks run."""
    import signal
    import time
    path = tmp_path / "s.toml"
    path.write_text('vehicle = "aucnat"\nspeed_kph = 88.0\nmeasures = ["hsso_m", "ra_peak"]\nchunk_size = 50\n'
                    '[design]\nkind = "random"\ncount = 100000\nseed = 1\n[factors]\n'
                    '"trailer1.mass_scale" = {distribution = "uniform", low = 0.8, high = 1.2}\n')
    out = tmp_path / "out"
    proc = subprocess.Popen(with_default_sigint(LCV + ["study", str(path), "--out", str(out), "--workers", "2"]),
                            stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.time() + HANG_S
    while time.time() < deadline and proc.poll() is None and \
            len(list((out / "chunks").glob("chunk-*.parquet")) if (out / "chunks").exists() else []) < after_chunks:
        time.sleep(0.05)
    if not after_chunks:
        time.sleep(1.0)                             # the cluster is starting
    os.killpg(proc.pid, signal.SIGINT)
    _stdout, stderr = proc.communicate(timeout=HANG_S)
    assert proc.returncode == 130 and stderr.strip().splitlines() == ["lcv: interrupted"], (proc.returncode,
                                                                                            stderr[-3000:])


# ---------------------------------------------------------------------------- 9, 10, 13, 14: the smaller refusals
@pytest.mark.parametrize("speed_kph", ["20", "0.36"])
def test_a_lane_change_needing_a_steer_beyond_the_range_is_refused(speed_kph):
    p = lcv("simulate", "--preset", "aucnat", "--speed-kph", speed_kph, "--steer", "lane-change:2g:0.4",
            "--t-end", "10", "--dt", "0.01")
    line = one_line(p)
    assert "needs a peak steer of" in line and "[-1, 1] rad" in line and p.stdout == ""


def test_the_peak_steer_of_the_refusal_is_the_continuous_responses():
    """The refusal's number is max|delta| of the inverse system's output (against a fine sample)."""
    from lcvreport import load_preset
    from lcvreport.analysis.exact import ManoeuvreError, check_lane_change_steer, response
    from lcvreport.manoeuvres.steer import parse_steer
    v, u = load_preset("aucnat"), 20 / 3.6
    r = response(v, u, parse_steer("lane-change:2g:0.4"), 10.0, 1e-3)
    fine = float(np.abs(r["delta"]).max())
    with pytest.raises(ManoeuvreError, match=r"needs a peak steer of (\d\.\d+) rad") as exc:
        check_lane_change_steer(r)
    peak = float(exc.value.args[0].split("peak steer of ")[1].split(" rad")[0])
    assert abs(peak - fine) <= 1e-3 * fine
    check_lane_change_steer(response(v, 88 / 3.6, parse_steer("lane-change:0.15g:0.4"), 10.0, 0.01))   # in range


def test_tracking_stats_refuses_an_axle_named_twice_and_a_negative_seed():
    base = ["tracking", "stats", "--preset", "aucnat", "--speed-kph", "88", "--conicity", "normal:0:120",
            "--ply-steer", "normal:40:60", "--mounting", "random", "--draws", "100"]
    assert "argument --axles: axle '21' is named twice" in one_line(lcv(*base, "--axles", "21,21"))
    assert "argument --seed: must be in [0, 2^63)" in one_line(lcv(*base, "--seed", "-1"))


def test_an_integer_of_thousands_of_digits_is_named_by_its_key(tmp_path):
    import re
    text = (ROOT / "examples" / "vehicles" / "b_double.toml").read_text()
    path = tmp_path / "v.toml"
    path.write_text(re.sub(r"mass_kg = [0-9.]+", "mass_kg = " + "9" * 5000, text, count=1))
    line = one_line(lcv("eig", "--vehicle", path, "--speed-kph", "88"))
    number = next(k for k, row in enumerate(text.splitlines(), 1) if row.startswith("mass_kg"))
    assert f"line {number}: mass_kg is an integer of 5000 digits" in line and "set_int_max_str_digits" not in line
    crit = tmp_path / "c.toml"
    crit.write_text("[limits]\nhsto_m = { max = " + "1" * 5000 + ", source = \"x\" }\n")
    assert "integer of 5000 digits" in one_line(
        lcv("measures", "--preset", "aucnat", "--speed-kph", "88", "--criteria", crit))


def test_a_name_holding_a_newline_and_an_escape_is_one_line_of_plain_text(tmp_path):
    text = (ROOT / "examples" / "vehicles" / "b_double.toml").read_text()
    path = tmp_path / "v.toml"
    path.write_text(text.replace('name = "prime_mover"', 'name = "prime\\nmo\\u001b[31mver"', 1))
    p = lcv("eig", "--vehicle", path, "--speed-kph", "88")
    line = one_line(p)
    assert "\x1b" not in p.stderr and '"prime\\nmo\\u001b[31mver"' in line


def test_a_unit_whose_inertia_makes_the_eigenvalues_unreliable_is_refused(tmp_path):
    """1e6 kg with 1e-10 kg m^2 (a radius of gyration of 1e-8 m): numpy read it unstable at 8 km/h
    (an eigenvalue 0) where mpmath gives -0.731 1/s; it is refused, naming the unit and the key."""
    path = tmp_path / "v.toml"
    path.write_text('format = "lcv-vehicle/1"\nname = "t"\n[[units]]\nname = "truck"\nmass_kg = 1.0e6\n'
                    'yaw_inertia_kg_m2 = 1.0e-10\n'
                    + "".join(f'  [[units.axles]]\n  name = "{n}"\n  x_m = {x}\n  tires = {t}\n  steered = {s}\n'
                              "  cornering_stiffness_N_per_rad = 2.0e5\n  aligning_stiffness_Nm_per_rad = 0.0\n"
                              "  longitudinal_stiffness_N = 0.0\n  dual_spacing_m = 0.0\n"
                              for n, x, t, s in (("f", 1.5, 2, "true"), ("r", -3.5, 4, "false"))))
    for cmd in (["eig"], ["measures"]):
        line = one_line(lcv(*cmd, "--vehicle", path, "--speed-kph", "8"))
        assert 'units[0] "truck"' in line and "yaw_inertia_kg_m2" in line and "radius of gyration" in line


def test_the_smallest_radius_of_gyration_accepted_still_gives_the_eigenvalues_of_mpmath():
    """At the limit (radius of gyration 1e-3 of the reach) the eigenvalues equal a 60-digit mpmath
    computation to 1e-9: the refusal starts where the numbers stop being right, not before."""
    import mpmath as mp
    from lcvreport.model.vehicle import Axle, Unit, Vehicle
    from lcvreport import eigenvalues, system_matrices
    from lcvreport.ranges import GYRATION_PER_REACH_MIN
    m, reach = 1.0e6, 3.5
    inertia = m * (1.0001 * GYRATION_PER_REACH_MIN * reach) ** 2
    v = Vehicle("t", (Unit("truck", m, inertia, (Axle("f", 1.5, 2, 2e5, 0.0, 0.0, 0.0, steered=True),
                                                  Axle("r", -3.5, 4, 1.5e5, 0.0, 0.0, 0.0))),))
    with pytest.raises(Exception, match="radius of gyration"):
        Unit("truck", m, inertia / 1.01 ** 2 / 1.0002, v.units[0].axles)
    mp.mp.dps = 60
    for kph in (2.0, 8.0, 88.0, 200.0):
        M, S = system_matrices(v, kph / 3.6)
        ref = [complex(z) for z in mp.eig(mp.inverse(mp.matrix(M.tolist())) * mp.matrix(S.tolist()))[0]]
        got = eigenvalues(v, kph / 3.6)
        for z in ref:
            assert min(abs(g - z) for g in got) <= 1e-9 * abs(z), (kph, z, got)
