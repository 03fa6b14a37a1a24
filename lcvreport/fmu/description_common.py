"""What the FMI 2.0 and FMI 3.0 modelDescription.xml share: unit definitions, declared
types, enumerations, log categories, the default experiment, dependencies and the guid.
"""
from __future__ import annotations

import hashlib
import math
import uuid
from xml.etree.ElementTree import Element, SubElement

import numpy as np

from ..model.linear import linear_model
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


#: outputs that depend on the inputs directly: the lateral accelerations and the yaw-roll model's
#: sprung accelerations, load transfers and LTRs
FEEDTHROUGH = ("ay", "extra")


def state_dependencies(itf: Interface) -> dict:
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
            if kind in FEEDTHROUGH:
                deps[v.name] |= {name for j, name in z_of.items() if j < linear_model(vehicle, itf.model).n_states}
            elif kind == "y":
                deps[v.name] |= {z_of[j] for j in heading_z if j in z_of and np.any(maps["W"][o] != 0)}
                deps[v.name] |= {z_of[j] for j in np.nonzero(maps["C"][o])[0] if j in z_of}   # roll offsets
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
            SubElement(unit, "DisplayUnit", {"name": dname, "factor": xml_number(factor)})
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


def real_attributes(v: FmuVariable, declared: dict, nominal: dict) -> dict:
    """The attributes of a real variable's type element (FMI 2.0 ``Real``, FMI 3.0 ``Float64``):
    declared type, unit, display unit, the range of what the FMU refuses (parameters and
    inputs, from the ranges table), start and, for a Model Exchange state, its nominal."""
    attrs = {}
    if (v.quantity, v.display_unit) in declared:
        attrs["declaredType"] = declared[(v.quantity, v.display_unit)]
    if v.unit:
        attrs["unit"] = v.unit
    if v.display_unit:
        attrs["displayUnit"] = v.display_unit
    if v.causality in ("parameter", "input"):
        if v.minimum is not None:
            attrs["min"] = xml_number(v.minimum)
        if v.maximum is not None:
            attrs["max"] = xml_number(v.maximum)
    if v.start is not None:
        attrs["start"] = xml_number(v.start)
    if v.name in nominal:                     # a Model Exchange state: its physical scale
        attrs["nominal"] = xml_number(nominal[v.name])
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


def direct_dependencies(itf: Interface, v: FmuVariable, states: dict | None = None) -> list[str]:
    """Inputs (feedthrough) and, with ``states``, continuous states an output depends on."""
    kind = v.source[0]
    out = set((states or {}).get(v.name, ()))
    if kind in FEEDTHROUGH:
        out |= {w.name for w in itf.inputs}
    if kind == "max_real_eig":
        out |= {"u"}
    return list(out)


def initial_dependencies(itf: Interface, v: FmuVariable) -> list[str]:
    """Inputs and parameters an output depends on at initialization."""
    kind = v.source[0]
    params = [p.name for p in itf.parameters]
    if kind in FEEDTHROUGH:
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


def xml_number(x: float) -> str:
    return repr(float(x))
