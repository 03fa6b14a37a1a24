"""The start of ``lcv`` (the console script and ``python -m lcvreport.cli``): Ctrl-C and SIGTERM
recorded from the first moment (:mod:`lcvreport.util.interrupts`), one BLAS thread unless told
otherwise (:mod:`lcvreport.util.threads`, set before numpy is imported: this module imports
neither), then :func:`lcvreport.cli.main.main`.  An interruption while the command's modules load
ends it with the one line "lcv: interrupted" and status 130, not a traceback.  The start-up and
shutdown costs are cut as :mod:`lcvreport.util.startup` measures: numpy's unused subpackages
loaded lazily, no garbage collection while the modules load, none of the modules at exit."""
from __future__ import annotations


def main() -> None:
    """Start ``lcv``."""
    import sys

    from ..util.interrupts import install
    install()                       # first: an interrupt during the imports is not lost
    try:
        from ..util.threads import configure_entry_point
        configure_entry_point()
        from ..util.startup import collection_paused, defer_numpy_subpackages, settle_before_exit
        with collection_paused():
            import numpy  # noqa: F401  (its BLAS reads the thread count set above)
            defer_numpy_subpackages()
            from .main import main as cli_main
    except KeyboardInterrupt:       # while the command's modules load: the one line, no traceback
        print("lcv: interrupted", file=sys.stderr)
        raise SystemExit(130) from None
    try:
        cli_main()
    finally:
        settle_before_exit()
