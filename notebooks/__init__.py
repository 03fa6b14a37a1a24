"""The report notebooks, installed as package data ``lcvreport.notebooks``: one per
thesis chapter, the audit, and the assessment report of any vehicle.  Executed by
:mod:`lcvreport.report.build` with papermill."""
