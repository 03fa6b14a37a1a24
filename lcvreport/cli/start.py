"""The start of ``lcv`` (the console script and ``python -m lcvreport.cli``): Ctrl-C and SIGTERM
recorded from the first moment (:mod:`lcvreport.util.interrupts`), one BLAS thread unless told
otherwise (:mod:`lcvreport.util.threads`, set before numpy is imported: this module imports
neither), then :func:`lcvreport.cli.main.main`.  An interruption while the command's modules load
ends it with the one line "lcv: interrupted" and status 130, not a traceback."""
from __future__ import annotations


def main() -> None:
    """Start ``lcv``."""
    import sys

    from ..util.interrupts import install
    install()                       # first: an interrupt during the imports is not lost
    try:
        from ..util.threads import configure_entry_point
        configure_entry_point()
        from .main import main as cli_main
    except KeyboardInterrupt:       # while the command's modules load: the one line, no traceback
        print("lcv: interrupted", file=sys.stderr)
        raise SystemExit(130) from None
    cli_main()
