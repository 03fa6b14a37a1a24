"""The command's start-up and shutdown (lcvreport.util.startup, docs/studies.md#the-command-start-up):
numpy's unused subpackages load late and still work when used, a command's dropped objects are
finalized before it exits, and `lcv assess` runs none of numpy.f2py's or numpy.testing's code.
Each check runs in a fresh interpreter (the suite's own has imported everything)."""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def python(code: str, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, *args, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, env={**os.environ, "PYTHONWARNINGS": "error"})


def test_a_deferred_subpackage_runs_no_code_until_used_and_then_works():
    p = python("""
        import sys, numpy
        from lcvreport.util.startup import defer_numpy_subpackages
        assert defer_numpy_subpackages() == ["numpy.testing", "numpy.f2py"]
        import scipy.linalg, scipy.integrate             # scipy's probe of numpy's names finds them
        assert numpy.testing is sys.modules["numpy.testing"]
        assert "numpy.testing._private.utils" not in sys.modules and "numpy.f2py.crackfortran" not in sys.modules
        from numpy.testing import assert_allclose
        assert_allclose(numpy.array([1.0]), numpy.array([1.0 + 1e-12]))
        import numpy.testing._private.utils as u
        assert u.assert_allclose is assert_allclose
        import numpy.f2py
        assert numpy.f2py.get_include().endswith("src")
        assert defer_numpy_subpackages() == []           # loaded: nothing to defer
        print("ok")
    """)
    assert p.returncode == 0 and p.stdout.split() == ["ok"], p.stderr


def test_nothing_is_deferred_before_numpy_is_imported():
    p = python("""
        import sys
        from lcvreport.util.startup import defer_numpy_subpackages
        assert defer_numpy_subpackages() == [] and "numpy.testing" not in sys.modules
        print("ok")
    """)
    assert p.returncode == 0 and p.stdout.split() == ["ok"], p.stderr


def test_the_commands_dropped_cycles_are_finalized_before_exit():
    """settle_before_exit collects before it freezes: a finalizer of the command's garbage runs."""
    p = python("""
        import gc, sys
        from lcvreport.util.startup import collection_paused, settle_before_exit
        with collection_paused():
            import numpy
        assert gc.isenabled()
        gc.disable()                                     # no collection but settle_before_exit's own
        class Node:
            def __del__(self):
                sys.stdout.write("finalized\\n"); sys.stdout.flush()
        a = Node(); a.self = a
        del a
        settle_before_exit()
        print("settled")
    """)
    assert p.returncode == 0 and p.stdout.split() == ["finalized", "settled"], (p.stdout, p.stderr)


def test_lcv_assess_runs_none_of_the_deferred_subpackages_code():
    p = subprocess.run([sys.executable, "-X", "importtime", "-m", "lcvreport.cli", "assess", "--vehicle",
                        "examples/vehicles/b_double.toml", "--scheme", "examples/schemes/template.toml", "--json"],
                       capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert p.returncode == 0, p.stderr[-2000:]
    imported = {line.rsplit("|", 1)[-1].strip() for line in p.stderr.splitlines() if line.startswith("import time:")}
    assert {"scipy.integrate", "scipy.linalg"} <= imported                  # the check sees the imports
    assert not {m for m in imported if m.startswith(("numpy.f2py.", "numpy.testing."))}, sorted(imported)
