"""``lcv turn``: the low-speed turn and its measures, with the swept-path figure."""
from __future__ import annotations

from .options import (Command, UsageError, add_source, help_range, model_choices, one_line, plot_path_of, ranged,
                      vehicle_of)
from .output import Output, write_figure_new


def cmd_turn(args, out: Output) -> int:
    from ..measures.low_speed import low_speed_turn
    from ..model.body import TurnError
    v = vehicle_of(args)
    plot = plot_path_of(args)
    if args.model == "nonlinear":
        return _turn_nonlinear(args, out, v, plot)
    for name in ("speed_kph", "friction_coefficient", "path_gain", "tire"):
        if getattr(args, name) is not None:
            raise UsageError(f"argument --{name.replace('_', '-')}: the nonlinear model's turn (--model nonlinear)")
    try:
        t = low_speed_turn(v, args.radius, args.angle_deg)
    except TurnError as exc:
        raise UsageError(f"argument --{'vehicle' if args.vehicle else 'preset'}: {exc}") from None
    if plot is not None:
        write_figure_new(t.plot(), plot)
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
                 f"  {label:<25} not computed: {one_line(t.undefined.get(key, ''))}")
    for name, val in t.tail_swing_m.items():
        out.line(f"  tail swing, {name:<13} {val:8.3f} m")
    if not t.tail_swing_m:
        out.line(f"  {'tail swing':<25} not computed: {one_line(t.undefined.get('max_tail_swing_m', ''))}")
    if plot is not None:
        out.line(f"wrote {plot}")
    return 0


def _turn_nonlinear(args, out: Output, v, plot) -> int:
    """``lcv turn --model nonlinear``: the turn with tire forces, friction demand per axle."""
    from ..analysis.integrate import IntegrationError
    from ..measures.friction_demand import (PATH_GAIN_RAD_PER_M, TURN_SPEED_KPH, turn_with_tire_forces)
    from ..model.body import TurnError
    from ..model.nonlinear.model import FRICTION_COEFFICIENT
    from ..model.vehicle import VehicleError
    try:
        t = turn_with_tire_forces(v, args.radius, args.angle_deg,
                                  TURN_SPEED_KPH if args.speed_kph is None else args.speed_kph,
                                  FRICTION_COEFFICIENT if args.friction_coefficient is None else args.friction_coefficient,
                                  PATH_GAIN_RAD_PER_M if args.path_gain is None else args.path_gain,
                                  tire=args.tire or "saturating")
    except (TurnError, VehicleError, ValueError) as exc:
        raise UsageError(f"argument --{'vehicle' if args.vehicle else 'preset'}: {one_line(exc)}") from None
    except IntegrationError as exc:
        raise UsageError(f"argument --speed-kph: {one_line(exc)}") from None
    if plot is not None:
        write_figure_new(t.plot(), plot)
    if args.json:
        out.json(t.to_dict())
        return 0
    out.line(f"{v.name}: low-speed {t.angle_deg:g} deg turn with tire forces ({t.tire} tires, mu {t.friction_coefficient:g},"
             f" {t.speed_kph:g} km/h), outside steer wheel on R = {t.radius_m:g} m, path gain "
             f"{t.path_gain_rad_per_m:g} rad/m")
    out.line(f"  path error, largest            {t.path_error_max_m:8.4f} m")
    for label, key, value in (("steer-tyre friction demand", "stfd", t.stfd),
                              ("drive-tyre friction demand", "friction_demand_drive", t.friction_demand_drive)):
        out.line(f"  {label:<30} {value:8.3f}" if value is not None else
                 f"  {label:<30} not computed: {one_line(t.undefined.get(key, ''))}")
    for axle, fd in t.friction_demand.items():
        out.line(f"  friction demand, axle {axle:<9} {fd:8.3f}")
    for label, key in (("swept width (lssp)", "lssp_m"), ("low-speed offtracking", "low_speed_offtracking_m"),
                       ("frontal swing", "frontal_swing_m"), ("tail swing, largest", "max_tail_swing_m")):
        mine = None if t.turn is None else getattr(t.turn, key)
        kin = getattr(t.kinematic, key)
        text = "not computed" if mine is None else f"{mine:8.3f} m"
        out.line(f"  {label:<30} {text}  (kinematic: {'not computed' if kin is None else f'{kin:.3f} m'})")
    if plot is not None:
        out.line(f"wrote {plot}")
    return 0


def turn_options(sp) -> None:
    from ..model.base import NONLINEAR_MODELS
    add_source(sp, masses=False)
    sp.add_argument("--radius", type=ranged("turn_radius", what="outside steer wheel radius in m"), default=12.5,
                    metavar="R", help=f"radius of the outside steer wheel's path [m], in "
                                      f"{help_range('turn_radius')}; default 12.5")
    sp.add_argument("--angle-deg", type=ranged("turn_angle", what="turn angle in deg"), default=90.0, metavar="A",
                    help=f"angle of the turn [deg], in {help_range('turn_angle')}; default 90")
    sp.add_argument("--plot", metavar="FILE", help="draw the swept path into FILE (.png, .pdf or .svg; a new file)")
    sp.add_argument("--model", default="kinematic", choices=("kinematic",) + model_choices(NONLINEAR_MODELS),
                    help="the kinematic model (default: no forces) or the nonlinear model with tire forces "
                         "(friction demand, docs/nonlinear.md)")
    sp.add_argument("--speed-kph", type=ranged("speed", factor=3.6, unit="km/h", what="turn speed in km/h"),
                    default=None, metavar="V", help="with --model nonlinear: unit 1's speed [km/h]; default 5")
    sp.add_argument("--friction-coefficient", type=ranged("friction", what="friction coefficient mu"),
                    metavar="MU", default=None, help="with --model nonlinear: mu, in (0, 2]; default 0.8")
    sp.add_argument("--path-gain", type=ranged("path_gain", what="path gain in rad/m"), metavar="K",
                    default=None, help="with --model nonlinear: the path-following law's gain [rad/m]; default 2 "
                                       "(and its integral term, docs/nonlinear.md)")
    sp.add_argument("--tire", choices=("saturating", "linear"), default=None,
                    help="with --model nonlinear: the tire law; default saturating")
    sp.add_argument("--json", action="store_true", help="machine-readable output")


COMMANDS = {"turn": Command("low-speed turn (90 deg by default): swept width, offtracking, tail and frontal swing "
                            "(kinematic model, docs/low_speed_turn.md)", turn_options, cmd_turn)}
