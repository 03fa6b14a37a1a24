"""Module paths of 0.2.x that moved in 0.3.0 still import (CHANGELOG.md): ``import
lcvreport.analysis.measures`` gives a module whose names are looked up where they live now
(``lcvreport/data/moved.toml``, generated from the repository's history), with one
DeprecationWarning naming the new place.  Installed by ``lcvreport/__init__.py``; imports nothing
of the package until an old path is asked for.

Examples
--------
>>> import sys, warnings
>>> _ = sys.modules.pop("lcvreport.analysis.measures", None)       # imported before: no new warning
>>> with warnings.catch_warnings(record=True) as caught:
...     warnings.simplefilter("always")
...     from lcvreport.analysis.measures import measure_set
>>> measure_set.__module__, "lcvreport.measures.measure_set" in str(caught[0].message)
('lcvreport.measures.measure_set', True)
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings
from pathlib import Path

_TABLE: dict | None = None


def moved_modules() -> dict[str, dict[str, str]]:
    """old module path -> {name: the module that defines it now}."""
    global _TABLE
    if _TABLE is None:
        import tomllib
        with open(Path(__file__).with_name("data") / "moved.toml", "rb") as f:
            _TABLE = tomllib.load(f)["modules"]
    return _TABLE


class _MovedModule(types.ModuleType):
    def __getattr__(self, name: str):
        where = moved_modules()[self.__name__].get(name)
        if where is None:
            raise AttributeError(f"module {self.__name__!r} (moved in 0.3.0, CHANGELOG.md) has no attribute {name!r}")
        value = getattr(importlib.import_module(where), name)
        setattr(self, name, value)
        return value

    def __dir__(self):
        return sorted(moved_modules()[self.__name__])


class _Loader(importlib.abc.Loader):
    def create_module(self, spec):
        return _MovedModule(spec.name)

    def exec_module(self, module):
        table = moved_modules()[module.__name__]
        places = sorted(set(table.values()))
        module.__doc__ = f"Moved in lcvreport 0.3.0: its names live in {', '.join(places)} (CHANGELOG.md)."
        module.__all__ = sorted(table)
        warnings.warn(f"{module.__name__} moved in lcvreport 0.3.0: import its names from {', '.join(places)} "
                      "(or the top-level lcvreport; CHANGELOG.md)", DeprecationWarning, stacklevel=3)


class MovedFinder(importlib.abc.MetaPathFinder):
    """Finds the old module paths of :func:`moved_modules` (after every other finder)."""

    def find_spec(self, fullname, path=None, target=None):
        if not fullname.startswith("lcvreport.") or fullname not in moved_modules():
            return None
        return importlib.machinery.ModuleSpec(fullname, _Loader())


def install() -> None:
    """Append the finder to ``sys.meta_path`` once."""
    if not any(isinstance(f, MovedFinder) for f in sys.meta_path):
        sys.meta_path.append(MovedFinder())
