"""Ctrl-C and SIGTERM that the interpreter could not deliver still end a command as interrupted.

Python raises ``KeyboardInterrupt`` where the main thread happens to be when the signal's handler
runs.  Where that is a weakref callback or a ``__del__`` (the import machinery's module locks are
weakref callbacks, so any ``import`` can be the place), the exception cannot propagate: the
interpreter prints "Exception ignored in ..." and drops it, and the command would run on to the
end and report success.  At an entry point (``lcv``, ``python -m lcvreport.cli``) :func:`install`
therefore

* makes SIGINT and SIGTERM *record* the signal before raising ``KeyboardInterrupt``, and
* routes an exception the interpreter could not raise (:data:`sys.unraisablehook`) that is a
  ``KeyboardInterrupt`` to the record, silently (the command's one line, "lcv: interrupted",
  says it); every other unraisable exception goes to the hook there was before.

The command looks at the record at its safe points -- :func:`raise_if_interrupted` before a report
is published, before a file is linked into place, and when the command returns -- so a swallowed
interrupt ends it as any other: status 130, one line, nothing half-published.  A library caller
who did not call :func:`install` sees no change (nothing is recorded, the check passes).

Examples
--------
>>> import signal
>>> clear()
>>> interrupted()
False
>>> try:
...     on_signal(signal.SIGINT, None)
... except KeyboardInterrupt:
...     pass
>>> interrupted()
True
>>> clear(); interrupted()
False
"""
from __future__ import annotations

import sys
import threading

#: the signal number of the first interruption received since :func:`install` or :func:`clear`
_received: int | None = None
_previous_unraisablehook = None


def on_signal(signum, _frame):
    """The handler of SIGINT and SIGTERM: the signal recorded, then ``KeyboardInterrupt``."""
    global _received
    if _received is None:
        _received = int(signum)
    raise KeyboardInterrupt


def _unraisable(info) -> None:
    """``sys.unraisablehook``: a KeyboardInterrupt the interpreter could not raise is recorded."""
    global _received
    if info.exc_type is not None and issubclass(info.exc_type, KeyboardInterrupt):
        if _received is None:
            import signal
            _received = int(signal.SIGINT)
        return
    (_previous_unraisablehook or sys.__unraisablehook__)(info)


def install() -> bool:
    """At an entry point, first thing: SIGINT and SIGTERM record and raise ``KeyboardInterrupt``;
    a swallowed ``KeyboardInterrupt`` is recorded.  Returns False (and changes nothing) outside
    the main thread, where no signal handler can be set."""
    global _previous_unraisablehook
    import signal
    if threading.current_thread() is not threading.main_thread():
        return False
    clear()
    for num in (signal.SIGINT, signal.SIGTERM):
        signal.signal(num, on_signal)
    if sys.unraisablehook is not _unraisable:
        _previous_unraisablehook = sys.unraisablehook
        sys.unraisablehook = _unraisable
    return True


def interrupted() -> bool:
    """Whether an interruption was received since :func:`install` (or :func:`clear`), raised or not."""
    return _received is not None


def raise_if_interrupted() -> None:
    """``KeyboardInterrupt`` if an interruption was received -- at a safe point, before something
    is published that an interrupted command must not leave behind."""
    if _received is not None:
        raise KeyboardInterrupt


def clear() -> None:
    """Forget a received interruption (a new command in the same process)."""
    global _received
    _received = None
