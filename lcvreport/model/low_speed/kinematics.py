r"""Low-speed kinematics of a combination: plane motion at walking pace, no inertia (docs/low_speed_turn.md).

A second model beside the linear yaw-plane one: angles of any size, no speed, no mass.

* **Pull points.** Unit 1 is pulled at a point of its frontmost steered axle -- its centre,
  or (``pull_offset_m``) a point across the unit from it, such as the turn's outside wheel --
  which follows a prescribed path; unit i >= 2 at its front coupling, which moves with unit
  i-1's rear coupling.  A lateral offset of the pull point does not change the heading law:
  the velocity across the unit's axis is the same at every point of one line across it.
* **Heading.** With no inertia the lateral forces of a unit's axles have no moment about
  its pull point.  With linear tires (C_j = tires x C_F of axle j, aligning and dual-tire
  terms neglected; the steered axles of unit 1 carry no lateral force) and d_j the signed
  x of axle j from the pull point along the unit's axis, the yaw rate per metre of path is

  .. math:: \frac{d\psi_i}{ds} = -\,v_{\perp,i}\,\frac{\sum_j C_j d_j}{\sum_j C_j d_j^2}

  with v_perp,i the pull point's velocity across the unit's axis per metre of path:
  independent of speed (a single axle gives the tractrix), a tandem acting as one axle
  at d = sum C d^2 / sum C d.

The frame is a plane one, X forward at the start, Y to the left, headings counter-clockwise
(a turn to the left has a growing heading); the measures that use it are distances.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.manoeuvres.paths import StraightArcPath
>>> import numpy as np
>>> v = load_preset("tractor_semitrailer")
>>> run = integrate(v, StraightArcPath(radius_m=12.0, angle_rad=np.pi / 2, exit_m=40.0), np.zeros(2))
>>> bool(run.headings(run.s_end)[1] > 1.5)          # the trailer has followed round the corner
True
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..vehicle import Vehicle

#: integrator tolerances (relative on the headings; absolute in rad)
RTOL = 1e-10


ATOL = 1e-12


class KinematicsError(ValueError):
    """A vehicle the low-speed model cannot pull: the message names the unit and what is missing."""


@dataclass(frozen=True)
class UnitGeometry:
    """What the heading law needs of one unit (x signed from its CG, forward positive) [m]."""

    pull_x_m: float
    rear_coupling_x_m: float | None
    d_m: np.ndarray               # axle x from the pull point, the axles that carry lateral force
    C_share: np.ndarray           # each one's share of their tires x C_F (stiffness_shares)
    gain_per_m: float             # sum C d / sum C d^2 [1/m] (C: the shares)
    pull_y_m: float = 0.0         # the pull point's y (to the left) on the unit's frame


def stiffness_shares(C) -> tuple[float, ...]:
    """Each axle's share of its unit's cornering stiffness, C_j / sum C, rounded to 12 significant
    digits: the heading law reads the stiffnesses only through these ratios, so a unit whose
    stiffnesses are scaled together (a study's ``cornering_stiffness_scale``) makes the same turn
    -- bit for bit, since the law is computed from the rounded shares themselves (12 digits: the
    turn moves by ~1e-11 m against the unrounded ratios).

    Examples
    --------
    >>> stiffness_shares([2.0e5, 1.0e5]) == stiffness_shares([2.2e5, 1.1e5])
    True
    """
    C = np.asarray(C, dtype=float)
    total = float(C.sum())
    return tuple(float(f"{x:.12g}") for x in (C / total if total > 0 else C))


def unit_geometry(vehicle: Vehicle, pull_offset_m: float = 0.0) -> list[UnitGeometry]:
    """Pull points and the heading law's gain of every unit; unit 1's pull point is
    ``pull_offset_m`` [m] to the left (negative: right) of its frontmost steered axle's centre.

    Raises
    ------
    KinematicsError
        A first unit with no steered axle or no unsteered one; a unit whose axles all sit
        at its pull point.
    """
    out = []
    for k, u in enumerate(vehicle.units):
        if k == 0:
            steered = [a for a in u.axles if a.steered]
            if not steered:
                raise KinematicsError(f'unit 1 "{u.name}": no steered axle to pull it along the path')
            pull = max(a.x_m for a in steered)
            axles = [a for a in u.axles if not a.steered]
            if not axles:
                raise KinematicsError(f'unit 1 "{u.name}": every axle is steered; the low-speed turn needs an '
                                      "unsteered one to fix the unit's heading")
        else:
            pull = u.front_coupling_m
            axles = list(u.axles)
        d = np.array([a.x_m - pull for a in axles])
        C = np.array(stiffness_shares([a.cornering_stiffness_axle_N_per_rad for a in axles]))
        den = float(np.sum(C * d * d))
        if not den > 0:
            raise KinematicsError(f'unit {k + 1} "{u.name}": every axle is at its pull point; its heading is '
                                  "not fixed")
        out.append(UnitGeometry(pull, u.rear_coupling_m, d, C, float(np.sum(C * d)) / den,
                                float(pull_offset_m) if k == 0 else 0.0))
    return out


@dataclass(frozen=True)
class KinematicRun:
    """Headings of every unit along the path, with the pull points (callable on arrays of s)."""

    vehicle: Vehicle
    path: object
    geometry: tuple
    pieces: tuple                 # OdeSolution per path segment
    s_end: float

    def _kept(self, name: str, s_arr: np.ndarray, compute):
        """``compute(s_arr)``, kept for the last array of many points asked (the turn's measures
        probe the same grid of s once per point of the vehicle; the array's bytes are the key)."""
        if s_arr.size < 16:
            return compute(s_arr)
        memo = self.__dict__.setdefault("_memo", {})
        key = s_arr.tobytes()
        got = memo.get(name)
        if got is None or got[0] != key:
            got = memo[name] = (key, compute(s_arr))
        return got[1]

    def headings(self, s) -> np.ndarray:
        """Headings [rad] of every unit at arc length ``s``: shape (N,) or (len(s), N)."""
        s_arr = np.atleast_1d(np.asarray(s, dtype=float))
        out = self._kept("headings", s_arr, self._headings)
        return out[0] if np.ndim(s) == 0 else out

    def _headings(self, s_arr: np.ndarray) -> np.ndarray:
        out = np.empty((s_arr.size, len(self.geometry)))
        edges = [p[0] for p in self.pieces] + [self.s_end]
        for k, (lo, sol) in enumerate(self.pieces):
            hi = edges[k + 1]
            mask = (s_arr >= lo) & ((s_arr <= hi) if k == len(self.pieces) - 1 else (s_arr < hi))
            if mask.any():
                out[mask] = sol(s_arr[mask]).T
        out.flags.writeable = False                 # kept: a caller must not change it
        return out

    def pull_points(self, s) -> np.ndarray:
        """Pull points [m] of every unit: shape (len(s), N, 2)."""
        s_arr = np.atleast_1d(np.asarray(s, dtype=float))
        return self._kept("pull_points", s_arr, self._pull_points)

    def _pull_points(self, s_arr: np.ndarray) -> np.ndarray:
        psi = self.headings(s_arr).reshape(s_arr.size, -1)
        P = np.empty((s_arr.size, len(self.geometry), 2))
        P[:, 0] = self.path.point(s_arr)
        for i in range(1, len(self.geometry)):
            g = self.geometry[i - 1]
            lx, ly = g.rear_coupling_x_m - g.pull_x_m, -g.pull_y_m
            c, sn = np.cos(psi[:, i - 1]), np.sin(psi[:, i - 1])
            P[:, i, 0] = P[:, i - 1, 0] + c * lx - sn * ly
            P[:, i, 1] = P[:, i - 1, 1] + sn * lx + c * ly
        P.flags.writeable = False
        return P

    def unit_points(self, s, k: int, x_m, y_m) -> np.ndarray:
        """World (X, Y) [m] of points of unit ``k`` at unit coordinates (x from its CG,
        forward; y to its left), at every arc length of ``s``: shape (len(s), n_points, 2)."""
        s_arr = np.atleast_1d(np.asarray(s, dtype=float))
        psi = self.headings(s_arr).reshape(s_arr.size, -1)[:, k]
        P = self.pull_points(s_arr)[:, k]
        x = np.atleast_1d(np.asarray(x_m, dtype=float)) - self.geometry[k].pull_x_m
        y = np.atleast_1d(np.asarray(y_m, dtype=float)) - self.geometry[k].pull_y_m
        c, sn = np.cos(psi)[:, None], np.sin(psi)[:, None]
        return np.stack([P[:, None, 0] + c * x - sn * y, P[:, None, 1] + sn * x + c * y], axis=-1)


class DenseHeadings:
    """A DOP853 run's dense output (scipy's :class:`~scipy.integrate.OdeSolution`) evaluated at
    many points in one pass: every step's interpolant stacked, each point's step found by one
    search -- the same segment and the same arithmetic as scipy's (bit for bit), without a Python
    call per step (the low-speed turn's measures probe the run at thousands of points)."""

    def __init__(self, sol):
        from scipy.integrate._ivp.rk import Dop853DenseOutput
        if not all(isinstance(i, Dop853DenseOutput) for i in sol.interpolants) or not sol.ascending:
            raise TypeError("DenseHeadings stacks an ascending DOP853 OdeSolution")   # pragma: no cover
        self.ts_sorted, self.side, self.n_segments = sol.ts_sorted, sol.side, sol.n_segments
        self.t_old = np.array([i.t_old for i in sol.interpolants])
        self.h = np.array([i.h for i in sol.interpolants])
        self.y_old = np.array([i.y_old for i in sol.interpolants])
        self.F = np.array([i.F for i in sol.interpolants])          # (segments, 7, n)

    def __call__(self, t) -> np.ndarray:
        """The states at ``t``: shape (n,) for a scalar, (n, len(t)) for an array (scipy's)."""
        t_arr = np.atleast_1d(np.asarray(t, dtype=float))
        seg = np.searchsorted(self.ts_sorted, t_arr, side=self.side) - 1
        np.clip(seg, 0, self.n_segments - 1, out=seg)
        x = ((t_arr - self.t_old[seg]) / self.h[seg])[:, None]
        F = self.F[seg]
        y = np.zeros((t_arr.size, self.y_old.shape[1]))
        for i in range(F.shape[1]):
            y += F[:, F.shape[1] - 1 - i]
            if i % 2 == 0:
                y *= x
            else:
                y *= 1 - x
        y += self.y_old[seg]
        return y[0] if np.ndim(t) == 0 else y.T


def _rhs(geometry, path):
    n = len(geometry)
    lever = [((g.rear_coupling_x_m - g.pull_x_m) if g.rear_coupling_x_m is not None else 0.0, -g.pull_y_m)
             for g in geometry]

    def f(s, psi):
        v = path.tangent(s)
        vx, vy = float(v[0]), float(v[1])
        out = np.empty(n)
        for i in range(n):
            c, sn = math.cos(psi[i]), math.sin(psi[i])
            v_perp = -sn * vx + c * vy
            rate = -v_perp * geometry[i].gain_per_m
            out[i] = rate
            # the next unit's pull point: this one's plus the lever (lx, ly) turning with this unit
            lx, ly = lever[i]
            vx, vy = vx - rate * (sn * lx + c * ly), vy + rate * (c * lx - sn * ly)
        return out
    return f


def integrate(vehicle: Vehicle, path, psi0, rtol: float = RTOL, atol: float = ATOL,
              pull_offset_m: float = 0.0) -> KinematicRun:
    """Headings of every unit along ``path`` from the headings ``psi0`` [rad] at s = 0; unit 1's
    pull point (the point that follows ``path``) is ``pull_offset_m`` [m] to the left of its
    frontmost steered axle's centre (the outside wheel of a left turn: minus half its track).

    Integrated in arc length with :func:`scipy.integrate.solve_ivp` (DOP853), segment by
    segment of the path (its curvature jumps between them).

    Parameters
    ----------
    vehicle : Vehicle
    path : StraightArcPath or StraightPath
        Anything with ``point(s)``, ``tangent(s)``, ``breaks`` and ``s_end`` [m].
    psi0 : array_like, shape (N,)
        Initial headings [rad].
    rtol, atol : float
        Tolerances of the integration.

    Returns
    -------
    KinematicRun
    """
    from scipy.integrate import solve_ivp
    geometry = tuple(unit_geometry(vehicle, pull_offset_m))
    f = _rhs(geometry, path)
    y = np.asarray(psi0, dtype=float).copy()
    pieces = []
    breaks = path.breaks
    for lo, hi in zip(breaks[:-1], breaks[1:]):
        if hi <= lo:
            continue
        sol = solve_ivp(f, (lo, hi), y, method="DOP853", rtol=rtol, atol=atol, dense_output=True)
        if not sol.success:            # pragma: no cover - DOP853 on a smooth, bounded field
            raise KinematicsError(f"the heading integration failed: {sol.message}")
        pieces.append((lo, DenseHeadings(sol.sol)))
        y = sol.y[:, -1]
    return KinematicRun(vehicle, path, geometry, tuple(pieces), float(path.s_end))
