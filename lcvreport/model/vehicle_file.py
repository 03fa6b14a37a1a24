"""Vehicle files: the user's own vehicle as TOML in SI units (docs/vehicle_files.md).

::

    format = "lcv-vehicle/1"
    name = "western_double"          # [A-Za-z][A-Za-z0-9_]*: also the FMU's model name
    description = "free text"        # optional

    [[units]]
    name = "tractor"                 # unique
    mass_kg = 8000.0                 # > 0
    yaw_inertia_kg_m2 = 35000.0      # > 0, about the CG
    rear_coupling_m = -0.30          # every unit but the last; absent on the last
    rear_end_m = -2.0                # optional: point whose lateral offset is y_k
    body_front_m = 3.0               # optional (with body_rear_m): x of the body's front face
    body_rear_m = -3.2               # optional: x of its rear face, behind the front
    body_width_m = 2.55              # optional: body width; the three are for the low-speed turn

      [[units.axles]]
      name = "steer"                 # unique in the vehicle, [A-Za-z0-9_]+
      x_m = 1.9
      tires = 2                      # integer >= 1; coefficients below are per tire
      steered = true                 # optional (false): first unit only
      cornering_stiffness_N_per_rad = 2.0e5     # > 0
      aligning_stiffness_Nm_per_rad = 8.0e3     # >= 0
      longitudinal_stiffness_N = 0.0            # >= 0 (with dual_spacing_m)
      dual_spacing_m = 0.0                      # >= 0
      static_load_N = 53000.0                   # optional; needed by the 1 % rule
      track_width_m = 2.05                      # optional: outermost tire centres; the low-speed turn

    [[units]]
    name = "trailer1"
    front_coupling_m = 5.2           # every unit but the first; absent on the first
    ...

Unknown keys, missing keys, wrong types, non-finite numbers and out-of-range values
are errors that name the unit, the axle and the key, e.g.
``units[2] "dolly1" axles[0] "d1": tires must be an integer >= 1 (at most 64), got 0``.
Nothing is defaulted but the keys marked optional.

Examples
--------
>>> text = '''
... format = "lcv-vehicle/1"
... name = "truck"
... [[units]]
... name = "truck"
... mass_kg = 9000.0
... yaw_inertia_kg_m2 = 30000.0
...   [[units.axles]]
...   name = "front"
...   x_m = 1.5
...   tires = 0
...   cornering_stiffness_N_per_rad = 2.0e5
...   aligning_stiffness_Nm_per_rad = 0.0
...   longitudinal_stiffness_N = 0.0
...   dual_spacing_m = 0.0
... '''
>>> loads_vehicle(text)
Traceback (most recent call last):
...
lcvreport.model.vehicle_file.VehicleFileError: units[0] "truck" axles[0] "front": tires must be an integer >= 1 (at most 64), got 0
"""
from __future__ import annotations

import json
import tomllib
import unicodedata
from pathlib import Path

from ..util.files import FileInputError, loads_toml, read_text_file
from .vehicle import AXLE_ROLL_KEYS, UNIT_ROLL_KEYS, Axle, Unit, Vehicle, VehicleError

#: the format tag of version 1
FORMAT = "lcv-vehicle/1"
#: the largest vehicle file read [bytes] (a 100-unit road train with comments is ~60 kB)
MAX_FILE_BYTES = 1 << 20
#: the deepest nesting of tables and arrays a vehicle file needs is 4; TOML deeper than this is refused
MAX_DEPTH = 16

#: keys of the top level, a unit and an axle: (required, optional)
TOP_KEYS = (("format", "name", "units"), ("description",))
UNIT_KEYS = (("name", "mass_kg", "yaw_inertia_kg_m2", "axles"),
             ("front_coupling_m", "rear_coupling_m", "rear_end_m", "body_front_m", "body_rear_m",
              "body_width_m") + UNIT_ROLL_KEYS)
AXLE_KEYS = (("name", "x_m", "tires", "cornering_stiffness_N_per_rad", "aligning_stiffness_Nm_per_rad",
              "longitudinal_stiffness_N", "dual_spacing_m"), ("steered", "driven", "static_load_N", "track_width_m")
             + AXLE_ROLL_KEYS)


class VehicleFileError(VehicleError):
    """A vehicle file that cannot be read or is invalid; the message names the place and key.

    Attributes
    ----------
    args : tuple
        ``(message,)``: one line naming the file, the table and the key.

    Examples
    --------
    >>> try:
    ...     loads_vehicle("not toml [")
    ... except VehicleFileError as exc:
    ...     "TOML" in str(exc)
    True
    """


def _keys(table: dict, spec: tuple, where: str) -> None:
    required, optional = spec
    for key, value in table.items():
        if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 64:
            raise VehicleFileError(key, f"{key} must be a number of physical size, got an integer of "
                                        f"{len(str(abs(value)))} digits", where)
        if isinstance(value, str):
            _printable(key, value, where)
    for key in table:
        if key not in required and key not in optional:
            raise VehicleFileError(key, f"unknown key {key!r}; valid keys: {', '.join(required + optional)}", where)
    for key in required:
        if key not in table:
            raise VehicleFileError(key, f"missing key {key!r}", where)


def _printable(key: str, text: str, where: str) -> None:
    """Text that goes into XML, C sources and reports: no control characters."""
    for ch in text:
        if unicodedata.category(ch) in ("Cc", "Cs", "Co", "Cn"):
            raise VehicleFileError(key, f"{key} must be printable text, got the control character "
                                        f"U+{ord(ch):04X} in {text[:60]!r}", where)


def _depth(value, limit: int = MAX_DEPTH) -> int:
    """Nesting depth of a parsed TOML value, without recursion (a file may nest 10^4 deep)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        v, d = stack.pop()
        deepest = max(deepest, d)
        if deepest > limit:
            return deepest
        if isinstance(v, dict):
            stack.extend((x, d + 1) for x in v.values())
        elif isinstance(v, list):
            stack.extend((x, d + 1) for x in v)
    return deepest


def _shown(name: str) -> str:
    """A name as a message shows it: in double quotes, control characters escaped (a name
    holding a newline or an ESC is one line of plain text, never a terminal command)."""
    return json.dumps(name, ensure_ascii=False)


def _table_list(value, key: str, where: str) -> list[dict]:
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise VehicleFileError(key, f"{key} must be an array of tables ([[{key}]]), got {value!r}", where)
    return value


def vehicle_from_dict(doc: dict, source: str = "") -> Vehicle:
    """Build a :class:`Vehicle` from a parsed vehicle file (the TOML as a dict).

    Raises
    ------
    VehicleFileError
        Naming the unit, the axle and the key.
    """
    if not isinstance(doc, dict):
        raise VehicleFileError("", "a vehicle file must be a TOML document")
    if _depth(doc) > MAX_DEPTH:
        raise VehicleFileError("", f"tables or arrays are nested more than {MAX_DEPTH} deep; a vehicle file needs 4")
    _keys(doc, TOP_KEYS, "")
    if doc["format"] != FORMAT:
        raise VehicleFileError("format", f"format must be {FORMAT!r}, got {doc['format']!r}")
    units = []
    for i, ut in enumerate(_table_list(doc["units"], "units", "")):
        uname = ut.get("name")
        where = f"units[{i}] {_shown(uname)}" if isinstance(uname, str) else f"units[{i}]"
        _keys(ut, UNIT_KEYS, where)
        axles = []
        for j, at in enumerate(_table_list(ut["axles"], "axles", where)):
            aname = at.get("name")
            awhere = f"{where} axles[{j}] {_shown(str(aname))}" if isinstance(aname, (str, int)) else \
                f"{where} axles[{j}]"
            _keys(at, AXLE_KEYS, awhere)
            try:
                axles.append(Axle(**at))
            except VehicleError as exc:
                raise VehicleFileError(exc.key, exc.bare, awhere) from None
        try:
            units.append(Unit(**{k: (tuple(axles) if k == "axles" else v) for k, v in ut.items()}))
        except VehicleError as exc:
            raise VehicleFileError(exc.key, exc.bare, where) from None
    try:
        return Vehicle(doc["name"], tuple(units), doc.get("description", ""), source=source)
    except VehicleError as exc:
        raise VehicleFileError(exc.key, exc.bare, exc.where) from None


def loads_vehicle(text: str, source: str = "") -> Vehicle:
    """Parse vehicle-file text (TOML); see :func:`vehicle_from_dict`.

    Parameters
    ----------
    text : str
        A vehicle file's text (docs/vehicle_files.md).
    source : str
        Where it came from, for messages.

    Returns
    -------
    Vehicle

    Raises
    ------
    VehicleFileError
        Not TOML, or a key, value or unit that is not as docs/vehicle_files.md says (one line naming it).

    Examples
    --------
    >>> from lcvreport import dumps_vehicle, load_preset
    >>> loads_vehicle(dumps_vehicle(load_preset("aucnat"))).n_units
    6
    """
    if len(text) > MAX_FILE_BYTES:
        raise VehicleFileError("", f"the text is {len(text)} characters long; a vehicle file has at most "
                                   f"{MAX_FILE_BYTES} bytes")
    _check_key_lengths(text)
    try:
        doc = loads_toml(text)
    except tomllib.TOMLDecodeError as exc:
        raise VehicleFileError("", f"not valid TOML: {exc}") from None
    except (RecursionError, MemoryError):
        raise VehicleFileError("", "not a vehicle file: its TOML nests too deeply") from None
    except ValueError as exc:          # an integer beyond Python's digit limit: its line and key
        raise VehicleFileError("", str(exc)) from None
    return vehicle_from_dict(doc, source)


def _check_key_lengths(text: str) -> None:
    """Refuse dotted keys of more than :data:`MAX_DEPTH` parts before parsing (tomllib takes
    time quadratic in the parts: a 40,000-part key would hang it); periods in comments and
    strings are not keys' (a comment listing loads in tonnes is a comment)."""
    from ..util.files import check_key_parts
    found = check_key_parts(text, MAX_DEPTH)
    if found is not None:
        raise VehicleFileError("", f"line {found[0]}: a key of {found[1]} dotted parts; a vehicle file needs at "
                                   "most 3")


def read_vehicle_text(path: str | Path) -> str:
    """The text of a vehicle file: a regular file of at most :data:`MAX_FILE_BYTES`, UTF-8
    (:func:`lcvreport.util.files.read_text_file`).

    A FIFO, a device (``/dev/zero``) or a folder is refused without reading from it.

    Raises
    ------
    VehicleFileError
    """
    try:
        return read_text_file(path, "vehicle file", MAX_FILE_BYTES)
    except FileInputError as exc:
        raise VehicleFileError("", str(exc)) from None


def load_vehicle(path: str | Path) -> Vehicle:
    """Read a vehicle file (TOML, SI units, docs/vehicle_files.md).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    Vehicle

    Raises
    ------
    VehicleFileError
        Unreadable file, invalid TOML, or an invalid vehicle (the message names the
        unit, the axle and the key).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> v = load_vehicle("examples/vehicles/western_double.toml")
    >>> v.unit_names
    ('tractor', 'trailer1', 'dolly', 'trailer2')
    """
    return loads_vehicle(read_vehicle_text(path), source=str(path))


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)
    text = str(v).replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    return f'"{text}"'


def dumps_vehicle(vehicle: Vehicle, header: str = "", unit_comments: dict | None = None,
                  axle_comments: dict | None = None) -> str:
    """The vehicle file text of ``vehicle`` (floats written to round-trip exactly).

    Parameters
    ----------
    vehicle : Vehicle
    header : str
        Comment lines put at the top (without ``#``).
    unit_comments, axle_comments : dict, optional
        Unit name / axle name -> comment lines written above that table.

    Returns
    -------
    str
        A ``lcv-vehicle/1`` file that :func:`loads_vehicle` reads back to an equal vehicle.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> v = load_preset("tractor_semitrailer")
    >>> loads_vehicle(dumps_vehicle(v)) == v
    True
    """
    unit_comments = unit_comments or {}
    axle_comments = axle_comments or {}
    out = [f"# {line}".rstrip() for line in header.splitlines()]
    out += [f"format = {_value(FORMAT)}", f"name = {_value(vehicle.name)}"]
    if vehicle.description:
        out.append(f"description = {_value(vehicle.description)}")
    for u in vehicle.units:
        out.append("")
        out += [f"# {line}".rstrip() for line in unit_comments.get(u.name, "").splitlines()]
        out.append("[[units]]")
        out.append(f"name = {_value(u.name)}")
        for key in ("mass_kg", "yaw_inertia_kg_m2", "front_coupling_m", "rear_coupling_m", "rear_end_m",
                    "body_front_m", "body_rear_m", "body_width_m") + UNIT_ROLL_KEYS:
            if getattr(u, key) is not None:
                out.append(f"{key} = {_value(getattr(u, key))}")
        for a in u.axles:
            out.append("")
            out += [f"  # {line}".rstrip() for line in axle_comments.get(a.name, "").splitlines()]
            out.append("  [[units.axles]]")
            for key in AXLE_KEYS[0] + AXLE_KEYS[1]:
                value = getattr(a, key)
                if key == "steered" and not value:
                    continue                           # (driven: written when given, None when not)
                if value is not None:
                    out.append(f"  {key} = {_value(value)}")
    return "\n".join(out) + "\n"
