"""The slave module pythonfmu loads from the FMU's resources (as ``lcv_slave_<hash>.py``: each
FMU's module has a name of its own, since pythonfmu 0.7.0 imports it by name and takes the
class from ``sys.modules`` -- a second FMU under the same name ran the first one's class): the class is
:class:`lcvreport.fmu.slave_fmi2.LCV` of the package bundled next to this file, under a name of
its own (``lcvreport_fmu_<hash>``, written in by the build where ``lcvreport`` stands
below), so a Python host that has imported another ``lcvreport`` -- another version, an
editable checkout -- neither runs it nor is disturbed by it.

pythonfmu 0.7.0 (``findClass`` in its PySlaveInstance.cpp) executes this file again on
every fmi2Instantiate to find the class, and each time (a) keeps every class the file
defines alive (the MRO list it builds is never released: 46 KB per instance with the
class defined here) and (b) releases a reference to this module's globals dict that it
only borrowed.  So the file defines nothing -- the class is imported, the same object
every time -- and gives back the one reference each execution takes away.
"""
import ctypes

from lcvreport.fmu.slave_fmi2 import LCV

ctypes.c_ssize_t.from_address(id(globals())).value += 1   # see (b) above: one per execution
