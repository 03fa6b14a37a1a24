"""``lcv tracking place`` and ``lcv tracking stats``: tire placement and the fleet statistics."""
from __future__ import annotations

import math

from .options import UsageError, source_force_of, speed_mps_of, speed_text, vehicle_of
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
    F = source_force_of(args, v)
    try:
        pl = place_tires(v, speed_mps_of(args), tires, positions, F, args.tire_scale, args.draws, args.seed)
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
    F = source_force_of(args, v)
    try:
        s = tracking_stats(v, speed_mps_of(args), dists["conicity"], dists["ply_steer"], args.mounting,
                           dists["conicity_moment"], dists["ply_steer_moment"], axles, args.lane_width_m,
                           args.body_width_m, args.draws, args.seed, F, args.tire_scale)
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
