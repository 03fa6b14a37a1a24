"""The assessment report of ``lcv assess --out`` (docs/assessment.md#report): its first page is
the verdict table, it names the toolkit's version and both files' SHA-256, and the folder is
self-contained -- copied to another path it keeps its mathematics (MathJax copied, not linked)."""
from __future__ import annotations

import hashlib
import json
import re
import shutil
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import nbformat
import pytest

from lcvreport.measures.scheme import load_scheme
from lcvreport.report.notebooks import MATHJAX, MATHJAX_PARTS, export_html

from conftest import EXAMPLES, ROOT

LCV = [sys.executable, "-m", "lcvreport.cli"]
TEMPLATE = ROOT / "examples" / "schemes" / "template.toml"
CHROMIUM = shutil.which("chromium")


def _links(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.is_symlink()]


def _rendered_math(index: Path, profile: Path) -> tuple[int, bool]:
    """(the math elements MathJax typeset, whether it reported an error) of ``index`` in headless
    Chromium (no network, a fresh profile)."""
    dom = subprocess.run([CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                          "--disable-background-networking", "--disable-component-update", "--disable-sync",
                          f"--user-data-dir={profile}", "--virtual-time-budget=20000", "--dump-dom", index.as_uri()],
                         capture_output=True, text=True, timeout=180).stdout
    return len(re.findall(r'<script type="math/tex', dom)), "Math Processing Error" in dom


@pytest.mark.skipif(not MATHJAX.exists(), reason="no MathJax on this machine (Debian's libjs-mathjax)")
def test_the_html_carries_its_mathjax_and_a_copy_renders_elsewhere(tmp_path):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("Inline $a_y = u r + \\dot v$ and displayed "
                                              "$$\\mathrm{RA} = \\frac{\\max|a_N|}{\\max|a_1|}$$")]
    built = tmp_path / "built"
    built.mkdir()
    export_html(nb, built)
    assert not _links(built)                                      # real files, nothing points outside
    for part in MATHJAX_PARTS:
        assert (built / "mathjax" / part).exists(), part
    html = (built / "index.html").read_text()
    urls = re.findall(r'<script[^>]+src="([^"]+)"', html)
    assert urls and all(not u.startswith(("/", "file:", "http")) for u in urls), urls
    copy = tmp_path / "elsewhere" / "deep" / "copy"
    shutil.copytree(built, copy, symlinks=True)
    shutil.rmtree(built)                                          # the original is gone
    if CHROMIUM is None:
        pytest.skip("no Chromium here to render the copy (the files are checked above)")
    typeset, error = _rendered_math(copy / "index.html", tmp_path / "profile1")
    assert typeset == 2 and not error
    shutil.rmtree(copy / "mathjax")                               # the control: without it, nothing is typeset
    assert _rendered_math(copy / "index.html", tmp_path / "profile2")[0] == 0


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("assess") / "report"
    vehicle = EXAMPLES / "b_double.toml"
    p = subprocess.run(LCV + ["assess", "--vehicle", str(vehicle), "--scheme", str(TEMPLATE), "--out", str(out),
                              "--json"], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return out, vehicle, json.loads(p.stdout)


def test_the_report_opens_on_the_verdict_table_and_names_what_was_assessed(report):
    out, vehicle, doc = report
    assert (out / "vehicle.toml").read_text() == vehicle.read_text()        # the user's file, as written
    assert (out / "scheme.toml").read_bytes() == TEMPLATE.read_bytes()
    page1 = subprocess.run(["pdftotext", "-l", "1", str(out / "report.pdf"), "-"], capture_output=True, text=True,
                           check=True).stdout
    flat = " ".join(page1.split())
    assert "Table A-1." in flat and "Level reached by the vehicle" in flat
    for m in load_scheme(TEMPLATE).measures:
        assert m.key in page1, m.key
    assert f"lcvreport {version('lcvreport')}" in flat
    for name in ("vehicle.toml", "scheme.toml"):
        digest = hashlib.sha256((out / name).read_bytes()).hexdigest()
        assert digest in flat.replace(" ", ""), name
    html = (out / "index.html").read_text()
    assert html.index("Table A-1.") < html.index("Figure A-1.")
    assert html.count("<strong>Figure A-") == len(doc["measures"])        # one figure of evidence per measure
    assert not _links(out)
    assert doc["levels"] == ["L1", "L2", "L3", "L4"]                        # --json with --out: the same JSON


def test_bad_out_folder_is_refused_before_anything_is_computed(tmp_path):
    busy = tmp_path / "busy"
    busy.mkdir()
    (busy / "notes.txt").write_text("mine")
    p = subprocess.run(LCV + ["assess", "--preset", "aucnat", "--scheme", str(TEMPLATE), "--out", str(busy)],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and (busy / "notes.txt").read_text() == "mine"
