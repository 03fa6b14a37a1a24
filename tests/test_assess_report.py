"""The assessment report of ``lcv assess --out`` (docs/assessment.md#report): its first page is
the verdict table, it names the toolkit's version and both files' SHA-256, and the folder is
self-contained (MathJax copied, not linked: tests/browser/ renders a copy elsewhere)."""
from __future__ import annotations

import hashlib
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest

from lcvreport.measures.scheme import load_scheme

from conftest import ROOT

LCV = [sys.executable, "-m", "lcvreport.cli"]
TEMPLATE = ROOT / "examples" / "schemes" / "template.toml"


def _links(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.is_symlink()]


@pytest.fixture
def report(scheme_report):
    return scheme_report


@pytest.mark.xdist_group("scheme_report")
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
