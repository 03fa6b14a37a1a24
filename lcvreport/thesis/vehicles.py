"""The six thesis vehicles, converted from Appendices B-D to SI vehicle files.

The presets ship as vehicle files (``lcvreport/data/vehicles/<preset>.toml``, the
format of docs/vehicle_files.md); this module is where they come from: the thesis tables
(in, lbf, lbf*s^2/in, lbf*in*s^2, per-tire coefficients) with the gaps of
``gaps.toml`` filled, converted to SI, axles named as in the thesis (``11`` is the
tractor steer axle, ``12``/``13`` the drive tandem, ``21`` the trailer 1 axle ...).
A test holds the shipped files equal to :func:`preset_file_text`, so the tables stay
the one source.  ``python -m lcvreport.thesis.vehicles DIR`` rewrites them.

Examples
--------
>>> v = preset_from_tables("tractor_semitrailer")
>>> v.unit_names, [a.name for a in v.axles]
(('tractor', 'trailer1'), ['11', '12', '13', '21'])
"""
from __future__ import annotations

import sys
from pathlib import Path

from ..model.vehicle import Axle, Unit, Vehicle
from ..model.vehicle_file import dumps_vehicle
from ..model.yaw_plane.states import joint_letter
from ..units import M_PER_IN, N_PER_LBF, THESIS
from .tables import dimensions, gaps, mass_table, tire_table

#: preset name -> (thesis configuration, number of units)
PRESET_SOURCES = {
    "aucnat": ("aucnat", 6), "legal_max": ("legal_max", 6), "loaded_loaded_empty": ("loaded_loaded_empty", 6),
    "empty_empty_loaded": ("empty_empty_loaded", 6), "empty": ("empty", 6), "tractor_semitrailer": ("aucnat", 2),
}
#: unit names of the thesis, front to back (Table 3-1)
UNIT_NAMES = ("tractor", "trailer1", "dolly1", "trailer2", "dolly2", "trailer3")
#: printed labels of the thesis' units (Table 3-1)
UNIT_LABELS = ("Tractor", "Trailer 1", "Dolly 1", "Trailer 2", "Dolly 2", "Trailer 3")
#: Table 3-3: the generalized coordinates of the triple, their description and SI unit
STATE_DESCRIPTIONS = {
    "v1": ("Tractor Lateral Velocity", "m/s"),
    "r1": ("Tractor Yaw Rate", "rad/s"), "r2": ("Trailer 1 Yaw Rate", "rad/s"), "r3": ("Dolly 1 Yaw Rate", "rad/s"),
    "r4": ("Trailer 2 Yaw Rate", "rad/s"), "r5": ("Dolly 2 Yaw Rate", "rad/s"), "r6": ("Trailer 3 Yaw Rate", "rad/s"),
    "thetaA": ("Articulation Angle at Joint A", "rad"), "thetaB": ("Articulation Angle at Joint B", "rad"),
    "thetaC": ("Articulation Angle at Joint C", "rad"), "thetaD": ("Articulation Angle at Joint D", "rad"),
    "thetaE": ("Articulation Angle at Joint E", "rad"),
}
#: Table C/D row holding each unit's tires (the tractor: steer and tandem rows)
_ROW = {"tractor": "tractor_steer", "trailer1": "trailer1", "dolly1": "dolly1", "trailer2": "trailer2",
        "dolly2": "dolly2", "trailer3": "trailer3"}


def _lbf_per_rad(v: float) -> float:
    return v * N_PER_LBF


def preset_from_tables(name: str) -> Vehicle:
    """The preset ``name`` built from the thesis tables, in SI.

    Parameters
    ----------
    name : str
        One of :data:`PRESET_SOURCES`.

    Returns
    -------
    Vehicle
    """
    config, n_units = PRESET_SOURCES[name]
    dims, mass, tires, g = dimensions(config), mass_table(config), tire_table(config), gaps()
    n_steer, n_other = g["tires_per_axle"]["steer"], g["tires_per_axle"]["other"]
    n_tandem = g["tandem"]["axles"]
    D_m = g["dual_spacing"]["D_in"] * M_PER_IN
    units = []

    b = g["bodies"]

    def axle(aname, x_in, row, n_tires, load_lbf, steered=False, dual=True):
        t = tires[row]
        return Axle(aname, x_in * M_PER_IN, n_tires, _lbf_per_rad(t["CF_lbf_per_rad"]),
                    t["CM_lbf_in_per_rad"] * THESIS.moment_Nm,
                    t.get("CS_lbf_per_rad", 0.0) * N_PER_LBF if dual else 0.0, D_m if dual else 0.0,
                    steered=steered, static_load_N=load_lbf * N_PER_LBF,
                    track_width_m=(b["dual_track_in"] if dual else b["steer_track_in"]) * M_PER_IN)

    def body(uname, axles, rear_coupling, rear_end):
        """(front, rear, width) [m] of a unit's body from the gaps of ``gaps.toml``."""
        xs = [a.x_m for a in axles]
        if uname == "tractor":
            return (max(xs) + b["tractor_front_ahead_of_steer_axle_in"] * M_PER_IN,
                    min(xs) - b["tractor_rear_behind_rear_axle_in"] * M_PER_IN, b["body_width_in"] * M_PER_IN)
        if uname.startswith("dolly"):
            return (max(xs) + b["dolly_front_ahead_of_axle_in"] * M_PER_IN,
                    min(xs) - b["dolly_rear_behind_axle_in"] * M_PER_IN, b["dolly_width_in"] * M_PER_IN)
        rear_face = rear_coupling if rear_coupling is not None else rear_end
        return rear_face + b["trailer_length_in"] * M_PER_IN, rear_face, b["body_width_in"] * M_PER_IN

    for k, uname in enumerate(UNIT_NAMES[:n_units]):
        i = k + 1
        front = None if k == 0 else dims[f"x{i}{joint_letter(k - 1)}_in"] * M_PER_IN
        rear = None if k == n_units - 1 else -dims[f"x{i}{joint_letter(k)}_in"] * M_PER_IN
        rear_end = None
        if k == n_units - 1:  # x2B for the tractor-semitrailer (eq. 3.43), x6F for the triple (eq. 4.46)
            rear_end = -(dims["x2B_in"] if n_units == 2 else g["rear_end"]["x6F_in"]) * M_PER_IN
        if uname == "tractor":
            axles = [axle("11", dims["x11_in"], "tractor_steer", n_steer, mass["tractor_steer"]["axle_load_lbf"],
                          steered=True, dual=False)]
            axles += [axle(f"1{j + 2}", -dims[f"x1{j + 2}_in"], "tractor_tandem", n_other,
                           mass["tractor_tandem"]["axle_load_lbf"] / n_tandem) for j in range(n_tandem)]
        else:
            axles = [axle(f"{i}1", -dims[f"x{i}1_in"], _ROW[uname], n_other, mass[_ROW[uname]]["axle_load_lbf"])]
        row = mass[_ROW[uname]]
        bf, br, bw = body(uname, axles, rear, rear_end)
        units.append(Unit(uname, row["mass_lbf_s2_per_in"] * THESIS.mass_kg,
                          row["inertia_lbf_in_s2"] * THESIS.inertia_kg_m2, tuple(axles), front, rear, rear_end,
                          body_front_m=bf, body_rear_m=br, body_width_m=bw))
    tables = f"Tables {dims['table']}, {mass['table']}, {tires['table']}"
    desc = (f"{tables} of Patterson (2011), converted to SI" +
            (" (tractor and trailer 1 of the AU-NCAT triple, chapter III)" if name == "tractor_semitrailer" else ""))
    return Vehicle(name, tuple(units), desc)


def preset_file_text(name: str) -> str:
    """The vehicle file of preset ``name``: SI numbers with the thesis sources as comments."""
    config, n_units = PRESET_SOURCES[name]
    g = gaps()
    v = preset_from_tables(name)
    header = (f"Preset {name!r}: {v.description}.\n"
              "Generated by lcvreport.thesis.vehicles from the thesis tables (lcvreport/data/thesis); do not edit.\n"
              "Positions are signed x from each unit's CG [m], forward positive; coefficients per tire.\n"
              f"Tires per axle: {g['tires_per_axle']['source']}\n"
              f"Dual spacing D = {g['dual_spacing']['D_in']:g} in: {g['dual_spacing']['source']}\n"
              f"Tractor tandem: {g['tandem']['source']}\n"
              "Steer axle 11: single tires, no dual term (C_S = 0, D = 0).\n"
              f"Bodies (low-speed turn, drawings): trailers {g['bodies']['trailer_length_source']}; "
              f"{g['bodies']['trailer_rear_source']}; width: {g['bodies']['body_width_source']}; tractor: "
              f"{g['bodies']['tractor_source']}; dollies: {g['bodies']['dolly_source']}.\n"
              f"Track widths: {g['bodies']['track_source']}.")
    dims, mass, tires = dimensions(config), mass_table(config), tire_table(config)
    unit_comments, axle_comments = {}, {}
    for k, u in enumerate(v.units):
        i, row = k + 1, mass[_ROW[u.name]]
        notes = [f"{UNIT_LABELS[k]}: mass {row['mass_lbf_s2_per_in']:g} lbf*s^2/in, yaw inertia "
                 f"{row['inertia_lbf_in_s2']:g} lbf*in*s^2 ({mass['table']})"]
        joints = []
        if k > 0:
            joints.append(f"front x{i}{joint_letter(k - 1)} = {dims[f'x{i}{joint_letter(k - 1)}_in']:g} in")
        if k < n_units - 1:
            joints.append(f"rear x{i}{joint_letter(k)} = {dims[f'x{i}{joint_letter(k)}_in']:g} in")
        elif n_units == 2:
            joints.append(f"rear end x2B = {dims['x2B_in']:g} in (eq. 3.43)")
        else:
            joints.append(f"rear end x6F = {g['rear_end']['x6F_in']:g} in: {g['rear_end']['source']}")
        notes.append(f"couplings ({dims['table']}): " + ", ".join(joints))
        unit_comments[u.name] = "\n".join(notes)
        for a in u.axles:
            trow = tires["tractor_steer" if a.name == "11" else "tractor_tandem" if u.name == "tractor" else _ROW[u.name]]
            cs = f", CS {trow['CS_lbf_per_rad']:g} lbf" if "CS_lbf_per_rad" in trow and a.name != "11" else ""
            axle_comments[a.name] = (f"axle {a.name}: x{a.name} = {dims[f'x{a.name}_in']:g} in ({dims['table']}); "
                                     f"load {a.static_load_N / N_PER_LBF:g} lbf ({mass['table']}); per tire CF "
                                     f"{trow['CF_lbf_per_rad']:g} lbf/rad, CM {trow['CM_lbf_in_per_rad']:g} "
                                     f"lbf*in/rad{cs} ({tires['table']})")
    return dumps_vehicle(v, header=header, unit_comments=unit_comments, axle_comments=axle_comments)


def write_preset_files(directory: Path) -> list[Path]:
    """Write every preset's vehicle file into ``directory``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    out = []
    for name in PRESET_SOURCES:
        path = directory / f"{name}.toml"
        path.write_text(preset_file_text(name), encoding="utf-8")
        out.append(path)
    return out


if __name__ == "__main__":  # pragma: no cover - maintenance entry point
    for p in write_preset_files(Path(sys.argv[1] if len(sys.argv) > 1 else "lcvreport/data/vehicles")):
        print(p)
