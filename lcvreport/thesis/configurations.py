r"""The load configurations of Figures 3-6..3-8 and 4-9..4-11, per tire (for drawing).

The figures are lost; the text describes them.  Every tire carries a residual force
of ``fraction`` of its vertical load, pointing along +y or -y:

``balanced``
    on every axle the curb-side tires push +y and the driver-side tires -y: the
    forces and moments cancel axle by axle ("tires carefully sorted").
``unbalanced_vehicle``
    every tire of every axle pushes +y ("all the residual lateral force pointed in
    the same direction").
``unbalanced_trailer``
    the tires of the last unit all push +y, the rest are balanced ("imbalance
    focused on the rearmost unit").

Examples
--------
>>> from lcvreport import load_preset
>>> forces = tire_forces(load_preset("tractor_semitrailer"), "unbalanced_vehicle")
>>> all(f.force_N > 0 for f in forces)
True
"""
from __future__ import annotations

from dataclasses import dataclass

from ..model.vehicle import Vehicle
from ..model.yaw_plane.loads import ONE_PERCENT

#: load configurations of Figures 3-6..3-8 and 4-9..4-11
CONFIGURATIONS = ("balanced", "unbalanced_vehicle", "unbalanced_trailer")
#: track width used to place the tires in the drawings [m] (72 in: drawing only)
TRACK_WIDTH_M = 1.8288


@dataclass(frozen=True)
class TireForce:
    """Residual force of one tire: on axle ``axle``, side ``side`` (``curb``, +y, or
    ``driver``, -y), its centre ``lateral_offset_m`` from the unit centreline [m] (+y
    toward the curb), ``force_N`` along +y [N]."""

    axle: str
    side: str
    lateral_offset_m: float
    force_N: float


def tire_forces(vehicle: Vehicle, configuration: str, fraction: float = ONE_PERCENT) -> list[TireForce]:
    """Per-tire residual forces of a load configuration (see the module docstring)."""
    if configuration not in CONFIGURATIONS:
        raise ValueError(f"configuration must be one of {', '.join(CONFIGURATIONS)}, got {configuration!r}")
    last = vehicle.units[-1].name
    out = []
    for unit in vehicle.units:
        for ax in unit.axles:
            per_tire = fraction * (ax.static_load_N or 0.0) / ax.tires
            D = ax.dual_spacing_m
            per_side = max(ax.tires // 2, 1)
            offsets = ([TRACK_WIDTH_M / 2] if per_side == 1 else
                       [TRACK_WIDTH_M / 2 - D / 2 + D * k / (per_side - 1) for k in range(per_side)])
            for side, sgn in (("curb", 1.0), ("driver", -1.0)):
                unbalanced = configuration == "unbalanced_vehicle" or (configuration == "unbalanced_trailer"
                                                                         and unit.name == last)
                direction = 1.0 if unbalanced else sgn
                for off in offsets:
                    out.append(TireForce(ax.name, side, sgn * off, direction * per_tire))
    return out
