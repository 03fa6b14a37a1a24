"""The driver FMU: a path-following driver (FMI 2.0, Co-Simulation and Model Exchange, C99),
built from ``fmu_src/c/driver/driver.c`` with the start values of
:data:`lcvreport.manoeuvres.drivers.DEFAULT` (docs/fmu.md, the SSP example).

Examples
--------
>>> import tempfile
>>> path = build_driver_fmu(tempfile.mkdtemp())
>>> path.name
'PreviewDriver.fmu'
"""
from __future__ import annotations

import hashlib
import tempfile
import uuid
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, indent, tostring

from ..manoeuvres.drivers import DEFAULT
from .c_sources import compile_c, c_files, fmi_header_dir, shipped_sources
from .c_tree import DRIVER_HEADERS, DRIVER_INCLUDE_DIRS, DRIVER_SOURCES, names
from .description_common import xml_number
from .package import write_zip, documentation_files
from ..version import __version__

MODEL_IDENTIFIER = "PreviewDriver"
SOURCES = names(DRIVER_SOURCES)
#: name, causality, unit, start, (min, max), description; value references in this order
VARIABLES = (
    ("gain_rad_per_m", "parameter", "rad/m", DEFAULT.gain_rad_per_m, (0.0, 1.0),
     "K: steer per metre of preview error, in (0, 1] rad/m"),
    ("preview_m", "parameter", "m", DEFAULT.preview_m, (0.0, 200.0), "L: preview distance ahead of the CG, in [0, 200] m"),
    ("target_offset_m", "parameter", "m", DEFAULT.target_offset_m, (-20.0, 20.0),
     "lane change: lateral offset of the reference path, +y to the right, in [-20, 20] m"),
    ("start_s", "parameter", "s", DEFAULT.start_s, (0.0, 1e6), "lane change: when the reference starts to move [s]"),
    ("duration_s", "parameter", "s", DEFAULT.duration_s, (0.0, 100.0),
     "lane change: half-cosine ramp duration, in (0, 100] s"),
    ("Y1", "input", "m", 0.0, None, "lateral position of the tractor CG (the vehicle FMU's output Y1), +y"),
    ("psi1", "input", "rad", 0.0, None, "heading of the tractor (the vehicle FMU's output psi1), nose-right positive"),
    ("delta", "output", "rad", None, None, "steer angle K (Y_ref(t) - (Y1 + L psi1)) (the vehicle FMU's input delta)"),
)
UNITS = {"rad/m": {"rad": "1", "m": "-1"}, "m": {"m": "1"}, "s": {"s": "1"}, "rad": {"rad": "1"}}


def driver_guid() -> str:
    h = hashlib.sha256(repr((MODEL_IDENTIFIER, VARIABLES, b"".join(f.read_bytes() for f in c_files(DRIVER_SOURCES + DRIVER_HEADERS)))).encode())
    return "{" + str(uuid.UUID(bytes=h.digest()[:16], version=5)) + "}"


def driver_model_description(fmu_guid: str) -> bytes:
    root = Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": MODEL_IDENTIFIER, "guid": fmu_guid,
        "description": "Path-following driver with preview: delta = K (Y_ref(t) - (Y1 + L psi1)), a half-cosine lane "
                       "change as the reference (lcvreport.manoeuvres.drivers.PreviewDriver).",
        "author": "lcvreport", "version": __version__, "license": "MIT", "generationTool": "lcvreport.fmu.driver (C99)",
        "variableNamingConvention": "flat", "numberOfEventIndicators": "0"})
    for tag, extra in (("ModelExchange", {"completedIntegratorStepNotNeeded": "true"}),
                       ("CoSimulation", {"canHandleVariableCommunicationStepSize": "true"})):
        el = SubElement(root, tag, {"modelIdentifier": MODEL_IDENTIFIER, "needsExecutionTool": "false", **extra})
        files = SubElement(el, "SourceFiles")
        for name in SOURCES:
            SubElement(files, "File", name=name)
    defs = SubElement(root, "UnitDefinitions")
    for name, base in UNITS.items():
        SubElement(SubElement(defs, "Unit", name=name), "BaseUnit", base)
    SubElement(root, "DefaultExperiment", {"startTime": "0.0", "stopTime": "10.0", "stepSize": "0.01"})
    mv = SubElement(root, "ModelVariables")
    for vr, (name, causality, unit, start, rng, text) in enumerate(VARIABLES):
        attrs = {"name": name, "valueReference": str(vr), "description": text, "causality": causality,
                 "variability": "fixed" if causality == "parameter" else "continuous"}
        if causality == "parameter":
            attrs["initial"] = "exact"
        elif causality == "output":
            attrs["initial"] = "calculated"
        real = {"unit": unit}
        if rng:
            real["min"], real["max"] = xml_number(rng[0]), xml_number(rng[1])
        if start is not None:
            real["start"] = xml_number(start)
        SubElement(SubElement(mv, "ScalarVariable", attrs), "Real", real)
    ms = SubElement(root, "ModelStructure")
    SubElement(SubElement(ms, "Outputs"), "Unknown", {"index": "8", "dependencies": "6 7"})
    SubElement(SubElement(ms, "InitialUnknowns"), "Unknown", {"index": "8", "dependencies": "1 2 3 4 5 6 7"})
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8") + b"\n"


def driver_config_header(fmu_guid: str) -> str:
    """``driver_config.h``: the start values, and what the FMI API file reads of a model."""
    d = DEFAULT
    return "\n".join([
        "/* Generated by lcvreport.fmu.driver: do not edit. */", "#ifndef DRIVER_CONFIG_H", "#define DRIVER_CONFIG_H",
        f'#define LCV_GUID "{fmu_guid}"', f'#define LCV_MODEL_IDENTIFIER_TEXT "{MODEL_IDENTIFIER}"',
        "#define LCV_N_ME_STATES 0", f"#define DRIVER_START_K {xml_number(d.gain_rad_per_m)}",
        f"#define DRIVER_START_L {xml_number(d.preview_m)}", f"#define DRIVER_START_TARGET {xml_number(d.target_offset_m)}",
        f"#define DRIVER_START_T0 {xml_number(d.start_s)}", f"#define DRIVER_START_T {xml_number(d.duration_s)}",
        "#ifndef M_PI", "#define M_PI 3.14159265358979323846", "#endif", "#endif", ""])


def build_driver_fmu(out_dir: str | Path) -> Path:
    """``<out_dir>/PreviewDriver.fmu``."""
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    fmu_guid = driver_guid()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "driver_config.h").write_text(driver_config_header(fmu_guid), encoding="utf-8")
        lib = tmp / f"{MODEL_IDENTIFIER}.so"
        compile_c(c_files(DRIVER_SOURCES), [tmp, *c_files(DRIVER_INCLUDE_DIRS), fmi_header_dir()], lib, ["-lm"])
        files = {"modelDescription.xml": driver_model_description(fmu_guid),
                 f"binaries/linux64/{MODEL_IDENTIFIER}.so": lib.read_bytes(),
                 "sources/driver_config.h": (tmp / "driver_config.h").read_bytes()}
        files.update(shipped_sources(DRIVER_SOURCES + DRIVER_HEADERS))

        class _Itf:
            description = "Path-following driver with preview (lcvreport.manoeuvres.drivers.PreviewDriver)."
        files.update(documentation_files(_Itf, MODEL_IDENTIFIER, native=True))
        return write_zip(out_dir / f"{MODEL_IDENTIFIER}.fmu", files)
