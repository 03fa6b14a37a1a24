"""``lcv tracking place`` and ``lcv tracking stats``: tire placement and the fleet statistics."""
from __future__ import annotations

import math

from .options import (Command, Parser, UsageError, add_source, add_speed, add_tire_scale, case_of, help_range,
                      ranged, speed_text, vehicle_of)
from .output import Output


def _trimmed_vehicle(args):
    """The vehicle of the options; it needs a steered axle (the trim's)."""
    v = vehicle_of(args)
    if not v.steered_axles:
        raise UsageError(f"argument --vehicle: {v.name} has no steered axle: the trim needs one")
    return v


def _json_or_heading(out: Output, args, result, vehicle, heading: str) -> bool:
    """``result.to_dict()`` as the JSON of ``--json`` (True: done), else the text's first line."""
    if args.json:
        out.json(result.to_dict())
        return True
    out.line(f"{vehicle.name} at {speed_text(args)}: {heading}")
    return False


def _cmd_place(args, out: Output) -> int:
    from ..tracking.placement import place_tires, read_measured_tires
    from ..tracking.tires import TrackingError
    v = _trimmed_vehicle(args)
    if not 1 <= args.draws <= 1_000_000:
        raise UsageError(f"argument --draws: must be in [1, 1e6], got {args.draws}")
    if not 0 <= args.seed < 2 ** 63:
        raise UsageError(f"argument --seed: must be in [0, 2^63), got {args.seed}")
    try:
        tires = read_measured_tires(args.measured_tires)
    except TrackingError as exc:
        raise UsageError(f"argument --tires: {exc}") from None
    positions = [p.strip() for p in args.positions.split(",")] if args.positions else None
    case = case_of(args, v)
    F = case.force()
    try:
        pl = place_tires(v, case.speed_mps, tires, positions, F, case.tire_scale, args.draws, args.seed)
    except TrackingError as exc:
        opt = "--positions" if str(exc).startswith("position") else "--tires"
        raise UsageError(f"argument {opt}: {exc}") from None
    if _json_or_heading(out, args, pl, v, f"mounting plan of {len(tires)} tires with the least |trimmed "
                                          "offtracking| (then |trim steer|)"):
        return 0
    out.line(f"  {'position':<18} {'tire':<14} serial side")
    for row in pl.plan:
        out.line(f"  {row['position']:<18} {row['tire']:<14} {row['serial_side']}")
    r = pl.to_dict()["random_placements"]
    out.line(f"  offtracking [m]   plan {pl.offtracking_m: .6g} (least possible >= {pl.lower_bound_m:.3g}; "
             f"trim steer {pl.trim_delta_rad:.6g} rad)")
    out.line(f"                    as listed, serial side out {pl.as_listed_offtracking_m: .6g} "
             f"(trim steer {pl.as_listed_trim_delta_rad:.6g} rad)")
    out.line(f"                    random placements: mean {r['mean']: .6g}  sd {r['sd']:.6g}  best |.| "
             f"{r['best_abs']:.6g}  ({r['draws']} draws, seed {r['seed']})")
    return 0


def cmd_tracking(args, out: Output) -> int:
    if args.tracking_command == "place":
        return _cmd_place(args, out)
    from ..tracking.statistics import ZERO, parse_distribution, tracking_stats
    from ..tracking.tires import TrackingError
    v = _trimmed_vehicle(args)
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
    case = case_of(args, v)
    F = case.force()
    try:
        s = tracking_stats(v, case.speed_mps, dists["conicity"], dists["ply_steer"], args.mounting,
                           dists["conicity_moment"], dists["ply_steer_moment"], axles, args.lane_width_m,
                           args.body_width_m, args.draws, args.seed, F, case.tire_scale)
    except TrackingError as exc:
        opt = " --axles" if "axle" in str(exc).split(";")[0] and args.axles else ""
        raise UsageError(f"argument{opt}: {exc}") from None
    if _json_or_heading(out, args, s, v, f"trimmed offtracking over the tire population (seed {s.seed}, "
                                        f"{s.draws} draws)"):
        return 0
    out.line(f"  offtracking [m]      mean {s.offtracking_mean_m: .6g}  sd {s.offtracking_sd_m:.6g}  (exact)")
    out.line(f"  trim steer [rad]     mean {s.trim_delta_mean_rad: .6g}  sd {s.trim_delta_sd_rad:.6g}  (exact)")
    out.line("  quantiles [m]        " + "  ".join(f"{q:g}: {val:.6g}" for q, val in s.quantiles_m.items()))
    lo, hi = s.exceedance_ci95
    out.line(f"  P(|offtracking| > {s.margin_m:.4g} m) = {s.exceedance_probability:.6g}  (95 % CI {lo:.3g} .. "
             f"{hi:.3g}, Monte Carlo)")
    return 0


# ---------------------------------------------------------------------------- options
def tracking_options(trk) -> None:
    tsub = trk.add_subparsers(dest="tracking_command", metavar="WHAT", parser_class=Parser)
    tsub.required = True
    st = tsub.add_parser("stats", help="offtracking over a tire population: exact mean and SD, Monte Carlo lane "
                                       "exceedance")
    add_source(st, masses=False)
    add_speed(st)
    add_tire_scale(st)
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
    _road(st)
    st.add_argument("--json", action="store_true", help="machine-readable output")
    pl = tsub.add_parser("place", help="mounting plan of measured tires with the least trimmed offtracking "
                                       "(exact, a mixed-integer program)")
    add_source(pl, masses=False)
    add_speed(pl)
    add_tire_scale(pl)
    pl.add_argument("--tires", dest="measured_tires", required=True, metavar="TIRES.csv",
                    help="measured tires: CSV id,conicity_N,ply_steer_N[,conicity_moment_Nm,ply_steer_moment_Nm]")
    pl.add_argument("--positions", metavar="POS,POS,...",
                    help="positions to fill, axle:slot (default: every tire position of units 2..N)")
    _road(pl)
    pl.add_argument("--draws", type=int, default=10_000, metavar="N", help="random placements to compare (1e4)")
    pl.add_argument("--seed", type=int, default=20110801, metavar="S", help="seed of the random placements")
    pl.add_argument("--json", action="store_true", help="machine-readable output")


def _road(sp) -> None:
    sp.add_argument("--crossfall-percent", type=ranged("crossfall", what="road crossfall in %"), metavar="C",
                    help=f"road crossfall [%%], in {help_range('crossfall')}")
    sp.add_argument("--misalignment", action="append", default=[], metavar="AXLE=RAD",
                    help="thrust angle of an axle [rad]; repeatable or comma-separated")


COMMANDS = {"tracking": Command("straight-line tracking: per-tire conicity and ply steer", tracking_options,
                                cmd_tracking)}
