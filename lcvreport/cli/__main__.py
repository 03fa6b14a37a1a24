"""``python -m lcvreport.cli``: one BLAS thread before numpy loads, then the command."""
from lcvreport.util.threads import configure_entry_point

configure_entry_point()

from lcvreport.cli.main import main  # noqa: E402

main()
