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

import argparse
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Callable

from ..units import MPS_PER_KPH
from .notebooks import (NOTEBOOKS, PAPERS, ReportError, execute_unchecked, execute, export_html, export_pdf, merge,
                        notebook_dir)
from .publish import (OutputFolderError, WriterLock, discard_staged, folder_state, prepare_folder, publish_staged, stage_folder,
                      check_output_folder, write_manifest)
from .tables import md_text

THESIS_TITLE = "Effect of conicity and ply steer on LCV yaw plane motion: the dissertation recomputed"


#: the assessment report's default speed [km/h]
DEFAULT_SPEED_KPH = 88.0


def build(build_dir: Path, fast: bool = False, pdf: bool = True, only: list[str] | None = None,
          jobs: int = 2, notebook_folder: Path | None = None, progress: Callable[[str], None] | None = None) -> dict:
    """Execute the thesis notebooks and build the thesis report; return paths and timings.

    ``notebook_folder`` replaces ``notebooks/`` (every ``*.ipynb`` in it, sorted, no
    parameter checks) -- for tests."""
    progress = progress or (lambda _text: None)
    build_dir = Path(build_dir).resolve()
    report_dir, data_dir = prepare_folder(build_dir / "report")
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
            execute_unchecked(stem, nb_dir, params, src)
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


def build_assessment(vehicle, out_dir: str | Path, speed_mps: float | None = None, load_units=None,
                     pdf: bool = True, progress: Callable[[str], None] | None = None, fast: bool = False,
                     source: str = "", vehicle_text: str | None = None, paper: str = "letter",
                     residuals: dict | None = None, criteria_file: str | None = None,
                     tracking: dict | None = None) -> dict:
    """The assessment report of ``vehicle`` (docs/reports.md) into ``out_dir``.

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
        Straight-line tracking (docs/tracking.md): ``tires`` (mounted tires, as
        :func:`lcvreport.tracking.tires.read_mounted_tires` returns them) and/or ``stats``
        (a tire population, :func:`lcvreport.tracking.statistics.parse_stats_spec`).

    Returns
    -------
    dict
        ``html``, ``pdf``, ``data`` paths (in ``out_dir``) and ``seconds``.

    Raises
    ------
    lcvreport.report.notebooks.ReportError
        A criteria file that is not valid, or a notebook that fails (one line naming it).
    lcvreport.report.publish.OutputFolderError
        An output folder that is not new, empty or an earlier report of this kind.

    Examples
    --------
    A report takes a Jupyter kernel and about a minute (``lcv report`` runs this):

    >>> from lcvreport import load_vehicle
    >>> res = build_assessment(load_vehicle("examples/vehicles/b_double.toml"), "b_double_report",
    ...                        pdf=False)  # doctest: +SKIP
    >>> sorted(res)  # doctest: +SKIP
    ['data', 'html', 'seconds']
    """
    from ..model.vehicle_file import dumps_vehicle
    version, progress = _start(paper, progress)
    speed_kph = DEFAULT_SPEED_KPH if speed_mps is None else speed_mps / MPS_PER_KPH
    if criteria_file is not None:               # through the one guarded reader, before anything is written
        from ..measures.criteria import CriteriaError, load_criteria
        try:
            load_criteria(criteria_file)
        except CriteriaError as exc:
            raise ReportError(f"criteria file {criteria_file}: {exc}") from None

    def params_of(staged: Path) -> dict:
        vehicle_file = staged / "vehicle.toml"
        text = vehicle_text if vehicle_text is not None else \
            dumps_vehicle(vehicle, header=f"The vehicle of this report ({source or vehicle.name}).")
        vehicle_file.write_text(text, encoding="utf-8")
        return {"preset": None, "vehicle_file": str(vehicle_file), "source": source or None,
                "speed_kph": float(speed_kph), "residuals": residuals,
                "criteria_file": None if criteria_file is None else str(Path(criteria_file).resolve()),
                "load_units": list(load_units) if load_units else None, "tracking": tracking}

    title = f"Yaw-plane and roll assessment of {vehicle.name} at {speed_kph:g} km/h"
    intro = (f"Linear yaw-plane model of *{md_text(vehicle.name)}* ({vehicle.n_units} units: "
             f"{md_text(', '.join(vehicle.unit_names))}){' from ' + md_text(source) if source else ''}, assessed "
             f"at {speed_kph:g} km/h (SI units; speeds in km/h). Written by lcvreport {version} on {{stamp}}.")
    return _one_notebook(out_dir, "assessment", params_of, title, intro, pdf, paper,
                         f"lcvreport {version} assessment of {vehicle.name}", f"lcvreport {version} (lcv report)",
                         progress, fast)


def build_scheme_report(vehicle, scheme_file: str | Path, out_dir: str | Path, tire_scale: float = 1.0,
                        load_units=None, residuals: dict | None = None, pdf: bool = True, paper: str = "letter",
                        source: str = "", vehicle_text: str | None = None, fast: bool = False,
                        progress: Callable[[str], None] | None = None) -> dict:
    """The report of an assessment against a scheme (``lcv assess --out DIR``, docs/assessment.md):
    its first page the verdict table, then the limits with their sources and the evidence of
    every measure with the limits drawn on it.  The folder is self-contained -- the vehicle file
    and the scheme file copied in as ``vehicle.toml`` and ``scheme.toml``, MathJax copied, not
    linked -- and the report names the toolkit's version and both files' SHA-256.  Written
    aside and moved into place whole, as :func:`build_assessment`.

    Returns
    -------
    dict
        ``html``, ``pdf``, ``data`` paths (in ``out_dir``) and ``seconds``.
    """
    import hashlib

    from ..model.vehicle_file import dumps_vehicle
    from ..measures.scheme import SchemeError, loads_scheme
    from ..util.files import FileInputError, read_file_bytes
    version, progress = _start(paper, progress)
    try:                        # the one guarded reader: a FIFO or a device is refused, never read
        scheme_bytes = read_file_bytes(scheme_file, "scheme file")
        text = scheme_bytes.decode("utf-8")
        scheme = loads_scheme(text[1:] if text.startswith("\ufeff") else text)
    except (FileInputError, UnicodeDecodeError, SchemeError) as exc:
        raise ReportError(f"scheme file {scheme_file}: {exc}") from None
    text = vehicle_text if vehicle_text is not None else \
        dumps_vehicle(vehicle, header=f"The vehicle of this report ({source or vehicle.name}).")
    sha_vehicle = hashlib.sha256(text.encode("utf-8")).hexdigest()
    sha_scheme = hashlib.sha256(scheme_bytes).hexdigest()

    def params_of(staged: Path) -> dict:
        (staged / "vehicle.toml").write_text(text, encoding="utf-8")
        (staged / "scheme.toml").write_bytes(scheme_bytes)
        return {"vehicle_file": str(staged / "vehicle.toml"), "scheme_file": str(staged / "scheme.toml"),
                "source": source or None, "tire_scale": float(tire_scale),
                "load_units": list(load_units) if load_units else None, "residuals": residuals}

    title = f"Assessment of {vehicle.name} against {scheme.name}"
    intro = (f"*{md_text(vehicle.name)}* ({vehicle.n_units} units){' from ' + md_text(source) if source else ''} "
             f"assessed against *{md_text(scheme.name)}* (status: {md_text(scheme.status)}), every measure at its "
             f"own conditions, by lcvreport {version} on {{stamp}}. Vehicle file (vehicle.toml beside this report) "
             f"SHA-256 `{sha_vehicle}`; scheme file (scheme.toml) SHA-256 `{sha_scheme}`.")
    out = _one_notebook(out_dir, "scheme", params_of, title, intro, pdf, paper, f"lcvreport {version} (lcv assess)",
                        f"lcvreport {version} (lcv assess)", progress, fast, toc=False)
    out["sha256"] = {"vehicle.toml": sha_vehicle, "scheme.toml": sha_scheme}
    return out


def _start(paper: str, progress) -> tuple[str, Callable[[str], None]]:
    """The package's version and the progress callback, once the paper size is checked."""
    from importlib.metadata import version
    if paper not in PAPERS:
        raise OutputFolderError(f"paper must be one of {', '.join(PAPERS)}, got {paper!r}")
    return version("lcvreport"), progress or (lambda _text: None)


def _one_notebook(out_dir, stem: str, params_of, title: str, intro: str, pdf: bool, paper: str, pdf_title: str,
                  written_by: str, progress, fast: bool, toc: bool = True) -> dict:
    """A one-notebook report: ``out_dir`` checked, the report written aside -- its ``data/``,
    the notebook ``stem`` executed with ``fast``, ``data_dir`` and ``params_of(staged)``,
    merged under ``title`` and ``intro`` (``{stamp}``: the date), exported -- and published
    into ``out_dir`` whole; nothing left behind on a failure or an interruption; one writer at a
    time (:class:`~lcvreport.report.publish.WriterLock`)."""
    out = check_output_folder(out_dir)
    with WriterLock(out):
        out = check_output_folder(out_dir)          # again, now that no other report writes it
        return _one_notebook_locked(out, stem, params_of, title, intro, pdf, paper, pdf_title, written_by, progress,
                                    fast, toc)


def _one_notebook_locked(out: Path, stem: str, params_of, title: str, intro: str, pdf: bool, paper: str,
                         pdf_title: str, written_by: str, progress, fast: bool, toc: bool) -> dict:
    import os
    before = folder_state(out)
    staged = stage_folder(out)
    try:
        data_dir = staged / "data"
        data_dir.mkdir()
        params = {"fast": bool(fast), "data_dir": str(data_dir), **params_of(staged)}
        t0 = time.perf_counter()
        nb_dir = staged / "notebooks"
        nb_dir.mkdir()
        path = execute(stem, nb_dir, params)
        progress(f"notebook {stem}: {time.perf_counter() - t0:.1f} s")
        stamp = time.strftime("%Y-%m-%d", time.gmtime(int(os.environ.get("SOURCE_DATE_EPOCH", time.time()))))
        written = _finish_single(staged, out, before, (stem, stem, title, path), title,
                                 intro.replace("{stamp}", stamp), pdf, pdf_title, paper, written_by, progress, toc)
    except BaseException as exc:
        discard_staged(staged, isinstance(exc, KeyboardInterrupt))
        raise
    res = {key: out / name for key, name in written.items()}
    res["seconds"] = time.perf_counter() - t0
    return res


def _finish_single(staged: Path, out: Path, before, part: tuple, title: str, intro: str, pdf: bool, pdf_title: str,
                   paper: str, written_by: str, progress, toc: bool = True) -> dict:
    """The end of a one-notebook report (the assessment, a study): merge, HTML, PDF, the
    manifest, then the staged folder published into ``out``; the files written, by kind."""
    nb = merge([part], title, intro)
    export_html(nb, staged)
    progress("html written")
    written = {"html": "index.html", "data": "data"}
    if pdf:
        export_pdf(nb, staged, pdf_title, paper=paper, title_page=False, toc=toc)
        written["pdf"] = "report.pdf"
        progress("pdf written")
    write_manifest(staged, written_by)
    publish_staged(staged, out, before)
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
    from ..study.results import read_study, stored_study
    from ..study.spec import StudyError
    version, progress = _start(paper, progress)
    study_dir = Path(study_dir).resolve()
    try:
        study = stored_study(study_dir)
        read_study(study_dir)                     # complete, readable: before anything is written
    except StudyError as exc:
        raise ReportError(str(exc)) from None
    params = {"study_dir": str(study_dir),
              "criteria_file": None if criteria_file is None else str(Path(criteria_file).resolve())}
    title = f"Study of {study.vehicle.name}: {study.n_cases} cases"
    intro = (f"The results of `lcv study` in {md_text(study_dir.name)}: {study.n_cases} cases of "
             f"*{md_text(study.vehicle.name)}*, measures {md_text(', '.join(study.measures))} (SI units; speeds "
             f"in km/h). Written by lcvreport {version} on {{stamp}}.")
    return _one_notebook(out_dir, "study", lambda _staged: params, title, intro, pdf, paper,
                         f"lcvreport {version} study of {study.vehicle.name}",
                         f"lcvreport {version} (lcv study --report)", progress, fast)


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
