"""The body of every unit: what a combination looks like from above, for the models that
need more than axles and couplings (the low-speed turn) and for the drawings.

A unit's body is its vehicle file's ``body_front_m``, ``body_rear_m``, ``body_width_m`` (x
from its CG, forward positive) where given; the drawings guess an outline from the axles
and couplings where not (:func:`body_extent`).  The low-speed turn needs the keys
(:func:`corners`, :func:`overall_length_m`; :class:`TurnError` names a missing one).

Examples
--------
>>> from lcvreport import load_preset
>>> v = load_preset("aucnat")
>>> [unit_kind(v, k) for k in range(v.n_units)]
['tractor', 'trailer', 'dolly', 'trailer', 'dolly', 'trailer']
>>> round(overall_length_m(v), 2)
29.15
"""
from __future__ import annotations

import math

import numpy as np

from ..units import M_PER_IN
from .vehicle import Vehicle


class TurnError(ValueError):
    """Geometry the turn needs is missing or invalid; the message names the unit/axle and key."""


def overall_length_m(vehicle: Vehicle) -> float:
    """Front of the first body to the rear of the rearmost, straight [m] (needs the body keys)."""
    need_bodies(vehicle)
    x0, lo, hi = 0.0, math.inf, -math.inf
    for k, u in enumerate(vehicle.units):
        if k > 0:
            prev = vehicle.units[k - 1]
            x0 = x0 + prev.rear_coupling_m - u.front_coupling_m
        hi = max(hi, x0 + u.body_front_m)
        lo = min(lo, x0 + u.body_rear_m)
    return hi - lo


def need_bodies(vehicle: Vehicle) -> None:
    for k, u in enumerate(vehicle.units):
        for key in ("body_front_m", "body_rear_m", "body_width_m"):
            if getattr(u, key) is None:
                raise TurnError(f'units[{k}] "{u.name}": missing key {key!r} (the low-speed turn needs every '
                                "unit's body_front_m, body_rear_m, body_width_m and every axle's track_width_m)")


def need_tracks(vehicle: Vehicle) -> None:
    for k, u in enumerate(vehicle.units):
        for j, a in enumerate(u.axles):
            if a.track_width_m is None:
                raise TurnError(f'units[{k}] "{u.name}" axles[{j}] "{a.name}": missing key \'track_width_m\' '
                                "(the low-speed turn needs every axle's track_width_m)")


def corners(vehicle: Vehicle, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Body corners of unit ``k`` in unit coordinates: x [front, front, rear, rear], y
    [left, right, right, left] [m]."""
    u = vehicle.units[k]
    h = u.body_width_m / 2
    return np.array([u.body_front_m, u.body_front_m, u.body_rear_m, u.body_rear_m]), np.array([h, -h, -h, h])


#: drawing dimensions [m] (drawing only; the yaw-plane model has no widths): 72 in track,
#: 102 in body width (the trailer width quoted in chapter V), 96 in cab, 30 in front overhang
TRACK_WIDTH_M = 72 * M_PER_IN


BODY_WIDTH_M = 102 * M_PER_IN


CAB_WIDTH_M = 96 * M_PER_IN


FRONT_OVERHANG_M = 30 * M_PER_IN


#: a unit shorter than this from its front coupling to its rearmost point is drawn as a dolly [m]
DOLLY_LENGTH_M = 3.0


#: a unit this light whose rear coupling sits over its axles is drawn as a (drawbar) dolly [kg]
DOLLY_MASS_KG = 4000.0


# ------------------------------------------------------------------ top views
def unit_kind(vehicle: Vehicle, k: int) -> str:
    """``tractor`` (first unit), ``dolly`` or ``trailer``: how a unit is drawn.

    A dolly is short coupled (front coupling to rear within :data:`DOLLY_LENGTH_M`: a
    converter dolly), or a light unit (at most :data:`DOLLY_MASS_KG`) with a unit behind it
    whose coupling sits over its axles (within 1 m: a full trailer's drawbar dolly)."""
    if k == 0:
        return "tractor"
    u = vehicle.units[k]
    rear = min(vehicle.rear_end_x_m(k), u.rearmost_axle.x_m)
    if u.front_coupling_m - rear < DOLLY_LENGTH_M:
        return "dolly"
    axle_x = sum(a.x_m for a in u.axles) / len(u.axles)
    if u.rear_coupling_m is not None and abs(u.rear_coupling_m - axle_x) <= 1.0 and u.mass_kg <= DOLLY_MASS_KG:
        return "dolly"
    return "trailer"


def unit_poses(vehicle: Vehicle, theta: np.ndarray | None = None) -> list[tuple[np.ndarray, float]]:
    """CG position [m] and heading [rad] of every unit, first unit's CG at the origin heading +x.

    ``theta`` are the articulation angles [rad]; headings follow psi_(k+1) = psi_k - theta_k.
    """
    theta = np.zeros(vehicle.n_units - 1) if theta is None else np.asarray(theta, dtype=float)
    poses = []
    for k, unit in enumerate(vehicle.units):
        if k == 0:
            cg, psi = np.zeros(2), 0.0
        else:
            prev_cg, prev_psi = poses[-1]
            joint = prev_cg + vehicle.units[k - 1].rear_coupling_m * direction(prev_psi)
            psi = prev_psi - theta[k - 1]
            cg = joint - unit.front_coupling_m * direction(psi)
        poses.append((cg.copy(), psi))
    return poses


def direction(psi: float) -> np.ndarray:
    return np.array([np.cos(psi), np.sin(psi)])


def body_rectangle(center: np.ndarray, psi: float, front: float, rear: float, half_width: float) -> np.ndarray:
    d = direction(psi)
    n = np.array([-d[1], d[0]])
    return np.array([center + front * d + half_width * n, center + front * d - half_width * n,
                     center + rear * d - half_width * n, center + rear * d + half_width * n])


def body_extent(vehicle: Vehicle, k: int) -> tuple[float, float, float]:
    """(front x, rear x, half width) of the drawn body of unit ``k`` [m, signed x from its CG]:
    the vehicle file's ``body_front_m``, ``body_rear_m``, ``body_width_m`` where given, else
    an outline guessed from the axles and couplings."""
    u = vehicle.units[k]
    if u.body_front_m is not None and u.body_width_m is not None:
        return u.body_front_m, u.body_rear_m, u.body_width_m / 2
    xs = [a.x_m for a in u.axles]
    kind = unit_kind(vehicle, k)
    if kind == "tractor":
        rear = min(min(xs) - 0.61, u.rear_coupling_m - 0.3 if u.rear_coupling_m is not None else np.inf)
        if u.rear_end_m is not None:
            rear = min(rear, u.rear_end_m)
        return max(xs) + FRONT_OVERHANG_M, rear, CAB_WIDTH_M / 2
    if kind == "dolly":     # the frame over the axles; the drawbar to the front coupling is drawn apart
        return max(xs) + 0.61, min(min(xs), vehicle.rear_end_x_m(k)) - 0.61, TRACK_WIDTH_M / 2 + 0.15
    return u.front_coupling_m + 0.76, min(vehicle.rear_end_x_m(k), min(xs) - 0.6), BODY_WIDTH_M / 2
