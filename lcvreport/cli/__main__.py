"""``python -m lcvreport.cli``: one BLAS thread before numpy loads, then the command."""
from lcvreport.util.interrupts import install

install()                           # first: an interrupt during the imports is not lost

from lcvreport.util.threads import configure_entry_point  # noqa: E402

configure_entry_point()

from lcvreport.cli.main import main  # noqa: E402

main()
