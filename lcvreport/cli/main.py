"""The ``lcv`` command: eigenvalues, matrices, steady state, time response, measures,
FMUs and reports of a preset or of a vehicle file.

Fixed contract (other parts and outside checks call these forms)::

    lcv eig      (--preset NAME | --vehicle FILE) (--speed-kph V | --speed-mph V) [--tire-scale S] --json
    lcv matrices (...) [--load UNITS --convention C] [--units thesis|si] --json
    lcv steady   (...) --load UNITS [--convention C] --json
    lcv simulate (...) --load UNITS [--t-end T] [--dt H] [--json]
    lcv measures (...) [--load UNITS] --json
    lcv fmu      (--preset NAME | --vehicle FILE) --out DIR [--kind python|native|both] [--fmi 2|3]
    lcv report   (--preset NAME | --vehicle FILE) [--speed-kph V] [--load UNITS] --out DIR
    lcv study    STUDY.toml --out DIR [--workers N | --scheduler ADDRESS] [--csv] [--scheme F] [--report R [--criteria F]]
    lcv assess   (--preset NAME | --vehicle FILE) --scheme SCHEME.toml [--json] [--out DIR]
    lcv presets  [--json]

``UNITS`` is a comma list of unit names of the vehicle; each gets the 1 % rule on its
axles (P along +y, T = 0.3048 m * P about +z).  ``--convention`` is ``consistent``
(default) or ``thesis`` (docs/thesis.md, erratum 1).  JSON units: eigenvalues [1/s]; matrices in
thesis units (lbf, in, s) for presets and SI for vehicle files unless ``--units`` says
otherwise; everything else SI.  Every number is checked against
:data:`lcvreport.ranges.RANGES`.  A bad argument exits with status 2 and one line naming
it and what is valid; an output that cannot be written exits 1 with one line; a
closed pipe (``lcv ... | head``) ends quietly with status 141, as SIGPIPE does for
other Unix tools.  No output is ever non-finite.
"""
from __future__ import annotations

import argparse
import errno
import os
import sys
from typing import Sequence


from ..ranges import RangeError
from .options import Parser, UsageError, one_line
from .output import OutputError, Output


#: exit status of a closed pipe (128 + SIGPIPE), as a shell reports a tool SIGPIPE ended
EXIT_BROKEN_PIPE = 141


#: exit status after Ctrl-C (128 + SIGINT), as a shell reports it
EXIT_INTERRUPTED = 130


#: the commands in the order of ``lcv --help``; each module lists its own (:class:`~.options.Command`:
#: help, options, run)
ORDER = ("eig", "matrices", "steady", "simulate", "measures", "fmu", "report", "tracking", "turn", "study", "assess",
         "roll", "presets")


def _commands() -> dict:
    from . import artifacts, assess, measures, model, roll, simulate, tracking, turn
    table = {}
    for module in (model, simulate, measures, artifacts, tracking, turn, assess, roll):
        table.update(module.COMMANDS)
    assert set(table) == set(ORDER), sorted(set(table) ^ set(ORDER))
    return {name: table[name] for name in ORDER}


#: command -> the function that runs it (``run(args, out) -> exit status``)
COMMANDS = {name: command.run for name, command in _commands().items()}


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``lcv``: each command's options from its module."""
    from ..version import __version__        # (not importlib.metadata: 8 ms of every command's start)
    p = Parser(prog="lcv", description="Linear yaw-plane and yaw-roll models of long combination vehicles.")
    p.add_argument("--version", action="version", version=f"lcv (lcvreport) {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True
    for name, command in _commands().items():
        command.options(sub.add_parser(name, help=command.help))
    return p


def run(argv: Sequence[str] | None = None, out=None) -> int:
    """Run ``lcv`` with ``argv``; return the exit status.  Output goes to ``out`` (stdout)."""
    import signal
    import threading

    from ..util import interrupts
    stream = out if out is not None else sys.stdout
    previous = None
    try:
        args = build_parser().parse_args(argv)
        writer = Output(stream)
        if threading.current_thread() is threading.main_thread():
            # a batch system's SIGTERM (a time limit) ends any command as Ctrl-C does: what it was
            # writing aside is removed, nothing half-written is left
            previous = signal.signal(signal.SIGTERM, _terminated)
        status = COMMANDS[args.command](args, writer)
        stream.flush()
        # an interruption the interpreter swallowed (it landed in a weakref callback): the command
        # checked it before publishing anything; it ends as any other interruption
        interrupts.raise_if_interrupted()
        return status
    except KeyboardInterrupt:
        interrupts.clear()
        print("lcv: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except UsageError as exc:
        print(f"lcv: error: {one_line(exc)}", file=sys.stderr)
        return 2
    except (RangeError, KeyError) as exc:
        print(f"lcv: error: {one_line(exc.args[0] if exc.args else exc)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    except OutputError as exc:
        print(f"lcv: error: {one_line(exc)}", file=sys.stderr)
        return 1
    except OSError as exc:
        if exc.errno == errno.EPIPE:
            _silence_stdout()
            return EXIT_BROKEN_PIPE
        print(f"lcv: error: cannot write the output: {one_line(exc.strerror or exc)}", file=sys.stderr)
        _silence_stdout()
        return 1
    except FloatingPointError as exc:
        print(f"lcv: error: {one_line(exc)}", file=sys.stderr)
        return 1
    except Exception as exc:  # noqa: BLE001 - one line, never a traceback
        print(f"lcv: internal error: {type(exc).__name__}: {one_line(exc)} (please report this)", file=sys.stderr)
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _terminated(signum, frame):
    from ..util.interrupts import on_signal
    on_signal(signum, frame)


def _silence_stdout() -> None:
    """Point fd 1 at /dev/null so that the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)
    except OSError:  # pragma: no cover
        pass


def main() -> None:
    """Console entry point."""
    status = run()
    if status == EXIT_INTERRUPTED:
        # leave at once: what Ctrl-C cut short (a notebook kernel's event loop) would
        # otherwise print its own tracebacks while the interpreter shuts down
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(status)
    sys.exit(status)

