"""Study charts: scatter of measures against factors, pass rates against criteria."""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT


def _study_label(name: str, unit: str) -> str:
    """``trailer3.cornering_stiffness_scale`` -> three short lines and the unit (panels are narrow)."""
    text = name.replace(".", "\n").replace("_stiffness_", "_stiffness\n")
    return f"{text} [{unit}]"


def fig_study_scatter(table, factors: list[str], measures: list[str], units: dict, max_points: int = 2000,
                      seed: int = 0) -> Figure:
    """Every measure (rows) against every factor (columns): the cases (at most ``max_points``,
    drawn with a fixed seed) and the median per bin of the factor.  ``units`` maps every column
    to its unit (the registry's, :func:`lcvreport.measures.registry.unit_of`)."""
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
                ax.set_xlabel(_study_label(f, units[f]), fontsize=SMALL_PT)
            if j == 0:
                ax.set_ylabel(_study_label(m, units[m]), fontsize=SMALL_PT)
    return fig


def study_pass_rates(rates, units: dict) -> Figure:
    """Pass rate [%] against each factor, one line per limit (and all together); ``units`` maps
    every factor to its unit."""
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
        ax.set_xlabel(_study_label(f, units[f]), fontsize=SMALL_PT)
        ax.tick_params(labelsize=SMALL_PT)
        if j == 0:
            ax.set_ylabel("cases passing [%]", fontsize=SMALL_PT)
    if factors and rates.by_factor[factors[0]][1]:
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, fontsize=SMALL_PT, loc="outside lower center", ncol=min(5, len(labels)))
    return fig
