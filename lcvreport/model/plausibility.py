"""Plausibility of a vehicle: numbers that are legal but probably typed in the wrong unit.

The vehicle-file schema refuses what is impossible (a negative mass) and what would
overflow; these checks catch what is possible but implausible for a road vehicle -- a
cornering stiffness in kN/rad, a mass in tonnes, an inertia in t*m^2 -- and return one
line each, to be shown as warnings (not errors: an unusual vehicle may be right).

=================================  =============================================  ==========
check                              quantity                                       plausible
=================================  =============================================  ==========
cornering stiffness vs load        C_F per tire / static load per tire [1/rad]    [1, 50]
mass vs axle loads                 sum of the unit's static axle loads / (m g)    [0.1, 50]
yaw inertia vs size                radius of gyration sqrt(I/m) / unit length     [0.05, 2]
=================================  =============================================  ==========

Typical values: a truck tire's cornering coefficient C_F/F_z is 5-12 /rad; a semitrailer
carries 60-85 % of its weight on its axles (the rest on the kingpin), a tractor more
than its own (the fifth-wheel load), a dolly many times its own (up to 12 seen); a rigid body's radius of gyration is 0.25-0.35 of
its length.

Examples
--------
>>> from lcvreport import load_vehicle
>>> plausibility_warnings(load_vehicle("examples/vehicles/b_double.toml"))
[]
"""
from __future__ import annotations

import math

from .vehicle import Vehicle

G = 9.80665
#: plausible ranges of the three ratios (see the module docstring)
CORNERING_PER_LOAD = (1.0, 50.0)
AXLE_LOAD_PER_WEIGHT = (0.1, 50.0)
GYRATION_PER_LENGTH = (0.05, 2.0)


def plausibility_warnings(vehicle: Vehicle) -> list[str]:
    """One line per implausible number of ``vehicle`` (empty when all look right).

    Parameters
    ----------
    vehicle : Vehicle

    Returns
    -------
    list of str
        Each names the unit (and axle), the ratio, its plausible range and the likely typo.
    """
    out = []
    for u in vehicle.units:
        loads = [a.static_load_N for a in u.axles if a.static_load_N]
        for a in u.axles:
            if a.static_load_N:
                ratio = a.cornering_stiffness_N_per_rad / (a.static_load_N / a.tires)
                lo, hi = CORNERING_PER_LOAD
                if not lo <= ratio <= hi:
                    out.append(f'unit "{u.name}" axle "{a.name}": cornering_stiffness_N_per_rad is {ratio:.3g} times '
                               f"the static load per tire (plausible {lo:g}-{hi:g} /rad); a stiffness in kN/rad or "
                               "per axle instead of per tire?")
        if loads and len(loads) == len(u.axles):
            ratio = sum(loads) / (u.mass_kg * G)
            lo, hi = AXLE_LOAD_PER_WEIGHT
            if not lo <= ratio <= hi:
                out.append(f'unit "{u.name}": its axles carry {ratio:.3g} times its weight (plausible {lo:g}-{hi:g}); '
                           "mass_kg in tonnes, or static_load_N in kg or kN?")
        xs = [a.x_m for a in u.axles] + [x for x in (u.front_coupling_m, u.rear_coupling_m, u.rear_end_m)
                                         if x is not None]
        length = max(xs) - min(xs)
        if length >= 0.5:
            ratio = math.sqrt(u.yaw_inertia_kg_m2 / u.mass_kg) / length
            lo, hi = GYRATION_PER_LENGTH
            if not lo <= ratio <= hi:
                out.append(f'unit "{u.name}": radius of gyration sqrt(I/m) is {ratio:.3g} of its length {length:.3g} m '
                           f"(plausible {lo:g}-{hi:g}); yaw_inertia_kg_m2 or mass_kg in another unit?")
    return out
