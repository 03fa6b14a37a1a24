"""``python -m lcvreport.cli``: the ``lcv`` command (:func:`lcvreport.cli.start.main`)."""
from lcvreport.cli.start import main

main()
