"""Units: conversion factors and the two consistent unit systems of the project.

The model core works in SI (N, m, kg, s, rad).  The thesis works in inch-pound-second
units: lengths in inches [in], forces in pound-force [lbf], masses in [lbf*s^2/in],
yaw inertias in [lbf*in*s^2].  Every conversion factor lives here and nowhere else.

A :class:`UnitSystem` names a consistent system (force = mass * length / s^2); the
model builder can express its matrices in either (:data:`SI`, :data:`THESIS`), which
is how the thesis' printed matrices are compared.  Speeds at every public interface
are in m/s; the helpers below convert from what a person types (km/h, mph).

Examples
--------
>>> round(mph_to_mps(50.0), 6)
22.352
>>> round(THESIS.speed(mph_to_mps(50.0)), 9)   # 50 mph in in/s
880.0
"""
from __future__ import annotations

from dataclasses import dataclass

#: metres per inch [m/in] (exact)
M_PER_IN = 0.0254
#: newtons per pound-force [N/lbf] (exact, standard gravity)
N_PER_LBF = 4.4482216152605
#: inches per foot [in/ft]
IN_PER_FT = 12.0
#: metres per foot [m/ft] (exact)
M_PER_FT = M_PER_IN * IN_PER_FT
#: inches per mile [in/mi]
IN_PER_MILE = 63360.0
#: seconds per hour [s/h]
S_PER_HOUR = 3600.0
#: metres per second in one mile per hour [(m/s)/(mi/h)] (= 0.44704, exact)
MPS_PER_MPH = M_PER_IN * IN_PER_MILE / S_PER_HOUR
#: metres per second in one kilometre per hour [(m/s)/(km/h)]
MPS_PER_KPH = 1000.0 / S_PER_HOUR
#: newton-metres per pound-force-inch [N*m/(lbf*in)]
NM_PER_LBF_IN = N_PER_LBF * M_PER_IN
#: newton-metres per pound-force-foot [N*m/(lbf*ft)]
NM_PER_LBF_FT = N_PER_LBF * M_PER_FT


def mph_to_mps(v_mph: float) -> float:
    """Convert a speed from [mi/h] to [m/s]."""
    return v_mph * MPS_PER_MPH


def mps_to_mph(v_mps: float) -> float:
    """Convert a speed from [m/s] to [mi/h]."""
    return v_mps / MPS_PER_MPH


def kph_to_mps(v_kph: float) -> float:
    """Convert a speed from [km/h] to [m/s]."""
    return v_kph * MPS_PER_KPH


def mps_to_kph(v_mps: float) -> float:
    """Convert a speed from [m/s] to [km/h]."""
    return v_mps / MPS_PER_KPH


def m_to_in(x_m: float) -> float:
    """Convert a length from [m] to [in]."""
    return x_m / M_PER_IN


def in_to_m(x_in: float) -> float:
    """Convert a length from [in] to [m]."""
    return x_in * M_PER_IN


@dataclass(frozen=True)
class UnitSystem:
    """A consistent unit system: force = mass * length / s^2, time in s, angles in rad.

    Attributes
    ----------
    name : str
        ``"SI"`` or ``"thesis"``.
    length_m : float
        Metres per length unit [m].
    force_N : float
        Newtons per force unit [N].
    length, force, moment, mass, inertia : str
        Unit labels for tables and axis labels.
    """

    name: str
    length_m: float
    force_N: float
    length: str
    force: str
    moment: str
    mass: str
    inertia: str

    @property
    def mass_kg(self) -> float:
        """Kilograms per mass unit [kg] (force unit * s^2 / length unit)."""
        return self.force_N / self.length_m

    @property
    def inertia_kg_m2(self) -> float:
        """kg*m^2 per inertia unit (force unit * length unit * s^2: numerically a moment unit)."""
        return self.moment_Nm

    @property
    def moment_Nm(self) -> float:
        """Newton-metres per moment unit (force unit * length unit)."""
        return self.force_N * self.length_m

    def speed(self, speed_mps: float):
        """A speed [m/s] (float or array) in this system's length unit per second."""
        return speed_mps / self.length_m


#: SI: N, m, kg, kg*m^2, s
SI = UnitSystem("SI", 1.0, 1.0, "m", "N", "N*m", "kg", "kg*m^2")
#: the thesis' inch-pound-second system: lbf, in, lbf*s^2/in, lbf*in*s^2, s
THESIS = UnitSystem("thesis", M_PER_IN, N_PER_LBF, "in", "lbf", "lbf*in", "lbf*s^2/in", "lbf*in*s^2")
#: unit systems by name
UNIT_SYSTEMS = {"SI": SI, "si": SI, "thesis": THESIS}
