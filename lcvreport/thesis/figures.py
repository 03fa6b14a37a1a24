"""The dissertation's own figures: the free body and load configurations of chapters III
and IV, the tire curves of chapter II and the tire fits of Appendix D (drawn with the
helpers of :mod:`lcvreport.plotting`).
"""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch

from ..model.body import direction, body_extent, unit_poses
from ..model.vehicle import Vehicle
from ..model.yaw_plane.states import joint_letter
from ..plotting.style import LENGTH_UNITS, PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure
from ..plotting.vehicle import top_view_axes, draw_unit, draw_vehicle


def fig_load_configuration(vehicle: Vehicle, configuration: str, title: str, fraction: float = 0.01,
                           unit: str = "in") -> Figure:
    """Figures 3-6..3-8, 4-9..4-11: residual lateral force of every tire as an arrow
    (red; dimmed where unchanged from the balanced configuration)."""
    from .configurations import tire_forces
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
        d = direction(psi)
        nrm = np.array([-d[1], d[0]])
        start = cg + axles[t.axle].x_m * d + t.lateral_offset_m * nrm
        end = start + np.sign(t.force_N) * (0.45 + 0.75 * abs(t.force_N) / fmax) * nrm
        changed = configuration != "balanced" and balanced[(t.axle, t.side, t.lateral_offset_m)] != t.force_N
        ax.add_patch(FancyArrowPatch(f * start, f * end, arrowstyle="-|>", mutation_scale=7, color="red",
                                     alpha=1.0 if configuration == "balanced" or changed else 0.25, lw=1.0))
    ax.set_title(f"{title} ({100 * fraction:g} % of each tire load along y)", fontsize=8)
    top_view_axes(ax, unit, ylim_m=2.8)
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
        top_view_axes(ax, unit, ylim_m=2.6)
        f_unit = 1.0 / LENGTH_UNITS[unit]
        ax.set_ylim(2.7 * f_unit, -4.1 * f_unit)
    axes[0].set_title(title, fontsize=8)
    return fig


# ------------------------------------------------------------------ tires (thesis, inch-pound units)
def fig_tire_vs_slip(quantity: str, loads_lbf: tuple[float, ...], title: str, residual_lbf: float = 0.0) -> Figure:
    """Figures 2-5, 2-6, 2-8: the linear tire model against slip angle for several
    vertical loads, per tire: lateral force F = CF alpha [lbf] or aligning moment
    -CM alpha [lbf*in]; ``residual_lbf`` shifts the force curves (Figure 2-8)."""
    from .tires import tire_fit
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
    from .tires import tire_fit
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
