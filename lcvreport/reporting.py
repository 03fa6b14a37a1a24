"""Helpers the notebooks call to show figures and tables with their thesis numbers.

Every figure and table is displayed with a caption that starts with its thesis
number (``Figure 4-2.``, ``Table D.3.``) and its data are written as CSV to the
report's data folder (``data_dir``), so numbers can be diffed between builds.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any, Iterable

import matplotlib
import numpy as np

from .plotting import figure_data


def setup(data_dir: str | Path) -> Path:
    """Configure figures (SVG for HTML, PDF for LaTeX, deterministic) and return the data folder."""
    matplotlib.rcParams.update({"svg.hashsalt": "lcvreport", "font.size": 8, "axes.titlesize": 9,
                                "svg.fonttype": "none", "pdf.fonttype": 42})
    try:  # inside IPython: emit both SVG and PDF for every figure
        from IPython import get_ipython
        ip = get_ipython()
        if ip is not None:
            from matplotlib_inline.backend_inline import set_matplotlib_formats
            set_matplotlib_formats("svg", "pdf", metadata={"Date": None})
    except ImportError:  # pragma: no cover
        pass
    path = Path(data_dir)
    path.mkdir(parents=True, exist_ok=True)
    return path


def check_parameters(**params: Any) -> None:
    """Validate notebook parameters; raise ``ValueError`` naming the bad one and the valid range."""
    from .loads import CONVENTIONS, LOADABLE_UNITS
    from .presets import PRESETS
    for name, value in params.items():
        if name == "preset" and value not in PRESETS:
            raise ValueError(f"parameter preset: unknown preset {value!r}; valid: {', '.join(PRESETS)}")
        if name == "convention" and value not in CONVENTIONS:
            raise ValueError(f"parameter convention must be one of {', '.join(CONVENTIONS)}, got {value!r}")
        if name in ("speed_mph", "t_end", "tire_scale"):
            if not isinstance(value, (int, float)) or not math.isfinite(value) or value <= 0:
                raise ValueError(f"parameter {name} must be a finite number > 0, got {value!r}")
        if name == "t_end" and value < 2.0:
            raise ValueError(f"parameter t_end must be at least 2 s (the slowest time constant is ~0.8 s), got {value!r}")
        if name == "load_units":
            bad = [u for u in value if u not in LOADABLE_UNITS]
            if not value or bad:
                raise ValueError(f"parameter load_units must be a non-empty list from {', '.join(LOADABLE_UNITS)}, "
                                 f"got {value!r}")
        if name == "fast" and not isinstance(value, bool):
            raise ValueError(f"parameter fast must be true or false, got {value!r}")


def _slug(number: str) -> str:
    return number.replace(" ", "_").replace(".", "_")


def write_csv(path: Path, rows: list[dict]) -> None:
    """Write ``rows`` (dicts with the same keys) as CSV; floats with repr (exact)."""
    if not rows:
        path.write_text("")
        return
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: repr(v) if isinstance(v, float) else v for k, v in r.items()})


def show_figure(fig, number: str, caption: str, data_dir: str | Path) -> None:
    """Display ``fig`` with the caption ``Figure <number>. <caption>`` and save its data."""
    from IPython.display import Markdown, display
    write_csv(Path(data_dir) / f"figure_{_slug(number)}.csv", figure_data(fig))
    display(fig)
    display(Markdown(f"**Figure {number}.** {caption}"))


def fmt(value: Any, digits: int = 4) -> str:
    """A number for a table cell: ``digits`` significant digits, compact."""
    if isinstance(value, complex):
        sign = "+" if value.imag >= 0 else "-"
        return f"{fmt(value.real, digits)} {sign} {fmt(abs(value.imag), digits)}i"
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if value == 0:
            return "0"
        text = f"{value:.{digits}g}"
        return text.replace("e+0", "e").replace("e-0", "e-").replace("e+", "e")
    return str(value)


def show_table(number: str, caption: str, rows: list[dict], data_dir: str | Path, digits: int = 4,
               columns: Iterable[str] | None = None) -> None:
    """Display ``rows`` as a Markdown table under ``Table <number>. <caption>``; save CSV.

    Column names should carry units (``speed_mph``, ``y6_in``)."""
    from IPython.display import Markdown, display
    write_csv(Path(data_dir) / f"table_{_slug(number)}.csv", rows)
    cols = list(columns) if columns is not None else (list(rows[0].keys()) if rows else [])
    cells = [[fmt(r.get(c, ""), digits).replace("|", "\\|").replace("*", "\\*") for c in cols] for r in rows]
    # relative column widths for pandoc (PDF): the dashes of the separator line
    widths = [max([len(c.replace("_", " ").split(" ")[0]) + 4] + [min(len(row[k]), 120) for row in cells])
              for k, c in enumerate(cols)]
    lines = [f"**Table {number}.** {caption}", "", "| " + " | ".join(c.replace("_", " ") for c in cols) + " |",
             "|" + "|".join("-" * max(3, w) for w in widths) + "|"]
    for row in cells:
        lines.append("| " + " | ".join(row) + " |")
    display(Markdown("\n".join(lines)))


def matrix_rows(matrix, row_names: list[str], col_names: list[str]) -> list[dict]:
    """Rows of a matrix for :func:`show_table` (first column the row name)."""
    return [{"row": rn, **{cn: float(v) for cn, v in zip(col_names, row)}} for rn, row in zip(row_names, matrix)]
