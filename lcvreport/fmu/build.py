"""Build the FMUs: the pythonfmu FMU and the C99 FMU of the presets or of any vehicle.

``python -m lcvreport.fmu.build --out build`` is what ``./build.sh fmu`` runs: it
writes ``build/LCV.fmu`` and ``build/LCVNative.fmu`` (docs/fmu.md).  ``lcv fmu``
calls :func:`build_vehicle_fmus` (docs/fmu.md): ``<name>.fmu`` and
``<name>Native.fmu`` with the vehicle built in.

Everything is generated from the interface table (:mod:`lcvreport.fmu.interface`):
the modelDescription.xml of both (:mod:`lcvreport.fmu.description_fmi2`), the C
header ``config.h`` (the ``ValueReference`` enum, sizes, the ranges of
:mod:`lcvreport.ranges`), ``config_data.h`` (names, start values, kinds) and
``vehicle_data.h`` (the matrices and the engine's output maps, round-trip exact), and
the pythonfmu loader's ``loader_config.h``.  The C sources live in the repository's
``fmu_src/c`` (installed as ``lcvreport.fmu_src``); the official FMI 2 headers come
from fmpy's package.  Needs gcc.

Examples
--------
>>> from lcvreport import load_preset
>>> text = config_header(vehicle_interface(load_preset("tractor_semitrailer")), "x", "{guid}")
>>> "vr_P_21 = 8" in text
True
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import sysconfig
import tempfile
import zipfile
from pathlib import Path


from ..model.vehicle import Vehicle
from ..model.vehicle_file import dumps_vehicle
from .c_sources import (EXPORT_LIB, EXPORT_LIBS, FmuBuildError, compile_c, c_files, config_data_header, config_header,
                        fmi_header_dir, loader_config_header, shipped_sources, source_dir, vehicle_data_header)
from .c_tree import (INCLUDE_DIRS, LOADER_HEADERS, LOADER_INCLUDE_DIRS, LOADER_SOURCES, NATIVE_HEADERS, NATIVE_SOURCES,
                     STUB_SOURCES)
from .description_common import guid
from .description_fmi2 import model_description
from .interface import U_START, Interface, fmu_base_name, preset_interface, vehicle_interface
from .package import SOURCES_README, package_copy, write_zip, bundled_package_name, documentation_files


def build_native_fmu(itf: Interface, out_dir: Path, model_identifier: str, stub: bool = False) -> Path:
    """Generate the headers, compile the C FMU with gcc, zip ``<model_identifier>.fmu``.

    ``stub=True`` builds the interface-only twin (model_stub.c: no model) for benchmarks.
    """
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    fmu_guid = guid(itf, model_identifier)
    generated = {"config.h": config_header(itf, model_identifier, fmu_guid),
                 "config_data.h": config_data_header(itf),
                 "vehicle_data.h": vehicle_data_header(itf) if not stub else ""}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name, text in generated.items():
            (tmp / name).write_text(text, encoding="utf-8")
        lib = tmp / f"{model_identifier}.so"
        compile_c(c_files(STUB_SOURCES if stub else NATIVE_SOURCES[2]), [tmp, *c_files(INCLUDE_DIRS), fmi_header_dir()],
                 lib, ["-lm"])
        files = {"modelDescription.xml": model_description(itf, model_identifier, native=True,
                                                           generation_tool="lcvreport.fmu.build (C99)"),
                 f"binaries/linux64/{model_identifier}.so": lib.read_bytes()}
        if not stub:
            files.update(shipped_sources(NATIVE_SOURCES[2] + NATIVE_HEADERS))
            for name, text in generated.items():
                files[f"sources/{name}"] = text.encode()
            files["sources/README.txt"] = SOURCES_README.format(identifier=model_identifier).encode()
            if not itf.preset_mode:   # the vehicle built in, as its file (for the user; the C code does not read it)
                files["resources/vehicle.toml"] = dumps_vehicle(itf.vehicles[0]).encode()
            files.update(documentation_files(itf, model_identifier, native=True))
        return write_zip(out_dir / f"{model_identifier}.fmu", files)


def build_native_fmu3(itf: Interface, out_dir: Path, model_identifier: str) -> Path:
    """The FMI 3.0 native FMU ``<model_identifier>.fmu`` (Co-Simulation and Model Exchange),
    from the same model code as the FMI 2.0 one with fmi3_api.c in front (docs/fmu.md)."""
    from .description_fmi3 import build_description3, model_description3
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    fmu_guid = guid(itf, model_identifier)
    generated = {"config.h": config_header(itf, model_identifier, fmu_guid),
                 "config_data.h": config_data_header(itf), "vehicle_data.h": vehicle_data_header(itf)}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for name, text in generated.items():
            (tmp / name).write_text(text, encoding="utf-8")
        lib = tmp / f"{model_identifier}.so"
        compile_c(c_files(NATIVE_SOURCES[3]), [tmp, *c_files(INCLUDE_DIRS), fmi_header_dir()], lib, ["-lm"],
                 defines=["LCV_FMI3"])
        files = {"modelDescription.xml": model_description3(itf, model_identifier,
                                                            generation_tool="lcvreport.fmu.build (C99)"),
                 f"binaries/x86_64-linux/{model_identifier}.so": lib.read_bytes(),
                 "sources/buildDescription.xml": build_description3(model_identifier)}
        files.update(shipped_sources(NATIVE_SOURCES[3] + NATIVE_HEADERS))
        for name, text in generated.items():
            files[f"sources/{name}"] = text.encode()
        if not itf.preset_mode:
            files["resources/vehicle.toml"] = dumps_vehicle(itf.vehicles[0]).encode()
        files.update(documentation_files(itf, model_identifier, native=True, fmi=3))
        return write_zip(out_dir / f"{model_identifier}.fmu", files)


def _pythonfmu_build(tool: str, itf: Interface, tmp: Path, alias: str, script: str, script_text: str,
                     model_identifier: str, binary_dir: str) -> tuple[dict, bytes]:
    """A pythonfmu (``tool="pythonfmu"``) or pythonfmu3 project in ``tmp/project`` -- the slave
    script, ``lcv_fmu.json``, the vehicle file, the package bundled as ``alias`` -- built with
    the tool; the FMU's files without its binaries, and the tool's export library for Linux."""
    proj = tmp / "project"
    proj.mkdir()
    (proj / script).write_text(script_text, encoding="utf-8")
    cfg = {"mode": "presets"} if itf.preset_mode else {
        "mode": "vehicle", "vehicle_file": "vehicle.toml",
        "u_start_mps": next(v.start for v in itf.variables if v.name == "u"), "model": itf.model}
    (proj / "lcv_fmu.json").write_text(json.dumps(cfg), encoding="utf-8")
    extra = [proj / "lcv_fmu.json"]
    if not itf.preset_mode:
        (proj / "vehicle.toml").write_text(dumps_vehicle(itf.vehicles[0]), encoding="utf-8")
        extra.append(proj / "vehicle.toml")
    package_copy(proj, alias)
    built = tmp / "built"
    cmd = [sys.executable, "-m", tool, "build", "-f", str(proj / script), "-d", str(built),
           "--handle-state", "--serialize-state", *map(str, extra), str(proj / alias)]
    env_build = dict(os.environ, PYTHONPATH=str(proj) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    p = subprocess.run(cmd, capture_output=True, text=True, cwd=tmp, env=env_build)
    fmu = built / f"{model_identifier}.fmu"
    if p.returncode != 0 or not fmu.exists():
        raise FmuBuildError(f"{tool} build failed:\n{p.stdout[-2000:]}\n{p.stderr[-4000:]}")
    with zipfile.ZipFile(fmu) as zf:
        files = {n: zf.read(n) for n in zf.namelist() if not n.endswith("/")}
    export = files.pop(f"binaries/{binary_dir}/{model_identifier}.so")
    for name in [n for n in files if n.startswith("binaries/")]:
        files.pop(name)   # the tool's Windows and macOS libraries: the loaders are Linux-only
    return files, export


def build_python_fmu(itf: Interface, out_dir: Path, model_identifier: str, env: dict | None = None) -> Path:
    """Build the pythonfmu FMU ``<model_identifier>.fmu`` with the loader as its binary."""
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    if model_identifier != itf.model_name:
        raise FmuBuildError(f"the pythonfmu FMU's model identifier is its model name {itf.model_name!r}")
    fmu_guid = guid(itf, model_identifier)
    src = source_dir()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        alias = bundled_package_name(fmu_guid)
        slave_text = (src / "LCV.py").read_text(encoding="utf-8")
        if "from lcvreport.fmu.slave_fmi2 import LCV" not in slave_text:
            raise FmuBuildError("fmu_src/LCV.py lost its import line")
        # the slave module's name is the FMU's own: pythonfmu 0.7.0 imports it by name and takes the class
        # from sys.modules, so a second FMU whose module had the same name ran the first one's class
        module = "lcv_slave_" + alias.rsplit("_", 1)[1]
        files, export = _pythonfmu_build("pythonfmu", itf, tmp, alias, f"{module}.py",
                                         slave_text.replace("from lcvreport.fmu.slave_fmi2 import LCV",
                                                            f"from {alias}.fmu.slave_fmi2 import LCV"),
                                         model_identifier, "linux64")
        files["modelDescription.xml"] = model_description(itf, model_identifier, native=False,
                                                          generation_tool="lcvreport.fmu.build (pythonfmu 0.7.0)")
        (tmp / "loader_config.h").write_text(loader_config_header(itf, model_identifier, fmu_guid, env), "utf-8")
        loader = tmp / f"{model_identifier}.so"
        # Python.h for the types of the initialization API only (the loader links no libpython)
        compile_c(c_files(LOADER_SOURCES[2]),
                 [tmp, *c_files(LOADER_INCLUDE_DIRS), fmi_header_dir(), Path(sysconfig.get_paths()["include"])], loader,
                 ["-ldl", "-lpthread"])
        files[f"binaries/linux64/{model_identifier}.so"] = loader.read_bytes()
        files[f"binaries/linux64/{EXPORT_LIB}"] = export
        files.update(shipped_sources(LOADER_SOURCES[2] + LOADER_HEADERS[2]))
        files["sources/loader_config.h"] = (tmp / "loader_config.h").read_bytes()
        files.update(documentation_files(itf, model_identifier, native=False))
        return write_zip(out_dir / f"{model_identifier}.fmu", files)


#: pythonfmu3's export library inside the FMI 3.0 Python FMU (the loader, loader3.c, loads it)
EXPORT_LIB3 = EXPORT_LIBS[3]


SLAVE3_TEMPLATE = '''"""The slave module pythonfmu3 imports from the FMU's resources (once per process, under this
file's name, which carries the FMU's own hash): the class extends lcvreport's FMI 3.0 slave of
the package bundled next to this file under a name of its own, so a Python host that has
imported another lcvreport neither runs it nor is disturbed by it."""
from pythonfmu3 import Fmi3Slave

from {alias}.fmu.slave_fmi3 import LCV3 as _LCV3


class {cls}(_LCV3, Fmi3Slave):
    MODEL_IDENTIFIER = {identifier!r}
'''


def build_python_fmu3(itf: Interface, out_dir: Path, model_identifier: str, env: dict | None = None) -> Path:
    """The FMI 3.0 Python FMU ``<model_identifier>.fmu`` (Co-Simulation, pythonfmu3 0.3.4) with
    the loader (``loader3.c``) as its binary, so that plain C hosts load it (docs/fmu.md)."""
    from .description_fmi3 import model_description3
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    fmu_guid = guid(itf, model_identifier)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        alias = bundled_package_name(fmu_guid)
        module = "lcv_slave3_" + alias.rsplit("_", 1)[1]      # unique per FMU: pythonfmu3 imports it by name
        files, export = _pythonfmu_build("pythonfmu3", itf, tmp, alias, f"{module}.py",
                                         SLAVE3_TEMPLATE.format(alias=alias, cls="LCVSlave3",
                                                                identifier=model_identifier),
                                         model_identifier, "x86_64-linux")
        files["modelDescription.xml"] = model_description3(itf, model_identifier, native=False,
                                                           generation_tool="lcvreport.fmu.build (pythonfmu3 0.3.4)")
        (tmp / "loader_config.h").write_text(loader_config_header(itf, model_identifier, fmu_guid, env, fmi=3), "utf-8")
        loader = tmp / f"{model_identifier}.so"
        compile_c(c_files(LOADER_SOURCES[3]),
                 [tmp, *c_files(LOADER_INCLUDE_DIRS), fmi_header_dir(), Path(sysconfig.get_paths()["include"])], loader,
                 ["-ldl", "-lpthread"], defines=["LCV_FMI3"])
        files[f"binaries/x86_64-linux/{model_identifier}.so"] = loader.read_bytes()
        files[f"binaries/x86_64-linux/{EXPORT_LIB3}"] = export
        files.update(shipped_sources(LOADER_SOURCES[3] + LOADER_HEADERS[3]))
        files["sources/loader_config.h"] = (tmp / "loader_config.h").read_bytes()
        files.update(documentation_files(itf, model_identifier, native=False, fmi=3))
        return write_zip(out_dir / f"{model_identifier}.fmu", files)


def build_preset_fmus(out_dir: Path) -> list[Path]:
    """``LCV.fmu`` and ``LCVNative.fmu`` (docs/fmu.md), and their FMI 3.0 siblings ``LCV3.fmu``
    and ``LCVNative3.fmu`` (docs/fmu.md)."""
    itf = preset_interface()
    return [build_python_fmu(itf, out_dir, "LCV"), build_native_fmu(itf, out_dir, "LCVNative"),
            build_python_fmu3(itf, out_dir, "LCV3"), build_native_fmu3(itf, out_dir, "LCVNative3")]


def fmi3_python_name(name: str) -> str:
    """The model identifier of a vehicle's FMI 3 Python FMU: ``<name>3``, or ``<name>_fmi3`` when the
    name ends in a digit (``bdouble26_fmi3``, not ``bdouble263``, which reads as another vehicle).

    Examples
    --------
    >>> fmi3_python_name("my_semi"), fmi3_python_name("nu4_bdouble26")
    ('my_semi3', 'nu4_bdouble26_fmi3')
    """
    return f"{name}_fmi3" if name[-1:].isdigit() else f"{name}3"


def build_vehicle_fmus(vehicle: Vehicle, out_dir: str | Path, kind: str = "both",
                       u_start_mps: float = U_START, fmi: int = 2, model: str = "yaw_plane") -> list[Path]:
    """``<name>.fmu`` (pythonfmu) and/or ``<name>Native.fmu`` (C99) of a vehicle (docs/fmu.md);
    with ``fmi=3``, ``<name>3.fmu`` (pythonfmu3; ``<name>_fmi3.fmu`` when the name ends in a digit)
    and/or ``<name>Native3.fmu`` (docs/fmu.md).

    Parameters
    ----------
    vehicle : Vehicle
    out_dir : path
    kind : {"python", "native", "both"}
    u_start_mps : float
        Start value of the input ``u`` [m/s] (default 50 mph).
    fmi : {2, 3}
    model : {"yaw_plane", "yaw_roll", "nonlinear"}
        The model built in (:func:`~lcvreport.fmu.interface.vehicle_interface`).  The
        yaw plane's FMUs are named for the vehicle, another model's for the vehicle and the model
        (``<name>_yaw_roll.fmu``, ``<name>_yaw_rollNative.fmu``, ``<name>_nonlinear.fmu``, ...): every
        kind of one vehicle sits in one folder and loads into one host (their model identifiers
        differ).  The nonlinear model's FMU is the Python FMI 2.0 one only.

    Returns
    -------
    list of pathlib.Path
        The FMUs written.

    Raises
    ------
    ValueError
        An unknown kind or FMI version; the nonlinear model with another kind or version.

    Examples
    --------
    >>> import tempfile
    >>> from lcvreport import load_vehicle
    >>> out = tempfile.mkdtemp()
    >>> [p.name for p in build_vehicle_fmus(load_vehicle("examples/vehicles/b_double.toml"), out, kind="native")]
    ['b_doubleNative.fmu']
    """
    if kind not in ("python", "native", "both"):
        raise ValueError(f"kind must be python, native or both, got {kind!r}")
    if fmi not in (2, 3):
        raise ValueError(f"fmi must be 2 or 3, got {fmi!r}")
    from ..model.base import check_model
    if check_model(model) == "nonlinear" and (kind != "python" or fmi != 2):
        raise ValueError(f"the nonlinear model's FMU is the Python FMI 2.0 Co-Simulation one (kind='python', "
                         f"fmi=2), got kind={kind!r}, fmi={fmi!r}: its steps are integrated by the package")
    itf = vehicle_interface(vehicle, u_start_mps, model)
    name = fmu_base_name(vehicle.name, model)
    out = []
    if fmi == 3:
        if kind in ("python", "both"):
            out.append(build_python_fmu3(itf, Path(out_dir), fmi3_python_name(name)))
        if kind in ("native", "both"):
            out.append(build_native_fmu3(itf, Path(out_dir), f"{name}Native3"))
        return out
    if kind in ("python", "both"):
        out.append(build_python_fmu(itf, Path(out_dir), name))
    if kind in ("native", "both"):
        out.append(build_native_fmu(itf, Path(out_dir), f"{name}Native"))
    return out


def main(argv: list[str] | None = None) -> int:
    """Command-line entry of ``./build.sh fmu``: the preset FMUs into ``--out``."""
    p = argparse.ArgumentParser(description="Build build/LCV.fmu (pythonfmu), build/LCVNative.fmu (C99) and their "
                                            "FMI 3.0 siblings build/LCV3.fmu and build/LCVNative3.fmu.")
    p.add_argument("--out", default="build", type=Path, help="output folder (default build)")
    args = p.parse_args(argv)
    try:
        for path in build_preset_fmus(args.out):
            print(f"built {path}")
    except FmuBuildError as exc:
        print(f"fmu build: error: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
