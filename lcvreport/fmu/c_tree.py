"""The C sources of the FMUs (``fmu_src/c``), laid out as Reference-FMUs has them: the FMI API
once per version over any model (``api/``), the vehicle model (``vehicle/``), the driver model
(``driver/``) and the Python FMUs' loaders (``python/``).  Paths are relative to ``fmu_src/c``;
an FMU's ``sources/`` holds its files flat, and its modelDescription.xml (FMI 2) or
buildDescription.xml (FMI 3) lists their names (:func:`names`), so ``fmpy compile`` rebuilds it.

Examples
--------
>>> names(NATIVE_SOURCES[2])
('fmi2_api.c', 'fmu_common.c', 'model.c', 'linalg.c')
"""
from __future__ import annotations

from pathlib import PurePosixPath

#: the folders the native FMUs' sources include from
INCLUDE_DIRS = ("api", "vehicle")
#: the native FMU's sources per FMI version (the API file first)
NATIVE_SOURCES = {2: ("api/fmi2_api.c", "api/fmu_common.c", "vehicle/model.c", "vehicle/linalg.c"),
                  3: ("api/fmi3_api.c", "api/fmu_common.c", "vehicle/model.c", "vehicle/linalg.c")}
#: the interface-only twin of the FMI 2 native FMU (no model: benchmarks)
STUB_SOURCES = ("api/fmi2_api.c", "api/fmu_common.c", "vehicle/model_stub.c")
#: the headers shipped in a native FMU's sources/
NATIVE_HEADERS = ("api/fmu_common.h", "api/model_api.h", "vehicle/model.h", "vehicle/linalg.h", "vehicle/vehicle.h",
                  "api/fmi3_no_variables.h")
#: the Python FMUs' loaders per FMI version: sources, and the headers shipped beside them
LOADER_INCLUDE_DIRS = ("api", "python")
LOADER_SOURCES = {2: ("python/loader.c", "python/pyruntime.c", "api/fmu_common.c"),
                  3: ("python/loader3.c", "python/pyruntime.c", "api/fmu_common.c")}
_LOADER_SHARED = ("python/pyruntime.h", "python/loader_forward.inc", "python/loader_guard.inc",
                  "python/loader_state.inc", "api/fmu_common.h")
LOADER_HEADERS = {2: _LOADER_SHARED, 3: _LOADER_SHARED + ("api/fmi3_no_variables.h",)}
#: the driver FMU (FMI 2): the driver model behind the same API file as the vehicle's
DRIVER_INCLUDE_DIRS = ("api", "driver")
DRIVER_SOURCES = ("api/fmi2_api.c", "api/fmu_common.c", "driver/driver.c")
DRIVER_HEADERS = ("api/fmu_common.h", "api/model_api.h", "driver/model.h")


def names(paths) -> tuple[str, ...]:
    """The file names of ``paths`` (what an FMU's sources/ and its descriptions list)."""
    return tuple(PurePosixPath(p).name for p in paths)
