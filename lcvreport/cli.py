"""The ``lcv`` command: eigenvalues, matrices, steady state, time response, measures,
FMUs and reports of a preset or of a vehicle file.

Fixed contract (other parts and outside checks call these forms)::

    lcv eig      (--preset NAME | --vehicle FILE) (--speed-kph V | --speed-mph V) [--tire-scale S] --json
    lcv matrices (...) [--load UNITS --convention C] [--units thesis|si] --json
    lcv steady   (...) --load UNITS [--convention C] --json
    lcv simulate (...) --load UNITS [--t-end T] [--dt H] [--json]
    lcv measures (...) [--load UNITS] --json
    lcv fmu      (--preset NAME | --vehicle FILE) --out DIR [--kind python|native|both]
    lcv report   (--preset NAME | --vehicle FILE) [--speed-kph V] [--load UNITS] --out DIR
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

import argparse
import errno
import json
import math
import os
import sys
import time
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
                       metavar="V", help=f"forward speed [km/h], in {RANGES['speed'].text(1 / MPS_PER_KPH, 'km/h')}")
        g.add_argument("--speed-mph", type=_ranged("speed", 1 / MPS_PER_MPH, "mph", "forward speed in mph"),
                       metavar="V", help=f"forward speed [mph], in {RANGES['speed'].text(1 / MPS_PER_MPH, 'mph')}")

    def tires(sp: argparse.ArgumentParser) -> None:
        sp.add_argument("--tire-scale", default=1.0, type=_ranged("tire_scale", what="factor on the tire "
                        "coefficients"), metavar="S",
                        help=f"factor on every tire coefficient (chapter V), in {RANGES['tire_scale'].text()}; "
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
    sim = sub.add_parser("simulate", help="exact step response from rest, streamed as CSV (or JSON), SI units")
    common(sim, True)
    sim.add_argument("--t-end", default=10.0, type=_ranged("t_end", what="end time in s"), metavar="T",
                     help=f"end time [s], in {RANGES['t_end'].text()}; default 10")
    sim.add_argument("--dt", default=0.01, type=_ranged("output_step", what="output step in s"), metavar="H",
                     help=f"output step [s], in {RANGES['output_step'].text()}; must divide t-end; default 0.01")
    mea = sub.add_parser("measures", help="yaw-plane measures: damping, critical speed, RA, gains, trim (SPEC 8)")
    source(mea)
    speed(mea)
    tires(mea)
    load(mea, False, convention=False)
    mea.add_argument("--json", action="store_true", help="machine-readable output")
    fmu = sub.add_parser("fmu", help="FMI 2.0 co-simulation FMUs of the vehicle")
    source(fmu, masses=False)
    fmu.add_argument("--out", required=True, metavar="DIR", help="output folder")
    fmu.add_argument("--kind", default="both", choices=("python", "native", "both"),
                     help="python (pythonfmu), native (C99) or both (default)")
    speed(fmu, required=False)
    rep = sub.add_parser("report", help="assessment report of the vehicle (HTML and PDF)")
    source(rep, masses=False)
    speed(rep, required=False)
    load(rep, False, convention=False)
    rep.add_argument("--out", required=True, metavar="DIR", help="output folder")
    rep.add_argument("--no-pdf", action="store_true", help="HTML only")
    rep.add_argument("--paper", default="letter", choices=("letter", "a4"), help="paper of the PDF (default letter)")
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
        print(f"lcv: warning: {args.vehicle}: {line}", file=sys.stderr)
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
    from .analysis.geometry import rear_offsets
    from .analysis.response import iter_step_response
    from .model.builder import system_coefficients
    v = _vehicle(args)
    F = _load_vector(args, v)
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
    n = v.n_units
    u = _speed_mps(args)
    co = system_coefficients(v)
    Ca, Da = co.acceleration_maps(u, args.tire_scale)
    aF = Da @ F
    names = (["time_s", "v1_m_per_s"] + [f"r{i + 1}_rad_per_s" for i in range(n)] +
             [f"{nm}_rad" for nm in v.state_names[n + 1:]] + [f"y{k + 2}_m" for k in range(n - 1)] +
             [f"ay{i + 1}_m_per_s2" for i in range(n)])
    if args.json:
        out.write('{"columns": ' + json.dumps(names) + ', "rows": [')
    else:
        out.line(",".join(names))
    first = True
    for t, z in iter_step_response(v, u, F, args.dt, steps, args.tire_scale):
        x = z[:2 * n]
        row = np.concatenate([[t], x, rear_offsets(v, x[n + 1:]), Ca @ x + aF])
        _finite(row)
        if args.json:
            out.write(("" if first else ", ") + json.dumps([float(val) for val in row]))
        else:
            out.line(",".join(f"{val:.10g}" for val in row))
        first = False
    if args.json:
        out.line("]}")
    return 0


def _cmd_measures(args, out: _Out) -> int:
    from .analysis.measures import measure_set
    v = _vehicle(args)
    units = _load_units(args, v) if args.load is not None else None
    try:
        m = measure_set(v, _speed_mps(args), args.tire_scale, units)
    except ValueError as exc:
        if "static_load_N" in str(exc):
            raise UsageError(f"argument --load: {exc}") from None
        raise
    doc = m.to_dict()
    _finite(*(val for val in doc.values() if isinstance(val, (int, float, list))))
    if args.json:
        out.json(doc)
        return 0
    out.line(f"{v.name} at {_speed_text(args)} ({mps_to_kph(m.speed_mps):.1f} km/h), tire scale {args.tire_scale:g}")
    for row in m.rows():
        val = row["value"]
        text = val if isinstance(val, str) else f"{val:.6g}"
        out.line(f"  {row['measure']:42s} {text:>12s} {row['unit']:10s} {row['note']}")
    return 0


def _cmd_fmu(args, out: _Out) -> int:
    from .fmu.build import FmuBuildError, build_vehicle_fmus
    v = _vehicle(args)
    try:
        kw = {}
        if args.speed_kph is not None or args.speed_mph is not None:
            kw["u_start_mps"] = _speed_mps(args)      # the start value of the input u
        paths = build_vehicle_fmus(v, args.out, kind=args.kind, **kw)
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
    text = None
    if args.vehicle is not None:               # the user's file as written, comments and all
        from .model.vehicle_file import read_vehicle_text
        text = read_vehicle_text(args.vehicle)
    t0 = time.perf_counter()
    try:
        res = build_assessment(v, args.out, speed_mps=speed, load_units=units, pdf=not args.no_pdf,
                               progress=lambda text: print(f"lcv report: {text}", file=sys.stderr, flush=True),
                               source=args.vehicle or f"preset {args.preset}", vehicle_text=text, paper=args.paper)
    except OutputFolderError as exc:
        raise UsageError(f"argument {exc}") from None
    except ReportError as exc:
        raise OutputError(str(exc)) from None
    for key in ("html", "pdf", "data"):
        if key in res:
            out.line(f"wrote {res[key]}")
    print(f"lcv report: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    return 0


COMMANDS = {"presets": _cmd_presets, "eig": _cmd_eig, "matrices": _cmd_matrices, "steady": _cmd_steady,
            "simulate": _cmd_simulate, "measures": _cmd_measures, "fmu": _cmd_fmu, "report": _cmd_report}


def run(argv: Sequence[str] | None = None, out=None) -> int:
    """Run ``lcv`` with ``argv``; return the exit status.  Output goes to ``out`` (stdout)."""
    stream = out if out is not None else sys.stdout
    try:
        args = build_parser().parse_args(argv)
        writer = _Out(stream)
        status = COMMANDS[args.command](args, writer)
        stream.flush()
        return status
    except KeyboardInterrupt:
        print("lcv: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except UsageError as exc:
        print(f"lcv: error: {exc}", file=sys.stderr)
        return 2
    except (RangeError, KeyError) as exc:
        print(f"lcv: error: {exc.args[0] if exc.args else exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except OutputError as exc:
        print(f"lcv: error: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        if exc.errno == errno.EPIPE:
            _silence_stdout()
            return EXIT_BROKEN_PIPE
        print(f"lcv: error: cannot write the output: {exc.strerror or exc}", file=sys.stderr)
        _silence_stdout()
        return 1
    except FloatingPointError as exc:
        print(f"lcv: error: {exc}", file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - one line, never a traceback
        print(f"lcv: internal error: {type(exc).__name__}: {exc} (please report this)", file=sys.stderr)
        return 1


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
    sys.exit(run())


if __name__ == "__main__":
    main()
