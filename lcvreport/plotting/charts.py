"""Generic charts: grouped bars and fitted curves."""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure

from .style import PAGE_WIDTH_IN, PALETTE, SMALL_PT, new_figure


def fig_bars(labels: list[str], groups: list[tuple[str, np.ndarray]], ylabel: str, title: str,
             height: float = 3.6, horizontal: bool = False) -> Figure:
    """Grouped bar chart (Figures 5-4, 5-8, 5-13, 5-18, 5-20; conicity sensitivity).

    ``horizontal=True`` lays the categories down the page, one row each, top to bottom in the
    order given, for many categories with long names (Figure 5-20): every value label then
    has a row of its own; ``ylabel`` names the value axis either way."""
    fig, ax = new_figure(PAGE_WIDTH_IN, height)
    x = np.arange(len(labels))
    w = 0.8 / len(groups)
    for i, (glabel, values) in enumerate(groups):
        pos = x + (i - (len(groups) - 1) / 2) * w
        if horizontal:
            bars = ax.barh(pos, values, w, label=glabel, color=PALETTE[i])
            for b, v in zip(bars, values):
                ax.annotate(f" {v:.3g} ", (b.get_width(), b.get_y() + b.get_height() / 2), va="center",
                            ha="left" if v >= 0 else "right", fontsize=SMALL_PT)
        else:
            bars = ax.bar(pos, values, w, label=glabel, color=PALETTE[i])
            for b, v in zip(bars, values):
                ax.annotate(f"{v:.3g}", (b.get_x() + b.get_width() / 2, b.get_height()), ha="center",
                            va="bottom" if v >= 0 else "top", fontsize=SMALL_PT)
    if horizontal:
        ax.set_yticks(x, labels, fontsize=SMALL_PT)
        ax.set_ylim(len(labels) - 0.5, -0.5)
        lo, hi = ax.get_xlim()
        ax.set_xlim(lo - 0.12 * (hi - lo), hi + 0.12 * (hi - lo))     # room for the value labels
        ax.axvline(0, color="black", lw=0.6)
        ax.set_xlabel(ylabel)
        ax.grid(True, axis="x", lw=0.3)
    else:
        ax.set_xticks(x, labels, rotation=25, ha="right", fontsize=SMALL_PT)
        ax.axhline(0, color="black", lw=0.6)
        ax.set_ylabel(ylabel)
        ax.grid(True, axis="y", lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig


def fig_fit(x: np.ndarray, ys: list[tuple[str, np.ndarray]], degree: int | None, xlabel: str, ylabel: str,
            title: str) -> Figure:
    """Points and (optional) least-squares polynomial fits of the given degree."""
    fig, ax = new_figure(PAGE_WIDTH_IN, 3.4)
    xx = np.linspace(np.min(x), np.max(x), 101)
    for i, (label, y) in enumerate(ys):
        ax.plot(x, y, "o", color=PALETTE[i], label=label)
        if degree is not None:
            c = np.polyfit(x, y, degree)
            ax.plot(xx, np.polyval(c, xx), "--", color=PALETTE[i], lw=1, label=f"degree-{degree} fit")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=SMALL_PT)
    ax.set_title(title, fontsize=9)
    return fig
