"""The report: every notebook runs (fast mode), every figure and table number is in the
HTML, the CSVs are deterministic, a failing notebook fails the build loudly."""
from __future__ import annotations

import filecmp
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

FIGURES = (["1-2", "2-1", "2-2", "2-5", "2-6", "2-8", "2-10"] + [f"3-{i}" for i in range(1, 14)]
           + [f"4-{i}" for i in range(1, 17)] + [f"5-{i}" for i in range(1, 22)] + ["D.1", "D.2", "D.3"])
TABLES = (["3-1", "3-2", "3-3"] + [f"5-{i}" for i in range(1, 5)] + [f"B.{i}" for i in range(1, 6)]
          + [f"C.{i}" for i in range(1, 6)] + [f"D.{i}" for i in range(1, 6)]
          + ["eq. 3.17", "eq. 3.18", "eq. 3.20", "eq. 3.34", "eq. 4.14", "eq. 4.17"]
          + ["E.M1", "E.M2", "E.S1", "E.S2", "E.F"])
NOT_REPRODUCED = ["1-1", "1-3", "1-4", "1-5", "2-3", "2-4", "2-7", "2-9", "2-11", "4-17"]


def _build(build_dir: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "lcvreport.report", "--build-dir", str(build_dir), "--fast", *extra],
                          capture_output=True, text=True, cwd=ROOT, timeout=900)


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    d = tmp_path_factory.mktemp("report1")
    p = _build(d)
    assert p.returncode == 0, p.stderr[-4000:]
    return d


def test_every_notebook_ran_and_both_documents_exist(built):
    executed = sorted(x.stem for x in (built / "notebooks").glob("*.ipynb"))
    assert executed == sorted(x.stem for x in (ROOT / "notebooks").glob("*.ipynb"))
    html = built / "report" / "index.html"
    pdf = built / "report" / "report.pdf"
    assert html.stat().st_size > 100_000
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 100_000
    assert (built / "report" / "mathjax" / "MathJax.js").exists()


def test_html_holds_every_figure_and_table_number(built):
    text = (built / "report" / "index.html").read_text(encoding="utf-8")
    missing = [f for f in FIGURES if f"Figure {f}.</strong>" not in text]
    assert not missing, f"figures missing: {missing}"
    missing = [t for t in TABLES if f"Table {t}.</strong>" not in text]
    assert not missing, f"tables missing: {missing}"
    for f in NOT_REPRODUCED:
        assert re.search(rf"<td>{re.escape(f)}</td>", text), f"figure {f} not listed as not reproduced"
    for anchor in ("ch1", "ch3", "ch4", "ch5", "app", "audit"):
        assert f'href="#{anchor}"' in text and f'id="{anchor}"' in text


def test_html_reads_offline(built):
    text = (built / "report" / "index.html").read_text(encoding="utf-8")
    assert not re.search(r'(src|href)="https?://', text), "the HTML loads something from the network"
    assert 'src="mathjax/MathJax.js' in text
    assert "data:image/png;base64" in text or "<svg" in text


def test_every_table_has_a_csv_with_units_in_the_header(built):
    data = built / "report" / "data"
    for t in TABLES[:-5]:
        slug = t.replace(" ", "_").replace(".", "_")
        assert (data / f"table_{slug}.csv").exists(), t
    header = (data / "table_5-1.csv").read_text().splitlines()[0]
    assert "corrected_steady_in" in header and "velocity_mph" in header


def test_audit_lists_every_published_number(built):
    rows = (built / "report" / "data" / "table_A-1.csv").read_text()
    for where in ("eq. 3.17", "eq. 3.18", "eq. 3.20", "eq. 3.22-3.25", "eq. 3.34", "eq. 3.35-3.38", "eq. 4.14",
                  "eq. 4.17", "eq. 4.18-4.29", "sec. 4.5", "ch. V/VI conclusions"):
        assert where in rows, where
    for verdict in ("holds", "holds only as published", "does not hold"):
        assert verdict in rows


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
    p = subprocess.run([sys.executable, "-m", "lcvreport.report", "--build-dir", str(tmp_path / "build"), "--fast",
                        "--notebooks", str(nbdir)], capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert p.returncode != 0
    assert "broken.ipynb" in p.stderr and "cell 3" in p.stderr and "deliberately broken" in p.stderr
    assert not (stale / "index.html").exists() and not (stale / "report.pdf").exists()


def test_bad_notebook_parameter_is_named(tmp_path):
    import papermill as pm
    with pytest.raises(pm.PapermillExecutionError, match="parameter preset"):
        pm.execute_notebook(str(ROOT / "notebooks" / "ch4_triple.ipynb"), str(tmp_path / "out.ipynb"),
                            parameters={"preset": "aucant", "fast": True, "data_dir": str(tmp_path)},
                            kernel_name="python3", cwd=str(ROOT / "notebooks"), progress_bar=False)
