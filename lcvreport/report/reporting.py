"""Figures and tables with their captions, for the notebooks; every number also as CSV.

Every figure and table is displayed with a caption that starts with its number
(``Figure 4-2.``, ``Table D.3.``) and is built from the parameters the notebook ran
with; its data are written as CSV to the report's data folder (``data_dir``, absolute)
so numbers can be diffed between builds.  Tables render as HTML in the HTML report
and as LaTeX in the PDF (:class:`Table`): text columns wrap inside paragraph
columns, numbers are right-aligned with a fixed number of significant digits, units
sit in the headers, and a table too wide for the page goes on a landscape page.

Examples
--------
>>> header_label("y6_in"), header_label("speed_kph"), header_label("damping_ratio")
('y6 [in]', 'speed [km/h]', 'damping ratio')
"""
from __future__ import annotations

import csv
import html
import math
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from .plotting import figure_data

#: unit suffixes of column names -> the unit printed in the header (longest first)
UNIT_SUFFIXES = (
    ("_lbf_in_per_rad", "lbf*in/rad"), ("_lbf_s2_per_in", "lbf*s^2/in"), ("_lbf_in_s2", "lbf*in*s^2"),
    ("_lbf_per_rad", "lbf/rad"), ("_N_per_rad", "N/rad"), ("_Nm_per_rad", "N*m/rad"), ("_kg_m2", "kg*m^2"),
    ("_m_per_s2_per_rad", "m/s^2/rad"), ("_m_per_s2", "m/s^2"), ("_rad_per_s", "rad/s"), ("_m_per_s", "m/s"),
    ("_per_s", "1/s"), ("_percent", "%"), ("_lbf", "lbf"), ("_mph", "mph"), ("_kph", "km/h"), ("_deg", "deg"),
    ("_rad", "rad"), ("_hz", "Hz"), ("_Nm", "N*m"), ("_kg", "kg"), ("_in", "in"), ("_m", "m"), ("_s", "s"),
    ("_N", "N"),
)
#: text width of the PDF page, in characters of the table font (footnotesize, portrait)
PORTRAIT_CHARS = 104
#: and on a landscape page
LANDSCAPE_CHARS = 150


def setup(data_dir: str | Path | None) -> Path | None:
    """Configure figures (SVG for HTML, PDF for LaTeX, deterministic) and return the data
    folder as an absolute path (created), or None when no CSV is to be written."""
    import matplotlib
    matplotlib.rcParams.update({"svg.hashsalt": "lcvreport", "font.size": 8, "axes.titlesize": 9,
                                "axes.labelsize": 8, "xtick.labelsize": 7, "ytick.labelsize": 7,
                                "legend.fontsize": 7, "svg.fonttype": "none", "pdf.fonttype": 42})
    try:  # inside IPython: emit both SVG and PDF for every figure
        from IPython import get_ipython
        if get_ipython() is not None:
            from matplotlib_inline.backend_inline import set_matplotlib_formats
            set_matplotlib_formats("svg", "pdf", metadata={"Date": None})
    except ImportError:  # pragma: no cover
        pass
    if data_dir in (None, ""):
        return None
    path = Path(data_dir).expanduser().resolve()
    path.mkdir(parents=True, exist_ok=True)
    return path


def header_label(column: str) -> str:
    """``y6_in`` -> ``y6 [in]``: the column name with its unit suffix as a bracketed unit."""
    for suffix, unit in UNIT_SUFFIXES:
        if column.endswith(suffix) and len(column) > len(suffix):
            return column[:-len(suffix)].replace("_", " ") + f" [{unit}]"
    return column.replace("_", " ")


def _slug(number: str) -> str:
    return number.replace(" ", "_").replace(".", "_").replace("/", "_")


def write_csv(path: Path, rows: list[dict]) -> None:
    """Write ``rows`` (dicts with the same keys) as CSV; floats with repr (exact)."""
    if not rows:
        path.write_text("")
        return
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: repr(float(v)) if isinstance(v, (float, np.floating)) else
                        repr(complex(v)) if isinstance(v, (complex, np.complexfloating)) else v
                        for k, v in r.items()})


def fmt(value: Any, digits: int = 4) -> str:
    """A number for a table cell: ``digits`` significant digits, compact."""
    if isinstance(value, (complex, np.complexfloating)):
        value = complex(value)
        sign = "+" if value.imag >= 0 else "-"
        return f"{fmt(value.real, digits)} {sign} {fmt(abs(value.imag), digits)}i"
    if isinstance(value, (bool, np.bool_)):
        return "yes" if value else "no"
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if value == 0:
            return "0"
        if not math.isfinite(value):
            return str(value)
        text = f"{value:.{digits}g}"
        return text.replace("e+0", "e").replace("e-0", "e-").replace("e+", "e")
    return str(value)


def _is_number(v) -> bool:
    return isinstance(v, (int, float, complex, np.integer, np.floating, np.complexfloating)) and not isinstance(v, bool)


def _latex_escape(text: str) -> str:
    out = []
    for ch in text:
        out.append({"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
                    "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\^{}"}.get(ch, ch))
    return "".join(out)


class Table:
    """A table with its caption, rendered as HTML, LaTeX (PDF) or Markdown.

    Parameters
    ----------
    number : str
        ``"5-1"``, ``"D.3"``, ``"eq. 4.14"``.
    caption : str
    rows : list of dict
        Column names carry units (``speed_mph``, ``y6_in``); see :func:`header_label`.
    digits : int
        Significant digits of numbers.
    columns : list of str, optional
    """

    def __init__(self, number: str, caption: str, rows: list[dict], digits: int = 4,
                 columns: Iterable[str] | None = None):
        self.number, self.caption, self.rows, self.digits = number, caption, rows, digits
        self.columns = list(columns) if columns is not None else (list(rows[0].keys()) if rows else [])
        self.cells = [[fmt(r.get(c, ""), digits) for c in self.columns] for r in rows]
        self.numeric = [bool(rows) and all(_is_number(r.get(c)) for r in rows) for c in self.columns]
        self.headers = [header_label(c) for c in self.columns]

    # --------------------------------------------------------------- layout
    def _widths(self) -> tuple[list[float], bool, str]:
        """Column widths as fractions of the line width, landscape or not, font size."""
        natural = []
        for k in range(len(self.columns)):
            longest_word = max([len(w) for w in self.headers[k].split()] or [1])
            body = max([len(row[k]) for row in self.cells] or [1])
            if self.numeric[k]:
                natural.append(max(body, longest_word, 3) + 1)
            else:
                natural.append((max(longest_word, 6) + 1, max(body, len(self.headers[k])) + 1))
        fixed = sum(w for w in natural if not isinstance(w, tuple))
        text_min = sum(w[0] for w in natural if isinstance(w, tuple))
        text_full = sum(w[1] for w in natural if isinstance(w, tuple))
        for chars, landscape, size in ((PORTRAIT_CHARS, False, "footnotesize"),
                                       (LANDSCAPE_CHARS, True, "footnotesize"),
                                       (LANDSCAPE_CHARS * 1.2, True, "scriptsize")):
            if fixed + text_min <= chars:
                break
        spare = max(chars - fixed, text_min)
        widths = []
        for w in natural:
            if isinstance(w, tuple):
                share = w[1] / text_full if text_full else 0.0
                widths.append(max(w[0], min(w[1], spare * share if fixed + text_full > chars else w[1])))
            else:
                widths.append(w)
        total = sum(widths)
        scale = min(1.0, chars / total) if total else 1.0
        return [w * scale / chars for w in widths], landscape, size

    # --------------------------------------------------------------- renderers
    def _repr_latex_(self) -> str:
        if not self.columns:
            return rf"\textbf{{Table {_latex_escape(self.number)}.}} {_latex_escape(self.caption)} (no rows)"
        widths, landscape, size = self._widths()
        spec = "".join((r">{\raggedleft\arraybackslash}p{%.3f\linewidth}" if num else
                        r">{\raggedright\arraybackslash}p{%.3f\linewidth}") % max(w - 0.025, 0.02)
                       for w, num in zip(widths, self.numeric))
        head = " & ".join(r"\textbf{%s}" % _latex_escape(h) for h in self.headers) + r" \\"
        body = "\n".join(" & ".join(_latex_escape(c) for c in row) + r" \\" for row in self.cells)
        cap = rf"\textbf{{Table {_latex_escape(self.number)}.}} {_latex_escape(self.caption)}"
        lines = [r"\begin{landscape}" if landscape else "", "{\\" + size, r"\setlength{\tabcolsep}{0.0125\linewidth}",
                 rf"\begin{{longtable}}{{{spec}}}", rf"\caption*{{{cap}}}\\", r"\toprule", head, r"\midrule",
                 r"\endfirsthead", r"\toprule", head, r"\midrule", r"\endhead", body, r"\bottomrule",
                 r"\end{longtable}}", r"\end{landscape}" if landscape else ""]
        return "\n".join(line for line in lines if line)

    def _repr_html_(self) -> str:
        align = ["right" if n else "left" for n in self.numeric]
        head = "".join(f'<th style="text-align:{a}">{html.escape(h)}</th>' for h, a in zip(self.headers, align))
        body = "".join("<tr>" + "".join(f'<td style="text-align:{a}">{html.escape(c)}</td>'
                                        for c, a in zip(row, align)) + "</tr>" for row in self.cells)
        return (f'<table class="lcv-table"><caption style="caption-side:top;text-align:left">'
                f"<b>Table {html.escape(self.number)}.</b> {html.escape(self.caption)}</caption>"
                f"<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def _repr_markdown_(self) -> str:
        lines = [f"**Table {self.number}.** {self.caption}", "",
                 "| " + " | ".join(self.headers) + " |",
                 "|" + "|".join("--:" if n else ":--" for n in self.numeric) + "|"]
        lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in self.cells]
        return "\n".join(lines)


def show_figure(fig, number: str, caption: str, data_dir: str | Path | None) -> None:
    """Display ``fig`` with the caption ``Figure <number>. <caption>`` and save its data as CSV."""
    from IPython.display import Markdown, display
    if data_dir is not None:
        write_csv(Path(data_dir) / f"figure_{_slug(number)}.csv", figure_data(fig))
    display(fig)
    display(Markdown(f"**Figure {number}.** {caption}"))


def show_table(number: str, caption: str, rows: list[dict], data_dir: str | Path | None, digits: int = 4,
               columns: Iterable[str] | None = None) -> Table:
    """Display ``rows`` as a :class:`Table` under ``Table <number>. <caption>``; save CSV."""
    from IPython.display import display
    if data_dir is not None:
        write_csv(Path(data_dir) / f"table_{_slug(number)}.csv", rows)
    table = Table(number, caption, rows, digits, columns)
    display(table)
    return table


def matrix_rows(matrix, row_names: list[str], col_names: list[str]) -> list[dict]:
    """Rows of a matrix for :func:`show_table` (first column the row name)."""
    return [{"row": rn, **{cn: float(v) for cn, v in zip(col_names, row)}} for rn, row in zip(row_names, matrix)]
