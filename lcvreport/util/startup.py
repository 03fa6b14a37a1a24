"""What a command pays before and after its work (docs/studies.md#the-command-start-up), and
three things ``lcv`` does about it (:mod:`lcvreport.cli.start`); importing the package as a
library does none of them.

Measured on ``lcv assess`` of the B-double (0.55 s as a command, of which 0.37 s are
importing numpy and scipy and 0.06 s the interpreter's shutdown):

- **Two numpy subpackages nobody uses load late** (:func:`defer_numpy_subpackages`):
  scipy's copy of array-api-compat probes every public name of numpy with ``hasattr``, which
  imports ``numpy.testing`` and ``numpy.f2py`` (37 ms).  They are registered with the
  standard library's :class:`importlib.util.LazyLoader`: the probe finds a module, and its code
  runs at the first use of one of its names.
- **No garbage collection while the modules load** (:func:`collection_paused`): the imports
  allocate hundreds of thousands of objects that all live to the end, and the collector
  traverses them again and again; afterwards they are moved out of its reach
  (:func:`gc.freeze`).
- **No collection of the modules at exit** (:func:`settle_before_exit`): what the command
  dropped is collected (its finalizers run), then everything left is frozen, so that the
  interpreter's shutdown does not traverse scipy's object graph (62 ms -> 12 ms).

Examples
--------
>>> import gc
>>> with collection_paused():
...     gc.isenabled()
False
>>> gc.isenabled()
True
"""
from __future__ import annotations

import gc
import importlib.util
import sys
from contextlib import contextmanager

#: numpy's subpackages an ``lcv`` command does not use, which scipy's import probes
NUMPY_SUBPACKAGES_PROBED = ("numpy.testing", "numpy.f2py")


def defer_numpy_subpackages(names=NUMPY_SUBPACKAGES_PROBED) -> list[str]:
    """Register each of ``names`` (a subpackage of an imported package, not yet imported) as a
    lazily loaded module: importing it or finding it as an attribute of its parent is
    immediate, its code runs at the first access to one of its attributes.  Returns the names
    deferred (those already imported, or not found, are left alone).

    Examples
    --------
    >>> import json, sys
    >>> _ = defer_numpy_subpackages(("json.tool",))      # [] if json.tool was imported before
    >>> import json.tool
    >>> callable(json.tool.main)
    True
    """
    deferred = []
    for name in names:
        parent_name, _, child = name.rpartition(".")
        parent = sys.modules.get(parent_name)
        if name in sys.modules or parent is None:
            continue
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            continue
        spec.loader = importlib.util.LazyLoader(spec.loader)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
        setattr(parent, child, module)      # as the import system does: numpy.testing is found
        deferred.append(name)
    return deferred


@contextmanager
def collection_paused():
    """No automatic garbage collection inside; on leaving, the objects made so far are frozen
    (:func:`gc.freeze`: kept out of later collections) and collection resumes (if it was on)."""
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if was_enabled:
            gc.enable()


def settle_before_exit() -> None:
    """Collect what the command dropped (its finalizers run), then freeze what is left: the
    interpreter's shutdown then frees the modules without traversing them for cycles."""
    gc.collect()
    gc.freeze()
