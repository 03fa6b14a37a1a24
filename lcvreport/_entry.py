"""The ``lcv`` console script: one BLAS thread unless told otherwise (:mod:`lcvreport.util.threads`),
set before numpy is imported, then :func:`lcvreport.cli.main.main`."""
from __future__ import annotations


def main() -> None:
    from .util.interrupts import install
    install()                       # first: an interrupt during the imports is not lost
    from .util.threads import configure_entry_point
    configure_entry_point()
    from .cli.main import main as cli_main
    cli_main()
