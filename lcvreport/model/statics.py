r"""Static axle and coupling loads that move with the masses: a unit made heavier, or loaded with
a payload, passes the added weight to its own supports by its own statics (docs/vehicle_files.md
#loads-that-follow-the-masses).

A unit's supports are its front coupling (if it has one) and its axles.  A unit with a front
coupling (a semitrailer, a dolly, a B-link's rear trailer) stands on two supports: the coupling
and its axle group, the group at the load-weighted centroid of its axles; a unit without one
(unit 1) on its front and rear axle groups, split at the largest gap between consecutive axles
(a tractor: the steer axle and the drive tandem).  A weight ``W`` at ``x`` goes to the two
supports by the lever rule; within a group, the axles share their part in proportion to their
static loads (a load-sharing tandem: equally when they are equal).  The part a front coupling
carries is a weight at the rear coupling of the unit ahead, which passes it on the same way --
so a trailer's payload reaches the tractor's axles through the fifth wheel.  The coupling loads
``W_k = sum_(i>k) m_i g - sum F_z0`` behind joint k follow (docs/roll.md): masses and loads stay
as consistent as the file's were.

A **payload** ``p`` [kg] at ``x_m`` (signed, from the unit's CG in the file) and ``height_m``
(above ground; default the unit's CG height) is a point mass (``length_m`` > 0: a uniform block
that long along x, adding ``p L^2 / 12`` to the yaw inertia); the unit's CG moves to
``p x / (m + p)`` (every position of the unit is measured from the new CG), its yaw inertia,
CG height, roll inertia and yaw-roll product follow from the parallel-axis theorem (the payload
joins the sprung mass).

Examples
--------
>>> from lcvreport import load_vehicle
>>> v = load_vehicle("examples/vehicles/b_double.toml")
>>> heavier = with_mass(v, "rear_trailer", 1.2 * v.units[2].mass_kg)
>>> added = sum(a.static_load_N for a in heavier.axles) - sum(a.static_load_N for a in v.axles)
>>> round(added / (0.2 * v.units[2].mass_kg * G_MPS2), 12)
1.0
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .vehicle import Vehicle, VehicleError

#: standard gravity [m/s^2]
G_MPS2 = 9.80665


class StaticsError(VehicleError):
    """Loads that cannot be passed on by statics (a unit with no second support)."""


def _groups(unit, loads: np.ndarray) -> list[tuple[np.ndarray, float]]:
    """The support groups of a unit without a front coupling: (axle indices, load-weighted x)."""
    order = np.argsort([-a.x_m for a in unit.axles])              # front to rear
    xs = np.array([unit.axles[j].x_m for j in order])
    if xs.size < 2:
        raise StaticsError("static_load_N", f"unit {unit.name!r} has one axle and no front coupling: it cannot "
                                            "stand on its own, so a weight on it has no second support")
    cut = int(np.argmax(-np.diff(xs))) + 1                        # the largest gap between consecutive axles
    return [(order[:cut], _centroid(unit, order[:cut], loads)), (order[cut:], _centroid(unit, order[cut:], loads))]


def _centroid(unit, idx: np.ndarray, loads: np.ndarray) -> float:
    x = np.array([unit.axles[j].x_m for j in idx])
    w = loads[idx]
    return float(np.average(x, weights=w)) if np.all(w > 0) and w.sum() > 0 else float(x.mean())


def _share(idx: np.ndarray, loads: np.ndarray, weight: float, out: np.ndarray) -> None:
    w = loads[idx]
    frac = w / w.sum() if np.all(w > 0) and w.sum() > 0 else np.full(idx.size, 1.0 / idx.size)
    out[idx] += weight * frac


def load_changes(vehicle: Vehicle, unit_index: int, weight_N: float, x_m: float) -> list[np.ndarray]:
    """The change of every axle's static load [N], per unit (in file order), when a vertical
    force ``weight_N`` (downward positive) acts at ``x_m`` on unit ``unit_index`` (signed x from
    its CG): passed to the unit's supports by its statics, a front coupling's part on to the unit
    ahead (see the module docstring).  Needs every axle's ``static_load_N``.

    Raises
    ------
    StaticsError
        A unit without a second support (one axle, no front coupling).
    """
    loads = [np.array([a.static_load_N for a in u.axles], dtype=float) for u in vehicle.units]
    delta = [np.zeros(len(u.axles)) for u in vehicle.units]
    k, W, x = unit_index, float(weight_N), float(x_m)
    while True:
        u = vehicle.units[k]
        if u.front_coupling_m is not None:
            idx = np.arange(len(u.axles))
            xg = _centroid(u, idx, loads[k])
            f = u.front_coupling_m
            if f == xg:
                raise StaticsError("front_coupling_m", f"unit {u.name!r}: its front coupling is over its axles: "
                                                       "no lever to share a weight between them")
            w_front = W * (x - xg) / (f - xg)
            _share(idx, loads[k], W - w_front, delta[k])
            if k == 0:                          # cannot happen: unit 1 has no front coupling
                break
            k, W, x = k - 1, w_front, vehicle.units[k - 1].rear_coupling_m
            continue
        (front, xf), (rear, xr) = _groups(u, loads[k])
        w_front = W * (x - xr) / (xf - xr)
        _share(front, loads[k], w_front, delta[k])
        _share(rear, loads[k], W - w_front, delta[k])
        break
    return delta


def _with_loads(vehicle: Vehicle, delta: list[np.ndarray]) -> Vehicle:
    units = []
    for u, d in zip(vehicle.units, delta):
        axles = tuple(dataclasses.replace(a, static_load_N=float(a.static_load_N + dj)) for a, dj in zip(u.axles, d))
        units.append(dataclasses.replace(u, axles=axles))
    return dataclasses.replace(vehicle, units=tuple(units))


def has_static_loads(vehicle: Vehicle) -> bool:
    """Whether every axle has ``static_load_N`` (the loads can follow the masses)."""
    return all(a.static_load_N is not None for a in vehicle.axles)


def _index(vehicle: Vehicle, unit: str | int) -> int:
    if isinstance(unit, int):
        return unit
    if unit not in vehicle.unit_names:
        raise KeyError(f"unknown unit {unit!r}; units: {', '.join(vehicle.unit_names)}")
    return vehicle.unit_names.index(unit)


def with_mass(vehicle: Vehicle, unit: str | int, mass_kg: float) -> Vehicle:
    """``vehicle`` with the mass of ``unit`` [kg] changed at its CG, the static axle loads moved
    with it by statics (unchanged when the vehicle has none).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> v = load_vehicle("examples/vehicles/b_double.toml")
    >>> w = with_mass(v, 0, v.units[0].mass_kg + 1000.0)
    >>> round(sum(a.static_load_N for a in w.axles) - sum(a.static_load_N for a in v.axles), 6)
    9806.65
    """
    k = _index(vehicle, unit)
    u = vehicle.units[k]
    changed = dataclasses.replace(vehicle, units=tuple(dataclasses.replace(x, mass_kg=float(mass_kg)) if i == k else x
                                                      for i, x in enumerate(vehicle.units)))
    if not has_static_loads(vehicle):
        return changed
    return _with_loads(changed, load_changes(vehicle, k, (float(mass_kg) - u.mass_kg) * G_MPS2, 0.0))


def with_payload(vehicle: Vehicle, unit: str | int, payload_kg: float, x_m: float = 0.0,
                 height_m: float | None = None, length_m: float = 0.0) -> Vehicle:
    """``vehicle`` with a payload of ``payload_kg`` on ``unit`` at ``x_m`` [m] from its CG and
    ``height_m`` above ground (default its CG height), a point mass or (``length_m`` > 0) a uniform
    block that long: the unit's mass, CG (every position of the unit then from the new CG), yaw
    inertia and roll data by the parallel-axis theorem, the static axle loads by statics (see the
    module docstring).

    Raises
    ------
    StaticsError
        A unit without a second support.

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> v = load_vehicle("examples/vehicles/b_double.toml")
    >>> w = with_payload(v, "rear_trailer", 5000.0, x_m=1.0)
    >>> m, p = v.units[2].mass_kg, 5000.0          # the CG moves p x / (m + p) forward: every x back by it
    >>> round((v.units[2].axles[0].x_m - w.units[2].axles[0].x_m) * (m + p) / p, 12)
    1.0
    """
    k = _index(vehicle, unit)
    u = vehicle.units[k]
    p, xp = float(payload_kg), float(x_m)
    m = u.mass_kg
    dx = p * xp / (m + p)                                          # the new CG, from the old
    inertia = u.yaw_inertia_kg_m2 + m * dx ** 2 + p * (xp - dx) ** 2 + p * float(length_m) ** 2 / 12.0
    fields = {"mass_kg": m + p, "yaw_inertia_kg_m2": inertia}
    for name in ("front_coupling_m", "rear_coupling_m", "rear_end_m", "body_front_m", "body_rear_m"):
        value = getattr(u, name, None)
        if value is not None:
            fields[name] = value - dx
    fields["axles"] = tuple(dataclasses.replace(a, x_m=a.x_m - dx) for a in u.axles)
    if u.cg_height_m is not None:
        hp = u.cg_height_m if height_m is None else float(height_m)
        ms = m - sum(a.unsprung_mass_kg or 0.0 for a in u.axles)
        h_new = (ms * u.cg_height_m + p * hp) / (ms + p)
        fields["cg_height_m"] = h_new
        if u.roll_inertia_kg_m2 is not None:
            fields["roll_inertia_kg_m2"] = (u.roll_inertia_kg_m2 + ms * (u.cg_height_m - h_new) ** 2
                                            + p * (hp - h_new) ** 2)
        # I_xz = sum x z dm about the CG, z down: the sprung mass's CG at (-dx, -(h - h_new)) from the
        # new CG, the payload's at (xp - dx, -(hp - h_new))
        ixz = u.yaw_roll_product_kg_m2 or 0.0
        fields["yaw_roll_product_kg_m2"] = (ixz + ms * (-dx) * (-(u.cg_height_m - h_new))
                                            + p * (xp - dx) * (-(hp - h_new)))
    loaded = dataclasses.replace(vehicle, units=tuple(dataclasses.replace(x, **fields) if i == k else x
                                                     for i, x in enumerate(vehicle.units)))
    if not has_static_loads(vehicle):
        return loaded
    return _with_loads(loaded, load_changes(vehicle, k, p * G_MPS2, xp))


def loads_of_masses(vehicle: Vehicle) -> Vehicle:
    """``vehicle`` with the static axle loads its masses give by statics (every unit's weight at
    its CG, passed to its supports as :func:`load_changes` does, a group's axles sharing equally):
    loads and masses that agree exactly, and no coupling that pulls up -- for a vehicle whose
    published loads belong to another configuration (a triple's, truncated to a double).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> v = loads_of_masses(load_vehicle("examples/vehicles/b_double.toml"))
    >>> round(sum(a.static_load_N for a in v.axles) / (G_MPS2 * sum(u.mass_kg for u in v.units)), 12)
    1.0
    """
    zero = dataclasses.replace(vehicle, units=tuple(dataclasses.replace(u, axles=tuple(
        dataclasses.replace(a, static_load_N=0.0) for a in u.axles)) for u in vehicle.units))
    total = [np.zeros(len(u.axles)) for u in vehicle.units]
    for k, u in enumerate(vehicle.units):
        for t, d in zip(total, load_changes(zero, k, u.mass_kg * G_MPS2, 0.0)):
            t += d
    return _with_loads(zero, total)


def coupling_loads(vehicle: Vehicle) -> np.ndarray:
    """The static vertical load of every coupling [N], front to rear: what unit k carries of the
    units behind joint k, ``sum_(i>k) m_i g - sum F_z0`` of the axles behind it (docs/roll.md)."""
    n = vehicle.n_units
    out = np.zeros(n - 1)
    for k in range(n - 1):
        behind = vehicle.units[k + 1:]
        out[k] = G_MPS2 * sum(u.mass_kg for u in behind) - sum(a.static_load_N for u in behind for a in u.axles)
    return out
