r"""Residual tire loads: conicity and ply steer as per-axle P and T.

* ``P`` [lbf] acts along +y at the axle, ``T`` about +z (nose-right positive).
* The thesis' 1 % rule (section 3.6): P = 1 % of the axle load [lbf] and
  T = 1 % of the axle load read as lbf*ft.
* Two conventions for turning P, T into the generalized force F of M x' = S x + F
  (SPEC section 4, erratum 1):

  ``consistent``
      T converted to lbf*in (x 12); every row in the units of M and S.
  ``thesis``
      the printed eq. 3.34 / 4.17: rows 2... are (sum of P * arm)/12 + T, i.e. the
      moment rows in lbf*ft while M and S are in lbf*in.  Equal to the consistent
      vector with rows 2.. divided by 12.

* Load configurations of Figures 3-6..3-8 and 4-9..4-11 (the figures are lost; the
  text describes them): every tire carries a residual force of ``fraction`` of its
  vertical load, pointing along +y or -y.

  ``balanced``
      on every axle the curb-side tires push +y and the driver-side tires -y: the
      forces and moments cancel axle by axle ("tires carefully sorted").
  ``unbalanced_vehicle``
      every tire of every axle pushes +y ("all the residual lateral force pointed
      in the same direction").
  ``unbalanced_trailer``
      the tires of the last unit all push +y, the rest are balanced ("imbalance
      focused on the rearmost unit").
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import system_coefficients
from .units import IN_PER_FT
from .vehicle import Train

#: load conventions (SPEC section 4)
CONVENTIONS = ("consistent", "thesis")
#: load configurations of Figures 3-6..3-8 and 4-9..4-11
CONFIGURATIONS = ("balanced", "unbalanced_vehicle", "unbalanced_trailer")
#: unit names accepted in load lists (the CLI's UNITS); ``tractor`` is an extension
LOADABLE_UNITS = ("tractor", "trailer1", "dolly1", "trailer2", "dolly2", "trailer3")
#: the thesis' residual load fraction of the vertical load
ONE_PERCENT = 0.01


@dataclass(frozen=True)
class ResidualLoads:
    """Per-axle residual lateral force and aligning moment.

    Attributes
    ----------
    P_lbf : dict
        Axle label -> residual lateral force along +y [lbf].
    T_lbf_ft : dict
        Axle label -> residual aligning moment about +z [lbf*ft] (the unit the
        thesis' 1 % rule implies; see the module docstring).
    """

    P_lbf: dict
    T_lbf_ft: dict

    def scaled(self, factor: float) -> "ResidualLoads":
        """Every P and T multiplied by ``factor``."""
        return ResidualLoads({k: v * factor for k, v in self.P_lbf.items()},
                             {k: v * factor for k, v in self.T_lbf_ft.items()})

    def vectors(self, train: Train) -> tuple[np.ndarray, np.ndarray]:
        """(P [lbf], T [lbf*in]) per axle of ``train`` in thesis axle order."""
        names = train.axle_names
        unknown = (set(self.P_lbf) | set(self.T_lbf_ft)) - set(names)
        if unknown:
            raise KeyError(f"axles {sorted(unknown)} are not on train {train.name!r} (axles: {', '.join(names)})")
        P = np.array([self.P_lbf.get(a, 0.0) for a in names], dtype=float)
        T = np.array([self.T_lbf_ft.get(a, 0.0) for a in names], dtype=float) * IN_PER_FT
        return P, T


def check_units(train: Train, units: list[str] | tuple[str, ...]) -> list[str]:
    """Validate unit names for a load list against ``train``; raise ``KeyError`` naming the valid ones."""
    valid = [u.name for u in train.units]
    out = []
    for name in units:
        if name not in valid:
            raise KeyError(f"unknown unit {name!r} for train {train.name!r}; valid: {', '.join(valid)}")
        out.append(name)
    return out


def one_percent_rule(train: Train, units: list[str] | tuple[str, ...], t_sign: float = 1.0,
                     fraction: float = ONE_PERCENT) -> ResidualLoads:
    """The thesis' rule on every axle of the named units.

    Parameters
    ----------
    train : Train
    units : list of str
        Unit names (``trailer1``, ``dolly1``, ...).
    t_sign : {+1, -1}
        +1: T about +z (with P along +y); -1: T about -z.  Eq. 4.17 needs +1 (T
        turning against the moment of P about the trailer CG), eq. 3.34 needs -1.
    fraction : float
        Residual load as a fraction of the axle load (0.01 in the thesis).

    Returns
    -------
    ResidualLoads
        P = fraction * axle load [lbf] along +y; T = t_sign * fraction * axle load [lbf*ft].
    """
    check_units(train, units)
    P, T = {}, {}
    for name in units:
        for ax in train.unit(name).axles:
            P[ax.name] = fraction * ax.load_lbf
            T[ax.name] = t_sign * fraction * ax.load_lbf
    return ResidualLoads(P, T)


def load_vector(train: Train, loads: ResidualLoads, convention: str = "consistent") -> np.ndarray:
    """Generalized force F of eq. 3.16 / 4.16 from per-axle residual loads.

    Parameters
    ----------
    train : Train
    loads : ResidualLoads
    convention : {"consistent", "thesis"}

    Returns
    -------
    numpy.ndarray, shape (2N,)
        Row 1 [lbf]; rows 2..N+1 [lbf*in] (consistent) or as printed (thesis);
        articulation rows 0.
    """
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {', '.join(CONVENTIONS)}, got {convention!r}")
    co = system_coefficients(train)
    P, T = loads.vectors(train)
    F = co.B_P @ P + co.B_T @ T
    if convention == "thesis":
        F = F.copy()
        F[1:] /= IN_PER_FT
    return F


def thesis_conversion(train: Train) -> np.ndarray:
    """Diagonal D with ``F_thesis = D @ F_consistent`` (1 on row 1, 1/12 on rows 2..)."""
    d = np.full(2 * train.n_units, 1.0 / IN_PER_FT)
    d[0] = 1.0
    return d


@dataclass(frozen=True)
class TireForce:
    """Residual force of one tire, for drawing (Figures 3-6..3-8, 4-9..4-11).

    Attributes
    ----------
    axle : str
    side : str
        ``curb`` (+y) or ``driver`` (-y).
    lateral_offset_in : float
        Tire centre from the unit centreline [in], +y toward the curb.
    force_lbf : float
        Residual lateral force along +y [lbf].
    moment_lbf_ft : float
        Residual aligning moment about +z [lbf*ft].
    """

    axle: str
    side: str
    lateral_offset_in: float
    force_lbf: float
    moment_lbf_ft: float


def tire_forces(train: Train, configuration: str, fraction: float = ONE_PERCENT) -> list[TireForce]:
    """Per-tire residual forces of a load configuration (see module docstring)."""
    if configuration not in CONFIGURATIONS:
        raise ValueError(f"configuration must be one of {', '.join(CONFIGURATIONS)}, got {configuration!r}")
    track = float(train.drawing.get("track_width_in", 72.0))
    D = train.dual_spacing_in
    last = train.units[-1].name
    out = []
    for unit in train.units:
        for ax in unit.axles:
            per_tire = fraction * ax.load_lbf / ax.tires
            offsets = [track / 2] if ax.tires == 2 else [track / 2 - D / 2, track / 2 + D / 2]
            for side, sgn in (("curb", 1.0), ("driver", -1.0)):
                if configuration == "unbalanced_vehicle" or (configuration == "unbalanced_trailer"
                                                            and unit.name == last):
                    direction = 1.0
                else:
                    direction = sgn
                for off in offsets:
                    out.append(TireForce(ax.name, side, sgn * off, direction * per_tire, direction * per_tire))
    return out


def configuration_loads(train: Train, configuration: str, fraction: float = ONE_PERCENT) -> ResidualLoads:
    """Per-axle P [lbf] and T [lbf*ft] summed from :func:`tire_forces`."""
    P: dict[str, float] = {}
    T: dict[str, float] = {}
    for tf in tire_forces(train, configuration, fraction):
        P[tf.axle] = P.get(tf.axle, 0.0) + tf.force_lbf
        T[tf.axle] = T.get(tf.axle, 0.0) + tf.moment_lbf_ft
    return ResidualLoads({k: v for k, v in P.items() if v != 0.0}, {k: v for k, v in T.items() if v != 0.0})
