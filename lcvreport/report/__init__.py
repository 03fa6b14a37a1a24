"""The reports: figures, tables with captions and CSV, and the papermill + nbconvert
orchestration of the thesis report and of the assessment report of any vehicle."""
