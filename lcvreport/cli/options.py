"""The options the commands share and their parsing: the vehicle (a preset or a file), the
speed, the load case, the residual sources; the one-line messages of a bad argument.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..ranges import RANGES
from ..units import MPS_PER_KPH, MPS_PER_MPH, SI


class UsageError(Exception):
    """A bad command-line argument; the message names it and what is valid (exit 2)."""


def _number(text: str, what: str) -> float:
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number ({what}), got {text!r}") from None


def ranged(key: str, factor: float = 1.0, unit: str | None = None, what: str = ""):
    r = RANGES[key]

    def conv(text: str) -> float:
        value = _number(text, what or r.description)
        if not r.contains(value / factor):
            raise argparse.ArgumentTypeError(f"must be in {r.text(factor, unit)} ({what or r.description}), "
                                             f"got {text}")
        return value
    return conv


def help_range(key: str, factor: float = 1.0, unit: str | None = None) -> str:
    """The valid range of ``key`` for a help text (argparse formats help with %: a unit of % is doubled)."""
    return RANGES[key].text(factor, unit).replace("%", "%%")


# ---------------------------------------------------------------------------- inputs
def vehicle_of(args: argparse.Namespace):
    from ..model.presets import PRESETS, load_preset
    from ..model.vehicle import VehicleError
    from ..model.vehicle_file import load_vehicle
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
    from ..model.plausibility import plausibility_warnings
    for line in plausibility_warnings(v):
        print(f"lcv: warning: {one_line(args.vehicle)}: {one_line(line)}", file=sys.stderr)
    return v


def plot_path_of(args: argparse.Namespace):
    """The new figure file of ``--plot`` (None without it): .png, .pdf or .svg, not an existing
    file, in an existing folder."""
    from pathlib import Path
    if args.plot is None:
        return None
    plot = Path(args.plot)
    if plot.suffix.lower() not in (".png", ".pdf", ".svg"):
        raise UsageError(f"argument --plot: {plot} must end in .png, .pdf or .svg")
    if plot.exists() or plot.is_symlink():
        raise UsageError(f"argument --plot: {plot} exists; name a new file (lcv never overwrites one)")
    if not plot.parent.is_dir():
        raise UsageError(f"argument --plot: the folder {plot.parent} does not exist")
    return plot


def speed_mps_of(args: argparse.Namespace) -> float:
    if getattr(args, "speed_kph", None) is not None:
        return args.speed_kph * MPS_PER_KPH
    return args.speed_mph * MPS_PER_MPH


def speed_text(args: argparse.Namespace) -> str:
    if getattr(args, "speed_kph", None) is not None:
        return f"{args.speed_kph:g} km/h"
    return f"{args.speed_mph:g} mph"


def load_units_of(args: argparse.Namespace, vehicle) -> list[str]:
    from ..model.yaw_plane.loads import check_unit_names
    names = [s.strip() for s in args.load.split(",")]
    valid = ",".join(vehicle.unit_names)
    if not names or any(not n for n in names):
        raise UsageError(f"argument --load: expected a comma list of units from {valid}, got {args.load!r}")
    try:
        return check_unit_names(vehicle, names)
    except KeyError as exc:
        raise UsageError(f"argument --load: {exc.args[0]}") from None


def load_vector_of(args: argparse.Namespace, vehicle, units=SI, model: str = "yaw_plane") -> np.ndarray:
    return one_percent_vector_of(args, vehicle, units, model)[0]


def one_percent_vector_of(args: argparse.Namespace, vehicle, units=SI, model: str = "yaw_plane"):
    """(F, P per axle [N]) of the 1 % rule on ``--load``."""
    from ..model.yaw_plane.loads import load_vector, one_percent_rule
    names = load_units_of(args, vehicle)
    try:
        res = one_percent_rule(vehicle, names, t_sign=1.0)
    except ValueError as exc:
        raise UsageError(f"argument --load: {exc}") from None
    return load_vector(vehicle, res, args.convention, units, model), res.vectors(vehicle)[0]


def source_force_of(args: argparse.Namespace, vehicle):
    """The generalized force [SI] of the residual sources of the options (None if none)."""
    src = sources_of(args, vehicle)
    return src.vector(vehicle, args.tire_scale) if src else None


def sources_of(args: argparse.Namespace, vehicle):
    """The residual sources of ``--residual``, ``--misalignment``, ``--crossfall-percent``."""
    from ..model.yaw_plane.loads import ResidualLoads, ResidualSources
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
        from ..tracking.tires import TrackingError, axle_residuals, read_mounted_tires
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


def parse_speeds(args: argparse.Namespace) -> tuple[list[float], str]:
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


#: the longest message line [characters]: a message quoting a user's file (ten thousand levels, a
#: list of paths) is cut, never a screenful
MESSAGE_CHARS = 600


def one_line(text) -> str:
    """``text`` as one short line of plain text: every character that is not printable (a newline,
    an ESC that would drive the terminal) escaped, so a message quoting a user's file is one line;
    at most :data:`MESSAGE_CHARS` characters (the cut marked and counted).

    Examples
    --------
    >>> one_line("a\\nb"), len(one_line("x" * 10_000)) <= MESSAGE_CHARS
    ('a\\\\nb', True)
    """
    line = "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in str(text))
    if len(line) <= MESSAGE_CHARS:
        return line
    kept = MESSAGE_CHARS - 40                       # room for the mark, whatever the count
    return line[:kept] + f" ... ({len(line) - kept} characters more)"


# ---------------------------------------------------------------------------- the parser
class Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line (:class:`UsageError`, exit 2), no usage dump."""

    def error(self, message: str) -> None:
        raise UsageError(message)


@dataclass(frozen=True)
class Command:
    """One ``lcv`` command: its help line, what adds its options to its parser, what runs it
    (``run(args, out) -> exit status``).  Each command module lists its own in ``COMMANDS``."""

    help: str
    options: Callable[[argparse.ArgumentParser], None]
    run: Callable


def add_source(sp: argparse.ArgumentParser, masses: bool = True) -> None:
    """``--preset NAME | --vehicle FILE`` (and a preset's ``--masses``)."""
    from ..model.presets import MASS_OPTIONS, PRESETS
    g = sp.add_mutually_exclusive_group(required=True)
    g.add_argument("--preset", metavar="NAME", help=f"vehicle preset: {', '.join(PRESETS)}")
    g.add_argument("--vehicle", metavar="FILE", help="vehicle file (TOML, SI; see the README)")
    if masses:
        sp.add_argument("--masses", default="table", choices=MASS_OPTIONS,
                        help="presets: table (printed, rounded) or unrounded (implied by the published "
                             "matrices; aucnat and tractor_semitrailer)")


def add_speed(sp: argparse.ArgumentParser, required: bool = True) -> None:
    """``--speed-kph V | --speed-mph V``, checked against the speed range."""
    g = sp.add_mutually_exclusive_group(required=required)
    g.add_argument("--speed-kph", type=ranged("speed", 1 / MPS_PER_KPH, "km/h", "forward speed in km/h"),
                   metavar="V", help=f"forward speed [km/h], in {help_range('speed', 1 / MPS_PER_KPH, 'km/h')}")
    g.add_argument("--speed-mph", type=ranged("speed", 1 / MPS_PER_MPH, "mph", "forward speed in mph"),
                   metavar="V", help=f"forward speed [mph], in {help_range('speed', 1 / MPS_PER_MPH, 'mph')}")


def add_tire_scale(sp: argparse.ArgumentParser) -> None:
    """``--tire-scale S``."""
    sp.add_argument("--tire-scale", default=1.0, type=ranged("tire_scale", what="factor on the tire coefficients"),
                    metavar="S", help=f"factor on every tire coefficient (chapter V), in {help_range('tire_scale')}; "
                                      "default 1")


def add_load(sp: argparse.ArgumentParser, required: bool, convention: bool = True) -> None:
    """``--load UNITS`` (the 1 % rule) and its ``--convention``."""
    from ..model.yaw_plane.loads import CONVENTIONS
    sp.add_argument("--load", required=required, metavar="UNITS",
                    help="comma list of units carrying the 1 %% rule (unit names of the vehicle)")
    if convention:
        sp.add_argument("--convention", default="consistent", choices=CONVENTIONS,
                        help="load-vector convention (default consistent)")


def add_common(sp: argparse.ArgumentParser, load_required: bool | None) -> None:
    """The vehicle, the speed, the tire scale, ``--load`` (unless None) and ``--json``."""
    add_source(sp)
    add_speed(sp)
    add_tire_scale(sp)
    if load_required is not None:
        add_load(sp, load_required)
    sp.add_argument("--json", action="store_true", help="machine-readable output")


def add_residuals(sp: argparse.ArgumentParser) -> None:
    """The residual sources: ``--residual``, ``--misalignment``, ``--crossfall-percent``, ``--tires``."""
    sp.add_argument("--residual", action="append", default=[], metavar="AXLE=P,T",
                    help="residual force P [N] (+y) and moment T [N*m] (+z) on an axle; repeatable")
    sp.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                    help=f"thrust angle of an axle [rad], nose-right positive, in "
                         f"{help_range('misalignment')}; repeatable or comma-separated")
    sp.add_argument("--crossfall-percent", type=ranged("crossfall", what="road crossfall in %"), metavar="C",
                    help=f"road crossfall [%%], positive falling toward +y, in {help_range('crossfall')}")
    sp.add_argument("--tires", metavar="FILE", help="mounted tires (CSV or TOML: position, conicity_N, "
                                                     "ply_steer_N, serial_side[, moments]): their axle P and T")


def add_conditions(sp: argparse.ArgumentParser) -> None:
    """One option per condition of the registry (but the speed and the crossfall)."""
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


def model_choices(models) -> tuple[str, ...]:
    """The command line's spelling (``yaw-plane``) of the models ``models`` (keys of
    :data:`lcvreport.model.base.MODELS`): what ``--model`` offers, from the registry of models."""
    return tuple(m.replace("_", "-") for m in models)         # a model registered after import too


# ---------------------------------------------------------------------------- the case
def case_of(args: argparse.Namespace, vehicle=None, speed: bool = True):
    """The :class:`~lcvreport.measures.case.Case` of the options, built once: the vehicle (given,
    or ``--preset``/``--vehicle``), the speed (unless ``speed`` is False: a sweep, an assessment),
    ``--tire-scale``, ``--model``, the registry's condition options, ``--load``, the residual
    sources and the model's ``--tire``.  A value the case refuses: one line naming the option (exit 2)."""
    from ..measures.case import Case
    from ..measures.registry import CONDITIONS
    from ..model.base import ModelError
    from ..ranges import RangeError
    v = vehicle if vehicle is not None else vehicle_of(args)
    given = getattr(args, "speed_kph", None) is not None or getattr(args, "speed_mph", None) is not None
    units = load_units_of(args, v) if getattr(args, "load", None) is not None else ()
    sources = sources_of(args, v)
    conditions = {k: getattr(args, k) for k in CONDITIONS
                  if k not in ("speed_kph", "crossfall_percent") and getattr(args, k, None) is not None}
    options = {"tire": args.tire} if getattr(args, "tire", None) is not None else {}
    model = getattr(args, "model", None) or "yaw-plane"
    try:
        return Case(v, speed_mps_of(args) if speed and given else None, getattr(args, "tire_scale", 1.0), model,
                    conditions, units, sources if sources else None, options)
    except ModelError as exc:
        raise UsageError(f"argument --model: {exc}") from None
    except (KeyError, RangeError, ValueError) as exc:
        raise UsageError(f"argument: {exc.args[0] if exc.args else exc}") from None
