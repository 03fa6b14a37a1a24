"""The package's shape: the folders are layers that import only downward, the package
map in ``lcvreport/__init__.py`` names every module, the FMU runtime stays numpy-only,
the C sources and notebooks are package data, and facts have one source."""
from __future__ import annotations

import ast
import subprocess
import sys
from importlib import resources
from pathlib import Path

import pytest

import lcvreport

PACKAGE = Path(lcvreport.__file__).resolve().parent
#: the layers, lowest first: a module may import its own folder and the ones before it
LAYERS = ["_moved", "version", "units", "ranges", "util", "model", "manoeuvres", "plotting", "analysis", "measures", "tracking", "thesis",
          "fmu", "study", "report", "cli", "_entry"]
#: imports of a higher layer allowed inside a function only (never at import time): none.  A
#: result that plots itself imports ``plotting`` downward, inside its ``.plot()``.
LAZY_UPWARD: set = set()


def _modules() -> dict[str, Path]:
    out = {}
    for p in sorted(PACKAGE.rglob("*.py")):
        rel = p.relative_to(PACKAGE).with_suffix("")
        parts = [x for x in rel.parts if x != "__init__"]
        out[".".join(parts)] = p
    return out


def _imports(path: Path, module: str) -> list[tuple[str, bool]]:
    """(imported lcvreport module relative to the package, inside a function?)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = module.split(".") if path.name == "__init__.py" else module.split(".")[:-1]
    out = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            nested = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
            if isinstance(child, ast.If) and ast.unparse(child.test) in ("TYPE_CHECKING", "typing.TYPE_CHECKING"):
                continue                           # annotations only: never imported at run time
            if isinstance(child, ast.ImportFrom):
                if child.level:
                    base = package[:len(package) - child.level + 1]
                    target = ".".join(base + ([child.module] if child.module else []))
                elif (child.module or "").startswith("lcvreport"):
                    target = child.module[len("lcvreport."):]
                else:
                    target = None
                if target is not None:
                    if child.module is None:       # from . import x, y
                        out.extend((f"{target}.{a.name}".strip("."), nested) for a in child.names)
                    else:
                        out.append((target, nested))
            elif isinstance(child, ast.Import):
                out.extend((a.name[len("lcvreport."):], nested) for a in child.names
                           if a.name.startswith("lcvreport."))
            visit(child, nested)

    visit(tree, False)
    return out


def _layer(module: str) -> str:
    return module.split(".")[0] if module else ""


MODULES = _modules()


def test_every_module_belongs_to_a_layer():
    assert {_layer(m) for m in MODULES if m} <= set(LAYERS), sorted({_layer(m) for m in MODULES} - set(LAYERS))


def test_layers_import_only_downward():
    wrong, lazy = [], set()
    for module, path in MODULES.items():
        if not module:
            continue
        mine = LAYERS.index(_layer(module))
        for target, in_function in _imports(path, module):
            if not target or LAYERS.index(_layer(target)) <= mine:
                continue
            pair = (module, target)
            if in_function and pair in LAZY_UPWARD:
                lazy.add(pair)
            else:
                wrong.append((module, target, "in a function" if in_function else "at import"))
    assert not wrong, wrong
    assert lazy == LAZY_UPWARD          # the allowance is used, not stale


def test_nothing_imports_the_cli():
    users = [m for m, p in MODULES.items() if _layer(m) != "cli" and any(_layer(t) == "cli" for t, _ in _imports(p, m))]
    assert users in ([], ["_entry"])          # the console script only (threads first, then the cli)


def test_the_package_map_names_every_module():
    doc = lcvreport.__doc__
    missing = [m for m in MODULES if m and f"``{m.split('.')[-1]}``" not in doc and f"``{m.split('.')[-1]}/``" not in doc]
    assert not missing, f"not in the map of lcvreport/__init__.py: {missing}"
    for folder in ("util", "model", "manoeuvres", "plotting", "analysis", "measures", "tracking", "thesis", "fmu",
                   "study", "report", "cli"):
        assert f"``{folder}/``" in doc


def test_the_package_and_the_fmu_runtime_load_numpy_only():
    """``import lcvreport`` and the FMU engine stepping a vehicle never load scipy,
    matplotlib or python-control (the embedded interpreter of LCV.fmu stays light)."""
    code = """
import sys
import lcvreport
from lcvreport.fmu.engine import LCVEngine
from lcvreport.fmu.interface import preset_interface, vehicle_interface
e = LCVEngine(preset_interface(), preset="aucnat")
w = e.start_inputs(); w[e.input_index["P61"]] = 1000.0
for _ in range(5):
    assert e.step(0.01, w) is None
e.outputs(w); e.max_real_eig(22.0)
v = lcvreport.load_vehicle(sys.argv[1])
e2 = LCVEngine(vehicle_interface(v)); e2.step(0.01, e2.start_inputs())
heavy = sorted(m for m in sys.modules if m.split(".")[0] in ("scipy", "matplotlib", "control", "pandas"))
print(",".join(heavy))
"""
    vehicle = PACKAGE.parent / "examples" / "vehicles" / "western_double.toml"
    p = subprocess.run([sys.executable, "-c", code, str(vehicle)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "", p.stdout


from lcvreport.fmu import c_tree  # noqa: E402

#: every file of the C tree the builds use
C_TREE_FILES = sorted({p for k, v in vars(c_tree).items() if k.isupper()
                       for group in (v.values() if isinstance(v, dict) else [v]) for p in group if "." in p})


@pytest.mark.parametrize("package, names", [
    ("lcvreport.fmu_src", ["LCV.py"] + [f"c/{p}" for p in C_TREE_FILES]),
    ("lcvreport.notebooks", [f"{s}.ipynb" for s in ("ch1_2_concepts", "ch3_tractor_semitrailer", "ch4_triple",
                                                    "ch5_parametric", "ch6_tracking", "appendices", "audit",
                                                    "assessment")]),
    ("lcvreport.data", ["vehicles/aucnat.toml", "thesis/published.toml"]),
])
def test_build_inputs_are_package_data(package, names):
    """The FMU sources and the notebooks are found through the installed package,
    not through the location of a checkout, and pyproject's package-data globs take them (an
    editable install finds them in the checkout whatever the globs say)."""
    import fnmatch
    import tomllib
    root = resources.files(package)
    globs = tomllib.loads((PACKAGE.parent / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]
    for name in names:
        assert root.joinpath(name).is_file(), f"{package}/{name}"
        own = globs.get(package, []) if package != "lcvreport.data" else globs["lcvreport"]
        prefix = "data/" if package == "lcvreport.data" else ""
        assert any(fnmatch.fnmatchcase(prefix + name, g) for g in own), f"{package}/{name} is not package data"


def test_one_source_for_joint_letters_and_ranges():
    """No module spells out the joint letters or a hard-coded speed limit of its own."""
    offenders = []
    for module, path in MODULES.items():
        text = path.read_text(encoding="utf-8")
        for literal in ('"ABCDE', "'ABCDE", "JOINT_LETTERS", "LOADABLE_UNITS"):
            if literal in text:
                offenders.append((module, literal))
    assert not offenders, offenders


def _graph() -> dict[str, set[str]]:
    """module -> the package modules it imports (at import time or inside a function)."""
    graph = {}
    for module, path in MODULES.items():
        if not module:
            continue
        targets = set()
        for target, _nested in _imports(path, module):
            while target and target not in MODULES:
                target = target.rpartition(".")[0]       # ``from .x import name``: the module x
            if target and target != module:
                targets.add(target)
        graph[module] = targets
    return graph


def test_no_import_cycle():
    """No module reaches itself through imports, lazy ones included (Tarjan's strongly connected
    components: every one of size 1)."""
    graph = _graph()
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    assert not cycles, cycles


def test_no_two_folders_import_each_other():
    graph = _graph()
    edges = {(_layer(m), _layer(t)) for m, ts in graph.items() for t in ts if _layer(m) != _layer(t)}
    pairs = sorted({tuple(sorted(e)) for e in edges if (e[1], e[0]) in edges})
    assert not pairs, pairs


def test_the_upward_allowance_is_empty():
    assert LAZY_UPWARD == set()


def test_no_module_is_longer_than_700_lines():
    long = {m: n for m, p in MODULES.items() if (n := len(p.read_text(encoding="utf-8").splitlines())) > 700}
    assert not long, long


def test_the_cycle_check_finds_a_cycle(tmp_path):
    """The check itself: two modules that import each other lazily are a cycle."""
    global MODULES
    saved = MODULES
    (tmp_path / "a.py").write_text("def f():\n    from .b import g\n")
    (tmp_path / "b.py").write_text("def g():\n    from .a import f\n")
    try:
        MODULES = {"analysis.a": tmp_path / "a.py", "analysis.b": tmp_path / "b.py"}
        with pytest.raises(AssertionError):
            test_no_import_cycle()
    finally:
        MODULES = saved


def test_the_code_cites_pages_a_reader_has():
    """The package cites ``docs/`` pages (and their sections) instead of a specification or
    issue numbers a reader of the repository does not have; every page and section it names
    exists."""
    import re
    docs = PACKAGE.parent / "docs"

    def anchors(page):
        return {re.sub(r"[^a-z0-9 -]", "", line.lstrip("#").strip().lower()).replace(" ", "-")
                for line in (docs / page).read_text(encoding="utf-8").splitlines() if line.startswith("#")}

    bad = []
    for module, path in MODULES.items():
        text = path.read_text(encoding="utf-8")
        if re.search(r"SPEC (section|erratum|sections|\d)|\bissue #?\d+", text):
            bad.append((module, "cites the specification or an issue"))
        for page, anchor in re.findall(r"docs/([a-z_]+\.md)(?:#([a-z0-9-]+))?", text):
            if not (docs / page).exists():
                bad.append((module, page))
            elif anchor and anchor not in anchors(page):
                bad.append((module, f"{page}#{anchor}"))
    assert not bad, bad


def test_the_c_tree_has_the_fmi_api_once_per_version():
    """As Reference-FMUs has it: the FMI functions are defined in api/ (once per version, over any
    model) and in the Python FMUs' loaders (python/), nowhere else; the models (vehicle/, driver/)
    are FMI-neutral -- no FMI header, type or function name in their code."""
    import re
    c = PACKAGE.parent / "fmu_src" / "c"
    definition = re.compile(r"^[A-Za-z0-9_ *]*\b(fmi[23][A-Z]\w*)\s*\(", re.M)
    defined = {}
    for path in sorted(c.rglob("*.c")):
        for name in definition.findall(path.read_text()):
            defined.setdefault(name, []).append(path.relative_to(c).parts[0])
    assert defined, "no FMI function found: the pattern is wrong"
    assert {folder for folders in defined.values() for folder in folders} == {"api", "python"}
    api = {name: [f for f in folders if f == "api"] for name, folders in defined.items()}
    assert all(len(f) <= 1 for f in api.values()), {n: f for n, f in api.items() if len(f) > 1}
    for folder in ("vehicle", "driver"):
        for path in (c / folder).iterdir():
            code = re.sub(r"/\*.*?\*/", "", path.read_text(), flags=re.S)       # comments may name the API
            assert not re.search(r"fmi[23]", code), f"{path.relative_to(c)} is not FMI-neutral"


def test_no_module_imports_another_modules_private_name():
    """A name that starts with ``_`` is its module's own (issue 41: 106 such imports, 63 in cli/);
    what another module needs is public in its module.  The package imports its own ``_moved``."""
    wrong = []
    for module, path in MODULES.items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom) or node.module == "__future__":
                continue
            if node.level == 0 and not (node.module or "").startswith("lcvreport"):
                continue
            wrong += [(module, node.module, a.name) for a in node.names
                      if a.name.startswith("_") and not a.name.startswith("__") and (module, a.name) != ("", "_moved")]
    assert not wrong, wrong
