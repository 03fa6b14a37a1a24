r"""Residual tire loads: conicity and ply steer as per-axle P and T (SI).

* ``P`` [N] acts along +y at the axle, ``T`` [N*m] about +z (nose-right positive).
* The 1 % rule (thesis section 3.6, docs/vehicle_files.md): P = 1 % of the static axle
  load along +y and T = 0.3048 m * P about +z -- the thesis' "T = 1 % of the axle
  load in lbf*ft" in consistent units.
* Two conventions for turning P, T into the generalized force F of M x' = S x + F
  (docs/thesis.md, erratum 1):

  ``consistent``
      every row in the units of M and S.
  ``thesis``
      the printed eq. 3.34 / 4.17: the moment rows (2..N+1) computed in lbf*ft while
      M and S are in lbf*in, i.e. the consistent vector with those rows divided by 12.

Examples
--------
>>> from lcvreport import load_preset, one_percent_rule, load_vector
>>> aucnat = load_preset("aucnat")
>>> loads = one_percent_rule(aucnat, ["trailer2", "trailer3"])
>>> round(loads.P_N["41"], 2)                  # 1 % of 21,400 lbf [N]
951.92
>>> load_vector(aucnat, loads).shape
(12,)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...ranges import RANGES, RangeError
from ...units import IN_PER_FT, M_PER_FT, SI, UnitSystem
from ..vehicle import Vehicle
from ..linear import linear_model
from .equations import system_coefficients

#: load conventions (docs/thesis.md)
CONVENTIONS = ("consistent", "thesis")
#: the thesis' residual load fraction of the vertical axle load
ONE_PERCENT = 0.01
#: the lever arm of the 1 % rule's moment: T = ONE_PERCENT_ARM_M * P [m] (1 ft)
ONE_PERCENT_ARM_M = M_PER_FT


@dataclass(frozen=True)
class ResidualLoads:
    """Per-axle residual lateral force and aligning moment, SI.

    Attributes
    ----------
    P_N : dict
        Axle name -> residual lateral force along +y [N].
    T_Nm : dict
        Axle name -> residual aligning moment about +z [N*m].

    Examples
    --------
    >>> r = ResidualLoads({"11": 100.0}, {"11": 30.0})
    >>> r.P_N["11"], r.T_Nm["11"]
    (100.0, 30.0)
    """

    P_N: dict = field(default_factory=dict)
    T_Nm: dict = field(default_factory=dict)

    def scaled(self, factor: float) -> "ResidualLoads":
        """Every P and T multiplied by ``factor``."""
        return ResidualLoads({k: v * factor for k, v in self.P_N.items()},
                             {k: v * factor for k, v in self.T_Nm.items()})

    def vectors(self, vehicle: Vehicle) -> tuple[np.ndarray, np.ndarray]:
        """(P [N], T [N*m]) per axle of ``vehicle``, in :attr:`Vehicle.axles` order.

        Raises
        ------
        KeyError
            For an axle the vehicle does not have.
        lcvreport.ranges.RangeError
            For a value outside :data:`lcvreport.ranges.RANGES`.
        """
        names = vehicle.axle_names
        unknown = (set(self.P_N) | set(self.T_Nm)) - set(names)
        if unknown:
            raise KeyError(f"axles {sorted(unknown)} are not on {vehicle.name} (axles: {', '.join(names)})")
        P = np.array([self.P_N.get(a, 0.0) for a in names], dtype=float)
        T = np.array([self.T_Nm.get(a, 0.0) for a in names], dtype=float)
        for key, arr, sym in (("residual_force", P, "P"), ("residual_moment", T, "T")):
            r = RANGES[key]
            for a, v in zip(names, arr):
                if not r.contains(v):
                    raise RangeError(f"{sym}_{a}", f"{sym}_{a} must be in {r.text()}, got {v:.6g}")
        return P, T


def check_unit_names(vehicle: Vehicle, units) -> list[str]:
    """Validate a list of unit names for a load list: known, not repeated.

    Raises
    ------
    KeyError
        Naming the unknown or repeated unit and the valid ones.
    """
    valid = vehicle.unit_names
    if isinstance(units, str) or not hasattr(units, "__iter__"):
        raise KeyError(f"load_units must be a list of unit names of {vehicle.name} ({', '.join(valid)}), got "
                       f"{units!r}")
    seen = []
    for name in units:
        if name not in valid:
            raise KeyError(f"unknown unit {name!r} for {vehicle.name}; valid: {', '.join(valid)}")
        if name in seen:
            raise KeyError(f"unit {name!r} is listed twice")
        seen.append(name)
    if not seen:
        raise KeyError(f"no unit listed; valid: {', '.join(valid)}")
    return seen


def one_percent_rule(vehicle: Vehicle, units, t_sign: float = 1.0, fraction: float = ONE_PERCENT) -> ResidualLoads:
    """The thesis' rule on every axle of the named units.

    Parameters
    ----------
    vehicle : Vehicle
    units : list of str
        Unit names; every axle of them needs ``static_load_N``.
    t_sign : {+1, -1}
        +1: T about +z (with P along +y); -1: T about -z.  Eq. 4.17 needs +1, eq. 3.34 -1.
    fraction : float
        Residual load as a fraction of the axle load (0.01 in the thesis).

    Returns
    -------
    ResidualLoads
        P = fraction * static load [N] along +y; T = t_sign * 0.3048 m * P [N*m].

    Raises
    ------
    KeyError
        An unknown or repeated unit.
    ValueError
        An axle of a listed unit without ``static_load_N``.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> r = one_percent_rule(load_preset("aucnat"), ["trailer3"])
    >>> sorted(r.P_N) == [a.name for a in load_preset("aucnat").units[5].axles]
    True
    """
    P, T = {}, {}
    for name in check_unit_names(vehicle, units):
        for ax in vehicle.unit(name).axles:
            if ax.static_load_N is None:
                raise ValueError(f'unit "{name}" axle "{ax.name}": static_load_N is needed by the 1 % rule '
                                 "but the vehicle file does not give it")
            P[ax.name] = fraction * ax.static_load_N
            T[ax.name] = t_sign * ONE_PERCENT_ARM_M * P[ax.name]
    return ResidualLoads(P, T)


def load_vector(vehicle: Vehicle, loads: ResidualLoads, convention: str = "consistent",
                units: UnitSystem = SI, model: str = "yaw_plane") -> np.ndarray:
    """Generalized force F of eq. 3.16 / 4.16 from per-axle residual loads.

    Parameters
    ----------
    vehicle : Vehicle
    loads : ResidualLoads
    convention : {"consistent", "thesis"}
    units : UnitSystem
        SI (default: row 1 in N, rows 2..N+1 in N*m) or THESIS (lbf, lbf*in).
    model : str
        The linear model whose generalized forces these are (default the yaw plane).

    Returns
    -------
    numpy.ndarray, shape (2N,)
        Articulation rows 0.

    Raises
    ------
    ValueError
        A ``convention`` that is not one of :data:`CONVENTIONS`.

    Examples
    --------
    >>> from lcvreport import load_preset, one_percent_rule
    >>> v = load_preset("aucnat")
    >>> load_vector(v, one_percent_rule(v, ["trailer3"])).shape
    (12,)
    """
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {', '.join(CONVENTIONS)}, got {convention!r}")
    co = system_coefficients(vehicle, units) if model == "yaw_plane" else linear_model(vehicle, model, units)
    P, T = loads.vectors(vehicle)
    F = co.B_P @ (P / units.force_N) + co.B_T @ (T / units.moment_Nm)
    if convention == "thesis":
        F = F.copy()
        F[1:vehicle.n_units + 1] /= IN_PER_FT
    return F


@dataclass(frozen=True)
class ResidualSources:
    """Every constant residual source of docs/manoeuvres.md, SI.

    Attributes
    ----------
    loads : ResidualLoads
        Per-axle residual force P [N] and moment T [N*m].
    misalignment_rad : dict
        Axle name -> thrust angle [rad], nose-right positive: the axle's slip angle gains it.
    crossfall_percent : float
        Road crossfall [%], positive when the road falls toward +y: m_i g sin(atan(c/100))
        along +y at every unit's CG.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> src = ResidualSources(misalignment_rad={"31": 0.002}, crossfall_percent=2.0)
    >>> src.vector(load_preset("aucnat")).shape
    (12,)
    """

    loads: ResidualLoads = field(default_factory=ResidualLoads)
    misalignment_rad: dict = field(default_factory=dict)
    crossfall_percent: float = 0.0

    def __bool__(self) -> bool:
        return bool(self.loads.P_N or self.loads.T_Nm or self.misalignment_rad or self.crossfall_percent)

    def vector(self, vehicle: Vehicle, tire_scale: float = 1.0, model: str = "yaw_plane") -> np.ndarray:
        """The generalized force F (n,) of every source on the linear model ``model``, SI (the
        misalignment's scales with the tire coefficients, the others do not).

        Raises
        ------
        KeyError
            An axle the vehicle does not have.
        lcvreport.ranges.RangeError
            A value outside :data:`lcvreport.ranges.RANGES`.
        """
        co = linear_model(vehicle, model)
        P, T = self.loads.vectors(vehicle)
        eps = self._misalignments(vehicle)
        c = RANGES["crossfall"].check(self.crossfall_percent, "crossfall")
        return (co.B_P @ P + co.B_T @ T + tire_scale * (co.B_eps @ eps)
                + math.sin(math.atan(c / 100.0)) * co.B_crossfall)

    def axle_forces(self, vehicle: Vehicle, tire_scale: float = 1.0) -> np.ndarray:
        """Each axle's constant lateral tire force of the sources [N]: its P plus ``s C_F eps``
        (what the load transfer of the yaw-roll model adds to the slip-angle force)."""
        P, _T = self.loads.vectors(vehicle)
        cf = np.array([a.cornering_stiffness_axle_N_per_rad for a in vehicle.axles])
        return P + tire_scale * cf * self._misalignments(vehicle)

    def _misalignments(self, vehicle: Vehicle) -> np.ndarray:
        names = vehicle.axle_names
        unknown = set(self.misalignment_rad) - set(names)
        if unknown:
            raise KeyError(f"axles {sorted(unknown)} are not on {vehicle.name} (axles: {', '.join(names)})")
        eps = np.array([self.misalignment_rad.get(a, 0.0) for a in names], dtype=float)
        for a, e in zip(names, eps):
            RANGES["misalignment"].check(e, f"misalignment of axle {a}")
        return eps

    def describe(self) -> str:
        """The sources in words, for captions and notes."""
        parts = []
        if self.loads.P_N or self.loads.T_Nm:
            parts.append("P, T on " + ", ".join(sorted(set(self.loads.P_N) | set(self.loads.T_Nm))))
        if self.misalignment_rad:
            parts.append("misalignment " + ", ".join(f"{a} {e:g} rad" for a, e in self.misalignment_rad.items()))
        if self.crossfall_percent:
            parts.append(f"crossfall {self.crossfall_percent:g} %")
        return "; ".join(parts) or "none"
