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
from lcvreport.study.spec import StudyError, load_study, study_from_dict

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
    from lcvreport.analysis.placement import read_measured_tires
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
    import lcvreport.study.run as run
    s, out = _small(), tmp_path / "out"
    real = Path.write_text

    def full(self, text, *a, **k):
        if self.name == ".manifest.json.tmp":
            real(self, text[: len(text) // 2], *a, **k)
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, text, *a, **k)
    monkeypatch.setattr(Path, "write_text", full)
    with pytest.raises(OSError):
        run.run_study(s, out)
    monkeypatch.setattr(Path, "write_text", real)
    assert not list(out.glob(".*.tmp")) and not (out / "manifest.json").exists()
    assert run.run_study(s, out).n_computed == 3
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
        assert addr in line and ("within 10 s" in line or "not a Dask scheduler" in line or "answers" in line), line
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
