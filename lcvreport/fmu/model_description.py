"""modelDescription.xml from the interface table: one writer for both FMUs.

Units and display units (``<UnitDefinitions>``, factors from :mod:`lcvreport.units`),
min/max from :mod:`lcvreport.ranges`, ``<ModelStructure>`` with the outputs'
direct dependencies and the initial unknowns, a guid that is a hash of the content
(no timestamp: the same vehicle gives the same file).

Examples
--------
>>> from lcvreport.fmu.interface import preset_interface
>>> xml = model_description(preset_interface(), "LCVNative", native=True)
>>> b'modelIdentifier="LCVNative"' in xml
True
"""
from __future__ import annotations

import hashlib
import math
import uuid

import numpy as np
from xml.etree.ElementTree import Element, SubElement, indent, tostring

from ..units import M_PER_FT, M_PER_IN, MPS_PER_MPH, N_PER_LBF, NM_PER_LBF_FT, NM_PER_LBF_IN, S_PER_HOUR
from .interface import FmuVariable, Interface

#: FMI unit name -> (SI base-unit exponents, [(display unit, factor)]): display = factor * value
UNIT_DEFINITIONS = {
    "m/s": ({"m": 1, "s": -1}, [("mph", 1 / MPS_PER_MPH), ("km/h", S_PER_HOUR / 1000.0)]),
    "m": ({"m": 1}, [("in", 1 / M_PER_IN), ("ft", 1 / M_PER_FT), ("mm", 1000.0)]),
    "rad": ({"rad": 1}, [("deg", 180.0 / math.pi)]),
    "rad/s": ({"rad": 1, "s": -1}, [("deg/s", 180.0 / math.pi)]),
    "rad/s2": ({"rad": 1, "s": -2}, [("deg/s2", 180.0 / math.pi)]),
    "N": ({"kg": 1, "m": 1, "s": -2}, [("lbf", 1 / N_PER_LBF), ("kN", 1e-3)]),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, [("lbf.ft", 1 / NM_PER_LBF_FT), ("lbf.in", 1 / NM_PER_LBF_IN),
                                        ("kN.m", 1e-3)]),
    "m/s2": ({"m": 1, "s": -2}, [("g", 1 / 9.80665)]),
    "1/s": ({"s": -1}, [("1/min", 60.0)]),
    "s": ({"s": 1}, []),
    "1": ({}, []),
    "%": ({"factor": 0.01}, []),
}
#: the unit of a state's time derivative
UNIT_DERIVATIVE = {"m/s": "m/s2", "rad": "rad/s", "m": "m/s", "rad/s": "rad/s2"}
#: log categories of both FMUs
LOG_CATEGORIES = {
    "logStatusWarning": "Log messages with fmi2Warning status (speed clamped to u_min).",
    "logStatusError": "Log messages with fmi2Error status (bad parameter, input or call).",
    "logAll": "Log all messages.",
}
#: default experiment
DEFAULT_EXPERIMENT = {"startTime": "0.0", "stopTime": "10.0", "stepSize": "0.001"}


#: the C sources of the native FMU listed in ``<SourceFiles>`` (``fmpy compile`` rebuilds it)
NATIVE_SOURCE_FILES = ("fmi2_api.c", "fmi2_shared.c", "model.c", "linalg.c")


def _state_dependencies(itf: Interface) -> dict:
    """Output name -> the continuous states it depends on (Model Exchange), from the engine's
    output maps of every vehicle of the FMU: linear outputs through C, rear offsets through
    the relative headings H, lateral accelerations through every state but psi1 and Y1."""
    from .engine import LCVEngine
    states = itf.continuous_states
    deps = {v.name: set() for v in itf.outputs}
    for vehicle in itf.vehicles:
        maps = LCVEngine(itf, preset=vehicle.name if itf.preset_mode else None).maps()
        z_of = {itf.state_index(sv, vehicle): sv.name for sv in states if itf.state_index(sv, vehicle) >= 0}
        heading_z = {j for j in range(maps["H"].shape[1]) if np.any(maps["H"][:, j] != 0)}
        for o, v in enumerate(itf.outputs):
            kind = v.source[0]
            if kind == "ay":
                deps[v.name] |= {name for j, name in z_of.items() if j < vehicle.n_states}
            elif kind == "y":
                deps[v.name] |= {z_of[j] for j in heading_z if j in z_of and np.any(maps["W"][o] != 0)}
            elif kind != "max_real_eig":
                deps[v.name] |= {z_of[j] for j in np.nonzero(maps["C"][o])[0] if j in z_of}
    return deps


def unit_definitions(root: Element, names) -> Element:
    """``<UnitDefinitions>`` of the units ``names`` (the same element in FMI 2.0 and 3.0)."""
    defs = SubElement(root, "UnitDefinitions")
    for name in sorted(names):
        base, displays = UNIT_DEFINITIONS[name]
        unit = SubElement(defs, "Unit", name=name)
        SubElement(unit, "BaseUnit", {k: str(e) for k, e in base.items()})
        for dname, factor in displays:
            SubElement(unit, "DisplayUnit", {"name": dname, "factor": _num(factor)})
    return defs


def variable_attributes(v: FmuVariable) -> dict:
    """name, value reference, description, causality, variability and initial of a variable
    (the same attributes in FMI 2.0 and 3.0)."""
    attrs = {"name": v.name, "valueReference": str(v.value_reference), "description": v.description,
             "causality": v.causality, "variability": v.variability}
    if v.causality == "output":
        attrs["initial"] = "calculated"
    elif v.causality == "parameter":
        attrs["initial"] = "exact"
    return attrs


def declared_types(itf: Interface) -> dict:
    """(quantity kind, display unit) -> (type name, attributes: quantity, unit, displayUnit) of
    every real variable's declared type."""
    from .interface import QUANTITIES
    out = {}
    for v in itf.variables:
        key = (v.quantity, v.display_unit)
        if v.type != "Real" or v.quantity not in QUANTITIES or key in out:
            continue
        name = QUANTITIES[v.quantity] + (f"_{v.display_unit.replace('/', '_per_').replace('.', '_')}"
                                         if v.display_unit else "")
        attrs = {"quantity": QUANTITIES[v.quantity]}
        if v.unit:
            attrs["unit"] = v.unit
        if v.display_unit:
            attrs["displayUnit"] = v.display_unit
        out[key] = (name, attrs)
    return out


def _direct_dependencies(itf: Interface, v: FmuVariable, states: dict | None = None) -> list[str]:
    """Inputs (feedthrough) and, with ``states``, continuous states an output depends on."""
    kind = v.source[0]
    out = set((states or {}).get(v.name, ()))
    if kind == "ay":
        out |= {w.name for w in itf.inputs}
    if kind == "max_real_eig":
        out |= {"u"}
    return list(out)


def _initial_dependencies(itf: Interface, v: FmuVariable) -> list[str]:
    """Inputs and parameters an output depends on at initialization."""
    kind = v.source[0]
    params = [p.name for p in itf.parameters]
    if kind == "ay":
        return [w.name for w in itf.inputs] + params
    if kind == "max_real_eig":
        return ["u"] + params
    return []


def enumeration_items(parent: Element, v: FmuVariable) -> None:
    """``<Item name=.. value=k>`` of every item of the Enumeration ``v`` (FMI 2.0 and 3.0 alike)."""
    for k, item in enumerate(v.items, 1):
        SubElement(parent, "Item", name=item, value=str(k))


def categories_and_experiment(root: Element) -> None:
    """``<LogCategories>`` and ``<DefaultExperiment>`` (the same elements in FMI 2.0 and 3.0)."""
    cats = SubElement(root, "LogCategories")
    for name, text in LOG_CATEGORIES.items():
        SubElement(cats, "Category", name=name, description=text)
    SubElement(root, "DefaultExperiment", DEFAULT_EXPERIMENT)


def enumeration_type_name(v: FmuVariable) -> str:
    """The declared type of an Enumeration variable: ``preset`` -> ``Preset``."""
    return v.name[:1].upper() + v.name[1:]


def enumeration_value(v: FmuVariable, item: str) -> int:
    """The value (1-based) of ``item`` of the Enumeration variable ``v``."""
    return v.items.index(item) + 1


def guid(itf: Interface, model_identifier: str) -> str:
    """A guid derived from the interface and the vehicles' numbers (reproducible)."""
    h = hashlib.sha256()
    h.update(model_identifier.encode())
    for v in itf.variables:
        h.update(repr((v.name, v.type, v.causality, v.variability, v.unit, v.start, v.source)).encode())
    for veh in itf.vehicles:
        h.update(repr(veh).encode())
    return "{" + str(uuid.UUID(bytes=h.digest()[:16], version=5)) + "}"


def _num(x: float) -> str:
    return repr(float(x))


def model_description(itf: Interface, model_identifier: str, native: bool, generation_tool: str = "lcvreport"
                      ) -> bytes:
    """The modelDescription.xml of an FMU of ``itf``.

    Parameters
    ----------
    itf : Interface
    model_identifier : str
        File stem of the FMU and of its binary.
    native : bool
        True for the C FMU (no execution tool); False for the pythonfmu FMU.
    generation_tool : str
    """
    root = Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": model_identifier, "guid": guid(itf, model_identifier),
        "description": itf.description + ("" if not native else " Native C implementation: no Python at run time."),
        "author": "lcvreport", "version": "0.2.0", "license": "MIT", "generationTool": generation_tool,
        "variableNamingConvention": "flat", "numberOfEventIndicators": "0"})
    if native:                  # Model Exchange from the same model code (SPEC section 15)
        me = SubElement(root, "ModelExchange", {
            "modelIdentifier": model_identifier, "needsExecutionTool": "false",
            "completedIntegratorStepNotNeeded": "true", "canBeInstantiatedOnlyOncePerProcess": "false",
            "canNotUseMemoryManagementFunctions": "true", "canGetAndSetFMUstate": "true",
            "canSerializeFMUstate": "true", "providesDirectionalDerivative": "true"})
        files = SubElement(me, "SourceFiles")
        for name in NATIVE_SOURCE_FILES:
            SubElement(files, "File", name=name)
    cs = SubElement(root, "CoSimulation", {
        "modelIdentifier": model_identifier, "needsExecutionTool": "false" if native else "true",
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true",
        "providesDirectionalDerivative": "true" if native else "false"})
    if native:                  # the official headers come with the importer (fmpy's c-code), not in sources/
        files = SubElement(cs, "SourceFiles")
        for name in NATIVE_SOURCE_FILES:
            SubElement(files, "File", name=name)
    used = {v.unit for v in itf.variables if v.unit}
    if native:                  # the units of the Model Exchange derivatives
        used |= {UNIT_DERIVATIVE[v.unit] for v in itf.continuous_states if v.unit in UNIT_DERIVATIVE}
    unit_definitions(root, used)
    types = SubElement(root, "TypeDefinitions")
    declared = declared_types(itf)
    for name, attrs in declared.values():
        SubElement(SubElement(types, "SimpleType", name=name), "Real", attrs)
    declared = {key: name for key, (name, _attrs) in declared.items()}
    for v in itf.variables:     # the Enumeration of the presets (SPEC section 15)
        if v.type == "Enumeration":
            enumeration_items(SubElement(SubElement(types, "SimpleType", name=enumeration_type_name(v),
                                                    description=f"Values of {v.name}"), "Enumeration"), v)
    categories_and_experiment(root)
    mv = SubElement(root, "ModelVariables")
    nominal = dict(zip((v.name for v in itf.continuous_states), itf.state_nominals())) if native else {}
    for v in itf.variables:
        sv = SubElement(mv, "ScalarVariable", variable_attributes(v))
        if v.type == "Enumeration":
            SubElement(sv, "Enumeration", {"declaredType": enumeration_type_name(v),
                                           "start": str(enumeration_value(v, v.start))})
            continue
        real = {}
        if (v.quantity, v.display_unit) in declared:
            real["declaredType"] = declared[(v.quantity, v.display_unit)]
        if v.unit:
            real["unit"] = v.unit
        if v.display_unit:
            real["displayUnit"] = v.display_unit
        if v.causality in ("parameter", "input"):   # what the FMU refuses, from the ranges table
            if v.minimum is not None:
                real["min"] = _num(v.minimum)
            if v.maximum is not None:
                real["max"] = _num(v.maximum)
        if v.start is not None:
            real["start"] = _num(v.start)
        if v.name in nominal:                     # a Model Exchange state: its physical scale
            real["nominal"] = _num(nominal[v.name])
        SubElement(sv, "Real", real)
    index = {v.name: v.value_reference + 1 for v in itf.variables}
    derivatives = []
    if native:                  # der(x) of every continuous state, locals after every variable
        for k, sv in enumerate(itf.continuous_states):
            vr = len(itf.variables) + k
            name = f"der({sv.name})"
            derivatives.append(name)
            index[name] = vr + 1
            dv = SubElement(mv, "ScalarVariable", {"name": name, "valueReference": str(vr),
                                                   "description": f"Time derivative of {sv.name}",
                                                   "causality": "local", "variability": "continuous",
                                                   "initial": "calculated"})
            real = {"derivative": str(index[sv.name])}
            if UNIT_DERIVATIVE.get(sv.unit):
                real["unit"] = UNIT_DERIVATIVE[sv.unit]
            SubElement(dv, "Real", real)
    states = _state_dependencies(itf) if native else None
    ms = SubElement(root, "ModelStructure")
    outs = SubElement(ms, "Outputs")
    if derivatives:
        ders = SubElement(ms, "Derivatives")
    init = SubElement(ms, "InitialUnknowns")
    for v in itf.outputs:                  # dependencies in ascending order (FMI 2.0.4, section 2.2.8)
        deps = " ".join(str(i) for i in sorted(index[n] for n in _direct_dependencies(itf, v, states)))
        SubElement(outs, "Unknown", {"index": str(index[v.name]), "dependencies": deps})
    for name in derivatives:               # every state and input (no dependencies attribute: all)
        SubElement(ders, "Unknown", {"index": str(index[name])})
    for v in itf.outputs:
        deps = " ".join(str(i) for i in sorted(index[n] for n in _initial_dependencies(itf, v)))
        SubElement(init, "Unknown", {"index": str(index[v.name]), "dependencies": deps})
    for name in derivatives:
        SubElement(init, "Unknown", {"index": str(index[name])})
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8") + b"\n"
