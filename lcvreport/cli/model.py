"""``lcv presets``, ``lcv eig``, ``lcv matrices`` and ``lcv steady``: the model itself."""
from __future__ import annotations

import math

import numpy as np

from ..model.linear import linear_model
from ..units import SI, THESIS
from .options import (Command, add_common, case_of, load_vector_of, model_choices, speed_mps_of, speed_text,
                      vehicle_of)
from .output import check_finite, Output


# ---------------------------------------------------------------------------- commands
def cmd_presets(args, out: Output) -> int:
    from ..model.presets import PRESET_LABELS, PRESETS
    if args.json:
        out.json({"presets": list(PRESETS)})
    else:
        for name in PRESETS:
            out.line(f"{name:22s} {PRESET_LABELS[name]}")
    return 0


def cmd_eig(args, out: Output) -> int:
    from ..analysis.modes import modes
    from ..model.linear import check_model
    model = check_model(args.model)
    if model == "yaw_roll":
        from .roll import roll_vehicle
        case = case_of(args, roll_vehicle(args))   # the roll keys, checked: one line naming what is missing
    else:
        case = case_of(args)
    v = case.vehicle
    m = modes(v, case.speed_mps, case.tire_scale, model=case.model)
    check_finite(m.eigenvalues)
    k = m.least_damped
    if args.json:
        out.json(m.to_dict())
        return 0
    out.line(f"{v.name} at {speed_text(args)}, tire scale {args.tire_scale:g} "
             f"({'stable' if m.stable else 'UNSTABLE'}); modes by real part, * = least damped")
    out.line(f"{'mode':>4} {'Re [1/s]':>10} {'Im [1/s]':>10} {'f_d [Hz]':>9} {'zeta [-]':>9}")
    for row in m.table():
        mark = " *" if k is not None and row["mode"] in (k + 1, k + 2) else ""
        out.line(f"{row['mode']:>4} {row['real_per_s']:>10.4f} {row['imag_per_s']:>10.4f} "
                 f"{row['damped_frequency_hz']:>9.4f} {row['damping_ratio']:>9.4f}{mark}")
    return 0


def cmd_matrices(args, out: Output) -> int:
    from ..model.yaw_plane.equations import system_matrices
    v = vehicle_of(args)
    which = args.units or ("thesis" if args.preset is not None else "si")
    units = THESIS if which == "thesis" else SI
    M, S = system_matrices(v, speed_mps_of(args), args.tire_scale, units=units)
    F = load_vector_of(args, v, units) if args.load is not None else None
    check_finite(M, S, F)
    label = "thesis units: lbf, in, s" if units is THESIS else "SI: N, m, kg, s"
    if args.json:
        doc = {"state": list(linear_model(v).state_names), "units": label, "M": M.tolist(), "S": S.tolist()}
        if F is not None:
            doc["F"] = F.tolist()
        out.json(doc)
        return 0
    out.line(f"state = {list(linear_model(v).state_names)}  ({label})")
    out.line("M =")
    out.line(np.array2string(M, precision=6, max_line_width=200))
    out.line("S =")
    out.line(np.array2string(S, precision=6, max_line_width=200))
    if F is not None:
        out.line(f"F ({args.convention} convention) =")
        out.line(np.array2string(F, precision=4, max_line_width=200))
    return 0


def cmd_steady(args, out: Output) -> int:
    from ..analysis.steady import steady_state
    from ..model.yaw_plane.outputs import rear_offsets
    v = vehicle_of(args)
    F = load_vector_of(args, v)
    x = steady_state(v, speed_mps_of(args), F, args.tire_scale)
    n = v.n_units
    y = rear_offsets(v, x[n + 1:])
    check_finite(x, y)
    state = {name: float(value) for name, value in zip(linear_model(v).state_names, x)}
    ydoc = {f"y{k + 2}": float(val) for k, val in enumerate(y)}
    if args.json:
        out.json({"state": state, "y": ydoc})
        return 0
    out.line(f"steady state, {v.name} at {speed_text(args)}, load on {args.load} ({args.convention} convention)")
    for name, value in state.items():
        unit = "m/s" if name == "v1" else "rad/s" if name.startswith("r") else "rad"
        extra = f"  ({math.degrees(value):.4f} deg)" if name.startswith("theta") else ""
        out.line(f"  {name:7s} {value: .6e} {unit}{extra}")
    for name, value in ydoc.items():
        out.line(f"  {name:7s} {value: .6e} m")
    return 0


# ---------------------------------------------------------------------------- options
def eig_options(sp) -> None:
    from ..model.base import LINEAR_MODELS
    add_common(sp, None)
    sp.add_argument("--model", default="yaw-plane", choices=model_choices(LINEAR_MODELS),
                    help="the model: yaw-plane (default) or yaw-roll (the vehicle's roll keys, docs/roll.md)")


def matrices_options(sp) -> None:
    add_common(sp, False)
    sp.add_argument("--units", choices=("thesis", "si"), default=None,
                    help="unit system of the matrices (default: thesis for presets, si for vehicle files)")


def presets_options(sp) -> None:
    sp.add_argument("--json", action="store_true")


COMMANDS = {
    "eig": Command("eigenvalues [1/s], damped frequency, damping ratio", eig_options, cmd_eig),
    "matrices": Command("M, S (and F with --load)", matrices_options, cmd_matrices),
    "steady": Command("steady state under the 1 %% rule loads, SI units", lambda sp: add_common(sp, True), cmd_steady),
    "presets": Command("list the presets", presets_options, cmd_presets),
}
