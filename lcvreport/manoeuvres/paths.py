"""Paths a unit's pull point follows (the low-speed kinematic model): the straight-arc-straight
path of the turn and a straight path.

Examples
--------
>>> import math
>>> p = StraightArcPath(radius_m=12.5, angle_rad=math.pi / 2, exit_m=10.0)
>>> [round(float(c), 6) for c in p.point(p.arc_end_s)]
[12.5, 12.5]
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np



@dataclass(frozen=True)
class StraightArcPath:
    """The path of unit 1's pull point: a circular arc to the left from (0, 0) heading +X,
    of ``radius_m`` through ``angle_rad``, then a straight exit of ``exit_m``.  Arc length
    s in [0, s_end]; a straight approach (s < 0) along Y = 0 for drawing."""

    radius_m: float
    angle_rad: float
    exit_m: float

    @property
    def arc_end_s(self) -> float:
        return self.radius_m * self.angle_rad

    @property
    def s_end(self) -> float:
        return self.arc_end_s + self.exit_m

    @property
    def centre(self) -> np.ndarray:
        return np.array([0.0, self.radius_m])

    @property
    def breaks(self) -> tuple[float, ...]:
        """Path lengths where the curvature jumps."""
        return (0.0, self.arc_end_s, self.s_end)

    def point(self, s):
        """(X, Y) [m] at arc length ``s`` (scalar or array)."""
        s = np.asarray(s, dtype=float)
        R, a = self.radius_m, self.angle_rad
        phi = np.clip(s, 0.0, self.arc_end_s) / R
        x = R * np.sin(phi) + np.where(s < 0, s, 0.0) + np.maximum(s - self.arc_end_s, 0.0) * math.cos(a)
        y = R * (1 - np.cos(phi)) + np.maximum(s - self.arc_end_s, 0.0) * math.sin(a)
        return np.stack([x, y], axis=-1)

    def tangent(self, s: float) -> np.ndarray:
        phi = min(max(s, 0.0), self.arc_end_s) / self.radius_m
        return np.array([math.cos(phi), math.sin(phi)])


@dataclass(frozen=True)
class StraightPath:
    """A straight path along +X from (0, 0) (the tractrix test)."""

    length_m: float

    @property
    def s_end(self) -> float:
        return self.length_m

    @property
    def breaks(self) -> tuple[float, ...]:
        return (0.0, self.length_m)

    def point(self, s):
        s = np.asarray(s, dtype=float)
        return np.stack([s, np.zeros_like(s)], axis=-1)

    def tangent(self, s: float) -> np.ndarray:
        return np.array([1.0, 0.0])
