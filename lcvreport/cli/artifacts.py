"""``lcv fmu``, ``lcv report`` and ``lcv study``: the commands that write folders of artifacts."""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path


from ..ranges import RangeError
from ..util.interrupts import raise_if_interrupted
from .options import (Command, UsageError, add_load, add_residuals, add_source, add_speed, load_units_of,
                      model_choices, sources_of, speed_mps_of, vehicle_of)
from .output import OutputError, Output


def run_report(command: str, build, wrote) -> None:
    """Build a report (``build()`` returns the paths it wrote by kind), turn its refusals into the
    CLI's (a bad output folder: usage, exit 2; a failed build: exit 1), name what it wrote through
    ``wrote`` and its time on stderr."""
    from ..report.notebooks import ReportError
    from ..report.publish import OutputFolderError
    t0 = time.perf_counter()
    try:
        res = build()
    except OutputFolderError as exc:
        raise UsageError(f"argument {exc}") from None
    except ReportError as exc:
        raise OutputError(str(exc)) from None
    for key in ("html", "pdf", "data"):
        if key in res:
            wrote(f"wrote {res[key]}")
    print(f"{command}: {time.perf_counter() - t0:.1f} s", file=sys.stderr)


def cmd_fmu(args, out: Output) -> int:
    from ..fmu.build import build_vehicle_fmus
    from ..fmu.c_sources import FmuBuildError
    from ..model.base import check_model
    model = check_model(args.model)
    if model == "yaw_roll":
        from ..measures.roll import unstable_at_rest
        from .roll import roll_vehicle
        v = roll_vehicle(args)                  # the roll keys, checked: one line naming what is missing
        why = unstable_at_rest(v)
        if why is not None:                     # its roll angle would grow without bound from any start
            raise UsageError(f"argument --model yaw-roll: {v.name}: {why.removeprefix('undefined: ')}; no FMU "
                             "was built")
    elif model == "nonlinear":
        if args.kind not in (None, "python") or str(args.fmi) != "2":
            raise UsageError(f"argument --model nonlinear: its FMU is the Python FMI 2.0 one (--kind python, "
                             f"--fmi 2), got --kind {args.kind or 'both'} --fmi {args.fmi}; no FMU was built")
        from ..model.nonlinear.model import nonlinear_model
        from ..model.vehicle import VehicleError
        v = vehicle_of(args)
        try:
            nonlinear_model(v)                  # every axle's static_load_N: one line naming the axle
        except VehicleError as exc:
            raise UsageError(f"argument --model nonlinear: {v.name}: {exc}; no FMU was built") from None
        args.kind = "python"
    else:
        v = vehicle_of(args)
    try:
        kw = {"model": model}
        if args.speed_kph is not None or args.speed_mph is not None:
            kw["u_start_mps"] = speed_mps_of(args)      # the start value of the input u
        kind = args.kind or "both"
        paths = build_vehicle_fmus(v, args.out, kind=kind, fmi=int(args.fmi), **kw)
    except FmuBuildError as exc:
        raise OutputError(str(exc)) from None
    for p in paths:
        out.line(f"wrote {p}")
    return 0


def cmd_report(args, out: Output) -> int:
    from ..report.build import build_assessment
    from ..report.publish import OutputFolderError, check_output_folder
    try:
        check_output_folder(args.out)          # before anything is computed
    except OutputFolderError as exc:
        raise UsageError(f"argument {exc}") from None
    v = vehicle_of(args)
    speed = speed_mps_of(args) if (args.speed_kph is not None or args.speed_mph is not None) else None
    units = load_units_of(args, v) if args.load is not None else None
    if units:
        from ..model.yaw_plane.loads import one_percent_rule
        try:
            one_percent_rule(v, units)
        except ValueError as exc:
            raise UsageError(f"argument --load: {exc}") from None
    src = sources_of(args, v)
    try:
        src.vector(v)
    except (KeyError, RangeError) as exc:
        raise UsageError(f"argument: {exc.args[0]}") from None
    residuals = {"P_N": src.loads.P_N, "T_Nm": src.loads.T_Nm, "misalignment_rad": src.misalignment_rad,
                 "crossfall_percent": src.crossfall_percent} if src else None
    if args.criteria is not None:
        from ..measures.criteria import CriteriaError, load_criteria
        try:
            load_criteria(args.criteria)
        except CriteriaError as exc:
            raise UsageError(f"argument --criteria {args.criteria}: {exc}") from None
    tracking = {"tires": None, "stats": None}
    if args.tires:
        from ..tracking.tires import read_mounted_tires
        tracking["tires"] = read_mounted_tires(args.tires)      # checked by sources_of above
        if not v.steered_axles:
            raise UsageError(f"argument --tires: {v.name} has no steered axle: the trim needs one")
    if args.tracking_stats is not None:
        from ..tracking.statistics import parse_stats_spec
        from ..tracking.tires import TrackingError
        if not v.steered_axles:
            raise UsageError(f"argument --tracking-stats: {v.name} has no steered axle: the trim needs one")
        try:
            tracking["stats"] = parse_stats_spec(args.tracking_stats)
        except TrackingError as exc:
            raise UsageError(f"argument --tracking-stats: {exc}") from None
    text = None
    if args.vehicle is not None:               # the user's file as written, comments and all
        from ..model.vehicle_file import read_vehicle_text
        text = read_vehicle_text(args.vehicle)
    run_report("lcv report", lambda: build_assessment(
        v, args.out, speed_mps=speed, load_units=units, pdf=not args.no_pdf,
        progress=lambda text: print(f"lcv report: {text}", file=sys.stderr, flush=True),
        source=args.vehicle or f"preset {args.preset}", vehicle_text=text, paper=args.paper, residuals=residuals,
        criteria_file=args.criteria, tracking=tracking if tracking["tires"] or tracking["stats"] else None), out.line)
    return 0


def cmd_study(args, out: Output) -> int:
    from ..study.run import run_study
    from ..study.spec import StudyError, load_study
    try:
        study = load_study(args.study_file)
    except StudyError as exc:
        raise UsageError(str(exc) if str(args.study_file) in str(exc) else f"{args.study_file}: {exc}") from None
    if args.scheme is not None:
        from ..measures.scheme import SchemeError, read_scheme_text
        try:
            study = study.with_scheme(read_scheme_text(args.scheme))
        except (SchemeError, StudyError) as exc:
            raise UsageError(f"argument --scheme {args.scheme}: {exc}") from None
    out_dir = Path(args.out)
    if args.scheduler is not None:
        from ..study.run import check_scheduler_address
        try:
            check_scheduler_address(args.scheduler)
        except StudyError as exc:
            raise UsageError(f"argument {exc}") from None
    if (args.criteria is not None or args.no_pdf) and args.report is None:
        raise UsageError("arguments --criteria and --no-pdf belong to --report REPORT_DIR")
    if args.report is not None:
        from ..report.publish import OutputFolderError, check_output_folder
        _checked("--report", check_output_folder, args.report, OutputFolderError)
        if Path(args.report).resolve() == out_dir.resolve():
            raise UsageError("argument --report: give another folder than --out")
    if args.criteria is not None:
        from ..measures.criteria import CriteriaError, load_criteria
        _checked(f"--criteria {args.criteria}", load_criteria, args.criteria, CriteriaError)
    csv_path = out_dir / "results.csv"
    if args.csv and (csv_path.exists() or csv_path.is_symlink()):
        raise UsageError(f"argument --csv: {csv_path} exists; lcv never overwrites a file (move it, or omit --csv)")
    if not args.json:
        seed = f", seed {study.seed}" if study.seed is not None else ""
        out.line(f"study of {study.vehicle.name}: {study.kind} design{seed}, {study.n_cases} cases in "
                 f"{study.n_chunks} chunks of {study.chunk}; measures {', '.join(study.measures)}"
                 + (f"; every case assessed against {study.scheme.name}" if study.scheme_toml else ""))
        for f in study.factors:
            out.line(f"  {f.describe()}")
        out.stream.flush()
    try:
        summary = run_study(study, out_dir, workers=args.workers, scheduler=args.scheduler)
    except StudyError as exc:
        raise UsageError(str(exc)) from None
    if args.csv:
        from ..study.results import read_study
        tmp = out_dir / ".results.csv.tmp"
        read_study(out_dir).to_csv(tmp, index=False, float_format="%.17g")
        try:
            raise_if_interrupted()     # an interruption the interpreter swallowed: nothing is linked
            os.link(tmp, csv_path)
        except FileExistsError:
            raise UsageError(f"argument --csv: {csv_path} appeared meanwhile; nothing was overwritten") from None
        finally:
            tmp.unlink()
    report = None
    if args.report is not None:
        from ..report.build import build_study_report
        from ..report.notebooks import ReportError
        from ..report.publish import OutputFolderError
        try:
            report = build_study_report(out_dir, args.report, criteria_file=args.criteria, pdf=not args.no_pdf,
                                        progress=lambda text: print(f"lcv study: report: {text}", file=sys.stderr,
                                                                    flush=True))
        except OutputFolderError as exc:
            raise UsageError(f"argument --report: {exc}") from None
        except ReportError as exc:
            raise OutputError(str(exc)) from None
    doc = summary.to_dict()
    if report is not None:
        doc["report"] = {k: str(v) for k, v in report.items() if k != "seconds"}
    if args.json:
        out.json(doc)
    else:
        for key in ("html", "pdf"):
            if report is not None and key in report:
                out.line(f"wrote {report[key]}")
        rate = (summary.n_computed and summary.n_cases * summary.n_computed / summary.n_chunks / summary.seconds)
        out.line(f"{summary.n_computed} chunks computed, {summary.n_found} found done, in {summary.seconds:.1f} s"
                 + (f" ({rate:.0f} cases/s)" if rate else "") + f"; results in {out_dir}"
                 + (f", {csv_path.name}" if args.csv else ""))
    return 0


def _checked(option: str, check, value, error) -> None:
    """``check(value)``; its ``error`` becomes the one line of the argument ``option`` (exit 2)."""
    try:
        check(value)
    except error as exc:
        raise UsageError(f"argument {option}: {exc}") from None


# ---------------------------------------------------------------------------- options
def fmu_options(sp) -> None:
    from ..fmu.interface import FMU_MODELS
    add_source(sp, masses=False)
    sp.add_argument("--out", required=True, metavar="DIR", help="output folder")
    sp.add_argument("--kind", default=None, choices=("python", "native", "both"),
                    help="python (pythonfmu, pythonfmu3 for FMI 3.0), native (C99) or both (default both)")
    sp.add_argument("--fmi", default="2", choices=("2", "3"),
                    help="FMI version (default 2): <name>.fmu and <name>Native.fmu, or <name>3.fmu and "
                         "<name>Native3.fmu")
    sp.add_argument("--model", default="yaw-plane", choices=model_choices(FMU_MODELS),
                    help="the model built in (default yaw-plane); yaw-roll adds the roll states and the "
                         "sprung accelerations, load transfers and LTRs as outputs, and needs the vehicle's roll "
                         "keys (docs/roll.md); nonlinear: the nonlinear planar model (docs/nonlinear.md), its "
                         "Python FMI 2.0 Co-Simulation FMU <name>_nonlinear.fmu only")
    add_speed(sp, required=False)


def report_options(sp) -> None:
    add_source(sp, masses=False)
    add_speed(sp, required=False)
    add_load(sp, False, convention=False)
    add_residuals(sp)
    sp.add_argument("--out", required=True, metavar="DIR", help="output folder")
    sp.add_argument("--no-pdf", action="store_true", help="HTML only")
    sp.add_argument("--paper", default="letter", choices=("letter", "a4"), help="paper of the PDF (default letter)")
    sp.add_argument("--criteria", metavar="FILE", help="limits to judge the measures by (TOML, see examples/)")
    sp.add_argument("--tracking-stats", metavar="SPEC",
                    help="a tire population for the straight-line tracking chapter: conicity=DIST,ply_steer=DIST,"
                         "mounting=out|in|random[,conicity_moment=DIST,ply_steer_moment=DIST,draws=N,seed=S,"
                         "lane_width_m=W,body_width_m=B], DIST = normal:MEAN:SD | uniform:LO:HI [N, N*m]")


def study_options(sp) -> None:
    sp.add_argument("study_file", metavar="STUDY.toml", help="the study file")
    sp.add_argument("--out", required=True, metavar="DIR", help="results folder: new, empty, or this study's "
                                                               "earlier results (then only missing chunks run)")
    where = sp.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N", help="a local Dask cluster of N worker processes")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="an existing Dask scheduler (tcp://host:8786). Connect only to a cluster you trust: "
                            "Dask's messages carry pickles, so a scheduler runs what it likes in this process")
    sp.add_argument("--csv", action="store_true", help="also write DIR/results.csv (one row per case)")
    sp.add_argument("--report", metavar="REPORT_DIR", help="then write the study report (HTML, PDF) into REPORT_DIR: "
                                                           "new, empty or an earlier report")
    sp.add_argument("--criteria", metavar="FILE", help="with --report: limits to judge the cases by (TOML)")
    sp.add_argument("--scheme", metavar="FILE", help="assess every case against a scheme file (docs/assessment.md): "
                                                     "the level each measure and the case reach as columns, and in "
                                                     "the report the share of cases reaching each level")
    sp.add_argument("--no-pdf", action="store_true", help="with --report: HTML only")
    sp.add_argument("--json", action="store_true", help="machine-readable summary")


COMMANDS = {
    "fmu": Command("FMUs of the vehicle (FMI 2.0 or 3.0; native: Co-Simulation and Model Exchange)", fmu_options,
                   cmd_fmu),
    "report": Command("assessment report of the vehicle (HTML and PDF)", report_options, cmd_report),
    "study": Command("a study file's cases (factors, design, measures) in batches on Dask, results in Parquet",
                     study_options, cmd_study),
}
