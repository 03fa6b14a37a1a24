"""The ``lcv`` command: eigenvalues, matrices, steady state and time response.

Fixed contract (other parts and outside checks call these forms)::

    lcv eig      --preset NAME --speed-mph V [--tire-scale S] --json
    lcv matrices --preset NAME --speed-mph V [--tire-scale S] [--load UNITS --convention C] --json
    lcv steady   --preset NAME --speed-mph V [--tire-scale S] --load UNITS [--convention C] --json

``UNITS`` is a comma list of ``trailer1,dolly1,trailer2,dolly2,trailer3`` (``tractor``
is accepted too); each gets the 1 % rule on its axles, P along +y and T about +z.
``--convention`` is ``consistent`` (default) or ``thesis``.  JSON units: eigenvalues
[1/s]; matrices in thesis units (lbf, in, s); steady state in SI (m/s, rad/s, rad, m).
Bad arguments exit with status 2 and one line naming the argument and what is valid.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Sequence

import numpy as np

from . import linear, loads, model, presets
from .units import in_to_m, mph_to_in_per_s


class UsageError(Exception):
    """A bad command-line argument; the message names it and what is valid."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump
        raise UsageError(message)


def _finite_positive(what: str):
    def conv(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be a number > 0 ({what}), got {text!r}") from None
        if not math.isfinite(value) or value <= 0:
            raise argparse.ArgumentTypeError(f"must be a finite number > 0 ({what}), got {text!r}")
        return value
    return conv


def _preset(text: str) -> str:
    if text not in presets.PRESETS:
        raise argparse.ArgumentTypeError(f"unknown preset {text!r}; valid: {', '.join(presets.PRESETS)}")
    return text


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``lcv``."""
    p = _Parser(prog="lcv", description="Linear yaw-plane model of long combination vehicles (Patterson 2011).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True

    def common(sp: argparse.ArgumentParser, load_required: bool | None) -> None:
        sp.add_argument("--preset", required=True, type=_preset, metavar="NAME",
                        help=f"vehicle preset: {', '.join(presets.PRESETS)}")
        sp.add_argument("--speed-mph", required=True, type=_finite_positive("forward speed in mph"), metavar="V",
                        help="forward speed [mph], > 0")
        sp.add_argument("--tire-scale", default=1.0, type=_finite_positive("factor on the tire coefficients"), metavar="S",
                        help="factor on every tire coefficient (chapter V), > 0; default 1")
        sp.add_argument("--masses", default="table", choices=presets.MASS_OPTIONS,
                        help="table (printed, rounded) or unrounded (implied by the published matrices)")
        if load_required is not None:
            sp.add_argument("--load", required=load_required, metavar="UNITS",
                            help="comma list of units carrying the 1 %% rule: " + ",".join(loads.LOADABLE_UNITS[1:]))
            sp.add_argument("--convention", default="consistent", choices=loads.CONVENTIONS,
                            help="load-vector convention (default consistent)")
        sp.add_argument("--json", action="store_true", help="machine-readable output")

    common(sub.add_parser("eig", help="eigenvalues [1/s], damped frequency, damping ratio"), None)
    common(sub.add_parser("matrices", help="M, S (and F with --load) in thesis units"), False)
    common(sub.add_parser("steady", help="steady state under the 1 %% rule loads, SI units"), True)
    sim = sub.add_parser("simulate", help="exact step response from rest; CSV in SI units")
    common(sim, True)
    sim.add_argument("--t-end", default=10.0, type=_finite_positive("end time in s"), metavar="T",
                     help="end time [s], default 10")
    sim.add_argument("--dt", default=0.01, type=_finite_positive("output step in s"), metavar="H",
                     help="output step [s], default 0.01")
    sub.add_parser("presets", help="list the presets").add_argument("--json", action="store_true")
    return p


def _train_and_speed(args: argparse.Namespace):
    try:
        train = presets.load_preset(args.preset, masses=args.masses)
    except ValueError as exc:
        raise UsageError(f"--masses: {exc}") from None
    return train, mph_to_in_per_s(args.speed_mph)


def _load_vector(args: argparse.Namespace, train) -> np.ndarray:
    names = [s.strip() for s in args.load.split(",")]
    valid = [u.name for u in train.units]
    if not names or any(not n for n in names):
        raise UsageError(f"--load: expected a comma list of units from {','.join(valid)}, got {args.load!r}")
    for n in names:
        if n not in valid:
            raise UsageError(f"--load: unknown unit {n!r} for preset {train.name}; valid: {','.join(valid)}")
    res = loads.one_percent_rule(train, names, t_sign=1.0)
    return loads.load_vector(train, res, args.convention)


def run(argv: Sequence[str] | None = None, out=None) -> int:
    """Run ``lcv`` with ``argv``; return the exit status. Output goes to ``out`` (stdout)."""
    out = out or sys.stdout
    try:
        args = build_parser().parse_args(argv)
        return _dispatch(args, out)
    except UsageError as exc:
        print(f"lcv: error: {exc}", file=sys.stderr)
        return 2


def _dispatch(args: argparse.Namespace, out) -> int:
    if args.command == "presets":
        if args.json:
            json.dump({"presets": list(presets.PRESETS)}, out)
            out.write("\n")
        else:
            for name in presets.PRESETS:
                print(f"{name:22s} {presets.PRESET_LABELS[name]}", file=out)
        return 0
    train, u = _train_and_speed(args)
    if args.command == "eig":
        m = linear.modes(train, u, args.tire_scale)
        if args.json:
            json.dump({"eigenvalues": [[float(l.real), float(l.imag)] for l in m.eigenvalues]}, out)
            out.write("\n")
        else:
            print(f"{train.name} at {args.speed_mph:g} mph, tire scale {args.tire_scale:g}"
                  f" ({'stable' if m.stable else 'UNSTABLE'})", file=out)
            print(f"{'mode':>4} {'Re [1/s]':>10} {'Im [1/s]':>10} {'f_d [Hz]':>9} {'zeta [-]':>9}", file=out)
            for row in m.table():
                print(f"{row['mode']:>4} {row['real_per_s']:>10.4f} {row['imag_per_s']:>10.4f} "
                      f"{row['damped_frequency_hz']:>9.4f} {row['damping_ratio']:>9.4f}", file=out)
        return 0
    if args.command == "matrices":
        M, S = model.system_matrices(train, u, args.tire_scale)
        F = _load_vector(args, train) if args.load is not None else None
        if args.json:
            doc = {"state": list(train.state_names), "M": M.tolist(), "S": S.tolist()}
            if F is not None:
                doc["F"] = F.tolist()
            json.dump(doc, out)
            out.write("\n")
        else:
            np.set_printoptions(linewidth=200)
            print(f"state = {list(train.state_names)}  (thesis units: lbf, in, s)", file=out)
            print("M =", file=out)
            print(np.array2string(M, precision=6, max_line_width=200), file=out)
            print("S =", file=out)
            print(np.array2string(S, precision=6, max_line_width=200), file=out)
            if F is not None:
                print(f"F ({args.convention} convention) =", file=out)
                print(np.array2string(F, precision=4, max_line_width=200), file=out)
        return 0
    F = _load_vector(args, train)
    if args.command == "steady":
        x = linear.steady_state(train, u, F, args.tire_scale)
        n = train.n_units
        state = {}
        for name, value in zip(train.state_names, x):
            state[name] = in_to_m(float(value)) if name == "v1" else float(value)
        y = linear.rear_displacements(train, x[n + 1:])
        ydoc = {f"y{k + 2}": in_to_m(float(v)) for k, v in enumerate(y)}
        if args.json:
            json.dump({"state": state, "y": ydoc}, out)
            out.write("\n")
        else:
            print(f"steady state, {train.name} at {args.speed_mph:g} mph, load on {args.load} "
                  f"({args.convention} convention)", file=out)
            for name, value in state.items():
                unit = "m/s" if name == "v1" else "rad/s" if name.startswith("r") else "rad"
                extra = f"  ({np.degrees(value):.4f} deg)" if name.startswith("theta") else ""
                print(f"  {name:7s} {value: .6e} {unit}{extra}", file=out)
            for name, value in ydoc.items():
                print(f"  {name:7s} {value: .6e} m  ({value / 0.0254:.3f} in)", file=out)
        return 0
    if args.command == "simulate":
        n_pts = int(round(args.t_end / args.dt)) + 1
        r = linear.step_response(train, u, F, args.t_end, n_pts, args.tire_scale)
        n = train.n_units
        cols = ["time_s", "v1_m_per_s"] + [f"r{i + 1}_rad_per_s" for i in range(n)] + \
               [f"{nm}_rad" for nm in train.state_names[n + 1:]] + [f"y{k + 2}_m" for k in range(n - 1)]
        print(",".join(cols), file=out)
        ys = in_to_m(r.rear_displacements)
        for k in range(r.time.size):
            row = [r.time[k], in_to_m(r.states[k, 0])] + list(r.states[k, 1:2 * n]) + list(ys[k])
            print(",".join(f"{v:.10g}" for v in row), file=out)
        return 0
    raise UsageError(f"unknown command {args.command!r}")  # pragma: no cover


def main() -> None:
    """Console entry point."""
    sys.exit(run())


if __name__ == "__main__":
    main()
