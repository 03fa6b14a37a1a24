"""Hostile input round five and what an assessor tripped on (issue 40): each numbered item of the
issue has its test here (or says where it is); each failed on the main of 2026-12-05.  Every
command runs in a process of its own with a time limit only a hang reaches."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lcvreport.measures.assess import assess
from lcvreport.measures.scheme import SchemeError, loads_scheme
from lcvreport.model.presets import load_preset
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLES, ROOT

LCV = [sys.executable, "-m", "lcvreport.cli"]
HANG_S = 120
TEMPLATE = ROOT / "examples" / "schemes" / "template.toml"


def lcv(*args, cwd=None, env=None, timeout=HANG_S):
    return subprocess.run(LCV + [str(a) for a in args], capture_output=True, text=True, timeout=timeout, cwd=cwd,
                          env=env)


def one_line(p, status=2):
    lines = p.stderr.strip().splitlines()
    assert p.returncode == status and len(lines) == 1 and lines[0].startswith("lcv: error: "), p.stderr
    assert "Traceback" not in p.stderr and "internal error" not in p.stderr
    return lines[0]


def scheme_text(levels=("L1", "L2"), name="s", key="hsso_m", limits=(0.5, 1.0), extra="", conditions="speed_kph = 100.0"):
    table = ", ".join(f"{json.dumps(lv)} = {{ max = {b} }}" for lv, b in zip(levels, limits))
    return (f"scheme = {json.dumps(name)}\nlevels = [{', '.join(json.dumps(lv) for lv in levels)}]\n{extra}"
            f"[measures.{json.dumps(key)}]\n{conditions}\nsource = \"test\"\nlevels = {{ {table} }}\n")


# ---------------------------------------------------------------------------- 16: scripts and TeX in a scheme
def test_16_a_level_with_tex_does_not_stop_the_report_and_a_nul_is_refused_when_read(tmp_path):
    """(The browser tests in tests/browser/ load such reports and click every link.)"""
    path = tmp_path / "s.toml"
    path.write_text(scheme_text(levels=("L1", "$\\href{x}{y}$")), encoding="utf-8")
    p = lcv("assess", "--preset", "aucnat", "--scheme", path, "--out", tmp_path / "r", "--no-pdf", timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    assert (tmp_path / "r" / "index.html").exists()
    for bad in ("\x00", "\x1b]0;title\x07", "\n", "\u202e"):
        with pytest.raises(SchemeError, match=r"control character U\+"):
            loads_scheme(scheme_text(levels=("L1", f"L{bad}2")))
    path.write_text(scheme_text(name="evil \x1b[31mred"), encoding="utf-8")
    line = one_line(lcv("assess", "--preset", "aucnat", "--scheme", path))
    assert "\x1b" not in line and "U+001B" in line


# ---------------------------------------------------------------------------- 17: a user's files
@pytest.fixture(scope="module")
def earlier_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("earlier") / "rep"
    p = lcv("assess", "--preset", "tractor_semitrailer", "--scheme", TEMPLATE, "--out", out, "--no-pdf",
            timeout=600)
    assert p.returncode == 0, p.stderr[-2000:]
    return out


@pytest.mark.parametrize("where", ["data/mine.csv", "notebooks/notes.txt", "mathjax/mine.js"])
def test_17_a_file_a_user_added_inside_an_earlier_report_is_never_removed(earlier_report, tmp_path, where):
    import shutil
    out = tmp_path / "rep"
    shutil.copytree(earlier_report, out)
    mine = out / where
    mine.write_text("mine")
    line = one_line(lcv("assess", "--preset", "tractor_semitrailer", "--scheme", TEMPLATE, "--out", out, "--no-pdf"))
    assert where in line and mine.read_text() == "mine"


def test_17_a_report_file_a_user_edited_is_never_replaced(earlier_report, tmp_path):
    import shutil
    out = tmp_path / "rep"
    shutil.copytree(earlier_report, out)
    (out / "index.html").write_text("my notes")
    line = one_line(lcv("assess", "--preset", "tractor_semitrailer", "--scheme", TEMPLATE, "--out", out, "--no-pdf"))
    assert "index.html (changed" in line and (out / "index.html").read_text() == "my notes"


def test_17_an_unchanged_earlier_report_is_replaced(earlier_report, tmp_path):
    import shutil
    out = tmp_path / "rep"
    shutil.copytree(earlier_report, out)
    p = lcv("assess", "--preset", "tractor_semitrailer", "--scheme", TEMPLATE, "--out", out, "--no-pdf", timeout=600)
    assert p.returncode == 0, p.stderr
    assert not [q for q in tmp_path.iterdir() if q.name.startswith(".rep.")]


def test_17_an_interruption_during_the_publish_waits_for_it(tmp_path, monkeypatch):
    """SIGTERM (as the CLI turns it into KeyboardInterrupt) arriving while the old report is being
    removed: the removal finishes, the new report is in place whole, nothing is left beside it,
    and the interruption is raised after -- deterministic: the signal is sent from inside."""
    import shutil

    from lcvreport.report import publish
    out, staged = tmp_path / "rep", tmp_path / ".rep.writing-1"
    for folder, text in ((out, "old"), (staged, "new")):
        (folder / "data").mkdir(parents=True)
        (folder / "index.html").write_text(text)
        (folder / "data" / "x.csv").write_text(text)
        publish.write_manifest(folder, "test")
    before = publish.folder_state(out)
    real_rmtree = shutil.rmtree

    def rmtree_interrupted(path, *a, **kw):
        os.kill(os.getpid(), signal.SIGTERM)          # arrives in the middle of the removal
        return real_rmtree(path, *a, **kw)

    def terminated(_signum, _frame):
        raise KeyboardInterrupt
    previous = signal.signal(signal.SIGTERM, terminated)
    monkeypatch.setattr(publish.shutil, "rmtree", rmtree_interrupted)
    try:
        with pytest.raises(KeyboardInterrupt):
            publish.publish_staged(staged, out, before)
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert (out / "index.html").read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["rep"]          # no half-removed copy beside it


def test_17_the_verdict_is_printed_before_the_report_is_written(tmp_path):
    busy = tmp_path / "rep"
    p = subprocess.Popen(LCV + ["assess", "--preset", "tractor_semitrailer", "--scheme", str(TEMPLATE), "--out",
                                str(busy), "--no-pdf"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = p.stdout.readline()                                           # the verdict, while the report runs
    assert first.startswith("tractor_semitrailer assessed against"), first
    p.stdout.read()
    p.wait(timeout=600)
    assert p.returncode == 0


# ---------------------------------------------------------------------------- 7: a FIFO through the Python API
def test_07_the_api_refuses_a_fifo_scheme_without_reading_it(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    code = ("import sys; from lcvreport import load_preset; from lcvreport.report.build import build_scheme_report; "
            "from lcvreport.report.notebooks import ReportError\n"
            f"try:\n    build_scheme_report(load_preset('aucnat'), {str(fifo)!r}, {str(tmp_path / 'r')!r})\n"
            "except ReportError as exc:\n    print(exc)")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=HANG_S)
    assert p.returncode == 0 and "FIFO" in p.stdout, p.stdout + p.stderr
    assert not (tmp_path / "r").exists()


# ---------------------------------------------------------------------------- 8: two writers
def test_08_a_second_report_into_a_folder_being_written_is_refused(tmp_path):
    from lcvreport.report.publish import WriterLock
    out = tmp_path / "rep"
    with WriterLock(out):                                  # the first writer holds the folder
        line = one_line(lcv("assess", "--preset", "tractor_semitrailer", "--scheme", TEMPLATE, "--out", out,
                            "--no-pdf"))
        assert f"process {os.getpid()}" in line and not out.exists()
    p = lcv("assess", "--preset", "tractor_semitrailer", "--scheme", TEMPLATE, "--out", out, "--no-pdf", timeout=600)
    assert p.returncode == 0, p.stderr                     # free again once the first is done
    assert not (tmp_path / ".rep.lock").exists()


# ---------------------------------------------------------------------------- 9: FMU names per model
def test_09_the_yaw_plane_and_yaw_roll_fmus_of_one_vehicle_sit_in_one_folder_and_one_host(tmp_path):
    import zipfile

    from fmpy import simulate_fmu
    paths = []
    for model in ("yaw-plane", "yaw-roll"):
        p = lcv("fmu", "--vehicle", EXAMPLES / "b_double.toml", "--model", model, "--kind", "native", "--out",
                tmp_path, timeout=600)
        assert p.returncode == 0, p.stderr
        paths.append(Path(p.stdout.split()[-1]))
    assert [q.name for q in paths] == ["b_doubleNative.fmu", "b_double_yaw_rollNative.fmu"]
    ids = []
    for q in paths:
        with zipfile.ZipFile(q) as z:
            xml = z.read("modelDescription.xml").decode()
        ids.append(xml.split('modelIdentifier="', 1)[1].split('"', 1)[0])
    assert ids == [q.stem for q in paths]
    runs = [simulate_fmu(str(q), stop_time=1.0, output_interval=0.1, start_values={"delta": 0.01}) for q in paths]
    assert all(np.isfinite(r["r1"]).all() for r in runs)                # both in one process


# ---------------------------------------------------------------------------- 14: file modes
def test_14_a_plot_file_gets_the_umasks_mode(tmp_path):
    out = tmp_path / "srt.png"
    p = subprocess.run(["sh", "-c", f"umask 022; exec {sys.executable} -m lcvreport.cli roll --vehicle "
                                    f"{EXAMPLES / 'b_double.toml'} --speed-kph 80 --plot {out}"],
                       capture_output=True, text=True, timeout=HANG_S)
    assert p.returncode == 0, p.stderr
    assert out.stat().st_mode & 0o777 == 0o644


# ---------------------------------------------------------------------------- 18: valid schemes, right verdicts
def test_18_a_scheme_of_the_trim_alone_is_judged():
    s = loads_scheme('scheme = "t"\nlevels = ["L1"]\n[measures."trim.delta_rad"]\nspeed_kph = 88.0\nsource = "x"\n'
                     'levels = { L1 = { max = 0.01, abs = true } }\n')
    a = assess(load_preset("aucnat"), s, load_units=["trailer2"])
    m = a.measures[0]
    assert m.value is not None and m.verdicts == {"L1": "pass"}
    from lcvreport.measures.measure_set import measure_set
    from lcvreport.units import kph_to_mps
    assert m.value == measure_set(load_preset("aucnat"), kph_to_mps(88.0), load_units=["trailer2"]).trim.delta_rad


@pytest.mark.parametrize("levels", [("value", "unit"), ("level reached", "L2"), ("L1_kph", "PBS_m"),
                                    ("measure", "conditions")])
def test_18_level_names_are_levels_whatever_they_are_called(levels):
    s = loads_scheme(scheme_text(levels=levels, limits=(0.5, 1.0)))
    a = assess(load_preset("aucnat"), s)
    rows = a.rows()
    cols = a.level_columns()
    assert list(cols.values()) == list(levels)
    first = rows[0]
    assert first["value"] == f"{a.measures[0].value:.4g}" and first["unit"] == "m"           # untouched
    assert first["level reached"] == (a.measures[0].level_reached or "none")
    verdicts = [first[c].split()[0] for c in cols]
    assert verdicts == ["FAIL", "pass"]                     # hsso_m 0.752 m against 0.5 and 1.0
    from lcvreport.report.tables import Table
    t = Table("A-1", "c", rows, columns=["measure", "value", "unit", *cols, "level reached"], headers=cols)
    assert t.headers == ["measure", "value", "unit", *levels, "level reached"]      # no "L1 [km/h]"


def test_18_a_relative_limit_that_overflows_is_a_limit_all_the_same():
    with np.errstate(all="raise"):                          # and no numpy warning on the way
        s = loads_scheme(scheme_text(key="hsso_m", levels=("L1",), limits=('"1e308 * ra_peak"',)))
        a = assess(load_preset("aucnat"), s)
    m = a.measures[0]
    assert m.verdicts == {"L1": "pass"} and "= inf" in m.limit_texts["L1"]


def test_18_a_level_name_cannot_forge_a_line_of_the_verdict():
    with pytest.raises(SchemeError, match=r"levels\[1\]: text only"):
        loads_scheme(scheme_text(levels=("L1", "L2\n  level reached by the vehicle: L1")))


# ---------------------------------------------------------------------------- 10, 11, 13: the verdict page and JSON
def _heavy_ydc():
    """The tractor-semitrailer at a speed where its joint is heavily damped (YDC null, bound 0.690)."""
    from lcvreport.measures.yaw_damping import yaw_damping_coefficient
    v = load_preset("tractor_semitrailer")
    for kph in (20.0, 30.0, 40.0, 50.0, 60.0):
        if yaw_damping_coefficient(v, kph / 3.6).value is None:
            return v, kph
    pytest.fail("no heavily damped speed found")


def test_10_a_heavily_damped_ydc_shows_its_bound_everywhere(tmp_path):
    v, kph = _heavy_ydc()
    text = scheme_text(key="yaw_damping_coefficient", levels=("L1",), limits=(0.15,),
                       conditions=f"speed_kph = {kph}").replace("max = 0.15", "min = 0.15")
    a = assess(v, loads_scheme(text))
    m = a.measures[0]
    assert m.value is None and m.lower_bound == pytest.approx(0.6901, abs=1e-4)
    assert m.verdicts == {"L1": "pass"} and m.value_text() == ">= 0.6901 (every joint heavily damped)"
    assert m.to_dict()["lower_bound"] == m.lower_bound
    assert a.rows()[0]["value"].startswith(">= 0.6901")
    assert a.evidence(m.key).kind == "pulse"                  # the decay is drawn, not an empty value plot


def test_11_13_the_json_names_the_vehicle_the_version_the_files_and_every_resolved_limit(tmp_path):
    from importlib.metadata import version
    import hashlib
    p = lcv("assess", "--vehicle", EXAMPLES / "b_double.toml", "--scheme", TEMPLATE, "--json", timeout=600)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["vehicle"] == "b_double" and doc["lcvreport_version"] == version("lcvreport")
    assert doc["files"]["vehicle"] == {"name": "b_double.toml",
                                       "sha256": hashlib.sha256((EXAMPLES / "b_double.toml").read_bytes()).hexdigest()}
    assert doc["files"]["scheme"]["sha256"] == hashlib.sha256(TEMPLATE.read_bytes()).hexdigest()
    srt = next(m["value"] for m in doc["measures"] if m["key"] == "srt_rrcu_g")
    ra = next(m for m in doc["measures"] if m["key"].startswith("ra_lane_change"))
    assert ra["limits_resolved"]["L1"]["max"] == pytest.approx(5.7 * srt, rel=1e-12)
    assert ra["margins"]["L1"] == pytest.approx(5.7 * srt - ra["value"], rel=1e-12)
    assert doc["level_reached"] is None and doc["reason"]                   # why it reaches no level
    assert all(m["standard"] for m in doc["measures"])


def test_11_the_verdict_page_prints_the_files_name_not_the_machines_path(tmp_path):
    p = lcv("assess", "--vehicle", (EXAMPLES / "b_double.toml").resolve(), "--scheme", TEMPLATE, "--out",
            tmp_path / "r", "--no-pdf", timeout=600)
    assert p.returncode == 0, p.stderr
    html = (tmp_path / "r" / "index.html").read_text()
    assert str(EXAMPLES.resolve()) not in html and "b_double.toml" in html
    assert "Static Rollover Threshold (SRT)" in html and "5.7 × srt_rrcu_g = 5.7 × 0.4799 = 2.735" in html


# ---------------------------------------------------------------------------- 2: RA reference points
def test_02_the_ra_points_are_conditions_with_the_measures_defaults():
    from lcvreport.measures.registry import MEASURES, default_condition
    for key in ("ra_single_sine_roll", "ra_lane_change_roll"):
        assert {"ra_numerator", "ra_denominator"} <= set(MEASURES[key].conditions)
    assert default_condition("ra_numerator", "ra_lane_change_roll") == "sprung_cg"
    assert default_condition("ra_denominator", "ra_single_sine_roll") == "cg"
    assert default_condition("ra_denominator", "ra_lane_change_roll") == "steer_axle"


@pytest.mark.parametrize("name", ["western_double", "b_double"])
def test_02_each_point_is_the_peak_of_its_signal_in_the_exact_response(name):
    """Independent of the family: the ratio of the named signals' peaks read off the response."""
    from lcvreport.measures.measure_set import measure_values
    from lcvreport.measures.offtracking import lane_change_measures
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    u, n = 80 / 3.6, v.n_units
    r = lane_change_measures(v, u, model="yaw_roll").response
    peak = {s: float(np.abs(r.extrema(s)[1]).max()) for s in (f"as{n}", f"ay{n}", "a_steer", "ay1")}
    for num, den, top, bottom in (("sprung_cg", "steer_axle", f"as{n}", "a_steer"),
                                  ("roll_axis", "steer_axle", f"ay{n}", "a_steer"),
                                  ("sprung_cg", "cg", f"as{n}", "ay1")):
        got = measure_values(v, u, ["ra_lane_change_roll"], conditions={"ra_numerator": num, "ra_denominator": den})
        assert got["ra_lane_change_roll"] == pytest.approx(peak[top] / peak[bottom], rel=1e-9)
    assert abs(peak[f"as{n}"] / peak[f"ay{n}"] - 1) > 0.02                 # the choice matters


def test_02_a_scheme_sets_the_points_and_the_verdict_page_prints_them():
    text = scheme_text(key="ra_lane_change_roll", levels=("L1",), limits=(3.0,),
                       conditions='speed_kph = 80.0\nra_numerator = "roll_axis"')
    a = assess(load_vehicle(EXAMPLES / "western_double.toml"), loads_scheme(text))
    m = a.measures[0]
    assert m.conditions["ra_numerator"] == "roll_axis" and m.conditions["ra_denominator"] == "steer_axle"
    assert "the rearmost unit's roll axis" in a.rows()[0]["conditions"] and "the steered axle" in a.rows()[0]["conditions"]
    with pytest.raises(SchemeError, match="ra_numerator must be one of sprung_cg, roll_axis"):
        loads_scheme(scheme_text(key="ra_lane_change_roll", levels=("L1",), limits=(3.0,),
                                 conditions='speed_kph = 80.0\nra_numerator = "hitch"'))


def test_02_a_study_batches_the_points_as_each_case_computes_them():
    from lcvreport.study.compute import compute_chunk
    from lcvreport.study.spec import study_from_dict
    s = study_from_dict({"vehicle": "western_double.toml", "speed_kph": 80.0,
                         "measures": ["ra_lane_change_roll", "ra_single_sine_roll"],
                         "factors": {"trailer2.mass_scale": {"values": [0.8, 1.0]}}}, EXAMPLES)
    cols = compute_chunk(s, [0, 1])
    from lcvreport.measures.measure_set import measure_values
    for k in range(2):
        v, u, _kw = s.case(k)
        ref = measure_values(v, u, ["ra_lane_change_roll", "ra_single_sine_roll"])
        for key in ref:
            assert cols[key][k] == pytest.approx(ref[key], rel=1e-11)


# ---------------------------------------------------------------------------- 3, 19: roll no body can have
def _soft(vehicle, factor=1e-3):
    """Every suspension a thousand times softer: m g e above the roll stiffness everywhere."""
    import dataclasses
    units = tuple(dataclasses.replace(u, axles=tuple(dataclasses.replace(
        a, roll_stiffness_Nm_per_rad=a.roll_stiffness_Nm_per_rad * factor) for a in u.axles)) for u in vehicle.units)
    return dataclasses.replace(vehicle, units=units)


def test_03_a_unit_unstable_at_rest_has_no_roll_gain_or_ltr(tmp_path):
    from lcvreport.measures.measure_set import measure_set
    from lcvreport.model.vehicle_file import dumps_vehicle
    v = _soft(load_vehicle(EXAMPLES / "western_double.toml"))
    m = measure_set(v, 80 / 3.6)
    for key in ("roll_gain_deg_per_g", "ltr_lane_change", "rltr_lane_change", "ltr_single_sine",
                "ra_lane_change_roll"):
        assert m.value(key) is None and "unstable at rest" in m.reason(key), key
    assert m.srt_min_g == 0.0
    path = tmp_path / "soft.toml"
    path.write_text(dumps_vehicle(v))
    line = one_line(lcv("fmu", "--vehicle", path, "--model", "yaw-roll", "--out", tmp_path / "f"))
    assert "unstable at rest" in line and not (tmp_path / "f").exists()


def test_19_a_yaw_roll_product_no_body_can_have_is_refused(tmp_path):
    text = (EXAMPLES / "b_double.toml").read_text().replace("cg_height_m = ", "yaw_roll_product_kg_m2 = 1e8\ncg_height_m = ", 1)
    (tmp_path / "v.toml").write_text(text)
    line = one_line(lcv("roll", "--vehicle", tmp_path / "v.toml", "--speed-kph", "80"))
    assert "yaw_roll_product_kg_m2" in line and "positive definite" in line


# ---------------------------------------------------------------------------- 4: TASP
def test_04_tasp_is_marked_steady_part_only_wherever_it_is_judged():
    s = loads_scheme(scheme_text(key="tasp_m", levels=("L1",), limits=(2.9,), conditions="speed_kph = 100.0"))
    a = assess(load_vehicle(EXAMPLES / "b_double.toml"), s)
    assert "steady part only" in a.rows()[0]["measure"] and "rough road" in a.to_dict()["measures"][0]["caveat"]
    from lcvreport.cli.assess import verdict_lines
    assert any("steady part only" in line for line in verdict_lines(a))


# ---------------------------------------------------------------------------- 5: one axle
def test_05_a_rigid_unit_on_one_axle_gets_reasons_not_a_crash(tmp_path):
    import dataclasses

    from lcvreport.model.vehicle_file import dumps_vehicle
    v = load_vehicle(EXAMPLES / "western_double.toml")
    u = v.units[0]
    one = dataclasses.replace(u, axles=(u.axles[0],), rear_coupling_m=None, rear_coupling_height_m=None,
                              rear_coupling_roll_stiffness_Nm_per_rad=None)
    path = tmp_path / "one.toml"
    path.write_text(dumps_vehicle(dataclasses.replace(v, name="one", units=(one,))))
    p = lcv("measures", "--vehicle", path, "--speed-kph", "80", "--json")
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["hsso_m"] is None and "no solution" in doc["reasons"]["hsso_m"]
    assert doc["srt_min_g"] > 0                                          # quasi-static: defined
    assert lcv("roll", "--vehicle", path, "--speed-kph", "80").returncode == 0


# ---------------------------------------------------------------------------- 6: comments
def test_06_a_comment_of_many_periods_is_a_comment(tmp_path):
    text = "# loads [t]: " + " ".join(f"{k}.{k}." for k in range(20)) + "\n" + (EXAMPLES / "b_double.toml").read_text()
    (tmp_path / "v.toml").write_text(text)
    assert lcv("eig", "--vehicle", tmp_path / "v.toml", "--speed-kph", "80").returncode == 0
    deep = "a" + ".a" * 20 + " = 1\n"
    (tmp_path / "w.toml").write_text(deep)
    assert "dotted parts" in one_line(lcv("eig", "--vehicle", tmp_path / "w.toml", "--speed-kph", "80"))


# ---------------------------------------------------------------------------- 12: the evidence
def test_12_the_swings_are_close_ups_of_their_corner_not_the_plan_view():
    s = loads_scheme(scheme_text(key="max_tail_swing_m", levels=("L1",), limits=(0.3,), conditions="")
                     .replace("[measures.\"max_tail_swing_m\"]\n\n", "[measures.\"max_tail_swing_m\"]\n"))
    a = assess(load_vehicle(EXAMPLES / "b_double.toml"), s)
    fig = a.evidence("max_tail_swing_m").plot()
    ax = fig.axes[0]
    width = ax.get_xlim()[1] - ax.get_xlim()[0]
    assert width < 10.0                                   # metres around the corner, not the 40 m turn
    labels = [h.get_label() for h in ax.get_lines()]
    assert any("beyond it" in lab for lab in labels) and any("farthest" in lab for lab in labels)
    legend = ax.get_legend().get_window_extent()
    fig.canvas.draw()
    assert legend.x0 >= ax.get_window_extent().x1 - 1     # the legend beside the data, over none of it


# ---------------------------------------------------------------------------- 14: smaller
def test_14_lcv_measures_columns_line_up_and_a_shared_reason_is_said_once():
    from lcvreport.measures.measure_set import measure_set
    rows = measure_set(load_preset("aucnat"), 88 / 3.6).rows()
    p = lcv("measures", "--preset", "aucnat", "--speed-kph", "88")
    lines = p.stdout.splitlines()[1:1 + len(rows)]
    label = max(len(r["measure"]) for r in rows)
    texts = [r["value"] if isinstance(r["value"], str) else f"{r['value']:.6g}" for r in rows]
    width = max(len(t) for t in texts)
    for line, row, text in zip(lines, rows, texts):       # every value ends in one column, the unit after it
        assert line[2:2 + label].rstrip() == row["measure"]
        assert line[3 + label:3 + label + width] == text.rjust(width), line
    assert p.stdout.count("missing roll key 'cg_height_m'") == 1


def test_14_lcv_eig_runs_the_yaw_roll_model():
    p = lcv("eig", "--vehicle", EXAMPLES / "b_double.toml", "--speed-kph", "80", "--model", "yaw-roll", "--json")
    assert p.returncode == 0, p.stderr
    from lcvreport.analysis.modes import eigenvalues
    ev = np.array([complex(*x) for x in json.loads(p.stdout)["eigenvalues"]])
    ref = eigenvalues(load_vehicle(EXAMPLES / "b_double.toml"), 80 / 3.6, model="yaw_roll")
    assert np.allclose(np.sort_complex(ev), np.sort_complex(ref), rtol=1e-12)


def test_14_keys_of_the_last_release_are_aliases(tmp_path):
    from lcvreport.measures.criteria import load_criteria
    (tmp_path / "c.toml").write_text('[limits]\ntrim_delta_rad = { max = 0.01, abs = true, source = "x" }\n')
    assert list(load_criteria(tmp_path / "c.toml").limits) == ["trim.delta_rad"]
    s = loads_scheme(scheme_text(key="trim_offtracking_m", levels=("L1",), limits=(0.3,)))
    assert s.measures[0].key == "trim.offtracking_m"


def test_14_the_western_doubles_loads_carry_its_masses():
    from lcvreport.model.statics import coupling_loads
    v = load_vehicle(EXAMPLES / "western_double.toml")
    weight = 9.80665 * sum(u.mass_kg for u in v.units)
    assert sum(a.static_load_N for a in v.axles) == pytest.approx(weight, rel=1e-12)
    assert np.all(coupling_loads(v) >= -1e-6)            # no coupling pulls up
    assert "statics" in (EXAMPLES / "western_double.toml").read_text().splitlines()[0]


# ---------------------------------------------------------------------------- 15: threads
def test_15_a_thread_leaving_the_blas_limit_leaves_it_on_for_the_others():
    import threading

    from threadpoolctl import threadpool_info, threadpool_limits

    from lcvreport.util.threads import blas_threads_limited

    def blas():
        return [i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas"]
    with threadpool_limits(2, user_api="blas"):
        if max(blas()) < 2:
            pytest.fail("this OpenBLAS runs one thread at most: the test cannot see the limit")
        a_in, b_in, a_out, seen = threading.Event(), threading.Event(), threading.Event(), []

        def first():
            with blas_threads_limited():
                a_in.set()
                b_in.wait(30)
            a_out.set()

        def second():
            a_in.wait(30)
            with blas_threads_limited():
                b_in.set()
                a_out.wait(30)
                seen.append(blas())                      # the first has left; this one still computes
        threads = [threading.Thread(target=first), threading.Thread(target=second)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
        assert seen == [[1] * len(seen[0])]
        assert max(blas()) == 2                          # the caller's count back after the last


# ---------------------------------------------------------------------------- 20: messages
def test_20_deep_nesting_and_ten_thousand_levels_are_one_short_line(tmp_path):
    (tmp_path / "deep.toml").write_text('scheme = "x"\nlevels = ["L1"]\nz = ' + "[" * 100_000 + "1" + "]" * 100_000)
    line = one_line(lcv("assess", "--preset", "aucnat", "--scheme", tmp_path / "deep.toml"))
    assert "nests too deeply" in line and len(line) < 700
    levels = [f"L{k}" for k in range(100_000)]
    (tmp_path / "many.toml").write_text(scheme_text(levels=levels, limits=(1.0,)))
    line = one_line(lcv("assess", "--preset", "aucnat", "--scheme", tmp_path / "many.toml"))
    assert len(line) <= len("lcv: error: ") + 600 and "100000 levels" in line


def test_20_a_refused_number_is_printed_as_given():
    p = lcv("measures", "--preset", "aucnat", "--speed-kph", "88", "--crossfall-percent", "20.000001")
    assert "got 20.000001" in one_line(p)


def test_20_the_api_refuses_what_is_no_vehicle_no_radius_no_unit_list_in_one_line():
    from lcvreport.measures.measure_set import measure_set
    from lcvreport.measures.offtracking import steady_turn
    from lcvreport.ranges import RangeError
    for bad in ("aucnat", None, 3.0):
        with pytest.raises(TypeError, match="vehicle must be a Vehicle"):
            measure_set(bad, 20.0)
    for radius in (float("nan"), -393.0, 1e-9):
        with pytest.raises(RangeError, match="radius_m must be in"):
            steady_turn(load_preset("aucnat"), 20.0, radius_m=radius)
    with pytest.raises(KeyError, match="load_units must be a list of unit names"):
        measure_set(load_preset("aucnat"), 20.0, load_units="trailer3")
    a = assess(load_preset("aucnat"), TEMPLATE)                      # a scheme file's path is read
    assert a.scheme.name.startswith("Template")
