"""The package's version (the one place it is written beside ``pyproject.toml``; a test holds
them equal): what ``lcvreport.__version__``, ``lcv --version`` and every FMU's modelDescription.xml
say."""

__version__ = "0.3.0"
