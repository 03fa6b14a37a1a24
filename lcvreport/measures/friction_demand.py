r"""The low-speed turn with tire forces (docs/nonlinear.md#the-low-speed-turn-with-tire-forces): the
nonlinear model driven round the turn of docs/low_speed_turn.md by a path-following law, the
turn's measures on its own poses, and the **friction demand** of every axle (docs/measures.md
#friction-demand).

The turn is section 16's: a straight approach, a circular arc to the left through ``angle_deg``
on which the outside wheel of the frontmost steered axle runs at ``radius_m``, a straight exit of
three overall lengths; unit 1's CG at ``speed_kph`` (5 km/h, walking pace).  The steer is

  delta = delta_kin(s) + K e + (K^2 / 4) int e ds,

delta_kin(s) the no-slip steer of the kinematic model at the same arc length s of the outside
wheel's path (the angle between the path's tangent there and unit 1's heading in the kinematic
run), e the outside wheel's signed distance from the path (positive to the left of its direction:
steer right), the integral over unit 1's travel, K = ``path_gain_rad_per_m`` (2 rad/m).  The
integral term holds the steer slip a tandem's scrub needs, which a proportional law would leave
as a steady error (docs/nonlinear.md#the-low-speed-turn-with-tire-forces).  ``path_error_max_m``
is max |e| over the run; beyond 0.05 m the law did not hold the path and the friction demands are
null with that reason, never a number that means nothing; at 0.5 m the run stops (the turn is
not being made).

Friction demand of axle j at time t: ``FD_j = sqrt(F_x,j^2 + F_y,j^2) / (mu F_z0,j)`` -- the share of
the friction available to the axle it uses (1: saturated); ``stfd`` the largest over the run of
unit 1's steered axles', ``friction_demand_drive`` of its driven axles'.

Examples
--------
>>> from lcvreport import load_vehicle
>>> t = turn_with_tire_forces(load_vehicle("examples/vehicles/b_double.toml"), angle_deg=90.0)
>>> 0.0 < t.stfd < 1.0, t.path_error_max_m < 0.05
(True, True)
"""
from __future__ import annotations

import copy
import ctypes
import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..model.body import overall_length_m
from ..model.nonlinear.model import FRICTION_COEFFICIENT, driven_axles, nonlinear_model
from ..model.vehicle import Vehicle
from ..units import kph_to_mps
from .low_speed import ANGLE_DEG, RADIUS_M, LowSpeedTurn, low_speed_turn, turn_of_run
from ..util.cache import LRUCache
from ..util.compiled import load
from ..util.threads import one_blas_thread
from .registry import MeasureCase

#: the turn's default speed [km/h]: walking pace
TURN_SPEED_KPH = 5.0
#: the path-following law's gain K [rad/m]
PATH_GAIN_RAD_PER_M = 2.0
#: the largest path error a turn's friction demand is given for [m]
PATH_ERROR_MAX_M = 0.05
#: the turn's integration tolerance: its friction demands agree with rtol 1e-8's to 1e-6
#: (tests/test_friction_demand.py), at half the evaluations
TURN_RTOL = 1e-5
#: the path error at which the run stops: the turn is not being made [m]
LOST_PATH_M = 0.5
#: the spacing of the run's table of poses for the turn's measures [m]
TABLE_M = 0.01
#: the samples of the run per metre of path
SAMPLES_PER_M = 10.0
#: the keys of the family
KEYS = ("stfd", "friction_demand_drive", "path_error_max_m")


def path_coordinates(path, X, Y, s_hint=None, heading_rad=None) -> tuple[np.ndarray, np.ndarray]:
    """(s, e) of points (X, Y) [m] in the kinematic frame (X forward, Y left) on the
    straight-arc-straight ``path``: the arc length of each point's nearest point on the path [m]
    and its signed distance from it, positive to the left of the path's direction [m].  Of the
    approach, the arc and the exit, the nearest that the point projects onto.  Scalars or arrays
    of one shape.

    Where the path comes back over itself (an arc of 270 degrees or more: its exit crosses or
    runs along the approach and the arc's laps coincide) the point's place on the path is
    ambiguous; ``heading_rad`` [rad, left positive, unwrapped: 2 pi after a lap], the direction
    of travel there, resolves it: the arc's lap is the one nearest the heading, and the approach
    and the exit count only while the heading is within a quarter turn of their direction (the
    approach's 0, the exit's ``path.angle_rad``).  ``s_hint`` [m], where the point is expected
    along the path, gives the heading ``clip(s_hint, 0, arc end) / R`` where ``heading_rad`` is
    not given; with neither, every piece counts and the arc's first lap is taken.

    Examples
    --------
    >>> from lcvreport.manoeuvres.paths import StraightArcPath
    >>> p = StraightArcPath(12.5, math.pi / 2, 20.0)
    >>> s, e = path_coordinates(p, 12.0 * math.sin(0.5), 12.5 - 12.0 * math.cos(0.5))
    >>> round(float(s), 6), round(float(e), 6)              # half a metre inside the arc at 0.5 rad
    (6.25, 0.5)
    >>> lap = StraightArcPath(12.5, 2 * math.pi, 20.0)       # a full circle: the exit runs over the approach
    >>> [round(float(v), 6) for v in path_coordinates(lap, -1.0, 0.2, heading_rad=0.0)]
    [-1.0, 0.2]
    >>> [round(float(v), 6) for v in path_coordinates(lap, 1.0, 0.2, heading_rad=2 * math.pi)]
    [79.539816, 0.2]
    """
    X, Y = np.broadcast_arrays(np.asarray(X, dtype=float), np.asarray(Y, dtype=float))
    R, a = path.radius_m, path.angle_rad
    if heading_rad is not None:
        h = np.broadcast_to(np.asarray(heading_rad, dtype=float), X.shape)
    elif s_hint is not None:
        h = np.clip(np.broadcast_to(np.asarray(s_hint, dtype=float), X.shape), 0.0, path.arc_end_s) / R
    else:
        h = None
    Cx, Cy = float(path.centre[0]), float(path.centre[1])
    inf = np.full(X.shape, np.inf)
    approach = np.ones(X.shape, bool) if h is None else h < 0.5 * math.pi
    leaving = np.ones(X.shape, bool) if h is None else h > a - 0.5 * math.pi
    # the approach (s <= 0)
    d0 = np.where((X <= 0.0) & approach, np.abs(Y), inf)
    # the arc: the angle from its start about the centre, on the lap nearest the heading
    phi = np.arctan2(X - Cx, -(Y - Cy))
    if h is not None:
        phi = phi + 2 * math.pi * np.round((np.clip(h, 0.0, a) - phi) / (2 * math.pi))
    r = np.hypot(X - Cx, Y - Cy)
    d1 = np.where((phi >= 0.0) & (phi <= a), np.abs(R - r), inf)
    # the exit straight
    ex, ey = R * math.sin(a), R * (1 - math.cos(a))
    tx, ty = math.cos(a), math.sin(a)
    along = (X - ex) * tx + (Y - ey) * ty
    e2 = tx * (Y - ey) - ty * (X - ex)
    d2 = np.where((along >= 0.0) & leaving, np.abs(e2), inf)
    # nearest to neither piece's interior: the corner points (the arc's ends)
    dc0, dc1 = np.hypot(X, Y), np.hypot(X - ex, Y - ey)
    d = np.stack([d0, d1, d2, np.where(approach, dc0, inf), np.where(leaving, dc1, inf)])
    s = np.stack([X, R * phi, path.arc_end_s + along, np.zeros(X.shape), np.full(X.shape, path.arc_end_s)])
    e = np.stack([Y, R - r, e2, dc0, dc1])
    k = np.argmin(d, axis=0)[None]
    return np.take_along_axis(s, k, 0)[0], np.take_along_axis(e, k, 0)[0]


class PathFollowing:
    r"""The nonlinear model steered round the turn by the path-following law (the module
    docstring): the model's states and one more, the integral of the path error over unit 1's
    travel ``E = int e ds`` [m^2]; a :class:`~lcvreport.model.base.VehicleModel` itself, so that one
    integration carries both.  Called as the steer law (``law(t, X) -> delta``, columns of states).
    """

    vectorized = True

    def __init__(self, model, kinematic_run, steer_axle, gain_rad_per_m: float, speed_mps: float):
        self.model, self.run = model, kinematic_run
        self.path = kinematic_run.path
        self.kind, self.vehicle = model.kind, model.vehicle
        self.x_m, self.half_track_m = float(steer_axle.x_m), float(steer_axle.track_width_m) / 2
        self.K = float(gain_rad_per_m)
        self.K_I = self.K ** 2 / 4                         # critically damped error in distance
        self.U = float(speed_mps)
        # delta_kin(s) on a 1 cm grid with the path's breaks (linear interpolation: < 1e-7 rad)
        grid = np.union1d(np.linspace(0.0, kinematic_run.s_end, int(kinematic_run.s_end / 0.01) + 2),
                          [b for b in self.path.breaks if 0.0 <= b <= kinematic_run.s_end])
        tangent = np.minimum(grid, self.path.arc_end_s) / self.path.radius_m
        self._s_grid = grid
        self._delta_kin = tangent - kinematic_run.headings(grid)[:, 0]            # left positive
        self._memo = (None, None, None)
        self._compiled = _compiled_law(self)

    def __getstate__(self):                  # the compiled law is this process's (ctypes)
        return {**self.__dict__, "_compiled": None}

    def __setstate__(self, state):
        self.__dict__.update(state)
        self._compiled = _compiled_law(self)

    @property
    def state_names(self) -> tuple:
        return (*self.model.state_names, "path_error_integral")

    @property
    def state_units(self) -> tuple:
        return (*self.model.state_units, "m^2")

    @property
    def input_names(self) -> tuple:
        return self.model.input_names

    def wheel(self, X) -> tuple[np.ndarray, np.ndarray]:
        """(X, Y) [m] in the kinematic frame of the outside (right) steer wheel, states as columns."""
        psi = X[2]
        c, sn = np.cos(psi), np.sin(psi)
        return X[0] + self.x_m * c - self.half_track_m * sn, -(X[1] + self.x_m * sn + self.half_track_m * c)

    def error(self, t, X) -> tuple[np.ndarray, np.ndarray]:
        """(s, e) [m] of the outside steer wheel of the states ``X`` (columns) at times ``t``
        (the last call's remembered: the law and the equations ask for the same states)."""
        return self._law(t, X)[:2]

    def _law(self, t, X, remember: bool = True) -> tuple:
        """(s, e, delta) of :meth:`error` and the steer, by the compiled law where this machine
        has it (path_following.c), the same arithmetic in numpy otherwise; the last call's
        remembered (``remember=False``: neither looked up nor kept -- a caller that takes all
        three at once)."""
        X = np.asarray(X, dtype=float)
        t = np.asarray(t, dtype=float)
        if remember:
            key = (t.tobytes(), X.tobytes())
            if self._memo[0] == key:
                return self._memo[1]
        if self._compiled is not None and X.ndim == 2:
            out = self._compiled(t if t.shape == X.shape[1:] else np.broadcast_to(t, X.shape[1:]), X)
        else:
            out = self.law_numpy(t, X)
        if remember:
            self._memo = (key, out)
        return out

    def law_numpy(self, t, X) -> tuple:
        """(s, e, delta) of the states ``X`` (columns) at times ``t`` by numpy: the outside steer
        wheel's arc length and path error [m] and the steer [rad] (the compiled law's reference)."""
        X = np.asarray(X, dtype=float)
        Xw, Yw = self.wheel(X)
        s, e = path_coordinates(self.path, Xw, Yw, heading_rad=-X[2])       # unit 1's heading, left positive
        delta_kin = np.interp(s, self._s_grid, self._delta_kin)        # clamped to the run's ends
        return s, e, -delta_kin + self.K * e + self.K_I * X[-1]

    def __call__(self, t, X) -> np.ndarray:
        """The steer [rad, the model's sign: nose right positive] of the states ``X`` (n, k)."""
        return self._law(t, X)[2]

    def lost(self, t, z) -> float:
        """Positive while the outside steer wheel is within :data:`LOST_PATH_M` of its path
        (the run's stop condition: beyond it the turn is not being made)."""
        return LOST_PATH_M - abs(float(self.error(t, np.asarray(z)[:, None])[1][0]))

    def derivatives(self, t, x, w, speed_mps, tire_scale=1.0):
        x = np.asarray(x, dtype=float)
        cols = np.atleast_2d(x)
        dx = np.atleast_2d(self.model.derivatives(t, cols[:, :-1], w, speed_mps, tire_scale))
        _s, e = self.error(t, cols.T)
        out = np.column_stack([dx, self.U * e])
        return out if x.ndim == 2 else out[0]

    def outputs(self, t, x, w, speed_mps, tire_scale=1.0) -> dict:
        x = np.asarray(x, dtype=float)
        out = dict(self.model.outputs(t, x[..., :-1], w, speed_mps, tire_scale))
        _s, e = self.error(t, np.atleast_2d(x).T)
        out["path_error"] = e if x.ndim == 2 else float(e[0])
        return out


@dataclass(frozen=True)
class SampledRun:
    """The nonlinear run's poses in the kinematic model's interface (kinematic frame: X forward,
    Y left, headings counter-clockwise), parameterized by the outside wheel's arc length s: what
    :func:`lcvreport.measures.low_speed.turn_of_run` reads.  The states are tabulated every
    :data:`TABLE_M` of travel from the integrator's dense output and interpolated linearly in s
    (a pose within 1e-6 m on a 12.5 m arc: h^2 / 8R), so that the measures' many probes cost a
    table look-up each."""

    vehicle: Vehicle
    path: object
    s_grid: np.ndarray
    states: np.ndarray
    s_end: float
    geometry: tuple = field(default=())

    @classmethod
    def of(cls, follow: "PathFollowing", response) -> "SampledRun":
        """The table of ``response`` (a run of ``follow``), every :data:`TABLE_M` of unit 1's travel."""
        t_end = float(response.time[-1])
        t = np.linspace(0.0, t_end, max(int(math.ceil(follow.U * t_end / TABLE_M)), 2) + 1)
        X = response.state_at(t)
        s, _e = follow.error(t, X.T)
        s = np.maximum.accumulate(s)
        keep = np.concatenate([[True], np.diff(s) > 0])
        return cls(follow.vehicle, follow.path, s[keep], X[keep], float(min(s[-1], follow.path.s_end)))

    def _states(self, s) -> np.ndarray:
        s = np.atleast_1d(np.asarray(s, dtype=float))
        g = self.s_grid
        k = np.clip(np.searchsorted(g, s) - 1, 0, g.size - 2)
        w = np.clip((s - g[k]) / (g[k + 1] - g[k]), 0.0, 1.0)[:, None]
        return (1.0 - w) * self.states[k] + w * self.states[k + 1]

    def headings(self, s) -> np.ndarray:
        N = self.vehicle.n_units
        out = -self._states(s)[:, 2:2 + N]
        return out[0] if np.ndim(s) == 0 else out

    def unit_points(self, s, k: int, x_m, y_m) -> np.ndarray:
        X = self._states(s)
        v = self.vehicle
        N = v.n_units
        psi = X[:, 2:2 + N]
        P = np.zeros((X.shape[0], 2))
        P[:, 0], P[:, 1] = X[:, 0], X[:, 1]
        for i in range(k):
            a, b = v.units[i].rear_coupling_m, v.units[i + 1].front_coupling_m
            P[:, 0] += a * np.cos(psi[:, i]) - b * np.cos(psi[:, i + 1])
            P[:, 1] += a * np.sin(psi[:, i]) - b * np.sin(psi[:, i + 1])
        x = np.atleast_1d(np.asarray(x_m, dtype=float))
        y = -np.atleast_1d(np.asarray(y_m, dtype=float))          # the kinematic frame's y is to the left
        c, sn = np.cos(psi[:, k])[:, None], np.sin(psi[:, k])[:, None]
        Xw = P[:, None, 0] + c * x - sn * y
        Yw = P[:, None, 1] + sn * x + c * y
        return np.stack([Xw, -Yw], axis=-1)                      # back to the kinematic frame (Y left)


@dataclass(frozen=True)
class TurnWithTireForces:
    """The low-speed turn of the nonlinear model (see the module docstring): the run
    (``response``), the friction demand of every axle over it, ``stfd``, ``friction_demand_drive``,
    ``path_error_max_m``, the turn's measures on this run's poses (``turn``) beside the kinematic
    model's (``kinematic``), and why a measure is null (``undefined``)."""

    vehicle: Vehicle
    radius_m: float
    angle_deg: float
    speed_kph: float
    friction_coefficient: float
    path_gain_rad_per_m: float
    tire: str
    response: object
    friction_demand: dict
    stfd: float | None
    friction_demand_drive: float | None
    path_error_max_m: float
    #: the path-following law the run was steered by (None: the run left the path): the turn's
    #: measures are read on the run's poses (:class:`SampledRun`), tabulated when first read
    follow: PathFollowing | None
    kinematic: LowSpeedTurn
    undefined: dict = field(default_factory=dict)

    @property
    def turn(self) -> LowSpeedTurn | None:
        """The turn's measures (docs/low_speed_turn.md) on this run's poses (None: the run left the
        path), computed when first read: the friction demand does not need them."""
        if self.follow is None:
            return None
        cache = self.__dict__.setdefault("_turn", [])
        if not cache:
            cache.append(turn_of_run(self.vehicle, SampledRun.of(self.follow, self.response), self.radius_m,
                                     self.angle_deg))
        return cache[0]

    def to_dict(self) -> dict:
        """The JSON of ``lcv turn --model nonlinear``."""
        turn = self.turn.to_dict() if self.turn is not None else None
        return {"model": "nonlinear", "tire": self.tire, "radius_m": self.radius_m, "angle_deg": self.angle_deg,
                "speed_kph": self.speed_kph, "friction_coefficient": self.friction_coefficient,
                "path_gain_rad_per_m": self.path_gain_rad_per_m, "stfd": self.stfd,
                "friction_demand_drive": self.friction_demand_drive, "path_error_max_m": self.path_error_max_m,
                "friction_demand": dict(self.friction_demand), "turn": turn, "kinematic": self.kinematic.to_dict(),
                "reasons": dict(self.undefined)}

    def plot(self, limit: float | None = None):
        """Every axle's friction demand over the run, the limit drawn (:func:`lcvreport.plotting.low_speed.fig_friction_demand`)."""
        from ..plotting.low_speed import fig_friction_demand
        return fig_friction_demand(self, limit)


def turn_with_tire_forces(vehicle: Vehicle, radius_m: float = RADIUS_M, angle_deg: float = ANGLE_DEG,
                          speed_kph: float = TURN_SPEED_KPH,
                          friction_coefficient: float = FRICTION_COEFFICIENT,
                          path_gain_rad_per_m: float = PATH_GAIN_RAD_PER_M, tire: str = "saturating",
                          tire_scale: float = 1.0, rtol: float = TURN_RTOL) -> TurnWithTireForces:
    """The low-speed turn of ``vehicle`` on the nonlinear model, steered by the path-following law
    (see the module docstring).

    Parameters
    ----------
    vehicle : Vehicle
        With the turn's body keys (docs/low_speed_turn.md) and every axle's ``static_load_N``.
    radius_m, angle_deg : float
        The outside steer wheel's radius [m] and the turn's angle [deg].
    speed_kph : float
        Unit 1's forward speed [km/h] (default 5).
    friction_coefficient : float
        mu, in (0, 2].
    path_gain_rad_per_m : float
        K of the path-following law [rad/m].
    tire : {"saturating", "linear"}
    tire_scale : float
    rtol : float
        The integration's relative tolerance.

    Returns
    -------
    TurnWithTireForces

    Raises
    ------
    TurnError
        Missing geometry, a radius or angle out of range.
    IntegrationError
        A driven axle out of friction (the speed cannot be held), naming the axle and the time.

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> t = turn_with_tire_forces(load_vehicle("examples/vehicles/western_double.toml"))
    >>> round(t.stfd, 3), t.path_error_max_m < 0.05
    (0.212, True)
    """
    args = (radius_m, angle_deg, speed_kph, friction_coefficient, path_gain_rad_per_m, tire, tire_scale, rtol)

    def compute():
        return vehicle, turns_with_tire_forces([vehicle], *args)[0]
    key = _key(vehicle, *args)
    if key is None:                                 # an argument that does not hash: its own refusal below
        owner, out = compute()
    else:
        owner, out = _RESULTS.get(key, compute)
        if owner is not vehicle and owner != vehicle:
            # a vehicle that differs only in its bodies' widths and overhangs (the same overall
            # length): the same run, bit for bit; its turn's measures on its own bodies
            if isinstance(out, Exception):          # a refusal may name a body: its own
                owner, out = compute()
            else:
                out = dataclasses.replace(out, vehicle=vehicle, kinematic=low_speed_turn(vehicle, radius_m, angle_deg),
                                          undefined=dict(out.undefined))
    if isinstance(out, Exception):
        raise out
    return out


#: the turns computed, by their arguments: a study's batch computes its cases' turns at once
#: (:func:`prefetch_turns`), each case's assessment then finds its own here
_RESULTS = LRUCache(256)


#: the unit keys the run of the turn with tire forces does not read: the bodies' extents, which
#: reach it only through the vehicle's overall length (the exit straight's length), which the key
#: holds; the turn's measures on the run's poses (``turn``) read them, from the vehicle asked about
BODY_KEYS = ("body_front_m", "body_rear_m", "body_width_m", "rear_end_m")


def _key(vehicle, *args) -> tuple | None:
    """The cache key of a turn's arguments: the vehicle without its bodies (:data:`BODY_KEYS`),
    its overall length and the arguments; None where one does not hash (a bad argument) or the
    vehicle has no overall length (its refusal is the turn's)."""
    try:
        run_vehicle = dataclasses.replace(vehicle, units=tuple(dataclasses.replace(u, **dict.fromkeys(BODY_KEYS))
                                                              for u in vehicle.units))
        key = (run_vehicle, overall_length_m(vehicle),
               *(float(a) if isinstance(a, (int, float)) and not isinstance(a, bool) else a for a in args))
        hash(key)
    except Exception:                                  # noqa: BLE001 - not a vehicle, no bodies: no key
        return None
    return key


def _clear() -> None:
    _RESULTS.clear()


turn_with_tire_forces.cache_clear = _clear


def prefetch_turns(vehicles, radius_m: float = RADIUS_M, angle_deg: float = ANGLE_DEG,
                   speed_kph: float = TURN_SPEED_KPH, friction_coefficient: float = FRICTION_COEFFICIENT,
                   path_gain_rad_per_m: float = PATH_GAIN_RAD_PER_M, tire: str = "saturating",
                   tire_scale: float = 1.0, rtol: float = TURN_RTOL) -> None:
    """Compute the turns of ``vehicles`` not yet computed in one batch
    (:func:`turns_with_tire_forces`), so that :func:`turn_with_tire_forces` of each finds it: what
    a study does before it assesses its cases one by one.  At most the cache's size (256) at once."""
    args = (radius_m, angle_deg, speed_kph, friction_coefficient, path_gain_rad_per_m, tire, tire_scale, rtol)
    todo = {}
    for v in vehicles:
        key = _key(v, *args)
        if key is not None and key not in _RESULTS and key not in todo:
            todo[key] = v
    items = list(todo.items())[:_RESULTS.maxsize]
    if not items:
        return
    for (key, v), out in zip(items, turns_with_tire_forces([v for _k, v in items], *args)):
        _RESULTS.get(key, lambda v=v, out=out: (v, out))


def prefetch_cases(vehicles, tire_scales, keys, conditions: dict | None = None) -> None:
    """:func:`prefetch_turns` of the cases (``vehicles``, ``tire_scales``) whose measures ``keys``
    include the friction demand family's, at the ``conditions`` (the registry's, as a scheme
    group or a study gives them; the rest the defaults): what a study does for a block of its
    cases before it computes them one by one, each then finding its turn computed."""
    from .measure_set import check_conditions
    from .registry import MEASURES
    if not any(MEASURES[k].family == "friction_demand" for k in keys if k in MEASURES):
        return
    given = check_conditions({k: v for k, v in (conditions or {}).items()
                              if k not in ("speed_kph", "ra_frequency_hz", "crossfall_percent")})
    scales: dict = {}
    for v, ts in zip(vehicles, tire_scales):
        scales.setdefault(float(ts), []).append(v)
    for ts, group in scales.items():
        case = MeasureCase(group[0], 1.0, ts, 0.5, conditions=given)
        prefetch_turns(group, case.condition("turn_radius_m"), case.condition("turn_angle_deg"),
                       case.condition("turn_speed_kph"), case.condition("friction_coefficient"),
                       case.condition("path_gain_rad_per_m"), tire_scale=ts)


class _Law(ctypes.Structure):
    _fields_ = [(k, ctypes.c_double) for k in ("R", "a", "arc_end", "x_m", "half_track", "K", "K_I", "U")] + \
        [("G", ctypes.c_longlong), ("grid", ctypes.c_void_p), ("dk", ctypes.c_void_p)]


_LAW_SOURCE = Path(__file__).with_name("path_following.c")


def _compiled_law(follow: PathFollowing):
    """The compiled path-following law of ``follow`` (path_following.c, :mod:`lcvreport.util.compiled`):
    a function (t (k,), X (n, k)) -> (s, e, delta), or None (no library, or a path that is not a
    straight-arc-straight one: the numpy law then)."""
    from ..manoeuvres.paths import StraightArcPath
    if type(follow.path) is not StraightArcPath:
        return None
    lib, _why = load(_LAW_SOURCE, {"lcv_path_following": (None, [
        ctypes.POINTER(_Law), ctypes.c_longlong, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p,
        ctypes.c_void_p, ctypes.c_void_p])})
    if lib is None:
        return None
    p = follow.path
    grid, dk = np.ascontiguousarray(follow._s_grid, dtype=float), np.ascontiguousarray(follow._delta_kin, dtype=float)
    law = _Law(float(p.radius_m), float(p.angle_rad), float(p.arc_end_s), follow.x_m, follow.half_track_m, follow.K,
               follow.K_I, follow.U, grid.size, grid.ctypes.data, dk.ctypes.data)
    f = lib.lcv_path_following

    def call(t, X, keep=(grid, dk, law)):
        rows = np.ascontiguousarray(X.T)
        k, n = rows.shape
        t = np.ascontiguousarray(t, dtype=float)
        out = np.empty((3, k))                               # s, e, delta
        at = out.ctypes.data
        f(ctypes.byref(law), k, t.ctypes.data, rows.ctypes.data, n, at, at + 8 * k, at + 16 * k)
        return out[0], out[1], out[2]
    return call


@one_blas_thread
def turns_with_tire_forces(vehicles, radius_m: float = RADIUS_M, angle_deg: float = ANGLE_DEG,
                           speed_kph: float = TURN_SPEED_KPH, friction_coefficient: float = FRICTION_COEFFICIENT,
                           path_gain_rad_per_m: float = PATH_GAIN_RAD_PER_M, tire: str = "saturating",
                           tire_scale: float = 1.0, rtol: float = TURN_RTOL) -> list:
    """:func:`turn_with_tire_forces` of every vehicle of ``vehicles``, the variants of one
    geometry integrated side by side (:func:`lcvreport.analysis.radau_batch.radau_batch`: each
    with its own steps, the same numbers as alone, bit for bit).  One item per vehicle: its
    :class:`TurnWithTireForces`, or the exception its turn raised (a vehicle without the turn's
    keys or a static load, a driven axle out of friction), not raised.

    Examples
    --------
    >>> import dataclasses
    >>> from lcvreport import load_vehicle
    >>> v = load_vehicle("examples/vehicles/b_double.toml")
    >>> w = dataclasses.replace(v, units=(v.units[0], dataclasses.replace(v.units[1], mass_kg=30000.0), v.units[2]))
    >>> a, b = turns_with_tire_forces([v, w])
    >>> a.stfd == turns_with_tire_forces([v])[0].stfd, a.stfd != b.stfd
    (True, True)
    """
    from ..analysis.integrate import ATOL, IntegrationError, input_vector
    from ..analysis.radau_batch import RowFailure, radau_batch
    from ..analysis.time_response import SampledResponse
    from ..model.nonlinear.model import Parameters, TractionError
    from ..ranges import RANGES
    RANGES["speed"].check(kph_to_mps(speed_kph), "turn speed", factor=3.6, unit="km/h")
    RANGES["path_gain"].check(path_gain_rad_per_m, "path_gain_rad_per_m")
    out: list = [None] * len(vehicles)
    groups: dict = {}
    for k, vehicle in enumerate(vehicles):
        try:
            kinematic = low_speed_turn(vehicle, radius_m, angle_deg)
            model = nonlinear_model(vehicle, tire, friction_coefficient)
        except Exception as exc:                          # the vehicle's own refusal, for its caller to raise
            out[k] = exc
            continue
        groups.setdefault((model.geometry_key(), id(kinematic.run)), []).append((k, vehicle, kinematic, model))
    U = kph_to_mps(speed_kph)
    for members in groups.values():
        _k0, vehicle, kinematic, model = members[0]
        kin = kinematic.run
        u1 = vehicle.units[0]
        steer_axle = max((a for a in u1.axles if a.steered), key=lambda a: a.x_m)
        follow = PathFollowing(model, kin, steer_axle, path_gain_rad_per_m, U)
        x0 = np.zeros(len(follow.state_names))
        x0[0], x0[1] = -steer_axle.x_m, -steer_axle.track_width_m / 2      # the outside wheel at the path's start
        dt = 1.0 / (SAMPLES_PER_M * U)
        n = max(int(math.ceil(float(kin.path.s_end / U) / dt)), 200)
        t_end = n * dt
        w0 = input_vector(model, 0.0, None, tire_scale)
        params = Parameters.concatenate([m._p for _k, _v, _kin, m in members])

        def fun(t, Y, rows, follow=follow, model=model, params=params, w0=w0, taken={}):
            W = np.broadcast_to(w0, (Y.shape[0], w0.size)).copy()
            _s, e, W[:, 0] = follow._law(t, Y.T, remember=False)
            key = rows.tobytes()                       # the calls' few patterns of rows: each taken once
            p = taken.get(key)
            if p is None:
                if len(taken) >= 256:
                    taken.clear()
                p = taken[key] = params.take(rows)
            try:
                dx = model.derivatives_rows(Y[:, :-1], W, U, tire_scale, p)
            except TractionError as exc:
                raise RowFailure(exc.row, str(exc)) from None
            return np.column_stack([dx, U * e])

        runs = radau_batch(fun, 0.0, np.tile(x0, (len(members), 1)), t_end, rtol, ATOL,
                           stop=lambda t, Y, rows, follow=follow: LOST_PATH_M - np.abs(follow.error(t, Y.T)[1]))
        for (k, vehicle, kinematic, model), run in zip(members, runs):
            if run.status == -1:
                out[k] = IntegrationError(run.message)
                continue
            mine = copy.copy(follow)
            mine.model, mine._memo = model, (None, None, None)
            time = np.linspace(0.0, n * dt, n + 1)
            end = run.stopped_at if run.status == 1 else t_end
            if run.status == 1:
                time = time[time <= run.stopped_at]
            r = SampledResponse(mine, time, [(0.0, end, run.sol)], U, tire_scale, mine, w0, "low-speed turn")
            r.stopped_at, r.evaluations, r.steer = run.stopped_at, run.nfev, mine
            out[k] = _turn_of(vehicle, kinematic, mine, r, radius_m, angle_deg, speed_kph, friction_coefficient,
                              path_gain_rad_per_m, tire)
    return out


def _turn_of(vehicle, kinematic, follow, r, radius_m, angle_deg, speed_kph, friction_coefficient,
             path_gain_rad_per_m, tire) -> TurnWithTireForces:
    """The turn's result of the run ``r`` of ``follow``: friction demands, path error, the
    turn's measures on its poses."""
    u1 = vehicle.units[0]
    s_run, e_run = follow.error(r.time, r.state_at(r.time).T)
    s_mono = np.maximum.accumulate(s_run)
    path_error = float(np.abs(e_run).max())
    fd = {a.name: float(np.max(r[f"fd_{a.name}"])) for a in vehicle.axles}
    steered = [a.name for a in u1.axles if a.steered]
    driven = [a.name for a, d in zip(vehicle.axles, driven_axles(vehicle)) if d]
    undefined = {}
    stfd = max(fd[a] for a in steered)
    drive = max(fd[a] for a in driven)
    conditions = (f"K = {path_gain_rad_per_m:g} rad/m, {speed_kph:g} km/h, mu = {friction_coefficient:g}, "
                  f"{tire} tires")
    if r.stopped_at is not None:
        path_error = max(path_error, LOST_PATH_M)
        why = (f"undefined: the combination left the path: its outside steer wheel was {LOST_PATH_M:g} m off it at "
               f"t = {r.stopped_at:.2f} s, {float(s_mono[-1]):.1f} m along it ({conditions}); the turn is not "
               "made, so it has no friction demand")
    elif path_error > PATH_ERROR_MAX_M:
        why = (f"undefined: the path-following law held the outside steer wheel within {path_error:.3g} m of its "
               f"path, not {PATH_ERROR_MAX_M:g} m ({conditions}): the friction demand of a turn not made is not "
               "the turn's")
    else:
        why = None
    if why is not None:
        stfd = drive = None
        undefined.update({"stfd": why, "friction_demand_drive": why})
    if r.stopped_at is not None:
        undefined["turn"] = why
    return TurnWithTireForces(vehicle, float(radius_m), float(angle_deg), float(speed_kph),
                              float(friction_coefficient), float(path_gain_rad_per_m), tire, r, fd, stfd, drive,
                              path_error, None if r.stopped_at is not None else follow, kinematic, undefined)


def friction_demand_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``friction_demand`` family of one case: the turn with tire forces at the
    case's conditions (the turn's radius and angle, ``turn_speed_kph``, ``friction_coefficient``,
    ``path_gain_rad_per_m``)."""
    from ..analysis.integrate import IntegrationError
    from ..model.body import TurnError
    from ..model.vehicle import VehicleError
    try:
        t = turn_with_tire_forces(case.vehicle, case.condition("turn_radius_m"), case.condition("turn_angle_deg"),
                                  case.condition("turn_speed_kph"), case.condition("friction_coefficient"),
                                  case.condition("path_gain_rad_per_m"), tire_scale=case.tire_scale)
    except (TurnError, VehicleError, IntegrationError, ValueError) as exc:
        why = f"undefined: {exc}"
        return dict.fromkeys(KEYS), dict.fromkeys(KEYS, why)
    values = {"stfd": t.stfd, "friction_demand_drive": t.friction_demand_drive, "path_error_max_m": t.path_error_max_m}
    return values, {k: why for k, why in t.undefined.items() if k in KEYS}


__all__ = ["TurnWithTireForces", "turn_with_tire_forces", "turns_with_tire_forces", "prefetch_turns", "prefetch_cases", "friction_demand_family", "path_coordinates",
           "overall_length_m"]
