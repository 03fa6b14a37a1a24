"""Figures: the vehicle seen from above, eigenvalue maps and root loci, time responses,
frequency responses, study charts, tire curves.  Plotting only; every number comes
from the analysis modules.

Conventions of the top views: x forward to the right, y toward the curb drawn
downward (the y axis is inverted), lengths to scale, in the display unit ``unit``
(``"m"`` for the assessment report, ``"in"`` for the thesis' figures).  Functions
return a :class:`matplotlib.figure.Figure` (no pyplot state); axis labels carry units;
the smallest text is 7 pt at the figure's own size, so figures are made at the width
they are printed at (:data:`PAGE_WIDTH_IN`).
"""
from __future__ import annotations

import math

import numpy as np
from matplotlib import patheffects
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch, Polygon

from ..analysis.geometry import rear_offsets
from ..analysis.modes import Modes
from ..model.vehicle import Vehicle, joint_letter
from ..units import M_PER_IN

#: colours per run, stable order
PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#7f7f7f",
           "#bcbd22")
BODY = {"tractor": "#4a6fa5", "trailer": "#b0b7c3", "dolly": "#6b6b6b"}
#: text width of the PDF report [in] (figures are made this wide, so text prints at its size)
PAGE_WIDTH_IN = 6.2
#: smallest font size used anywhere [pt]
SMALL_PT = 7.0
#: drawing dimensions [m] (drawing only; the yaw-plane model has no widths): 72 in track,
#: 102 in body width (the trailer width quoted in chapter V), 96 in cab, 30 in front overhang
TRACK_WIDTH_M = 72 * M_PER_IN
BODY_WIDTH_M = 102 * M_PER_IN
CAB_WIDTH_M = 96 * M_PER_IN
FRONT_OVERHANG_M = 30 * M_PER_IN
#: a unit shorter than this from its front coupling to its rearmost point is drawn as a dolly [m]
DOLLY_LENGTH_M = 3.0
#: a unit this light whose rear coupling sits over its axles is drawn as a (drawbar) dolly [kg]
DOLLY_MASS_KG = 4000.0
#: display units of lengths: metres per display unit
LENGTH_UNITS = {"m": 1.0, "in": M_PER_IN}


def new_figure(width: float = PAGE_WIDTH_IN, height: float = 3.6, ncols: int = 1, nrows: int = 1, **kw):
    """A figure and its axes (not registered with pyplot: no global state)."""
    fig = Figure(figsize=(width, height), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=True, **kw)
    return fig, axes


# ------------------------------------------------------------------ top views
def unit_kind(vehicle: Vehicle, k: int) -> str:
    """``tractor`` (first unit), ``dolly`` or ``trailer``: how a unit is drawn.

    A dolly is short coupled (front coupling to rear within :data:`DOLLY_LENGTH_M`: a
    converter dolly), or a light unit (at most :data:`DOLLY_MASS_KG`) with a unit behind it
    whose coupling sits over its axles (within 1 m: a full trailer's drawbar dolly)."""
    if k == 0:
        return "tractor"
    u = vehicle.units[k]
    rear = min(vehicle.rear_end_x_m(k), u.rearmost_axle.x_m)
    if u.front_coupling_m - rear < DOLLY_LENGTH_M:
        return "dolly"
    axle_x = sum(a.x_m for a in u.axles) / len(u.axles)
    if u.rear_coupling_m is not None and abs(u.rear_coupling_m - axle_x) <= 1.0 and u.mass_kg <= DOLLY_MASS_KG:
        return "dolly"
    return "trailer"


def unit_poses(vehicle: Vehicle, theta: np.ndarray | None = None) -> list[tuple[np.ndarray, float]]:
    """CG position [m] and heading [rad] of every unit, first unit's CG at the origin heading +x.

    ``theta`` are the articulation angles [rad]; headings follow psi_(k+1) = psi_k - theta_k.
    """
    theta = np.zeros(vehicle.n_units - 1) if theta is None else np.asarray(theta, dtype=float)
    poses = []
    for k, unit in enumerate(vehicle.units):
        if k == 0:
            cg, psi = np.zeros(2), 0.0
        else:
            prev_cg, prev_psi = poses[-1]
            joint = prev_cg + vehicle.units[k - 1].rear_coupling_m * _dir(prev_psi)
            psi = prev_psi - theta[k - 1]
            cg = joint - unit.front_coupling_m * _dir(psi)
        poses.append((cg.copy(), psi))
    return poses


def _dir(psi: float) -> np.ndarray:
    return np.array([np.cos(psi), np.sin(psi)])


def _rect(center: np.ndarray, psi: float, front: float, rear: float, half_width: float) -> np.ndarray:
    d = _dir(psi)
    n = np.array([-d[1], d[0]])
    return np.array([center + front * d + half_width * n, center + front * d - half_width * n,
                     center + rear * d - half_width * n, center + rear * d + half_width * n])


def body_extent(vehicle: Vehicle, k: int) -> tuple[float, float, float]:
    """(front x, rear x, half width) of the drawn body of unit ``k`` [m, signed x from its CG]:
    the vehicle file's ``body_front_m``, ``body_rear_m``, ``body_width_m`` where given, else
    an outline guessed from the axles and couplings."""
    u = vehicle.units[k]
    if u.body_front_m is not None and u.body_width_m is not None:
        return u.body_front_m, u.body_rear_m, u.body_width_m / 2
    xs = [a.x_m for a in u.axles]
    kind = unit_kind(vehicle, k)
    if kind == "tractor":
        rear = min(min(xs) - 0.61, u.rear_coupling_m - 0.3 if u.rear_coupling_m is not None else np.inf)
        if u.rear_end_m is not None:
            rear = min(rear, u.rear_end_m)
        return max(xs) + FRONT_OVERHANG_M, rear, CAB_WIDTH_M / 2
    if kind == "dolly":     # the frame over the axles; the drawbar to the front coupling is drawn apart
        return max(xs) + 0.61, min(min(xs), vehicle.rear_end_x_m(k)) - 0.61, TRACK_WIDTH_M / 2 + 0.15
    return u.front_coupling_m + 0.76, min(vehicle.rear_end_x_m(k), min(xs) - 0.6), BODY_WIDTH_M / 2


def draw_unit(ax, vehicle: Vehicle, k: int, cg: np.ndarray, psi: float, alpha: float = 1.0, labels: bool = True,
              tires: bool = True, outline_only: bool = False, unit: str = "m") -> None:
    """Draw unit ``k`` (0-based) of ``vehicle`` with its CG at ``cg`` [m] and heading ``psi`` [rad]."""
    f = 1.0 / LENGTH_UNITS[unit]
    u = vehicle.units[k]
    kind = unit_kind(vehicle, k)
    front, rear, hw = body_extent(vehicle, k)
    # bodies under everything; a dolly's frame and drawbar above the trailer body that covers
    # it; every axle above all bodies (a tractor's drive axles sit under the semitrailer's front)
    ax.add_patch(Polygon(f * _rect(cg, psi, front, rear, hw), closed=True, alpha=alpha,
                         facecolor="none" if outline_only else BODY[kind], edgecolor="black", lw=0.8,
                         zorder=1.6 if kind == "dolly" else 1.0))
    if kind == "dolly" and u.front_coupling_m > front:
        ax.add_patch(Polygon(f * _rect(cg, psi, u.front_coupling_m, front, 0.08), closed=True, alpha=alpha,
                             facecolor="none" if outline_only else BODY[kind], edgecolor="black", lw=0.8,
                             zorder=1.6))
    if tires:
        nrm = np.array([-np.sin(psi), np.cos(psi)])
        for a in u.axles:
            centre = cg + a.x_m * _dir(psi)
            per_side = max(a.tires // 2, 1)
            D = a.dual_spacing_m
            offs = [TRACK_WIDTH_M / 2] if per_side == 1 else [TRACK_WIDTH_M / 2 - D / 2 + D * j / (per_side - 1)
                                                              for j in range(per_side)]
            for side in (1, -1):
                for o in offs:
                    ax.add_patch(Polygon(f * _rect(centre + side * o * nrm, psi, 0.5, -0.5, 0.11), closed=True,
                                         facecolor="black", alpha=alpha, lw=0, zorder=2.5))
            a_end = centre + (TRACK_WIDTH_M / 2 + D) * nrm
            b_end = centre - (TRACK_WIDTH_M / 2 + D) * nrm
            ax.plot(f * np.array([a_end[0], b_end[0]]), f * np.array([a_end[1], b_end[1]]), color="black",
                    lw=0.8, alpha=alpha, zorder=2.5)
    if k > 0:
        j = f * (cg + u.front_coupling_m * _dir(psi))
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


def _top_view_axes(ax, unit: str, ylim_m: float | None = None):
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
        _top_view_axes(ax, unit, ylim_m=2.3)
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
    _top_view_axes(ax, "m", ylim_m=2.6)
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
    _top_view_axes(ax, unit)
    return fig


def fig_load_configuration(vehicle: Vehicle, configuration: str, title: str, fraction: float = 0.01,
                           unit: str = "in") -> Figure:
    """Figures 3-6..3-8, 4-9..4-11: residual lateral force of every tire as an arrow
    (red; dimmed where unchanged from the balanced configuration)."""
    from ..thesis.configurations import tire_forces
    f = 1.0 / LENGTH_UNITS[unit]
    fig, ax = new_figure(PAGE_WIDTH_IN, 2.4)
    poses = draw_vehicle(ax, vehicle, unit=unit)
    balanced = {(t.axle, t.side, t.lateral_offset_m): t.force_N for t in tire_forces(vehicle, "balanced", fraction)}
    forces = tire_forces(vehicle, configuration, fraction)
    fmax = max(abs(t.force_N) for t in forces)
    where = {a.name: i for i, u in enumerate(vehicle.units) for a in u.axles}
    axles = {a.name: a for a in vehicle.axles}
    for t in forces:
        cg, psi = poses[where[t.axle]]
        d = _dir(psi)
        nrm = np.array([-d[1], d[0]])
        start = cg + axles[t.axle].x_m * d + t.lateral_offset_m * nrm
        end = start + np.sign(t.force_N) * (0.45 + 0.75 * abs(t.force_N) / fmax) * nrm
        changed = configuration != "balanced" and balanced[(t.axle, t.side, t.lateral_offset_m)] != t.force_N
        ax.add_patch(FancyArrowPatch(f * start, f * end, arrowstyle="-|>", mutation_scale=7, color="red",
                                     alpha=1.0 if configuration == "balanced" or changed else 0.25, lw=1.0))
    ax.set_title(f"{title} ({100 * fraction:g} % of each tire load along y)", fontsize=8)
    _top_view_axes(ax, unit, ylim_m=2.8)
    return fig


def fig_free_body(vehicle: Vehicle, title: str, unit: str = "in") -> Figure:
    """Figures 3-1 and 4-1: free-body diagrams seen from above: tire forces F_ij and
    residual forces P_ij at the axles, joint forces at the joints, u, v_i, r_i at the CGs.
    The units are pulled apart and drawn in two rows when there are more than two."""
    f = 1.0 / LENGTH_UNITS[unit]
    n = vehicle.n_units
    rows = 1 if n <= 2 else 2
    per_row = int(np.ceil(n / rows))
    fig, axes = new_figure(PAGE_WIDTH_IN, 2.9 * rows, nrows=rows)
    axes = np.atleast_1d(axes)
    poses = unit_poses(vehicle)
    for r, ax in enumerate(axes):
        ks = range(r * per_row, min(n, (r + 1) * per_row))
        if not len(ks):
            continue
        # pull every unit back from the one ahead until their bodies are 1 m apart
        x_cg, x = {}, 0.0
        for k in ks:
            if k == ks[0]:
                x = 0.0
            else:
                rear_ahead = x_cg[k - 1] + body_extent(vehicle, k - 1)[1]
                x = min(poses[k][0][0] - poses[k - 1][0][0] + x_cg[k - 1], rear_ahead - 1.0 -
                        body_extent(vehicle, k)[0])
            x_cg[k] = x
        for k in ks:
            u = vehicle.units[k]
            cg = np.array([x_cg[k], 0.0])
            draw_unit(ax, vehicle, k, cg, 0.0, labels=False, unit=unit)
            ax.add_patch(FancyArrowPatch(f * cg, f * (cg + (1.1, 0)), arrowstyle="-|>", mutation_scale=7, color="#333"))
            ax.add_patch(FancyArrowPatch(f * cg, f * (cg + (0, 0.95)), arrowstyle="-|>", mutation_scale=7,
                                         color="#333"))
            ax.annotate(f"u, v{k + 1}, r{k + 1}", f * cg, xytext=(4, 4), textcoords="offset points",
                        fontsize=SMALL_PT)
            previous = None
            for a in sorted(u.axles, key=lambda a: -a.x_m):
                p = cg + (a.x_m, 0)
                # an axle close behind the previous one gets its label one step further out
                far = previous is not None and previous[0] - a.x_m < 1.6 and not previous[1]
                top = -2.0 - (0.75 if far else 0.0)
                ax.add_patch(FancyArrowPatch(f * (p + (0, top)), f * (p + (0, -1.2)), arrowstyle="-|>",
                                             mutation_scale=7, color="blue"))
                ax.annotate(f"F{a.name}, P{a.name}\nM{a.name}, T{a.name}", f * (p + (0, top - 0.05)), ha="center",
                            fontsize=SMALL_PT, color="blue")
                previous = (a.x_m, far)
            if k > 0:
                p = cg + (u.front_coupling_m, 0)
                ax.add_patch(FancyArrowPatch(f * (p + (0, 1.8)), f * (p + (0, 1.15)), arrowstyle="-|>",
                                             mutation_scale=7, color="green"))
                ax.annotate(f"F{joint_letter(k - 1)}", f * (p + (0, 2.05)), ha="center", va="top",
                            fontsize=SMALL_PT, color="green")
            if k < n - 1:
                p = cg + (u.rear_coupling_m, 0)
                ax.add_patch(FancyArrowPatch(f * (p + (0, 1.15)), f * (p + (0, 1.8)), arrowstyle="-|>",
                                             mutation_scale=7, color="green"))
                ax.annotate(f"F{joint_letter(k)}", f * (p + (0, 2.05)), ha="center", va="top",
                            fontsize=SMALL_PT, color="green")
        _top_view_axes(ax, unit, ylim_m=2.6)
        f_unit = 1.0 / LENGTH_UNITS[unit]
        ax.set_ylim(2.7 * f_unit, -4.1 * f_unit)
    axes[0].set_title(title, fontsize=8)
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
    _top_view_axes(ax, unit)
    return fig


# ------------------------------------------------------------------ eigenvalues
def fig_eigenvalues(sets: list[tuple[str, np.ndarray]], title: str, upper: bool = False,
                    connect_mode: int | None = None) -> Figure:
    """Eigenvalue map(s): real part [1/s] against imaginary part [1/s].

    ``upper`` shows only the upper-left quadrant; ``connect_mode`` (1-based, mode
    order of :func:`lcvreport.analysis.modes.mode_order`) joins that mode across the
    sets with a dashed black line, as the thesis does for Mode 7.
    """
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.6)
    markers = "osD^v<>ph"
    for i, (label, lam) in enumerate(sets):
        ax.scatter(lam.real, lam.imag, s=18, marker=markers[i % len(markers)], color=PALETTE[i % len(PALETTE)],
                   label=label, zorder=3)
    if connect_mode is not None:
        pts = np.array([lam[connect_mode - 1] for _, lam in sets])
        ax.plot(pts.real, pts.imag, "k--", lw=1, label=f"Mode {connect_mode}")
    ax.axvline(0, color="black", lw=0.8)
    ax.axhline(0, color="black", lw=0.5)
    if upper:
        ax.set_xlim(right=0)
        ax.set_ylim(bottom=0)
    ax.set_xlabel("Re(lambda) [1/s]")
    ax.set_ylabel("Im(lambda) [1/s]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


def fig_root_locus(speeds_kph: np.ndarray, eigenvalues: np.ndarray, title: str,
                   critical_kph: float | None = None) -> Figure:
    """Root locus over speed: every eigenvalue [1/s] coloured by the speed [km/h]."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.8)
    sc = None
    for j in range(eigenvalues.shape[1]):
        sc = ax.scatter(eigenvalues[:, j].real, eigenvalues[:, j].imag, c=speeds_kph, cmap="viridis", s=6,
                        zorder=3, label="_nolegend_" if j else "eigenvalues")
    cb = fig.colorbar(sc, ax=ax)
    cb.set_label("speed [km/h]", fontsize=8)
    cb.ax.tick_params(labelsize=SMALL_PT)
    ax.axvline(0, color="black", lw=0.8)
    ax.axhline(0, color="black", lw=0.5)
    # zoom to the oscillatory modes: far-left real poles (fast, well damped) would squeeze them
    osc = np.abs(eigenvalues.imag) > 1e-9 * np.abs(eigenvalues).max()
    if osc.any():
        left = 1.15 * min(eigenvalues.real[osc].min(), 0.0) - 0.05
        right = max(0.1 * abs(left), 1.15 * eigenvalues.real.max())
        hidden = int(np.sum(eigenvalues.real.min(axis=0) < left))
        ax.set_xlim(left, right)
        top = 1.1 * np.abs(eigenvalues.imag[osc]).max()
        ax.set_ylim(-top, top)
        if hidden:
            ax.text(0.01, 0.02, f"{hidden} real mode(s) left of the frame (faster, Re < {left:.3g} 1/s; in the CSV)",
                    transform=ax.transAxes, fontsize=SMALL_PT, ha="left", va="bottom")
    note = "stable throughout" if critical_kph is None else f"critical speed {critical_kph:.1f} km/h"
    ax.set_xlabel("Re(lambda) [1/s]")
    ax.set_ylabel("Im(lambda) [1/s]")
    ax.grid(True, lw=0.3)
    ax.set_title(f"{title} ({note})", fontsize=9)
    return fig


def fig_damping_over_speed(speeds_kph: np.ndarray, zeta: np.ndarray, max_real: np.ndarray, title: str,
                           critical_kph: float | None, speed_kph: float | None = None) -> Figure:
    """Least damping ratio [-] and largest real part [1/s] against speed [km/h]."""
    fig, (a1, a2) = new_figure(PAGE_WIDTH_IN, 3.8, nrows=2, sharex=True)
    a1.plot(speeds_kph, zeta, color=PALETTE[0])
    a1.set_ylabel("least damping ratio [-]")
    a2.plot(speeds_kph, max_real, color=PALETTE[1])
    a2.axhline(0, color="black", lw=0.8)
    a2.set_ylabel("max Re(lambda) [1/s]")
    a2.set_xlabel("speed [km/h]")
    for ax in (a1, a2):
        ax.grid(True, lw=0.3)
        if critical_kph is not None:
            ax.axvline(critical_kph, color="red", ls="--", lw=1)
        if speed_kph is not None:
            ax.axvline(speed_kph, color="black", ls=":", lw=1)
    note = "stable throughout" if critical_kph is None else f"critical speed {critical_kph:.1f} km/h (red)"
    a1.set_title(f"{title}: {note}" + ("; dotted: the report's speed" if speed_kph is not None else ""), fontsize=9)
    return fig


# ------------------------------------------------------------------ time and frequency
def fig_time(series: list[tuple[str, np.ndarray, np.ndarray, dict]], ylabel: str, title: str,
             hlines: list[tuple[str, float]] = (), xlim: tuple | None = None, annotate_peaks: bool = False,
             height: float = 3.4) -> Figure:
    """Time histories: ``series`` of (label, time [s], values, line style keywords).

    ``annotate_peaks`` marks each series' largest magnitude (within ``xlim``) with a dot and
    gives its value in the legend; ``hlines`` are (label, value) dotted lines, one labelled
    on the plot, several labelled in the right margin at their heights, spread apart
    where they would overlap.  More than eight series put the legend below the plot."""
    fig, ax = new_figure(PAGE_WIDTH_IN, height + (0.9 if len(series) > 8 else 0.0))
    for i, (label, t, y, style) in enumerate(series):
        kw = {"color": PALETTE[i % len(PALETTE)], "lw": 1.1}
        kw.update(style)
        if annotate_peaks:
            mask = np.ones_like(t, dtype=bool) if xlim is None else (t >= xlim[0]) & (t <= xlim[1])
            k = int(np.argmax(np.abs(np.where(mask, y, 0))))
            label = f"{label} (peak {y[k]:.3f})"
            ax.plot(t[k], y[k], "o", ms=3, color=kw["color"])
        ax.plot(t, y, label=label, **kw)
    for label, value in hlines:
        ax.axhline(value, color="black", ls=":", lw=1)
    if len(hlines) == 1:
        ax.annotate(hlines[0][0], (1.0, hlines[0][1]), xycoords=("axes fraction", "data"), ha="right",
                    va="bottom", fontsize=SMALL_PT)
    if xlim is not None:
        ax.set_xlim(*xlim)
    if len(hlines) > 1:
        _margin_labels(ax, hlines)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    if len(series) > 8:
        ax.legend(fontsize=SMALL_PT, ncol=2, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    elif series:
        ax.legend(fontsize=SMALL_PT, ncol=2)
    ax.set_title(title, fontsize=9)
    return fig


def _margin_labels(ax, lines: list[tuple[str, float]]) -> None:
    """Label horizontal lines in the right margin, each at its height unless that would put
    it within one text line of its neighbour: then the labels are spread evenly apart
    (keeping their order) and a leader joins each to its line."""
    lo, hi = ax.get_ylim()
    height_pt = ax.figure.get_size_inches()[1] * 72 * 0.75          # about the axes' height [pt]
    gap = (SMALL_PT * 1.35) * (hi - lo) / height_pt                     # one text line in data units
    order = sorted(range(len(lines)), key=lambda k: lines[k][1])
    placed = [lines[k][1] for k in order]
    for _ in range(len(placed)):                                        # push up, then pull the block down
        for j in range(1, len(placed)):
            placed[j] = max(placed[j], placed[j - 1] + gap)
        excess = placed[-1] - max(hi - gap / 2, lines[order[-1]][1])
        if excess <= 0:
            break
        placed = [p - excess for p in placed]
    for k, y in zip(order, placed):
        label, value = lines[k]
        ax.annotate(label, (1.0, value), xycoords=("axes fraction", "data"), xytext=(1.03, y),
                    textcoords=("axes fraction", "data"), ha="left", va="center", fontsize=SMALL_PT,
                    annotation_clip=False, arrowprops=dict(arrowstyle="-", lw=0.4, color="0.4",
                                                           shrinkA=0, shrinkB=1))


def plot_time_response(response, signals=None, ax=None, **style) -> Figure:
    """Signals of a :class:`lcvreport.analysis.response.TimeResponse` against time."""
    names = signals or [f"y{k}" for k in range(2, response.vehicle.n_units + 1)] or ["Y1"]
    if ax is None:
        fig, ax = new_figure(PAGE_WIDTH_IN, 3.2)
    else:
        fig = ax.figure
    units = {"v": "m/s", "r": "rad/s", "t": "rad", "y": "m", "Y": "m", "a": "m/s²", "p": "rad"}
    for i, name in enumerate(names):
        kw = {"color": PALETTE[i % len(PALETTE)], "lw": 1.1}
        kw.update(style)
        ax.plot(response.time, response[name], label=f"{name} [{units.get(name[0], '')}]", **kw)
    ax.set_xlabel("time [s]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT, ncol=2)
    if response.label:
        ax.set_title(response.label, fontsize=9)
    return fig


def plot_manoeuvre(response, signals=None, ax=None) -> Figure:
    """Signals of a :class:`lcvreport.analysis.exact.ManoeuvreResponse` against time
    (default: every unit's lateral acceleration [m/s^2], the steer angle [deg] dotted on
    a second axis)."""
    if ax is None:
        fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    else:
        fig = ax.figure
    v = response.vehicle
    signals = signals or [f"ay{i + 1}" for i in range(v.n_units)]
    for i, name in enumerate(signals):
        ax.plot(response.time, response[name], color=PALETTE[i % len(PALETTE)], lw=1.0, label=name)
    ax2 = ax.twinx()
    ax2.plot(response.time, np.degrees(response["delta"]), color="black", lw=0.8, ls=":", label="steer angle")
    ax2.set_ylabel("steer angle [deg] (dotted)")
    ax2.tick_params(labelsize=SMALL_PT)
    ax.set_xlabel("time [s]")
    units = {"ay": "m/s²", "Y_": "m", "the": "rad", "r": "rad/s", "y": "m"}
    unit = next((u for k, u in units.items() if signals[0].startswith(k)), "SI")
    ax.set_ylabel(f"{', '.join(signals[:3])}{' ...' if len(signals) > 3 else ''} [{unit}]")
    ax.grid(True, lw=0.3)
    ax.legend(handles=ax.get_lines() + ax2.get_lines(), fontsize=SMALL_PT, ncol=4, loc="upper center",
              bbox_to_anchor=(0.5, -0.18), frameon=False)
    return fig


def plot_single_sine(ss, ax=None) -> Figure:
    """Lateral accelerations [m/s^2] of every unit in a single-sine manoeuvre, and the steer angle."""
    if ax is None:
        fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    else:
        fig = ax.figure
    ay = ss.ay
    names = ss.vehicle.unit_names if ss.vehicle is not None else [f"unit {i + 1}" for i in range(ay.shape[1])]
    for i in range(ay.shape[1]):
        ax.plot(ss.time, ay[:, i], color=PALETTE[i % len(PALETTE)], lw=1.0,
                label=f"a{i + 1} {names[i]} (peak {ss.peaks[i]:.3g})")
    ax2 = ax.twinx()
    ax2.plot(ss.time, np.degrees(ss.delta), color="black", lw=0.8, ls=":", label="steer angle")
    ax2.set_ylabel("steer angle [deg] (dotted)")
    ax2.tick_params(labelsize=SMALL_PT)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("lateral acceleration [m/s²]")
    ax.grid(True, lw=0.3)
    # below the axes: inside, it covered the peaks RA is computed from
    ax.legend(handles=ax.get_lines() + ax2.get_lines(), fontsize=SMALL_PT, ncol=3, loc="upper center",
              bbox_to_anchor=(0.5, -0.18), frameon=False)
    return fig


def fig_frequency(f_hz: np.ndarray, curves: list[tuple[str, np.ndarray]], ylabel: str, title: str,
                  mark_hz: float | None = None, logy: bool = False, peak: tuple | None = None) -> Figure:
    """Curves against frequency [Hz] (RA(f), gains)."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.2)
    for i, (label, y) in enumerate(curves):
        ax.plot(f_hz, y, color=PALETTE[i % len(PALETTE)], lw=1.1, label=label)
    if mark_hz is not None:
        ax.axvline(mark_hz, color="black", ls=":", lw=1)
    if peak is not None:
        ax.plot([peak[0]], [peak[1]], "o", color="black", ms=4)
        ax.annotate(f"peak {peak[1]:.3f} at {peak[0]:.3f} Hz", peak, xytext=(10, 4), textcoords="offset points",
                    fontsize=SMALL_PT)
    if logy:
        ax.set_yscale("log")
    ax.set_xlabel("steer frequency [Hz]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3, which="both")
    ax.legend(fontsize=SMALL_PT, ncol=2)
    ax.set_title(title, fontsize=9)
    return fig


def fig_lane_change(lc, title: str) -> Figure:
    """The path-following lane change (:class:`lcvreport.analysis.field_measures.LaneChangeMeasures`):
    the steer [deg]; the paths of the steered axle and of the rearmost axle [m] with the
    final offset and HSTO marked; the steered axle's and the last unit's lateral
    accelerations [m/s^2]."""
    r = lc.response
    fig, axes = new_figure(PAGE_WIDTH_IN, 5.6, nrows=3, sharex=True)
    axes[0].plot(r.time, np.degrees(r["delta"]), color="black", lw=1.0)
    axes[0].set_ylabel("steer [deg]")
    ys, yr = r[f"Y_{lc.steered_axle}"], r[f"Y_{lc.rear_axle}"]
    axes[1].plot(r.time, ys, color=PALETTE[0], lw=1.1, label=f"steered axle {lc.steered_axle}")
    axes[1].plot(r.time, yr, color=PALETTE[1], lw=1.1, label=f"rearmost axle {lc.rear_axle}")
    axes[1].axhline(lc.final_offset_m, color="gray", ls=":", lw=0.9)
    k = int(np.argmax(np.sign(lc.final_offset_m or 1.0) * (yr - lc.final_offset_m)))
    if lc.hsto_m > 0:
        axes[1].annotate(f"HSTO {lc.hsto_m:.3f} m", (r.time[k], yr[k]), xytext=(12, -14), textcoords="offset points",
                         fontsize=SMALL_PT, arrowprops={"arrowstyle": "->", "lw": 0.6})
        axes[1].plot([r.time[k], r.time[k]], [lc.final_offset_m, yr[k]], color=PALETTE[1], lw=2.0)
    axes[1].set_ylabel("lateral position [m]")
    axes[1].legend(fontsize=SMALL_PT, loc="lower right")
    n = r.vehicle.n_units
    axes[2].plot(r.time, r["a_steer"], color=PALETTE[0], lw=1.0, label="steered axle a_s")
    axes[2].plot(r.time, r[f"ay{n}"], color=PALETTE[1], lw=1.0, label=f"a{n} (last unit's CG)")
    axes[2].set_ylabel("lateral acc. [m/s²]")
    axes[2].set_xlabel("time [s]")
    axes[2].legend(fontsize=SMALL_PT, loc="lower right")
    for ax in axes:
        ax.grid(True, lw=0.3)
    axes[0].set_title(title, fontsize=9)
    return fig


def fig_pulse(ydc, names: list[str], title: str) -> Figure:
    """Articulation angles [deg] after the pulse steer of the yaw damping measure, the
    extrema the ratio method uses marked (:class:`lcvreport.analysis.field_measures.YawDamping`)."""
    r = ydc.response
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    end = min(r.time[-1], 12.0)
    sel = r.time <= end
    for i, name in enumerate(names):
        c = PALETTE[i % len(PALETTE)]
        ax.plot(r.time[sel], np.degrees(r[name][sel]), color=c, lw=1.0,
                label=f"{name} (ζ {ydc.per_joint[i]:.3f})" if ydc.per_joint[i] is not None else name)
        t, v = ydc.extrema[i]
        used = len(ydc.amplitudes[i]) + 1 if len(ydc.amplitudes[i]) else 0
        keep = np.arange(t.size) < used
        ax.plot(t[keep & (t <= end)], np.degrees(v[keep & (t <= end)]), "o", ms=3, color=c)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("articulation angle [deg]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.18), frameon=False)
    ax.set_title(title, fontsize=9)
    return fig


def fig_offtracking_histogram(stats, title: str) -> Figure:
    """The Monte Carlo offtracking [m] of :class:`lcvreport.analysis.tracking.TrackingStats`
    as a histogram, the exact mean and the lane margins marked."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.0)
    x = stats.samples_m
    m = stats.margin_m
    ax.hist(x, bins=120, color=PALETTE[0], alpha=0.8, density=True, label=f"{stats.draws} draws (seed {stats.seed})")
    ax.axvline(stats.offtracking_mean_m, color="black", lw=1.0, label=f"mean {stats.offtracking_mean_m:.4g} m (exact)")
    if abs(x).max() >= 0.5 * m:
        for sgn in (-1, 1):
            ax.axvline(sgn * m, color=PALETTE[1], ls="--", lw=1.0, label="lane margin ±%.3f m" % m if sgn > 0 else None)
    else:                               # the margin would squash the histogram: say where it is
        sd = stats.offtracking_sd_m
        far = (m - abs(stats.offtracking_mean_m)) / sd if sd > 0 else float("inf")
        ax.plot([], [], " ", label=f"lane margin ±{m:.3f} m: off the axis, {far:.3g} SD from the mean")
    ax.set_xlabel("trimmed offtracking [m]")
    ax.set_ylabel("probability density [1/m]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(f"{title}: P(|offtracking| > {m:.3f} m) = {stats.exceedance_probability:.3g}", fontsize=9)
    return fig


def fig_swept_path(turn, title: str, outlines_every_m: float = 2.0) -> Figure:
    """The low-speed turn seen from above, to scale (SPEC section 16): every unit's outline
    every ``outlines_every_m`` of path, the swept region's envelope within the turn, the
    paths of the outside steer wheel and of the last unit's inside rear wheel, the arc's
    centre and the measures marked [m].  ``turn`` is a
    :class:`lcvreport.analysis.low_speed_turn.LowSpeedTurn`."""
    from matplotlib.patches import Polygon as _Poly
    from ..analysis.low_speed_turn import corners
    v, run = turn.vehicle, turn.run
    path = run.path
    C = path.centre
    s_draw_end = min(path.s_end, path.arc_end_s + 1.2 * turn.overall_length_m)
    fig, ax = new_figure(PAGE_WIDTH_IN, 5.6)
    # outlines
    s_out = np.arange(0.0, s_draw_end + 1e-9, outlines_every_m)
    for k in range(v.n_units):
        cx, cy = corners(v, k)
        pts = run.unit_points(s_out, k, cx, cy)
        for j, poly in enumerate(pts):
            ax.add_patch(_Poly(poly, closed=True, facecolor="none", edgecolor=PALETTE[k % len(PALETTE)],
                               lw=0.35, alpha=0.55, zorder=1))
    # the vehicle at the start, filled
    for k in range(v.n_units):
        cx, cy = corners(v, k)
        ax.add_patch(_Poly(run.unit_points([0.0], k, cx, cy)[0], closed=True, facecolor=PALETTE[k % len(PALETTE)],
                           edgecolor="black", lw=0.5, alpha=0.35, zorder=2,
                           label="the combination before the turn" if k == 0 else None))
    # the envelope of the swept region within the turn (computed by the turn, drawn here)
    mid, r_min, r_max = turn.envelope()
    env = lambda rr: np.stack([C[0] + rr * np.sin(mid), C[1] - rr * np.cos(mid)], axis=1)  # noqa: E731
    ax.plot(*env(r_max).T, color="black", lw=1.4, zorder=6, label="envelope of the swept region (in the turn)")
    ax.plot(*env(r_min).T, color="black", lw=1.4, zorder=6)
    angle = math.radians(min(turn.angle_deg, 360.0))
    # the two wheel paths
    steer = max((a for a in v.units[0].axles if a.steered), key=lambda a: a.x_m)
    s_path = np.linspace(-0.3 * turn.overall_length_m, s_draw_end, 800)
    s_pos = np.clip(s_path, 0.0, None)
    ow = run.unit_points(s_pos, 0, [steer.x_m], [-steer.track_width_m / 2])[:, 0]
    ow[s_path < 0, 0] += s_path[s_path < 0]
    ax.plot(*ow.T, color=PALETTE[1], lw=1.2, zorder=5, label=f"outside wheel of axle {steer.name} (R = "
            f"{turn.radius_m:g} m)")
    last = v.n_units - 1
    rear = v.units[last].rearmost_axle
    iw = run.unit_points(s_pos, last, [rear.x_m], [rear.track_width_m / 2])[:, 0]
    iw[s_path < 0, 0] += s_path[s_path < 0]
    ax.plot(*iw.T, color=PALETTE[2], lw=1.2, zorder=5, label=f"inside wheel of axle {rear.name}")
    ax.plot(*C, "+", color="black", ms=8, zorder=6)
    # measures: the swept width along the bisector of the turn, the offtracking in the text
    w = turn.where
    if turn.lssp_m is not None:
        b = 0.5 * angle
        u_dir = np.array([math.sin(b), -math.cos(b)])
        p_in, p_out = C + w["inner_radius_m"] * u_dir, C + w["outer_radius_m"] * u_dir
        ax.annotate("", p_out, p_in, arrowprops=dict(arrowstyle="<->", lw=0.9, color="black"), zorder=7)
        ax.text(*(0.5 * (p_in + p_out)), f"  swept width {turn.lssp_m:.2f} m", fontsize=SMALL_PT, zorder=7,
                rotation=math.degrees(b) - 90 if -90 < math.degrees(b) - 90 < 90 else 0)
    ax.set_aspect("equal")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.grid(True, lw=0.3)
    ax.autoscale_view()
    ax.legend(fontsize=SMALL_PT, loc="upper left")
    def m(value, digits=2):
        return "not computed" if value is None else f"{value:.{digits}f} m"
    ax.set_title(f"{title}\nswept width {m(turn.lssp_m)}, low-speed offtracking {m(turn.low_speed_offtracking_m)}, "
                 f"largest tail swing {m(turn.max_tail_swing_m, 3)}, frontal swing {m(turn.frontal_swing_m)}",
                 fontsize=8)
    fig.lcv_data = turn.rows()
    return fig


def fig_tracking_sensitivity(answer) -> Figure:
    """Trimmed offtracking SD [m] and lane exceedance against the population's scale factor
    (:class:`lcvreport.thesis.tracking_questions.SensitivityAnswer`)."""
    rows = answer.rows()
    k = np.array([r["scale"] for r in rows])
    fig, (ax1, ax2) = new_figure(PAGE_WIDTH_IN, 3.0, ncols=2)
    ax1.plot(k, [r["offtracking_sd_m"] for r in rows], "o-", color=PALETTE[0], label="standard deviation (exact)")
    ax1.plot(k, [abs(r["offtracking_mean_m"]) for r in rows], "s--", color=PALETTE[1], label="|mean| (exact)")
    ax1.set_xlabel("scale on the assumed population [-]")
    ax1.set_ylabel("trimmed offtracking [m]")
    ax1.grid(True, lw=0.3)
    ax1.legend(fontsize=SMALL_PT)
    p = np.array([r["p_exceed"] for r in rows])
    hi = np.array([r["p_exceed_ci95_hi"] for r in rows])
    ax2.plot(k, [r["log10_p_exceed_gaussian"] for r in rows], "o-", color=PALETTE[0], label="closed form (normal)")
    ax2.plot(k, np.where(p > 0, np.log10(np.where(p > 0, p, 1.0)), np.nan), "s", color=PALETTE[1],
             label="Monte Carlo estimate")
    ax2.plot(k, np.log10(hi), "v:", color=PALETTE[2], label="Monte Carlo: upper end of its 95 % interval")
    ax2.set_xlabel("scale on the assumed population [-]")
    ax2.set_ylabel("log10 P(|offtracking| > lane margin) [-]")
    ax2.grid(True, lw=0.3)
    floor = -40.0                       # the smallest scales' closed form (e.g. 10^-2181) would squash the rest
    if min(r["log10_p_exceed_gaussian"] for r in rows) < floor:
        ax2.set_ylim(floor, 1.0)
        ax2.text(0.98, 0.72, "below 10^-40: off the axis (see the table)", transform=ax2.transAxes, ha="right",
                 va="top", fontsize=SMALL_PT)
    ax2.legend(fontsize=SMALL_PT, loc="lower left")
    fig.suptitle("aucnat at 50 mph: the assumed tire population scaled", fontsize=9)
    fig.lcv_data = rows
    return fig


def fig_mounting_study(answer) -> Figure:
    """|Trimmed offtracking| [m] of drawn tire sets mounted at random, in order with every
    serial side out, and by the exact plan (:class:`lcvreport.thesis.tracking_questions.MountingAnswer`)."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 2.8)
    groups = (("at random", answer.random_offtracking_m), ("serial side out", answer.out_offtracking_m),
              ("exact plan", answer.planned_offtracking_m))
    for i, (label, x) in enumerate(groups):
        y = np.full(x.size, i) + np.linspace(-0.2, 0.2, x.size)
        ax.plot(np.abs(x) * 1e3, y, "o", ms=3, color=PALETTE[i], label=label)
    ax.set_yticks(range(len(groups)), [g[0] for g in groups])
    ax.set_xlabel("|trimmed offtracking| [mm]")
    ax.grid(True, lw=0.3)
    ax.set_title(f"aucnat at 50 mph: {answer.random_offtracking_m.size} tire sets drawn from the assumed population",
                 fontsize=9)
    fig.lcv_data = [{"set": k, "random_mounting_m": float(a), "serial_side_out_m": float(b), "plan_m": float(c)}
                    for k, (a, b, c) in enumerate(zip(answer.random_offtracking_m, answer.out_offtracking_m,
                                                      answer.planned_offtracking_m))]
    return fig


def fig_bars(labels: list[str], groups: list[tuple[str, np.ndarray]], ylabel: str, title: str,
             height: float = 3.6, horizontal: bool = False) -> Figure:
    """Grouped bar chart (Figures 5-4, 5-8, 5-13, 5-18, 5-20; conicity sensitivity).

    ``horizontal=True`` lays the categories down the page, one row each, top to bottom in the
    order given, for many categories with long names (Figure 5-20): every value label then
    has a row of its own; ``ylabel`` names the value axis either way."""
    fig, ax = new_figure(PAGE_WIDTH_IN, height)
    x = np.arange(len(labels))
    w = 0.8 / len(groups)
    for i, (glabel, values) in enumerate(groups):
        pos = x + (i - (len(groups) - 1) / 2) * w
        if horizontal:
            bars = ax.barh(pos, values, w, label=glabel, color=PALETTE[i])
            for b, v in zip(bars, values):
                ax.annotate(f" {v:.3g} ", (b.get_width(), b.get_y() + b.get_height() / 2), va="center",
                            ha="left" if v >= 0 else "right", fontsize=SMALL_PT)
        else:
            bars = ax.bar(pos, values, w, label=glabel, color=PALETTE[i])
            for b, v in zip(bars, values):
                ax.annotate(f"{v:.3g}", (b.get_x() + b.get_width() / 2, b.get_height()), ha="center",
                            va="bottom" if v >= 0 else "top", fontsize=SMALL_PT)
    if horizontal:
        ax.set_yticks(x, labels, fontsize=SMALL_PT)
        ax.set_ylim(len(labels) - 0.5, -0.5)
        lo, hi = ax.get_xlim()
        ax.set_xlim(lo - 0.12 * (hi - lo), hi + 0.12 * (hi - lo))     # room for the value labels
        ax.axvline(0, color="black", lw=0.6)
        ax.set_xlabel(ylabel)
        ax.grid(True, axis="x", lw=0.3)
    else:
        ax.set_xticks(x, labels, rotation=25, ha="right", fontsize=SMALL_PT)
        ax.axhline(0, color="black", lw=0.6)
        ax.set_ylabel(ylabel)
        ax.grid(True, axis="y", lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


def fig_fit(x: np.ndarray, ys: list[tuple[str, np.ndarray]], degree: int | None, xlabel: str, ylabel: str,
            title: str) -> Figure:
    """Points and (optional) least-squares polynomial fits of the given degree."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    xx = np.linspace(np.min(x), np.max(x), 101)
    for i, (label, y) in enumerate(ys):
        ax.plot(x, y, "o", color=PALETTE[i], label=label)
        if degree is not None:
            c = np.polyfit(x, y, degree)
            ax.plot(xx, np.polyval(c, xx), "--", color=PALETTE[i], lw=1, label=f"degree-{degree} fit")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


# ------------------------------------------------------------------ tires (thesis, inch-pound units)
def fig_tire_vs_slip(quantity: str, loads_lbf: tuple[float, ...], title: str, residual_lbf: float = 0.0) -> Figure:
    """Figures 2-5, 2-6, 2-8: the linear tire model against slip angle for several
    vertical loads, per tire: lateral force F = CF alpha [lbf] or aligning moment
    -CM alpha [lbf*in]; ``residual_lbf`` shifts the force curves (Figure 2-8)."""
    from ..thesis.tires import tire_fit
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    fit = tire_fit()
    alpha_deg = np.linspace(-2.0, 2.0, 81)
    alpha = np.radians(alpha_deg)
    for i, w in enumerate(loads_lbf):
        cf, cm, _cs = fit.evaluate(w)
        y = cf * alpha + residual_lbf if quantity == "force" else -cm * alpha
        ax.plot(alpha_deg, y, color=PALETTE[i], label=f"tire load {w:.0f} lbf")
    if residual_lbf:
        ax.annotate(f"residual force {residual_lbf:g} lbf at zero slip", (0, residual_lbf), xytext=(10, -25),
                    textcoords="offset points", fontsize=SMALL_PT, arrowprops=dict(arrowstyle="->"))
    ax.axhline(0, color="black", lw=0.6)
    ax.axvline(0, color="black", lw=0.6)
    ax.set_xlabel("slip angle alpha [deg]")
    ax.set_ylabel("lateral force per tire [lbf]" if quantity == "force" else "aligning moment per tire [lbf*in]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


def fig_tire_fit(key: str, ylabel: str, title: str) -> Figure:
    """Figures D.1-D.3: per-tire coefficient against tire load, the Table D points and the cubic fit."""
    from ..thesis.tires import tire_fit
    fit = tire_fit()
    pts = fit.points[key]
    coef = getattr(fit, key)
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    w = np.linspace(pts[:, 0].min(), pts[:, 0].max(), 201)
    ax.plot(pts[:, 0], pts[:, 1], "o", color=PALETTE[0], label="Tables D.1-D.5")
    ax.plot(w, np.polyval(coef, w), "-", color=PALETTE[1],
            label="cubic fit: " + " + ".join(f"{c:.4g} W^{3 - k}" for k, c in enumerate(coef)))
    ax.set_xlabel("vertical tire load W [lbf]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


def _study_label(name: str) -> str:
    """``trailer3.cornering_stiffness_scale`` -> three short lines and the unit (panels are narrow)."""
    text = name.replace(".", "\n").replace("_stiffness_", "_stiffness\n")
    from ..analysis.registry import unit_of
    return f"{text} [{unit_of(name)}]"


def fig_study_scatter(table, factors: list[str], measures: list[str], max_points: int = 2000,
                      seed: int = 0) -> Figure:
    """Every measure (rows) against every factor (columns): the cases (at most ``max_points``,
    drawn with a fixed seed) and the median per bin of the factor."""
    nrows, ncols = len(measures), len(factors)
    fig = Figure(figsize=(PAGE_WIDTH_IN, max(1.6, 1.35 * nrows + 0.4)), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=False)
    n = len(table)
    pick = np.sort(np.random.default_rng(seed).choice(n, min(n, max_points), replace=False)) if n else np.arange(0)
    for i, m in enumerate(measures):
        y_all = table[m].to_numpy(dtype=float)
        for j, f in enumerate(factors):
            ax = axes[i][j]
            x_all = table[f].to_numpy(dtype=float)
            ax.plot(x_all[pick], y_all[pick], ".", ms=1.5, color=PALETTE[0], alpha=0.35, rasterized=True)
            ok = np.isfinite(y_all)
            if ok.sum() > 10:
                distinct = np.unique(x_all[ok])
                if distinct.size <= 12:
                    centres = distinct
                    med = [np.median(y_all[ok][x_all[ok] == c]) for c in distinct]
                else:
                    edges = np.quantile(x_all[ok], np.linspace(0, 1, 11))
                    which = np.clip(np.searchsorted(edges, x_all[ok], side="right") - 1, 0, 9)
                    centres = [np.median(x_all[ok][which == b]) for b in range(10) if np.any(which == b)]
                    med = [np.median(y_all[ok][which == b]) for b in range(10) if np.any(which == b)]
                ax.plot(centres, med, "-", color=PALETTE[1], lw=1.2)
            ax.tick_params(labelsize=SMALL_PT)
            if i == nrows - 1:
                ax.set_xlabel(_study_label(f), fontsize=SMALL_PT)
            if j == 0:
                ax.set_ylabel(_study_label(m), fontsize=SMALL_PT)
    return fig


def study_pass_rates(rates) -> Figure:
    """Pass rate [%] against each factor, one line per limit (and all together)."""
    factors = list(rates.by_factor)
    fig = Figure(figsize=(PAGE_WIDTH_IN, 2.4), layout="constrained")
    axes = fig.subplots(1, max(1, len(factors)), squeeze=False)
    for j, f in enumerate(factors):
        ax = axes[0][j]
        centres, per = rates.by_factor[f]
        for k, (key, r) in enumerate(per.items()):
            ax.plot(centres, 100 * r, "o-" if key == "all" else ".-", ms=3, lw=1.0,
                    color="black" if key == "all" else PALETTE[k % len(PALETTE)], label=key)
        ax.set_ylim(-3, 103)
        ax.set_xlabel(_study_label(f), fontsize=SMALL_PT)
        ax.tick_params(labelsize=SMALL_PT)
        if j == 0:
            ax.set_ylabel("cases passing [%]", fontsize=SMALL_PT)
    if factors and rates.by_factor[factors[0]][1]:
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, fontsize=SMALL_PT, loc="outside lower center", ncol=min(5, len(labels)))
    return fig


def figure_data(fig: Figure) -> list[dict]:
    """The numbers a figure shows (lines, markers, bars, patches), for CSV export and diffing."""
    rows = []
    for ia, ax in enumerate(fig.axes):
        for il, line in enumerate(ax.get_lines()):
            for x, y in line.get_xydata():
                rows.append({"axes": ia, "artist": f"line{il}", "label": line.get_label(), "x": float(x), "y": float(y)})
        for ic, coll in enumerate(ax.collections):
            for x, y in np.asarray(coll.get_offsets()):
                rows.append({"axes": ia, "artist": f"points{ic}", "label": coll.get_label(), "x": float(x),
                             "y": float(y)})
        for ib, cont in enumerate(ax.containers):
            for bar in cont:
                rows.append({"axes": ia, "artist": f"bars{ib}", "label": cont.get_label(),
                             "x": float(bar.get_x() + bar.get_width() / 2), "y": float(bar.get_height())})
        for ip, patch in enumerate(ax.patches):
            if isinstance(patch, Polygon):
                for x, y in patch.get_xy():
                    rows.append({"axes": ia, "artist": f"polygon{ip}", "label": "", "x": float(x), "y": float(y)})
    return rows
