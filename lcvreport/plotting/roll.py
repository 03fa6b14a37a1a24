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
    for k, g in enumerate(threshold.groups, 1):
        a = np.asarray(g.path_g)
        for u, name in enumerate(g.units):
            phi = np.degrees(np.asarray(g.path_phi_rad)[:, u])
            ax.plot(phi, a, color=PALETTE[colour % len(PALETTE)], lw=1.2,
                    label=f"group {k}: {name} (SRT {g.srt_g:.3f} g)")
            ax.plot(phi[1:], a[1:], "o", ms=3, color=PALETTE[colour % len(PALETTE)])
            colour += 1
        lifted = {}
        for axle, at in g.lift_off_g.items():
            if at is not None:
                lifted.setdefault(round(at, 9), []).append(axle)
        phi_last = np.degrees(np.asarray(g.path_phi_rad)[:, -1])
        for event, (at, axles) in enumerate(sorted(lifted.items()), 1):
            if event < len(a):
                ax.annotate(", ".join(axles), (phi_last[event], a[event]), fontsize=SMALL_PT, xytext=(4, -8),
                            textcoords="offset points")
    ax.set_xlabel("outward roll of the sprung mass φ [deg]")
    ax.set_ylabel("lateral acceleration a_y [g]")
    ax.set_title(f"{threshold.vehicle.name}: static rollover threshold, lift-off axle by axle", fontsize=SMALL_PT + 1)
    ax.grid(True, lw=0.3)
    ax.set_xlim(left=0.0)
    ax.set_ylim(bottom=0.0)
    ax.legend(fontsize=SMALL_PT, loc="lower right")
    return fig
