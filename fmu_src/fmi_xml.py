"""Extensions of pythonfmu's modelDescription.xml that pythonfmu 0.7.0 lacks.

XML only, no model: units and display units on Real variables, <UnitDefinitions>,
dependencies on <Outputs>, the <InitialUnknowns> list, a reproducible guid and no
generation timestamp.  Bundled into the FMU next to LCV.py.
"""
from __future__ import annotations

import uuid
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Real

#: FMI unit name -> (SI base-unit exponents, [(display unit, factor, offset)])
#: display = factor * value + offset (FMI 2.0, section 2.2.2)
UNITS = {
    "m/s": ({"m": 1, "s": -1}, [("mph", 2.2369362920544, 0.0), ("km/h", 3.6, 0.0)]),
    "m": ({"m": 1}, [("in", 39.37007874015748, 0.0), ("ft", 3.280839895013123, 0.0)]),
    "rad": ({"rad": 1}, [("deg", 57.29577951308232, 0.0)]),
    "rad/s": ({"rad": 1, "s": -1}, [("deg/s", 57.29577951308232, 0.0)]),
    "N": ({"kg": 1, "m": 1, "s": -2}, [("lbf", 0.2248089430997105, 0.0)]),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, [("lbf.ft", 0.7375621492772654, 0.0), ("lbf.in", 8.850745791327184, 0.0)]),
    "1/s": ({"s": -1}, []),
    "1": ({}, []),
}
#: display unit used by default per unit
DISPLAY = {"m/s": "mph", "m": "in", "rad": "deg", "rad/s": "deg/s", "N": "lbf", "N.m": "lbf.ft"}


class UnitReal(Real):
    """A pythonfmu Real that writes ``unit`` and ``displayUnit`` attributes."""

    def __init__(self, name: str, unit: str = "", **kwargs):
        super().__init__(name, **kwargs)
        self.unit = unit

    def to_xml(self) -> Element:
        node = super().to_xml()
        real = node.find("Real")
        if self.unit and real is not None:
            real.set("unit", self.unit)
            if self.unit in DISPLAY:
                real.set("displayUnit", DISPLAY[self.unit])
        return node


def unit_definitions(used: set[str]) -> Element:
    """<UnitDefinitions> for the units in ``used``."""
    defs = Element("UnitDefinitions")
    for name in sorted(used):
        base, displays = UNITS[name]
        unit = SubElement(defs, "Unit", name=name)
        SubElement(unit, "BaseUnit", {k: str(v) for k, v in base.items()})
        for dname, factor, offset in displays:
            attrs = {"name": dname, "factor": repr(factor)}
            if offset:
                attrs["offset"] = repr(offset)
            SubElement(unit, "DisplayUnit", attrs)
    return defs


def finish_model_description(root: Element, variables: list, depends: dict[str, list[str]],
                             initial_depends: dict[str, list[str]]) -> Element:
    """Complete pythonfmu's XML in place and return it.

    Parameters
    ----------
    root : Element
        ``fmiModelDescription`` from ``Fmi2Slave.to_xml``.
    variables : list
        The slave's registered variables, in value-reference order.
    depends : dict
        Output name -> names of the inputs it depends on directly (feedthrough).
    initial_depends : dict
        Output name -> names of inputs/parameters it depends on at initialization.
    """
    # reproducible identity: the guid is a hash of the interface, no timestamp
    signature = ";".join(f"{v.name}:{v.causality}:{getattr(v, 'unit', '')}" for v in variables)
    root.set("guid", "{" + str(uuid.uuid5(uuid.NAMESPACE_URL, "lcvreport/LCV/" + signature)) + "}")
    root.attrib.pop("generationDateAndTime", None)

    used = {v.unit for v in variables if getattr(v, "unit", "")}
    children = list(root)
    cs_index = [i for i, c in enumerate(children) if c.tag == "CoSimulation"][0]
    root.insert(cs_index + 1, unit_definitions(used))

    index = {v.name: i + 1 for i, v in enumerate(variables)}
    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    outputs = SubElement(structure, "Outputs")
    initial = SubElement(structure, "InitialUnknowns")
    for v in variables:
        if str(v.causality) == "output" or getattr(v.causality, "name", "") == "output":
            deps = sorted(index[n] for n in depends.get(v.name, []))
            SubElement(outputs, "Unknown", index=str(index[v.name]), dependencies=" ".join(map(str, deps)))
            ideps = sorted(index[n] for n in initial_depends.get(v.name, []))
            SubElement(initial, "Unknown", index=str(index[v.name]), dependencies=" ".join(map(str, ideps)))
    return root
