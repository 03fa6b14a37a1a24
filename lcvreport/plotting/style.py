"""The look of every figure: page width, the smallest font, the palette, display units of
lengths, a figure without pyplot state, and the data behind a figure (for its CSV).
"""
from __future__ import annotations


import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Polygon

from ..units import M_PER_IN

#: colours per run, stable order
PALETTE = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf", "#7f7f7f",
           "#bcbd22")


BODY = {"tractor": "#4a6fa5", "trailer": "#b0b7c3", "dolly": "#6b6b6b"}


#: text width of the PDF report [in] (figures are made this wide, so text prints at its size)
PAGE_WIDTH_IN = 6.2


#: the line styles of a scheme's levels' limits, most demanding first
LEVEL_STYLES = ("--", "-.", ":", (0, (5, 1, 1, 1, 1, 1)), (0, (1, 1)))


#: smallest font size used anywhere [pt]
SMALL_PT = 7.0


#: display units of lengths: metres per display unit
LENGTH_UNITS = {"m": 1.0, "in": M_PER_IN}


def plain(text) -> str:
    r"""``text`` as matplotlib sets it literally: every ``$`` escaped (``\$``), so that a user's
    string -- a scheme's level, a source -- is never parsed as mathtext (an unknown TeX command
    such as ``\href`` would stop the drawing), and line breaks as spaces.

    Examples
    --------
    >>> plain(r"L1 $\href{x}{y}$")
    'L1 \\$\\href{x}{y}\\$'
    """
    return " ".join(str(text).split()).replace("$", r"\$")


def new_figure(width: float = PAGE_WIDTH_IN, height: float = 3.6, ncols: int = 1, nrows: int = 1, **kw):
    """A figure and its axes (not registered with pyplot: no global state)."""
    fig = Figure(figsize=(width, height), layout="constrained")
    axes = fig.subplots(nrows, ncols, squeeze=True, **kw)
    return fig, axes


def figure_data(fig: Figure) -> list[dict]:
    """The numbers a figure shows (lines, markers, bars, patches), for CSV export and diffing."""
    rows = []
    for ia, ax in enumerate(fig.axes):
        for il, line in enumerate(ax.get_lines()):
            for x, y in line.get_xydata():
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
