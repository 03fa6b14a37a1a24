"""Report orchestration: papermill executes every notebook, nbconvert builds one HTML
and one PDF.

``python -m lcvreport.report --build-dir build [--fast]`` is what ``./build.sh report``
runs.  Steps:

1. remove the previous ``index.html`` and ``report.pdf`` (a failed build never leaves a
   stale report looking fresh);
2. execute ``notebooks/*.ipynb`` with papermill (typed parameters, the venv's own
   ``python3`` kernel) into ``<build>/notebooks/``; a failing notebook stops the build
   with its name and cell;
3. merge the executed notebooks into one, without the parameter cells (their ids and
   timestamps differ from run to run), and export it with nbconvert to
   ``<build>/report/index.html`` (images embedded, MathJax shipped next to it from
   Debian's ``libjs-mathjax``, so it reads offline) and ``<build>/report/report.pdf``
   (LaTeX route, xelatex, DejaVu fonts);
4. tables and figure data are written as CSV to ``<build>/report/data/`` by the
   notebooks themselves.
"""
from __future__ import annotations

import argparse
import copy
import shutil
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOK_DIR = ROOT / "notebooks"
TEMPLATES = Path(__file__).resolve().parent / "templates"
MATHJAX = Path("/usr/share/javascript/mathjax")

#: (file stem, anchor, title) in report order
NOTEBOOKS = (
    ("ch1_2_concepts", "ch1", "Chapters I and II: the vehicles, their oscillations, tire forces"),
    ("ch3_tractor_semitrailer", "ch3", "Chapter III: the tractor-semitrailer (4 DOF)"),
    ("ch4_triple", "ch4", "Chapter IV: the triple trailer LCV (12 DOF)"),
    ("ch5_parametric", "ch5", "Chapter V: parametric study"),
    ("appendices", "app", "Appendices B-E: dimensions, masses, tires, the 12-DOF matrices"),
    ("audit", "audit", "Audit of the published numbers"),
)
TITLE = "Effect of conicity and ply steer on LCV yaw plane motion: the dissertation recomputed"


class ReportError(RuntimeError):
    """A notebook failed or an export failed; the message names where."""


def execute(stem: str, out_dir: Path, parameters: dict, notebook_dir: Path = NOTEBOOK_DIR) -> Path:
    """Execute ``<notebook_dir>/<stem>.ipynb`` with papermill into ``out_dir``."""
    import papermill as pm
    src = notebook_dir / f"{stem}.ipynb"
    dst = out_dir / f"{stem}.ipynb"
    try:
        pm.execute_notebook(str(src), str(dst), parameters=parameters, kernel_name="python3",
                            cwd=str(notebook_dir), progress_bar=False, log_output=False)
    except pm.PapermillExecutionError as exc:
        where = _failed_cell(src, dst, exc.cell_index)
        raise ReportError(f"notebook {src.name} failed in {where}: {exc.ename}: {exc.evalue} "
                          f"(executed copy: {dst})") from None
    return dst


def _failed_cell(src: Path, executed: Path, fallback: int) -> str:
    """'cell <i> (id <id>)' of the source notebook (0-based, as in the .ipynb) for the
    cell that raised; papermill's own index counts its injected parameters cell."""
    import nbformat
    try:
        run = nbformat.read(executed, as_version=4)
        source = nbformat.read(src, as_version=4)
        ids = [c.get("id") for c in source.cells]
        for cell in run.cells:
            if any(o.get("output_type") == "error" for o in cell.get("outputs", [])) and cell.get("id") in ids:
                return f"cell {ids.index(cell['id'])} (id {cell['id']})"
    except Exception:  # pragma: no cover - fall back to papermill's index
        pass
    return f"cell {fallback} of the executed copy"


def merge(executed: list[tuple[str, str, str, Path]]):
    """One notebook: title, table of contents, then every chapter without parameter cells."""
    import nbformat
    nb = nbformat.v4.new_notebook()
    nb.metadata = {"title": TITLE,
                   "kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"},
                   "language_info": {"name": "python"}}
    toc = ["# " + TITLE, "",
           "Every figure and table of J. J. Patterson, *Effect of conicity and ply steer on long combination "
           "vehicle yaw plane motion* (University of Akron, 2011), recomputed from the model of `lcvreport`, "
           "side by side with what was published, in two readings: **as published** (the thesis' load "
           "convention, its modal method, its 1 s end time) and **corrected** (unit-consistent loads, the exact "
           "response, the true steady state).", "", "## Contents", ""]
    toc += [f"{i + 1}. [{title}](#{anchor})" for i, (_s, anchor, title, _p) in enumerate(executed)]
    cells = [nbformat.v4.new_markdown_cell("\n".join(toc))]
    for stem, anchor, title, path in executed:
        src = nbformat.read(path, as_version=4)
        cells.append(nbformat.v4.new_markdown_cell(f'<a id="{anchor}"></a>\n\n# {title}'))
        for cell in src.cells:
            tags = cell.get("metadata", {}).get("tags", [])
            if "parameters" in tags or "injected-parameters" in tags or "report-skip" in tags:
                continue
            c = copy.deepcopy(cell)
            c.metadata = {}
            if c.cell_type == "code":
                c.execution_count = None
                for out in c.get("outputs", []):
                    if "execution_count" in out:
                        out["execution_count"] = None
            cells.append(c)
    for i, c in enumerate(cells):
        c["id"] = f"cell-{i:04d}"
    nb.cells = cells
    return nb


def export_html(nb, out_dir: Path) -> Path:
    """Self-contained HTML (figures inline), MathJax copied next to it."""
    from nbconvert import HTMLExporter
    exporter = HTMLExporter(template_name="lab", exclude_input=True, exclude_input_prompt=True,
                            exclude_output_prompt=True, embed_images=True)
    exporter.mathjax_url = "mathjax/MathJax.js?config=TeX-AMS_CHTML-full,Safe"
    exporter.require_js_url = ""
    body, _ = exporter.from_notebook_node(nb)
    body = body.replace('<script src=""></script>', "")
    if MATHJAX.exists():
        dst = out_dir / "mathjax"
        if not dst.exists():
            shutil.copytree(MATHJAX, dst, symlinks=False, ignore=shutil.ignore_patterns("unpacked", "test"))
    path = out_dir / "index.html"
    path.write_text(body, encoding="utf-8")
    return path


def export_pdf(nb, out_dir: Path) -> Path:
    """PDF through nbconvert's LaTeX route (xelatex) with the lcvlatex template."""
    from nbconvert import PDFExporter
    exporter = PDFExporter(template_name="lcvlatex", extra_template_basedirs=[str(TEMPLATES)], exclude_input=True,
                           exclude_input_prompt=True, exclude_output_prompt=True)
    exporter.latex_command = ["xelatex", "-interaction=batchmode", "-halt-on-error", "{filename}"]
    try:
        pdf, _ = exporter.from_notebook_node(nb, resources={"metadata": {"name": "report"}})
    except Exception as exc:  # nbconvert raises LatexFailed with the log
        raise ReportError(f"PDF export (xelatex) failed: {str(exc)[-2000:]}") from None
    path = out_dir / "report.pdf"
    path.write_bytes(pdf)
    return path


def build(build_dir: Path, fast: bool = False, pdf: bool = True, only: list[str] | None = None,
          jobs: int = 2, notebook_dir: Path | None = None) -> dict:
    """Execute the notebooks and build the report; return paths and timings.

    ``notebook_dir`` replaces ``notebooks/`` (every ``*.ipynb`` in it, sorted) -- for tests."""
    build_dir = build_dir.resolve()
    report_dir = build_dir / "report"
    nb_dir = build_dir / "notebooks"
    data_dir = report_dir / "data"
    for stale in (report_dir / "index.html", report_dir / "report.pdf"):
        stale.unlink(missing_ok=True)
    if data_dir.exists():
        shutil.rmtree(data_dir)
    for d in (report_dir, nb_dir, data_dir):
        d.mkdir(parents=True, exist_ok=True)
    if notebook_dir is None:
        notebook_dir = NOTEBOOK_DIR
        catalogue = NOTEBOOKS
    else:
        catalogue = tuple((p.stem, p.stem, p.stem) for p in sorted(Path(notebook_dir).glob("*.ipynb")))
    selected = [n for n in catalogue if only is None or n[0] in only]
    params = {"fast": bool(fast), "data_dir": str(data_dir)}
    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [(n, pool.submit(execute, n[0], nb_dir, params, Path(notebook_dir))) for n in selected]
        executed, errors = [], []
        for (stem, anchor, title), fut in futures:
            try:
                executed.append((stem, anchor, title, fut.result()))
            except ReportError as exc:
                errors.append(str(exc))
    if errors:
        raise ReportError("\n".join(errors))
    t_exec = time.perf_counter() - t0
    nb = merge(executed)
    html = export_html(nb, report_dir)
    t_html = time.perf_counter() - t0 - t_exec
    out = {"html": html, "data": data_dir, "seconds_execute": t_exec, "seconds_html": t_html}
    if pdf:
        out["pdf"] = export_pdf(nb, report_dir)
        out["seconds_pdf"] = time.perf_counter() - t0 - t_exec - t_html
    return out


def main(argv: list[str] | None = None) -> int:
    """Command-line entry of ``./build.sh report``."""
    p = argparse.ArgumentParser(description="Execute the notebooks and build build/report/{index.html,report.pdf}.")
    p.add_argument("--build-dir", type=Path, default=ROOT / "build")
    p.add_argument("--fast", action="store_true", help="coarse time grids (tests)")
    p.add_argument("--no-pdf", action="store_true", help="skip the PDF")
    p.add_argument("--only", nargs="*", help="notebook stems to run (default all)")
    p.add_argument("--notebooks", type=Path, default=None, help="another notebook folder (tests)")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    try:
        out = build(args.build_dir, fast=args.fast, pdf=not args.no_pdf, only=args.only, notebook_dir=args.notebooks)
    except ReportError as exc:
        print(f"report: error: {exc}", file=sys.stderr)
        return 1
    for key in ("html", "pdf", "data"):
        if key in out:
            print(f"report: wrote {out[key]}")
    print(f"report: {time.perf_counter() - t0:.1f} s (notebooks {out['seconds_execute']:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
