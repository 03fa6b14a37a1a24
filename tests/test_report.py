"""The two reports.

The thesis report (``python -m lcvreport.report.build``, fast mode): every notebook runs,
every figure and table number is in the HTML, CSVs are deterministic, a failing notebook
fails the build loudly; every notebook runs for every preset it accepts and refuses the
others before any cell runs; captions follow the parameters; ``data_dir`` is absolute;
the PDF has no line or table running into the margin.

The assessment report (``lcv report``) of an example vehicle file and of a preset: both
documents, a CSV per table and figure, captions naming the vehicle and speed, and the
measures table equal to ``lcv measures``.
"""
from __future__ import annotations

import csv
import filecmp
import json
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from lcvreport.fmu.interface import vehicle_interface
from lcvreport.model.presets import PRESETS
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.report.notebooks import NOTEBOOKS, SPECS, ReportError, execute, kernel_options, overfull_boxes

from conftest import ASSESSMENTS, EXAMPLES, MOUNTED, ROOT, TRACKING_STATS, build_thesis_report as _build
from helpers import with_default_sigint

FIGURES = (["1-2", "2-1", "2-2", "2-5", "2-6", "2-8", "2-10"] + [f"3-{i}" for i in range(1, 14)]
           + [f"4-{i}" for i in range(1, 17)] + [f"5-{i}" for i in range(1, 22)] + ["D.1", "D.2", "D.3"])
TABLES = (["3-1", "3-2", "3-3"] + [f"5-{i}" for i in range(1, 5)] + [f"B.{i}" for i in range(1, 6)]
          + [f"C.{i}" for i in range(1, 6)] + [f"D.{i}" for i in range(1, 6)]
          + ["eq. 3.17", "eq. 3.18", "eq. 3.20", "eq. 3.34", "eq. 4.14", "eq. 4.17"]
          + ["E.M1", "E.M2", "E.S1", "E.S2", "E.F"])
NOT_REPRODUCED = ["1-1", "1-3", "1-4", "1-5", "2-3", "2-4", "2-7", "2-9", "2-11", "4-17"]
# Tests that share a built report run on one xdist worker (./build.sh test uses
# --dist loadgroup), so each report is built once.

#: how far a line may run into the margin [pt] (TeX's own tolerance is 0.1 pt; a table
#: that does not fit runs tens of points over)
OVERFULL_PT = 1.0


@pytest.fixture
def built(thesis_report):
    """The thesis report, built once per worker (tests/conftest.py: a session fixture; the tests
    using it share an xdist group, so a run builds it once)."""
    return thesis_report


# ---------------------------------------------------------------------------- the thesis report
@pytest.mark.xdist_group("thesis_report")
def test_every_notebook_ran_and_both_documents_exist(built):
    executed = sorted(x.stem for x in (built / "notebooks").glob("*.ipynb"))
    assert executed == sorted(s.stem for s in NOTEBOOKS)
    html = built / "report" / "index.html"
    pdf = built / "report" / "report.pdf"
    assert html.stat().st_size > 100_000
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 100_000
    assert (built / "report" / "mathjax" / "MathJax.js").exists()


@pytest.mark.xdist_group("thesis_report")
def test_html_holds_every_figure_and_table_number(built):
    text = (built / "report" / "index.html").read_text(encoding="utf-8")
    missing = [f for f in FIGURES if f"Figure {f}.</strong>" not in text]
    assert not missing, f"figures missing: {missing}"
    missing = [t for t in TABLES if f"Table {t}.</b>" not in text]
    assert not missing, f"tables missing: {missing}"
    for f in NOT_REPRODUCED:
        assert re.search(rf"<td[^>]*>{re.escape(f)}</td>", text), f"figure {f} not listed as not reproduced"
    for s in NOTEBOOKS:
        assert f'href="#{s.anchor}"' in text and f'id="{s.anchor}"' in text


@pytest.mark.xdist_group("thesis_report")
def test_the_tracking_chapter_beyond_the_thesis(built):
    """Chapter VI's open questions (issue 18): every table and figure, the population
    labelled as assumed, and no solver log in the document."""
    text = (built / "report" / "index.html").read_text(encoding="utf-8")
    for n in ("T-1", "T-2", "T-3", "T-4", "T-5"):
        assert f"Table {n}.</b>" in text, n
    for n in ("T-1", "T-2"):
        assert f"Figure {n}.</strong>" in text, n
    assert "ASSUMED (not measured)" in text
    assert "HighsMip" not in text and "tmpSolver" not in text


@pytest.mark.xdist_group("thesis_report")
def test_html_reads_offline(built):
    text = (built / "report" / "index.html").read_text(encoding="utf-8")
    assert not re.search(r'(src|href)="https?://', text), "the HTML loads something from the network"
    assert 'src="mathjax/MathJax.js' in text
    assert "data:image/svg+xml" in text                       # figures embedded


@pytest.mark.xdist_group("thesis_report")
def test_pdf_has_nothing_in_the_margin(built):
    """No table or line wider than the text (LaTeX's own measure, from the log of the run)."""
    boxes = overfull_boxes((built / "report" / "latex.log").read_text(errors="replace"))
    assert not [b for b in boxes if b[0] > OVERFULL_PT], boxes[:5]
    text = subprocess.run(["pdftotext", "-layout", str(built / "report" / "report.pdf"), "-"], capture_output=True,
                          text=True, check=True).stdout
    # the published-vs-recomputed tables read as tables: their headers are whole words
    assert "published" in text and "recomputed" in text and "the-\nsis" not in text


@pytest.mark.xdist_group("thesis_report")
def test_every_table_has_a_csv_with_units_in_the_header(built):
    data = built / "report" / "data"
    for t in TABLES[:-5]:
        slug = t.replace(" ", "_").replace(".", "_")
        assert (data / f"table_{slug}.csv").exists(), t
    header = (data / "table_5-1.csv").read_text().splitlines()[0]
    assert "corrected_steady_in" in header and "velocity_mph" in header


@pytest.mark.xdist_group("thesis_report")
def test_audit_lists_every_published_number(built):
    rows = (built / "report" / "data" / "table_A-1.csv").read_text()
    for where in ("eq. 3.17", "eq. 3.18", "eq. 3.20", "eq. 3.22-3.25", "eq. 3.34", "eq. 3.35-3.38", "eq. 4.14",
                  "eq. 4.17", "eq. 4.18-4.29", "sec. 4.5", "ch. V/VI conclusions"):
        assert where in rows, where
    for verdict in ("holds", "holds only as published", "does not hold"):
        assert verdict in rows


@pytest.mark.xdist_group("thesis_report")
def test_two_builds_give_identical_csvs(built, tmp_path):
    p = _build(tmp_path, "--no-pdf")
    assert p.returncode == 0, p.stderr[-4000:]
    a, b = built / "report" / "data", tmp_path / "report" / "data"
    names = sorted(x.name for x in a.iterdir())
    assert names == sorted(x.name for x in b.iterdir()) and len(names) > 80
    _match, mismatch, errors = filecmp.cmpfiles(a, b, names, shallow=False)
    assert not mismatch and not errors, mismatch


def test_failing_notebook_fails_the_build_and_leaves_no_stale_report(tmp_path):
    nbdir = tmp_path / "nb"
    nbdir.mkdir()
    bad = json.loads((ROOT / "notebooks" / "ch3_tractor_semitrailer.ipynb").read_text())
    bad["cells"][3]["source"] = "raise RuntimeError('deliberately broken')"
    (nbdir / "broken.ipynb").write_text(json.dumps(bad))
    stale = tmp_path / "build" / "report"
    stale.mkdir(parents=True)
    (stale / "index.html").write_text("old report")
    (stale / "report.pdf").write_text("old report")
    p = subprocess.run([sys.executable, "-m", "lcvreport.report.build", "--build-dir", str(tmp_path / "build"),
                        "--fast", "--notebooks", str(nbdir)], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert p.returncode != 0
    assert "broken.ipynb" in p.stderr and "cell 3" in p.stderr and "deliberately broken" in p.stderr
    assert not (stale / "index.html").exists() and not (stale / "report.pdf").exists()


# ---------------------------------------------------------------------------- parameters
def _accepted(stem: str) -> tuple[str, ...]:
    """The presets notebook ``stem`` serves, asked of its parameter check."""
    from lcvreport.report.notebooks import check_notebook_parameters
    ok = []
    for p in PRESETS:
        try:
            check_notebook_parameters(stem, {"preset": p})
            ok.append(p)
        except ReportError:
            pass
    return tuple(ok)


WITH_PRESET = [s.stem for s in NOTEBOOKS if "preset" in s.parameters]
#: every (notebook, preset) it accepts, but the default preset (the full build runs that); the
#: default suite runs each notebook on its first other preset, the rest are marked slow (~95 s of
#: the suite's time; ``-m slow`` runs them)
PRESET_RUNS = [pytest.param(stem, p, marks=() if k == 0 else pytest.mark.slow)
               for stem in WITH_PRESET for k, p in enumerate(q for q in _accepted(stem) if q != "aucnat")]
REFUSED = [(stem, p) for stem in WITH_PRESET for p in PRESETS if p not in _accepted(stem)]


def test_the_presets_each_notebook_serves():
    assert set(WITH_PRESET) == {"ch1_2_concepts", "ch4_triple", "appendices"}
    assert _accepted("appendices") == PRESETS
    assert _accepted("ch4_triple") == _accepted("ch1_2_concepts") == tuple(p for p in PRESETS
                                                                          if p != "tractor_semitrailer")


@pytest.mark.parametrize("stem, preset", PRESET_RUNS)
def test_every_notebook_runs_for_every_preset_it_accepts(stem, preset, tmp_path):
    out = execute(stem, tmp_path, {"fast": True, "data_dir": str(tmp_path / "data"), "preset": preset})
    nb = nbformat.read(out, as_version=4)
    errors = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "error"]
    assert not errors
    assert any((tmp_path / "data").iterdir())


@pytest.mark.parametrize("stem, preset", REFUSED)
def test_a_preset_a_notebook_cannot_serve_is_refused_before_any_cell_runs(stem, preset, tmp_path):
    with pytest.raises(ReportError, match=rf"parameter preset: this notebook serves .*needs a triple.*{preset}"):
        execute(stem, tmp_path, {"fast": True, "data_dir": None, "preset": preset})
    assert not (tmp_path / f"{stem}.ipynb").exists()          # papermill never started


def test_papermill_run_directly_stops_at_the_check_with_the_parameter_named(tmp_path):
    import papermill as pm
    with pytest.raises(pm.PapermillExecutionError, match="parameter preset"):
        pm.execute_notebook(str(ROOT / "notebooks" / "ch4_triple.ipynb"), str(tmp_path / "out.ipynb"),
                            parameters={"preset": "aucant", "fast": True, "data_dir": str(tmp_path)},
                            kernel_name="python3", cwd=str(tmp_path), progress_bar=False, **kernel_options())
    nb = nbformat.read(tmp_path / "out.ipynb", as_version=4)
    shown = [o for c in nb.cells for o in c.get("outputs", []) if o.get("output_type") == "display_data"]
    assert not shown                                           # nothing computed before the refusal


def test_each_kernel_has_its_own_unix_sockets():
    """The report's kernels start on Unix sockets named by a random token: two kernels
    started at once cannot take each other's address (on TCP a port picked free could be
    bound by another kernel first: ``Address already in use``, a report failed by timing)."""
    managers = [kernel_options()["kernel_manager_class"](kernel_name="python3") for _ in range(2)]
    assert [m.transport for m in managers] == ["ipc", "ipc"]
    assert managers[0].ip != managers[1].ip
    assert all(Path(m.ip).parent.is_dir() and len(m.ip) <= 96 for m in managers)


def test_a_temporary_folder_too_long_for_a_socket_keeps_tcp(monkeypatch, tmp_path):
    import tempfile
    monkeypatch.setattr(tempfile, "gettempdir", lambda: str(tmp_path / ("x" * 100)))
    assert kernel_options(tmp_path) == {"extra_arguments": ["--IPKernelApp.log_level=CRITICAL"],
                                        "resources": {"metadata": {"path": str(tmp_path)}}}


def test_kernels_started_together_all_run(tmp_path):
    """Four notebooks executed at once on four threads (what the report's build does) all run,
    each kernel in its folder, and the process's own folder stays where it was (papermill's
    ``cwd=`` changes it for the whole process: threads restored each other's, and the suite's
    later tests ran in a test's temporary folder)."""
    import os
    from concurrent.futures import ThreadPoolExecutor
    import papermill as pm
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell("import os\nprint(os.path.basename(os.getcwd()))")])
    nbformat.write(nb, tmp_path / "tiny.ipynb")
    for i in range(4):
        (tmp_path / f"run{i}").mkdir()
    options = [kernel_options(tmp_path / f"run{i}") for i in range(4)]
    sockets = [Path(o["kernel_manager_class"](kernel_name="python3").ip) for o in options]

    def run(i):
        out = tmp_path / f"out{i}.ipynb"
        pm.execute_notebook(str(tmp_path / "tiny.ipynb"), str(out), kernel_name="python3", progress_bar=False,
                            **options[i])
        return nbformat.read(out, as_version=4).cells[0].outputs[0]["text"]

    here = os.getcwd()
    with ThreadPoolExecutor(4) as pool:
        assert list(pool.map(run, range(4))) == [f"run{i}\n" for i in range(4)]
    assert os.getcwd() == here
    assert not [p for s in sockets for p in s.parent.glob(s.name + "-*")]     # removed at each kernel's shutdown


def _markdown_outputs(path: Path) -> str:
    nb = nbformat.read(path, as_version=4)
    return "\n".join(o["data"]["text/markdown"] for c in nb.cells for o in c.get("outputs", [])
                     if "text/markdown" in o.get("data", {}))


def test_captions_follow_the_parameters(tmp_path):
    """Run at 55 mph with legal_max, every figure of the run says so; only the published
    case (eq. 4.14, 4.17, the AU-NCAT test of Figure 4-16) keeps its own vehicle and speed."""
    out = execute("ch4_triple", tmp_path, {"fast": True, "data_dir": None, "preset": "legal_max", "speed_mph": 55.0})
    captions = dict(re.findall(r"\*\*Figure (4-\d+)\.\*\*([^\n]*)", _markdown_outputs(out)))
    assert sorted(captions, key=lambda n: int(n[2:])) == [f"4-{i}" for i in range(1, 17)]
    for number in [f"4-{i}" for i in range(1, 16)]:
        caption = captions[number].replace("published AU-NCAT values at 50 mph", "")
        assert "legal_max" in caption and "aucnat" not in caption and "50 mph" not in caption, (number, caption)
    for number in [f"4-{i}" for i in (2, 3, 4, 5, 6, 7, 8, 12, 13, 14, 15)]:
        assert "55 mph" in captions[number], (number, captions[number])
    assert "Table B.2" in captions["4-1"]                     # legal_max's dimensions table


def test_relative_data_dir_is_resolved_against_the_run_folder(tmp_path):
    """papermill run from another folder writes the CSVs where data_dir says, resolved
    to an absolute path in the notebook's working folder -- not next to the notebook."""
    import papermill as pm
    work = tmp_path / "elsewhere"
    work.mkdir()
    pm.execute_notebook(str(ROOT / "notebooks" / "appendices.ipynb"), str(work / "out.ipynb"),
                        parameters={"fast": True, "data_dir": "csv"}, kernel_name="python3", cwd=str(work),
                        progress_bar=False, **kernel_options())
    assert sorted(p.name for p in (work / "csv").iterdir())[:1] == ["figure_D_1.csv"]
    assert not (ROOT / "notebooks" / "csv").exists()


# ---------------------------------------------------------------------------- the assessment report
def _lcv(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "lcvreport.cli", *args], capture_output=True, text=True,
                          timeout=600, cwd=cwd)




@pytest.mark.xdist_group("assessment")
def test_assessment_writes_both_documents_with_a_progress_line(assessment):
    name, out, p = assessment
    assert (out / "index.html").stat().st_size > 50_000
    assert (out / "report.pdf").read_bytes()[:5] == b"%PDF-"
    text = p.stdout + p.stderr
    assert re.search(r"notebook assessment: \d+\.\d s", text)
    assert "Traceback" not in text and "WARNING" not in text


@pytest.mark.xdist_group("assessment")
def test_assessment_has_a_csv_for_every_table_and_figure(assessment):
    name, out, _p = assessment
    html = (out / "index.html").read_text(encoding="utf-8")
    figures = sorted(set(re.findall(r"Figure (\d+)\.</strong>", html)), key=int)
    tables = sorted(set(re.findall(r"Table (\d+)\.</b>", html)), key=int)
    assert len(figures) >= 9 and len(tables) >= 6
    for f in figures:
        assert (out / "data" / f"figure_{f}.csv").stat().st_size > 0, f
    for t in tables:
        assert (out / "data" / f"table_{t}.csv").stat().st_size > 0, t


@pytest.mark.xdist_group("assessment")
def test_assessment_captions_name_the_vehicle_and_the_speed(assessment):
    name, out, _p = assessment
    html = (out / "index.html").read_text(encoding="utf-8")
    # the captions as a reader sees them (user text in them is escaped Markdown: read the HTML)
    captions = [(n, re.sub(r"<[^>]+>", "", c)) for n, c in re.findall(r"<strong>Figure (\d+)\.</strong>(.*?)</p>",
                                                                       html, flags=re.S)]
    assert captions and all(name in c for _n, c in captions)
    assert sum("88 km/h" in c for _n, c in captions) >= len(captions) - 1   # Figure 1 is the drawing
    assert f"Yaw-plane and roll assessment of {name} at 88 km/h" in html


@pytest.mark.xdist_group("assessment")
def test_assessment_measures_table_equals_lcv_measures(assessment):
    name, out, _p = assessment
    args = ASSESSMENTS[name]
    if "--tracking-stats" in args:                  # a report-only option
        k = args.index("--tracking-stats")
        args = args[:k] + args[k + 2:]
    p = _lcv("measures", *args, "--speed-kph", "88", "--json")
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    with open(out / "data" / "table_4.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    seen = set()
    for row in rows:
        key = row["json_key"]
        m = re.fullmatch(r"(\w+)\[(\d+)\]", key)
        value = doc[m.group(1)][int(m.group(2))] if m else \
            doc["trim"][key.split(".")[1]] if key.startswith("trim.") else doc[key]
        if value is None:
            assert row["value"] == "none", key
        else:
            assert float(row["value"]) == value, key          # the same number, to the last bit
        seen.add(key.split("[")[0].split(".")[0])
    assert seen == set(doc) - {"reasons"}            # every measure (the reasons are the rows' notes)


@pytest.mark.xdist_group("assessment")
def test_assessment_tracking_chapter(assessment):
    """With --tires and --tracking-stats (aucnat): the population's exact moments and the
    placement plan are the package's (SPEC 13), the CSV beside each; without: a note."""
    from lcvreport import load_preset
    from lcvreport.analysis.steady import trim
    from lcvreport.tracking.placement import place_tires
    from lcvreport.tracking.tires import axle_residuals, read_mounted_tires
    from lcvreport.tracking.statistics import parse_stats_spec, stats_from_spec
    from lcvreport.model.yaw_plane.loads import ResidualSources
    name, out, _p = assessment
    html = (out / "index.html").read_text(encoding="utf-8")
    assert "Straight-line tracking" in html
    if name != "aucnat":
        assert "Not computed: no tire population" in html and not (out / "data" / "table_5b.csv").exists()
        return
    v = load_preset("aucnat")
    u = 88 / 3.6
    tires = read_mounted_tires(MOUNTED)
    # every other residual source of the report: none here (the 1 % rule is the measures' trim only)
    stats = stats_from_spec(v, u, parse_stats_spec(TRACKING_STATS))
    with open(out / "data" / "table_5b.csv", encoding="utf-8") as f:
        rows = {r["quantity"]: r["value"] for r in csv.DictReader(f)}
    assert float(rows["trimmed offtracking, mean"]) == pytest.approx(stats.offtracking_mean_m, rel=1e-5)
    assert float(rows["trimmed offtracking, standard deviation"]) == pytest.approx(stats.offtracking_sd_m, rel=1e-5)
    assert (out / "data" / "figure_9a.csv").stat().st_size > 0
    plan = place_tires(v, u, [{k: t[k] for k in ("id", "conicity_N", "ply_steer_N")} for t in tires],
                       [t["position"] for t in tires])
    with open(out / "data" / "table_5d.csv", encoding="utf-8") as f:
        shown = [(r["position"], r["tire"], r["serial_side"]) for r in csv.DictReader(f)]
    assert shown == [(r["position"], r["tire"], r["serial_side"]) for r in plan.plan]
    with open(out / "data" / "table_5e.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    F = ResidualSources(axle_residuals(v, tires)).vector(v)
    assert float(rows[0]["offtracking_m"]) == pytest.approx(trim(v, u, F).offtracking_m, rel=1e-9)
    assert abs(float(rows[1]["offtracking_m"])) <= 2e-6
    with open(out / "data" / "table_5c.csv", encoding="utf-8") as f:
        sums = {r["position"]: float(r["axle_P_N"]) for r in csv.DictReader(f) if r["position"].startswith("axle")}
    # serial side out on the left faces -y, on the right +y; "in" the opposite (by hand)
    assert sums == {"axle 51": (35 - 140) + (42 + 60) + (28 + 90) + (51 - 20),
                    "axle 61": (30 - 160) + (45 + 75) + (38 - 110) + (40 + 25)}


@pytest.mark.xdist_group("assessment")
def test_assessment_interface_table_is_the_fmu_interface(assessment):
    name, out, _p = assessment
    vehicle = load_vehicle(out / "vehicle.toml")
    with open(out / "data" / "table_6.csv", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    itf = vehicle_interface(vehicle)
    assert [(r["name"], int(r["value_reference"]), r["causality"]) for r in rows] == \
        [(v.name, v.value_reference, v.causality) for v in itf.variables]


@pytest.mark.xdist_group("assessment")
def test_assessment_pdf_has_nothing_in_the_margin(assessment):
    _name, out, _p = assessment
    boxes = overfull_boxes((out / "latex.log").read_text(errors="replace"))
    assert not [b for b in boxes if b[0] > OVERFULL_PT], boxes[:5]


def test_bad_report_arguments_are_one_line_and_exit_2(tmp_path):
    for args, fragment in ((["--preset", "aucant"], "preset"), (["--speed-kph", "900"], "speed"),
                           (["--load", "trailer9"], "load"),
                           (["--tracking-stats", "conicity=normal:0:1,mounting=out"], "ply_steer is missing"),
                           (["--tracking-stats", "conicity=normal:0:1,ply_steer=normal:0:-1,mounting=out"], "SD"),
                           (["--tracking-stats", "conicity=normal:0:1,ply_steer=normal:0:1,mounting=up"], "mounting"),
                           (["--tires", str(tmp_path / "none.csv")], "--tires")):
        base = [] if "--preset" in args else ["--preset", "aucnat"]
        p = _lcv("report", *base, *args, "--out", str(tmp_path / "r"))
        assert p.returncode == 2 and fragment in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr
        assert not (tmp_path / "r" / "index.html").exists()


def test_every_notebook_has_its_spec():
    assert sorted(SPECS) == sorted(p.stem for p in (ROOT / "notebooks").glob("*.ipynb"))


def test_markdown_cells_have_no_stray_emphasis():
    """A lone ``*`` between two word characters (``lbf*in``) turns the text that follows into
    italics in both documents; units are written with a middle dot in prose."""
    for path in sorted((ROOT / "notebooks").glob("*.ipynb")):
        for cell in nbformat.read(path, as_version=4).cells:
            if cell.cell_type == "markdown":
                text = cell.source.replace("**", "")
                assert not re.search(r"\w\*\w", text), (path.name, cell.id, text)


# ---------------------------------------------------------------------------- the output folder (issue 22)
def _tree(folder: Path) -> dict:
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def test_a_folder_with_files_the_report_did_not_write_is_refused_untouched(tmp_path):
    """--out holding a data/ folder, an index.html and the vehicle file itself: before,
    data/ was removed, index.html deleted and the vehicle file overwritten, exit 0."""
    out = tmp_path / "work"
    (out / "data").mkdir(parents=True)
    (out / "data" / "mine.csv").write_text("a,b\n1,2\n")
    (out / "index.html").write_text("<p>my page</p>")
    vehicle = out / "vehicle.toml"
    vehicle.write_text("# my comments\n" + (EXAMPLES / "western_double.toml").read_text())
    before = _tree(out)
    p = _lcv("report", "--vehicle", str(vehicle), "--out", str(out))
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "not empty" in p.stderr, p.stderr
    assert _tree(out) == before
    assert not [q for q in tmp_path.iterdir() if q.name.startswith(".")]


@pytest.mark.xdist_group("assessment")
def test_the_vehicle_file_is_copied_as_written(assessment):
    name, out, _p = assessment
    if name == "western_double":
        assert (out / "vehicle.toml").read_bytes() == (EXAMPLES / "western_double.toml").read_bytes()
    manifest = json.loads((out / ".lcv-report.json").read_text())
    assert sorted(manifest["files"]) == sorted(q.name for q in out.iterdir())
    # MathJax copied in, not linked: a copy of the folder keeps its mathematics
    assert not (out / "mathjax").is_symlink() and (out / "mathjax" / "MathJax.js").is_file()
    assert not [q for q in out.rglob("*") if q.is_symlink()]


def test_an_earlier_report_is_replaced_whole_and_a_foreign_file_beside_it_is_refused(tmp_path):
    out = tmp_path / "r"
    args = ["--preset", "tractor_semitrailer", "--no-pdf", "--out", str(out)]
    assert _lcv("report", *args).returncode == 0
    first = _tree(out)
    p = _lcv("report", *args[:2], "--speed-kph", "60", *args[2:])
    assert p.returncode == 0, p.stderr[-2000:]
    assert "at 60 km/h" in (out / "index.html").read_text(encoding="utf-8")
    assert set(_tree(out)) == set(first)
    (out / "notes.txt").write_text("mine")
    p = _lcv("report", *args)
    assert p.returncode == 2 and "notes.txt" in p.stderr, p.stderr
    assert (out / "notes.txt").read_text() == "mine"
    assert not [q for q in tmp_path.iterdir() if q.name.startswith(".")]


def _interrupted_report(tmp_path, delay_s: float, sig, group: bool = True):
    """Start ``lcv report``, wait until it writes aside, then ``delay_s`` more, then send ``sig``."""
    import os
    import time
    out = tmp_path / "r"
    proc = subprocess.Popen(with_default_sigint([sys.executable, "-m", "lcvreport.cli", "report", "--preset",
                                                 "tractor_semitrailer", "--no-pdf", "--out", str(out)]),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    deadline = time.time() + 120                     # a hang guard: the staging folder appears in ~1 s
    while not list(tmp_path.glob(".r.writing-*")) and time.time() < deadline and proc.poll() is None:
        time.sleep(0.01)
    time.sleep(delay_s)
    (os.killpg if group else os.kill)(proc.pid, sig)
    stdout, stderr = proc.communicate(timeout=120)
    return out, proc.returncode, stderr


# the interrupt swept over the report's start: before the kernel, while it starts, in the notebook
@pytest.mark.parametrize("delay_s", [0.0, 0.3, 0.8, 1.5, 3.0])
def test_ctrl_c_ends_a_report_with_one_line_and_leaves_nothing(tmp_path, delay_s):
    import signal
    out, code, stderr = _interrupted_report(tmp_path, delay_s, signal.SIGINT)   # what Ctrl-C sends: the group
    assert code == 130, (code, stderr[-3000:])
    assert "Traceback" not in stderr and stderr.strip().splitlines() == ["lcv: interrupted"], stderr
    assert not out.exists()
    assert not list(tmp_path.iterdir())


def test_sigterm_ends_a_report_as_ctrl_c_does(tmp_path):
    import signal
    out, code, stderr = _interrupted_report(tmp_path, 1.0, signal.SIGTERM, group=False)
    assert code == 130 and stderr.strip().splitlines() == ["lcv: interrupted"], (code, stderr[-3000:])
    assert not list(tmp_path.iterdir())


def test_a_killed_reports_staging_folder_is_cleared_by_the_rerun(tmp_path):
    import signal
    out, code, _stderr = _interrupted_report(tmp_path, 1.0, signal.SIGKILL)
    left = sorted(p.name.split("-")[0] for p in tmp_path.iterdir())
    assert code == -signal.SIGKILL and left in ([".r.writing"], [".r.lock", ".r.writing"])    # the lock: nobody's
    p = _lcv("report", "--preset", "tractor_semitrailer", "--no-pdf", "--out", str(out))
    assert p.returncode == 0, p.stderr[-3000:]
    assert sorted(q.name for q in tmp_path.iterdir()) == ["r"]


def test_two_reports_into_one_folder_at_once_leave_one_whole_report(tmp_path):
    out = tmp_path / "r"
    runs = [subprocess.Popen([sys.executable, "-m", "lcvreport.cli", "report", *src, "--no-pdf", "--out", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            for src in (["--preset", "tractor_semitrailer"], ["--vehicle", str(EXAMPLES / "b_double.toml")])]
    results = [(r.wait(timeout=600), r.stderr.read()) for r in runs]
    assert sorted(code for code, _ in results) in ([0, 1], [0, 2]), results
    html = (out / "index.html").read_text(encoding="utf-8")
    winner = "tractor_semitrailer" if results[0][0] == 0 else "b_double"
    loser = "b_double" if winner == "tractor_semitrailer" else "tractor_semitrailer"
    assert f"assessment of {winner}" in html and f"assessment of {loser}" not in html
    assert not [q for q in tmp_path.iterdir() if q.name.startswith(".")]


@pytest.mark.xdist_group("assessment")
def test_figure_csvs_hold_engineering_data_with_units_and_no_nan(assessment):
    """Not the plotting library's objects (_child3, 52,506 rows) and no NaN rows."""
    _name, out, _p = assessment
    for path in sorted((out / "data").glob("figure_*.csv")):
        text = path.read_text()
        header = text.splitlines()[0]
        assert "_child" not in text and "nan" not in text.lower().replace("nano", ""), path.name
        assert not header.startswith("axes,artist"), (path.name, header)
        assert len(text.splitlines()) < 20_000, path.name


@pytest.mark.xdist_group("assessment")
def test_page_one_has_the_summary_and_the_report_says_its_version(assessment):
    name, out, _p = assessment
    page1 = subprocess.run(["pdftotext", "-l", "1", str(out / "report.pdf"), "-"], capture_output=True,
                           text=True).stdout
    assert "Summary" in page1 and "least damping ratio" in page1 and "Written by lcvreport" in page1
    assert "`" not in subprocess.run(["pdftotext", str(out / "report.pdf"), "-"], capture_output=True,
                                     text=True).stdout
    html = (out / "index.html").read_text(encoding="utf-8")
    assert ".writing-" not in html                    # captions name the user's file, not the staging folder


def test_a_vehicle_without_a_steered_axle_gets_a_report_saying_what_is_not_computed(tmp_path):
    path = tmp_path / "nosteer.toml"
    path.write_text((EXAMPLES / "western_double.toml").read_text().replace("steered = true\n", ""))
    out = tmp_path / "r"
    p = _lcv("report", "--vehicle", str(path), "--no-pdf", "--out", str(out))
    assert p.returncode == 0, p.stderr[-3000:]
    assert "no steered axle" in (out / "index.html").read_text(encoding="utf-8")


def test_a4_paper(tmp_path):
    out = tmp_path / "r"
    p = _lcv("report", "--preset", "tractor_semitrailer", "--paper", "a4", "--out", str(out))
    assert p.returncode == 0, p.stderr[-3000:]
    info = subprocess.run(["pdfinfo", str(out / "report.pdf")], capture_output=True, text=True).stdout
    assert "595.276 x 841.89 pts (A4)" in info or "595.28 x 841.89" in info, info


def test_the_assessment_shows_the_manoeuvres_the_residual_sources_and_the_verdicts(tmp_path):
    out = tmp_path / "r"
    p = _lcv("report", "--preset", "tractor_semitrailer", "--misalignment", "21=0.002", "--crossfall-percent", "2",
             "--criteria", str(ROOT / "examples" / "criteria" / "example_limits.toml"), "--no-pdf", "--out", str(out))
    assert p.returncode == 0, p.stderr[-3000:]
    data = out / "data"
    for name in ("figure_10.csv", "figure_11.csv", "table_4a.csv", "table_5a.csv"):
        assert (data / name).stat().st_size > 0, name
    verdicts = list(csv.DictReader(open(data / "table_4a.csv", encoding="utf-8")))
    assert {r["measure"] for r in verdicts} >= {"ra_single_sine", "hsto_m"}
    assert all(r["verdict"] in ("pass", "fail", "not computed") for r in verdicts)
    html = (out / "index.html").read_text(encoding="utf-8")
    assert "misalignment 21 0.002 rad; crossfall 2 %" in html and "HSTO" in html
    measures = {r["json_key"]: r["value"] for r in csv.DictReader(open(data / "table_4.csv", encoding="utf-8"))}
    doc = json.loads(_lcv("measures", "--preset", "tractor_semitrailer", "--speed-kph", "88", "--misalignment",
                          "21=0.002", "--crossfall-percent", "2", "--json").stdout)
    assert float(measures["trim.offtracking_m"]) == pytest.approx(doc["trim"]["offtracking_m"], rel=1e-12)
    assert float(measures["hsto_m"]) == pytest.approx(doc["hsto_m"], rel=1e-12)


def test_a_failed_notebook_is_kept_where_the_message_says(tmp_path):
    """An assessment report's staging folder is removed when it fails: the executed notebook
    the message names is a copy outside it, and it exists."""
    out = tmp_path / "staging"
    out.mkdir()
    with pytest.raises(ReportError) as info:
        execute("assessment", out, {"fast": True, "data_dir": None, "preset": "aucnat", "vehicle_file": None,
                                    "source": None, "speed_kph": 88.0, "residuals": None,
                                    "criteria_file": str(tmp_path / "absent.toml"), "load_units": None,
                                    "tracking": None})
    kept = Path(re.search(r"executed copy: (\S+\.ipynb)\)", str(info.value)).group(1))
    assert kept.exists() and out not in kept.parents
    assert "CriteriaError" in str(info.value)
