"""Drivers: the path-following preview driver of the driver FMU."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np



@dataclass(frozen=True)
class PreviewDriver:
    """Gain [rad/m], preview distance [m], lane change offset [m], start [s] and duration [s]."""

    gain_rad_per_m: float = 0.02
    preview_m: float = 30.0
    target_offset_m: float = 1.5
    start_s: float = 1.0
    duration_s: float = 3.0

    def reference_m(self, t):
        """Y_ref(t) [m]: 0 before the start, the half-cosine ramp, the offset after."""
        x = np.clip((np.asarray(t, dtype=float) - self.start_s) / self.duration_s, 0.0, 1.0)
        return self.target_offset_m * 0.5 * (1.0 - np.cos(math.pi * x))

    def steer_rad(self, t, Y1_m, psi1_rad):
        """delta = K (Y_ref(t) - (Y1 + L psi1)) [rad]."""
        return self.gain_rad_per_m * (self.reference_m(t) - (Y1_m + self.preview_m * psi1_rad))


#: the driver FMU's start values
DEFAULT = PreviewDriver()
