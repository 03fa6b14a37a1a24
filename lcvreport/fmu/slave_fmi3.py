"""The FMI 3.0 Python FMU's slave: :class:`lcvreport.fmu.slave_core.SlaveCore` behind pythonfmu3.

Loaded inside an FMU by its slave module (written by :func:`lcvreport.fmu.build.build_python_fmu3`).
What it computes is the core's, the same as the FMI 2.0 Python FMU; this adapter maps the FMI 3.0
calls pythonfmu3 makes (``get_float64``, ``set_int64`` ...) onto the core's, logs through
pythonfmu3's log queue and writes the FMI 3.0 modelDescription.xml
(:func:`lcvreport.fmu.description_fmi3.model_description3`, Co-Simulation only).  The loader in
front of pythonfmu3 (``fmu_src/c/python/loader3.c``) checks every argument, keeps the state machine and
turns a call that logged an error into ``fmi3Error``.
"""
from pythonfmu3 import Fmi3Slave
from pythonfmu3.enums import Fmi3Status

from .description_fmi3 import model_description3
from .slave_core import SlaveCore
from ..version import __version__


class LCV3(SlaveCore, Fmi3Slave):
    """The FMI 3.0 slave: one vehicle (or the six presets) through the interface table."""

    FMI_PREFIX = "fmi3"
    FMI_FUNCTIONS = {"GetReal": "fmi3GetFloat64", "SetReal": "fmi3SetFloat64", "GetInteger": "fmi3GetInt64",
                     "SetInteger": "fmi3SetInt64", "GetFMUstate": "fmi3GetFMUState",
                     "SetFMUstate": "fmi3SetFMUState"}
    #: the model identifier (the FMU's file stem); the build writes it into the slave module
    MODEL_IDENTIFIER = "LCV3"

    def __init__(self, **kwargs):
        Fmi3Slave.__init__(self, **kwargs)
        self._setup(self.resources)
        self.modelName = self.MODEL_IDENTIFIER
        self.author, self.license, self.version = "lcvreport", "MIT", __version__

    def _error(self, text):
        self.log(text, Fmi3Status.error, "logStatusError")

    def _warning(self, text):
        self.log(text, Fmi3Status.warning, "logStatusWarning")

    # FMI 3.0 names of the core's calls
    def get_float64(self, vrs):
        return self.get_real(vrs)

    def set_float64(self, vrs, values):
        self.set_real(vrs, values)

    def get_int64(self, vrs):
        return self.get_integer(vrs)

    def set_int64(self, vrs, values):
        self.set_integer(vrs, values)

    def setup_experiment(self, start_time):
        pass

    def to_xml(self, model_options=dict()):
        from xml.etree.ElementTree import fromstring
        return fromstring(model_description3(self.itf, self.MODEL_IDENTIFIER, native=False,
                                             generation_tool="lcvreport.fmu.build (pythonfmu3 0.3.4)"))
