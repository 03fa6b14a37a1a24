"""The FMI 2.0 Python FMU's slave: :class:`lcvreport.fmu.slave_core.SlaveCore` behind pythonfmu 0.7.

Loaded inside an FMU by the slave module ``fmu_src/LCV.py``.  What it computes is the
core's; this adapter registers the variables with pythonfmu, logs through pythonfmu's
logger and writes the modelDescription.xml (:mod:`lcvreport.fmu.description_fmi2`).
"""
import sys

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Status

from .description_fmi2 import model_description
from .slave_core import SlaveCore
from ..version import __version__

_CAUSALITY = {"parameter": Fmi2Causality.parameter, "input": Fmi2Causality.input, "output": Fmi2Causality.output}
_VARIABILITY = {"fixed": Fmi2Variability.fixed, "continuous": Fmi2Variability.continuous}


class LCV(SlaveCore, Fmi2Slave):
    """The FMI 2.0 slave: one vehicle (or the six presets) through the interface table."""

    author = "lcvreport"
    license = "MIT"
    version = __version__

    def __init__(self, **kwargs):
        Fmi2Slave.__init__(self, **kwargs)
        # pythonfmu 0.7.0 inserts the resources folder into sys.path on every instantiation:
        # keep one entry
        if self.resources and sys.path.count(self.resources) > 1:
            sys.path[:] = [self.resources] + [p for p in sys.path if p != self.resources]
        self._setup(self.resources)
        for v in self.itf.variables:  # value reference = registration order = table index
            kw = dict(causality=_CAUSALITY[v.causality], variability=_VARIABILITY[v.variability],
                      description=v.description)
            if v.causality == "output":
                kw["initial"] = Fmi2Initial.calculated
            var = (Integer if v.type == "Enumeration" else Real)(v.name, getter=lambda: 0, setter=lambda x: None,
                                                                 **kw)
            self.register_variable(var)
            assert var.value_reference == v.value_reference

    def _error(self, text):
        self.log(text, Fmi2Status.error, "logStatusError")

    def _warning(self, text):
        self.log(text, Fmi2Status.warning, "logStatusWarning")

    def to_xml(self, model_options=dict()):
        from xml.etree.ElementTree import fromstring
        return fromstring(model_description(self.itf, self.itf.model_name, native=False,
                                            generation_tool="lcvreport.fmu.build (pythonfmu 0.7.0)"))
