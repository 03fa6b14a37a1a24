"""Every kind of HTML page the toolkit writes, opened offline in Debian's Chromium (issue 45): the
thesis report, a vehicle report, a vehicle report with the tracking-statistics chapter, an
assessment against a scheme -- and the same pages built from hostile schemes and vehicle files.

Each page: no console error, no page error, no failed or refused request, every image loaded,
every formula of the toolkit's own text typeset (no raw ``$...$`` left, no "Math Processing
Error"), no text of the user's typeset, MathJax's Safe extension loaded, and the same from a copy
of the folder on another path.  Hostile strings: every link clicked, no script of the user's
runs, no ``javascript:``/``data:`` link is live, no element carries an event handler.  The first
screen of each page is saved as PNG under pytest's tmp path.
"""
from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from lcvreport.report.notebooks import MATHJAX_CONFIG, MATHJAX_PARTS, export_html

from conftest import EXAMPLES, ROOT
from .chromium import MARKER, browser_session, inspect

LCV = [sys.executable, "-m", "lcvreport.cli"]

browser = pytest.fixture(scope="session")(browser_session)


def _moved(folder: Path, tmp_path: Path) -> Path:
    """A copy of ``folder`` on another path (deeper, another name), the original untouched."""
    copy = tmp_path / "elsewhere" / "deep" / f"copy of {folder.name}"
    shutil.copytree(folder, copy, symlinks=True)
    return copy


def _assert_reads(report, what: str, images: int = 1, formulas: int = 0) -> None:
    assert report.clean, f"{what}: {report.problems()}"
    assert report.images >= images and not report.broken_images, (what, report.images, report.broken_images)
    assert report.mathjax and report.safe_extension, f"{what}: MathJax's Safe extension did not load"
    assert report.math_typeset >= formulas and not report.math_errors, (what, report.math_typeset)
    assert not report.raw_math, f"{what}: formulas left as raw TeX: {report.raw_math[:5]}"
    assert report.user_text_typeset == 0, f"{what}: a user's text was typeset"
    assert not report.live_links and not report.handlers and not report.marker, (
        what, report.live_links, report.handlers)


# ---------------------------------------------------------------------------- the toolkit's own pages
@pytest.mark.xdist_group("thesis_report")
def test_the_thesis_report_reads_in_chromium_and_from_a_copy(browser, thesis_report, tmp_path):
    index = thesis_report / "report" / "index.html"
    r = inspect(browser, index, tmp_path / "thesis.png")
    _assert_reads(r, "thesis report", images=50, formulas=11)
    assert (tmp_path / "thesis.png").stat().st_size > 10_000
    copy = inspect(browser, _moved(thesis_report / "report", tmp_path) / "index.html")
    _assert_reads(copy, "thesis report, copied", images=50, formulas=11)
    assert copy.math_typeset == r.math_typeset


@pytest.mark.xdist_group("assessment")
def test_the_vehicle_reports_read_in_chromium_and_from_a_copy(browser, assessment, tmp_path):
    name, out, _p = assessment
    html = (out / "index.html").read_text(encoding="utf-8")
    if name == "aucnat":                                  # the report with the tracking-statistics chapter
        assert "Monte Carlo" in html and "mounting plan" in html.lower()
    r = inspect(browser, out / "index.html", tmp_path / f"{name}.png")
    _assert_reads(r, f"vehicle report {name}", images=9)
    assert (tmp_path / f"{name}.png").stat().st_size > 10_000
    _assert_reads(inspect(browser, _moved(out, tmp_path) / "index.html"), f"vehicle report {name}, copied", images=9)


def _verdict_table(page_text: str) -> str:
    return page_text[page_text.index("Table A-1."):page_text.index("Level reached by the vehicle")]


@pytest.mark.xdist_group("scheme_report")
def test_the_assessment_reads_in_chromium_and_its_table_says_what_the_json_says(browser, scheme_report, tmp_path):
    out, _vehicle, doc = scheme_report
    r = inspect(browser, out / "index.html", tmp_path / "assessment.png")
    _assert_reads(r, "assessment", images=len(doc["measures"]))
    _assert_reads(inspect(browser, _moved(out, tmp_path) / "index.html"), "assessment, copied",
                  images=len(doc["measures"]))
    # what the reader sees is what the JSON says: every measure's value and verdict per level
    context = browser.new_context()
    page = context.new_page()
    page.goto((out / "index.html").resolve().as_uri())
    rows = page.eval_on_selector_all("table.lcv-table", """tables => {
        const t = tables.find(x => x.querySelector('caption').innerText.startsWith('Table A-1.'));
        return Array.from(t.querySelectorAll('tbody tr')).map(tr =>
            Array.from(tr.querySelectorAll('td')).map(td => td.innerText.trim()));
    }""")
    headers = page.eval_on_selector_all("table.lcv-table", """tables => {
        const t = tables.find(x => x.querySelector('caption').innerText.startsWith('Table A-1.'));
        return Array.from(t.querySelectorAll('thead th')).map(th => th.innerText.trim());
    }""")
    context.close()
    assert len(rows) == len(doc["measures"]) + 1                      # one row per measure and the vehicle
    for row, m in zip(rows, doc["measures"]):
        cells = dict(zip(headers, row))
        assert m["key"] in cells["measure"]
        shown = float(re.match(r"[-+0-9.e]+", cells["value"]).group(0))
        assert shown == pytest.approx(m["value"], rel=5e-4)
        for level in doc["levels"]:
            word = {"pass": "pass", "fail": "FAIL", "not computed": "n/c"}[m["verdicts"][level]]
            assert cells[level].startswith(word), (m["key"], level, cells[level])
        assert cells["level reached"] == (m["level_reached"] or "none")
    assert dict(zip(headers, rows[-1]))["level reached"] == (doc["level_reached"] or "none")


# ---------------------------------------------------------------------------- MathJax shipped whole
def _math_notebook():
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("Inline $a_y = u r + \\dot v$ and displayed "
                                              "$$\\mathrm{RA} = \\frac{\\max|a_N|}{\\max|a_1|}$$")]
    return nb


def test_every_configured_mathjax_part_is_copied_and_a_copy_renders_elsewhere(browser, tmp_path):
    built = tmp_path / "built"
    built.mkdir()
    export_html(_math_notebook(), built)
    html = (built / "index.html").read_text()
    config = re.search(r'MathJax\.js\?config=([^"&]+)', html).group(1).split(",")
    assert config == list(MATHJAX_CONFIG)
    for name in config:                                   # every configuration the page asks for is shipped
        assert f"config/{name}.js" in MATHJAX_PARTS and (built / "mathjax" / "config" / f"{name}.js").is_file()
    assert not [p for p in built.rglob("*") if p.is_symlink()]
    copy = _moved(built, tmp_path)
    shutil.rmtree(built)                                  # the original is gone
    r = inspect(browser, copy / "index.html")
    assert r.clean and r.safe_extension and r.math_typeset == 2 and not r.raw_math, r.problems()


def test_a_missing_mathjax_part_is_caught(browser, tmp_path):
    export_html(_math_notebook(), tmp_path)
    (tmp_path / "mathjax" / "config" / "Safe.js").unlink()           # what the copy lacked before issue 45
    r = inspect(browser, tmp_path / "index.html")
    assert any("Safe.js" in f for f in r.failed_requests) and not r.safe_extension and not r.clean
    shutil.rmtree(tmp_path / "mathjax")                              # and without MathJax nothing is typeset
    assert inspect(browser, tmp_path / "index.html").math_typeset == 0


# ---------------------------------------------------------------------------- hostile strings
#: a script that marks the page when it runs (window.lcvPwned; alert() is caught as a dialog too)
RUN = f"window.{MARKER}=1;alert(1)"
HOSTILE = [f"<img src=x onerror=\"{RUN}\">", f"[click](javascript:{RUN})", f"$\\href{{javascript:{RUN}}}{{m}}$",
           f"<a href=\"javascript:{RUN}\">a</a>", f"<script>{RUN}</script>", f"[d](data:text/html,<script>{RUN}</script>)",
           "$\\style{color:red}{x}$", f"<svg onload=\"{RUN}\">", "$$x^2$$", "\\(y\\)"]


def _toml(text: str) -> str:
    return json.dumps(text)                               # a TOML basic string is a JSON string


def _hostile_scheme(path: Path) -> Path:
    levels = [f"L1 {HOSTILE[0]}", f"L2 {HOSTILE[2]}", f"L3 {HOSTILE[1]}"]
    limits = ", ".join(f"{_toml(lv)} = {{ max = {v}, source = {_toml('limit ' + HOSTILE[k])} }}"
                       for k, (lv, v) in enumerate(zip(levels, (0.4, 0.6, 1.0))))
    text = "\n".join([f"scheme = {_toml('Scheme ' + ' '.join(HOSTILE))}",
                      f"description = {_toml('Description ' + ' '.join(HOSTILE))}",
                      f"levels = [{', '.join(_toml(lv) for lv in levels)}]",
                      "[measures.hsso_m]", "speed_kph = 100.0", f"source = {_toml('Source ' + HOSTILE[3])}",
                      f"levels = {{ {limits} }}",
                      "[measures.lssp_m]", f"source = {_toml('Source ' + HOSTILE[4])}",
                      f"levels = {{ {', '.join(f'{_toml(lv)} = {{ max = 9.0 }}' for lv in levels)} }}"])
    path.write_text(text, encoding="utf-8")
    return path


def _hostile_vehicle(folder: Path) -> Path:
    """The b-double with a hostile description, saved under a hostile file name."""
    text = (EXAMPLES / "b_double.toml").read_text(encoding="utf-8")
    line = f"description = {_toml('Vehicle ' + ' '.join(HOSTILE))}"
    text = re.sub(r'^description = .*$', lambda _m: line, text, count=1, flags=re.M)
    assert "Vehicle <img" in text
    path = folder / f"evil $\\href{{javascript:x}}{{m}}$ <b onclick=x>[l](javascript:x).toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def hostile_pages(tmp_path_factory):
    d = tmp_path_factory.mktemp("hostile")
    vehicle, scheme = _hostile_vehicle(d), _hostile_scheme(d / "scheme.toml")
    assess = subprocess.run(LCV + ["assess", "--vehicle", str(vehicle), "--scheme", str(scheme), "--out",
                                   str(d / "assessment"), "--no-pdf"], capture_output=True, text=True, timeout=600,
                            cwd=d)
    assert assess.returncode == 0, assess.stderr[-3000:]
    report = subprocess.run(LCV + ["report", "--vehicle", vehicle.name, "--out", str(d / "report"), "--no-pdf"],
                            capture_output=True, text=True, timeout=600, cwd=d)
    assert report.returncode == 0, report.stderr[-3000:]
    return {"assessment": d / "assessment" / "index.html", "report": d / "report" / "index.html"}


@pytest.mark.xdist_group("hostile_pages")
@pytest.mark.parametrize("page", ["assessment", "report"])
def test_no_hostile_string_runs_even_when_every_link_is_clicked(browser, hostile_pages, page, tmp_path):
    r = inspect(browser, hostile_pages[page], tmp_path / f"hostile_{page}.png", click_links=True)
    _assert_reads(r, f"hostile {page}")
    # the strings are on the page, as the text the user wrote
    assert "[click](javascript:" in r.full_text and "evil $\\href{javascript:x}{m}$ <b onclick=x>" in r.full_text
    if page == "assessment":
        assert "Scheme <img src=x onerror=" in r.full_text and "L2 $\\href{javascript:" in r.full_text
    else:
        assert "Vehicle <img src=x onerror=" in r.full_text
