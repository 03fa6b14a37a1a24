"""The low-speed turn seen from above: outlines, the envelope the turn computed, the wheel
paths and the measures.
"""
from __future__ import annotations

import math

import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure


def fig_swept_path(turn, title: str, outlines_every_m: float = 2.0) -> Figure:
    """The low-speed turn seen from above, to scale (docs/low_speed_turn.md): every unit's outline
    every ``outlines_every_m`` of path, the swept region's envelope within the turn, the
    paths of the outside steer wheel and of the last unit's inside rear wheel, the arc's
    centre and the measures marked [m].  ``turn`` is a
    :class:`lcvreport.measures.low_speed.LowSpeedTurn`."""
    from matplotlib.patches import Polygon as _Poly

    from ..model.body import corners
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


def fig_swing(swing: dict, which: str, title: str, limits=()) -> Figure:
    """A close-up of the corner a swing measure reads (``swing`` from
    :meth:`lcvreport.measures.low_speed.LowSpeedTurn.swing`): ``which`` ``"tail"`` -- the rear
    outer corner's path against its approach line, each limit drawn as a line that far beyond
    it -- or ``"frontal"`` -- the front outer corner's path against the outside steer wheel's
    circle, each limit as a circle that far outside it; the farthest point marked [m].
    ``limits``: (label, distance [m]) pairs."""
    from .style import LEVEL_STYLES, plain
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.6)
    if not swing:
        ax.text(0.5, 0.5, "not computed", transform=ax.transAxes, ha="center", va="center", fontsize=SMALL_PT)
        ax.set_title(title, fontsize=8)
        return fig
    pts, at = swing["points"], swing["at"]
    corner = "rear" if which == "tail" else "front"
    ax.plot(*pts.T, color=PALETTE[0], lw=1.4, label=f"{corner} outer corner of {swing['unit']}")
    if which == "tail":
        y0 = swing["line_y_m"]
        span = np.array([pts[:, 0].min(), pts[:, 0].max()])
        ax.plot(span, [y0, y0], color="black", lw=0.9, label="its straight approach line")
        for i, (label, d) in enumerate(limits):
            ax.plot(span, [y0 - d] * 2, color="black", ls=LEVEL_STYLES[i % len(LEVEL_STYLES)], lw=0.8,
                    label=plain(f"{label}: {d:.4g} m beyond it"))
        ax.annotate("", (at[0], y0), tuple(at), arrowprops=dict(arrowstyle="<->", lw=0.8))
        # the close-up: where the corner swings out, a few metres either side
        window = max(3.0 * max(swing["value_m"], max((d for _l, d in limits), default=0.0)), 2.0)
        ax.set_xlim(at[0] - 2 * window, at[0] + 2 * window)
        ax.set_ylim(y0 - 1.6 * window, y0 + 0.6 * window)
    else:
        C, R = swing["centre"], swing["radius_m"]
        th = np.linspace(0.0, math.radians(min(swing["angle_deg"], 360.0)), 400)
        circle = lambda r: np.stack([C[0] + r * np.sin(th), C[1] - r * np.cos(th)], axis=1)  # noqa: E731
        ax.plot(*circle(R).T, color="black", lw=0.9, label=f"outside steer wheel's circle (R = {R:g} m)")
        for i, (label, d) in enumerate(limits):
            ax.plot(*circle(R + d).T, color="black", ls=LEVEL_STYLES[i % len(LEVEL_STYLES)], lw=0.8,
                    label=plain(f"{label}: {d:.4g} m outside it"))
        u = (at - C) / np.hypot(*(at - C))
        ax.annotate("", tuple(C + R * u), tuple(at), arrowprops=dict(arrowstyle="<->", lw=0.8))
        window = max(3.0 * max(swing["value_m"], max((d for _l, d in limits), default=0.0)), 2.0)
        ax.set_xlim(at[0] - 2 * window, at[0] + 2 * window)
        ax.set_ylim(at[1] - 2 * window, at[1] + 2 * window)
    ax.plot(*at, "o", color=PALETTE[1], ms=5, zorder=5, label=f"farthest: {swing['value_m']:.3f} m")
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.suptitle(title, fontsize=8)
    fig.lcv_data = [{"X_m": float(x), "Y_m": float(y)} for x, y in pts]
    return fig


def draw_friction_demand(ax, turn, levels=()) -> dict:
    """Every axle's friction demand over the turn with tire forces against unit 1's distance
    travelled [m] on ``ax``, the steered and driven axles drawn heavier, STFD and FDDT marked at
    their peaks, each of ``levels`` ((label, value) pairs) drawn as a line; the drawn data as
    columns (``distance_m``, ``fd_<axle>``)."""
    from ..model.nonlinear.model import driven_axles
    from .style import LEVEL_STYLES, plain
    v, r = turn.vehicle, turn.response
    dist = r.time * turn.speed_kph / 3.6
    steered = {a.name for a in v.units[0].axles if a.steered}
    driven = {a.name for a, d in zip(v.axles, driven_axles(v)) if d}
    rows = {"distance_m": dist}
    for j, a in enumerate(v.axles):
        fd = np.asarray(r[f"fd_{a.name}"], dtype=float)
        rows[f"fd_{a.name}"] = fd
        role = " (steered)" if a.name in steered else " (driven)" if a.name in driven else ""
        ax.plot(dist, fd, color=PALETTE[j % len(PALETTE)], lw=1.5 if role else 0.8, label=plain(f"axle {a.name}{role}"))
    for i, (label, value) in enumerate(levels):
        ax.axhline(value, color="black", ls=LEVEL_STYLES[i % len(LEVEL_STYLES)], lw=0.9,
                   label=plain(f"{label}: {value:.4g}"))
    for key, value, names in (("STFD", turn.stfd, steered), ("FDDT", turn.friction_demand_drive, driven)):
        if value is None or not names:
            continue
        name = max(names, key=lambda n: turn.friction_demand[n])
        k = int(np.argmax(rows[f"fd_{name}"]))
        ax.plot(dist[k], value, "o", color="black", ms=4, zorder=5)
        ax.annotate(f"{key} {value:.3f}", (dist[k], value), textcoords="offset points", xytext=(4, 4),
                    fontsize=SMALL_PT)
    ax.set_xlabel("distance travelled by unit 1 [m]")
    ax.set_ylabel("friction demand √(Fx² + Fy²) / (μ Fz0) [-]")
    top = max([float(np.max(f)) for k, f in rows.items() if k != "distance_m"] + [value for _l, value in levels])
    ax.set_ylim(0.0, max(1.05, 1.1 * top))
    ax.grid(True, lw=0.3)
    return rows


def draw_turn_paths(ax, turn) -> list:
    """Both models' turn seen from above on ``ax``, to scale: the outside steer wheel's and the
    last unit's inside rear wheel's paths and the swept region's envelope, kinematic (solid) and
    with tire forces (dashed) [m]; the drawn paths as rows."""
    v = turn.vehicle
    steer = max((a for a in v.units[0].axles if a.steered), key=lambda a: a.x_m)
    last = v.n_units - 1
    rear = v.units[last].rearmost_axle
    rows = []
    for name, t, ls in (("kinematic", turn.kinematic, "-"), ("nonlinear", turn.turn, "--")):
        if t is None:
            continue
        run = t.run
        s = np.linspace(0.0, min(run.s_end, run.path.arc_end_s + 1.2 * t.overall_length_m), 600)
        ow = run.unit_points(s, 0, [steer.x_m], [-steer.track_width_m / 2])[:, 0]
        iw = run.unit_points(s, last, [rear.x_m], [rear.track_width_m / 2])[:, 0]
        ax.plot(*ow.T, color=PALETTE[1], ls=ls, lw=1.1, label=f"{name}: outside wheel of axle {steer.name}")
        ax.plot(*iw.T, color=PALETTE[2], ls=ls, lw=1.1, label=f"{name}: inside wheel of axle {rear.name}")
        if t.lssp_m is not None:
            C = run.path.centre
            mid, r_min, r_max = t.envelope()
            env = lambda rr: np.stack([C[0] + rr * np.sin(mid), C[1] - rr * np.cos(mid)], axis=1)  # noqa: E731
            ax.plot(*env(r_max).T, color="black", ls=ls, lw=1.0, label=f"{name}: swept region (width {t.lssp_m:.2f} m)")
            ax.plot(*env(r_min).T, color="black", ls=ls, lw=1.0)
        rows += [{"model": name, "wheel": f"outside {steer.name}", "X_m": float(x), "Y_m": float(y)} for x, y in ow]
        rows += [{"model": name, "wheel": f"inside {rear.name}", "X_m": float(x), "Y_m": float(y)} for x, y in iw]
    ax.plot(*turn.kinematic.run.path.centre, "+", color="black", ms=8)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.grid(True, lw=0.3)
    return rows


def _title_of(turn) -> str:
    return (f"{turn.vehicle.name}: the {turn.angle_deg:g}° turn at {turn.speed_kph:g} km/h, R = {turn.radius_m:g} m, "
            f"μ = {turn.friction_coefficient:g} ({turn.tire} tires)")


def fig_friction_demand(turn, limit: float | None = None, limits=(), title: str | None = None) -> Figure:
    """The friction demand of every axle over the low-speed turn with tire forces
    (docs/measures.md#friction-demand) against the distance unit 1 has travelled [m], each limit
    drawn (``limit``: one value; ``limits``: (label, value) pairs).  ``turn`` is a
    :class:`lcvreport.measures.friction_demand.TurnWithTireForces`."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.6)
    levels = list(limits) + ([("limit", limit)] if limit is not None else [])
    rows = draw_friction_demand(ax, turn, levels)
    ax.legend(fontsize=SMALL_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.suptitle(title or f"friction demand: {_title_of(turn)}", fontsize=8)
    keys = list(rows)
    fig.lcv_data = [{k: float(rows[k][i]) for k in keys} for i in range(len(rows["distance_m"]))]
    return fig


def fig_turn_paths(turn, title: str | None = None) -> Figure:
    """The low-speed turn of both models seen from above, to scale (:func:`draw_turn_paths`).
    ``turn`` is a :class:`lcvreport.measures.friction_demand.TurnWithTireForces`."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 5.0)
    rows = draw_turn_paths(ax, turn)
    ax.legend(fontsize=SMALL_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    fig.suptitle(title or f"{_title_of(turn)}: kinematic (solid) and with tire forces (dashed; path error "
                          f"≤ {turn.path_error_max_m:.3f} m)", fontsize=8)
    fig.lcv_data = rows
    return fig


def fig_friction_demand_evidence(turn, limits, title: str) -> Figure:
    """The evidence of a friction-demand measure: every axle's friction demand over the turn
    with each level's limit drawn (``limits``: (label, value) pairs), above the swept path of
    both models overlaid."""
    fig = Figure(figsize=(PAGE_WIDTH_IN, 7.6), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, height_ratios=[1.0, 1.3])
    rows = draw_friction_demand(ax1, turn, limits)
    ax1.legend(fontsize=SMALL_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    draw_turn_paths(ax2, turn)
    ax2.legend(fontsize=SMALL_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False)
    ax2.set_title(f"kinematic (solid) and with tire forces (dashed): path error ≤ {turn.path_error_max_m:.3f} m",
                  fontsize=SMALL_PT + 1)
    fig.suptitle(title, fontsize=8)
    keys = list(rows)
    fig.lcv_data = [{k: float(rows[k][i]) for k in keys} for i in range(len(rows["distance_m"]))]
    return fig
