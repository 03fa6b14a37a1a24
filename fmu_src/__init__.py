"""FMU sources, installed as package data ``lcvreport.fmu_src``: the pythonfmu slave
module (``LCV.py``, which imports :mod:`lcvreport.fmu.slave_fmi2`) and the C sources of the native FMU and of the pythonfmu FMU's loader
(``c/``).  Built by :mod:`lcvreport.fmu.build`."""
