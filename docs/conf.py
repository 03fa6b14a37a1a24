"""Sphinx configuration of the lcvreport documentation site (``./build.sh docs`` -> build/docs/).

The pages are the Markdown files of docs/ (MyST, formulas in dollar math); the API reference is
generated from the docstrings of ``lcvreport.__all__`` (numpydoc).  Built with warnings as errors
(``-W``): a broken cross-reference or a public name without its page fails the build.
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import lcvreport  # noqa: E402

project = "lcvreport"
author = "the lcvreport authors"
copyright = "2026, the lcvreport authors"
release = version = lcvreport.__version__

extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.autosummary", "numpydoc", "sphinx.ext.mathjax"]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "figures/*.csv"]
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
suppress_warnings = ["myst.header", "myst.xref_missing"]

autosummary_generate = True
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_validation_checks: set = set()
numpydoc_xref_param_type = False



def _bars_are_text(app, what, name, obj, options, lines):
    """``|x|`` in a docstring is an absolute value, not a reST substitution: escaped, outside
    examples and tables."""
    for k, line in enumerate(lines):
        stripped = line.lstrip()
        if "|" in line and not stripped.startswith((">>>", "...", "|", "+")):
            lines[k] = line.replace("|", "\\|")


def setup(app):
    app.connect("autodoc-process-docstring", _bars_are_text)


html_theme = "alabaster"
html_title = f"lcvreport {release}"
html_static_path: list = []
# MathJax from the machine's Debian package would need a local path; the site names the CDN
# only as Sphinx's default: pages read offline show the TeX source of a formula
