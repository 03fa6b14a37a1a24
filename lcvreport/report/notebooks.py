"""The report notebooks: their parameters and the checks of every value, papermill
execution, the merge of several notebooks into one, and the HTML and PDF export
(nbconvert, with the LaTeX template in ``templates/``).
"""
from __future__ import annotations

import copy
import shutil
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from ..model.presets import PRESETS, load_preset
from ..model.yaw_plane.loads import CONVENTIONS
from ..ranges import RANGES
from ..units import MPS_PER_KPH, MPS_PER_MPH
from .tables import md_text

TEMPLATES = Path(__file__).resolve().parent / "templates"


MATHJAX = Path("/usr/share/javascript/mathjax")


#: the five triple-trailer presets (chapter IV and the mode shapes of chapter II need a triple)
TRIPLES = PRESETS[:5]


#: tag of the merged report's cells that only the HTML shows (title, contents)
HTML_ONLY = "lcv-html-only"


#: the kernel logs errors only
KERNEL_ARGS = ["--IPKernelApp.log_level=CRITICAL"]


def kernel_options(cwd: Path | str | None = None) -> dict:
    """The notebook client's options that start each kernel on its own Unix sockets, in the
    folder ``cwd`` (given to the kernel alone: papermill's own ``cwd=`` changes the folder of the
    whole process while the notebook runs, and notebooks run in parallel threads then restore
    each other's, leaving the process in a report's folder).

    On TCP, jupyter_client picks a free port, releases it and the kernel binds it later: a
    kernel started meanwhile (the report's notebooks run in parallel, other processes run
    theirs) can take the port first, and the report failed with ``Address already in use``.
    Unix sockets named by a random token in the temporary folder cannot collide.  Where the
    socket path would exceed the system's limit (a long ``TMPDIR``), the client's TCP default
    stays."""
    import os
    import tempfile
    import uuid
    options = {"extra_arguments": KERNEL_ARGS}
    if cwd is not None:
        options["resources"] = {"metadata": {"path": str(cwd)}}
    base = os.path.join(tempfile.gettempdir(), f"lcv-kernel-{uuid.uuid4().hex[:16]}")
    if os.name == "posix" and len(base) <= 96:        # sun_path holds 108 bytes; "-5" and NUL follow
        options["kernel_manager_class"] = _ipc_kernel_manager(base)
    return options


def _ipc_kernel_manager(base: str):
    from jupyter_client import AsyncKernelManager

    class IpcKernelManager(AsyncKernelManager):
        """A kernel on Unix sockets ``<base>-1`` ... ``<base>-5`` (removed at its shutdown)."""

        def __init__(self, **kwargs):
            kwargs.setdefault("transport", "ipc")
            kwargs.setdefault("ip", base)
            super().__init__(**kwargs)

    return IpcKernelManager


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
    from ..model.yaw_plane.loads import ResidualLoads, ResidualSources
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
    from ..tracking.statistics import check_stats_spec
    from ..tracking.tires import TrackingError, axle_residuals
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
ASSESSMENT = NotebookSpec("assessment", "assessment", "Yaw-plane and roll assessment",
                          {**_COMMON, "preset": lambda n, v, c: None, "vehicle_file": _vehicle_file,
                           "source": _text_or_none, "residuals": _residuals, "criteria_file": _text_or_none,
                           "tracking": _tracking,
                           "speed_kph": _speed(1 / MPS_PER_KPH, "km/h"), "load_units": _load_units})


def _read_by(what: str, reader: str, refusal: str):
    """A parameter naming ``what`` (a file or folder) that ``reader`` reads ("module:function" of
    the package, imported on use), refused in one line with its reader's reason (``refusal``)."""
    import importlib

    def check(name, value, _ctx):
        read_module, read_name = reader.split(":")
        error_module, error_name = refusal.split(":")
        error = getattr(importlib.import_module(error_module, __package__), error_name)
        if not isinstance(value, str):
            raise ReportError(f"parameter {name} must be {what}, got {value!r}")
        try:
            getattr(importlib.import_module(read_module, __package__), read_name)(value)
        except error as exc:
            raise ReportError(f"parameter {name} {value}: {exc}") from None
    return check


#: the study report's notebook
STUDY = NotebookSpec("study", "study", "Study", {
    **_COMMON, "study_dir": _read_by("the --out folder of lcv study", "..study.results:stored_study",
                                     "..study.spec:StudyError"),
    "criteria_file": _text_or_none})

_scheme_file = _read_by("the path of a scheme file", "..measures.scheme:load_scheme", "..measures.scheme:SchemeError")


def _tire_scale(name, value, _ctx):
    from ..ranges import RANGES
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not RANGES["tire_scale"].contains(value):
        raise ReportError(f"parameter {name} must be in {RANGES['tire_scale'].text()}, got {value!r}")


def _scheme_vehicle(name, value, ctx):
    if not isinstance(value, str):
        raise ReportError(f"parameter {name} must be the path of a vehicle file, got {value!r}")
    ctx["vehicle"] = _assessment_vehicle(None, value)


def _scheme_residuals(name, value, ctx):
    if isinstance(value, dict) and "crossfall_percent" in value:
        raise ReportError(f"parameter {name}: the crossfall is a condition of the scheme (crossfall_percent per "
                          "measure), not a residual source here")
    _residuals(name, value, ctx)


#: the scheme assessment report's notebook (lcv assess --out): the vehicle file is read first, so
#: that the loads and residual sources are checked against its units and axles
SCHEME = NotebookSpec("scheme", "scheme", "Assessment against a scheme",
                      {**_COMMON, "vehicle_file": _scheme_vehicle, "scheme_file": _scheme_file,
                       "source": _text_or_none, "tire_scale": _tire_scale, "load_units": _load_units,
                       "residuals": _scheme_residuals})


SPECS = {s.stem: s for s in NOTEBOOKS + (ASSESSMENT, STUDY, SCHEME)}


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
    if stem == "scheme":
        ctx["optional_loads"] = True
        _scheme_vehicle("vehicle_file", params.get("vehicle_file"), ctx)
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


#: the loggers of the notebook machinery: silent while a report is built (a failure is one
#: :class:`ReportError` naming the notebook and the cell; an interruption one line)
CLIENT_LOGGERS = ("traitlets", "nbclient", "papermill", "jupyter_client")


def silence_client_loggers() -> None:
    """Nothing from the notebook client reaches the terminal.  Its event-loop thread reports a
    kernel that ends under it (a Ctrl-C during the kernel's start, which the kernel cannot yet
    catch) as an error, possibly before the main thread has taken the interruption."""
    import logging
    for name in CLIENT_LOGGERS:
        logging.getLogger(name).setLevel(logging.CRITICAL + 1)


def execute(stem: str, out_dir: Path, parameters: dict, source_dir: Path | None = None) -> Path:
    """Check the parameters, then execute ``<source_dir>/<stem>.ipynb`` with papermill into ``out_dir``."""
    import papermill as pm

    from ..util.interrupts import raise_if_interrupted
    raise_if_interrupted()          # one the interpreter swallowed (in the imports): no kernel is started
    silence_client_loggers()
    if stem in SPECS:
        check_notebook_parameters(stem, parameters)
    src = (source_dir or notebook_dir()) / f"{stem}.ipynb"
    dst = out_dir / f"{stem}.ipynb"
    try:
        pm.execute_notebook(str(src), str(dst), parameters=parameters, kernel_name="python3",
                            progress_bar=False, log_output=False, **kernel_options(out_dir))
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
    # the title may hold a user's text (a scheme's name): set literally, never as Markdown or TeX
    cells = [nbformat.v4.new_markdown_cell("# " + md_text(title), metadata=html_only),
             nbformat.v4.new_markdown_cell(intro)]
    if len(executed) > 1:
        toc = ["## Contents", ""] + [f"{i + 1}. [{t}](#{a})" for i, (_s, a, t, _p) in enumerate(executed)]
        cells.append(nbformat.v4.new_markdown_cell("\n".join(toc), metadata=html_only))
    for stem, anchor, part_title, path in executed:
        src = nbformat.read(path, as_version=4)
        if len(executed) > 1:
            cells.append(nbformat.v4.new_markdown_cell(f'<a id="{anchor}"></a>\n\n# {md_text(part_title)}'))
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


#: the reports' MathJax configuration: the combined TeX/CommonHTML configuration and ``Safe``
#: (``config/Safe.js``, which loads the Safe extension: ``\href{javascript:...}``, ``\style`` and
#: ``\class`` in typeset text stay dead)
MATHJAX_CONFIG = ("TeX-AMS_CHTML-full", "Safe")
#: the part of MathJax 2 (Debian's libjs-mathjax, 54 MB in all) :data:`MATHJAX_CONFIG` loads: the
#: loader, every configuration file it names, the TeX input and CommonHTML output jax, the
#: extensions (Safe, the menu and zoom loaded on use) and the TeX web fonts -- 1.6 MB, copied into
#: every report so that a copied folder keeps its mathematics
MATHJAX_PARTS = ("MathJax.js", *(f"config/{name}.js" for name in MATHJAX_CONFIG), "extensions", "jax/input/TeX",
                 "jax/output/CommonHTML", "jax/element", "fonts/HTML-CSS/TeX/woff")


def copy_mathjax(dst: Path) -> None:
    """Copy :data:`MATHJAX_PARTS` of the machine's MathJax into ``dst`` (real files, no links)."""
    for part in MATHJAX_PARTS:
        src, target = MATHJAX / part, dst / part
        target.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            shutil.copytree(src, target, symlinks=False, dirs_exist_ok=True)
        else:
            shutil.copyfile(src, target)


def export_html(nb, out_dir: Path) -> Path:
    """Self-contained HTML (figures inline), the MathJax it needs copied next to it."""
    from nbconvert import HTMLExporter
    # embed_images stays off: with it nbconvert re-parses every inline HTML tag of the Markdown on
    # its own (to find <img>), which closes md_text's <span class="tex2jax_ignore"> at once and
    # leaves the user's text outside it, where MathJax typesets it (figures are outputs, inline
    # either way; no Markdown cell of the reports holds an image)
    exporter = HTMLExporter(template_name="lab", exclude_input=True, exclude_input_prompt=True,
                            exclude_output_prompt=True, embed_images=False)
    exporter.mathjax_url = "mathjax/MathJax.js?config=" + ",".join(MATHJAX_CONFIG)
    exporter.require_js_url = ""
    body, _ = exporter.from_notebook_node(nb)
    body = body.replace('<script src=""></script>', "")
    if MATHJAX.exists():
        copy_mathjax(out_dir / "mathjax")
    path = out_dir / "index.html"
    path.write_text(body, encoding="utf-8")
    return path


def export_pdf(nb, out_dir: Path, author: str, paper: str = "letter", title_page: bool = True,
               toc: bool = True) -> Path:
    """PDF through nbconvert's LaTeX route (xelatex) with the lcvlatex template (``toc``: a table
    of contents after the title); the LaTeX log of the last run is kept as ``latex.log`` beside
    it (see :func:`overfull_boxes`)."""
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
                                                              "lcv_paper": paper, "lcv_title_page": title_page,
                                                              "lcv_toc": toc})
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


def execute_unchecked(stem, nb_dir, params, src):
    import papermill as pm

    from ..util.interrupts import raise_if_interrupted
    raise_if_interrupted()          # one the interpreter swallowed (in the imports): no kernel is started
    dst = nb_dir / f"{stem}.ipynb"
    try:
        pm.execute_notebook(str(src / f"{stem}.ipynb"), str(dst), parameters=params, kernel_name="python3",
                            progress_bar=False, log_output=False, **kernel_options(nb_dir))
    except pm.PapermillExecutionError as exc:
        where = _failed_cell(src / f"{stem}.ipynb", dst, exc.cell_index)
        raise ReportError(f"notebook {stem}.ipynb failed in {where}: {exc.ename}: {exc.evalue} "
                          f"(executed copy: {dst})") from None
    return dst


def process_alive(pid: int) -> bool:
    import os
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def stop_kernels() -> None:
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
