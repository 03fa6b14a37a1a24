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
    lcv study    STUDY.toml --out DIR [--workers N | --scheduler ADDRESS] [--csv] [--report R [--criteria F]]
    lcv presets  [--json]

``UNITS`` is a comma list of unit names of the vehicle; each gets the 1 % rule on its
axles (P along +y, T = 0.3048 m * P about +z).  ``--convention`` is ``consistent``
(default) or ``thesis`` (SPEC erratum 1).  JSON units: eigenvalues [1/s]; matrices in
thesis units (lbf, in, s) for presets and SI for vehicle files unless ``--units`` says
otherwise; everything else SI.  Every number is checked against
:data:`lcvreport.ranges.RANGES`.  A bad argument exits with status 2 and one line naming
it and what is valid; an output that cannot be written exits 1 with one line; a
closed pipe (``lcv ... | head``) ends quietly with status 141, as SIGPIPE does for
other Unix tools.  No output is ever non-finite.
"""
from __future__ import annotations

if __name__ == "__main__":          # python -m lcvreport.cli: one BLAS thread before numpy loads
    from lcvreport.util.threads import configure_entry_point
    configure_entry_point()

import argparse  # noqa: E402
import errno
import json
import math
import os
import sys
import time
from pathlib import Path
from typing import Sequence

import numpy as np

from .ranges import RANGES, RangeError
from .units import MPS_PER_KPH, MPS_PER_MPH, THESIS, SI, mps_to_kph

#: exit status of a closed pipe (128 + SIGPIPE), as a shell reports a tool SIGPIPE ended
EXIT_BROKEN_PIPE = 141
#: exit status after Ctrl-C (128 + SIGINT), as a shell reports it
EXIT_INTERRUPTED = 130


class UsageError(Exception):
    """A bad command-line argument; the message names it and what is valid (exit 2)."""


class OutputError(Exception):
    """The output cannot be written or would not be finite (exit 1)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump
        raise UsageError(message)


def _number(text: str, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number ({what}), got {text!r}") from None


def _ranged(key: str, factor: float = 1.0, unit: str | None = None, what: str = ""):
    r = RANGES[key]

    def conv(text: str) -> float:
        value = _number(text, what or r.description)
        if not r.contains(value / factor):
            raise argparse.ArgumentTypeError(f"must be in {r.text(factor, unit)} ({what or r.description}), "
                                             f"got {text}")
        return value
    return conv


def _help_range(key: str, factor: float = 1.0, unit: str | None = None) -> str:
    """The valid range of ``key`` for a help text (argparse formats help with %: a unit of % is doubled)."""
    return RANGES[key].text(factor, unit).replace("%", "%%")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``lcv``."""
    from .model.presets import MASS_OPTIONS, PRESETS
    from importlib.metadata import version
    __version__ = version("lcvreport")
    p = _Parser(prog="lcv", description="Linear yaw-plane model of long combination vehicles.")
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
        g.add_argument("--speed-kph", type=_ranged("speed", 1 / MPS_PER_KPH, "km/h", "forward speed in km/h"),
                       metavar="V", help=f"forward speed [km/h], in {_help_range('speed', 1 / MPS_PER_KPH, 'km/h')}")
        g.add_argument("--speed-mph", type=_ranged("speed", 1 / MPS_PER_MPH, "mph", "forward speed in mph"),
                       metavar="V", help=f"forward speed [mph], in {_help_range('speed', 1 / MPS_PER_MPH, 'mph')}")

    def tires(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--tire-scale", default=1.0, type=_ranged("tire_scale", what="factor on the tire "
                        "coefficients"), metavar="S",
                        help=f"factor on every tire coefficient (chapter V), in {_help_range('tire_scale')}; "
                             "default 1")

    def load(sp: argparse.ArgumentParser, required: bool, convention: bool = True) -> None:
        from .model.loads import CONVENTIONS
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

    common(sub.add_parser("eig", help="eigenvalues [1/s], damped frequency, damping ratio"), None)
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
                             f"{_help_range('misalignment')}; repeatable or comma-separated")
        sp.add_argument("--crossfall-percent", type=_ranged("crossfall", what="road crossfall in %"), metavar="C",
                        help=f"road crossfall [%%], positive falling toward +y, in {_help_range('crossfall')}")
        sp.add_argument("--tires", metavar="FILE", help="mounted tires (CSV or TOML: position, conicity_N, "
                                                         "ply_steer_N, serial_side[, moments]): their axle P and T")

    sim = sub.add_parser("simulate", help="exact response from rest to a steer input and residual sources, "
                                          "streamed as CSV (or JSON), SI units")
    common(sim, False)
    residuals(sim)
    sim.add_argument("--steer", metavar="SPEC", default=None,
                     help="steer input: step:A, sine:A:F, pulse:A:D, csv:FILE, lane-change:A0:F (A0 in m/s^2 or "
                          "with g, e.g. 0.15g); default none")
    sim.add_argument("--t-end", default=10.0, type=_ranged("t_end", what="end time in s"), metavar="T",
                     help=f"end time [s], in {_help_range('t_end')}; default 10")
    sim.add_argument("--dt", default=0.01, type=_ranged("output_step", what="output step in s"), metavar="H",
                     help=f"output step [s], in {_help_range('output_step')}; must divide t-end; default 0.01")
    mea = sub.add_parser("measures", help="yaw-plane measures: damping, RA, YDC, HSTO, HSSO, trim, the low-speed "
                                          "turn (defined in docs/measures.md)")
    source(mea)
    g = mea.add_mutually_exclusive_group(required=True)
    g.add_argument("--speed-kph", metavar="V", help="forward speed [km/h], or a sweep START:STOP:STEP")
    g.add_argument("--speed-mph", metavar="V", help="forward speed [mph], or a sweep START:STOP:STEP")
    tires(mea)
    load(mea, False, convention=False)
    residuals(mea)
    mea.add_argument("--criteria", metavar="FILE", help="limits to judge the measures by (TOML, see examples/)")
    mea.add_argument("--json", action="store_true", help="machine-readable output")
    fmu = sub.add_parser("fmu", help="FMUs of the vehicle (FMI 2.0 or 3.0; native: Co-Simulation and Model Exchange)")
    source(fmu, masses=False)
    fmu.add_argument("--out", required=True, metavar="DIR", help="output folder")
    fmu.add_argument("--kind", default=None, choices=("python", "native", "both"),
                     help="python (pythonfmu, pythonfmu3 for FMI 3.0), native (C99) or both (default both)")
    fmu.add_argument("--fmi", default="2", choices=("2", "3"),
                     help="FMI version (default 2): <name>.fmu and <name>Native.fmu, or <name>3.fmu and "
                          "<name>Native3.fmu")
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
    st.add_argument("--crossfall-percent", type=_ranged("crossfall", what="road crossfall in %"), metavar="C",
                    help=f"road crossfall [%%], in {_help_range('crossfall')}")
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
    pl.add_argument("--crossfall-percent", type=_ranged("crossfall", what="road crossfall in %"), metavar="C",
                    help=f"road crossfall [%%], in {_help_range('crossfall')}")
    pl.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                    help="thrust angle of an axle [rad]; repeatable or comma-separated")
    pl.add_argument("--draws", type=int, default=10_000, metavar="N", help="random placements to compare (1e4)")
    pl.add_argument("--seed", type=int, default=20110801, metavar="S", help="seed of the random placements")
    pl.add_argument("--json", action="store_true", help="machine-readable output")
    turn = sub.add_parser("turn", help="low-speed turn (90 deg by default): swept width, offtracking, tail and "
                                       "frontal swing (kinematic model, docs/low_speed_turn.md)")
    source(turn, masses=False)
    turn.add_argument("--radius", type=_ranged("turn_radius", what="outside steer wheel radius in m"), default=12.5,
                      metavar="R", help=f"radius of the outside steer wheel's path [m], in "
                                        f"{_help_range('turn_radius')}; default 12.5")
    turn.add_argument("--angle-deg", type=_ranged("turn_angle", what="turn angle in deg"), default=90.0, metavar="A",
                      help=f"angle of the turn [deg], in {_help_range('turn_angle')}; default 90")
    turn.add_argument("--plot", metavar="FILE", help="draw the swept path into FILE (.png, .pdf or .svg; a new file)")
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
    st.add_argument("--no-pdf", action="store_true", help="with --report: HTML only")
    st.add_argument("--json", action="store_true", help="machine-readable summary")
    sub.add_parser("presets", help="list the presets").add_argument("--json", action="store_true")
    return p


# ---------------------------------------------------------------------------- output
class _Out:
    """Writes to a stream; turns write failures into :class:`OutputError` and refuses
    non-finite numbers."""

    def __init__(self, stream):
        if stream is None:
            raise OutputError("standard output is closed; nothing can be written")
        self.stream = stream

    def write(self, text: str) -> None:
        self.stream.write(text)

    def line(self, text: str = "") -> None:
        self.stream.write(text + "\n")

    def json(self, doc) -> None:
        try:
            text = json.dumps(doc, allow_nan=False)
        except ValueError:
            raise OutputError("the result is not finite (a number is inf or NaN); nothing was written") from None
        self.line(text)


def _finite(*arrays) -> None:
    for a in arrays:
        if a is not None and not np.all(np.isfinite(np.asarray(a, dtype=complex))):
            raise OutputError("the result is not finite (a number is inf or NaN); nothing was written")


# ---------------------------------------------------------------------------- inputs
def _vehicle(args: argparse.Namespace):
    from .model.presets import PRESETS, load_preset
    from .model.vehicle import VehicleError
    from .model.vehicle_file import load_vehicle
    if getattr(args, "preset", None) is not None:
        if args.preset not in PRESETS:
            raise UsageError(f"argument --preset: unknown preset {args.preset!r}; valid: {', '.join(PRESETS)}")
        try:
            return load_preset(args.preset, masses=getattr(args, "masses", "table"))
        except ValueError as exc:
            raise UsageError(f"argument --masses: {exc}") from None
    if getattr(args, "masses", "table") != "table":
        raise UsageError("argument --masses: only presets have unrounded masses")
    try:
        v = load_vehicle(args.vehicle)
    except VehicleError as exc:
        raise UsageError(f"argument --vehicle {args.vehicle}: {exc}") from None
    from .model.plausibility import plausibility_warnings
    for line in plausibility_warnings(v):
        print(f"lcv: warning: {_line(args.vehicle)}: {_line(line)}", file=sys.stderr)
    return v


def _speed_mps(args: argparse.Namespace) -> float:
    if getattr(args, "speed_kph", None) is not None:
        return args.speed_kph * MPS_PER_KPH
    return args.speed_mph * MPS_PER_MPH


def _speed_text(args: argparse.Namespace) -> str:
    if getattr(args, "speed_kph", None) is not None:
        return f"{args.speed_kph:g} km/h"
    return f"{args.speed_mph:g} mph"


def _load_units(args: argparse.Namespace, vehicle) -> list[str]:
    from .model.loads import check_unit_names
    names = [s.strip() for s in args.load.split(",")]
    valid = ",".join(vehicle.unit_names)
    if not names or any(not n for n in names):
        raise UsageError(f"argument --load: expected a comma list of units from {valid}, got {args.load!r}")
    try:
        return check_unit_names(vehicle, names)
    except KeyError as exc:
        raise UsageError(f"argument --load: {exc.args[0]}") from None


def _load_vector(args: argparse.Namespace, vehicle, units=SI) -> np.ndarray:
    from .model.loads import load_vector, one_percent_rule
    names = _load_units(args, vehicle)
    try:
        res = one_percent_rule(vehicle, names, t_sign=1.0)
    except ValueError as exc:
        raise UsageError(f"argument --load: {exc}") from None
    return load_vector(vehicle, res, args.convention, units)


def _sources(args: argparse.Namespace, vehicle):
    """The residual sources of ``--residual``, ``--misalignment``, ``--crossfall-percent``."""
    from .model.loads import ResidualLoads, ResidualSources
    axles = vehicle.axle_names
    P, T, eps = {}, {}, {}

    def axle(option, name):
        if name not in axles:
            raise UsageError(f"argument {option}: unknown axle {name!r} of {vehicle.name}; valid: {', '.join(axles)}")
        return name

    for item in getattr(args, "residual", []) or []:
        name, sep, value = item.partition("=")
        parts = value.split(",")
        if not sep or len(parts) != 2:
            raise UsageError(f"argument --residual: expected AXLE=P,T (N, N*m), got {item!r}")
        a = axle("--residual", name.strip())
        if a in P:
            raise UsageError(f"argument --residual: axle {a!r} is given twice")
        for sym, text, key in (("P", parts[0], "residual_force"), ("T", parts[1], "residual_moment")):
            try:
                val = float(text)
            except ValueError:
                raise UsageError(f"argument --residual: {sym} of axle {a} must be a number, got {text!r}") from None
            if not RANGES[key].contains(val):
                raise UsageError(f"argument --residual: {sym} of axle {a} must be in {RANGES[key].text()}, got {text}")
            (P if sym == "P" else T)[a] = val
    for group in getattr(args, "misalignment", []) or []:
        for item in group.split(","):
            name, sep, value = item.partition("=")
            if not sep:
                raise UsageError(f"argument --misalignment: expected AXLE=RAD, got {item!r}")
            a = axle("--misalignment", name.strip())
            if a in eps:
                raise UsageError(f"argument --misalignment: axle {a!r} is given twice")
            try:
                val = float(value)
            except ValueError:
                raise UsageError(f"argument --misalignment: the angle of axle {a} must be a number, got {value!r}") \
                    from None
            if not RANGES["misalignment"].contains(val):
                raise UsageError(f"argument --misalignment: the angle of axle {a} must be in "
                                 f"{RANGES['misalignment'].text()}, got {value}")
            eps[a] = val
    if getattr(args, "tires", None):
        from .analysis.tracking import TrackingError, axle_residuals, read_mounted_tires
        try:
            loads = axle_residuals(vehicle, read_mounted_tires(args.tires))
        except TrackingError as exc:
            raise UsageError(f"argument --tires: {exc}") from None
        for a, val in loads.P_N.items():
            P[a] = P.get(a, 0.0) + val
        for a, val in loads.T_Nm.items():
            T[a] = T.get(a, 0.0) + val
    crossfall = getattr(args, "crossfall_percent", None) or 0.0
    return ResidualSources(ResidualLoads(P, T), eps, crossfall)


def _parse_speeds(args: argparse.Namespace) -> tuple[list[float], str]:
    """Speeds [m/s] of ``--speed-kph``/``--speed-mph`` (one, or START:STOP:STEP) and the unit."""
    text, unit, factor = (args.speed_kph, "km/h", MPS_PER_KPH) if args.speed_kph is not None else \
        (args.speed_mph, "mph", MPS_PER_MPH)
    option = "--speed-kph" if unit == "km/h" else "--speed-mph"
    r = RANGES["speed"]
    parts = text.split(":")
    try:
        nums = [float(x) for x in parts]
    except ValueError:
        raise UsageError(f"argument {option}: expected a number or START:STOP:STEP, got {text!r}") from None
    if len(nums) == 1:
        values = nums
    elif len(nums) == 3:
        lo, hi, step = nums
        if not (math.isfinite(step) and step > 0 and hi >= lo):
            raise UsageError(f"argument {option}: START:STOP:STEP needs STOP >= START and STEP > 0, got {text!r}")
        count = int(math.floor((hi - lo) / step + 1e-9)) + 1
        if count > 1000:
            raise UsageError(f"argument {option}: {count} speeds; at most 1000")
        values = [lo + k * step for k in range(count)]
    else:
        raise UsageError(f"argument {option}: expected a number or START:STOP:STEP, got {text!r}")
    for val in values:
        if not r.contains(val * factor):
            raise UsageError(f"argument {option}: must be in {r.text(1 / factor, unit)}, got {val:g}")
    return [val * factor for val in values], unit


# ---------------------------------------------------------------------------- commands
def _cmd_presets(args, out: _Out) -> int:
    from .model.presets import PRESET_LABELS, PRESETS
    if args.json:
        out.json({"presets": list(PRESETS)})
    else:
        for name in PRESETS:
            out.line(f"{name:22s} {PRESET_LABELS[name]}")
    return 0


def _cmd_eig(args, out: _Out) -> int:
    from .analysis.modes import modes
    v = _vehicle(args)
    m = modes(v, _speed_mps(args), args.tire_scale)
    _finite(m.eigenvalues)
    k = m.least_damped
    if args.json:
        out.json({"eigenvalues": [[float(lam.real), float(lam.imag)] for lam in m.eigenvalues],
                  "damping_ratio": [float(z) for z in m.damping_ratio],
                  "damped_frequency_hz": [float(f) for f in m.damped_frequency_hz],
                  "least_damped_mode": None if k is None else k + 1})
        return 0
    out.line(f"{v.name} at {_speed_text(args)}, tire scale {args.tire_scale:g} "
             f"({'stable' if m.stable else 'UNSTABLE'}); modes by real part, * = least damped")
    out.line(f"{'mode':>4} {'Re [1/s]':>10} {'Im [1/s]':>10} {'f_d [Hz]':>9} {'zeta [-]':>9}")
    for row in m.table():
        mark = " *" if k is not None and row["mode"] in (k + 1, k + 2) else ""
        out.line(f"{row['mode']:>4} {row['real_per_s']:>10.4f} {row['imag_per_s']:>10.4f} "
                 f"{row['damped_frequency_hz']:>9.4f} {row['damping_ratio']:>9.4f}{mark}")
    return 0


def _cmd_matrices(args, out: _Out) -> int:
    from .model.builder import system_matrices
    v = _vehicle(args)
    which = args.units or ("thesis" if args.preset is not None else "si")
    units = THESIS if which == "thesis" else SI
    M, S = system_matrices(v, _speed_mps(args), args.tire_scale, units=units)
    F = _load_vector(args, v, units) if args.load is not None else None
    _finite(M, S, F)
    label = "thesis units: lbf, in, s" if units is THESIS else "SI: N, m, kg, s"
    if args.json:
        doc = {"state": list(v.state_names), "units": label, "M": M.tolist(), "S": S.tolist()}
        if F is not None:
            doc["F"] = F.tolist()
        out.json(doc)
        return 0
    out.line(f"state = {list(v.state_names)}  ({label})")
    out.line("M =")
    out.line(np.array2string(M, precision=6, max_line_width=200))
    out.line("S =")
    out.line(np.array2string(S, precision=6, max_line_width=200))
    if F is not None:
        out.line(f"F ({args.convention} convention) =")
        out.line(np.array2string(F, precision=4, max_line_width=200))
    return 0


def _cmd_steady(args, out: _Out) -> int:
    from .analysis.geometry import rear_offsets
    from .analysis.steady import steady_state
    v = _vehicle(args)
    F = _load_vector(args, v)
    x = steady_state(v, _speed_mps(args), F, args.tire_scale)
    n = v.n_units
    y = rear_offsets(v, x[n + 1:])
    _finite(x, y)
    state = {name: float(value) for name, value in zip(v.state_names, x)}
    ydoc = {f"y{k + 2}": float(val) for k, val in enumerate(y)}
    if args.json:
        out.json({"state": state, "y": ydoc})
        return 0
    out.line(f"steady state, {v.name} at {_speed_text(args)}, load on {args.load} ({args.convention} convention)")
    for name, value in state.items():
        unit = "m/s" if name == "v1" else "rad/s" if name.startswith("r") else "rad"
        extra = f"  ({math.degrees(value):.4f} deg)" if name.startswith("theta") else ""
        out.line(f"  {name:7s} {value: .6e} {unit}{extra}")
    for name, value in ydoc.items():
        out.line(f"  {name:7s} {value: .6e} m")
    return 0


def _cmd_simulate(args, out: _Out) -> int:
    from .analysis.exact import ManoeuvreError, check_lane_change_steer, final_state, response
    from .analysis.manoeuvres import SteerError, parse_steer, step
    v = _vehicle(args)
    steps_f = args.t_end / args.dt
    steps = int(round(steps_f))
    if args.dt > args.t_end:
        raise UsageError(f"argument --dt: {args.dt:g} s is longer than --t-end {args.t_end:g} s")
    if abs(steps_f - steps) > 1e-9 * max(steps_f, 1.0):
        raise UsageError(f"argument --dt: {args.dt:g} s does not divide --t-end {args.t_end:g} s into whole steps "
                         f"({steps_f:.6g} steps); choose --dt {args.t_end / max(math.floor(steps_f), 1):.6g} or "
                         f"--t-end {math.floor(steps_f) * args.dt:.6g}")
    rows = RANGES["output_rows"]
    if steps + 1 > rows.high:
        raise UsageError(f"arguments --t-end/--dt: {steps + 1} rows; at most {rows.high:.0f} (raise --dt)")
    try:
        steer = parse_steer(args.steer) if args.steer is not None else step(0.0)
    except SteerError as exc:
        raise UsageError(f"argument --steer: {exc}") from None
    if args.steer is not None and not v.steered_axles:
        raise UsageError(f"argument --steer: {v.name} has no steered axle")
    F = _load_vector(args, v) if args.load is not None else np.zeros(v.n_states)
    try:
        F = F + _sources(args, v).vector(v, args.tire_scale)
    except (KeyError, RangeError) as exc:
        raise UsageError(f"argument: {exc.args[0]}") from None
    u = _speed_mps(args)
    chunk = 20000                                  # rows per exact run: constant memory
    first = True
    state, k = None, 0
    while k < steps:
        n = min(chunk, steps - k)
        t_b = (k + n) * args.dt
        try:
            r = response(v, u, steer, t_b, args.dt, F, args.tire_scale, t_start=k * args.dt, state=state)
            check_lane_change_steer(r)      # a computed steer beyond [-1, 1] rad: refused before a row is written
        except ManoeuvreError as exc:
            raise UsageError(f"argument --steer: {exc}") from None
        M = r.matrix()
        _finite(M)
        if first:
            names = r.columns()
            if args.json:
                out.write('{"columns": ' + json.dumps(names) + ', "rows": [')
            else:
                out.line(",".join(names))
        body = M if first else M[1:]
        if args.json:
            out.write(("" if first else ", ") + ", ".join(json.dumps(row) for row in body.tolist()))
        else:
            if first:
                row_format = ",".join(["%.10g"] * M.shape[1]) + "\n"     # one format per row: 2x faster
            out.write("".join([row_format % tuple(row) for row in body.tolist()]))
        first = False
        state = final_state(r)
        k += n
    if args.json:
        out.line("]}")
    return 0


def _cmd_measures(args, out: _Out) -> int:
    from .analysis.criteria import CriteriaError, judge, load_criteria
    from .analysis.measures import measure_set
    v = _vehicle(args)
    speeds, unit = _parse_speeds(args)
    units = _load_units(args, v) if args.load is not None else None
    sources = _sources(args, v)
    criteria = None
    if args.criteria is not None:
        try:
            criteria = load_criteria(args.criteria)
        except CriteriaError as exc:
            raise UsageError(f"argument --criteria {args.criteria}: {exc}") from None
    docs, sets = [], []
    for u in speeds:
        try:
            m = measure_set(v, u, args.tire_scale, units, sources=sources if sources else None)
        except ValueError as exc:
            if "static_load_N" in str(exc):
                raise UsageError(f"argument --load: {exc}") from None
            raise
        doc = m.to_dict()
        if criteria is not None:
            doc["verdicts"] = judge(criteria, doc)
        docs.append(doc)
        sets.append(m)
    for doc in docs:
        _finite(*(val for val in doc.values() if isinstance(val, (int, float))),
                *(val for val in doc.values() if isinstance(val, list) and val and not isinstance(val[0], dict)))
    sweep = len(speeds) > 1
    if args.json:
        out.json(docs if sweep else docs[0])
        return 0
    if sweep:
        cols = _flat_columns(docs[0], v)
        out.line(",".join(cols))
        for doc in docs:
            flat = _flatten(doc, v)
            out.line(",".join("" if flat.get(c) is None else (f"{flat[c]:.10g}" if isinstance(flat[c], float)
                                                             else str(flat[c])) for c in cols))
        return 0
    m, doc = sets[0], docs[0]
    out.line(f"{v.name} at {args.speed_kph or args.speed_mph} {unit} ({mps_to_kph(m.speed_mps):.1f} km/h), tire scale "
             f"{args.tire_scale:g}")
    for row in m.rows():
        val = row["value"]
        text = val if isinstance(val, str) else f"{val:.6g}"
        out.line(f"  {row['measure']:42s} {text:>12s} {row['unit']:10s} {row['note']}")
    if criteria is not None:
        out.line(f"verdicts against {args.criteria} (limits and their sources as the file gives them):")
        for key, verdict in doc["verdicts"].items():
            out.line(f"  {key:28s} {verdict['verdict']:14s} {verdict['note']}")
    return 0


def _flatten(doc: dict, vehicle) -> dict:
    flat = {}
    for key, val in doc.items():
        if key == "ay_gain_per_unit":
            for name, g in zip(vehicle.unit_names, val or [None] * vehicle.n_units):
                flat[f"ay_gain_{name}_m_per_s2_per_rad"] = g
        elif key == "trim":                      # the registry's keys (trim.delta_rad, trim.offtracking_m)
            flat["trim.delta_rad"] = None if val is None else val["delta_rad"]
            flat["trim.offtracking_m"] = None if val is None else val["offtracking_m"]
        elif key == "verdicts":
            for k, verdict in val.items():
                flat[f"verdict_{k}"] = verdict["verdict"]
        elif key == "reasons":                   # the text output and the JSON say why; a CSV cell is a number
            continue
        else:
            flat[key] = val
    return flat


def _flat_columns(doc: dict, vehicle) -> list[str]:
    return list(_flatten(doc, vehicle))


def _cmd_fmu(args, out: _Out) -> int:
    from .fmu.build import FmuBuildError, build_vehicle_fmus
    v = _vehicle(args)
    try:
        kw = {}
        if args.speed_kph is not None or args.speed_mph is not None:
            kw["u_start_mps"] = _speed_mps(args)      # the start value of the input u
        kind = args.kind or "both"
        paths = build_vehicle_fmus(v, args.out, kind=kind, fmi=int(args.fmi), **kw)
    except FmuBuildError as exc:
        raise OutputError(str(exc)) from None
    for p in paths:
        out.line(f"wrote {p}")
    return 0


def _cmd_report(args, out: _Out) -> int:
    from .report.build import OutputFolderError, ReportError, build_assessment, check_output_folder
    try:
        check_output_folder(args.out)          # before anything is computed
    except OutputFolderError as exc:
        raise UsageError(f"argument {exc}") from None
    v = _vehicle(args)
    speed = _speed_mps(args) if (args.speed_kph is not None or args.speed_mph is not None) else None
    units = _load_units(args, v) if args.load is not None else None
    if units:
        from .model.loads import one_percent_rule
        try:
            one_percent_rule(v, units)
        except ValueError as exc:
            raise UsageError(f"argument --load: {exc}") from None
    src = _sources(args, v)
    try:
        src.vector(v)
    except (KeyError, RangeError) as exc:
        raise UsageError(f"argument: {exc.args[0]}") from None
    residuals = {"P_N": src.loads.P_N, "T_Nm": src.loads.T_Nm, "misalignment_rad": src.misalignment_rad,
                 "crossfall_percent": src.crossfall_percent} if src else None
    if args.criteria is not None:
        from .analysis.criteria import CriteriaError, load_criteria
        try:
            load_criteria(args.criteria)
        except CriteriaError as exc:
            raise UsageError(f"argument --criteria {args.criteria}: {exc}") from None
    tracking = {"tires": None, "stats": None}
    if args.tires:
        from .analysis.tracking import read_mounted_tires
        tracking["tires"] = read_mounted_tires(args.tires)      # checked by _sources above
        if not v.steered_axles:
            raise UsageError(f"argument --tires: {v.name} has no steered axle: the trim needs one")
    if args.tracking_stats is not None:
        from .analysis.tracking import TrackingError, parse_stats_spec
        if not v.steered_axles:
            raise UsageError(f"argument --tracking-stats: {v.name} has no steered axle: the trim needs one")
        try:
            tracking["stats"] = parse_stats_spec(args.tracking_stats)
        except TrackingError as exc:
            raise UsageError(f"argument --tracking-stats: {exc}") from None
    text = None
    if args.vehicle is not None:               # the user's file as written, comments and all
        from .model.vehicle_file import read_vehicle_text
        text = read_vehicle_text(args.vehicle)
    t0 = time.perf_counter()
    try:
        res = build_assessment(v, args.out, speed_mps=speed, load_units=units, pdf=not args.no_pdf,
                               progress=lambda text: print(f"lcv report: {text}", file=sys.stderr, flush=True),
                               source=args.vehicle or f"preset {args.preset}", vehicle_text=text, paper=args.paper,
                               residuals=residuals, criteria_file=args.criteria,
                               tracking=tracking if tracking["tires"] or tracking["stats"] else None)
    except OutputFolderError as exc:
        raise UsageError(f"argument {exc}") from None
    except ReportError as exc:
        raise OutputError(str(exc)) from None
    for key in ("html", "pdf", "data"):
        if key in res:
            out.line(f"wrote {res[key]}")
    print(f"lcv report: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


def _cmd_place(args, out: _Out) -> int:
    from .analysis.placement import place_tires, read_measured_tires
    from .analysis.tracking import TrackingError
    v = _vehicle(args)
    if not v.steered_axles:
        raise UsageError(f"argument --vehicle: {v.name} has no steered axle: the trim needs one")
    if not 1 <= args.draws <= 1_000_000:
        raise UsageError(f"argument --draws: must be in [1, 1e6], got {args.draws}")
    if not 0 <= args.seed < 2 ** 63:
        raise UsageError(f"argument --seed: must be in [0, 2^63), got {args.seed}")
    try:
        tires = read_measured_tires(args.measured_tires)
    except TrackingError as exc:
        raise UsageError(f"argument --tires: {exc}") from None
    positions = [p.strip() for p in args.positions.split(",")] if args.positions else None
    src = _sources(args, v)
    try:
        F = src.vector(v, args.tire_scale) if src else None
        pl = place_tires(v, _speed_mps(args), tires, positions, F, args.tire_scale, args.draws, args.seed)
    except TrackingError as exc:
        opt = "--positions" if str(exc).startswith("position") else "--tires"
        raise UsageError(f"argument {opt}: {exc}") from None
    doc = pl.to_dict()
    if args.json:
        out.json(doc)
        return 0
    out.line(f"{v.name} at {_speed_text(args)}: mounting plan of {len(tires)} tires with the least |trimmed "
             f"offtracking| (then |trim steer|)")
    out.line(f"  {'position':<18} {'tire':<14} serial side")
    for row in pl.plan:
        out.line(f"  {row['position']:<18} {row['tire']:<14} {row['serial_side']}")
    r = doc["random_placements"]
    out.line(f"  offtracking [m]   plan {pl.offtracking_m: .6g} (least possible >= {pl.lower_bound_m:.3g}; "
             f"trim steer {pl.trim_delta_rad:.6g} rad)")
    out.line(f"                    as listed, serial side out {pl.as_listed_offtracking_m: .6g} "
             f"(trim steer {pl.as_listed_trim_delta_rad:.6g} rad)")
    out.line(f"                    random placements: mean {r['mean']: .6g}  sd {r['sd']:.6g}  best |.| "
             f"{r['best_abs']:.6g}  ({r['draws']} draws, seed {r['seed']})")
    return 0


def _cmd_tracking(args, out: _Out) -> int:
    if args.tracking_command == "place":
        return _cmd_place(args, out)
    from .analysis.tracking import ZERO, TrackingError, parse_distribution, tracking_stats
    v = _vehicle(args)
    if not v.steered_axles:
        raise UsageError(f"argument --vehicle: {v.name} has no steered axle: the trim needs one")
    try:
        dists = {name: (parse_distribution(getattr(args, name), "--" + name.replace("_", "-"))
                        if getattr(args, name) is not None else ZERO)
                 for name in ("conicity", "ply_steer", "conicity_moment", "ply_steer_moment")}
    except TrackingError as exc:
        raise UsageError(f"argument {exc}") from None
    if not 1 <= args.draws <= 10_000_000:
        raise UsageError(f"argument --draws: must be in [1, 1e7], got {args.draws}")
    if not 0 <= args.seed < 2 ** 63:
        raise UsageError(f"argument --seed: must be in [0, 2^63), got {args.seed}")
    for opt, val in (("--lane-width-m", args.lane_width_m), ("--body-width-m", args.body_width_m)):
        if not (math.isfinite(val) and 0 < val <= 10):
            raise UsageError(f"argument {opt}: must be in (0, 10] m, got {val:g}")
    axles = [a.strip() for a in args.axles.split(",")] if args.axles else None
    src = _sources(args, v)
    try:
        F = src.vector(v, args.tire_scale) if src else None
        s = tracking_stats(v, _speed_mps(args), dists["conicity"], dists["ply_steer"], args.mounting,
                           dists["conicity_moment"], dists["ply_steer_moment"], axles, args.lane_width_m,
                           args.body_width_m, args.draws, args.seed, F, args.tire_scale)
    except TrackingError as exc:
        opt = " --axles" if "axle" in str(exc).split(";")[0] and args.axles else ""
        raise UsageError(f"argument{opt}: {exc}") from None
    doc = s.to_dict()
    if args.json:
        out.json(doc)
        return 0
    out.line(f"{v.name} at {_speed_text(args)}: trimmed offtracking over the tire population (seed {s.seed}, "
             f"{s.draws} draws)")
    out.line(f"  offtracking [m]      mean {s.offtracking_mean_m: .6g}  sd {s.offtracking_sd_m:.6g}  (exact)")
    out.line(f"  trim steer [rad]     mean {s.trim_delta_mean_rad: .6g}  sd {s.trim_delta_sd_rad:.6g}  (exact)")
    out.line("  quantiles [m]        " + "  ".join(f"{q:g}: {val:.6g}" for q, val in s.quantiles_m.items()))
    lo, hi = s.exceedance_ci95
    out.line(f"  P(|offtracking| > {s.margin_m:.4g} m) = {s.exceedance_probability:.6g}  (95 % CI {lo:.3g} .. "
             f"{hi:.3g}, Monte Carlo)")
    return 0


def _cmd_turn(args, out: _Out) -> int:
    from .analysis.low_speed_turn import TurnError, low_speed_turn
    v = _vehicle(args)
    plot = None
    if args.plot is not None:
        plot = Path(args.plot)
        if plot.suffix.lower() not in (".png", ".pdf", ".svg"):
            raise UsageError(f"argument --plot: {plot} must end in .png, .pdf or .svg")
        if plot.exists() or plot.is_symlink():
            raise UsageError(f"argument --plot: {plot} exists; name a new file (lcv never overwrites one)")
        if not plot.parent.is_dir():
            raise UsageError(f"argument --plot: the folder {plot.parent} does not exist")
    try:
        t = low_speed_turn(v, args.radius, args.angle_deg)
    except TurnError as exc:
        raise UsageError(f"argument --{'vehicle' if args.vehicle else 'preset'}: {exc}") from None
    if plot is not None:
        _write_figure_new(t.plot(), plot)
    if args.json:
        out.json(t.to_dict())
        return 0
    centre = "" if t.steer_axle_radius_m is None else \
        f" (steered axle centre on up to {t.steer_axle_radius_m:.3f} m)"
    out.line(f"{v.name}: low-speed {t.angle_deg:g} deg turn, outside steer wheel on R = {t.radius_m:g} m{centre}; "
             f"overall length {t.overall_length_m:.2f} m")
    for label, key, value in (("swept width (lssp)", "lssp_m", t.lssp_m),
                              ("low-speed offtracking", "low_speed_offtracking_m", t.low_speed_offtracking_m),
                              ("frontal swing", "frontal_swing_m", t.frontal_swing_m)):
        out.line(f"  {label:<25} {value:8.3f} m" if value is not None else
                 f"  {label:<25} not computed: {_line(t.undefined.get(key, ''))}")
    for name, val in t.tail_swing_m.items():
        out.line(f"  tail swing, {name:<13} {val:8.3f} m")
    if not t.tail_swing_m:
        out.line(f"  {'tail swing':<25} not computed: {_line(t.undefined.get('max_tail_swing_m', ''))}")
    if plot is not None:
        out.line(f"wrote {plot}")
    return 0


def _write_figure_new(fig, path: Path) -> None:
    """Save a figure to a new file: written aside, then linked into place (never over a file)."""
    import os
    import tempfile
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=150)
        try:
            os.link(tmp, path)
        except FileExistsError:
            raise UsageError(f"argument --plot: {path} appeared while it was drawn; nothing was overwritten") \
                from None
        except OSError as exc:
            raise OutputError(f"cannot write {path}: {exc.strerror}") from None
    finally:
        os.unlink(tmp)


def _cmd_study(args, out: _Out) -> int:
    from .study.run import run_study
    from .study.spec import StudyError, load_study
    try:
        study = load_study(args.study_file)
    except StudyError as exc:
        raise UsageError(str(exc) if str(args.study_file) in str(exc) else f"{args.study_file}: {exc}") from None
    out_dir = Path(args.out)
    if args.scheduler is not None:
        from .study.run import check_scheduler_address
        try:
            check_scheduler_address(args.scheduler)
        except StudyError as exc:
            raise UsageError(f"argument {exc}") from None
    if (args.criteria is not None or args.no_pdf) and args.report is None:
        raise UsageError("arguments --criteria and --no-pdf belong to --report REPORT_DIR")
    if args.report is not None:
        from .report.build import OutputFolderError, check_output_folder
        try:
            check_output_folder(args.report)
        except OutputFolderError as exc:
            raise UsageError(f"argument --report: {exc}") from None
        if Path(args.report).resolve() == out_dir.resolve():
            raise UsageError("argument --report: give another folder than --out")
    if args.criteria is not None:
        from .analysis.criteria import CriteriaError, load_criteria
        try:
            load_criteria(args.criteria)
        except CriteriaError as exc:
            raise UsageError(f"argument --criteria {args.criteria}: {exc}") from None
    csv_path = out_dir / "results.csv"
    if args.csv and (csv_path.exists() or csv_path.is_symlink()):
        raise UsageError(f"argument --csv: {csv_path} exists; lcv never overwrites a file (move it, or omit --csv)")
    if not args.json:
        seed = f", seed {study.seed}" if study.seed is not None else ""
        out.line(f"study of {study.vehicle.name}: {study.kind} design{seed}, {study.n_cases} cases in "
                 f"{study.n_chunks} chunks of {study.chunk}; measures {', '.join(study.measures)}")
        for f in study.factors:
            out.line(f"  {f.describe()}")
        out.stream.flush()
    try:
        summary = run_study(study, out_dir, workers=args.workers, scheduler=args.scheduler)
    except StudyError as exc:
        raise UsageError(str(exc)) from None
    if args.csv:
        from .study.results import read_study
        tmp = out_dir / ".results.csv.tmp"
        read_study(out_dir).to_csv(tmp, index=False, float_format="%.17g")
        try:
            os.link(tmp, csv_path)
        except FileExistsError:
            raise UsageError(f"argument --csv: {csv_path} appeared meanwhile; nothing was overwritten") from None
        finally:
            tmp.unlink()
    report = None
    if args.report is not None:
        from .report.build import OutputFolderError, ReportError, build_study_report
        try:
            report = build_study_report(out_dir, args.report, criteria_file=args.criteria, pdf=not args.no_pdf,
                                        progress=lambda text: print(f"lcv study: report: {text}", file=sys.stderr,
                                                                    flush=True))
        except OutputFolderError as exc:
            raise UsageError(f"argument --report: {exc}") from None
        except ReportError as exc:
            raise OutputError(str(exc)) from None
    doc = {"out": str(out_dir), "n_cases": summary.n_cases, "n_chunks": summary.n_chunks,
           "chunks_computed": summary.n_computed, "chunks_found": summary.n_found, "seconds": summary.seconds,
           "seed": study.seed}
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


COMMANDS = {"presets": _cmd_presets, "eig": _cmd_eig, "matrices": _cmd_matrices, "steady": _cmd_steady,
            "simulate": _cmd_simulate, "measures": _cmd_measures, "fmu": _cmd_fmu, "report": _cmd_report,
            "tracking": _cmd_tracking, "turn": _cmd_turn, "study": _cmd_study}


def _line(text) -> str:
    """``text`` as one line of plain text: every character that is not printable (a newline, an
    ESC that would drive the terminal) escaped, so a message quoting a user's file is one line."""
    return "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in str(text))


def run(argv: Sequence[str] | None = None, out=None) -> int:
    """Run ``lcv`` with ``argv``; return the exit status.  Output goes to ``out`` (stdout)."""
    import signal
    import threading
    stream = out if out is not None else sys.stdout
    previous = None
    try:
        args = build_parser().parse_args(argv)
        writer = _Out(stream)
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
        print(f"lcv: error: {_line(exc)}", file=sys.stderr)
        return 2
    except (RangeError, KeyError) as exc:
        print(f"lcv: error: {_line(exc.args[0] if exc.args else exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except OutputError as exc:
        print(f"lcv: error: {_line(exc)}", file=sys.stderr)
        return 1
    except OSError as exc:
        if exc.errno == errno.EPIPE:
            _silence_stdout()
            return EXIT_BROKEN_PIPE
        print(f"lcv: error: cannot write the output: {_line(exc.strerror or exc)}", file=sys.stderr)
        _silence_stdout()
        return 1
    except FloatingPointError as exc:
        print(f"lcv: error: {_line(exc)}", file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - one line, never a traceback
        print(f"lcv: internal error: {type(exc).__name__}: {_line(exc)} (please report this)", file=sys.stderr)
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


if __name__ == "__main__":
    main()
