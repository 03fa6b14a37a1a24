"""The low-speed turn and its measures (docs/low_speed_turn.md), on the kinematic
model of :mod:`lcvreport.model.low_speed`.

The combination runs straight and aligned up to the turn; the **outside wheel of the frontmost
steered axle** then runs on a circle of ``radius_m`` (12.5 m) through ``angle_deg`` (90; any
angle in (0, 3600]), then a straight exit of 3 overall lengths lets every unit realign.  Unit
1 is pulled at that wheel (the axle is not radial while the tractor yaws, so its centre runs
on a larger radius than radius - track/2).  The turn is to the left; the measures are the
same to the right.

A position counts for the measures while its angle about the arc's centre -- **unwrapped
continuously** from the approach, 0 where the arc starts -- lies in [0, angle]: on a turn past
180 or 360 degrees nothing is lost or counted twice, and the exit never counts.  An extreme on
the sector's edge is located on the edge (the crossing found to 1e-12 m of path), an extreme
inside it on the integrator's dense output (bounded scalar minimization).

Measures [m]:

``lssp_m``
    swept width: the largest distance from the arc's centre reached by any body corner or
    outside wheel, less the smallest reached by any point of a body's inner side or an inside
    wheel, within the sector;
``low_speed_offtracking_m``
    the largest radius of the steered axle centre's path less the smallest radius of the last
    unit's rearmost axle centre, within the sector (on a long arc: the steady offtracking);
``tail_swing_m``
    per unit, the largest outward displacement of its rear outer body corner beyond the straight
    line it ran on before the turn (0 if it never crosses it), while the unit has turned less
    than a quarter turn (after that its approach line is no longer beside it); ``max_tail_swing_m``
    the largest;
``frontal_swing_m``
    the largest distance of unit 1's front outer body corner outside the outside steer wheel's
    circle, within the sector.

A measure no position defines (a turn so tight that the last axle passes round the arc's centre
and never enters the sector) is None, with the reason in ``undefined``.  A wheel is the centre
of the outermost tire (track_width_m / 2 from the axle centre).

Examples
--------
>>> from lcvreport import load_vehicle
>>> t = low_speed_turn(load_vehicle("examples/vehicles/b_double.toml"))
>>> round(t.lssp_m, 2), round(t.low_speed_offtracking_m, 2)
(9.07, 6.07)
"""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..manoeuvres.paths import StraightArcPath
from ..model.body import TurnError, need_bodies, need_tracks, corners, overall_length_m
from ..model.low_speed.kinematics import KinematicRun, KinematicsError, integrate
from ..model.vehicle import Vehicle
from ..util.cache import LRUCache
from ..util.threads import one_blas_thread
from .registry import MeasureCase


@functools.lru_cache(maxsize=64)
def low_speed_measures(vehicle: Vehicle, radius_m: float | None = None, angle_deg: float | None = None
                       ) -> tuple[dict, dict]:
    """The low-speed turn's measures of ``vehicle`` (docs/low_speed_turn.md) in the turn of
    ``radius_m`` [m] and ``angle_deg`` [deg] (default :data:`RADIUS_M`, :data:`ANGLE_DEG`;
    independent of speed and tire scale: cached per vehicle and turn) and, for each that is
    null, why: (values, reasons)."""
    from ..model.body import TurnError
    try:
        t = low_speed_turn(vehicle, RADIUS_M if radius_m is None else float(radius_m),
                           ANGLE_DEG if angle_deg is None else float(angle_deg))
    except TurnError as exc:
        return {}, {k: f"undefined: {exc}" for k in LOW_SPEED_KEYS}
    values = {"lssp_m": t.lssp_m, "low_speed_offtracking_m": t.low_speed_offtracking_m,
              "max_tail_swing_m": t.max_tail_swing_m, "frontal_swing_m": t.frontal_swing_m}
    return values, {k: f"undefined: {why}" for k, why in t.undefined.items()}


#: the low-speed measures' keys (a second model: computed per vehicle, cached)
LOW_SPEED_KEYS = ("lssp_m", "low_speed_offtracking_m", "max_tail_swing_m", "frontal_swing_m")


#: the turn of the field's low-speed test: outside steer wheel radius [m] and angle [deg]
RADIUS_M = 12.5


ANGLE_DEG = 90.0


#: exit straight, in overall lengths
EXIT_LENGTHS = 3.0


#: sampling of the path for the extremes [m] (each extreme then refined)
SAMPLE_M = 0.05


#: the largest articulation a turn's measures are given for [rad]: beyond a quarter turn between two
#: units the trailer jackknifes (couplings stop at 70-90 deg), and the vehicle cannot make the turn
JACKKNIFE_RAD = math.pi / 2


def check_turn_geometry(vehicle: Vehicle) -> None:
    """Every key the turn needs is there and the model can pull the vehicle.

    Raises
    ------
    TurnError
        Naming the unit (and axle) and the key.
    """
    need_bodies(vehicle)
    need_tracks(vehicle)
    try:
        from ..model.low_speed.kinematics import unit_geometry
        unit_geometry(vehicle)
    except KinematicsError as exc:
        raise TurnError(str(exc)) from None


@dataclass(frozen=True)
class LowSpeedTurn:
    """A low-speed turn and its measures [m] (docs/low_speed_turn.md); a None measure has its reason in
    ``undefined``."""

    vehicle: Vehicle
    radius_m: float
    angle_deg: float
    lssp_m: float | None
    low_speed_offtracking_m: float | None
    tail_swing_m: dict
    frontal_swing_m: float | None
    overall_length_m: float
    run: KinematicRun = field(repr=False)
    where: dict = field(repr=False, default_factory=dict)
    undefined: dict = field(default_factory=dict)

    @property
    def max_tail_swing_m(self) -> float | None:
        return max(self.tail_swing_m.values()) if self.tail_swing_m else None

    @property
    def steer_axle_radius_m(self) -> float | None:
        """The largest radius of the steered axle centre's path in the sector [m] (the steady
        radius on a long arc; the outside wheel runs on ``radius_m``); None with the measures."""
        r = self.where.get("steer_axle_radius_m", math.nan)
        return None if not math.isfinite(r) else r

    def to_dict(self) -> dict:
        """The JSON of ``lcv turn`` (SI); ``reasons`` names why a null measure is null."""
        return {"radius_m": self.radius_m, "angle_deg": self.angle_deg, "lssp_m": self.lssp_m,
                "low_speed_offtracking_m": self.low_speed_offtracking_m, "tail_swing_m": dict(self.tail_swing_m),
                "max_tail_swing_m": self.max_tail_swing_m, "frontal_swing_m": self.frontal_swing_m,
                "overall_length_m": self.overall_length_m, "steer_axle_radius_m": self.steer_axle_radius_m,
                "reasons": dict(self.undefined)}

    def rows(self) -> list[dict]:
        """The measures as a table."""
        rows = [{"measure": "swept width (low-speed swept path)", "json_key": "lssp_m", "value_m": self.lssp_m},
                {"measure": "low-speed offtracking", "json_key": "low_speed_offtracking_m",
                 "value_m": self.low_speed_offtracking_m},
                {"measure": "frontal swing of unit 1", "json_key": "frontal_swing_m", "value_m": self.frontal_swing_m}]
        rows += [{"measure": f"tail swing of {name}", "json_key": f"tail_swing_m.{name}", "value_m": val}
                 for name, val in self.tail_swing_m.items()]
        return rows

    def envelope(self, bins: int = 90) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The swept region within the turn's sector: (angles about the arc's centre [rad], the
        least and the largest radius reached in each of ``bins`` equal bins of angle [m]) -- every
        body corner, side and wheel, sampled along the path; a turn past 360 degrees is folded
        onto one lap.  What the swept-path figure draws (the drawing computes nothing)."""
        v, run = self.vehicle, self.run
        s = np.linspace(0.0, run.s_end, 1500 + int(run.s_end / 0.5))
        centre = run.path.centre
        angle = math.radians(self.angle_deg)
        edges = np.linspace(0.0, min(angle, 2 * math.pi), bins + 1)
        r_min, r_max = np.full(bins, np.inf), np.full(bins, -np.inf)
        for k, u in enumerate(v.units):
            cx, cy = corners(v, k)
            xs = np.concatenate([cx, np.linspace(u.body_front_m, u.body_rear_m, 12),
                                 np.linspace(u.body_front_m, u.body_rear_m, 12)])
            ys = np.concatenate([cy, np.full(12, u.body_width_m / 2), np.full(12, -u.body_width_m / 2)])
            for a in u.axles:
                xs = np.append(xs, [a.x_m, a.x_m])
                ys = np.append(ys, [a.track_width_m / 2, -a.track_width_m / 2])
            pts = run.unit_points(s, k, xs, ys)                              # (n_s, n_pts, 2)
            phi = _unwrapped(pts, centre, run.headings(s)[:, k])
            r = np.hypot(pts[..., 0] - centre[0], pts[..., 1] - centre[1])
            inside = (phi >= 0) & (phi <= angle)
            folded = np.where(angle > 2 * math.pi, np.mod(phi, 2 * math.pi), phi)
            idx = np.clip(np.digitize(folded, edges) - 1, 0, bins - 1)
            for b in range(bins):
                sel = inside & (idx == b)
                if sel.any():
                    r_min[b] = min(r_min[b], r[sel].min())
                    r_max[b] = max(r_max[b], r[sel].max())
        mid = 0.5 * (edges[1:] + edges[:-1])
        found = np.isfinite(r_min)
        return mid[found], r_min[found], r_max[found]

    def swing(self, which: str) -> dict:
        """The path of the corner a swing measure reads, for a close-up of it (what
        :func:`lcvreport.plotting.low_speed.fig_swing` draws): ``which`` ``"tail"`` -- the rear
        outer corner of the unit with the largest tail swing, its approach line and where it is
        farthest beyond it -- or ``"frontal"`` -- unit 1's front outer corner, the outside steer
        wheel's circle and where the corner is farthest outside it.  Keys: ``unit``, ``points``
        ((n, 2) [m], world X, Y), ``at`` (the farthest point [m]), ``value_m``, and ``line_y_m``
        (tail) or ``centre``, ``radius_m`` (frontal); empty when the measure is null."""
        v, run = self.vehicle, self.run
        if which == "tail":
            if not self.tail_swing_m:
                return {}
            name = max(self.tail_swing_m, key=self.tail_swing_m.get)
            k = v.unit_names.index(name)
            s_at, y0, s_end = self.where["tail_swing"][name]
            u = v.units[k]
            s = np.linspace(0.0, max(s_end, 1e-9), 600)
            pts = run.unit_points(s, k, [u.body_rear_m], [-u.body_width_m / 2])[:, 0]
            at = run.unit_points(np.array([s_at]), k, [u.body_rear_m], [-u.body_width_m / 2])[0, 0]
            return {"unit": name, "points": pts, "at": at, "value_m": self.tail_swing_m[name], "line_y_m": y0}
        if which == "frontal":
            if self.frontal_swing_m is None:
                return {}
            u = v.units[0]
            s = np.linspace(0.0, run.s_end, 1500)
            pts = run.unit_points(s, 0, [u.body_front_m], [-u.body_width_m / 2])[:, 0]
            at = run.unit_points(np.array([self.where["frontal_swing_s"]]), 0, [u.body_front_m],
                                 [-u.body_width_m / 2])[0, 0]
            return {"unit": u.name, "points": pts, "at": at, "value_m": self.frontal_swing_m,
                    "centre": np.asarray(run.path.centre, dtype=float), "radius_m": self.radius_m,
                    "angle_deg": self.angle_deg}
        raise ValueError(f"which must be tail or frontal, got {which!r}")

    def plot(self, title: str | None = None, outlines_every_m: float = 2.0):
        """The swept path seen from above, to scale (:func:`lcvreport.plotting.low_speed.fig_swept_path`)."""
        from ..plotting.low_speed import fig_swept_path
        return fig_swept_path(self, title or f"{self.vehicle.name}: low-speed {self.angle_deg:g} deg turn, outside "
                              f"steer wheel on R = {self.radius_m:g} m", outlines_every_m)


def _raw_angle(points: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """Angle of points about the arc's centre, 0 at the arc's start, growing with the turn (in (-pi, pi])."""
    rel = points - centre
    return np.arctan2(rel[..., 0], -rel[..., 1])


def _unwrapped(points: np.ndarray, centre: np.ndarray, heading) -> np.ndarray:
    """The angle of points of one unit about the arc's centre, unwrapped with the turn: of the
    values of the angle (2 pi apart), the one nearest the unit's heading (its own turning from
    the approach, continuous and growing with the turn).  For a point going round the centre
    with the turn this is its continuous unwrapping from the approach; a point of a unit that
    cuts inside so far that its path does not enclose the centre (a long trailer on a tight
    circle) is still counted by how far the unit has turned, so it never re-enters the sector
    from the exit straight.  ``heading`` broadcasts against the points' leading axes."""
    raw = _raw_angle(points, centre)
    h = np.asarray(heading, dtype=float)
    h = h.reshape(h.shape + (1,) * (raw.ndim - h.ndim))
    return raw + 2 * np.pi * np.round((h - raw) / (2 * np.pi))


@dataclass
class _Probe:
    """One point of the vehicle followed along the path: ``points(s)`` -> (len(s), 2) world
    positions; ``heading(s)`` its unit's heading [rad], which fixes how its angle about the
    arc's centre is unwrapped."""

    name: str
    points: object
    heading: object


#: points per level of the refinement of an extreme or an edge crossing on the dense output
#: (each level one vectorized evaluation; the bracket shrinks by half this per level)
REFINE_POINTS = 513
#: levels: an interior extreme's bracket of two grid steps (0.1 m) shrinks to 6e-9 m in s (the
#: value's error is its curvature times the square of that), an edge crossing's to 4e-7 m and is
#: then interpolated linearly in the unwrapped angle (error ~ curvature x 4e-7^2)
EXTREME_LEVELS, EDGE_LEVELS = 3, 2
#: how far below the best grid value another point's grid value may lie and still be refined [m]:
#: the grid's value (the sector's edges interpolated linearly) is within max|f''| h^2 / 8 of the
#: refined one over the grid step h = SAMPLE_M; measured on every preset and example at 90, 180,
#: 360 and 1440 deg (1558 refinements): at most 9.8e-5 m -- the margin is 127 times that
MARGIN_M = 0.0125


def _best_of(probes, value, sign: float, s, centre, lo: float, hi: float):
    """The extreme over ``probes`` (each ``(probe, name)``) as ``(value, s, name)`` or None: every
    probe's grid extreme, then only those within :data:`MARGIN_M` of the best refined."""
    grid = [(r, p, name) for p, name in probes if (r := _extreme(p, value, sign, s, centre, lo, hi, refine=False))]
    if not grid:
        return None
    top = max(sign * r[0] for r, _p, _n in grid)
    found = [(_extreme(p, value, sign, s, centre, lo, hi), name) for r, p, name in grid
             if sign * r[0] >= top - MARGIN_M]
    return max(((r[0], r[1], name) for r, name in found if r), key=lambda r: sign * r[0])


def _extreme(probe: _Probe, value, sign: float, s: np.ndarray, centre: np.ndarray, lo: float, hi: float,
             refine: bool = True):
    """The largest (``sign`` +1) or smallest (-1) of ``value(points)`` over the positions of
    ``probe`` whose unwrapped angle lies in [lo, hi]: interior extremes refined on the dense
    output, extremes on the sector's edges located on the edge.  None if no position is in it.
    Every refinement is a few vectorized evaluations (a fine grid in the bracket, zoomed), not a
    scalar search; ``refine=False``: the grid's extreme only (a bound within :data:`MARGIN_M`).

    Returns
    -------
    (value, s) or None
    """
    pts = probe.points(s)
    phi = _unwrapped(pts, centre, probe.heading(s))
    vals = value(pts)
    inside = (phi >= lo) & (phi <= hi)
    if not inside.any():
        return None

    def phis(xs):
        return _unwrapped(probe.points(xs), centre, probe.heading(xs))

    best = None

    def offer(v, x):
        nonlocal best
        if best is None or sign * v > sign * best[0]:
            best = (v, x)
    k = np.flatnonzero(inside)
    runs = np.split(k, np.flatnonzero(np.diff(k) > 1) + 1)
    for run in runs:
        i0, i1 = int(run[0]), int(run[-1])
        j = i0 + int(np.argmax(sign * vals[i0:i1 + 1]))
        offer(float(vals[j]), float(s[j]))
        if not refine:                               # the edges' values interpolated on the grid
            for a_i, b_i, inner in ((i0 - 1, i0, i0), (i1, i1 + 1, i1)):
                if a_i < 0 or b_i >= s.size:
                    continue
                out = a_i if inner == b_i else b_i
                edge = lo if phi[out] < lo else hi
                w = (edge - phi[a_i]) / (phi[b_i] - phi[a_i]) if phi[b_i] != phi[a_i] else 0.0
                offer(float(vals[a_i] + w * (vals[b_i] - vals[a_i])), float(s[a_i] + w * (s[b_i] - s[a_i])))
            continue
        if i0 < j < i1:                              # inside the sector: refine between the neighbours
            a, b = float(s[j - 1]), float(s[j + 1])
            for _level in range(EXTREME_LEVELS):
                xs = np.linspace(a, b, REFINE_POINTS)
                p = probe.points(xs)
                v = sign * value(p)
                ok = np.isfinite(v)
                if not ok.any():
                    break
                m = int(np.argmax(np.where(ok, v, -np.inf)))
                ph = float(_unwrapped(p[m:m + 1], centre, probe.heading(xs[m:m + 1]))[0])
                if lo <= ph <= hi:
                    offer(sign * float(v[m]), float(xs[m]))
                a, b = float(xs[max(m - 1, 0)]), float(xs[min(m + 1, xs.size - 1)])
        for a_i, b_i, inner in ((i0 - 1, i0, i0), (i1, i1 + 1, i1)):      # the edges the run crosses
            if a_i < 0 or b_i >= s.size:
                continue
            out = a_i if inner == b_i else b_i
            edge = lo if phi[out] < lo else hi
            a, b = float(s[a_i]), float(s[b_i])
            fa, fb = float(phi[a_i]) - edge, float(phi[b_i]) - edge
            for _level in range(EDGE_LEVELS):
                xs = np.linspace(a, b, REFINE_POINTS)
                f = phis(xs) - edge
                f[0], f[-1] = fa, fb
                c = int(np.flatnonzero(np.sign(f[:-1]) != np.sign(f[1:]))[0]) if np.any(
                    np.sign(f[:-1]) != np.sign(f[1:])) else 0
                a, b, fa, fb = float(xs[c]), float(xs[c + 1]), float(f[c]), float(f[c + 1])
            x = a if fb == fa else a + (b - a) * (-fa) / (fb - fa)       # the crossing, interpolated
            offer(float(value(probe.points(np.array([x])))[0]), x)
    return best


def turn_geometry(vehicle: Vehicle) -> tuple:
    """Everything of ``vehicle`` the low-speed turn reads (docs/low_speed_turn.md): the names, the
    couplings, the bodies, every axle's position, steering and track, each axle's share of its
    unit's cornering stiffness (:func:`~lcvreport.model.low_speed.kinematics.stiffness_shares`)
    and whether each unit is light enough to be a dolly -- not its masses, inertias, loads, roll
    data or the stiffnesses' scale, so that variants that differ only in those share one turn (a
    study's mass and cornering-stiffness factors).

    Examples
    --------
    >>> from dataclasses import replace
    >>> from lcvreport import load_preset
    >>> v = load_preset("tractor_semitrailer")
    >>> heavier = replace(v, units=tuple(replace(u, mass_kg=1.1 * u.mass_kg) for u in v.units))
    >>> turn_geometry(heavier) == turn_geometry(v), heavier == v
    (True, False)
    """
    from ..model.body import DOLLY_MASS_KG
    from ..model.low_speed.kinematics import stiffness_shares
    units = []
    for k, u in enumerate(vehicle.units):
        lateral = [a for a in u.axles if not (k == 0 and a.steered)]   # the axles the heading law weighs
        shares = dict(zip((a.name for a in lateral),
                          stiffness_shares([a.cornering_stiffness_axle_N_per_rad for a in lateral])))
        units.append((u.name, u.mass_kg <= DOLLY_MASS_KG, u.front_coupling_m, u.rear_coupling_m, u.rear_end_m,
                      u.body_front_m, u.body_rear_m, u.body_width_m,
                      tuple((a.name, a.x_m, a.steered, a.track_width_m, shares.get(a.name)) for a in u.axles)))
    return (vehicle.name, tuple(units))


#: the turns computed, by :func:`turn_geometry` and the turn's arguments
_TURNS = LRUCache(64)


def low_speed_turn(vehicle: Vehicle, radius_m: float = RADIUS_M, angle_deg: float = ANGLE_DEG,
                   rtol: float = 1e-10, atol: float = 1e-12) -> LowSpeedTurn:
    """The low-speed turn of ``vehicle`` and its measures (docs/low_speed_turn.md); computed
    once per geometry and turn (:func:`turn_geometry`: variants that differ in masses, loads or
    roll data share it; the measures, the evidence and the turn with tire forces read the same
    run) -- the same numbers bit for bit as a fresh computation, since the turn reads nothing else.

    Parameters
    ----------
    vehicle : Vehicle
        With every unit's body keys and every axle's track width (docs/low_speed_turn.md).
    radius_m : float
        Radius of the outside steer wheel's path [m], in (track/2, 100] (the ranges table's
        ``turn_radius``, and more than half the steered axle's track).
    angle_deg : float
        Angle of the turn [deg], in the ranges table's ``turn_angle``: (0, 3600].
    rtol, atol : float
        Tolerances of the heading integration.

    Returns
    -------
    LowSpeedTurn

    Raises
    ------
    TurnError
        Missing or invalid geometry, a radius or an angle out of range.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> t = low_speed_turn(load_preset("tractor_semitrailer"), angle_deg=270.0)
    >>> bool(t.lssp_m < 10.0)                       # the exit straight never counts
    True
    """
    try:
        key = (turn_geometry(vehicle), type(radius_m), radius_m, type(angle_deg), angle_deg, rtol, atol)
        hash(key)
    except (TypeError, AttributeError):                 # not a vehicle, an unhashable argument: its refusal
        return _low_speed_turn(vehicle, radius_m, angle_deg, rtol, atol)
    t = _TURNS.get(key, lambda: _low_speed_turn(vehicle, radius_m, angle_deg, rtol, atol))
    return t if t.vehicle is vehicle else replace(t, vehicle=vehicle)


low_speed_turn.cache_clear = _TURNS.clear


@one_blas_thread
def _low_speed_turn(vehicle: Vehicle, radius_m: float, angle_deg: float, rtol: float, atol: float) -> LowSpeedTurn:
    from ..ranges import RANGES
    check_turn_geometry(vehicle)
    for key, value, name in (("turn_angle", angle_deg, "angle_deg"), ("turn_radius", radius_m, "radius_m")):
        r = RANGES[key]
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not r.contains(float(value)):
            raise TurnError(f"{name} must be in {r.text()} ({r.description}), got {value!r}")
    u1 = vehicle.units[0]
    steer = max((a for a in u1.axles if a.steered), key=lambda a: a.x_m)
    half_track = steer.track_width_m / 2
    if not radius_m > half_track:
        raise TurnError(f"radius must be in ({half_track:g}, 100] m (the outside wheel of axle {steer.name} is "
                        f"{half_track:g} m from its centre), got {radius_m!r}")
    path = StraightArcPath(radius_m, math.radians(angle_deg), EXIT_LENGTHS * overall_length_m(vehicle))          # the outside wheel's path
    run = integrate(vehicle, path, np.zeros(vehicle.n_units), rtol, atol, pull_offset_m=-half_track)
    return turn_of_run(vehicle, run, radius_m, angle_deg)


def turn_of_run(vehicle: Vehicle, run, radius_m: float, angle_deg: float) -> LowSpeedTurn:
    """The low-speed turn's measures of ``vehicle`` on the poses of ``run`` -- the kinematic
    model's, or any run with its interface (``path``, ``s_end``, ``headings(s)``,
    ``unit_points(s, k, x, y)`` in the kinematic frame: X forward, Y left, headings
    counter-clockwise; s the outside steer wheel's arc length): the nonlinear model's turn gives
    its own poses here (:mod:`lcvreport.measures.friction_demand`)."""
    u1 = vehicle.units[0]
    steer = max((a for a in u1.axles if a.steered), key=lambda a: a.x_m)
    length = overall_length_m(vehicle)
    angle = math.radians(angle_deg)
    path = run.path
    centre = path.centre
    n_s = max(int(math.ceil(run.s_end / SAMPLE_M)), 200) + 1
    s = np.linspace(0.0, run.s_end, n_s)
    if vehicle.n_units > 1:                      # a jackknife: the turn is beyond the vehicle
        art = np.abs(np.diff(run.headings(s), axis=1))
        k, j = np.unravel_index(int(np.argmax(art)), art.shape)
        if art[k, j] > JACKKNIFE_RAD:
            why = (f"joint {j + 1} ({vehicle.units[j].name}-{vehicle.units[j + 1].name}) articulates to "
                   f"{math.degrees(art[k, j]):.0f} deg in this turn (beyond {math.degrees(JACKKNIFE_RAD):.0f} deg: a "
                   f"jackknife): {vehicle.name} cannot make a {angle_deg:g} deg turn with its outside steer wheel on "
                   f"{radius_m:g} m")
            undefined = {key: why for key in ("lssp_m", "low_speed_offtracking_m", "frontal_swing_m",
                                              "max_tail_swing_m")}
            return LowSpeedTurn(vehicle, float(radius_m), float(angle_deg), None, None, {}, None, float(length), run,
                                {"steer_axle_radius_m": math.nan}, undefined)

    def radius(points):
        return np.hypot(points[..., 0] - centre[0], points[..., 1] - centre[1])

    def point(k, x, y):
        return lambda ss: run.unit_points(ss, k, [x], [y])[:, 0]

    def heading(k):
        return lambda ss: run.headings(np.atleast_1d(ss)).reshape(np.size(ss), -1)[:, k]

    # what reaches outward (body corners, outside wheels) and inward (inner sides, inside wheels)
    outer, inner = [], []
    for k, u in enumerate(vehicle.units):
        cx, cy = corners(vehicle, k)
        outer += [_Probe(f"{u.name} body corner {j}", point(k, cx[j], cy[j]), heading(k)) for j in range(4)]
        for a in u.axles:
            h = a.track_width_m / 2
            outer.append(_Probe(f"{u.name} axle {a.name} outside wheel", point(k, a.x_m, -h), heading(k)))
            inner.append(_Probe(f"{u.name} axle {a.name} inside wheel", point(k, a.x_m, h), heading(k)))

        def side(ss, k=k, u=u):                  # the point of the inner side closest to the centre
            ends = run.unit_points(ss, k, [u.body_front_m, u.body_rear_m], [u.body_width_m / 2] * 2)
            a, b = ends[:, 0], ends[:, 1]
            ab = b - a
            t = np.clip(np.einsum("ij,ij->i", centre - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
            return a + t[:, None] * ab
        inner.append(_Probe(f"{u.name} body inner side", side, heading(k)))
    undefined = {}
    never = ("no position of {what} lies in the turn's sector (0 to {angle:g} deg about the arc's centre): a turn "
             "this tight takes it round the centre, or one this short ends before it arrives")
    last = vehicle.n_units - 1
    rear = vehicle.units[last].rearmost_axle
    r_rear = _extreme(_Probe("rear axle centre", point(last, rear.x_m, 0.0), heading(last)), radius, -1.0, s, centre,
                      0.0, angle)
    if r_rear is None:                           # the turn is beyond the vehicle (or too short): no measure
        why = never.format(what=f"the last unit's rearmost axle {rear.name}", angle=angle_deg)
        undefined = {key: why for key in ("lssp_m", "low_speed_offtracking_m", "frontal_swing_m",
                                          "max_tail_swing_m")}
        return LowSpeedTurn(vehicle, float(radius_m), float(angle_deg), None, None, {}, None, float(length), run,
                            {"steer_axle_radius_m": math.nan}, undefined)
    best_out = _best_of([(p, p.name) for p in outer], radius, +1.0, s, centre, 0.0, angle)
    best_in = _best_of([(p, p.name) for p in inner], radius, -1.0, s, centre, 0.0, angle)
    lssp = None if best_out is None or best_in is None else best_out[0] - best_in[0]
    if lssp is None:
        undefined["lssp_m"] = never.format(what="the vehicle's inner or outer edge", angle=angle_deg)
    # low-speed offtracking: the steered axle centre's path against the last unit's rearmost axle centre
    r_steer = _extreme(_Probe("steered axle centre", point(0, steer.x_m, 0.0), heading(0)), radius, +1.0, s, centre,
                       0.0, angle)
    offtracking = None if r_steer is None else r_steer[0] - r_rear[0]
    if offtracking is None:
        undefined["low_speed_offtracking_m"] = never.format(what=f"the centre of axle {steer.name}", angle=angle_deg)
    # tail swing: the rear outer (right) corner beyond its approach line Y = its initial Y, while the
    # unit has turned less than a quarter turn
    tail, tail_at = {}, {}
    quarter = min(angle, math.pi / 2)
    for k_u, u in enumerate(vehicle.units):
        corner = point(k_u, u.body_rear_m, -u.body_width_m / 2)
        y0 = float(corner(np.array([0.0]))[0, 1])
        turned = np.flatnonzero(heading(k_u)(s) >= quarter)
        s_end = s[turned[0]] if turned.size else s[-1]
        grid = s[s <= s_end] if s_end > 0 else s[:1]
        probe = _Probe(f"{u.name} rear outer corner", corner, heading(k_u))
        res = _extreme(probe, lambda pts, y0=y0: y0 - pts[..., 1], +1.0, grid, centre, -math.inf,
                       math.inf)                     # no sector: the whole entry, up to the quarter turn
        tail[u.name] = max(0.0, res[0]) if res else 0.0
        tail_at[u.name] = (float(res[1]) if res else 0.0, y0, float(s_end))
    # frontal swing: unit 1's front outer (right) corner outside the outside wheel's circle
    front = _extreme(_Probe("front outer corner", point(0, u1.body_front_m, -u1.body_width_m / 2), heading(0)),
                     lambda pts: radius(pts) - radius_m, +1.0, s, centre, 0.0, angle)
    frontal = max(0.0, front[0]) if front is not None else None
    if frontal is None:
        undefined["frontal_swing_m"] = never.format(what="unit 1's front outer corner", angle=angle_deg)
    where = {"outermost": best_out[2] if best_out else "", "innermost": best_in[2] if best_in else "",
             "outer_radius_m": best_out[0] if best_out else math.nan,
             "inner_radius_m": best_in[0] if best_in else math.nan,
             "steer_axle_radius_m": r_steer[0] if r_steer else math.nan,
             "tail_swing": tail_at, "frontal_swing_s": front[1] if front is not None else math.nan}
    return LowSpeedTurn(vehicle, float(radius_m), float(angle_deg), None if lssp is None else float(lssp),
                        None if offtracking is None else float(offtracking), tail,
                        None if frontal is None else float(frontal), float(length), run, where, undefined)


def low_speed_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``low_speed_turn`` family of one case (the speed plays no part)."""
    return low_speed_measures(case.vehicle, case.condition("turn_radius_m"), case.condition("turn_angle_deg"))
