"""Roll figures: the static rollover threshold's a_y - phi curve of every roll-coupled group,
each axle's lift-off marked, like a tilt-table chart (docs/roll.md)."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure


def plot_rollover(threshold, ax=None) -> Figure:
    """Lateral acceleration [g] against every unit's outward roll [deg] on the equilibrium path of
    its group, up to the static rollover threshold; a marker and the axle's name at each lift-off.
    ``threshold`` is a :class:`lcvreport.measures.rollover.RolloverThreshold`."""
    if ax is None:
        fig, ax = new_figure(PAGE_WIDTH_IN, 3.6)
    else:
        fig = ax.figure
    colour = 0
    curves = []
    for k, g in enumerate(threshold.groups, 1):
        a = np.asarray(g.path_g)
        for u, name in enumerate(g.units):
            phi = np.degrees(np.asarray(g.path_phi_rad)[:, u])
            curves += ax.plot(phi, a, color=PALETTE[colour % len(PALETTE)], lw=1.2,
                              label=f"group {k}: {name} (SRT {g.srt_g:.3f} g)")
            ax.plot(phi[1:], a[1:], "o", ms=3, color=PALETTE[colour % len(PALETTE)],
                    label=f"group {k}: {name}, lift-offs")
            colour += 1
        lifted = {}
        for axle, at in g.lift_off_g.items():
            if at is not None:
                lifted.setdefault(round(at, 9), []).append(axle)
        phi_last = np.degrees(np.asarray(g.path_phi_rad)[:, -1])
        events = [(event, axles) for event, (_at, axles) in enumerate(sorted(lifted.items()), 1) if event < len(a)]
        # the labels in a column below their points, at least a line apart (lift-offs close together
        # keep their labels apart): positions in points, from the data's height on an axes of
        # about 180 pt (the figure's), the highest label first
        top = max(float(np.max(a)) * 1.05, 1e-9)
        label_pt = []
        for event, _axles in sorted(events, key=lambda e: -a[e[0]]):
            want = a[event] / top * 180.0 - 14.0
            label_pt.append((event, min(want, label_pt[-1][1] - 10.0) if label_pt else want))
        for event, y_pt in label_pt:
            axles = dict(events)[event]
            ax.annotate(", ".join(axles), (phi_last[event], a[event]), fontsize=SMALL_PT, ha="left",
                        xytext=(14, y_pt - a[event] / top * 180.0), textcoords="offset points",
                        arrowprops={"arrowstyle": "-", "lw": 0.4, "color": "gray"})
    ax.set_xlabel("outward roll of the sprung mass φ [deg]")
    ax.set_ylabel("lateral acceleration a_y [g]")
    ax.set_title(f"{threshold.vehicle.name}: static rollover threshold, lift-off axle by axle", fontsize=SMALL_PT + 1)
    ax.grid(True, lw=0.3)
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=0.0)
    ax.legend(handles=curves, fontsize=SMALL_PT, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2,
              frameon=False)
    rows = []
    for k, g in enumerate(threshold.groups, 1):
        events = {}
        for axle, at in g.lift_off_g.items():
            if at is not None:
                events.setdefault(at, []).append(axle)
        lifted = [""] + [" ".join(events.get(at, [])) for at in np.asarray(g.path_g)[1:]]
        for e, (at, phis) in enumerate(zip(np.asarray(g.path_g), np.asarray(g.path_phi_rad))):
            for name, phi in zip(g.units, phis):
                rows.append({"group": k, "unit": name, "lateral_acceleration_g": float(at),
                             "outward_roll_deg": float(np.degrees(phi)), "axles_lifting": lifted[e]})
    fig.lcv_data = rows
    return fig


def plot_ltr(response, n_groups: int, title: str) -> Figure:
    """The load transfer ratio of every roll-coupled group [-] against time [s] in a manoeuvre
    (``response``: a yaw-roll :class:`lcvreport.analysis.exact.ManoeuvreResponse`), with
    |LTR| = 1 (the inner wheels unloaded) marked."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.0)
    for g in range(n_groups):
        ax.plot(response.time, response[f"ltr{g + 1}"], color=PALETTE[g % len(PALETTE)], lw=1.1,
                label=f"group {g + 1}")
    for level in (-1.0, 1.0):
        ax.axhline(level, color="gray", ls=":", lw=0.9, label=f"LTR = {level:+.0f}: inner wheels unloaded")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("load transfer ratio LTR [-]")
    ax.set_title(title, fontsize=SMALL_PT + 1)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT, loc="lower right")
    t = np.asarray(response.time)
    keep = np.arange(0, t.size, max(1, t.size // 2000))          # at most ~2,000 rows in the figure's CSV
    ltr = [np.asarray(response[f"ltr{g + 1}"]) for g in range(n_groups)]
    fig.lcv_data = [{"time_s": float(t[i]), **{f"ltr_group{g + 1}": float(ltr[g][i]) for g in range(n_groups)}}
                    for i in keep]
    return fig
