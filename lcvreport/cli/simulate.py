"""``lcv simulate``: the exact response to a step of the residual loads or to a steer input."""
from __future__ import annotations

import json
import math

import numpy as np

from ..model.base import LINEAR_MODELS, MODELS, check_model
from ..model.linear import linear_model
from ..ranges import RANGES, RangeError
from .options import (Command, UsageError, add_common, add_residuals, help_range, model_choices, one_line,
                      one_percent_vector_of, ranged, sources_of, speed_mps_of, vehicle_of)
from .output import check_finite, Output


def cmd_simulate(args, out: Output) -> int:
    from ..analysis.exact import ManoeuvreError, check_lane_change_steer, final_state, response
    from ..manoeuvres.steer import SteerError, parse_steer, step
    v = vehicle_of(args)
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
    model = check_model(args.model, MODELS)
    if model == "yaw_roll":
        from .roll import roll_vehicle
        roll_vehicle(args)                      # the roll keys, checked: one line naming what is missing
    if model not in LINEAR_MODELS:                # integrated: the nonlinear model, or any model MODELS names
        return _simulate_integrated(args, out, v, steer, steps, model)
    if args.tire is not None or args.friction_coefficient is not None:
        raise UsageError("arguments --tire/--friction-coefficient: the nonlinear model's (--model nonlinear)")
    axle_force = np.zeros(len(v.axles))
    if args.load is not None:
        F, axle_force = one_percent_vector_of(args, v, model=model)
    else:
        F = np.zeros(linear_model(v, model).n_states)
    try:
        src = sources_of(args, v)
        F = F + src.vector(v, args.tire_scale, model)
        axle_force = axle_force + src.axle_forces(v, args.tire_scale)
    except (KeyError, RangeError) as exc:
        raise UsageError(f"argument: {exc.args[0]}") from None
    u = speed_mps_of(args)
    chunk = 20000                                  # rows per exact run: constant memory
    first = True
    state, k = None, 0
    while k < steps:
        n = min(chunk, steps - k)
        t_b = (k + n) * args.dt
        try:
            r = response(v, u, steer, t_b, args.dt, F, args.tire_scale, t_start=k * args.dt, state=state,
                         model=model, axle_force_N=axle_force)
            check_lane_change_steer(r)      # a computed steer beyond [-1, 1] rad: refused before a row is written
        except ManoeuvreError as exc:
            raise UsageError(f"argument --steer: {exc}") from None
        M = r.matrix()
        check_finite(M)
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


def _simulate_integrated(args, out: Output, v, steer, steps: int, model: str) -> int:
    """``lcv simulate --model nonlinear`` (or any model of MODELS that is not linear): the model
    integrated (docs/nonlinear.md), the columns of its outputs; a lane change of the inverse system
    is a linear model's (refused)."""
    from ..analysis.integrate import IntegrationError, integrate
    from ..model.base import build_model
    from ..model.vehicle import VehicleError
    if args.load is not None:
        raise UsageError("argument --load: the 1 %% rule is a linear model's load case; give --residual AXLE=P,T")
    try:
        options = {"tire": args.tire or "saturating",
                   "friction_coefficient": 0.8 if args.friction_coefficient is None else args.friction_coefficient} \
            if model == "nonlinear" else {k: val for k, val in (("tire", args.tire),
                                                                ("friction_coefficient", args.friction_coefficient))
                                          if val is not None}
        m = build_model(v, model, **options)
    except (VehicleError, ValueError, TypeError) as exc:
        raise UsageError(f"argument --model {args.model}: {one_line(exc)}") from None
    try:
        src = sources_of(args, v)
        src.vector(v, args.tire_scale)                    # each source checked against the vehicle
    except (KeyError, RangeError) as exc:
        raise UsageError(f"argument: {exc.args[0]}") from None
    try:
        r = integrate(m, steer, speed_mps_of(args), steps * args.dt, args.dt, args.tire_scale,
                      sources=src if src else None)
    except IntegrationError as exc:
        raise UsageError(f"argument --steer: {one_line(exc)}") from None
    M = r.matrix() + 0.0                                  # no -0 printed
    check_finite(M)
    names = r.columns()
    if args.json:
        out.write('{"columns": ' + json.dumps(names) + ', "rows": [')
        out.write(", ".join(json.dumps(row) for row in M.tolist()))
        out.line("]}")
        return 0
    out.line(",".join(names))
    row_format = ",".join(["%.10g"] * M.shape[1]) + "\n"
    out.write("".join([row_format % tuple(row) for row in M.tolist()]))
    return 0


def simulate_options(sp) -> None:
    add_common(sp, False)
    add_residuals(sp)
    sp.add_argument("--steer", metavar="SPEC", default=None,
                    help="steer input: step:A, sine:A:F, pulse:A:D, csv:FILE, lane-change:A0:F (A0 in m/s^2 or "
                         "with g, e.g. 0.15g), driver:A0:F[:K:T] (that path driven in closed loop by a preview "
                         "driver, gain K rad/m, preview T s); default none")
    sp.add_argument("--t-end", default=10.0, type=ranged("t_end", what="end time in s"), metavar="T",
                    help=f"end time [s], in {help_range('t_end')}; default 10")
    sp.add_argument("--tire", choices=("saturating", "linear"), default=None,
                    help="the nonlinear model's tire law (default saturating: the brush tire)")
    sp.add_argument("--friction-coefficient", type=ranged("friction", what="friction coefficient mu"),
                    metavar="MU", default=None, help="the nonlinear model's mu, in (0, 2]; default 0.8")
    sp.add_argument("--model", default="yaw-plane", choices=model_choices(MODELS),
                    help="the model: yaw-plane (default), yaw-roll (adds roll rates, roll angles, sprung CG "
                         "accelerations, axle load transfers and load transfer ratios; needs the roll keys) or "
                         "nonlinear (docs/nonlinear.md)")
    sp.add_argument("--dt", default=0.01, type=ranged("output_step", what="output step in s"), metavar="H",
                    help=f"output step [s], in {help_range('output_step')}; must divide t-end; default 0.01")


COMMANDS = {"simulate": Command("exact response from rest to a steer input and residual sources, streamed as CSV "
                                "(or JSON), SI units", simulate_options, cmd_simulate)}
