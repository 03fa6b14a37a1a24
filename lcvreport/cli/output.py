"""The command's output: a stream that refuses non-finite numbers and turns a closed pipe
into status 141, and figures written aside and then linked into place (never overwriting).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .options import UsageError


class OutputError(Exception):
    """The output cannot be written or would not be finite (exit 1)."""


# ---------------------------------------------------------------------------- output
class Output:
    """Writes to a stream; turns write failures into :class:`OutputError` and refuses
    non-finite numbers."""

    def __init__(self, stream):
        if stream is None:
            raise OutputError("standard output is closed; nothing can be written")
        self.stream = stream

    def write(self, text: str) -> None:
        self.stream.write(text)

    def line(self, text: str = "") -> None:
        self.stream.write(text + "\n")

    def flush(self) -> None:
        self.stream.flush()

    def json(self, doc) -> None:
        try:
            text = json.dumps(doc, allow_nan=False)
        except ValueError:
            raise OutputError("the result is not finite (a number is inf or NaN); nothing was written") from None
        self.line(text)


def check_finite(*arrays) -> None:
    for a in arrays:
        if a is not None and not np.all(np.isfinite(np.asarray(a, dtype=complex))):
            raise OutputError("the result is not finite (a number is inf or NaN); nothing was written")


def write_figure_new(fig, path: Path) -> None:
    """Save a figure to a new file: written aside, then linked into place (never over a file)."""
    import os
    import tempfile

    from ..util.interrupts import raise_if_interrupted
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    umask = os.umask(0)
    os.umask(umask)
    os.fchmod(fd, 0o666 & ~umask)                  # as open() would create it (mkstemp makes 0600)
    os.close(fd)
    try:
        fig.savefig(tmp, dpi=150)
        raise_if_interrupted()     # an interruption the interpreter swallowed: nothing is linked
        try:
            os.link(tmp, path)
        except FileExistsError:
            raise UsageError(f"argument --plot: {path} appeared while it was drawn; nothing was overwritten") \
                from None
        except OSError as exc:
            raise OutputError(f"cannot write {path}: {exc.strerror}") from None
    finally:
        os.unlink(tmp)
