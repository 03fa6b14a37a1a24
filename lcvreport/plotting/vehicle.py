"""The vehicle seen from above: units and combinations, mode shapes, steady states.

Conventions of the top views: x forward to the right, y toward the curb drawn downward
(the y axis is inverted), lengths to scale, in the display unit ``unit`` (``"m"`` for the
assessment report, ``"in"`` for the thesis' figures).  Functions return a
:class:`matplotlib.figure.Figure` (no pyplot state); axis labels carry units; the smallest
text is 7 pt at the figure's own size, so figures are made at the width they are printed
at (:data:`lcvreport.plotting.style.PAGE_WIDTH_IN`).  The bodies come from
:mod:`lcvreport.model.body`; nothing here computes a result.
"""
from __future__ import annotations

from typing import TYPE_CHECKING


import numpy as np
from matplotlib import patheffects
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from ..model.body import FRONT_OVERHANG_M, TRACK_WIDTH_M, direction, body_rectangle, body_extent, unit_kind, unit_poses
from ..model.vehicle import Vehicle
from ..model.yaw_plane.outputs import rear_offsets
from ..model.yaw_plane.states import joint_letter
from .style import BODY, LENGTH_UNITS, PAGE_WIDTH_IN, SMALL_PT, new_figure

if TYPE_CHECKING:                     # annotations only: plotting sits below analysis
    from ..analysis.modes import Modes


def draw_unit(ax, vehicle: Vehicle, k: int, cg: np.ndarray, psi: float, alpha: float = 1.0, labels: bool = True,
              tires: bool = True, outline_only: bool = False, unit: str = "m") -> None:
    """Draw unit ``k`` (0-based) of ``vehicle`` with its CG at ``cg`` [m] and heading ``psi`` [rad]."""
    f = 1.0 / LENGTH_UNITS[unit]
    u = vehicle.units[k]
    kind = unit_kind(vehicle, k)
    front, rear, hw = body_extent(vehicle, k)
    # bodies under everything; a dolly's frame and drawbar above the trailer body that covers
    # it; every axle above all bodies (a tractor's drive axles sit under the semitrailer's front)
    ax.add_patch(Polygon(f * body_rectangle(cg, psi, front, rear, hw), closed=True, alpha=alpha,
                         facecolor="none" if outline_only else BODY[kind], edgecolor="black", lw=0.8,
                         zorder=1.6 if kind == "dolly" else 1.0))
    if kind == "dolly" and u.front_coupling_m > front:
        ax.add_patch(Polygon(f * body_rectangle(cg, psi, u.front_coupling_m, front, 0.08), closed=True, alpha=alpha,
                             facecolor="none" if outline_only else BODY[kind], edgecolor="black", lw=0.8,
                             zorder=1.6))
    if tires:
        nrm = np.array([-np.sin(psi), np.cos(psi)])
        for a in u.axles:
            centre = cg + a.x_m * direction(psi)
            per_side = max(a.tires // 2, 1)
            D = a.dual_spacing_m
            offs = [TRACK_WIDTH_M / 2] if per_side == 1 else [TRACK_WIDTH_M / 2 - D / 2 + D * j / (per_side - 1)
                                                              for j in range(per_side)]
            for side in (1, -1):
                for o in offs:
                    ax.add_patch(Polygon(f * body_rectangle(centre + side * o * nrm, psi, 0.5, -0.5, 0.11), closed=True,
                                         facecolor="black", alpha=alpha, lw=0, zorder=2.5))
            a_end = centre + (TRACK_WIDTH_M / 2 + D) * nrm
            b_end = centre - (TRACK_WIDTH_M / 2 + D) * nrm
            ax.plot(f * np.array([a_end[0], b_end[0]]), f * np.array([a_end[1], b_end[1]]), color="black",
                    lw=0.8, alpha=alpha, zorder=2.5)
    if k > 0:
        j = f * (cg + u.front_coupling_m * direction(psi))
        ax.plot(j[0], j[1], "o", ms=4, color="white", mec="black", alpha=alpha, zorder=5)
        if labels:
            ax.annotate(joint_letter(k - 1), j, xytext=(0, -12), textcoords="offset points", ha="center",
                        fontsize=SMALL_PT, alpha=alpha)
    if labels:
        ax.annotate(f"{k + 1}", f * cg, xytext=(0, 6), textcoords="offset points", ha="center", va="center",
                    fontsize=8, fontweight="bold", alpha=alpha, color="black",
                    path_effects=[patheffects.withStroke(linewidth=2.0, foreground="white")])


def draw_vehicle(ax, vehicle: Vehicle, theta: np.ndarray | None = None, alpha: float = 1.0, labels: bool = True,
                 tires: bool = True, outline_only: bool = False, unit: str = "m") -> list:
    """Draw ``vehicle`` from above on ``ax`` to scale in the display ``unit`` ("m" or "in").

    Returns the unit poses used (CG position [m], heading [rad]).
    """
    poses = unit_poses(vehicle, theta)
    for k, (cg, psi) in enumerate(poses):
        draw_unit(ax, vehicle, k, cg, psi, alpha, labels, tires, outline_only, unit)
    return poses


def top_view_axes(ax, unit: str, ylim_m: float | None = None):
    ax.set_aspect("equal")
    ax.set_xlabel(f"x, forward [{unit}]")
    ax.set_ylabel(f"y, toward the curb [{unit}]")
    ax.autoscale_view()
    if ylim_m is not None:
        f = 1.0 / LENGTH_UNITS[unit]
        ax.set_ylim(ylim_m * f, -ylim_m * f)
    else:
        ax.invert_yaxis()


def fig_combinations(vehicles: list[tuple[str, Vehicle]], unit: str = "m") -> Figure:
    """Vehicle combinations drawn to scale, one per row (Figure 1-2)."""
    fig, axes = new_figure(PAGE_WIDTH_IN, 1.5 * len(vehicles), nrows=len(vehicles), sharex=True)
    for ax, (label, v) in zip(np.atleast_1d(axes), vehicles):
        draw_vehicle(ax, v, unit=unit)
        ax.set_title(label, fontsize=8, loc="left")
        top_view_axes(ax, unit, ylim_m=2.3)
    return fig


def fig_vehicle(vehicle: Vehicle, title: str) -> Figure:
    """The vehicle to scale from its file, with the couplings, axles and CGs marked [m]."""
    poses = unit_poses(vehicle)
    ends = [(cg[0] + body_extent(vehicle, k)[0], cg[0] + body_extent(vehicle, k)[1]) for k, (cg, _p) in enumerate(poses)]
    length = max(e[0] for e in ends) - min(e[1] for e in ends)      # tractor front to rearmost body end
    fig, ax = new_figure(PAGE_WIDTH_IN, 2.4)
    draw_vehicle(ax, vehicle)
    for k, (cg, _psi) in enumerate(poses):
        ax.plot(cg[0], cg[1], "+", color="red", ms=5, mew=0.8, zorder=6)
    from_file = all(u.body_front_m is not None and u.body_width_m is not None for u in vehicle.units)
    ax.set_title(f"{title} (to scale; + CG, o coupling)\n" +
                 (f"overall {length:.2f} m (bodies from the vehicle file)" if from_file else
                  f"overall about {length:.1f} m (bodies guessed: the file has no body keys; cab front assumed "
                  f"{FRONT_OVERHANG_M:.2f} m ahead of the steer axle)"), fontsize=8)
    top_view_axes(ax, "m", ylim_m=2.6)
    return fig


def fig_mode_shape(vehicle: Vehicle, modes: Modes, index: int, title: str, max_angle_deg: float = 6.0,
                   unit: str = "m") -> Figure:
    """A mode shape seen from above: the articulation angles of mode ``index`` at
    phases 0, 90, 180 and 270 degrees, scaled so the largest angle is ``max_angle_deg``;
    the first unit's own motion is left out, as in the thesis.  A single unit has no
    articulation: its drawing is the straight vehicle with the mode in the title."""
    n = vehicle.n_units
    X = modes.shapes[:, index]
    th = X[n + 1:2 * n]
    fig, ax = new_figure(PAGE_WIDTH_IN, 2.3)
    if th.size and np.abs(th).max() > 0:
        scale = np.radians(max_angle_deg) / np.abs(th).max()
        for phase, alpha in ((0, 1.0), (90, 0.45), (180, 0.3), (270, 0.45)):
            theta = (th * scale * np.exp(1j * np.radians(phase))).real
            draw_vehicle(ax, vehicle, theta, alpha=alpha, labels=phase == 0, tires=phase == 0,
                         outline_only=phase != 0, unit=unit)
    else:
        draw_vehicle(ax, vehicle, unit=unit)
    lam = modes.eigenvalues[index]
    ax.set_title(f"{title}: λ = {lam.real:.3f} {'+' if lam.imag >= 0 else '−'} {abs(lam.imag):.3f}i 1/s, "
                 f"f_d = {modes.damped_frequency_hz[index]:.3f} Hz, ζ = {modes.damping_ratio[index]:.3f}\n"
                 f"(phases 0/90/180/270 deg, largest articulation {max_angle_deg:g} deg)", fontsize=SMALL_PT + 0.5)
    top_view_axes(ax, unit)
    return fig


def fig_steady_state_top_view(vehicle: Vehicle, x_ss: np.ndarray, title: str, exaggerate: float,
                              unit: str = "m") -> Figure:
    """Steady state seen from above with the articulation angles multiplied by
    ``exaggerate`` (Figure 2-10: dog-tracking); the straight-ahead pose is dimmed."""
    n = vehicle.n_units
    fig, ax = new_figure(PAGE_WIDTH_IN, 2.4)
    draw_vehicle(ax, vehicle, alpha=0.25, labels=False, outline_only=True, unit=unit)
    draw_vehicle(ax, vehicle, x_ss[n + 1:2 * n] * exaggerate, unit=unit)
    y = rear_offsets(vehicle, x_ss[n + 1:2 * n]) / LENGTH_UNITS[unit]
    ax.set_title(f"{title}: rear end of unit {n} offset {y[-1]:.3f} {unit} from the tractor axis "
                 f"(angles drawn x{exaggerate:g})", fontsize=8)
    top_view_axes(ax, unit)
    return fig
