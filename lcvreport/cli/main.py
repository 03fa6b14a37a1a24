"""The ``lcv`` command: eigenvalues, matrices, steady state, time response, measures,
FMUs and reports of a preset or of a vehicle file.

Fixed contract (other parts and outside checks call these forms)::

    lcv eig      (--preset NAME | --vehicle FILE) (--speed-kph V | --speed-mph V) [--tire-scale S] --json
    lcv matrices (...) [--load UNITS --convention C] [--units thesis|si] --json
    lcv steady   (...) --load UNITS [--convention C] --json
    lcv simulate (...) --load UNITS [--t-end T] [--dt H] [--json]
    lcv measures (...) [--load UNITS] --json
    lcv fmu      (--preset NAME | --vehicle FILE) --out DIR [--kind python|native|both] [--fmi 2|3]
    lcv report   (--preset NAME | --vehicle FILE) [--speed-kph V] [--load UNITS] --out DIR
    lcv study    STUDY.toml --out DIR [--workers N | --scheduler ADDRESS] [--csv] [--scheme F] [--report R [--criteria F]]
    lcv assess   (--preset NAME | --vehicle FILE) --scheme SCHEME.toml [--json] [--out DIR]
    lcv presets  [--json]

``UNITS`` is a comma list of unit names of the vehicle; each gets the 1 % rule on its
axles (P along +y, T = 0.3048 m * P about +z).  ``--convention`` is ``consistent``
(default) or ``thesis`` (docs/thesis.md, erratum 1).  JSON units: eigenvalues [1/s]; matrices in
thesis units (lbf, in, s) for presets and SI for vehicle files unless ``--units`` says
otherwise; everything else SI.  Every number is checked against
:data:`lcvreport.ranges.RANGES`.  A bad argument exits with status 2 and one line naming
it and what is valid; an output that cannot be written exits 1 with one line; a
closed pipe (``lcv ... | head``) ends quietly with status 141, as SIGPIPE does for
other Unix tools.  No output is ever non-finite.
"""
from __future__ import annotations

import argparse
import errno
import os
import sys
from typing import Sequence


from ..ranges import RangeError
from ..units import MPS_PER_KPH, MPS_PER_MPH
from .artifacts import cmd_fmu, cmd_report, cmd_study
from .assess import cmd_assess
from .measures import cmd_measures
from .model import cmd_eig, cmd_matrices, cmd_presets, cmd_steady
from .options import UsageError, help_range, one_line, ranged
from .output import OutputError, Output
from .roll import cmd_roll
from .simulate import cmd_simulate
from .tracking import cmd_tracking
from .turn import cmd_turn


#: exit status of a closed pipe (128 + SIGPIPE), as a shell reports a tool SIGPIPE ended
EXIT_BROKEN_PIPE = 141


#: exit status after Ctrl-C (128 + SIGINT), as a shell reports it
EXIT_INTERRUPTED = 130


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump
        raise UsageError(message)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``lcv``."""
    from ..model.presets import MASS_OPTIONS, PRESETS
    from importlib.metadata import version
    __version__ = version("lcvreport")
    p = _Parser(prog="lcv", description="Linear yaw-plane and yaw-roll models of long combination vehicles.")
    p.add_argument("--version", action="version", version=f"lcv (lcvreport) {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def source(sp: argparse.ArgumentParser, masses: bool = True) -> None:
        g = sp.add_mutually_exclusive_group(required=True)
        g.add_argument("--preset", metavar="NAME", help=f"vehicle preset: {', '.join(PRESETS)}")
        g.add_argument("--vehicle", metavar="FILE", help="vehicle file (TOML, SI; see the README)")
        if masses:
            sp.add_argument("--masses", default="table", choices=MASS_OPTIONS,
                            help="presets: table (printed, rounded) or unrounded (implied by the published "
                                 "matrices; aucnat and tractor_semitrailer)")

    def speed(sp: argparse.ArgumentParser, required: bool = True) -> None:
        g = sp.add_mutually_exclusive_group(required=required)
        g.add_argument("--speed-kph", type=ranged("speed", 1 / MPS_PER_KPH, "km/h", "forward speed in km/h"),
                       metavar="V", help=f"forward speed [km/h], in {help_range('speed', 1 / MPS_PER_KPH, 'km/h')}")
        g.add_argument("--speed-mph", type=ranged("speed", 1 / MPS_PER_MPH, "mph", "forward speed in mph"),
                       metavar="V", help=f"forward speed [mph], in {help_range('speed', 1 / MPS_PER_MPH, 'mph')}")

    def tires(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--tire-scale", default=1.0, type=ranged("tire_scale", what="factor on the tire "
                        "coefficients"), metavar="S",
                        help=f"factor on every tire coefficient (chapter V), in {help_range('tire_scale')}; "
                             "default 1")

    def load(sp: argparse.ArgumentParser, required: bool, convention: bool = True) -> None:
        from ..model.yaw_plane.loads import CONVENTIONS
        sp.add_argument("--load", required=required, metavar="UNITS",
                        help="comma list of units carrying the 1 %% rule (unit names of the vehicle)")
        if convention:
            sp.add_argument("--convention", default="consistent", choices=CONVENTIONS,
                            help="load-vector convention (default consistent)")

    def common(sp, load_required):
        source(sp)
        speed(sp)
        tires(sp)
        if load_required is not None:
            load(sp, load_required)
        sp.add_argument("--json", action="store_true", help="machine-readable output")

    eig = sub.add_parser("eig", help="eigenvalues [1/s], damped frequency, damping ratio")
    common(eig, None)
    eig.add_argument("--model", default="yaw-plane", choices=("yaw-plane", "yaw-roll"),
                     help="the model: yaw-plane (default) or yaw-roll (the vehicle's roll keys, docs/roll.md)")
    mat = sub.add_parser("matrices", help="M, S (and F with --load)")
    common(mat, False)
    mat.add_argument("--units", choices=("thesis", "si"), default=None,
                     help="unit system of the matrices (default: thesis for presets, si for vehicle files)")
    common(sub.add_parser("steady", help="steady state under the 1 %% rule loads, SI units"), True)
    def residuals(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--residual", action="append", default=[], metavar="AXLE=P,T",
                        help="residual force P [N] (+y) and moment T [N*m] (+z) on an axle; repeatable")
        sp.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                        help=f"thrust angle of an axle [rad], nose-right positive, in "
                             f"{help_range('misalignment')}; repeatable or comma-separated")
        sp.add_argument("--crossfall-percent", type=ranged("crossfall", what="road crossfall in %"), metavar="C",
                        help=f"road crossfall [%%], positive falling toward +y, in {help_range('crossfall')}")
        sp.add_argument("--tires", metavar="FILE", help="mounted tires (CSV or TOML: position, conicity_N, "
                                                         "ply_steer_N, serial_side[, moments]): their axle P and T")

    def conditions(sp: argparse.ArgumentParser) -> None:
        from ..measures.registry import CONDITIONS
        for c in CONDITIONS.values():
            if c.key in ("speed_kph", "crossfall_percent"):
                continue
            if c.choices:                          # a choice (the RA reference points), not a number
                sp.add_argument(c.option, dest=c.key, choices=c.choices,
                                help=c.definition.replace("%", "%%") + (f"; default {c.default}" if c.default else ""))
                continue
            sp.add_argument(c.option, dest=c.key, type=ranged(c.range, unit=c.unit, what=c.label), metavar="X",
                            help=c.definition.replace("%", "%%") + f" [{c.unit}], in "
                                 f"{help_range(c.range, unit=c.unit)}; default {c.default:g}")

    sim = sub.add_parser("simulate", help="exact response from rest to a steer input and residual sources, "
                                          "streamed as CSV (or JSON), SI units")
    common(sim, False)
    residuals(sim)
    sim.add_argument("--steer", metavar="SPEC", default=None,
                     help="steer input: step:A, sine:A:F, pulse:A:D, csv:FILE, lane-change:A0:F (A0 in m/s^2 or "
                          "with g, e.g. 0.15g), driver:A0:F[:K:T] (that path driven in closed loop by a preview "
                          "driver, gain K rad/m, preview T s); default none")
    sim.add_argument("--t-end", default=10.0, type=ranged("t_end", what="end time in s"), metavar="T",
                     help=f"end time [s], in {help_range('t_end')}; default 10")
    sim.add_argument("--tire", choices=("saturating", "linear"), default=None,
                     help="the nonlinear model's tire law (default saturating: the brush tire)")
    sim.add_argument("--friction-coefficient", type=ranged("friction", what="friction coefficient mu"),
                     metavar="MU", default=None, help="the nonlinear model's mu, in (0, 2]; default 0.8")
    sim.add_argument("--model", default="yaw-plane", choices=("yaw-plane", "yaw-roll", "nonlinear"),
                     help="the linear model: yaw-plane (default) or yaw-roll (adds roll rates, roll angles, sprung "
                          "CG accelerations, axle load transfers and load transfer ratios; needs the roll keys)")
    sim.add_argument("--dt", default=0.01, type=ranged("output_step", what="output step in s"), metavar="H",
                     help=f"output step [s], in {help_range('output_step')}; must divide t-end; default 0.01")
    mea = sub.add_parser("measures", help="the measures: damping, RA, YDC, HSTO, HSSO, trim, the low-speed turn, "
                                          "roll (SRT, LTR, roll gains; with roll data) (defined in docs/measures.md)")
    source(mea)
    g = mea.add_mutually_exclusive_group(required=True)
    g.add_argument("--speed-kph", metavar="V", help="forward speed [km/h], or a sweep START:STOP:STEP")
    g.add_argument("--speed-mph", metavar="V", help="forward speed [mph], or a sweep START:STOP:STEP")
    tires(mea)
    load(mea, False, convention=False)
    residuals(mea)
    conditions(mea)
    mea.add_argument("--criteria", metavar="FILE", help="limits to judge the measures by (TOML, see examples/)")
    from ..model.base import CLI_NAMES
    mea.add_argument("--model", default="yaw-plane", choices=tuple(CLI_NAMES.values()),
                     help="the model of the manoeuvres' and eigenvalues' measures (their keys are the same on every "
                          "model: hsto_m of the yaw-roll model is the default's hsto_m_roll); nonlinear: its "
                          "responses, its linearization's eigenvalues and its friction demand (docs/model.md)")
    mea.add_argument("--json", action="store_true", help="machine-readable output")
    fmu = sub.add_parser("fmu", help="FMUs of the vehicle (FMI 2.0 or 3.0; native: Co-Simulation and Model Exchange)")
    source(fmu, masses=False)
    fmu.add_argument("--out", required=True, metavar="DIR", help="output folder")
    fmu.add_argument("--kind", default=None, choices=("python", "native", "both"),
                     help="python (pythonfmu, pythonfmu3 for FMI 3.0), native (C99) or both (default both)")
    fmu.add_argument("--fmi", default="2", choices=("2", "3"),
                     help="FMI version (default 2): <name>.fmu and <name>Native.fmu, or <name>3.fmu and "
                          "<name>Native3.fmu")
    fmu.add_argument("--model", default="yaw-plane", choices=("yaw-plane", "yaw-roll", "nonlinear"),
                     help="the model built in (default yaw-plane); yaw-roll adds the roll states and the "
                          "sprung accelerations, load transfers and LTRs as outputs, and needs the vehicle's roll "
                          "keys (docs/roll.md); nonlinear: the nonlinear planar model (docs/nonlinear.md), its "
                          "Python FMI 2.0 Co-Simulation FMU <name>_nonlinear.fmu only")
    speed(fmu, required=False)
    rep = sub.add_parser("report", help="assessment report of the vehicle (HTML and PDF)")
    source(rep, masses=False)
    speed(rep, required=False)
    load(rep, False, convention=False)
    residuals(rep)
    rep.add_argument("--out", required=True, metavar="DIR", help="output folder")
    rep.add_argument("--no-pdf", action="store_true", help="HTML only")
    rep.add_argument("--paper", default="letter", choices=("letter", "a4"), help="paper of the PDF (default letter)")
    rep.add_argument("--criteria", metavar="FILE", help="limits to judge the measures by (TOML, see examples/)")
    rep.add_argument("--tracking-stats", metavar="SPEC",
                     help="a tire population for the straight-line tracking chapter: conicity=DIST,ply_steer=DIST,"
                          "mounting=out|in|random[,conicity_moment=DIST,ply_steer_moment=DIST,draws=N,seed=S,"
                          "lane_width_m=W,body_width_m=B], DIST = normal:MEAN:SD | uniform:LO:HI [N, N*m]")
    trk = sub.add_parser("tracking", help="straight-line tracking: per-tire conicity and ply steer")
    tsub = trk.add_subparsers(dest="tracking_command", metavar="WHAT", parser_class=_Parser)
    tsub.required = True
    st = tsub.add_parser("stats", help="offtracking over a tire population: exact mean and SD, Monte Carlo lane "
                                       "exceedance")
    source(st, masses=False)
    speed(st)
    tires(st)
    for opt, what in (("--conicity", "conicity force per tire [N]"), ("--ply-steer", "ply steer force per tire [N]"),
                      ("--conicity-moment", "conicity moment per tire [N*m]"),
                      ("--ply-steer-moment", "ply steer moment per tire [N*m]")):
        st.add_argument(opt, metavar="DIST", required=opt in ("--conicity", "--ply-steer"),
                        help=f"{what}: normal:MEAN:SD or uniform:LO:HI")
    st.add_argument("--mounting", required=True, choices=("out", "in", "random"), help="serial side of every tire")
    st.add_argument("--axles", metavar="A,B,...", help="axles whose tires are drawn (default: units 2..N)")
    st.add_argument("--lane-width-m", type=float, default=3.66, metavar="W", help="lane width [m] (3.66)")
    st.add_argument("--body-width-m", type=float, default=2.59, metavar="B", help="body width [m] (2.59)")
    st.add_argument("--draws", type=int, default=1_000_000, metavar="N", help="Monte Carlo draws (1e6)")
    st.add_argument("--seed", type=int, default=20110801, metavar="S", help="random seed (printed)")
    st.add_argument("--crossfall-percent", type=ranged("crossfall", what="road crossfall in %"), metavar="C",
                    help=f"road crossfall [%%], in {help_range('crossfall')}")
    st.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                    help="thrust angle of an axle [rad]; repeatable or comma-separated")
    st.add_argument("--json", action="store_true", help="machine-readable output")
    pl = tsub.add_parser("place", help="mounting plan of measured tires with the least trimmed offtracking "
                                       "(exact, a mixed-integer program)")
    source(pl, masses=False)
    speed(pl)
    tires(pl)
    pl.add_argument("--tires", dest="measured_tires", required=True, metavar="TIRES.csv",
                    help="measured tires: CSV id,conicity_N,ply_steer_N[,conicity_moment_Nm,ply_steer_moment_Nm]")
    pl.add_argument("--positions", metavar="POS,POS,...",
                    help="positions to fill, axle:slot (default: every tire position of units 2..N)")
    pl.add_argument("--crossfall-percent", type=ranged("crossfall", what="road crossfall in %"), metavar="C",
                    help=f"road crossfall [%%], in {help_range('crossfall')}")
    pl.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                    help="thrust angle of an axle [rad]; repeatable or comma-separated")
    pl.add_argument("--draws", type=int, default=10_000, metavar="N", help="random placements to compare (1e4)")
    pl.add_argument("--seed", type=int, default=20110801, metavar="S", help="seed of the random placements")
    pl.add_argument("--json", action="store_true", help="machine-readable output")
    turn = sub.add_parser("turn", help="low-speed turn (90 deg by default): swept width, offtracking, tail and "
                                       "frontal swing (kinematic model, docs/low_speed_turn.md)")
    source(turn, masses=False)
    turn.add_argument("--radius", type=ranged("turn_radius", what="outside steer wheel radius in m"), default=12.5,
                      metavar="R", help=f"radius of the outside steer wheel's path [m], in "
                                        f"{help_range('turn_radius')}; default 12.5")
    turn.add_argument("--angle-deg", type=ranged("turn_angle", what="turn angle in deg"), default=90.0, metavar="A",
                      help=f"angle of the turn [deg], in {help_range('turn_angle')}; default 90")
    turn.add_argument("--plot", metavar="FILE", help="draw the swept path into FILE (.png, .pdf or .svg; a new file)")
    turn.add_argument("--model", default="kinematic", choices=("kinematic", "nonlinear"),
                      help="the kinematic model (default: no forces) or the nonlinear model with tire forces "
                           "(friction demand, docs/nonlinear.md)")
    turn.add_argument("--speed-kph", type=ranged("speed", factor=3.6, unit="km/h", what="turn speed in km/h"),
                      default=None, metavar="V", help="with --model nonlinear: unit 1's speed [km/h]; default 5")
    turn.add_argument("--friction-coefficient", type=ranged("friction", what="friction coefficient mu"),
                      metavar="MU", default=None, help="with --model nonlinear: mu, in (0, 2]; default 0.8")
    turn.add_argument("--path-gain", type=ranged("path_gain", what="path gain in rad/m"), metavar="K",
                      default=None, help="with --model nonlinear: the path-following law's gain [rad/m]; default 2 (and its integral term, docs/nonlinear.md)")
    turn.add_argument("--tire", choices=("saturating", "linear"), default=None,
                      help="with --model nonlinear: the tire law; default saturating")
    turn.add_argument("--json", action="store_true", help="machine-readable output")
    st = sub.add_parser("study", help="a study file's cases (factors, design, measures) in batches on Dask, "
                                      "results in Parquet")
    st.add_argument("study_file", metavar="STUDY.toml", help="the study file")
    st.add_argument("--out", required=True, metavar="DIR", help="results folder: new, empty, or this study's "
                                                               "earlier results (then only missing chunks run)")
    where = st.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, metavar="N", help="a local Dask cluster of N worker processes")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="an existing Dask scheduler (tcp://host:8786). Connect only to a cluster you trust: "
                            "Dask's messages carry pickles, so a scheduler runs what it likes in this process")
    st.add_argument("--csv", action="store_true", help="also write DIR/results.csv (one row per case)")
    st.add_argument("--report", metavar="REPORT_DIR", help="then write the study report (HTML, PDF) into REPORT_DIR: "
                                                           "new, empty or an earlier report")
    st.add_argument("--criteria", metavar="FILE", help="with --report: limits to judge the cases by (TOML)")
    st.add_argument("--scheme", metavar="FILE", help="assess every case against a scheme file (docs/assessment.md): "
                                                     "the level each measure and the case reach as columns, and in "
                                                     "the report the share of cases reaching each level")
    st.add_argument("--no-pdf", action="store_true", help="with --report: HTML only")
    st.add_argument("--json", action="store_true", help="machine-readable summary")
    ass = sub.add_parser("assess", help="a performance-based standards assessment: every measure of a scheme file "
                                        "at its own conditions, judged per level (docs/assessment.md)")
    source(ass)
    ass.add_argument("--scheme", required=True, metavar="FILE",
                     help="the scheme file (TOML): levels, and per measure its conditions and limits per level, "
                          "each with its source (examples/schemes/)")
    tires(ass)
    load(ass, False, convention=False)
    ass.add_argument("--residual", action="append", default=[], metavar="AXLE=P,T",
                     help="residual force P [N] (+y) and moment T [N*m] (+z) on an axle, a source of the trim and "
                          "the straight path; repeatable (the crossfall is the scheme's crossfall_percent)")
    ass.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                     help=f"thrust angle of an axle [rad], in {help_range('misalignment')}; repeatable or "
                          f"comma-separated")
    ass.add_argument("--tires", metavar="FILE", help="mounted tires (CSV or TOML): their axle P and T")
    ass.add_argument("--out", metavar="DIR", help="also write the assessment report (HTML, PDF; the verdict table "
                                                  "first, then the evidence of every measure): new, empty or an "
                                                  "earlier report")
    ass.add_argument("--no-pdf", action="store_true", help="with --out: HTML only")
    ass.add_argument("--paper", default="letter", choices=("letter", "a4"), help="paper of the PDF (default letter)")
    ass.add_argument("--json", action="store_true", help="machine-readable output (docs/assessment.md)")
    rol = sub.add_parser("roll", help="roll: static rollover threshold per roll-coupled group (lift-off axle by "
                                      "axle), roll gains, load transfer ratios, roll modes (docs/roll.md)")
    common(rol, None)
    rol.add_argument("--plot", metavar="FILE", help="write the a_y - phi curve of every group, each lift-off marked "
                                                    "(.png, .pdf or .svg; a new file)")
    sub.add_parser("presets", help="list the presets").add_argument("--json", action="store_true")
    return p


COMMANDS = {"presets": cmd_presets, "eig": cmd_eig, "matrices": cmd_matrices, "steady": cmd_steady,
            "simulate": cmd_simulate, "measures": cmd_measures, "fmu": cmd_fmu, "report": cmd_report,
            "tracking": cmd_tracking, "turn": cmd_turn, "study": cmd_study, "roll": cmd_roll,
            "assess": cmd_assess}


def run(argv: Sequence[str] | None = None, out=None) -> int:
    """Run ``lcv`` with ``argv``; return the exit status.  Output goes to ``out`` (stdout)."""
    import signal
    import threading
    stream = out if out is not None else sys.stdout
    previous = None
    try:
        args = build_parser().parse_args(argv)
        writer = Output(stream)
        if threading.current_thread() is threading.main_thread():
            # a batch system's SIGTERM (a time limit) ends any command as Ctrl-C does: what it was
            # writing aside is removed, nothing half-written is left
            previous = signal.signal(signal.SIGTERM, _terminated)
        status = COMMANDS[args.command](args, writer)
        stream.flush()
        return status
    except KeyboardInterrupt:
        print("lcv: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except UsageError as exc:
        print(f"lcv: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except (RangeError, KeyError) as exc:
        print(f"lcv: error: {one_line(exc.args[0] if exc.args else exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except OutputError as exc:
        print(f"lcv: error: {one_line(exc)}", file=sys.stderr)
        return 1
    except OSError as exc:
        if exc.errno == errno.EPIPE:
            _silence_stdout()
            return EXIT_BROKEN_PIPE
        print(f"lcv: error: cannot write the output: {one_line(exc.strerror or exc)}", file=sys.stderr)
        _silence_stdout()
        return 1
    except FloatingPointError as exc:
        print(f"lcv: error: {one_line(exc)}", file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - one line, never a traceback
        print(f"lcv: internal error: {type(exc).__name__}: {one_line(exc)} (please report this)", file=sys.stderr)
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _terminated(_signum, _frame):
    raise KeyboardInterrupt


def _silence_stdout() -> None:
    """Point fd 1 at /dev/null so that the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    except OSError:  # pragma: no cover
        pass


def main() -> None:
    """Console entry point."""
    status = run()
    if status == EXIT_INTERRUPTED:
        # leave at once: what Ctrl-C cut short (a notebook kernel's event loop) would
        # otherwise print its own tracebacks while the interpreter shuts down
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(status)
    sys.exit(status)

