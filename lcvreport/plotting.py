"""Figures: the vehicle seen from above, eigenvalue maps, time responses, study charts,
tire curves.  Plotting only; every number comes from the analysis modules.

Conventions of the top views: x forward to the right, y toward the curb drawn
downward (the y axis is inverted), lengths to scale in inches.  Functions return a
:class:`matplotlib.figure.Figure`; axis labels carry units.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch, Polygon

from .linear import Modes, rear_displacements
from .loads import tire_forces
from .tires import tire_fit
from .vehicle import JOINT_LETTERS, Train

#: colours per run, stable order
PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#7f7f7f")
BODY = {"tractor": "#4a6fa5", "trailer": "#b0b7c3", "dolly": "#6b6b6b"}


def new_figure(width: float = 7.0, height: float = 4.0, ncols: int = 1, nrows: int = 1, **kw):
    """A figure and its axes (not registered with pyplot: no global state)."""
    fig = Figure(figsize=(width, height), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=True, **kw)
    return fig, axes


# ------------------------------------------------------------------ top views
def unit_poses(train: Train, theta: np.ndarray | None = None) -> list[tuple[np.ndarray, float]]:
    """CG position [in] and heading [rad] of every unit, tractor CG at the origin heading +x.

    ``theta`` are the articulation angles [rad]; headings follow psi_(k+1) = psi_k - theta_k.
    """
    theta = np.zeros(train.n_units - 1) if theta is None else np.asarray(theta, dtype=float)
    poses = []
    cg = np.zeros(2)
    psi = 0.0
    for k, unit in enumerate(train.units):
        if k > 0:
            joint = poses[-1][0] - train.units[k - 1].rear_joint_in * _dir(poses[-1][1])
            psi = poses[-1][1] - theta[k - 1]
            cg = joint - unit.front_joint_in * _dir(psi)
        poses.append((cg.copy(), psi))
    return poses


def _dir(psi: float) -> np.ndarray:
    return np.array([np.cos(psi), np.sin(psi)])


def _rect(center: np.ndarray, psi: float, front: float, rear: float, half_width: float) -> np.ndarray:
    d = _dir(psi)
    n = np.array([-d[1], d[0]])
    return np.array([center + front * d + half_width * n, center + front * d - half_width * n,
                     center - rear * d - half_width * n, center - rear * d + half_width * n])


def draw_train(ax, train: Train, theta: np.ndarray | None = None, alpha: float = 1.0, labels: bool = True,
               offset: tuple[float, float] = (0.0, 0.0), tires: bool = True, outline_only: bool = False) -> list:
    """Draw ``train`` from above on ``ax`` (to scale, inches).

    Returns the unit poses used (CG position [in], heading [rad]).
    """
    poses = unit_poses(train, theta)
    off = np.asarray(offset, dtype=float)
    track = float(train.drawing.get("track_width_in", 72.0))
    width = float(train.drawing.get("body_width_in", 102.0))
    overhang = float(train.drawing.get("tractor_front_overhang_in", 30.0))
    D = train.dual_spacing_in
    for k, (unit, (cg, psi)) in enumerate(zip(train.units, poses)):
        cg = cg + off
        if unit.kind == "tractor":
            front, rear, hw = unit.axles[0].position_in + overhang, -min(a.position_in for a in unit.axles) + 24, 48
        elif unit.kind == "dolly":
            front, rear, hw = unit.front_joint_in, 24.0, track / 2 + 6
        else:
            front, rear, hw = unit.front_joint_in + 30.0, unit.rear_joint_in, width / 2
        poly = Polygon(_rect(cg, psi, front, rear, hw), closed=True, alpha=alpha,
                       facecolor="none" if outline_only else BODY[unit.kind], edgecolor="black", lw=0.8)
        ax.add_patch(poly)
        if tires:
            for ax_ in unit.axles:
                centre = cg + ax_.position_in * _dir(psi)
                n = np.array([-np.sin(psi), np.cos(psi)])
                offsets = [track / 2] if ax_.tires == 2 else [track / 2 - D / 2, track / 2 + D / 2]
                for side in (1, -1):
                    for o in offsets:
                        tc = centre + side * o * n
                        ax.add_patch(Polygon(_rect(tc, psi, 20, 20, 4.5), closed=True, facecolor="black",
                                             alpha=alpha, lw=0))
                a = centre + (track / 2 + D) * n
                b = centre - (track / 2 + D) * n
                ax.plot([a[0], b[0]], [a[1], b[1]], color="black", lw=0.8, alpha=alpha)
        if k > 0:
            j = cg + unit.front_joint_in * _dir(psi)
            ax.plot(j[0], j[1], "o", ms=4, color="white", mec="black", alpha=alpha, zorder=5)
            if labels:
                ax.annotate(JOINT_LETTERS[k - 1], j, xytext=(0, -14), textcoords="offset points", ha="center",
                            fontsize=7, alpha=alpha)
        if labels:
            ax.annotate(f"{unit.number}", cg, ha="center", va="center", fontsize=8, fontweight="bold", alpha=alpha,
                        color="white" if unit.kind != "trailer" else "black")
    return poses


def _top_view_axes(ax, xlim=None, ylim=None):
    ax.set_aspect("equal")
    ax.invert_yaxis()
    ax.set_xlabel("x, forward [in]")
    ax.set_ylabel("y, toward the curb [in]")
    ax.autoscale_view()
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)


def fig_combinations(trains: list[tuple[str, Train]]) -> Figure:
    """Figure 1-2: vehicle combinations drawn from presets, one per row."""
    fig, axes = new_figure(8.0, 1.6 * len(trains), nrows=len(trains))
    for ax, (label, train) in zip(np.atleast_1d(axes), trains):
        draw_train(ax, train)
        ax.set_title(label, fontsize=9, loc="left")
        _top_view_axes(ax)
        ax.set_ylim(90, -90)
    return fig


def fig_mode_shape(train: Train, modes: Modes, index: int, title: str, max_angle_deg: float = 6.0) -> Figure:
    """A mode shape seen from above: the articulation angles of mode ``index`` at
    phases 0, 90, 180 and 270 degrees, scaled so the largest angle is ``max_angle_deg``;
    the tractor's own motion is left out, as in the thesis."""
    n = train.n_units
    X = modes.shapes[:, index]
    th = X[n + 1:2 * n]
    scale = np.radians(max_angle_deg) / max(np.abs(th).max(), 1e-300)
    fig, ax = new_figure(8.0, 2.6)
    for phase, alpha in ((0, 1.0), (90, 0.45), (180, 0.3), (270, 0.45)):
        theta = (th * scale * np.exp(1j * np.radians(phase))).real
        draw_train(ax, train, theta, alpha=alpha, labels=phase == 0, tires=phase == 0, outline_only=phase != 0)
    lam = modes.eigenvalues[index]
    ax.set_title(f"{title}: lambda = {lam.real:.3f} {'+' if lam.imag >= 0 else '-'} {abs(lam.imag):.3f}i 1/s, "
                 f"f_d = {modes.damped_frequency_hz[index]:.3f} Hz, zeta = {modes.damping_ratio[index]:.3f} "
                 f"(phases 0/90/180/270 deg, largest angle {max_angle_deg:g} deg)", fontsize=8)
    _top_view_axes(ax)
    return fig


def fig_load_configuration(train: Train, configuration: str, title: str, fraction: float = 0.01) -> Figure:
    """Figures 3-6..3-8, 4-9..4-11: residual lateral force of every tire as an arrow
    (red; dimmed where unchanged from the balanced configuration)."""
    fig, ax = new_figure(8.0, 2.8)
    poses = draw_train(ax, train)
    balanced = {(f.axle, f.side, f.lateral_offset_in): f.force_lbf for f in tire_forces(train, "balanced", fraction)}
    forces = tire_forces(train, configuration, fraction)
    fmax = max(abs(f.force_lbf) for f in forces)
    by_axle = {a.name: (a, train.units[a.unit - 1]) for a in train.axles}
    for f in forces:
        axle, unit = by_axle[f.axle]
        cg, psi = poses[unit.number - 1]
        d = _dir(psi)
        nrm = np.array([-d[1], d[0]])
        start = cg + axle.position_in * d + f.lateral_offset_in * nrm
        end = start + np.sign(f.force_lbf) * (18 + 30 * abs(f.force_lbf) / fmax) * nrm
        changed = configuration != "balanced" and balanced[(f.axle, f.side, f.lateral_offset_in)] != f.force_lbf
        ax.add_patch(FancyArrowPatch(start, end, arrowstyle="-|>", mutation_scale=8, color="red",
                                     alpha=1.0 if configuration == "balanced" or changed else 0.25, lw=1.2))
    ax.set_title(f"{title} ({100 * fraction:g} % of each tire load along y)", fontsize=9)
    _top_view_axes(ax)
    ax.set_ylim(110, -110)
    return fig


def fig_free_body(train: Train, title: str) -> Figure:
    """Figures 3-1 and 4-1: free-body diagrams seen from above: tire forces F_ij and
    residual forces P_ij at the axles, joint forces at the joints, u, v_i, r_i at the CGs."""
    fig, ax = new_figure(9.0, 3.2 if train.n_units > 2 else 3.6)
    gap = 90.0
    x_shift = 0.0
    poses = unit_poses(train)
    for k, unit in enumerate(train.units):
        single = Train(train.name, (unit,), train.dual_spacing_in, drawing=train.drawing)
        off = (poses[k][0][0] + x_shift, 0.0)
        draw_train(ax, single, offset=off, labels=False)
        cg = np.array(off)
        ax.add_patch(FancyArrowPatch(cg, cg + (45, 0), arrowstyle="-|>", mutation_scale=7, color="#333"))
        ax.add_patch(FancyArrowPatch(cg, cg + (0, 38), arrowstyle="-|>", mutation_scale=7, color="#333"))
        ax.annotate(f"u, v{unit.number}, r{unit.number}", cg, xytext=(4, 4), textcoords="offset points", fontsize=6)
        for a in unit.axles:
            p = cg + (a.position_in, 0)
            ax.add_patch(FancyArrowPatch(p + (0, -80), p + (0, -48), arrowstyle="-|>", mutation_scale=7, color="blue"))
            ax.annotate(f"F{a.name}, P{a.name}\nM{a.name}, T{a.name}", p + (0, -82), ha="center", fontsize=6,
                        color="blue")
        if k > 0:
            p = cg + (unit.front_joint_in, 0)
            ax.add_patch(FancyArrowPatch(p + (0, 70), p + (0, 45), arrowstyle="-|>", mutation_scale=7, color="green"))
            ax.annotate(f"F{JOINT_LETTERS[k - 1]}", p + (0, 78), ha="center", fontsize=6, color="green")
        if k < train.n_units - 1:
            p = cg + (-unit.rear_joint_in, 0)
            ax.add_patch(FancyArrowPatch(p + (0, 45), p + (0, 70), arrowstyle="-|>", mutation_scale=7, color="green"))
            ax.annotate(f"F{JOINT_LETTERS[k]}", p + (0, 78), ha="center", fontsize=6, color="green")
        x_shift -= gap
    ax.set_title(title, fontsize=9)
    _top_view_axes(ax)
    ax.set_ylim(110, -110)
    return fig


def fig_steady_state_top_view(train: Train, x_ss: np.ndarray, title: str, exaggerate: float) -> Figure:
    """Steady state seen from above with the articulation angles multiplied by
    ``exaggerate`` (Figure 2-10: dog-tracking); the straight-ahead pose is dimmed."""
    n = train.n_units
    fig, ax = new_figure(8.0, 2.8)
    draw_train(ax, train, alpha=0.25, labels=False, outline_only=True)
    draw_train(ax, train, x_ss[n + 1:2 * n] * exaggerate)
    y = rear_displacements(train, x_ss[n + 1:2 * n])
    ax.set_title(f"{title}: rear end of unit {n} offset {y[-1]:.3f} in from the tractor axis "
                 f"(angles drawn x{exaggerate:g})", fontsize=8)
    _top_view_axes(ax)
    return fig


# ------------------------------------------------------------------ eigenvalues
def fig_eigenvalues(sets: list[tuple[str, np.ndarray]], title: str, upper: bool = False, connect_mode: int | None = None
                    ) -> Figure:
    """Eigenvalue map(s): real part [1/s] against imaginary part [1/s].

    ``upper`` shows only the upper-left quadrant; ``connect_mode`` (1-based, mode
    order of :func:`lcvreport.linear.mode_order`) joins that mode across the sets
    with a dashed black line, as the thesis does for Mode 7.
    """
    fig, ax = new_figure(6.5, 4.2)
    markers = "osD^v<>ph"
    for i, (label, lam) in enumerate(sets):
        ax.scatter(lam.real, lam.imag, s=22, marker=markers[i % len(markers)], color=PALETTE[i % len(PALETTE)],
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
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    return fig


# ------------------------------------------------------------------ time histories
def fig_time(series: list[tuple[str, np.ndarray, np.ndarray, dict]], ylabel: str, title: str,
             hlines: list[tuple[str, float]] = (), xlim: tuple | None = None, annotate_peaks: bool = False) -> Figure:
    """Time histories: ``series`` of (label, time [s], values, line style keywords)."""
    fig, ax = new_figure(7.0, 3.8)
    for i, (label, t, y, style) in enumerate(series):
        kw = {"color": PALETTE[i % len(PALETTE)], "lw": 1.2}
        kw.update(style)
        ax.plot(t, y, label=label, **kw)
        if annotate_peaks:
            mask = np.ones_like(t, dtype=bool) if xlim is None else (t >= xlim[0]) & (t <= xlim[1])
            k = int(np.argmax(np.abs(np.where(mask, y, 0))))
            ax.annotate(f"{y[k]:.3f}", (t[k], y[k]), fontsize=6, color=kw["color"], xytext=(2, 2),
                        textcoords="offset points")
    for i, (label, value) in enumerate(hlines):
        ax.axhline(value, color="black", ls=":", lw=1)
        ax.annotate(label, (1.0, value), xycoords=("axes fraction", "data"), ha="right", va="bottom", fontsize=7)
    if xlim is not None:
        ax.set_xlim(*xlim)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(title, fontsize=9)
    return fig


def fig_bars(labels: list[str], groups: list[tuple[str, np.ndarray]], ylabel: str, title: str) -> Figure:
    """Grouped bar chart (Figures 5-4, 5-8, 5-13, 5-18, 5-20)."""
    fig, ax = new_figure(7.5, 3.8)
    x = np.arange(len(labels))
    w = 0.8 / len(groups)
    for i, (glabel, values) in enumerate(groups):
        bars = ax.bar(x + (i - (len(groups) - 1) / 2) * w, values, w, label=glabel, color=PALETTE[i])
        for b, v in zip(bars, values):
            ax.annotate(f"{v:.2f}", (b.get_x() + b.get_width() / 2, b.get_height()), ha="center",
                        va="bottom" if v >= 0 else "top", fontsize=6)
    ax.set_xticks(x, labels, rotation=25, ha="right", fontsize=7)
    ax.axhline(0, color="black", lw=0.6)
    ax.set_ylabel(ylabel)
    ax.legend(fontsize=7)
    ax.grid(True, axis="y", lw=0.3)
    ax.set_title(title, fontsize=9)
    return fig


def fig_fit(x: np.ndarray, ys: list[tuple[str, np.ndarray]], degree: int | None, xlabel: str, ylabel: str,
            title: str) -> Figure:
    """Points and (optional) least-squares polynomial fits of the given degree."""
    fig, ax = new_figure(6.5, 3.8)
    xx = np.linspace(np.min(x), np.max(x), 101)
    for i, (label, y) in enumerate(ys):
        ax.plot(x, y, "o", color=PALETTE[i], label=label)
        if degree is not None:
            c = np.polyfit(x, y, degree)
            terms = " + ".join(f"{v:.4g} x^{degree - k}" if degree - k > 1 else (f"{v:.4g} x" if degree - k == 1
                               else f"{v:.4g}") for k, v in enumerate(c))
            ax.plot(xx, np.polyval(c, xx), "--", color=PALETTE[i], lw=1, label=f"fit: {terms}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    return fig


# ------------------------------------------------------------------ tires
def fig_tire_vs_slip(quantity: str, loads_lbf: tuple[float, ...], title: str, residual_lbf: float = 0.0) -> Figure:
    """Figures 2-5, 2-6, 2-8: the linear tire model against slip angle for several
    vertical loads, per tire: lateral force F = CF alpha [lbf] or aligning moment
    -CM alpha [lbf*in]; ``residual_lbf`` shifts the force curves (Figure 2-8)."""
    fig, ax = new_figure(6.5, 3.8)
    fit = tire_fit()
    alpha_deg = np.linspace(-2.0, 2.0, 81)
    alpha = np.radians(alpha_deg)
    for i, w in enumerate(loads_lbf):
        cf, cm, _cs = fit.evaluate(w)
        if quantity == "force":
            y = cf * alpha + residual_lbf
        else:
            y = -cm * alpha
        ax.plot(alpha_deg, y, color=PALETTE[i], label=f"tire load {w:.0f} lbf")
    if residual_lbf:
        ax.annotate(f"residual force {residual_lbf:g} lbf at zero slip", (0, residual_lbf), xytext=(10, -25),
                    textcoords="offset points", fontsize=7, arrowprops=dict(arrowstyle="->"))
    ax.axhline(0, color="black", lw=0.6)
    ax.axvline(0, color="black", lw=0.6)
    ax.set_xlabel("slip angle alpha [deg]")
    ax.set_ylabel("lateral force per tire [lbf]" if quantity == "force" else "aligning moment per tire [lbf*in]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    return fig


def fig_tire_fit(key: str, ylabel: str, title: str) -> Figure:
    """Figures D.1-D.3: per-tire coefficient against tire load, the Table D points and the cubic fit."""
    fit = tire_fit()
    pts = fit.points[key]
    coef = getattr(fit, key)
    fig, ax = new_figure(6.5, 3.8)
    w = np.linspace(pts[:, 0].min(), pts[:, 0].max(), 201)
    ax.plot(pts[:, 0], pts[:, 1], "o", color=PALETTE[0], label="Tables D.1-D.5")
    ax.plot(w, np.polyval(coef, w), "-", color=PALETTE[1],
            label="cubic fit: " + " + ".join(f"{c:.4g} W^{3 - k}" for k, c in enumerate(coef)))
    ax.set_xlabel("vertical tire load W [lbf]")
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    ax.set_title(title, fontsize=9)
    return fig


def figure_data(fig: Figure) -> list[dict]:
    """The numbers a figure shows (lines, markers, bars), for CSV export and diffing."""
    rows = []
    for ia, ax in enumerate(fig.axes):
        for il, line in enumerate(ax.get_lines()):
            xy = line.get_xydata()
            for x, y in xy:
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
