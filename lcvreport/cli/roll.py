"""``lcv roll``: the static rollover threshold of every roll-coupled group, roll gains, load
transfer ratios and the roll modes (docs/roll.md#cli)."""
from __future__ import annotations

import sys

from .options import Command, UsageError, add_common, case_of, one_line, plot_path_of, vehicle_of
from .output import Output, write_figure_new


def roll_vehicle(args):
    """The vehicle of the options, its roll data checked (a missing or invalid key: one line, exit 2;
    static loads that disagree with the masses: one warning line)."""
    from ..model.vehicle import VehicleError
    from ..model.yaw_roll.parameters import roll_parameters
    v = vehicle_of(args)
    try:
        rp = roll_parameters(v)
    except VehicleError as exc:
        where = f"--vehicle {args.vehicle}" if args.vehicle else f"--preset {args.preset}"
        raise UsageError(f"argument {where}: {exc}") from None
    if rp.load_warning:
        print(f"lcv: {one_line(rp.load_warning)}", file=sys.stderr)
    return v


def cmd_roll(args, out: Output) -> int:
    from ..measures.roll import roll_summary, unstable_at_rest_note
    case = case_of(args, roll_vehicle(args))
    v = case.vehicle
    plot = plot_path_of(args)
    s = roll_summary(v, case.speed_mps, case.tire_scale)
    if plot is not None:
        write_figure_new(s.plot(), plot)
    if args.json:
        out.json(s.to_dict())
        return 0
    doc = s.to_dict()
    fmt = lambda x, spec=".3f": "none" if x is None else format(x, spec)  # noqa: E731
    out.line(f"{v.name}: roll at {s.speed_mps * 3.6:.1f} km/h, tire scale {args.tire_scale:g} (docs/roll.md)")
    for k, g in enumerate(doc["groups"], 1):
        out.line(f"  group {k} ({', '.join(g['units'])}): static rollover threshold {g['srt_g']:.3f} g")
        for axle, a in g["lift_off_g"].items():
            out.line(f"    lift-off {axle:<14} {'does not lift before SRT' if a is None else f'{a:.3f} g'}")
    out.line(f"  SRT, weakest group {doc['srt_min_g']:.3f} g; rearmost roll-coupled unit {doc['srt_rrcu_g']:.3f} g")
    note = unstable_at_rest_note(s.threshold)
    if note:
        out.line(f"  {note}")
    if doc["roll_gain_deg_per_g"] is None:
        out.line(f"  roll gains not computed: {one_line(doc['reasons'].get('roll_gain_deg_per_g', ''))}")
    for name, gain in (doc["roll_gain_deg_per_g"] or {}).items():
        out.line(f"  roll gain, {name:<16} {fmt(gain, '.3f'):>8} deg/g")
    for key, label in (("ltr_lane_change", "LTR, lane change 0.15 g 0.4 Hz"),
                       ("ltr_single_sine", "LTR, single sine 0.4 Hz, 0.15 g")):
        values = doc[key]
        text = ", ".join(f"{x:.3f}" for x in values) if values is not None else \
            f"not computed: {one_line(doc['reasons'].get(key, ''))}"
        out.line(f"  {label:<34} {text}  (per group, front to rear)")
    out.line(f"  roll-model least damping ratio     {fmt(doc['roll_least_damping_ratio'], '.4f')}")
    crit = doc["roll_critical_speed_kph"]
    out.line(f"  roll-model critical speed          {'stable to 200 km/h' if crit is None else f'{crit:.1f} km/h'}")
    if plot is not None:
        out.line(f"wrote {plot}")
    return 0


def roll_options(sp) -> None:
    add_common(sp, None)
    sp.add_argument("--plot", metavar="FILE", help="write the a_y - phi curve of every group, each lift-off marked "
                                                   "(.png, .pdf or .svg; a new file)")


COMMANDS = {"roll": Command("roll: static rollover threshold per roll-coupled group (lift-off axle by axle), roll "
                            "gains, load transfer ratios, roll modes (docs/roll.md)", roll_options, cmd_roll)}
