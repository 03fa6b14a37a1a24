"""The evidence of an assessment drawn with every level's limit on it: the manoeuvre's time
history, the turn's swept path, the tilt curve, or the value against the limits
(:class:`lcvreport.measures.evidence.Evidence`)."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure

#: the line styles of the levels' limits, most demanding first
LEVEL_STYLES = ("--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (1, 1)))


def _title(ev) -> str:
    m = ev.verdict
    value = "none" if m.value is None else f"{m.value:.4g} {m.unit}"
    return f"{m.key} = {value} ({m.conditions_text()}); reaches {m.level_reached or 'no level'}"


def _limits(ev) -> list[tuple[str, float, str]]:
    """(level, the bound as a number, 'min' or 'max') of every level with a finite bound, one
    entry per distinct bound (the levels sharing it named together)."""
    seen = {}
    for level in ev.levels:
        lo, hi = ev.verdict.bounds.get(level, (None, None))
        for kind, b in (("min", lo), ("max", hi)):
            if b is not None:
                seen.setdefault((kind, b), []).append(level)
    return [("/".join(levels), b, kind) for (kind, b), levels in seen.items()]


def _hlines(ax, ev, scale: float = 1.0, offset: float = 0.0, symmetric: bool = False, what: str = "limit") -> None:
    for i, (levels, b, kind) in enumerate(_limits(ev)):
        ls = LEVEL_STYLES[i % len(LEVEL_STYLES)]
        y = offset + scale * b
        ax.axhline(y, color="black", ls=ls, lw=0.9, label=f"{levels} {what} ({kind} {b:.4g})")
        if symmetric:
            ax.axhline(offset - scale * b, color="black", ls=ls, lw=0.9)


def _legend(ax) -> None:
    ax.legend(fontsize=SMALL_PT, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, frameon=False)


def fig_evidence(ev) -> Figure:
    """One measure's evidence with its limits (see the module docstring)."""
    key = ev.verdict.key
    if ev.kind == "lane_change":
        return _lane_change(ev, key)
    if ev.kind == "single_sine":
        return _single_sine(ev, key)
    if ev.kind == "pulse":
        from .time import fig_pulse
        names = [f"theta{c}" for c in ev.result.response.vehicle.joint_letters]
        fig = fig_pulse(ev.result, names, _title(ev))
        _text_box(fig.axes[0], ev)
        return fig
    if ev.kind == "swept_path":
        from .low_speed import fig_swept_path
        fig = fig_swept_path(ev.result, _title(ev))
        _text_box(fig.axes[0], ev, x=0.55)                  # the drawing's legend holds the upper left
        return fig
    if ev.kind == "tilt":
        from .roll import plot_rollover
        fig = plot_rollover(ev.result)
        ax = fig.axes[0]
        _hlines(ax, ev, what="limit on the SRT")
        ax.set_title(_title(ev), fontsize=SMALL_PT + 1)
        handles = [h for h in ax.get_lines() if not h.get_label().startswith("_") and "lift-offs" not in h.get_label()]
        ax.legend(handles=handles, fontsize=SMALL_PT, loc="lower right")
        return fig
    return _value(ev)


def _text_box(ax, ev, x: float = 0.01) -> None:
    """The limits and verdicts of every level in a box at the top of ``ax`` (from ``x``, axes fraction)."""
    lines = [f"{level}: {ev.verdict.limits[level]}: {ev.verdict.verdicts[level]}" for level in ev.levels]
    ax.text(x, 0.99, "\n".join(lines), transform=ax.transAxes, fontsize=SMALL_PT, va="top", ha="left",
            bbox={"facecolor": "white", "edgecolor": "gray", "lw": 0.5, "alpha": 0.9}, zorder=10)


def _lane_change(ev, key: str) -> Figure:
    from .roll import plot_ltr
    from .time import fig_lane_change
    lc = ev.result
    if key == "rltr_lane_change":
        from ..model.linear import linear_model
        groups = len(linear_model(lc.response.vehicle, "yaw_roll").roll.groups)
        fig = plot_ltr(lc.response, groups, _title(ev))
        _hlines(fig.axes[0], ev, symmetric=True, what="limit on |LTR| of the rearmost group")
        fig.axes[0].legend(fontsize=SMALL_PT, loc="lower right")
        return fig
    fig = fig_lane_change(lc, _title(ev))
    if key.startswith("hsto"):                     # hsto_m, hsto_m_roll, hsto_driver_m
        sign = 1.0 if lc.final_offset_m >= 0 else -1.0
        _hlines(fig.axes[1], ev, scale=sign, offset=lc.final_offset_m, what="limit: final offset + HSTO")
        fig.axes[1].legend(fontsize=SMALL_PT, loc="lower right")
    else:
        peak = float(np.abs(lc.response.extrema("a_steer")[1]).max())
        _hlines(fig.axes[2], ev, scale=peak, symmetric=True, what="limit: RA x max|a_s|")
        fig.axes[2].legend(fontsize=SMALL_PT, loc="lower right")
    return fig


def _single_sine(ev, key: str) -> Figure:
    ss = ev.result
    n = ss.vehicle.n_units
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    if key == "ra_yaw_rate_single_sine":
        signals, label, unit = [f"r{i + 1}" for i in range(n)], "yaw rate", "rad/s"
    else:
        signals, label, unit = [f"ay{i + 1}" for i in range(n)], "lateral acceleration", "m/s²"
    peaks = ss.response.peaks_abs(signals)
    for i, name in enumerate(signals):
        ax.plot(ss.time, ss.response[name], color=PALETTE[i % len(PALETTE)], lw=1.0,
                label=f"{name} {ss.vehicle.unit_names[i]} (peak {peaks[i]:.3g})")
    _hlines(ax, ev, scale=float(peaks[0]), symmetric=True, what=f"limit: RA x max|{signals[0]}|")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"{label} [{unit}]")
    ax.set_title(_title(ev), fontsize=SMALL_PT + 1)
    ax.grid(True, lw=0.3)
    _legend(ax)
    fig.lcv_data = [{"time_s": float(t), **{f"{s}_{unit.replace('/', '_per_').replace('²', '2')}":
                                            float(ss.response[s][k]) for s in signals}}
                    for k, t in enumerate(ss.time) if k % max(1, len(ss.time) // 2000) == 0]
    return fig


def _value(ev) -> Figure:
    """The value against every level's limit on one axis (a measure not read from a time
    history or a drawing: a steady turn, the straight path, a damping ratio), the failing side
    of each limit shaded."""
    m = ev.verdict
    fig, ax = new_figure(PAGE_WIDTH_IN, 2.2)
    limits = _limits(ev)
    xs = [b for _l, b, _k in limits] + ([m.value] if m.value is not None else [])
    lo, hi = (min(xs), max(xs)) if xs else (0.0, 1.0)
    pad = 0.15 * (hi - lo) if hi > lo else 0.15 * max(abs(hi), 1.0)
    lo, hi = lo - pad, hi + pad
    for i, (levels, b, kind) in enumerate(limits):
        ls = LEVEL_STYLES[i % len(LEVEL_STYLES)]
        ax.axvline(b, color="black", ls=ls, lw=0.9, label=f"{levels} limit ({kind} {b:.4g})")
        ax.axvspan(b, hi, color="red", alpha=0.06) if kind == "max" else ax.axvspan(lo, b, color="red", alpha=0.06)
    if m.value is not None:
        ax.plot([m.value], [0.5], "o", color=PALETTE[0], ms=7, label=f"{m.key} = {m.value:.4g} {m.unit}")
    else:
        ax.text(0.5, 0.5, f"not computed: {m.reason}", transform=ax.transAxes, ha="center", va="center",
                fontsize=SMALL_PT, wrap=True)
    ax.set_xlim(lo, hi)
    ax.set_ylim(0, 1)
    ax.set_yticks([])
    ax.set_xlabel(f"{m.label} [{m.unit}]")
    ax.set_title(_title(ev), fontsize=SMALL_PT + 1)
    ax.grid(True, axis="x", lw=0.3)
    ax.legend(fontsize=SMALL_PT, loc="upper center", bbox_to_anchor=(0.5, -0.45), ncol=3, frameon=False)
    fig.lcv_data = [{"level": level, "min": ev.verdict.bounds[level][0], "max": ev.verdict.bounds[level][1],
                     "value": m.value, "verdict": ev.verdict.verdicts[level]} for level in ev.levels]
    return fig
