"""Time histories: any time response, the manoeuvres of the measures (single sine, lane
change, pulse) with their measures marked.
"""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure


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
    """Signals of a :class:`lcvreport.analysis.time_response.TimeResponse` against time, each
    labelled with its unit; where the run knows its steer, the steer angle [deg] dotted on a
    second axis.  Default signals: every unit's lateral acceleration [m/s^2] where the steer is
    known, else the rear offsets y2..yN [m] (Y1 of a single unit)."""
    if ax is None:
        fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    else:
        fig = ax.figure
    v = response.vehicle
    units = {k: u.replace("^2", "²") for k, u in response.units().items()}
    steer = "delta" in units
    signals = list(signals or ([f"ay{i + 1}" for i in range(v.n_units)] if steer else
                               [f"y{k}" for k in range(2, v.n_units + 1)] or ["Y1"]))
    for i, name in enumerate(signals):
        kw = {"color": PALETTE[i % len(PALETTE)], "lw": 1.0}
        kw.update(style)
        ax.plot(response.time, response[name], label=f"{name} [{units.get(name, '')}]", **kw)
    handles = ax.get_lines()
    if steer and "delta" not in signals:
        ax2 = ax.twinx()
        ax2.plot(response.time, np.degrees(response["delta"]), color="black", lw=0.8, ls=":", label="steer angle")
        ax2.set_ylabel("steer angle [deg] (dotted)")
        ax2.tick_params(labelsize=SMALL_PT)
        handles = handles + ax2.get_lines()
    ax.set_xlabel("time [s]")
    shown = {units.get(name, "") for name in signals}
    ax.set_ylabel(f"{', '.join(signals[:3])}{' ...' if len(signals) > 3 else ''}"
                  + (f" [{shown.pop()}]" if len(shown) == 1 else ""))
    ax.grid(True, lw=0.3)
    ax.legend(handles=handles, fontsize=SMALL_PT, ncol=4, loc="upper center", bbox_to_anchor=(0.5, -0.18),
              frameon=False)
    if response.label:
        ax.set_title(response.label, fontsize=9)
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


def fig_lane_change(lc, title: str) -> Figure:
    """The path-following lane change (:class:`lcvreport.measures.offtracking.LaneChangeMeasures`):
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
    extrema the ratio method uses marked (:class:`lcvreport.measures.yaw_damping.YawDamping`)."""
    r = ydc.response
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    end = min(r.time[-1], 12.0)
    sel = r.time <= end
    for i, name in enumerate(names):
        c = PALETTE[i % len(PALETTE)]
        heavy = f"{name} (heavily damped: ζ ≥ {ydc.heavy_zeta:.3f})"
        ax.plot(r.time[sel], np.degrees(r[name][sel]), color=c, lw=1.0,
                label=f"{name} (ζ {ydc.per_joint[i]:.3f})" if ydc.per_joint[i] is not None else heavy)
        t, v = ydc.extrema[i]
        used = len(ydc.amplitudes[i]) + 1 if len(ydc.amplitudes[i]) else 0
        keep = np.arange(t.size) < used
        ax.plot(t[keep & (t <= end)], np.degrees(v[keep & (t <= end)]), "o", ms=3, color=c)
    ax.margins(y=0.12)                       # the first peaks clear of the frame
    ax.set_xlabel("time [s]")
    ax.set_ylabel("articulation angle [deg]")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT, ncol=3, loc="upper center", bbox_to_anchor=(0.5, -0.18), frameon=False)
    ax.set_title(title, fontsize=9)
    return fig
