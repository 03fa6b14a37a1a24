"""``lcv measures``: every measure of the registry as text, CSV or JSON, judged against
``--criteria``.
"""
from __future__ import annotations

from ..measures.registry import MEASURES
from ..units import mps_to_kph
from .options import (Command, UsageError, add_conditions, add_load, add_residuals, add_source, add_tire_scale,
                      case_of, model_choices, one_line, parse_speeds, vehicle_of)
from .output import check_finite, Output


def cmd_measures(args, out: Output) -> int:
    from ..measures.criteria import CriteriaError, judge, load_criteria
    v = vehicle_of(args)
    speeds, unit = parse_speeds(args)
    case = case_of(args, v, speed=False)        # every option checked once, before any measure is computed
    criteria = None
    if args.criteria is not None:
        try:
            criteria = load_criteria(args.criteria)
        except CriteriaError as exc:
            raise UsageError(f"argument --criteria {args.criteria}: {exc}") from None
    model = case.model
    if model != "yaw_plane":                    # the model's keys checked before any measure is computed
        from ..model.vehicle import VehicleError
        try:
            case.model_object()
        except (VehicleError, ValueError) as exc:
            raise UsageError(f"argument --model {args.model}: {one_line(exc)}") from None
    docs, sets = [], []
    for u in speeds:
        try:
            m = case.replace(speed_mps=u).measure_set()
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
        check_finite(*(val for val in doc.values() if isinstance(val, (int, float))),
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
    on = "" if model == "yaw_plane" else f", the {args.model} model's manoeuvres and eigenvalues"
    out.line(f"{v.name} at {args.speed_kph or args.speed_mph} {unit} ({mps_to_kph(m.speed_mps):.1f} km/h), tire scale "
             f"{args.tire_scale:g}{on}")
    for line in text_lines(m.rows()):
        out.line(line)
    if criteria is not None:
        out.line(f"verdicts against {args.criteria} (limits and their sources as the file gives them):")
        for key, verdict in doc["verdicts"].items():
            out.line(f"  {key:28s} {verdict['verdict']:14s} {verdict['note']}")
    return 0


def text_lines(rows: list[dict]) -> list[str]:
    """The measures as aligned text: columns as wide as their longest entry, and a reason that
    many rows share (a vehicle without roll data: one missing key for every roll measure) said
    once, the rows pointing to it.

    Examples
    --------
    >>> rows = [{"measure": "a", "value": 1.0, "unit": "m", "note": "why"},
    ...         {"measure": "a longer label", "value": "none", "unit": "-", "note": "x"}]
    >>> print("\\n".join(text_lines(rows)))
      a                 1 m  why
      a longer label none -  x
    """
    from collections import Counter
    texts = [row["value"] if isinstance(row["value"], str) else f"{row['value']:.6g}" for row in rows]
    shared = Counter(row["note"] for row, text in zip(rows, texts) if text == "none")
    repeated = [note for note, count in shared.items() if count >= 3 and len(note) > 40]
    label = max(len(row["measure"]) for row in rows)
    value = max(len(t) for t in texts)
    unit = max(len(row["unit"]) for row in rows)
    lines = []
    for row, text in zip(rows, texts):
        note = row["note"]
        if text == "none" and note in repeated:
            note = f"not computed: see note {repeated.index(note) + 1} below"
        lines.append(f"  {row['measure']:<{label}} {text:>{value}} {row['unit']:<{unit}}  {note}".rstrip())
    lines += [f"  note {k + 1}: {note}" for k, note in enumerate(repeated)]
    return lines


def _flatten(doc: dict, vehicle) -> dict:
    flat = {}
    for key, val in doc.items():
        if key == "ay_gain_per_unit":
            for name, g in zip(vehicle.unit_names, val or [None] * vehicle.n_units):
                flat[f"ay_gain_{name}_m_per_s2_per_rad"] = g
        elif key == "roll_gain_deg_per_g":
            for name, g in zip(vehicle.unit_names, val or [None] * vehicle.n_units):
                flat[f"roll_gain_{name}_deg_per_g"] = g
        elif key in PER_GROUP:                   # one column per roll-coupled group, front to rear
            for g, x in enumerate(val or [None] * _groups(vehicle)):
                flat[f"{key}.group{g + 1}"] = x
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


#: the measures with one value per roll-coupled group
PER_GROUP = tuple(k for k, m in MEASURES.items() if m.shape == "per_group")


def _groups(vehicle) -> int:
    """The vehicle's number of roll-coupled groups (by its couplings' roll stiffness; 1 without data)."""
    return 1 + sum(1 for u in vehicle.units[:-1] if u.rear_coupling_roll_stiffness_Nm_per_rad == 0.0)


def _flat_columns(doc: dict, vehicle) -> list[str]:
    return list(_flatten(doc, vehicle))


def measures_options(sp) -> None:
    from ..model.base import MODELS
    add_source(sp)
    g = sp.add_mutually_exclusive_group(required=True)
    g.add_argument("--speed-kph", metavar="V", help="forward speed [km/h], or a sweep START:STOP:STEP")
    g.add_argument("--speed-mph", metavar="V", help="forward speed [mph], or a sweep START:STOP:STEP")
    add_tire_scale(sp)
    add_load(sp, False, convention=False)
    add_residuals(sp)
    add_conditions(sp)
    sp.add_argument("--criteria", metavar="FILE", help="limits to judge the measures by (TOML, see examples/)")
    sp.add_argument("--model", default="yaw-plane", choices=model_choices(MODELS),
                    help="the model of the manoeuvres' and eigenvalues' measures (their keys are the same on every "
                         "model: hsto_m of the yaw-roll model is the default's hsto_m_roll); nonlinear: its "
                         "responses, its linearization's eigenvalues and its friction demand (docs/model.md)")
    sp.add_argument("--json", action="store_true", help="machine-readable output")


COMMANDS = {"measures": Command("the measures: damping, RA, YDC, HSTO, HSSO, trim, the low-speed turn, roll (SRT, "
                                "LTR, roll gains; with roll data) (defined in docs/measures.md)", measures_options,
                                cmd_measures)}
