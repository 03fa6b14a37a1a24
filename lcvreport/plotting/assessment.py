"""The evidence of an assessment drawn with every level's limit on it: the manoeuvre's time
history, the turn's swept path, the friction demand of every axle over the turn with tire
forces above both models' swept paths, the tilt curve, or the value against the limits
(:class:`lcvreport.measures.evidence.Evidence`)."""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from .style import LEVEL_STYLES, PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure, plain



def _title(ev) -> str:
    m = ev.verdict
    value = "none" if m.value is None else f"{m.value:.4g} {m.unit}"
    return plain(f"{m.key} = {value} ({m.conditions_text()}); reaches {m.level_reached or 'no level'}")


def _limits(ev) -> list[tuple[str, float, str]]:
    """(level, the bound as a number, 'min' or 'max') of every level with a finite bound, one
    entry per distinct bound (the levels sharing it named together)."""
    seen = {}
    for level in ev.levels:
        lo, hi = ev.verdict.bounds.get(level, (None, None))
        for kind, b in (("min", lo), ("max", hi)):
            if b is not None:
                seen.setdefault((kind, b), []).append(level)
    return [(plain("/".join(levels)), b, kind) for (kind, b), levels in seen.items()]


def _hlines(ax, ev, scale: float = 1.0, offset: float = 0.0, symmetric: bool = False, what: str = "limit") -> None:
    for i, (levels, b, kind) in enumerate(_limits(ev)):
        ls = LEVEL_STYLES[i % len(LEVEL_STYLES)]
        y = offset + scale * b
        ax.axhline(y, color="black", ls=ls, lw=0.9, label=f"{levels} {what} ({kind} {b:.4g})")
        if symmetric:
            ax.axhline(offset - scale * b, color="black", ls=ls, lw=0.9)


def _legend(ax) -> None:
    ax.legend(fontsize=SMALL_PT, loc="upper center", bbox_to_anchor=(0.5, -0.2), ncol=3, frameon=False)


def _beside(ax, handles=None) -> None:
    """The legend right of the axes: over no curve and no limit line."""
    kw = {} if handles is None else {"handles": handles}
    ax.legend(fontsize=SMALL_PT, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False, **kw)


def fig_evidence(ev) -> Figure:
    """One measure's evidence with its limits (see the module docstring)."""
    key = ev.verdict.key
    drawing = ev.drawing                          # the registry's (measures.toml "evidence")
    if drawing == "value":
        return _value(ev)
    if drawing == "ratio" and ev.ratio:
        return _ratio(ev, ev.result.response)
    if ev.kind == "lane_change" and drawing in ("offset", "ltr"):
        return _lane_change(ev, key)
    if ev.kind == "single_sine" and drawing == "ratio":
        return _single_sine(ev, key)
    if ev.kind == "pulse":
        from .time import fig_pulse
        names = [f"theta{c}" for c in ev.result.response.vehicle.joint_letters]
        fig = fig_pulse(ev.result, names, _title(ev))
        _text_box(fig.axes[0], ev)
        return fig
    if ev.kind == "swept_path" and drawing == "swing":
        from .low_speed import fig_swing
        which = "tail" if key == "max_tail_swing_m" else "frontal"
        limits = [(levels, b) for levels, b, _kind in _limits(ev)]
        return fig_swing(ev.result.swing(which), which, _title(ev), limits)
    if ev.kind == "swept_path":
        from .low_speed import fig_swept_path
        fig = fig_swept_path(ev.result, _title(ev))
        _text_box(fig.axes[0], ev)
        return fig
    if ev.kind == "friction_demand":
        from .low_speed import fig_friction_demand_evidence
        limits = [(f"{levels} limit ({kind})", b) for levels, b, kind in _limits(ev)]
        # a limit on the path error is no friction demand: drawn as text, not on the demand's axis
        fig = fig_friction_demand_evidence(ev.result, limits if key != "path_error_max_m" else [], _title(ev))
        if key == "path_error_max_m":
            _text_box(fig.axes[1], ev)
        return fig
    if ev.kind == "tilt":
        from .roll import plot_rollover
        fig = plot_rollover(ev.result)
        ax = fig.axes[0]
        _hlines(ax, ev, what="limit on the SRT")
        ax.set_title(_title(ev), fontsize=SMALL_PT + 1)
        handles = [h for h in ax.get_lines() if not h.get_label().startswith("_") and "lift-offs" not in h.get_label()]
        ax.legend(handles=handles, fontsize=SMALL_PT, loc="upper center", bbox_to_anchor=(0.5, -0.18), ncol=2,
                  frameon=False)
        return fig
    return _value(ev)


def _text_box(ax, ev) -> None:
    """The limit and the verdict of every level as the title's second line (over no data, and no
    legend over it)."""
    m = ev.verdict
    limits = "; ".join(f"{level} {m.limit_texts.get(level, m.limits[level])}: {m.verdicts[level]}"
                       for level in ev.levels)
    import textwrap
    ax.set_title("\n".join([_title(ev), *textwrap.wrap(plain(limits), 90)]), fontsize=SMALL_PT + 1)


def _lane_change(ev, key: str) -> Figure:
    from .roll import plot_ltr
    from .time import fig_lane_change
    lc = ev.result
    if ev.drawing == "ltr":
        from ..model.linear import linear_model
        groups = len(linear_model(lc.response.vehicle, "yaw_roll").roll.groups)
        fig = plot_ltr(lc.response, groups, _title(ev))
        _hlines(fig.axes[0], ev, symmetric=True, what="limit on |LTR| of the rearmost group")
        _beside(fig.axes[0])
        return fig
    if ev.ratio:                                   # a rearward amplification: its two points
        return _ratio(ev, lc.response)
    fig = fig_lane_change(lc, _title(ev))
    sign = 1.0 if lc.final_offset_m >= 0 else -1.0     # hsto_m, hsto_m_roll, hsto_driver_m
    _hlines(fig.axes[1], ev, scale=sign, offset=lc.final_offset_m, what="limit: final offset + HSTO")
    _beside(fig.axes[1])
    return fig


#: what a ratio's signals are, for the axis and the legend
SIGNAL_WORDS = {"a_steer": "steered axle", "ay1": "unit 1's CG"}


def _signal_label(name: str, n_units: int) -> str:
    if name in SIGNAL_WORDS:
        return f"{name} ({SIGNAL_WORDS[name]})"
    if name == f"as{n_units}":
        return f"{name} (the rearmost unit's sprung CG)"
    if name == f"ay{n_units}":
        return f"{name} (the rearmost unit's CG; its roll-axis point in the yaw-roll model)"
    return name


def _ratio(ev, response) -> Figure:
    """A rearward amplification's evidence: its numerator's and its denominator's time histories
    (the measure's reference points), their peaks marked, and every level's limit as the band
    ±(limit × max|denominator|) the numerator must stay inside."""
    num, den = ev.ratio
    n = response.vehicle.n_units
    unit = "rad/s" if num.startswith("r") else "m/s²"
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.2)
    t = np.asarray(response.time)
    for i, name in enumerate((den, num)):
        ax.plot(t, response[name], color=PALETTE[i], lw=1.0, label=plain(_signal_label(name, n)))
    (tn, yn), (td, yd) = response.extrema_many([num, den])
    kn, kd = int(np.argmax(np.abs(yn))), int(np.argmax(np.abs(yd)))
    ax.plot([td[kd]], [yd[kd]], "o", color=PALETTE[0], ms=4, label=f"max|{den}| = {abs(yd[kd]):.4g} {unit}")
    ax.plot([tn[kn]], [yn[kn]], "o", color=PALETTE[1], ms=4, label=f"max|{num}| = {abs(yn[kn]):.4g} {unit}")
    _hlines(ax, ev, scale=float(abs(yd[kd])), symmetric=True, what=f"limit: RA × max|{den}|")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"lateral {'yaw rate' if unit == 'rad/s' else 'acceleration'} [{unit}]")
    import textwrap
    fig.suptitle("\n".join(textwrap.wrap(_title(ev), 90) + [plain(f"RA = max|{num}| / max|{den}|")]),
                 fontsize=SMALL_PT + 1)
    ax.grid(True, lw=0.3)
    _beside(ax)
    keep = np.arange(0, t.size, max(1, t.size // 2000))
    tag = unit.replace("/", "_per_").replace("²", "2")
    fig.lcv_data = [{"time_s": float(t[k]), f"{den}_{tag}": float(response[den][k]),
                     f"{num}_{tag}": float(response[num][k])} for k in keep]
    return fig


def _single_sine(ev, key: str) -> Figure:
    if ev.ratio:
        return _ratio(ev, ev.result.response)
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
        ax.text(0.5, 0.5, plain(f"not computed: {m.reason}"), transform=ax.transAxes, ha="center", va="center",
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
