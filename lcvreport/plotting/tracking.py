"""Straight-line tracking: the offtracking histogram, the axle sensitivities, the mounting study."""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure


def fig_offtracking_histogram(stats, title: str) -> Figure:
    """The Monte Carlo offtracking [m] of :class:`lcvreport.tracking.statistics.TrackingStats`
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
