"""The ``lcv`` command: one module per command group over the package."""
