"""modelDescription.xml and buildDescription.xml of the FMI 3.0 native FMU (docs/fmu.md).

The same interface table, units, types and dependencies as the FMI 2.0 file
(:mod:`lcvreport.fmu.description_fmi2`), in FMI 3.0's form: ``Float64``/``Enumeration``
variables, an ``instantiationToken``, an independent variable ``time`` (its value
reference after the derivatives), ``<ModelStructure>`` by value reference, and the sources
listed in ``sources/buildDescription.xml`` so that ``fmpy compile`` rebuilds the binary.

Examples
--------
>>> from lcvreport.fmu.interface import preset_interface
>>> xml = model_description3(preset_interface(), "LCVNative3")
>>> b'fmiVersion="3.0"' in xml and b'causality="independent"' in xml
True
"""
from __future__ import annotations

from xml.etree.ElementTree import Element, SubElement, indent, tostring

from .c_tree import NATIVE_SOURCES, names
from .description_common import (UNIT_DERIVATIVE, direct_dependencies, initial_dependencies, state_dependencies,
                                 categories_and_experiment, declared_types, enumeration_items, enumeration_type_name,
                                 enumeration_value, guid, real_attributes, unit_definitions, variable_attributes)
from .interface import Interface
from ..version import __version__

#: the C sources of the FMI 3.0 native FMU (built with LCV_FMI3 defined)
FMI3_SOURCE_FILES = names(NATIVE_SOURCES[3])


def time_value_reference(itf: Interface) -> int:
    """The value reference of the independent variable ``time``: after every variable and derivative."""
    return len(itf.variables) + len(itf.continuous_states)


def model_description3(itf: Interface, model_identifier: str, generation_tool: str = "lcvreport",
                       native: bool = True) -> bytes:
    """The FMI 3.0 modelDescription.xml of an FMU of ``itf``: the native FMU (Co-Simulation and
    Model Exchange, directional derivatives) or, with ``native=False``, the Python FMU
    (Co-Simulation only, ``needsExecutionTool="true"``)."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": model_identifier, "instantiationToken": guid(itf, model_identifier),
        "description": itf.description + (" Native C implementation: no Python at run time." if native else
                                          " Runs the lcvreport package in an embedded Python (pythonfmu3)."),
        "author": "lcvreport", "version": __version__, "license": "MIT", "generationTool": generation_tool,
        "variableNamingConvention": "flat"})
    if native:
        SubElement(root, "ModelExchange", {
            "modelIdentifier": model_identifier, "canGetAndSetFMUState": "true", "canSerializeFMUState": "true",
            "needsCompletedIntegratorStep": "false", "providesDirectionalDerivatives": "true"})
    SubElement(root, "CoSimulation", {
        "modelIdentifier": model_identifier, "needsExecutionTool": "false" if native else "true",
        "canGetAndSetFMUState": "true", "canSerializeFMUState": "true",
        "canHandleVariableCommunicationStepSize": "true", "hasEventMode": "false",
        "providesIntermediateUpdate": "false", "providesDirectionalDerivatives": "true" if native else "false"})
    states = itf.continuous_states if native else ()
    used = {v.unit for v in itf.variables if v.unit}
    used |= {UNIT_DERIVATIVE[v.unit] for v in states if v.unit in UNIT_DERIVATIVE}
    unit_definitions(root, used | {"s"})
    types = SubElement(root, "TypeDefinitions")
    declared = {}
    for key, (name, attrs) in declared_types(itf).items():
        SubElement(types, "Float64Type", {"name": name, **attrs})
        declared[key] = name
    for v in itf.variables:
        if v.type == "Enumeration":
            enumeration_items(SubElement(types, "EnumerationType", name=enumeration_type_name(v),
                                         description=f"Values of {v.name}"), v)
    categories_and_experiment(root)
    mv = SubElement(root, "ModelVariables")
    t_vr = time_value_reference(itf)
    SubElement(mv, "Float64", {"name": "time", "valueReference": str(t_vr), "causality": "independent",
                               "variability": "continuous", "unit": "s", "description": "Simulation time"})
    nominal = dict(zip((v.name for v in itf.continuous_states), itf.state_nominals())) if native else {}
    for v in itf.variables:
        attrs = variable_attributes(v)
        if v.type == "Enumeration":
            SubElement(mv, "Enumeration", {**attrs, "declaredType": enumeration_type_name(v),
                                           "start": str(enumeration_value(v, v.start))})
            continue
        SubElement(mv, "Float64", {**attrs, **real_attributes(v, declared, nominal)})
    der_vr = {}
    for k, sv in enumerate(states):
        vr = len(itf.variables) + k
        der_vr[sv.name] = vr
        attrs = {"name": f"der({sv.name})", "valueReference": str(vr), "description": f"Time derivative of {sv.name}",
                 "causality": "local", "variability": "continuous", "initial": "calculated",
                 "derivative": str(sv.value_reference)}
        if sv.unit in UNIT_DERIVATIVE:
            attrs["unit"] = UNIT_DERIVATIVE[sv.unit]
        SubElement(mv, "Float64", attrs)
    vr_of = {v.name: v.value_reference for v in itf.variables}
    state_deps = state_dependencies(itf) if native else None
    ms = SubElement(root, "ModelStructure")
    for v in itf.outputs:
        deps = " ".join(str(i) for i in sorted(vr_of[n] for n in direct_dependencies(itf, v, state_deps)))
        SubElement(ms, "Output", {"valueReference": str(v.value_reference), "dependencies": deps})
    for sv in states:
        SubElement(ms, "ContinuousStateDerivative", {"valueReference": str(der_vr[sv.name])})
    for v in itf.outputs:
        deps = " ".join(str(i) for i in sorted(vr_of[n] for n in initial_dependencies(itf, v)))
        SubElement(ms, "InitialUnknown", {"valueReference": str(v.value_reference), "dependencies": deps})
    for sv in states:
        SubElement(ms, "InitialUnknown", {"valueReference": str(der_vr[sv.name])})
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8") + b"\n"


def build_description3(model_identifier: str) -> bytes:
    """``sources/buildDescription.xml``: the sources and the LCV_FMI3 definition (``fmpy compile``)."""
    root = Element("fmiBuildDescription", fmiVersion="3.0")
    cfg = SubElement(root, "BuildConfiguration", modelIdentifier=model_identifier)
    files = SubElement(cfg, "SourceFileSet", language="C99")
    for name in FMI3_SOURCE_FILES:
        SubElement(files, "SourceFile", name=name)
    SubElement(files, "PreprocessorDefinition", name="LCV_FMI3", value="1")
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8") + b"\n"
