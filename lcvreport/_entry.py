"""The ``lcv`` console script: :func:`lcvreport.cli.start.main` (Ctrl-C recorded from the first
moment, one BLAS thread before numpy is imported, then the command)."""
from __future__ import annotations


def main() -> None:
    from .cli.start import main as start
    start()
