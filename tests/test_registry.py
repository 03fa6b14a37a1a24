"""The measure registry is the one list of measures: every printed key is registered, every
family's functions exist and agree with each other, criteria and studies accept exactly its
keys, and a new measure is one function and one entry (nothing else to touch)."""
from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import lcvreport.measures.registry as registry
from lcvreport import load_preset, load_vehicle
from lcvreport.analysis.batch import VariantBatch
from lcvreport.measures.criteria import CriteriaError, load_criteria
from lcvreport.measures.measure_set import batch_measures, measure_set, residual_force
from lcvreport.measures.registry import (BATCHED, CRITERIA_KEYS, FAMILIES, MEASURES, Family, Measure, MeasureCase,
                                         _resolve)
from lcvreport.study.spec import MEASURES as STUDY_MEASURES
from lcvreport.study.spec import StudyError, study_from_dict

ROOT = Path(__file__).resolve().parents[1]
U = 88 / 3.6


def _printed_keys(doc: dict) -> set[str]:
    keys = {k for k in doc if k not in ("reasons", "trim")}
    if "trim" in doc:
        keys |= {f"trim.{k}" for k in doc["trim"]}
    return keys


def test_the_keys_lcv_measures_prints_are_exactly_the_registry():
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "aucnat", "--speed-kph", "88",
                        "--load", "trailer3", "--json"], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert _printed_keys(json.loads(p.stdout)) == set(MEASURES)


def test_every_family_is_registered_once_and_its_functions_exist():
    named = {m.family for m in MEASURES.values() if m.family}
    assert named == set(FAMILIES)                          # no family without a measure, no measure without one
    for f in FAMILIES.values():
        assert f.keys, f.name
        assert callable(_resolve(f.scalar)), f.scalar
        if f.batched:
            assert callable(_resolve(f.batched)), f.batched
            assert BATCHED[f.name] == f.batched_keys
        assert f.model in ("yaw_plane", "low_speed", "yaw_roll", "nonlinear")
        assert f.needs in ("", "steer", "sources", "geometry")


def test_a_family_computes_exactly_its_keys():
    v = load_preset("aucnat")
    case = MeasureCase(v, U, 1.0, 0.4, residual_force(v, ["trailer3"]))
    for f in FAMILIES.values():
        values, reasons = f.compute(case)
        assert set(values) == set(f.keys), f.name
        assert set(reasons) <= set(f.keys) | {"trim"}, f.name
        assert all(reasons.get(k) for k, x in values.items() if x is None), (f.name, reasons)


def test_every_batched_family_equals_its_scalar_one_for_a_batch_of_one():
    """The two functions of every family are independent code paths (one variant at a time,
    and the variants over a leading axis): they agree to 1e-10 on a vehicle of every kind."""
    for v in (load_preset("aucnat"), load_vehicle(ROOT / "examples/vehicles/b_double.toml")):
        F = residual_force(v, [v.unit_names[-1]])
        case = MeasureCase(v, U, 1.0, 0.4, F)
        batch = VariantBatch(v, {f"{v.unit_names[-1]}.mass_kg": np.array([v.units[-1].mass_kg])})
        bcase = MeasureCase(v, U, 1.0, 0.4, F[None, :])
        for f in FAMILIES.values():
            if not f.batched:
                continue
            values, _ = f.compute(case)
            arrays = f.compute_batched(batch, bcase)
            assert list(arrays) == list(f.batched_keys), f.name
            for key, arr in arrays.items():
                want = values[key]
                if want is None:
                    assert np.isnan(arr[0]), (f.name, key)
                else:
                    assert arr[0] == pytest.approx(want, rel=1e-10, abs=1e-13), (f.name, key)


def test_measure_set_holds_every_registered_key_and_nothing_else():
    v = load_preset("tractor_semitrailer")
    m = measure_set(v, U, load_units=["trailer1"])
    assert set(m.values) == set(MEASURES) - {"speed_mps"}
    for key in MEASURES:
        assert m.value(key) == (m.speed_mps if key == "speed_mps" else m.values[key])
    assert m.hsso_m == m.values["hsso_m"]
    with pytest.raises(AttributeError):
        m.not_a_measure


def test_batch_measures_has_a_column_for_every_batched_key():
    v = load_preset("aucnat")
    b = VariantBatch(v, {"trailer3.mass_kg": v.units[5].mass_kg * np.array([0.9, 1.1])})
    t = batch_measures(b, U)
    assert set(t) == {"case_id", "trailer3.mass_kg", "speed_mps"} | {k for f, keys in BATCHED.items()
                                                                      if f != "trim" for k in keys}


def test_criteria_and_studies_take_exactly_the_registry_keys(tmp_path):
    assert set(STUDY_MEASURES) == set(CRITERIA_KEYS)
    assert set(CRITERIA_KEYS) == {k for k, m in MEASURES.items() if m.shape == "scalar" and m.family}
    for key in CRITERIA_KEYS:
        crit = tmp_path / "c.toml"
        crit.write_text(f'[limits]\n"{key}" = {{ max = 1.0, source = "test" }}\n')
        assert key in load_criteria(crit).limits
        study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": [key],
                         "factors": {"trailer1.mass_scale": {"values": [1.0]}}})
    crit = tmp_path / "c.toml"                          # a key of the last release: read as today's
    crit.write_text('[limits]\n"trim_offtracking_m" = { max = 1.0, source = "test" }\n')
    assert list(load_criteria(crit).limits) == ["trim.offtracking_m"]
    for bad in ("ay_gain_per_unit", "speed_mps", "hsso"):
        crit = tmp_path / "c.toml"
        crit.write_text(f'[limits]\n"{bad}" = {{ max = 1.0, source = "test" }}\n')
        with pytest.raises(CriteriaError):
            load_criteria(crit)
        with pytest.raises(StudyError):
            study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": [bad],
                             "factors": {"trailer1.mass_scale": {"values": [1.0]}}})


def _twice_hsso(case):
    """A measure a newcomer adds: a function of the case and its reason."""
    from lcvreport.measures.offtracking import steady_turn
    return {"twice_hsso_m": 2.0 * steady_turn(case.vehicle, case.speed_mps, case.tire_scale).hsso_m}, {}


def test_a_new_measure_is_one_function_and_one_entry(monkeypatch):
    """Registering a family and its measure is all it takes: measure_set, the JSON, the tables,
    criteria keys (new readers of the tables) see it."""
    monkeypatch.setattr(registry, "_resolve", lambda ref: _twice_hsso if ref == "test:twice" else _resolve(ref))
    families = dict(FAMILIES)
    families["twice"] = Family("twice", "test:twice", None, needs="steer")
    measures = dict(MEASURES)
    measures["twice_hsso_m"] = Measure("twice_hsso_m", "twice HSSO", "m", "2 HSSO", "test", family="twice",
                                       limit="max")
    monkeypatch.setattr(registry, "FAMILIES", families)
    monkeypatch.setattr(registry, "MEASURES", measures)
    import lcvreport.measures.measure_set as ms
    monkeypatch.setattr(ms, "FAMILIES", families)
    monkeypatch.setattr(ms, "MEASURES", measures)
    m = measure_set(load_preset("tractor_semitrailer"), U)
    assert m.twice_hsso_m == pytest.approx(2 * m.hsso_m, rel=1e-15)
    doc = m.to_dict()
    assert list(doc)[-2] == "twice_hsso_m" and doc["twice_hsso_m"] == m.twice_hsso_m
    assert any(r["json_key"] == "twice_hsso_m" and r["unit"] == "m" for r in m.rows())


def test_no_steered_axle_gives_every_steer_measure_its_reason():
    v = load_preset("tractor_semitrailer")
    units = list(v.units)
    units[0] = replace(units[0], axles=tuple(replace(a, steered=False) for a in units[0].axles))
    m = measure_set(replace(v, units=tuple(units)), U)
    for f in FAMILIES.values():
        if f.needs == "steer":
            for k in f.keys:
                assert m.value(k) is None and "no steered axle" in m.reason(k), k


def test_families_give_mappings_a_new_key_shifts_nothing(monkeypatch):
    """Issue 41 item 5: a family's batched values are a mapping by key.  A key added to the lane
    change's batched function reaches no other key (the roll family reads the lane change by name,
    not by position), and a batched function whose tuple no longer matches its family's keys is
    refused, never read shifted."""
    import functools

    import numpy as np

    from lcvreport.analysis.batch import VariantBatch
    from lcvreport.measures import offtracking, roll
    from lcvreport.measures.registry import FAMILIES, MeasureCase
    from lcvreport.model.vehicle_file import load_vehicle

    from conftest import EXAMPLES
    v = load_vehicle(EXAMPLES / "b_double.toml")
    b = VariantBatch(v, {"rear_trailer.mass_kg": v.units[-1].mass_kg * np.array([0.9, 1.0])})
    before = roll.roll_batched(b, 25.0)
    real = offtracking.lane_change_batched

    @functools.wraps(real)
    def with_a_new_key(*args, **kwargs):
        out = real(*args, **kwargs)
        return {"final_offset_m": np.zeros(2), **out}            # a key added first: positions all move
    monkeypatch.setattr(offtracking, "lane_change_batched", with_a_new_key)
    after = roll.roll_batched(b, 25.0)
    assert list(after) == list(before)
    for key in before:
        np.testing.assert_array_equal(after[key], before[key])
    case = MeasureCase(v, 25.0, 1.0, 0.4)
    got = FAMILIES["lane_change"].compute_batched(b, case)
    assert list(got) == ["hsto_m", "ra_lane_change"]
    monkeypatch.setattr(offtracking, "lane_change_batched", lambda *a, **k: (np.zeros(2),) * 3)
    with pytest.raises(TypeError, match="gives 3 arrays for 2 keys"):
        FAMILIES["lane_change"].compute_batched(b, case)
