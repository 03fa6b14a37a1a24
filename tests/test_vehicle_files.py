"""Vehicle files (SPEC section 7): the schema, every invalid-file case with its message,
presets and examples as files, round trips."""
from __future__ import annotations

import copy
import subprocess
import sys
import tomllib

import numpy as np
import pytest
from hypothesis import given, settings

from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule
from lcvreport.model.presets import PRESETS, load_preset, preset_path
from lcvreport.model.vehicle import Axle, Unit, Vehicle, VehicleError
from lcvreport.model.vehicle_file import VehicleFileError, dumps_vehicle, load_vehicle, loads_vehicle, vehicle_from_dict
from lcvreport.thesis.vehicles import preset_file_text
from lcvreport.units import THESIS

from conftest import EXAMPLE_NAMES, EXAMPLES, ROOT
from helpers import vehicles


@pytest.fixture(scope="module")
def base_doc():
    return tomllib.loads((EXAMPLES / "western_double.toml").read_text())


def _mutated(doc, path, value=None, delete=False):
    d = copy.deepcopy(doc)
    target = d
    for key in path[:-1]:
        target = target[key]
    if delete:
        del target[path[-1]]
    else:
        target[path[-1]] = value
    return d


U1 = 'units[1] "trailer1"'
A10 = 'units[1] "trailer1" axles[0] "trailer1_axle"'
BAD_FILES = [
    # (path, value or "DELETE", message fragments)
    (("colour",), "red", ["unknown key 'colour'"]),
    (("format",), "DELETE", ["missing key 'format'"]),
    (("format",), "lcv-vehicle/2", ["format must be 'lcv-vehicle/1'"]),
    (("name",), "1double", ["name must be a name that starts with a letter"]),
    (("name",), "double-1", ["name must be"]),
    (("description",), 5, ["description must be text"]),
    (("units",), [], ["a vehicle needs at least one unit"]),
    (("units",), "tractor", ["units must be an array of tables"]),
    (("units", 1, "mas_kg"), 1.0, [U1, "unknown key 'mas_kg'"]),
    (("units", 1, "mass_kg"), "DELETE", [U1, "missing key 'mass_kg'"]),
    (("units", 1, "mass_kg"), 0.0, [U1, "mass_kg must be in (0, 1e+06] kg, got 0"]),
    (("units", 1, "mass_kg"), -3.0, [U1, "mass_kg must be in"]),
    (("units", 1, "mass_kg"), "heavy", [U1, "mass_kg must be a number, got 'heavy'"]),
    (("units", 1, "mass_kg"), float("nan"), [U1, "mass_kg must be finite"]),
    (("units", 1, "mass_kg"), float("inf"), [U1, "mass_kg must be finite"]),
    (("units", 1, "mass_kg"), True, [U1, "mass_kg must be a number, got True"]),
    (("units", 1, "mass_kg"), 2.2e7, [U1, "mass_kg must be in (0, 1e+06] kg"]),
    (("units", 1, "yaw_inertia_kg_m2"), 0.0, [U1, "yaw_inertia_kg_m2 must be in (0, 1e+08]"]),
    (("units", 0, "rear_coupling_m"), "DELETE", ['units[0] "tractor"', "rear_coupling_m is required"]),
    (("units", 3, "rear_coupling_m"), -4.0, ['units[3] "trailer2"', "rear_coupling_m must be absent on the last"]),
    (("units", 1, "front_coupling_m"), "DELETE", [U1, "front_coupling_m is required"]),
    (("units", 0, "front_coupling_m"), 1.0, ['units[0] "tractor"', "front_coupling_m must be absent on the first"]),
    (("units", 1, "front_coupling_m"), 1e3, [U1, "front_coupling_m must be in [-50, 50] m"]),
    (("units", 1, "name"), "tractor", ['units[1] "tractor"', "unit name 'tractor' is used twice"]),
    (("units", 1, "name"), "trailer,1", ["name must be a name of letters"]),
    (("units", 1, "axles"), [], [U1, "a unit needs at least one axle"]),
    (("units", 1, "axles", 0, "camber"), 0.0, [A10, "unknown key 'camber'"]),
    (("units", 1, "axles", 0, "x_m"), "DELETE", [A10, "missing key 'x_m'"]),
    (("units", 1, "axles", 0, "x_m"), float("inf"), [A10, "x_m must be finite"]),
    (("units", 1, "axles", 0, "tires"), 0, [A10, "tires must be an integer >= 1 (at most 64), got 0"]),
    (("units", 1, "axles", 0, "tires"), 4.0, [A10, "tires must be an integer >= 1"]),
    (("units", 1, "axles", 0, "tires"), "4", [A10, "tires must be an integer >= 1"]),
    (("units", 1, "axles", 0, "tires"), True, [A10, "tires must be an integer >= 1"]),
    (("units", 1, "axles", 0, "cornering_stiffness_N_per_rad"), 0.0, [A10, "cornering_stiffness_N_per_rad must be in (0"]),
    (("units", 1, "axles", 0, "cornering_stiffness_N_per_rad"), -1e5, [A10, "cornering_stiffness_N_per_rad must be in"]),
    (("units", 1, "axles", 0, "aligning_stiffness_Nm_per_rad"), -1.0, [A10, "aligning_stiffness_Nm_per_rad must be in [0"]),
    (("units", 1, "axles", 0, "longitudinal_stiffness_N"), -1.0, [A10, "longitudinal_stiffness_N must be in [0"]),
    (("units", 1, "axles", 0, "dual_spacing_m"), -0.3, [A10, "dual_spacing_m must be in [0, 2] m"]),
    (("units", 1, "axles", 0, "static_load_N"), -5.0, [A10, "static_load_N must be in [0"]),
    (("units", 1, "axles", 0, "steered"), True, [A10, "steered axles must be on the first unit"]),
    (("units", 0, "axles", 0, "steered"), "yes", ['axles[0] "steer"', "steered must be true or false"]),
    (("units", 1, "axles", 0, "name"), "steer", [A10.replace("trailer1_axle", "steer"), "axle name 'steer' is used twice"]),
    (("units", 1, "axles", 0, "name"), "axle 1", ["name must be a name of letters, digits and _"]),
]


@pytest.mark.parametrize("path, value, fragments", BAD_FILES, ids=[f"{'.'.join(map(str, p))}={v!r}"[:60]
                                                                   for p, v, _f in BAD_FILES])
def test_every_invalid_file_is_named_unit_axle_and_key(base_doc, path, value, fragments):
    doc = _mutated(base_doc, path, delete=True) if value == "DELETE" else _mutated(base_doc, path, value)
    with pytest.raises(VehicleFileError) as err:
        vehicle_from_dict(doc)
    text = str(err.value)
    for frag in fragments:
        assert frag in text, text
    assert "\n" not in text


def test_unreadable_and_not_toml_files_are_named(tmp_path):
    with pytest.raises(VehicleFileError, match="cannot read"):
        load_vehicle(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("format = \n")
    with pytest.raises(VehicleFileError, match="not valid TOML"):
        load_vehicle(bad)
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\xff\xfe\x00")
    with pytest.raises(VehicleFileError, match="not UTF-8 text"):
        load_vehicle(binary)


@pytest.mark.parametrize("path, value, fragments", BAD_FILES[::6])
def test_a_bad_file_is_one_line_and_exit_2_in_every_command(base_doc, tmp_path, path, value, fragments):
    """Through the CLI: one clear line naming the place, status 2, no traceback."""
    doc = _mutated(base_doc, path, delete=True) if value == "DELETE" else _mutated(base_doc, path, value)
    text = _toml(doc)
    f = tmp_path / "v.toml"
    f.write_text(text)
    for cmd in (["eig"], ["steady", "--load", "trailer2"], ["measures"], ["simulate", "--load", "trailer2"]):
        p = subprocess.run([sys.executable, "-m", "lcvreport.cli", *cmd, "--vehicle", str(f), "--speed-kph", "88"],
                           capture_output=True, text=True)
        assert p.returncode == 2 and p.stdout == "", (cmd, p.stderr)
        lines = p.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in p.stderr and f"--vehicle {f}" in lines[0], p.stderr
        assert all(frag in lines[0] for frag in fragments[:1]), lines


def _toml(doc) -> str:
    """A small TOML writer for the test documents (the format is flat)."""
    def val(v):
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, float):
            return {"nan": "nan", "inf": "inf", "-inf": "-inf"}.get(repr(v), repr(v))
        if isinstance(v, str):
            return '"' + v.replace('"', '\\"') + '"'
        if isinstance(v, list) and not v:
            return "[]"
        return repr(v)
    out = [f"{k} = {val(v)}" for k, v in doc.items() if not (isinstance(v, list) and v and isinstance(v[0], dict))]
    for u in doc.get("units", []) if isinstance(doc.get("units"), list) else []:
        out.append("[[units]]")
        out += [f"{k} = {val(v)}" for k, v in u.items() if not (isinstance(v, list) and v and isinstance(v[0], dict))]
        for a in u.get("axles", []) if isinstance(u.get("axles"), list) else []:
            out.append("[[units.axles]]")
            out += [f"{k} = {val(v)}" for k, v in a.items()]
    return "\n".join(out) + "\n"


def test_legal_but_implausible_geometry_is_accepted():
    """A hitch behind the rear axle (truck and full trailer), an axle ahead of a kingpin,
    a coupling at the CG: legal chains, accepted."""
    v = load_vehicle(EXAMPLES / "truck_full_trailer.toml")
    assert v.units[0].rear_coupling_m < v.units[0].rearmost_axle.x_m
    ax = Axle("a", 3.0, 4, 1e5, 0.0, 0.0, 0.0)
    Vehicle("odd", (Unit("t", 9000.0, 3e4, (Axle("s", 1.0, 2, 2e5, 0.0, 0.0, 0.0),), None, 0.0),
                    Unit("x", 5000.0, 2e4, (ax,), 1.0)))


def test_the_api_checks_as_the_files_do():
    with pytest.raises(VehicleError, match="mass_kg must be a number"):
        Unit("u", "heavy", 1.0, (Axle("a", 0.0, 2, 1e5, 0.0, 0.0, 0.0),))
    with pytest.raises(VehicleError, match="at least one unit"):
        Vehicle("empty", ())
    with pytest.raises(VehicleError, match="tires must be an integer"):
        Axle("a", 0.0, 0, 1e5, 0.0, 0.0, 0.0)


# ---------------------------------------------------------------------------- presets and examples as files
@pytest.mark.parametrize("name", PRESETS)
def test_preset_files_are_the_thesis_tables_converted(name):
    """The shipped files are what lcvreport.thesis.vehicles makes of the tables: one source."""
    assert preset_path(name).read_text(encoding="utf-8") == preset_file_text(name)


@pytest.mark.parametrize("name", PRESETS)
@pytest.mark.parametrize("masses", ["table", "unrounded"])
def test_presets_as_files_build_the_matrices_of_before_to_1e_12(name, masses):
    """The thesis-unit matrices, input and load vectors of commit 7c31b7f (tests/data, made by
    tests/data/make_thesis_matrices_snapshot.py before the SI core), row-relative 1e-12."""
    snap = np.load(ROOT / "tests" / "data" / "thesis_matrices_7c31b7f.npz")
    key = f"{name}/{masses}"
    if f"{key}/M" not in snap:
        pytest.skip("no unrounded masses for this preset")
    v = load_preset(name, masses)
    co = system_coefficients(v, THESIS)
    u = snap["speeds_in_per_s"] * THESIS.length_m
    units = list(v.unit_names[1:])
    got = {"M": co.M(u), "S": co.S(u, 1.0), "S_scale0.8": co.S(u, 0.8), "B_delta": co.B_delta(1.0), "B_P": co.B_P,
           "B_T": co.B_T, "F_consistent": load_vector(v, one_percent_rule(v, units), "consistent", THESIS),
           "F_thesis": load_vector(v, one_percent_rule(v, units), "thesis", THESIS)}
    for k, g in got.items():
        ref = snap[f"{key}/{k}"]
        assert g.shape == ref.shape, k
        scale = np.abs(ref).max(axis=-1, keepdims=True)
        assert np.all(np.abs(g - ref) <= 1e-12 * scale), f"{k}: {np.max(np.abs(g - ref) / np.where(scale > 0, scale, 1)):.2e}"
        assert np.array_equal(g == 0, ref == 0), f"{k}: zero pattern"


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_example_files_are_what_their_script_writes(name):
    sys.path.insert(0, str(EXAMPLES))
    try:
        import make_examples
    finally:
        sys.path.remove(str(EXAMPLES))
    text = (EXAMPLES / f"{name}.toml").read_text()
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    assert "# " in text.splitlines()[0]          # where the numbers come from, first line
    built = {"western_double": make_examples.western_double}.get(name)
    if built is not None:
        made = built()
    else:
        spec = {"b_double": make_examples.B_DOUBLE, "truck_full_trailer": make_examples.TRUCK_FULL_TRAILER}[name]
        made = make_examples.chain(name, v.description, spec)
    made = make_examples.with_roll(made)
    # the tire coefficients come from least-squares fits (LAPACK): their last digits depend on
    # the BLAS kernel of the machine (3 ulp seen between two x86-64 kernels), so numbers are
    # compared to 1e-13 relative and everything else exactly
    a, b = _flat(made), _flat(v)
    numbers = [i for i, x in enumerate(b) if isinstance(x, float)]
    assert [x for i, x in enumerate(a) if i not in numbers] == [x for i, x in enumerate(b) if i not in numbers]
    assert [a[i] for i in numbers] == pytest.approx([b[i] for i in numbers], rel=1e-13, abs=0.0)


def _flat(vehicle) -> list:
    out = [vehicle.name, vehicle.description]
    for unit in vehicle.units:
        out += [getattr(unit, f) for f in unit.__dataclass_fields__ if f != "axles"]
        for axle in unit.axles:
            out += [getattr(axle, f) for f in axle.__dataclass_fields__]
    return out


def test_example_vehicles_are_what_they_say(example):
    kinds = {"western_double": 4, "b_double": 3, "truck_full_trailer": 3}
    assert example.n_units == kinds[example.name]
    if example.name != "western_double":   # derived by statics: the axles carry the masses exactly
        loads = sum(a.static_load_N for a in example.axles)
        assert loads == pytest.approx(sum(u.mass_kg for u in example.units) * 9.80665, rel=1e-12)


@settings(max_examples=30, deadline=None, derandomize=True)
@given(vehicles())
def test_dumps_loads_round_trip_exactly(vehicle):
    assert loads_vehicle(dumps_vehicle(vehicle)) == vehicle


@pytest.mark.parametrize("name", PRESETS)
def test_presets_round_trip(name):
    v = load_preset(name)
    assert loads_vehicle(dumps_vehicle(v)) == v


def test_a_description_with_control_characters_is_refused_in_the_api_too():
    """It goes into modelDescription.xml, C sources and reports (issue 22)."""
    v = load_preset("tractor_semitrailer")
    with pytest.raises(VehicleError, match="control character U\\+0001"):
        Vehicle("x", v.units, "a\x01b")
