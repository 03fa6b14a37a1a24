"""Write the example vehicle files of this folder, with where each number comes from.

    python examples/vehicles/make_examples.py        (from the repository root)

* ``western_double.toml``: a US western double (6x4 tractor, two 28-ft class trailers,
  one converter dolly): the tractor, trailer 1, dolly 1 and trailer 2 of the AU-NCAT
  triple of Patterson (2011), Tables B.1, C.1 and D.1, converted to SI.
* ``b_double.toml``: an Australian-style B-double (6x4 prime mover, lead trailer with a
  fifth wheel over its tri-axle group, tri-axle semitrailer).
* ``truck_full_trailer.toml``: a 6x4 rigid truck with a hitch behind its rear axle, and
  a full trailer (a drawbar dolly with a turntable, and the trailer body).

For the last two the geometry and the axle and coupling loads are stated below
(typical of such vehicles; not measurements of one), bodies included (front and rear
faces, width 2.5 m: the Australian and European limit) and track widths (centres of the
outermost tires: 2.05 m on steer axles, 2.2 m on dual axles); the rest follows:

* masses and CG positions from statics: ``m g = sum of axle loads + load on the front
  coupling - load from the unit behind``, the CG where the moments balance;
* yaw inertias of a uniform box about its CG, ``I = m (L^2 + W^2) / 12``, with the body
  length L and width W = 2.5 m (an estimate: the mass is not uniform);
* tire coefficients per tire from the thesis' Appendix D fits at the tire load
  (:func:`lcvreport.thesis.tires.tire_properties`), duals 0.3048 m apart as the thesis.
"""
from __future__ import annotations

from pathlib import Path

from lcvreport.model.presets import load_preset
from lcvreport.model.vehicle import Axle, Unit, Vehicle
from lcvreport.model.vehicle_file import dumps_vehicle
from lcvreport.thesis.tires import tire_properties
from lcvreport.units import N_PER_LBF, THESIS

HERE = Path(__file__).resolve().parent
G = 9.80665
DUAL_M = 0.3048
BODY_WIDTH_M = 2.5
#: centres of the outermost tires [m]: steer axles (single tires) and dual axles
STEER_TRACK_M = 2.05
DUAL_TRACK_M = 2.2


def tire(load_N: float, tires: int, dual: bool) -> dict:
    """Per-tire coefficients from the thesis' Appendix D fits at the tire load."""
    cf, cm, cs = tire_properties(load_N / tires / N_PER_LBF)
    return {"cornering_stiffness_N_per_rad": cf * N_PER_LBF, "aligning_stiffness_Nm_per_rad": cm * THESIS.moment_Nm,
            "longitudinal_stiffness_N": cs * N_PER_LBF if dual else 0.0, "dual_spacing_m": DUAL_M if dual else 0.0}


def chain(name: str, description: str, specs: list[dict]) -> Vehicle:
    """Units from geometry (x along each unit from a reference point, forward positive)
    and loads [kg]: masses and CGs by statics, from the last unit forward."""
    units = []
    for k, s in enumerate(specs):
        behind = specs[k + 1]["front_load_kg"] if k + 1 < len(specs) else 0.0
        front = s.get("front_load_kg", 0.0)
        axle_kg = sum(a[2] for a in s["axles"])
        mass = axle_kg + front - behind
        moment = sum(a[1] * a[2] for a in s["axles"]) + front * s.get("front_coupling", 0.0) - \
            behind * s.get("rear_coupling", 0.0)
        cg = moment / mass
        axles = tuple(Axle(a[0], a[1] - cg, a[3], steered=a[4], static_load_N=a[2] * G,
                           track_width_m=DUAL_TRACK_M if a[3] >= 4 else STEER_TRACK_M,
                           **tire(a[2] * G, a[3], dual=a[3] >= 4)) for a in s["axles"])
        front_face, rear_face = s["body"]
        units.append(Unit(s["name"], mass, mass * (s["length"] ** 2 + BODY_WIDTH_M ** 2) / 12, axles,
                          s["front_coupling"] - cg if "front_coupling" in s else None,
                          s["rear_coupling"] - cg if "rear_coupling" in s else None,
                          s["rear_end"] - cg if "rear_end" in s else None,
                          body_front_m=front_face - cg, body_rear_m=rear_face - cg, body_width_m=BODY_WIDTH_M))
    return Vehicle(name, tuple(units), description)


# x from the front axle (prime mover, truck) or from the front coupling (trailers), forward positive
# axles: (name, x [m], load [kg], tires, steered); front_load_kg: what the unit puts on the unit ahead;
# body: (front face, rear face) x [m] in the same coordinates
B_DOUBLE = [
    {"name": "prime_mover", "length": 6.5, "rear_coupling": -3.85, "body": (1.4, -5.7),
     "axles": [("steer", 0.0, 5400, 2, True), ("drive1", -3.65, 8500, 4, False), ("drive2", -5.02, 8500, 4, False)]},
    {"name": "lead_trailer", "length": 10.0, "front_coupling": 0.0, "front_load_kg": 11000.0, "rear_coupling": -7.3,
     "rear_end": -8.9, "body": (1.0, -9.9),
     "axles": [("a1", -6.54, 6667, 4, False), ("a2", -7.90, 6667, 4, False), ("a3", -9.26, 6666, 4, False)]},
    {"name": "rear_trailer", "length": 13.0, "front_coupling": 0.0, "front_load_kg": 9500.0, "rear_end": -12.3,
     "body": (1.0, -12.3),
     "axles": [("b1", -8.84, 6667, 4, False), ("b2", -10.20, 6667, 4, False), ("b3", -11.56, 6666, 4, False)]},
]
TRUCK_FULL_TRAILER = [
    {"name": "truck", "length": 9.5, "rear_coupling": -7.4, "rear_end": -6.9, "body": (1.4, -6.9),
     "axles": [("steer", 0.0, 5400, 2, True), ("drive1", -4.55, 8000, 4, False), ("drive2", -5.92, 8000, 4, False)]},
    {"name": "drawbar_dolly", "length": 3.5, "front_coupling": 0.0, "front_load_kg": 0.0, "rear_coupling": -3.2,
     "body": (-2.4, -3.9), "axles": [("d1", -3.2, 9300, 4, False)]},
    {"name": "trailer", "length": 7.5, "front_coupling": 0.0, "front_load_kg": 8500.0, "rear_end": -7.0,
     "body": (0.6, -7.0), "axles": [("t1", -5.0, 8000, 4, False), ("t2", -6.36, 8000, 4, False)]},
]


def western_double() -> Vehicle:
    """Tractor, trailer 1, dolly 1, trailer 2 of the AU-NCAT triple, renamed."""
    v = load_preset("aucnat").truncated(4, "western_double")
    names = {"11": "steer", "12": "drive1", "13": "drive2", "21": "trailer1_axle", "31": "dolly_axle",
             "41": "trailer2_axle"}
    from dataclasses import replace
    units = tuple(replace(u, name={"dolly1": "dolly"}.get(u.name, u.name),
                          axles=tuple(replace(a, name=names[a.name]) for a in u.axles)) for u in v.units)
    from lcvreport.model.statics import loads_of_masses
    # Table C.1's axle loads are the triple's: on the double they summed 3 % below its weight and
    # left the dolly pushing trailer 1's pintle up (-22 kN); the loads of its masses by statics
    return loads_of_masses(replace(v, units=units, description="US western double: 6x4 tractor, two 28-ft class "
                                   "trailers, one converter dolly; the AU-NCAT tractor, trailer 1, dolly 1 and "
                                   "trailer 2 of Patterson (2011)"))


# Roll data (docs/roll.md).  ASSUMED, every number: typical of the configuration as the rollover
# literature describes it (Winkler & Ervin, "Rollover of heavy commercial vehicles", UMTRI-99-19,
# 1999: loaded van trailers' CG 1.9-2.2 m, tractor sprung CG about 1.1 m, roll centres 0.5-0.8 m,
# fifth wheels about 1.2-1.3 m), not measurements of one vehicle.  Roll inertias of the sprung
# masses as uniform boxes I_x = m_s (W^2 + H^2) / 12 (W 2.5 m, H the load's height); no yaw-roll
# product; suspension roll damping giving roll-mode damping ratios of about 0.1.
#: per unit: (cg_height_m, roll_axis_height_m, box height H [m], rear coupling (height_m, roll stiffness
#: Nm/rad: 0 roll-free drawbar or pintle, > 0 a fifth wheel or turntable) or None)
ROLL_UNITS = {
    "prime_mover": (1.10, 0.55, 1.8, (1.25, 5.0e6)), "lead_trailer": (2.00, 0.75, 2.4, (1.30, 5.0e6)),
    "rear_trailer": (2.05, 0.75, 2.4, None),
    "tractor": (1.10, 0.55, 1.8, (1.25, 5.0e6)), "trailer1": (2.00, 0.75, 2.4, (0.90, 0.0)),
    "dolly": (0.95, 0.75, 0.6, (1.20, 5.0e6)), "trailer2": (2.00, 0.75, 2.4, None),
    "truck": (1.60, 0.70, 2.4, (0.90, 0.0)), "drawbar_dolly": (0.95, 0.75, 0.6, (1.10, 5.0e6)),
    "trailer": (2.00, 0.75, 2.4, None),
}
#: per axle kind: (roll_stiffness_Nm_per_rad, roll_damping_Nms_per_rad, unsprung_mass_kg)
ROLL_AXLES = {"steer": (4.0e5, 2.0e4, 600.0), "drive": (8.0e5, 3.0e4, 1000.0), "trailer": (1.0e6, 3.0e4, 700.0),
              "dolly": (1.0e6, 3.0e4, 500.0)}
ROLL_HEADER = ("Roll data: ASSUMED, typical of the configuration (Winkler & Ervin, UMTRI-99-19, 1999), not measured: "
               "the heights, suspension roll stiffness and damping, unsprung masses and coupling roll stiffnesses of "
               "make_examples.py ROLL_UNITS / ROLL_AXLES; roll inertias of uniform boxes.")


def with_roll(vehicle: Vehicle) -> Vehicle:
    """``vehicle`` with the assumed roll data of :data:`ROLL_UNITS` and :data:`ROLL_AXLES`."""
    from dataclasses import replace

    def kind(axle, unit):
        if axle.steered:
            return "steer"
        if "dolly" in unit.name:
            return "dolly"
        return "drive" if unit is vehicle.units[0] else "trailer"

    units = []
    for u in vehicle.units:
        h, hr, box, coupling = ROLL_UNITS[u.name]
        axles = tuple(replace(a, **dict(zip(("roll_stiffness_Nm_per_rad", "roll_damping_Nms_per_rad",
                                             "unsprung_mass_kg"), ROLL_AXLES[kind(a, u)]))) for a in u.axles)
        ms = u.mass_kg - sum(a.unsprung_mass_kg for a in axles)
        extra = {} if coupling is None else {"rear_coupling_height_m": coupling[0],
                                             "rear_coupling_roll_stiffness_Nm_per_rad": coupling[1]}
        units.append(replace(u, axles=axles, cg_height_m=h, roll_axis_height_m=hr,
                             roll_inertia_kg_m2=round(ms * (BODY_WIDTH_M ** 2 + box ** 2) / 12, 1), **extra))
    return replace(vehicle, units=tuple(units))


def main() -> None:
    files = {
        "western_double": (western_double(), "Numbers: Patterson (2011) Tables B.1 (dimensions), C.1 (masses, inertias), "
                           "D.1 (tires, per tire), converted to SI; static_load_N by statics from the masses and CGs "
                           "(lcvreport.model.statics.loads_of_masses: Table C.1's axle loads are the triple's, which on "
                           "the double summed 3 % below its weight with the dolly lifting trailer 1's pintle by 22 kN); "
                           "trailer 2's rear end is its rear hitch "
                           "x4D = 155.28 in; dual spacing 12 in (SPEC gap); bodies and track widths as the aucnat "
                           "preset's (lcvreport/data/thesis/gaps.toml [bodies]). Generated by make_examples.py."),
        "b_double": (chain("b_double", "Australian-style B-double, 26 m: 6x4 prime mover, lead trailer with a fifth "
                           "wheel over its tri-axle group, tri-axle semitrailer; 62.4 t on the axles", B_DOUBLE),
                     "Geometry and loads: typical of the configuration (steer 5.4 t (the tire fits end at 6,000 lbf per tire), drive tandem 17 t, tri-axle groups "
                     "20 t, kingpin loads 11 t and 9.5 t), not one vehicle's measurements. Masses and CGs by statics, "
                     "yaw inertias of uniform boxes, tires from the thesis' Appendix D fits at the tire load. "
                     "Generated by make_examples.py (its docstring has the rules)."),
        "truck_full_trailer": (chain("truck_full_trailer", "6x4 rigid truck with a rear hitch behind its last axle, "
                                     "and a full trailer: a drawbar dolly with a turntable over its axle and the trailer "
                                     "body with a rear tandem; 46.7 t on the axles", TRUCK_FULL_TRAILER),
                               "Geometry and loads: typical of the configuration (steer 5.4 t, drive tandem 16 t, "
                               "dolly axle 9.3 t (0.8 t of dolly), trailer tandem 16 t; the drawbar carries no vertical load), not one "
                               "vehicle's measurements. Masses and CGs by statics, yaw inertias of uniform boxes, tires "
                               "from the thesis' Appendix D fits at the tire load. Generated by make_examples.py."),
    }
    for stem, (vehicle, header) in files.items():
        text = dumps_vehicle(with_roll(vehicle), header=header + "\n" + ROLL_HEADER)
        (HERE / f"{stem}.toml").write_text(text, encoding="utf-8")
        print(HERE / f"{stem}.toml")


if __name__ == "__main__":
    main()
