"""Parameter sets of an A-train: axles, units and the train itself.

Everything here is plain data in the thesis unit system (in, lbf, s).  Signed
longitudinal positions are positive ahead of the unit's CG (SPEC section 2).
Tire coefficients stored on an :class:`Axle` are per AXLE (per-tire table value
times the number of tires) and unscaled; the chapter V tire scale factor is applied
by the model builder.
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

#: Thesis names of the units, front to back (Table 3-1).
UNIT_NAMES = ("tractor", "trailer1", "dolly1", "trailer2", "dolly2", "trailer3")
#: Thesis letters of the joints, joint k joins unit k and k+1 (Table 3-2).
JOINT_LETTERS = ("A", "B", "C", "D", "E")


#: Table 3-3 of the thesis: generalized coordinates, their description and unit
STATE_DESCRIPTIONS = {
    "v1": ("Tractor Lateral Velocity", "in/s"),
    "r1": ("Tractor Yaw Rate", "rad/s"), "r2": ("Trailer 1 Yaw Rate", "rad/s"), "r3": ("Dolly 1 Yaw Rate", "rad/s"),
    "r4": ("Trailer 2 Yaw Rate", "rad/s"), "r5": ("Dolly 2 Yaw Rate", "rad/s"), "r6": ("Trailer 3 Yaw Rate", "rad/s"),
    "thetaA": ("Articulation Angle at Joint A", "rad"), "thetaB": ("Articulation Angle at Joint B", "rad"),
    "thetaC": ("Articulation Angle at Joint C", "rad"), "thetaD": ("Articulation Angle at Joint D", "rad"),
    "thetaE": ("Articulation Angle at Joint E", "rad"),
}
#: Table 3-1: unit numbering
UNIT_LABELS = ("Tractor", "Trailer 1", "Dolly 1", "Trailer 2", "Dolly 2", "Trailer 3")


@dataclass(frozen=True)
class Axle:
    """One axle of one unit.

    Attributes
    ----------
    name : str
        Thesis label ``"ij"``: axle j of unit i (``"11"`` is the steer axle).
    unit : int
        Unit number i, 1 = tractor.
    position_in : float
        Signed longitudinal position of the axle relative to the unit CG [in],
        positive ahead (``+x11``, ``-x12``, ``-x21``...).
    load_lbf : float
        Static vertical axle load [lbf].
    tires : int
        Number of tires on the axle (2 steer, 4 for two duals).
    CF : float
        Cornering force coefficient of the axle [lbf/rad].
    CM : float
        Aligning moment coefficient of the axle [lbf*in/rad].
    CS : float
        Circumferential stiffness of the axle [lbf] (dual axles only, eq. 3.11).
    dual : bool
        True for dual-tire axles (adds the -CS*D^2/u yaw damping term).
    steer : bool
        True for the tractor steer axle (receives the steer angle input).
    """

    name: str
    unit: int
    position_in: float
    load_lbf: float
    tires: int
    CF: float
    CM: float
    CS: float
    dual: bool
    steer: bool = False


@dataclass(frozen=True)
class Unit:
    """One rigid unit (tractor, semitrailer or converter dolly).

    Attributes
    ----------
    number : int
        Unit number, 1 = tractor.
    name : str
        ``tractor``, ``trailer1``, ``dolly1``, ...
    kind : str
        ``tractor``, ``trailer`` or ``dolly``.
    mass : float
        Mass [lbf*s^2/in].
    inertia : float
        Yaw moment of inertia about the CG [lbf*in*s^2].
    front_joint_in : float
        CG to front joint distance f_i [in] (``x2A``, ``x3B``...); 0 for the tractor.
    rear_joint_in : float
        CG to rear joint distance b_i [in] (``x1A``, ``x2B``...). For the last unit
        this is the CG to rear end distance used by eq. 3.43 / 4.46 (``x2B`` for a
        tractor-semitrailer, ``x6F`` for the triple).
    axles : tuple of Axle
    """

    number: int
    name: str
    kind: str
    mass: float
    inertia: float
    front_joint_in: float
    rear_joint_in: float
    axles: tuple[Axle, ...]

    @property
    def length_between_ends_in(self) -> float:
        """Front joint to rear joint (or rear end) distance [in]."""
        return self.front_joint_in + self.rear_joint_in


@dataclass(frozen=True)
class Train:
    """An A-train of N units joined by N-1 frictionless joints.

    Attributes
    ----------
    name : str
        Preset or user name.
    units : tuple of Unit
        Front to back; ``units[0]`` is the tractor.
    dual_spacing_in : float
        Lateral spacing D between the two tires of a dual set [in].
    description : str
        Where the data come from.
    """

    name: str
    units: tuple[Unit, ...]
    dual_spacing_in: float
    description: str = ""
    drawing: dict = field(default_factory=dict, compare=False, hash=False)

    @property
    def n_units(self) -> int:
        """Number of units N."""
        return len(self.units)

    @property
    def axles(self) -> tuple[Axle, ...]:
        """All axles, front to back, in thesis order (11, 12, 13, 21, 31, ...)."""
        return tuple(a for u in self.units for a in u.axles)

    @property
    def axle_names(self) -> tuple[str, ...]:
        """Thesis labels of all axles, front to back."""
        return tuple(a.name for a in self.axles)

    @property
    def state_names(self) -> tuple[str, ...]:
        """Names of the thesis state vector x = [v1, r1..rN, thetaA..]."""
        n = self.n_units
        return ("v1",) + tuple(f"r{i + 1}" for i in range(n)) + tuple(
            f"theta{JOINT_LETTERS[k]}" for k in range(n - 1))

    @property
    def gross_weight_lbf(self) -> float:
        """Sum of the axle loads [lbf]."""
        return float(sum(a.load_lbf for a in self.axles))

    def unit(self, name: str) -> Unit:
        """The unit called ``name`` (``tractor``, ``trailer1``, ...)."""
        for u in self.units:
            if u.name == name:
                return u
        valid = ", ".join(u.name for u in self.units)
        raise KeyError(f"unknown unit {name!r}; this train has: {valid}")

    def symbols(self) -> dict[str, float]:
        """Thesis dimension symbols of this train (x1A, x2A, x11, ...) [in]."""
        out: dict[str, float] = {}
        for k, u in enumerate(self.units):
            i = u.number
            if k > 0:
                out[f"x{i}{JOINT_LETTERS[k - 1]}"] = u.front_joint_in
            rear = "ABCDEF"[k]  # the last unit's rear end: x2B (N = 2) ... x6F (N = 6)
            out[f"x{i}{rear}"] = u.rear_joint_in
            for a in u.axles:
                out[f"x{a.name}"] = abs(a.position_in)
        return out

    def with_masses(self, masses: list[float] | np.ndarray) -> "Train":
        """Copy with unit masses replaced [lbf*s^2/in], front to back."""
        if len(masses) != self.n_units:
            raise ValueError(f"masses: expected {self.n_units} values, got {len(masses)}")
        units = tuple(replace(u, mass=float(m)) for u, m in zip(self.units, masses))
        return replace(self, units=units)

    def scaled_mass(self, factor: float) -> "Train":
        """Copy with every mass, inertia and axle load multiplied by ``factor``."""
        units = tuple(replace(u, mass=u.mass * factor, inertia=u.inertia * factor,
                              axles=tuple(replace(a, load_lbf=a.load_lbf * factor) for a in u.axles))
                      for u in self.units)
        return replace(self, units=units)

    def scaled_tires(self, factor: float) -> "Train":
        """Copy with every tire coefficient (CF, CM, CS) multiplied by ``factor``."""
        units = tuple(replace(u, axles=tuple(replace(a, CF=a.CF * factor, CM=a.CM * factor, CS=a.CS * factor)
                                             for a in u.axles)) for u in self.units)
        return replace(self, units=units)

    def truncated(self, n_units: int, name: str | None = None) -> "Train":
        """The first ``n_units`` units as a train of their own."""
        return replace(self, units=self.units[:n_units], name=name or self.name)
