"""Report orchestration: papermill executes the notebooks, nbconvert builds one HTML and
one PDF.

Two reports:

* **the thesis report** (``./build.sh report``, ``python -m lcvreport.report.build``):
  the six notebooks of the dissertation's chapters and the audit, into
  ``<build>/report/index.html``, ``report.pdf`` and ``data/*.csv``;
* **the assessment report** of any vehicle (``lcv report``, :func:`build_assessment`):
  ``notebooks/assessment.ipynb`` with the vehicle, the speed and the loads as
  parameters, into ``<out>/index.html``, ``report.pdf`` and ``data/*.csv``.

Every notebook declares its parameters here (:data:`NOTEBOOKS`); they are checked
before any cell runs (:func:`check_notebook_parameters`, which the notebooks call too
when run by papermill directly), so a bad value or a preset a notebook cannot serve
stops with one message naming the parameter and what is valid.  Steps of a build:

1. remove the previous ``index.html`` and ``report.pdf`` (a failed build never leaves
   a stale report looking fresh);
2. execute the notebooks with papermill (the venv's own ``python3`` kernel) into
   ``<build>/notebooks/``; a failing notebook stops the build with its name and cell;
3. merge the executed notebooks into one, without the parameter cells, and export it
   with nbconvert to HTML (images embedded, MathJax shipped next to it from Debian's
   ``libjs-mathjax``, so it reads offline) and PDF (LaTeX route, xelatex);
4. tables and figure data are written as CSV by the notebooks themselves.
"""
from __future__ import annotations

if __name__ == "__main__":          # the thesis report: kernels inherit one BLAS thread
    from lcvreport.util.threads import configure_entry_point
    configure_entry_point()

import argparse
import copy
import shutil
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Callable

from ..model.loads import CONVENTIONS
from ..model.presets import PRESETS, load_preset
from ..ranges import RANGES
from ..units import MPS_PER_KPH, MPS_PER_MPH
from .reporting import md_text

TEMPLATES = Path(__file__).resolve().parent / "templates"
MATHJAX = Path("/usr/share/javascript/mathjax")
THESIS_TITLE = "Effect of conicity and ply steer on LCV yaw plane motion: the dissertation recomputed"
#: the five triple-trailer presets (chapter IV and the mode shapes of chapter II need a triple)
TRIPLES = PRESETS[:5]
#: the assessment report's default speed [km/h]
DEFAULT_SPEED_KPH = 88.0
#: tag of the merged report's cells that only the HTML shows (title, contents)
HTML_ONLY = "lcv-html-only"
#: the kernel logs errors only (its TCP-on-localhost warning is not the reader's concern)
KERNEL_ARGS = ["--IPKernelApp.log_level=CRITICAL"]
#: paper sizes of the PDF (LaTeX geometry names)
PAPERS = ("letter", "a4")


class ReportError(RuntimeError):
    """A bad parameter, a failing notebook or a failing export; the message names where."""


# ---------------------------------------------------------------------------- parameters
def _bool(name, value, _ctx):
    if not isinstance(value, bool):
        raise ReportError(f"parameter {name} must be true or false, got {value!r}")


def _data_dir(name, value, _ctx):
    if value is not None and not isinstance(value, str):
        raise ReportError(f"parameter {name} must be a folder path (text) or None, got {value!r}")


def _speed(factor, unit):
    def check(name, value, _ctx):
        r = RANGES["speed"]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not r.contains(value / factor):
            raise ReportError(f"parameter {name} must be a number in {r.text(factor, unit)}, got {value!r}")
    return check


def _t_end(name, value, _ctx):
    r = RANGES["t_end"]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (2.0 <= value <= r.high):
        raise ReportError(f"parameter {name} must be a number in [2, {r.high:g}] s (the slowest time constant is "
                          f"about 0.8 s), got {value!r}")


def _preset(accepted):
    def check(name, value, _ctx):
        if value not in accepted:
            why = "" if set(accepted) == set(PRESETS) else " (this notebook needs a triple: a dolly and three trailers)"
            raise ReportError(f"parameter {name}: this notebook serves {', '.join(accepted)}{why}; got {value!r}")
    return check


def _convention(name, value, _ctx):
    if value not in CONVENTIONS:
        raise ReportError(f"parameter {name} must be one of {', '.join(CONVENTIONS)}, got {value!r}")


def _load_units(name, value, ctx):
    vehicle = ctx.get("vehicle")
    valid = vehicle.unit_names if vehicle is not None else ()
    if value is None and name == "load_units" and ctx.get("optional_loads"):
        return
    if not isinstance(value, (list, tuple)) or not value or any(u not in valid for u in value) \
            or len(set(value)) != len(value):
        raise ReportError(f"parameter {name} must be a non-empty list of distinct units from {', '.join(valid)}, "
                          f"got {value!r}")


def _residuals(name, value, ctx):
    if value is None:
        return
    allowed = {"P_N", "T_Nm", "misalignment_rad", "crossfall_percent"}
    if not isinstance(value, dict) or set(value) - allowed:
        raise ReportError(f"parameter {name} must be None or a dict with keys {', '.join(sorted(allowed))}, "
                          f"got {value!r}")
    from ..model.loads import ResidualLoads, ResidualSources
    try:
        ResidualSources(ResidualLoads(dict(value.get("P_N", {})), dict(value.get("T_Nm", {}))),
                        dict(value.get("misalignment_rad", {})),
                        float(value.get("crossfall_percent", 0.0))).vector(ctx["vehicle"])
    except (KeyError, ValueError, TypeError) as exc:
        raise ReportError(f"parameter {name}: {exc.args[0] if exc.args else exc}") from None


def _tracking(name, value, ctx):
    if value is None:
        return
    if not isinstance(value, dict) or set(value) - {"tires", "stats"}:
        raise ReportError(f"parameter {name} must be None or a dict with keys tires, stats, got {value!r}")
    from ..analysis.tracking import TrackingError, axle_residuals, check_stats_spec
    try:
        if value.get("tires") is not None:
            if not isinstance(value["tires"], list) or not value["tires"] or \
                    not all(isinstance(t, dict) for t in value["tires"]):
                raise TrackingError("tires must be a non-empty list of mounted tires (dicts)")
            axle_residuals(ctx["vehicle"], value["tires"])
            ids = [t.get("id") for t in value["tires"] if t.get("id")]
            if len(set(ids)) != len(ids):
                raise TrackingError("tire ids must be distinct")
        if value.get("stats") is not None:
            check_stats_spec(value["stats"])
    except (TrackingError, KeyError, TypeError, ValueError) as exc:
        raise ReportError(f"parameter {name}: {exc.args[0] if exc.args else exc}") from None


def _text_or_none(name, value, _ctx):
    if value is not None and not isinstance(value, str):
        raise ReportError(f"parameter {name} must be text or None, got {value!r}")


def _vehicle_file(name, value, _ctx):
    if value is not None and not isinstance(value, str):
        raise ReportError(f"parameter {name} must be the path of a vehicle file or None, got {value!r}")


@dataclass(frozen=True)
class NotebookSpec:
    """A notebook of a report: its anchor and title, and its parameters' checks."""

    stem: str
    anchor: str
    title: str
    parameters: dict = field(default_factory=dict)


_COMMON = {"fast": _bool, "data_dir": _data_dir}
#: the thesis report's notebooks in report order, with their parameters
NOTEBOOKS = (
    NotebookSpec("ch1_2_concepts", "ch1", "Chapters I and II: the vehicles, their oscillations, tire forces",
                 {**_COMMON, "preset": _preset(TRIPLES), "speed_mph": _speed(1 / MPS_PER_MPH, "mph")}),
    NotebookSpec("ch3_tractor_semitrailer", "ch3", "Chapter III: the tractor-semitrailer (4 DOF)",
                 {**_COMMON, "speed_mph": _speed(1 / MPS_PER_MPH, "mph"), "t_end": _t_end}),
    NotebookSpec("ch4_triple", "ch4", "Chapter IV: the triple trailer LCV (12 DOF)",
                 {**_COMMON, "preset": _preset(TRIPLES), "speed_mph": _speed(1 / MPS_PER_MPH, "mph"),
                  "load_units": _load_units, "convention": _convention, "t_end": _t_end}),
    NotebookSpec("ch5_parametric", "ch5", "Chapter V: parametric study", {**_COMMON, "t_end": _t_end}),
    NotebookSpec("ch6_tracking", "ch6", "Chapter VI, beyond the thesis: its open questions on straight-line tracking",
                 dict(_COMMON)),
    NotebookSpec("appendices", "app", "Appendices B-E: dimensions, masses, tires, the 12-DOF matrices",
                 {**_COMMON, "preset": _preset(PRESETS), "speed_mph": _speed(1 / MPS_PER_MPH, "mph")}),
    NotebookSpec("audit", "audit", "Audit of the published numbers", {**_COMMON, "t_end": _t_end}),
)
#: the assessment report's notebook
ASSESSMENT = NotebookSpec("assessment", "assessment", "Yaw-plane assessment",
                          {**_COMMON, "preset": lambda n, v, c: None, "vehicle_file": _vehicle_file,
                           "source": _text_or_none, "residuals": _residuals, "criteria_file": _text_or_none,
                           "tracking": _tracking,
                           "speed_kph": _speed(1 / MPS_PER_KPH, "km/h"), "load_units": _load_units})
def _study_dir(name, value, _ctx):
    from ..study.spec import StudyError
    from ..study.results import stored_study
    if not isinstance(value, str):
        raise ReportError(f"parameter {name} must be the --out folder of lcv study, got {value!r}")
    try:
        stored_study(value)
    except StudyError as exc:
        raise ReportError(f"parameter {name}: {exc}") from None


#: the study report's notebook
STUDY = NotebookSpec("study", "study", "Study", {**_COMMON, "study_dir": _study_dir, "criteria_file": _text_or_none})
SPECS = {s.stem: s for s in NOTEBOOKS + (ASSESSMENT, STUDY)}


def check_notebook_parameters(stem: str, values: dict, strict: bool = True) -> None:
    """Check the parameters of notebook ``stem``.

    Parameters
    ----------
    stem : str
    values : dict
        The parameters (``strict``: nothing else), or a notebook's ``globals()``.
    strict : bool
        Refuse names that are not parameters of the notebook.

    Raises
    ------
    ReportError
        Naming the first bad parameter and what is valid.
    """
    spec = SPECS[stem]
    params = {k: values[k] for k in spec.parameters if k in values}
    unknown = [k for k in values if k not in spec.parameters] if strict else []
    if unknown:
        raise ReportError(f"notebook {stem} has no parameter {unknown[0]!r}; its parameters: "
                          f"{', '.join(spec.parameters)}")
    ctx: dict = {}
    if stem == "assessment":
        ctx["optional_loads"] = True
        if (params.get("preset") is None) == (params.get("vehicle_file") is None):
            raise ReportError("parameters preset and vehicle_file: give exactly one")
        if params.get("preset") is not None and params["preset"] not in PRESETS:
            raise ReportError(f"parameter preset: unknown preset {params['preset']!r}; valid: {', '.join(PRESETS)}")
        ctx["vehicle"] = _assessment_vehicle(params.get("preset"), params.get("vehicle_file"))
    elif "preset" in params:
        spec.parameters["preset"]("preset", params["preset"], ctx)
        ctx["vehicle"] = load_preset(params["preset"])
    for name, value in params.items():
        spec.parameters[name](name, value, ctx)


def _assessment_vehicle(preset, vehicle_file):
    from ..model.vehicle import VehicleError
    from ..model.vehicle_file import load_vehicle
    if preset is not None:
        return load_preset(preset)
    try:
        return load_vehicle(vehicle_file)
    except VehicleError as exc:
        raise ReportError(f"parameter vehicle_file {vehicle_file}: {exc}") from None


# ---------------------------------------------------------------------------- execution
def notebook_dir() -> Path:
    """The report notebooks (``notebooks/`` in the repository, ``lcvreport/notebooks`` installed)."""
    return Path(str(resources.files("lcvreport.notebooks")))


def execute(stem: str, out_dir: Path, parameters: dict, source_dir: Path | None = None) -> Path:
    """Check the parameters, then execute ``<source_dir>/<stem>.ipynb`` with papermill into ``out_dir``."""
    import papermill as pm
    if stem in SPECS:
        check_notebook_parameters(stem, parameters)
    src = (source_dir or notebook_dir()) / f"{stem}.ipynb"
    dst = out_dir / f"{stem}.ipynb"
    try:
        pm.execute_notebook(str(src), str(dst), parameters=parameters, kernel_name="python3",
                            cwd=str(out_dir), progress_bar=False, log_output=False, extra_arguments=KERNEL_ARGS)
    except pm.PapermillExecutionError as exc:
        if exc.ename == "KeyboardInterrupt":     # Ctrl-C reached the kernel too: an interruption, not a failure
            raise KeyboardInterrupt from None
        where = _failed_cell(src, dst, exc.cell_index)
        raise ReportError(f"notebook {src.name} failed in {where}: {exc.ename}: {exc.evalue} "
                          f"(executed copy: {_keep_failed(dst)})") from None
    return dst


def _keep_failed(executed: Path) -> Path:
    """A copy of a failed executed notebook outside the report being written (an assessment
    report's staging folder is removed when it fails): a new temporary folder."""
    import tempfile
    if not executed.exists():
        return executed
    keep = Path(tempfile.mkdtemp(prefix="lcv-failed-notebook-")) / executed.name
    shutil.copy(executed, keep)
    return keep


def _failed_cell(src: Path, executed: Path, fallback: int) -> str:
    """'cell <i> (id <id>)' of the source notebook for the cell that raised."""
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


def merge(executed: list[tuple[str, str, str, Path]], title: str, intro: str):
    """One notebook: title, table of contents, then every part without parameter cells."""
    import nbformat
    nb = nbformat.v4.new_notebook()
    nb.metadata = {"title": title, "kernelspec": {"name": "python3", "display_name": "Python 3", "language": "python"},
                   "language_info": {"name": "python"}}
    html_only = {"tags": [HTML_ONLY]}    # the PDF has its own title page and table of contents
    cells = [nbformat.v4.new_markdown_cell("# " + title, metadata=html_only), nbformat.v4.new_markdown_cell(intro)]
    if len(executed) > 1:
        toc = ["## Contents", ""] + [f"{i + 1}. [{t}](#{a})" for i, (_s, a, t, _p) in enumerate(executed)]
        cells.append(nbformat.v4.new_markdown_cell("\n".join(toc), metadata=html_only))
    for stem, anchor, part_title, path in executed:
        src = nbformat.read(path, as_version=4)
        if len(executed) > 1:
            cells.append(nbformat.v4.new_markdown_cell(f'<a id="{anchor}"></a>\n\n# {part_title}'))
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
        # one copy on the machine (Debian's libjs-mathjax, 32 MB), linked, not copied per report
        dst = out_dir / "mathjax"
        if not dst.exists() and not dst.is_symlink():
            dst.symlink_to(MATHJAX, target_is_directory=True)
    path = out_dir / "index.html"
    path.write_text(body, encoding="utf-8")
    return path


def export_pdf(nb, out_dir: Path, author: str, paper: str = "letter", title_page: bool = True) -> Path:
    """PDF through nbconvert's LaTeX route (xelatex) with the lcvlatex template; the LaTeX
    log of the last run is kept as ``latex.log`` beside it (see :func:`overfull_boxes`)."""
    from nbconvert import PDFExporter

    class _Exporter(PDFExporter):
        def run_latex(self, filename, raise_on_failure=None):
            kwargs = {} if raise_on_failure is None else {"raise_on_failure": raise_on_failure}
            ok = super().run_latex(filename, **kwargs)
            log = Path(filename).with_suffix(".log")
            if log.exists():
                shutil.copyfile(log, out_dir / "latex.log")
            return ok

    exporter = _Exporter(template_name="lcvlatex", extra_template_basedirs=[str(TEMPLATES)], exclude_input=True,
                         exclude_input_prompt=True, exclude_output_prompt=True)
    exporter.latex_command = ["xelatex", "-interaction=batchmode", "-halt-on-error", "{filename}"]
    try:
        pdf, _ = exporter.from_notebook_node(nb, resources={"metadata": {"name": "report"}, "lcv_author": author,
                                                              "lcv_paper": paper, "lcv_title_page": title_page})
    except Exception as exc:  # nbconvert raises LatexFailed with the log
        raise ReportError(f"PDF export (xelatex) failed: {str(exc)[-2000:]}") from None
    path = out_dir / "report.pdf"
    path.write_bytes(pdf)
    return path


def overfull_boxes(log_text: str) -> list[tuple[float, str]]:
    """The overfull horizontal boxes of a LaTeX log: (how much too wide [pt], the
    log's line), widest first -- a table or line that runs into the margin."""
    import re
    out = []
    lines = log_text.splitlines()
    for i, line in enumerate(lines):
        m = re.match(r"Overfull \\hbox \((\d+(?:\.\d+)?)pt too wide\)(.*)", line)
        if m:
            context = (m.group(2) + " " + (lines[i + 1] if i + 1 < len(lines) else "")).strip()
            out.append((float(m.group(1)), context))
    return sorted(out, key=lambda x: -x[0])


def _prepare(out_dir: Path) -> tuple[Path, Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    for stale in (out_dir / "index.html", out_dir / "report.pdf", out_dir / "latex.log"):
        stale.unlink(missing_ok=True)
    data_dir = out_dir / "data"
    if data_dir.exists():
        shutil.rmtree(data_dir)
    data_dir.mkdir(parents=True)
    return out_dir, data_dir


def build(build_dir: Path, fast: bool = False, pdf: bool = True, only: list[str] | None = None,
          jobs: int = 2, notebook_folder: Path | None = None, progress: Callable[[str], None] | None = None) -> dict:
    """Execute the thesis notebooks and build the thesis report; return paths and timings.

    ``notebook_folder`` replaces ``notebooks/`` (every ``*.ipynb`` in it, sorted, no
    parameter checks) -- for tests."""
    progress = progress or (lambda _text: None)
    build_dir = Path(build_dir).resolve()
    report_dir, data_dir = _prepare(build_dir / "report")
    nb_dir = build_dir / "notebooks"
    nb_dir.mkdir(parents=True, exist_ok=True)
    if notebook_folder is None:
        catalogue = [(s.stem, s.anchor, s.title) for s in NOTEBOOKS]
        src = notebook_dir()
    else:
        src = Path(notebook_folder)
        catalogue = [(p.stem, p.stem, p.stem) for p in sorted(src.glob("*.ipynb"))]
    selected = [n for n in catalogue if only is None or n[0] in only]
    params = {"fast": bool(fast), "data_dir": str(data_dir)}
    t0 = time.perf_counter()

    def run(item):
        stem, anchor, title = item
        t = time.perf_counter()
        path = execute(stem, nb_dir, dict(params), src) if notebook_folder is None else \
            _execute_unchecked(stem, nb_dir, params, src)
        progress(f"notebook {stem}: {time.perf_counter() - t:.1f} s")
        return stem, anchor, title, path

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(run, n) for n in selected]
        executed, errors = [], []
        for fut in futures:
            try:
                executed.append(fut.result())
            except ReportError as exc:
                errors.append(str(exc))
    if errors:
        raise ReportError("\n".join(errors))
    t_exec = time.perf_counter() - t0
    intro = ("Every figure and table of J. J. Patterson, *Effect of conicity and ply steer on long combination "
             "vehicle yaw plane motion* (University of Akron, 2011), recomputed from the model of `lcvreport`, side "
             "by side with what was published, in two readings: **as published** (the thesis' load convention, its "
             "modal method, its 1 s end time) and **corrected** (unit-consistent loads, the exact response, the true "
             "steady state).")
    nb = merge(executed, THESIS_TITLE, intro)
    html = export_html(nb, report_dir)
    progress("html written")
    out = {"html": html, "data": data_dir, "seconds_execute": t_exec}
    if pdf:
        out["pdf"] = export_pdf(nb, report_dir, "Recomputed with lcvreport from Patterson (2011)")
        progress("pdf written")
    return out


def _execute_unchecked(stem, nb_dir, params, src):
    import papermill as pm
    dst = nb_dir / f"{stem}.ipynb"
    try:
        pm.execute_notebook(str(src / f"{stem}.ipynb"), str(dst), parameters=params, kernel_name="python3",
                            cwd=str(nb_dir), progress_bar=False, log_output=False, extra_arguments=KERNEL_ARGS)
    except pm.PapermillExecutionError as exc:
        where = _failed_cell(src / f"{stem}.ipynb", dst, exc.cell_index)
        raise ReportError(f"notebook {stem}.ipynb failed in {where}: {exc.ename}: {exc.evalue} "
                          f"(executed copy: {dst})") from None
    return dst


#: the manifest an assessment report leaves in its folder: the names it wrote
MANIFEST = ".lcv-report.json"


class OutputFolderError(ReportError):
    """``--out`` names a folder the report may not write into (a usage error)."""


def check_output_folder(out_dir: str | Path) -> Path:
    """The folder an assessment report may be written to, resolved.

    A report goes into a new folder, an empty one, or the folder of an earlier report
    (every entry in it listed in that report's manifest, so replacing it removes nothing
    a person put there).  Anything else is refused: a report never removes or rewrites a
    file it did not write.

    Raises
    ------
    OutputFolderError
        Naming the folder and what is in the way.
    """
    import json
    out = Path(out_dir).resolve()
    if out.exists() and not out.is_dir():
        raise OutputFolderError(f"--out {out_dir}: exists and is not a folder")
    if not out.exists():
        if not out.parent.is_dir():
            raise OutputFolderError(f"--out {out_dir}: its parent folder {out.parent} does not exist")
        return out
    entries = sorted(p.name for p in out.iterdir())
    if not entries:
        return out
    manifest = out / MANIFEST
    try:
        owned = set(json.loads(manifest.read_text(encoding="utf-8"))["files"]) | {MANIFEST}
    except (OSError, ValueError, KeyError, TypeError):
        raise OutputFolderError(f"--out {out_dir}: the folder is not empty ({', '.join(entries[:3])}"
                                f"{', ...' if len(entries) > 3 else ''}) and holds no report written by lcv report; "
                                "give a new or empty folder") from None
    foreign = [e for e in entries if e not in owned]
    if foreign:
        raise OutputFolderError(f"--out {out_dir}: besides an earlier report the folder holds "
                                f"{', '.join(foreign[:3])}{', ...' if len(foreign) > 3 else ''}, which lcv report did "
                                "not write; give a new or empty folder")
    return out


def _stage(out: Path) -> Path:
    """A new hidden folder beside ``out`` to write the report into: ``.<name>.writing-<pid>-XXXX``.
    Folders of that form left by a process that no longer runs (SIGKILL, a power cut) are removed
    first: they are this command's, and nobody else writes them."""
    import os
    import re
    import tempfile
    pattern = re.compile(rf"\.{re.escape(out.name)}\.(?:writing|replaced)-(\d+)(?:-.*)?\Z")
    for p in out.parent.iterdir() if out.parent.is_dir() else ():
        m = pattern.match(p.name)
        if m and p.is_dir() and not p.is_symlink() and not _alive(int(m.group(1))):
            shutil.rmtree(p, ignore_errors=True)
    return Path(tempfile.mkdtemp(prefix=f".{out.name}.writing-{os.getpid()}-", dir=out.parent))


def _alive(pid: int) -> bool:
    import os
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _stop_kernels() -> None:
    """Kill the notebook kernels this process started (an interrupted report: the kernel runs
    in a session of its own, so Ctrl-C does not reach it, and it must not outlive -- or print
    into -- the folder about to be removed)."""
    try:
        import psutil
    except ImportError:                     # pragma: no cover - ipykernel brings psutil
        return
    try:
        children = psutil.Process().children(recursive=True)
    except psutil.Error:                    # pragma: no cover
        return
    kernels = []
    for child in children:
        try:
            if any("ipykernel" in part for part in child.cmdline()):
                child.kill()
                kernels.append(child)
        except psutil.Error:
            pass
    psutil.wait_procs(kernels, timeout=10)


def _discard(staged: Path, interrupted: bool = False) -> None:
    """Remove a report's staging folder after a failure or an interruption: its kernels first.
    After an interruption the notebook client's event loop still waits in its own thread for the
    cell the kernel was running; the loggers it reports through are silenced first, so that the
    kernel's end is not reported as an error (the interruption is the one line)."""
    if interrupted:
        import logging
        for name in ("traitlets", "nbclient", "papermill", "jupyter_client"):
            logging.getLogger(name).setLevel(logging.CRITICAL + 1)
    _stop_kernels()
    shutil.rmtree(staged, ignore_errors=True)


def _publish(staged: Path, out: Path, existed_as: tuple) -> None:
    """Move the finished report ``staged`` into place as ``out`` (renames on one file
    system: a reader sees the old report or the new one, never a mix)."""
    import os
    now = _folder_state(out)
    if now != existed_as:
        raise ReportError(f"{out} changed while the report was being written (another report into the same "
                          "folder?); nothing was replaced")
    if now[0] == "report":
        aside = out.with_name(f".{out.name}.replaced-{os.getpid()}")
        os.rename(out, aside)
        try:
            os.rename(staged, out)
        except OSError:
            os.rename(aside, out)
            raise
        shutil.rmtree(aside, ignore_errors=True)
    else:
        os.rename(staged, out)     # replaces an empty folder atomically; fails if one appeared meanwhile


def _folder_state(out: Path) -> tuple:
    if not out.exists():
        return ("absent",)
    entries = sorted(p.name for p in out.iterdir())
    if not entries:
        return ("empty",)
    try:
        return ("report", (out / MANIFEST).read_bytes())
    except OSError:
        return ("other", tuple(entries))


def build_assessment(vehicle, out_dir: str | Path, speed_mps: float | None = None, load_units=None,
                     pdf: bool = True, progress: Callable[[str], None] | None = None, fast: bool = False,
                     source: str = "", vehicle_text: str | None = None, paper: str = "letter",
                     residuals: dict | None = None, criteria_file: str | None = None,
                     tracking: dict | None = None) -> dict:
    """The assessment report of ``vehicle`` (SPEC section 10) into ``out_dir``.

    The report is written into a hidden folder beside ``out_dir`` and moved into place
    whole when it is complete; ``out_dir`` must be new, empty or an earlier report
    (:func:`check_output_folder`).  An interrupted or failed build leaves ``out_dir`` as
    it was.

    Parameters
    ----------
    vehicle : Vehicle
        A preset (by name, when ``source`` is ``"preset <name>"``) or any vehicle; it is
        written next to the report as ``vehicle.toml`` and the notebook reads that file.
    out_dir : path
    speed_mps : float, optional
        Speed of the modes, measures and time histories [m/s] (default 88 km/h).
    load_units : list of str, optional
        Units carrying the 1 % rule for the trim.
    pdf : bool
    progress : callable, optional
        Called with a line of text per step.
    fast : bool
        Coarser grids (tests).
    source : str
        Where the vehicle came from, for the report.
    vehicle_text : str, optional
        The vehicle file as the user wrote it (copied as is, comments kept); default: the
        vehicle written out.
    paper : {"letter", "a4"}
        Paper size of the PDF.
    residuals : dict, optional
        Residual sources beyond the 1 % rule: ``P_N``, ``T_Nm``, ``misalignment_rad`` (by
        axle), ``crossfall_percent``.
    criteria_file : str, optional
        Limits to judge the measures by (a verdict table).
    tracking : dict, optional
        Straight-line tracking (SPEC 13): ``tires`` (mounted tires, as
        :func:`lcvreport.analysis.tracking.read_mounted_tires` returns them) and/or ``stats``
        (a tire population, :func:`lcvreport.analysis.tracking.parse_stats_spec`).

    Returns
    -------
    dict
        ``html``, ``pdf``, ``data`` paths (in ``out_dir``) and ``seconds``.
    """
    import os
    from ..model.vehicle_file import dumps_vehicle
    from importlib.metadata import version
    __version__ = version("lcvreport")
    if paper not in PAPERS:
        raise OutputFolderError(f"paper must be one of {', '.join(PAPERS)}, got {paper!r}")
    progress = progress or (lambda _text: None)
    out = check_output_folder(out_dir)
    before = _folder_state(out)
    staged = _stage(out)
    try:
        data_dir = staged / "data"
        data_dir.mkdir()
        speed_kph = DEFAULT_SPEED_KPH if speed_mps is None else speed_mps / MPS_PER_KPH
        vehicle_file = staged / "vehicle.toml"
        text = vehicle_text if vehicle_text is not None else \
            dumps_vehicle(vehicle, header=f"The vehicle of this report ({source or vehicle.name}).")
        vehicle_file.write_text(text, encoding="utf-8")
        params = {"fast": bool(fast), "data_dir": str(data_dir), "preset": None, "vehicle_file": str(vehicle_file),
                  "source": source or None, "speed_kph": float(speed_kph), "residuals": residuals,
                  "criteria_file": None if criteria_file is None else str(Path(criteria_file).resolve()),
                  "load_units": list(load_units) if load_units else None, "tracking": tracking}
        t0 = time.perf_counter()
        nb_dir = staged / "notebooks"
        nb_dir.mkdir()
        path = execute("assessment", nb_dir, params)
        progress(f"notebook assessment: {time.perf_counter() - t0:.1f} s")
        title = f"Yaw-plane assessment of {vehicle.name} at {speed_kph:g} km/h"
        stamp = time.strftime("%Y-%m-%d", time.gmtime(int(os.environ.get("SOURCE_DATE_EPOCH", time.time()))))
        intro = (f"Linear yaw-plane model of *{md_text(vehicle.name)}* ({vehicle.n_units} units: "
                 f"{md_text(', '.join(vehicle.unit_names))}){' from ' + md_text(source) if source else ''}, assessed "
                 f"at {speed_kph:g} km/h (SI units; speeds in km/h). Written by lcvreport {__version__} on {stamp}.")
        written = _finish_single(staged, out, before, ("assessment", "assessment", title, path), title, intro,
                                 pdf, f"lcvreport {__version__} assessment of {vehicle.name}", paper,
                                 f"lcvreport {__version__} (lcv report)", progress)
    except BaseException as exc:
        _discard(staged, isinstance(exc, KeyboardInterrupt))
        raise
    res = {key: out / name for key, name in written.items()}
    res["seconds"] = time.perf_counter() - t0
    return res


def _finish_single(staged: Path, out: Path, before, part: tuple, title: str, intro: str, pdf: bool, pdf_title: str,
                   paper: str, written_by: str, progress) -> dict:
    """The end of a one-notebook report (the assessment, a study): merge, HTML, PDF, the
    manifest, then the staged folder published into ``out``; the files written, by kind."""
    import json
    nb = merge([part], title, intro)
    export_html(nb, staged)
    progress("html written")
    written = {"html": "index.html", "data": "data"}
    if pdf:
        export_pdf(nb, staged, pdf_title, paper=paper, title_page=False)
        written["pdf"] = "report.pdf"
        progress("pdf written")
    files = sorted(p.name for p in staged.iterdir()) + [MANIFEST]
    (staged / MANIFEST).write_text(json.dumps({"written_by": written_by, "files": files}, indent=1),
                                   encoding="utf-8")
    _publish(staged, out, before)
    return written


def build_study_report(study_dir, out_dir, criteria_file: str | None = None, pdf: bool = True,
                       fast: bool = False, paper: str = "letter",
                       progress: Callable[[str], None] | None = None) -> dict:
    """The report of a study's results (``lcv study ... --report DIR``): its factors, the spread
    of each measure, each measure against each factor, and pass rates against ``criteria_file``.
    Written aside and moved into place whole, as :func:`build_assessment`; ``out_dir`` must be
    new, empty or an earlier report.

    Returns
    -------
    dict
        ``html``, ``pdf``, ``data`` paths (in ``out_dir``) and ``seconds``.
    """
    import os
    from importlib.metadata import version
    from ..study.results import read_study, stored_study
    from ..study.spec import StudyError
    __version__ = version("lcvreport")
    if paper not in PAPERS:
        raise OutputFolderError(f"paper must be one of {', '.join(PAPERS)}, got {paper!r}")
    progress = progress or (lambda _text: None)
    study_dir = Path(study_dir).resolve()
    try:
        study = stored_study(study_dir)
        read_study(study_dir)                     # complete, readable: before anything is written
    except StudyError as exc:
        raise ReportError(str(exc)) from None
    out = check_output_folder(out_dir)
    before = _folder_state(out)
    staged = _stage(out)
    try:
        data_dir = staged / "data"
        data_dir.mkdir()
        params = {"fast": bool(fast), "data_dir": str(data_dir), "study_dir": str(study_dir),
                  "criteria_file": None if criteria_file is None else str(Path(criteria_file).resolve())}
        t0 = time.perf_counter()
        nb_dir = staged / "notebooks"
        nb_dir.mkdir()
        path = execute("study", nb_dir, params)
        progress(f"notebook study: {time.perf_counter() - t0:.1f} s")
        title = f"Study of {study.vehicle.name}: {study.n_cases} cases"
        stamp = time.strftime("%Y-%m-%d", time.gmtime(int(os.environ.get("SOURCE_DATE_EPOCH", time.time()))))
        intro = (f"The results of `lcv study` in {md_text(study_dir.name)}: {study.n_cases} cases of "
                 f"*{md_text(study.vehicle.name)}*, measures {md_text(', '.join(study.measures))} (SI units; speeds "
                 f"in km/h). Written by lcvreport {__version__} on {stamp}.")
        written = _finish_single(staged, out, before, ("study", "study", title, path), title, intro, pdf,
                                 f"lcvreport {__version__} study of {study.vehicle.name}", paper,
                                 f"lcvreport {__version__} (lcv study --report)", progress)
    except BaseException as exc:
        _discard(staged, isinstance(exc, KeyboardInterrupt))
        raise
    res = {key: out / name for key, name in written.items()}
    res["seconds"] = time.perf_counter() - t0
    return res


def main(argv: list[str] | None = None) -> int:
    """Command-line entry of ``./build.sh report``: the thesis report."""
    p = argparse.ArgumentParser(description="Execute the thesis notebooks and build <build>/report/{index.html,"
                                            "report.pdf,data/}.")
    p.add_argument("--build-dir", type=Path, default=Path("build"))
    p.add_argument("--fast", action="store_true", help="coarse time grids (tests)")
    p.add_argument("--no-pdf", action="store_true", help="skip the PDF")
    p.add_argument("--only", nargs="*", help="notebook stems to run (default all)")
    p.add_argument("--notebooks", type=Path, default=None, help="another notebook folder (tests)")
    args = p.parse_args(argv)
    t0 = time.perf_counter()
    try:
        out = build(args.build_dir, fast=args.fast, pdf=not args.no_pdf, only=args.only,
                    notebook_folder=args.notebooks, progress=lambda text: print(f"report: {text}", flush=True))
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
