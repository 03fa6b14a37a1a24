"""``lcv turn``: the low-speed turn and its measures, with the swept-path figure."""
from __future__ import annotations

from .options import UsageError, _line, _plot_path, _vehicle
from .output import _Out, _write_figure_new


def _cmd_turn(args, out: _Out) -> int:
    from ..measures.low_speed import low_speed_turn
    from ..model.body import TurnError
    v = _vehicle(args)
    plot = _plot_path(args)
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
