"""An interruption the interpreter swallowed still ends a command as interrupted
(:mod:`lcvreport.util.interrupts`).

Ctrl-C at the instant ``lcv report`` started once landed in a weakref callback of the import
machinery: Python printed "Exception ignored in ..." and dropped the KeyboardInterrupt, and the
report ran to the end and exited 0.  These tests put the interruption in a weakref callback on
purpose -- every time, not by timing -- and check what the command does afterwards."""
from __future__ import annotations

import subprocess
import sys
import textwrap

from conftest import ROOT

#: the interruption delivered inside a weakref callback, where Python cannot raise it
SWALLOW = textwrap.dedent("""
    import gc, signal, weakref

    class _Thing:
        pass

    def _callback(_ref):
        signal.raise_signal(signal.SIGINT)      # the handler runs here: KeyboardInterrupt, unraisable
        sum(range(10))                          # bytecode after the signal: the handler surely ran

    thing = _Thing()
    ref = weakref.ref(thing, _callback)
    del thing
    gc.collect()
""")


def _python(code: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=timeout)


def test_without_the_record_python_drops_the_interrupt():
    """The premise: with Python's own handler the interrupt is printed as ignored and the program
    runs on (if this ever fails, Python delivers it now and the module is no longer needed)."""
    p = _python(SWALLOW + "print('ran on')")
    assert p.returncode == 0 and p.stdout.strip() == "ran on", p
    assert "Exception ignored" in p.stderr and "KeyboardInterrupt" in p.stderr, p.stderr


def test_the_swallowed_interrupt_is_recorded_silently():
    p = _python("from lcvreport.util import interrupts\nprint(interrupts.install())\n" + SWALLOW
                + "print(interrupts.interrupted())\n"
                  "try:\n    interrupts.raise_if_interrupted()\nexcept KeyboardInterrupt:\n    print('raised')\n")
    assert p.returncode == 0 and p.stdout.split() == ["True", "True", "raised"], p
    assert p.stderr == "", p.stderr


def test_other_unraisable_exceptions_still_reach_the_hook_before():
    p = _python("from lcvreport.util import interrupts\ninterrupts.install()\n"
                "class A:\n    def __del__(self):\n        raise ValueError('from __del__')\n"
                "A()\nprint(interrupts.interrupted())\n")
    assert p.returncode == 0 and p.stdout.strip() == "False", p
    assert "ValueError: from __del__" in p.stderr, p.stderr


def _lcv_after_swallow(*args: str) -> subprocess.CompletedProcess:
    """``lcv ARGS`` through its console entry point, the interruption swallowed after the entry
    point installed its handlers (where a signal at the command's start lands)."""
    code = ("import sys\nfrom lcvreport.util import interrupts\ninterrupts.install()\n" + SWALLOW
            + f"sys.argv = ['lcv', *{list(args)!r}]\n"
              "from lcvreport.util.threads import configure_entry_point\nconfigure_entry_point()\n"
              "from lcvreport.cli.main import main\nmain()\n")
    return _python(code)


def test_a_command_that_swallowed_ctrl_c_ends_interrupted():
    p = _lcv_after_swallow("eig", "--preset", "tractor_semitrailer", "--speed-kph", "88")
    assert p.returncode == 130 and p.stderr.strip().splitlines() == ["lcv: interrupted"], p.stderr


def test_a_figure_is_not_linked_after_a_swallowed_ctrl_c(tmp_path):
    png = tmp_path / "turn.png"
    p = _lcv_after_swallow("turn", "--preset", "tractor_semitrailer", "--plot", str(png))
    assert p.returncode == 130 and p.stderr.strip().splitlines() == ["lcv: interrupted"], p.stderr
    assert not list(tmp_path.iterdir())


def test_a_report_that_swallowed_ctrl_c_ends_before_its_kernel(tmp_path):
    """The defect itself: the interruption was dropped where it landed; the report starts no kernel,
    ends with its one line and status 130, and leaves nothing."""
    out = tmp_path / "r"
    p = _lcv_after_swallow("report", "--preset", "tractor_semitrailer", "--no-pdf", "--out", str(out))
    assert p.returncode == 130, (p.returncode, p.stderr[-3000:])
    assert p.stderr.strip().splitlines() == ["lcv: interrupted"], p.stderr[-3000:]
    assert not list(tmp_path.iterdir())


def test_a_finished_report_is_not_published_after_a_swallowed_ctrl_c(tmp_path, monkeypatch):
    """The last safe point: a report finished while the record was set is discarded, not published."""
    import pytest

    from lcvreport.report.publish import folder_state, publish_staged
    from lcvreport.util import interrupts
    out = tmp_path / "r"
    staged = tmp_path / ".r.writing-1"
    staged.mkdir()
    (staged / "index.html").write_text("<p>finished</p>")
    before = folder_state(out)
    monkeypatch.setattr(interrupts, "_received", 2)
    with pytest.raises(KeyboardInterrupt):
        publish_staged(staged, out, before)
    assert not out.exists() and (staged / "index.html").exists()    # the caller discards the staging folder
    monkeypatch.setattr(interrupts, "_received", None)
    publish_staged(staged, out, before)                               # the same call, no interruption: published
    assert (out / "index.html").read_text() == "<p>finished</p>"


#: an interruption while the command's modules load: an import that raises KeyboardInterrupt
INTERRUPTED_IMPORT = textwrap.dedent("""
    import sys

    class _Interrupting:
        def find_spec(self, name, path=None, target=None):
            if name == "lcvreport.cli.main":
                raise KeyboardInterrupt
            return None

    sys.meta_path.insert(0, _Interrupting())
    sys.argv = ["lcv", "eig", "--preset", "tractor_semitrailer"]
""")


def test_ctrl_c_while_the_command_loads_is_one_line_not_a_traceback():
    for start in ("import runpy\nrunpy.run_module('lcvreport.cli', run_name='__main__')\n",
                  "from lcvreport._entry import main\nmain()\n"):
        p = _python(INTERRUPTED_IMPORT + start)
        assert p.returncode == 130 and p.stderr.strip().splitlines() == ["lcv: interrupted"], (start, p.stderr)
