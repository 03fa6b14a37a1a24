"""FMU sources, installed as package data ``lcvreport.fmu_src``: the pythonfmu slave
(``LCV.py``) and the C sources of the native FMU and of the pythonfmu FMU's loader
(``c/``).  Built by :mod:`lcvreport.fmu.build`."""
