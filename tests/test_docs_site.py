"""The documentation site (issue 44): ``./build.sh docs``'s Sphinx build with warnings as errors,
its API reference listing every name of ``lcvreport.__all__``, its search finding the measures'
page; the public names' docstrings; the old module paths of 0.2.x importing with a warning."""
from __future__ import annotations

import inspect
import json
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import lcvreport

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("docs")
    p = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "-d",
                        str(out / ".doctrees"), str(ROOT / "docs"), str(out / "html")],
                       capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, (p.stdout + p.stderr)[-4000:]
    assert not p.stderr.strip(), p.stderr[-4000:]                     # no warning at all
    return out / "html"


def test_the_api_reference_lists_every_public_name(site):
    listed = re.findall(r"^   (\w+)$", (ROOT / "docs" / "api.rst").read_text(encoding="utf-8"), re.M)
    assert sorted(listed) == sorted(lcvreport.__all__)
    for name in lcvreport.__all__:
        assert (site / "generated" / f"lcvreport.{name}.html").exists(), name


def _search_index(site: Path) -> dict:
    text = (site / "searchindex.js").read_text(encoding="utf-8")
    return json.loads(text[text.index("(") + 1:text.rindex(")")])


def _stem(word: str) -> str:
    """The search index's term of ``word`` (Sphinx's English search stems with snowball's porter)."""
    import snowballstemmer
    return snowballstemmer.stemmer("porter").stemWord(word.lower())


@pytest.mark.parametrize("words", ["friction demand", "static rollover threshold"])
def test_a_search_finds_the_measures_page(site, words):
    index = _search_index(site)
    docs = index["docnames"]
    hits = None
    for word in words.split():
        stem = _stem(word)
        found = set()
        for table in ("terms", "titleterms"):                   # words of a section title: titleterms
            got = index[table].get(stem, [])
            found |= {got} if isinstance(got, int) else set(got)
        hits = found if hits is None else hits & found
    assert docs.index("measures") in hits, [docs[k] for k in hits]


def test_every_new_public_function_has_a_numpydoc_docstring():
    """Parameters, Returns and an example on every function of the API this release added
    (the 0.2.0 names: docs/index.md#what-is-public lists those whose sections are still owed)."""
    for name in NEW_IN_0_3:
        doc = inspect.getdoc(getattr(lcvreport, name)) or ""
        for section in ("Parameters", "Returns", "Examples"):
            assert f"\n{section}\n---" in f"\n{doc}", (name, section)


NEW_IN_0_3 = ("assess", "load_scheme", "loads_scheme", "roll", "low_speed_turn", "turn_with_tire_forces",
              "tracking_stats", "place_tires", "build_fmus", "build_report", "build_model", "respond", "integrate",
              "nonlinear_model")


def test_a_module_path_of_0_2_still_imports_with_a_warning_naming_the_new_place():
    code = ("import warnings; warnings.simplefilter('error', DeprecationWarning)\n"
            "try:\n    import lcvreport.analysis.low_speed_turn\nexcept DeprecationWarning as w:\n    print(w)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert "lcvreport.measures.low_speed" in p.stdout, p.stdout + p.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        from lcvreport.analysis.low_speed_turn import low_speed_turn
        from lcvreport.analysis.measures import measure_set
    assert low_speed_turn is lcvreport.low_speed_turn and measure_set is lcvreport.measure_set


def _sections_owed(obj) -> list[str]:
    doc = "\n" + (inspect.getdoc(obj) or "")
    if inspect.isclass(obj):
        wanted = (("Attributes", "Parameters"), ("Examples",))
    else:
        wanted = (("Parameters",), ("Returns",), ("Examples",)) + ((("Raises",),) if _raises(obj) else ())
    return [alts[0] for alts in wanted if not any(f"\n{a}\n---" in doc for a in alts)]


def _raises(function) -> bool:
    """Whether ``function``'s own body has a ``raise`` statement (what it raises itself: numpydoc's
    Raises section is owed)."""
    import ast
    import textwrap
    return any(isinstance(node, ast.Raise) for node in ast.walk(ast.parse(textwrap.dedent(inspect.getsource(function)))))


def test_every_public_name_has_a_numpydoc_docstring():
    """Every function of ``__all__``: Parameters, Returns, an example, and Raises where it raises
    itself; every class: its
    Attributes (or Parameters) and an example.  The constant ``PRESETS`` and the modules
    ``ranges`` and ``units`` have their own module docstrings."""
    owed = {}
    for name in lcvreport.__all__:
        obj = getattr(lcvreport, name)
        if not (inspect.isclass(obj) or callable(obj)):
            continue
        missing = _sections_owed(getattr(obj, "__wrapped__", obj))
        if missing:
            owed[name] = missing
    assert not owed, owed
