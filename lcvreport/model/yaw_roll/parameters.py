r"""The roll data of a vehicle, checked and in arrays: what the yaw-roll model and the static
rollover threshold are computed from (docs/roll.md).

Every roll key is optional in a vehicle file and required here: a missing one is a
:class:`~lcvreport.model.vehicle.VehicleError` naming the unit, the axle and the key.  Per unit
``i``: the sprung mass ``m_s = mass_kg - sum(unsprung_mass_kg)``, ``e = h - h_r``; per joint
``k``: the coupling height ``h_c``, roll stiffness ``k_c`` and the static vertical coupling load
``W_k = sum_(i>k) m_i g - sum F_z0`` of the axles behind joint k; per axle: ``K``, ``C``,
``m_u``, ``F_z0`` and the load-transfer track ``T = track_width_m - dual_spacing_m``.  Roll-coupled
groups are the runs of units joined by couplings with ``k_c > 0``.

Examples
--------
>>> from lcvreport import load_vehicle
>>> rp = roll_parameters(load_vehicle("examples/vehicles/b_double.toml"))
>>> rp.groups                       # a B-double: one roll-coupled group
((0, 1, 2),)
>>> round(float(rp.e_m[0]), 3)
0.55
>>> from lcvreport import load_preset
>>> roll_parameters(load_preset("aucnat"))
Traceback (most recent call last):
...
lcvreport.model.vehicle.VehicleError: units[0] "tractor": missing roll key 'cg_height_m' (docs/roll.md): the yaw-roll model needs it
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..vehicle import Vehicle, VehicleError

#: standard gravity [m/s^2]
G_MPS2 = 9.80665
#: static loads and masses may disagree by this fraction before a warning
LOAD_BALANCE_TOLERANCE = 0.05


@dataclass(frozen=True, eq=False)
class RollParameters:
    """The checked roll data of one vehicle, SI (see the module docstring).

    Attributes
    ----------
    m_kg, ms_kg, e_m, h_m, hr_m, Ix_kg_m2, Ixz_kg_m2 : numpy.ndarray, shape (N,)
        Unit mass, sprung mass, CG above roll axis, CG height, roll-axis height, roll inertia
        about the sprung CG, yaw-roll product of inertia.
    hc_m, kc_Nm_per_rad, W_N : numpy.ndarray, shape (N-1,)
        Coupling height, coupling roll stiffness, static vertical coupling load.
    K_Nm_per_rad, C_Nms_per_rad, mu_kg, Fz0_N, T_m : numpy.ndarray, shape (n_axles,)
        Per axle, in :attr:`Vehicle.axles` order.
    axle_unit : numpy.ndarray of int, shape (n_axles,)
    groups : tuple of tuple of int
        Roll-coupled groups (0-based unit indices), front to rear.
    load_warning : str or None
        One line when the static loads and the masses disagree by more than 5 %.
    """

    m_kg: np.ndarray
    ms_kg: np.ndarray
    e_m: np.ndarray
    h_m: np.ndarray
    hr_m: np.ndarray
    Ix_kg_m2: np.ndarray
    Ixz_kg_m2: np.ndarray
    hc_m: np.ndarray
    kc_Nm_per_rad: np.ndarray
    W_N: np.ndarray
    K_Nm_per_rad: np.ndarray
    C_Nms_per_rad: np.ndarray
    mu_kg: np.ndarray
    Fz0_N: np.ndarray
    T_m: np.ndarray
    axle_unit: np.ndarray
    groups: tuple
    load_warning: str | None = None

    @property
    def group_of_unit(self) -> np.ndarray:
        """The group index of every unit, shape (N,)."""
        out = np.zeros(self.m_kg.size, dtype=int)
        for g, units in enumerate(self.groups):
            out[list(units)] = g
        return out


def _need(value, key: str, where: str):
    if value is None:
        raise VehicleError(key, f"missing roll key {key!r} (docs/roll.md): the yaw-roll model needs it", where)
    return float(value)


def has_roll_data(vehicle: Vehicle) -> bool:
    """Whether ``vehicle`` has every roll key (:func:`roll_parameters` would succeed)."""
    return missing_roll_data(vehicle) is None


def missing_roll_data(vehicle: Vehicle) -> str | None:
    """None when the vehicle's roll data is complete and valid, else the one line saying
    what is missing or wrong (unit, axle, key)."""
    try:
        roll_parameters(vehicle)
    except VehicleError as exc:
        return str(exc)
    return None


@lru_cache(maxsize=256)
def roll_parameters(vehicle: Vehicle) -> RollParameters:
    """The checked roll data of ``vehicle`` (cached per vehicle).

    Raises
    ------
    VehicleError
        A missing roll key, a load-transfer track ``track_width_m - dual_spacing_m <= 0``, a
        static load <= 0, naming the unit, the axle and the key.
    """
    n = vehicle.n_units
    m, ms, e, h, hr, Ix, Ixz = (np.zeros(n) for _ in range(7))
    hc, kc = np.zeros(n - 1), np.zeros(n - 1)
    K, C, mu, Fz0, T, au = [], [], [], [], [], []
    for i, u in enumerate(vehicle.units):
        where = f'units[{i}] "{u.name}"'
        h[i] = _need(u.cg_height_m, "cg_height_m", where)
        hr[i] = _need(u.roll_axis_height_m, "roll_axis_height_m", where)
        Ix[i] = _need(u.roll_inertia_kg_m2, "roll_inertia_kg_m2", where)
        Ixz[i] = 0.0 if u.yaw_roll_product_kg_m2 is None else u.yaw_roll_product_kg_m2
        if i < n - 1:
            hc[i] = _need(u.rear_coupling_height_m, "rear_coupling_height_m", where)
            kc[i] = _need(u.rear_coupling_roll_stiffness_Nm_per_rad, "rear_coupling_roll_stiffness_Nm_per_rad", where)
        unsprung = 0.0
        for j, a in enumerate(u.axles):
            awhere = f'{where} axles[{j}] "{a.name}"'
            K.append(_need(a.roll_stiffness_Nm_per_rad, "roll_stiffness_Nm_per_rad", awhere))
            C.append(_need(a.roll_damping_Nms_per_rad, "roll_damping_Nms_per_rad", awhere))
            mu.append(_need(a.unsprung_mass_kg, "unsprung_mass_kg", awhere))
            fz = _need(a.static_load_N, "static_load_N", awhere)
            if fz <= 0:
                raise VehicleError("static_load_N", f"static_load_N must be > 0 for roll (the load transfer ratio "
                                                    f"and the lift-off divide by it), got {fz:g} N", awhere)
            Fz0.append(fz)
            track = _need(a.track_width_m, "track_width_m", awhere)
            t = track - a.dual_spacing_m
            if t <= 0:
                raise VehicleError("track_width_m", f"the load-transfer track track_width_m - dual_spacing_m must be "
                                                    f"> 0, got {track:g} - {a.dual_spacing_m:g} = {t:g} m", awhere)
            T.append(t)
            au.append(i)
            unsprung += mu[-1]
        m[i] = u.mass_kg
        ms[i] = u.mass_kg - unsprung
        e[i] = h[i] - hr[i]
    Fz0a, aua = np.array(Fz0), np.array(au, dtype=int)
    W = np.array([G_MPS2 * m[k + 1:].sum() - Fz0a[aua > k].sum() for k in range(n - 1)])
    groups, start = [], 0
    for k in range(n - 1):
        if kc[k] == 0.0:
            groups.append(tuple(range(start, k + 1)))
            start = k + 1
    groups.append(tuple(range(start, n)))
    weight = G_MPS2 * m.sum()
    warning = None
    if abs(Fz0a.sum() - weight) > LOAD_BALANCE_TOLERANCE * weight:
        warning = (f"warning: {vehicle.name}: the static axle loads sum to {Fz0a.sum():.6g} N, the masses weigh "
                   f"{weight:.6g} N ({100 * (Fz0a.sum() / weight - 1):+.1f} %); the roll model uses both "
                   "(the lateral balance and the coupling loads)")
    arrays = [m, ms, e, h, hr, Ix, Ixz, hc, kc, W, np.array(K), np.array(C), np.array(mu), Fz0a, np.array(T), aua]
    for arr in arrays:
        arr.setflags(write=False)
    return RollParameters(*arrays, tuple(groups), warning)
