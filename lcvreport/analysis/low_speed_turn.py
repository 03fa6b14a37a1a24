"""The low-speed 90-degree turn and its measures (SPEC section 16), on the kinematic model
of :mod:`lcvreport.model.low_speed`.

The combination runs straight and aligned up to the turn; the **outside wheel of the
steered axle** then runs on a circle of ``radius_m`` (12.5 m) through ``angle_deg`` (90)
-- the axle centre at radius - track/2 -- and a straight exit of 3 overall lengths lets
every unit realign.  The turn is to the left; the measures are the same to the right.

Measures [m]:

``lssp_m``
    swept width: the largest distance from the arc's centre reached by any body corner or
    outside wheel, less the smallest reached by any point of a body's inner side or an
    inside wheel, counting positions within the arc's sector;
``low_speed_offtracking_m``
    the steered axle centre's path radius less the smallest radius of the last unit's
    rearmost axle centre within the sector;
``tail_swing_m``
    per unit, the largest outward displacement of its rear outer body corner beyond the
    straight line it ran on before the turn (0 if it never crosses it); ``max_tail_swing_m``
    the largest;
``frontal_swing_m``
    the largest distance of unit 1's front outer body corner outside the outside steer
    wheel's circle, within the sector.

A wheel is the centre of the outermost tire (track_width_m / 2 from the axle centre).
Positions are sampled every :data:`SAMPLE_M` of path and each extreme refined on the
integrator's dense output (bounded scalar minimization), so the measures carry the
integration's accuracy, not the sampling's.

Examples
--------
>>> from lcvreport import load_vehicle
>>> t = low_speed_turn(load_vehicle("examples/vehicles/b_double.toml"))
>>> round(t.lssp_m, 2), round(t.low_speed_offtracking_m, 2)
(9.03, 6.04)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..model.low_speed import KinematicsError, KinematicRun, StraightArcPath, integrate
from ..model.vehicle import Vehicle

#: the turn of the field's low-speed test: outside steer wheel radius [m] and angle [deg]
RADIUS_M = 12.5
ANGLE_DEG = 90.0
#: exit straight, in overall lengths
EXIT_LENGTHS = 3.0
#: sampling of the path for the extremes [m] (each extreme then refined)
SAMPLE_M = 0.05


class TurnError(ValueError):
    """Geometry the turn needs is missing or invalid; the message names the unit/axle and key."""


def overall_length_m(vehicle: Vehicle) -> float:
    """Front of the first body to the rear of the rearmost, straight [m] (needs the body keys)."""
    _need_bodies(vehicle)
    x0, lo, hi = 0.0, math.inf, -math.inf
    for k, u in enumerate(vehicle.units):
        if k > 0:
            prev = vehicle.units[k - 1]
            x0 = x0 + prev.rear_coupling_m - u.front_coupling_m
        hi = max(hi, x0 + u.body_front_m)
        lo = min(lo, x0 + u.body_rear_m)
    return hi - lo


def _need_bodies(vehicle: Vehicle) -> None:
    for k, u in enumerate(vehicle.units):
        for key in ("body_front_m", "body_rear_m", "body_width_m"):
            if getattr(u, key) is None:
                raise TurnError(f'units[{k}] "{u.name}": missing key {key!r} (the low-speed turn needs every '
                                "unit's body_front_m, body_rear_m, body_width_m and every axle's track_width_m)")


def _need_tracks(vehicle: Vehicle) -> None:
    for k, u in enumerate(vehicle.units):
        for j, a in enumerate(u.axles):
            if a.track_width_m is None:
                raise TurnError(f'units[{k}] "{u.name}" axles[{j}] "{a.name}": missing key \'track_width_m\' '
                                "(the low-speed turn needs every axle's track_width_m)")


def check_turn_geometry(vehicle: Vehicle) -> None:
    """Every key the turn needs is there and the model can pull the vehicle.

    Raises
    ------
    TurnError
        Naming the unit (and axle) and the key.
    """
    _need_bodies(vehicle)
    _need_tracks(vehicle)
    try:
        from ..model.low_speed import unit_geometry
        unit_geometry(vehicle)
    except KinematicsError as exc:
        raise TurnError(str(exc)) from None


@dataclass(frozen=True)
class LowSpeedTurn:
    """A low-speed turn and its measures [m] (SPEC section 16)."""

    vehicle: Vehicle
    radius_m: float
    angle_deg: float
    lssp_m: float
    low_speed_offtracking_m: float
    tail_swing_m: dict
    frontal_swing_m: float
    overall_length_m: float
    run: KinematicRun = field(repr=False)
    where: dict = field(repr=False, default_factory=dict)

    @property
    def max_tail_swing_m(self) -> float:
        return max(self.tail_swing_m.values())

    @property
    def steer_axle_radius_m(self) -> float:
        """Radius of the steered axle centre's path [m]."""
        return self.run.path.radius_m

    def to_dict(self) -> dict:
        """The JSON of ``lcv turn`` (SI)."""
        return {"radius_m": self.radius_m, "angle_deg": self.angle_deg, "lssp_m": self.lssp_m,
                "low_speed_offtracking_m": self.low_speed_offtracking_m, "tail_swing_m": dict(self.tail_swing_m),
                "max_tail_swing_m": self.max_tail_swing_m, "frontal_swing_m": self.frontal_swing_m,
                "overall_length_m": self.overall_length_m, "steer_axle_radius_m": self.steer_axle_radius_m}

    def rows(self) -> list[dict]:
        """The measures as a table."""
        rows = [{"measure": "swept width (low-speed swept path)", "json_key": "lssp_m", "value_m": self.lssp_m},
                {"measure": "low-speed offtracking", "json_key": "low_speed_offtracking_m",
                 "value_m": self.low_speed_offtracking_m},
                {"measure": "frontal swing of unit 1", "json_key": "frontal_swing_m", "value_m": self.frontal_swing_m}]
        rows += [{"measure": f"tail swing of {name}", "json_key": f"tail_swing_m.{name}", "value_m": val}
                 for name, val in self.tail_swing_m.items()]
        return rows

    def plot(self, title: str | None = None, outlines_every_m: float = 2.0):
        """The swept path seen from above, to scale (:func:`lcvreport.report.plotting.fig_swept_path`)."""
        from ..report.plotting import fig_swept_path
        return fig_swept_path(self, title or f"{self.vehicle.name}: low-speed {self.angle_deg:g} deg turn, outside "
                              f"steer wheel on R = {self.radius_m:g} m", outlines_every_m)


def corners(vehicle: Vehicle, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Body corners of unit ``k`` in unit coordinates: x [front, front, rear, rear], y
    [left, right, right, left] [m]."""
    u = vehicle.units[k]
    h = u.body_width_m / 2
    return np.array([u.body_front_m, u.body_front_m, u.body_rear_m, u.body_rear_m]), np.array([h, -h, -h, h])


def _sector_mask(points: np.ndarray, centre: np.ndarray, angle_rad: float) -> np.ndarray:
    """Points whose direction from the arc's centre is within the turn's sector."""
    rel = points - centre
    phi = np.arctan2(rel[..., 0], -rel[..., 1])          # 0 at the turn's start, growing with the turn
    if angle_rad >= 2 * math.pi:
        return np.ones(phi.shape, dtype=bool)
    return (phi >= -1e-12) & (phi <= angle_rad + 1e-12)


def _refine(fun, s_grid: np.ndarray, values: np.ndarray, k: int, sign: float) -> tuple[float, float]:
    """Refine the extreme of ``fun`` near sample ``k`` (sign +1: maximum, -1: minimum) on the
    dense output; the sample itself where a neighbour is outside the sector or the path."""
    from scipy.optimize import minimize_scalar
    if 0 < k < len(s_grid) - 1 and np.isfinite(values[k - 1]) and np.isfinite(values[k + 1]):
        res = minimize_scalar(lambda s: -sign * fun(s), bounds=(s_grid[k - 1], s_grid[k + 1]), method="bounded",
                              options={"xatol": 1e-9})
        if np.isfinite(res.fun) and sign * (-sign * res.fun) >= sign * values[k]:
            return float(-sign * res.fun), float(res.x)
    return float(values[k]), float(s_grid[k])


def low_speed_turn(vehicle: Vehicle, radius_m: float = RADIUS_M, angle_deg: float = ANGLE_DEG,
                   rtol: float = 1e-10, atol: float = 1e-12) -> LowSpeedTurn:
    """The low-speed turn of ``vehicle`` and its measures.

    Parameters
    ----------
    vehicle : Vehicle
        With every unit's body keys and every axle's track width (SPEC section 16).
    radius_m : float
        Radius of the outside steer wheel's path [m], in (track/2, 100].
    angle_deg : float
        Angle of the turn [deg], in (0, 360].
    rtol, atol : float
        Tolerances of the heading integration.

    Returns
    -------
    LowSpeedTurn

    Raises
    ------
    TurnError
        Missing or invalid geometry, a radius the steered axle cannot follow.
    """
    check_turn_geometry(vehicle)
    if not (math.isfinite(angle_deg) and 0 < angle_deg <= 3600):
        raise TurnError(f"angle_deg must be in (0, 3600], got {angle_deg!r}")
    u1 = vehicle.units[0]
    steer = max((a for a in u1.axles if a.steered), key=lambda a: a.x_m)
    half_track = steer.track_width_m / 2
    if not (math.isfinite(radius_m) and half_track < radius_m <= 100.0):
        raise TurnError(f"radius must be in ({half_track:g}, 100] m (the outside wheel of axle {steer.name} is "
                        f"{half_track:g} m from its centre), got {radius_m!r}")
    length = overall_length_m(vehicle)
    angle = math.radians(angle_deg)
    R_axle = radius_m - half_track
    path = StraightArcPath(R_axle, angle, EXIT_LENGTHS * length)
    run = integrate(vehicle, path, np.zeros(vehicle.n_units), rtol, atol)
    centre = path.centre
    n_s = max(int(math.ceil(path.s_end / SAMPLE_M)), 200) + 1
    s = np.linspace(0.0, path.s_end, n_s)

    def radius(points):
        return np.hypot(points[..., 0] - centre[0], points[..., 1] - centre[1])

    # the outermost and innermost things at every sample, with what reached them
    outer_fns, inner_fns = [], []
    for k, u in enumerate(vehicle.units):
        cx, cy = corners(vehicle, k)
        outer_fns.append((f"{u.name} body corners", lambda ss, k=k, cx=cx, cy=cy: run.unit_points(ss, k, cx, cy)))
        for a in u.axles:
            h = a.track_width_m / 2
            outer_fns.append((f"{u.name} axle {a.name} outside wheel",
                              lambda ss, k=k, x=a.x_m, h=h: run.unit_points(ss, k, [x], [-h])))
            inner_fns.append((f"{u.name} axle {a.name} inside wheel",
                              lambda ss, k=k, x=a.x_m, h=h: run.unit_points(ss, k, [x], [h]), None))
        inner_fns.append((f"{u.name} body inner side",
                          lambda ss, k=k, u=u: run.unit_points(ss, k, [u.body_front_m, u.body_rear_m],
                                                               [u.body_width_m / 2] * 2), "segment"))

    def outer_value(fn, ss):
        pts = fn(np.atleast_1d(ss))
        r = np.where(_sector_mask(pts, centre, angle), radius(pts), -np.inf)
        return r.max(axis=1)

    def inner_value(fn, kind, ss):
        pts = fn(np.atleast_1d(ss))
        if kind == "segment":              # the closest point of the side to the centre
            a, b = pts[:, 0], pts[:, 1]
            ab = b - a
            t = np.clip(np.einsum("ij,ij->i", centre - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
            pts = (a + t[:, None] * ab)[:, None, :]
        r = np.where(_sector_mask(pts, centre, angle), radius(pts), np.inf)
        return r.min(axis=1)

    best_out, where_out = -np.inf, ""
    for name, fn in outer_fns:
        vals = outer_value(fn, s)
        k = int(np.argmax(vals))
        if np.isfinite(vals[k]):
            val, _ = _refine(lambda x: float(outer_value(fn, x)[0]), s, vals, k, +1.0)
            if val > best_out:
                best_out, where_out = val, name
    best_in, where_in = np.inf, ""
    for name, fn, kind in inner_fns:
        vals = inner_value(fn, kind, s)
        k = int(np.argmin(vals))
        if np.isfinite(vals[k]):
            val, _ = _refine(lambda x: float(inner_value(fn, kind, x)[0]), s, vals, k, -1.0)
            if val < best_in:
                best_in, where_in = val, name
    # low-speed offtracking: the last unit's rearmost axle centre
    last = vehicle.n_units - 1
    rear_x = vehicle.units[last].rearmost_axle.x_m

    def rear_axle_radius(ss):
        pts = run.unit_points(np.atleast_1d(ss), last, [rear_x], [0.0])
        return np.where(_sector_mask(pts, centre, angle), radius(pts), np.inf)[:, 0]
    vals = rear_axle_radius(s)
    k = int(np.argmin(vals))
    r_min, _ = _refine(lambda x: float(rear_axle_radius(x)[0]), s, vals, k, -1.0)
    offtracking = R_axle - r_min
    # tail swing: rear outer (right) corner beyond its approach line Y = its initial Y
    tail = {}
    for k_u, u in enumerate(vehicle.units):
        y0 = run.unit_points([0.0], k_u, [u.body_rear_m], [-u.body_width_m / 2])[0, 0, 1]

        def outward(ss, k_u=k_u, u=u, y0=y0):
            return y0 - run.unit_points(np.atleast_1d(ss), k_u, [u.body_rear_m], [-u.body_width_m / 2])[:, 0, 1]
        vals = outward(s)
        k = int(np.argmax(vals))
        val, _ = _refine(lambda x: float(outward(x)[0]), s, vals, k, +1.0)
        tail[u.name] = max(0.0, val)
    # frontal swing: unit 1's front outer (right) corner outside the outside wheel's circle
    def front_out(ss):
        pts = run.unit_points(np.atleast_1d(ss), 0, [u1.body_front_m], [-u1.body_width_m / 2])
        return np.where(_sector_mask(pts, centre, angle), radius(pts), -np.inf)[:, 0] - radius_m
    vals = front_out(s)
    k = int(np.argmax(vals))
    frontal = max(0.0, _refine(lambda x: float(front_out(x)[0]), s, vals, k, +1.0)[0]) if np.isfinite(vals[k]) \
        else 0.0
    return LowSpeedTurn(vehicle, float(radius_m), float(angle_deg), float(best_out - best_in), float(offtracking),
                        tail, float(frontal), float(length), run,
                        {"outermost": where_out, "innermost": where_in, "outer_radius_m": float(best_out),
                         "inner_radius_m": float(best_in)})
