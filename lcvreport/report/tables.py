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
from functools import lru_cache
from pathlib import Path
from typing import Any, Iterable

import numpy as np

from ..plotting.style import figure_data

#: unit suffixes of column names -> the unit printed in the header (longest first)
UNIT_SUFFIXES = (
    ("_lbf_in_per_rad", "lbf·in/rad"), ("_lbf_s2_per_in", "lbf·s²/in"), ("_lbf_in_s2", "lbf·in·s²"),
    ("_lbf_per_rad", "lbf/rad"), ("_N_per_rad", "N/rad"), ("_Nm_per_rad", "N·m/rad"), ("_kg_m2", "kg·m²"),
    ("_m_per_s2_per_rad", "m/s²/rad"), ("_m_per_s2", "m/s²"), ("_rad_per_s", "rad/s"), ("_m_per_s", "m/s"),
    ("_per_s", "1/s"), ("_percent", "%"), ("_lbf", "lbf"), ("_mph", "mph"), ("_kph", "km/h"), ("_deg", "deg"),
    ("_mrad", "mrad"), ("_rad", "rad"), ("_hz", "Hz"), ("_mm", "mm"), ("_Nm", "N·m"), ("_kg", "kg"), ("_in", "in"), ("_m", "m"), ("_s", "s"),
    ("_N", "N"),
)
#: text width of the PDF page [pt]: US letter with 2 cm margins (the lcvlatex template), portrait
PORTRAIT_LINE_PT = 500.0
#: and on a landscape page
LANDSCAPE_LINE_PT = 675.0
#: cell values that stand for "no number" in a numeric column
BLANKS = ("", None, "none", "-")
#: a one-row table with more columns than this is shown transposed (quantity, value)
TRANSPOSE_COLUMNS = 5
#: a table up to this height [pt] is set as one block with its caption (taller ones break
#: over pages): 60 % of the text height of a portrait page, or of a landscape page's
UNBROKEN_HEIGHT_PT = {False: 0.6 * 678.0, True: 0.6 * PORTRAIT_LINE_PT}


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


@lru_cache(maxsize=2)
def _font(bold: bool):
    from matplotlib import font_manager, ft2font
    prop = font_manager.FontProperties(family="DejaVu Serif", weight="bold" if bold else "normal")
    return ft2font.FT2Font(font_manager.findfont(prop, fallback_to_default=True))


def text_width_pt(text: str, size_pt: float = 8.0, bold: bool = False) -> float:
    """Width of ``text`` set in DejaVu Serif (the PDF's font) at ``size_pt`` [pt]."""
    if not text:
        return 0.0
    font = _font(bold)
    font.set_size(size_pt, 72)
    font.set_text(text, 0.0)
    return font.get_width_height()[0] / 64.0


def header_label(column: str) -> str:
    """``y6_in`` -> ``y6 [in]``: the column name with its unit suffix as a bracketed unit."""
    for suffix, unit in UNIT_SUFFIXES:
        if column.endswith(suffix) and len(column) > len(suffix):
            return column[:-len(suffix)].replace("_", " ") + f" [{unit}]"
    return column.replace("_", " ")


def _slug(number: str) -> str:
    return number.replace(" ", "_").replace(".", "_").replace("/", "_")


def write_csv(path: Path, rows: list[dict]) -> None:
    """Write ``rows`` (dicts with the same keys) as CSV; floats with repr (exact), an
    undefined number (NaN) as an empty cell."""
    if not rows:
        path.write_text("")
        return
    with open(path, "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()), lineterminator="\n")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if np.isnan(v) else repr(float(v))) if isinstance(v, (float, np.floating)) else
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
        if 1e-3 <= abs(value) < 1e6:   # fixed point: `digits` significant digits, integers whole
            decimals = max(0, digits - 1 - math.floor(math.log10(abs(value))))
            return f"{value:.{decimals}f}"
        text = f"{value:.{digits - 1}e}"
        mantissa, exponent = text.split("e")
        return f"{mantissa}e{int(exponent)}"
    return str(value)


def _is_number(v) -> bool:
    return isinstance(v, (int, float, complex, np.integer, np.floating, np.complexfloating)) and not isinstance(v, bool)


def _latex_escape(text: str) -> str:
    out = []
    for ch in text:
        out.append({"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_",
                    "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}", "^": r"\^{}"}.get(ch, ch))
    return "".join(out)


#: the characters Markdown (CommonMark, and pandoc's Markdown) treats as syntax: each is escaped
MARKDOWN_PUNCTUATION = frozenset(r"""!"#$%&'()*+,-./:;<=>?@[\]^_`{|}~""")


def md_text(text) -> str:
    r"""``text`` -- a vehicle's description, a file path, a criteria file's source, any string a
    user wrote -- as Markdown that renders it literally, in the HTML and in the PDF.

    Every ASCII punctuation character is backslash-escaped (CommonMark and pandoc both read
    ``\<`` as a plain ``<``), so HTML tags, links, emphasis, LaTeX commands (``\input``) and
    math delimiters (``$``) in it are text; line breaks become spaces; and the whole sits in a
    ``tex2jax_ignore`` span, so that MathJax leaves it alone (pandoc keeps the span's text in
    the LaTeX).  Interpolate user strings into Markdown through this, never raw.

    Examples
    --------
    >>> md_text("<img src=x onerror=alert(1)>")
    '<span class="tex2jax_ignore">\\<img src\\=x onerror\\=alert\\(1\\)\\></span>'
    """
    text = " ".join(str(text).split())
    return '<span class="tex2jax_ignore">' + "".join("\\" + c if c in MARKDOWN_PUNCTUATION else c
                                                       for c in text) + "</span>"


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
    headers : dict, optional
        Column -> header text set as given (a user's name: a scheme's level ``L1_kph`` is not a
        unit suffix); the other columns' headers come from :func:`header_label`.
    portrait : bool
        Keep the table on a portrait page (smaller type, down to 6 pt, before a landscape page):
        a verdict table that must stay on page 1.
    """

    def __init__(self, number: str, caption: str, rows: list[dict], digits: int = 4,
                 columns: Iterable[str] | None = None, headers: dict | None = None, portrait: bool = False):
        self.number, self.caption, self.rows, self.digits = number, caption, rows, digits
        self.portrait = portrait
        self.columns = list(columns) if columns is not None else (list(rows[0].keys()) if rows else [])
        self.cells = [[fmt(r.get(c, ""), digits) for c in self.columns] for r in rows]
        # a numeric column: numbers, or blanks where a row has none (a coupling that does not exist)
        self.numeric = [any(_is_number(r.get(c)) for r in rows) and
                        all(_is_number(r.get(c)) or r.get(c) in BLANKS for r in rows) for c in self.columns]
        given = headers or {}
        self.headers = [" ".join(str(given[c]).split()) if c in given else header_label(c) for c in self.columns]
        if len(rows) == 1 and len(self.columns) > TRANSPOSE_COLUMNS:
            # one row of many columns reads better as a list of quantities
            values = [rows[0].get(c, "") for c in self.columns]
            self.cells = [[h, fmt(v, digits)] for h, v in zip(self.headers, values)]
            self.numeric = [False, all(_is_number(v) or v in BLANKS for v in values)]
            self.headers = ["quantity", "value"]

    # --------------------------------------------------------------- layout
    def _header_lines(self, k: int, width_pt: float, size_pt: float) -> list[str]:
        """The header of column ``k`` broken between words into lines no wider than
        ``width_pt`` (a word wider than that stays whole: never letter by letter)."""
        lines: list[str] = []
        for word in self.headers[k].split():
            if lines and text_width_pt(lines[-1] + " " + word, size_pt, bold=True) <= width_pt:
                lines[-1] += " " + word
            else:
                lines.append(word)
        return lines or [""]

    def _layout(self) -> tuple[list[float], bool, float, float]:
        """Column widths [pt] (numbers: their natural width, text: a paragraph width),
        whether the table needs a landscape page, the font size [pt] and the space
        between columns [pt].  Widths are measured with the PDF's font (DejaVu Serif)."""
        tries = ((PORTRAIT_LINE_PT, False, 8.0), (LANDSCAPE_LINE_PT, True, 8.0), (LANDSCAPE_LINE_PT, True, 7.0))
        if self.portrait:               # a table that must stay on its page: smaller type before a turned page
            tries = ((PORTRAIT_LINE_PT, False, 8.0), (PORTRAIT_LINE_PT, False, 7.0), (PORTRAIT_LINE_PT, False, 6.0),
                     *tries[1:])
        for line_pt, landscape, size in tries:
            natural, text_min, text_full = [], 0.0, 0.0
            for k in range(len(self.headers)):
                words = self.headers[k].split() or [""]
                head_word = max(text_width_pt(w, size, bold=True) for w in words)
                body_full = max([text_width_pt(row[k], size) for row in self.cells] or [0.0])
                if self.numeric[k]:
                    natural.append(max(body_full, head_word, 2 * size))
                    continue
                body_word = max([text_width_pt(w, size) for row in self.cells for w in row[k].split()] or [0.0])
                full = max(body_full, text_width_pt(self.headers[k], size, bold=True), 2 * size)
                low = min(full, max(head_word, body_word, 6 * size))
                natural.append((low, full))
                text_min += low
                text_full += full
            fixed = sum(w for w in natural if not isinstance(w, tuple))
            gap = 5.0 if fixed + text_full + 10.0 * len(natural) <= line_pt else 3.0
            room = line_pt - fixed - 2 * gap * len(natural)
            # portrait when the text columns get at least 40 % of the width they would like
            # beyond their minimum
            share = (room - text_min) / (text_full - text_min) if text_full > text_min else 1.0
            if text_min <= room and (share >= 0.4 or size < 8.0 or (self.portrait and size <= 6.0)):
                break
        # text columns: their minimum width, plus a share of what is left in proportion to
        # how much more they would need (the table never exceeds the line when it can)
        spare, need = room - text_min, text_full - text_min
        widths = [w if not isinstance(w, tuple) else
                  w[0] + (w[1] - w[0]) * (min(1.0, max(spare, 0.0) / need) if need > 0 else 0.0) for w in natural]
        return widths, landscape, size, gap

    def _height_pt(self, widths: list[float], size: float) -> float:
        """Estimated height of the table body and header [pt]: a row is as many lines as
        its most wrapped text cell."""
        lines = 0
        for row in self.cells:
            lines += max([1] + [math.ceil(1.15 * text_width_pt(c, size) / w) for c, w, num
                                in zip(row, widths, self.numeric) if not num and w > 0])
        return (lines + 4) * (size + 1.5)

    # --------------------------------------------------------------- renderers
    def _repr_latex_(self) -> str:
        """Numbers in right-aligned columns of their natural width (a number never
        breaks), text in ragged paragraph columns, headers broken between words, the
        caption above; one block up to :data:`UNBROKEN_HEIGHT_PT`, else a longtable;
        on a landscape page when the columns need it."""
        cap = rf"\textbf{{Table {_latex_escape(self.number)}.}} {_code_spans(self.caption, _latex_escape, 'latex')}"
        if not self.headers:
            return cap + " (no rows)"
        widths, landscape, size, gap = self._layout()
        spec = "".join("r" if num else r">{\raggedright\arraybackslash}p{%.1fpt}" % w
                       for w, num in zip(widths, self.numeric))
        heads = []
        for k, (w, num) in enumerate(zip(widths, self.numeric)):
            if num:
                lines = [_latex_escape(line) for line in self._header_lines(k, w, size)]
                heads.append(r"\begin{tabular}[b]{@{}r@{}}\textbf{%s}\end{tabular}"
                             % r"}\\\textbf{".join(lines))
            else:
                heads.append(r"\textbf{%s}" % _latex_escape(self.headers[k]))
        head = " & ".join(heads) + r" \\"
        body = "\n".join(" & ".join(_latex_escape(c) for c in row) + r" \\" for row in self.cells)
        n = len(self.headers)
        font = r"\fontsize{%g}{%g}\selectfont" % (size, size + 1.5)
        setup = [font, r"\setlength{\tabcolsep}{%gpt}" % gap]
        if self._height_pt(widths, size) <= UNBROKEN_HEIGHT_PT[landscape]:
            # one unbreakable block: the caption never leaves its table
            lines = [r"\par\medskip\noindent\begin{minipage}{\linewidth}", r"{\raggedright " + cap + r"\par}",
                     r"\smallskip{", *setup, rf"\begin{{tabular}}{{@{{}}{spec}@{{}}}}", r"\toprule", head,
                     r"\midrule", body, r"\bottomrule", r"\end{tabular}}", r"\end{minipage}\par\medskip"]
        else:
            # a long table breaks over pages, its header repeated
            lines = [r"\par\medskip\noindent{\raggedright " + cap + r"\par}", "{", *setup,
                     r"\setlength{\LTpre}{2pt}\setlength{\LTleft}{0pt}\setlength{\LTright}{\fill}",
                     rf"\begin{{longtable}}{{@{{}}{spec}@{{}}}}", r"\toprule", head, r"\midrule", r"\endfirsthead",
                     rf"\multicolumn{{{n}}}{{@{{}}l}}{{\normalsize\textbf{{Table {_latex_escape(self.number)}}} "
                     r"(continued)}\\[2pt]",
                     r"\toprule", head, r"\midrule", r"\endhead", body, r"\bottomrule", r"\end{longtable}}"]
        if landscape:
            lines = [r"\begin{landscape}", *lines, r"\end{landscape}"]
        return "\n".join(lines)

    def _repr_html_(self) -> str:
        align = ["right" if n else "left" for n in self.numeric]
        head = "".join(f'<th style="text-align:{a}">{html.escape(h)}</th>' for h, a in zip(self.headers, align))
        body = "".join("<tr>" + "".join(f'<td style="text-align:{a}">{html.escape(c)}</td>'
                                        for c, a in zip(row, align)) + "</tr>" for row in self.cells)
        # tex2jax_ignore: MathJax leaves the cells alone (tire ids, sources: text the user wrote)
        return (f'<table class="lcv-table tex2jax_ignore"><caption style="caption-side:top;text-align:left">'
                f"<b>Table {html.escape(self.number)}.</b> {_code_spans(self.caption, html.escape, 'html')}</caption>"
                f"<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>")

    def _repr_markdown_(self) -> str:
        lines = [f"**Table {self.number}.** {self.caption}", "",
                 "| " + " | ".join(self.headers) + " |",
                 "|" + "|".join("--:" if n else ":--" for n in self.numeric) + "|"]
        lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in self.cells]
        return "\n".join(lines)


def _code_spans(text: str, escape, target: str) -> str:
    """``text`` escaped for ``target`` ("latex" or "html"), its `code spans` set as code
    (Markdown captions may name commands such as `lcv measures`)."""
    parts = text.split("`")
    if len(parts) % 2 == 0:            # an unpaired backtick: plain text
        return escape(text)
    out = []
    for i, part in enumerate(parts):
        if i % 2 == 0:
            out.append(escape(part))
        elif target == "latex":
            out.append(r"\texttt{" + escape(part) + "}")
        else:
            out.append("<code>" + escape(part) + "</code>")
    return "".join(out)


def show_figure(fig, number: str, caption: str, data_dir: str | Path | None) -> None:
    """Display ``fig`` with the caption ``Figure <number>. <caption>`` and save its data as CSV.

    The CSV holds the engineering data behind the figure when the code that drew it
    attached them (``fig.lcv_data``: rows with units in the column names), else the
    points of every line, marker set, bar and polygon (:func:`figure_data`)."""
    from IPython.display import Markdown, display
    if data_dir is not None:
        rows = getattr(fig, "lcv_data", None)
        write_csv(Path(data_dir) / f"figure_{_slug(number)}.csv", rows if rows is not None else figure_data(fig))
    display(fig)
    display(Markdown(f"**Figure {number}.** {caption}"))


def show_table(number: str, caption: str, rows: list[dict], data_dir: str | Path | None, digits: int = 4,
               columns: Iterable[str] | None = None, headers: dict | None = None, portrait: bool = False) -> None:
    """Display ``rows`` as a :class:`Table` under ``Table <number>. <caption>``; save CSV
    (``headers``: column -> header set as given; ``portrait``: kept on a portrait page; :class:`Table`).

    Returns None, so a call ending a notebook cell does not display the table twice."""
    from IPython.display import display
    if data_dir is not None:
        write_csv(Path(data_dir) / f"table_{_slug(number)}.csv", rows)
    display(Table(number, caption, rows, digits, columns, headers, portrait))


