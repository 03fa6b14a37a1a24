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

from xml.etree.ElementTree import Element, SubElement, indent, tostring

from .c_tree import NATIVE_SOURCES, names
from .description_common import (UNIT_DERIVATIVE, direct_dependencies, initial_dependencies, state_dependencies,
                                 categories_and_experiment, declared_types, enumeration_items, enumeration_type_name,
                                 enumeration_value, guid, real_attributes, unit_definitions, variable_attributes)
from .interface import Interface
from ..version import __version__

#: the C sources of the native FMU listed in ``<SourceFiles>`` (``fmpy compile`` rebuilds it)
NATIVE_SOURCE_FILES = names(NATIVE_SOURCES[2])


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
        "author": "lcvreport", "version": __version__, "license": "MIT", "generationTool": generation_tool,
        "variableNamingConvention": "flat", "numberOfEventIndicators": "0"})
    if native:                  # Model Exchange from the same model code (docs/fmu.md)
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
    for v in itf.variables:     # the Enumeration of the presets (docs/fmu.md)
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
        SubElement(sv, "Real", real_attributes(v, declared, nominal))
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
    states = state_dependencies(itf) if native else None
    ms = SubElement(root, "ModelStructure")
    outs = SubElement(ms, "Outputs")
    if derivatives:
        ders = SubElement(ms, "Derivatives")
    init = SubElement(ms, "InitialUnknowns")
    for v in itf.outputs:                  # dependencies in ascending order (FMI 2.0.4, section 2.2.8)
        deps = " ".join(str(i) for i in sorted(index[n] for n in direct_dependencies(itf, v, states)))
        SubElement(outs, "Unknown", {"index": str(index[v.name]), "dependencies": deps})
    for name in derivatives:               # every state and input (no dependencies attribute: all)
        SubElement(ders, "Unknown", {"index": str(index[name])})
    for v in itf.outputs:
        deps = " ".join(str(i) for i in sorted(index[n] for n in initial_dependencies(itf, v)))
        SubElement(init, "Unknown", {"index": str(index[v.name]), "dependencies": deps})
    for name in derivatives:
        SubElement(init, "Unknown", {"index": str(index[name])})
    indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + tostring(root, encoding="utf-8") + b"\n"
