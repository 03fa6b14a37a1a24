r"""The tire laws of the nonlinear planar model (docs/nonlinear.md#tires), one function per law,
vectorized over the axles: the lateral force and the aligning moment of one tire from its slip
angle's tangent, its load and the friction it has left (docs/nonlinear.md#tires).

``linear``: ``F_y = -C_F tan(alpha)``, ``M_z = +C_M tan(alpha)`` (section 2 at small angles, whose
slip angle is minus this one: the linearization test).

``saturating`` (the brush, or Fiala, tire): with ``theta = C_F |tan(alpha)| / (3 mu_y F_z)``,
``F_y = -mu_y F_z (3 theta - 3 theta^2 + theta^3) sign(alpha)`` for ``theta < 1`` and
``-mu_y F_z sign(alpha)`` beyond; ``M_z = +C_M tan(alpha) (1 - theta)^3`` for ``theta < 1``, 0
beyond.  ``mu_y = sqrt(mu^2 - (F_x / F_z)^2)``: what a tire carrying a drive force ``F_x`` has left
(the friction ellipse).  Its slope at 0 is ``-C_F``, as the linear law's.

Examples
--------
>>> import numpy as np
>>> t = np.array([0.0, 0.01, 1.0])
>>> F, M = saturating(t, 2.0e5, 5.0e3, 2.5e4, 0.8)
>>> float(abs(F[0])), round(float(F[1] / (-2.0e5 * 0.01)), 4), bool(F[2] == -0.8 * 2.5e4)
(0.0, 0.967, True)
"""
from __future__ import annotations

import numpy as np

#: the tire laws: name -> function (tan alpha, C_F, C_M, F_z, mu_y) -> (F_y, M_z) per tire
LAWS = ("linear", "saturating")


def linear(tan_alpha, cornering_N_per_rad, aligning_Nm_per_rad, load_N=None, mu=None):
    """``F_y = -C_F tan(alpha)``, ``M_z = +C_M tan(alpha)`` [N, N m] per tire (no saturation;
    complex-safe: the linearization test differentiates it by complex steps)."""
    return -cornering_N_per_rad * tan_alpha, aligning_Nm_per_rad * tan_alpha


def saturating(tan_alpha, cornering_N_per_rad, aligning_Nm_per_rad, load_N, mu):
    """The brush tire [N, N m] per tire: ``load_N`` the tire's vertical load ``F_z``, ``mu`` the
    friction it has laterally (``mu_y``); see the module docstring."""
    t = np.asarray(tan_alpha, dtype=float)
    cap = mu * load_N                                              # the largest lateral force
    theta = cornering_N_per_rad * np.abs(t) / (3.0 * np.where(cap > 0, cap, np.inf))
    sliding = theta >= 1.0
    th = np.minimum(theta, 1.0)
    F = -np.sign(t) * cap * np.where(sliding, 1.0, 3.0 * th - 3.0 * th ** 2 + th ** 3)
    M = np.where(sliding, 0.0, aligning_Nm_per_rad * t * (1.0 - th) ** 3)
    return F, M


def law(name: str):
    """The tire law ``name`` (:data:`LAWS`)."""
    if name not in LAWS:
        raise ValueError(f"tire must be one of {', '.join(LAWS)}, got {name!r}")
    return linear if name == "linear" else saturating
