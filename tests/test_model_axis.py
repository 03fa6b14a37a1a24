"""The model as an axis (issue 41, docs/model.md#the-model-object): measures take a model object
or a model name, their keys are model-neutral, today's ``*_roll`` keys are the neutral keys on the
yaw-roll model; a scheme entry names its model; the nonlinear model gives its responses, its
linearization's eigenvalues and its friction demand, and says why the others are null."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from lcvreport.measures.measure_set import measure_set, measure_values
from lcvreport.measures.registry import FAMILIES, MEASURE_RTOL, MODEL_KEYS, model_of_family
from lcvreport.model.base import VehicleModel, build_model
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLE_NAMES, EXAMPLES

LCV = [sys.executable, "-m", "lcvreport.cli"]
U = 88 / 3.6


@pytest.mark.parametrize("name", ["yaw_plane", "yaw_roll"])
def test_the_linear_models_meet_the_protocol_and_their_derivatives_are_their_linearization(name):
    v = load_vehicle(EXAMPLES / "b_double.toml")
    m = build_model(v, name)
    assert isinstance(m, VehicleModel) and m.name == name and m.kind == "linear"
    lin = m.linearize(U)
    assert lin is m
    rng = np.random.default_rng(7)
    x = rng.normal(size=len(m.state_names)) * 0.01
    w = rng.normal(size=len(m.input_names)) * 0.01
    # derivatives = M^-1 (S x + B w), computed again here from the coefficients
    M, S = m.M(U), m.S(U, 1.0)
    B = m.input_matrix_full(1.0)
    ref = np.linalg.solve(M, S @ x + B @ w)
    got = m.derivatives(0.0, x, w, U)
    assert np.abs(got - ref).max() <= 1e-12 * max(1.0, np.abs(ref).max())


def _same(a: dict, b: dict) -> bool:
    """Two measure sets' JSON equal key by key, bit for bit."""
    assert a.keys() == b.keys()
    for k in a:
        assert a[k] == b[k], k
    return True


def test_a_model_object_gives_the_measure_set_of_its_name():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    for name in ("yaw_plane", "yaw_roll"):
        by_object = measure_set(build_model(v, name), U).to_dict()
        by_name = measure_set(v, U, model=name).to_dict()
        assert _same(by_object, by_name), name
    assert _same(measure_set(v, U).to_dict(), measure_set(v, U, model="yaw_plane").to_dict())


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_the_roll_keys_are_the_neutral_keys_on_the_yaw_roll_model(name):
    """Every example (each has roll data): hsto_m, ra_lane_change, ra_single_sine, the least
    damping ratio and the critical speed of the yaw-roll model equal the default's *_roll keys,
    to the bit; the families of a fixed model (low-speed turn, SRT) are the same on both."""
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    default = measure_set(v, U).to_dict()
    roll = measure_set(v, U, model="yaw_roll").to_dict()
    assert roll["model"] == "yaw_roll" and "model" not in default
    for (key, _model), named in MODEL_KEYS.items():
        assert roll[key] == default[named], key
    for key in ("lssp_m", "srt_rrcu_g", "rltr_lane_change", "hsto_m_roll"):
        assert roll[key] == default[key], key
    assert roll["hsso_m"] is None and "yaw plane" in roll["reasons"]["hsso_m"]


def test_lcv_measures_model_yaw_roll_gives_hsto_m_equal_to_the_defaults_hsto_m_roll():
    args = ["measures", "--vehicle", str(EXAMPLES / "western_double.toml"), "--speed-kph", "88", "--json"]
    a = json.loads(subprocess.run(LCV + args, capture_output=True, text=True, check=True).stdout)
    b = json.loads(subprocess.run(LCV + args + ["--model", "yaw-roll"], capture_output=True, text=True,
                                  check=True).stdout)
    assert b["hsto_m"] == a["hsto_m_roll"] and b["ra_lane_change"] == a["ra_lane_change_roll"]
    bad = subprocess.run(LCV + ["measures", "--preset", "aucnat", "--speed-kph", "88", "--model", "yaw-roll"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "cg_height_m" in bad.stderr


def test_each_family_says_what_it_needs_of_the_model():
    needs = {f.requires for f in FAMILIES.values() if f.model == "yaw_plane"}
    assert needs == {"linear", "response", "inverse", "steady"}
    assert model_of_family(FAMILIES["least_damping"], "nonlinear") == ("yaw_plane", None)
    assert model_of_family(FAMILIES["single_sine"], "nonlinear") == ("nonlinear", None)
    assert model_of_family(FAMILIES["lane_change"], "yaw_roll") == ("yaw_roll", None)
    for fam in ("lane_change", "steady_turn", "trim"):
        assert model_of_family(FAMILIES[fam], "nonlinear")[0] is None
    assert model_of_family(FAMILIES["roll"], "nonlinear") == ("yaw_roll", None)        # a fixed model


def test_the_nonlinear_models_measures():
    """Its linearization's eigenvalues are the yaw plane's (docs/nonlinear.md#reduction-checks);
    its responses differ from the linear ones by what the brush tire does at 0.15 g; the lane
    change of the inverse system and the steady-state families are null with their reasons; the
    friction demand is computed (asked for by the model); a measure's integration tolerance
    (MEASURE_RTOL) gives the strict one's value to its order."""
    v = load_vehicle(EXAMPLES / "western_double.toml")
    plane = measure_set(v, U).to_dict()
    keys = ["least_damping_ratio", "critical_speed_kph", "ra_peak", "ra_single_sine", "yaw_damping_coefficient",
            "hsto_m", "hsso_m", "hsto_driver_m", "stfd"]
    reasons = {}
    nl = measure_values(v, U, keys, model="nonlinear", reasons=reasons)
    assert nl["least_damping_ratio"] == plane["least_damping_ratio"] and nl["ra_peak"] == plane["ra_peak"]
    assert nl["hsto_m"] is None and "inverse system" in reasons["hsto_m"]
    assert nl["hsso_m"] is None and "steady-state equations" in reasons["hsso_m"]
    assert 0.0 < nl["stfd"] < 1.0
    for key in ("ra_single_sine", "yaw_damping_coefficient", "hsto_driver_m"):
        assert nl[key] is not None and abs(nl[key] / plane[key] - 1) < 0.15, key       # near, not equal
    assert nl["hsto_driver_m"] > plane["hsto_driver_m"]        # the brush tire is softer than its slope at 0.15 g
    from lcvreport.measures.amplification import single_sine
    opts = {"tire": "saturating", "friction_coefficient": 0.8}
    loose = single_sine(v, U, model="nonlinear", options={**opts, "rtol": MEASURE_RTOL}).rearward_amplification
    strict = single_sine(v, U, model="nonlinear", options={**opts, "rtol": 1e-8}).rearward_amplification
    assert loose == pytest.approx(strict, rel=1e-6) and loose == pytest.approx(nl["ra_single_sine"], rel=1e-12)


def test_a_scheme_entry_names_its_model_and_the_models_beside_it(tmp_path):
    from lcvreport.measures.assess import assess
    from lcvreport.measures.scheme import SchemeError, loads_scheme
    head = 'scheme = "axis"\nlevels = ["L1"]\n'
    s = loads_scheme(head + '[measures.hsto_m]\nspeed_kph = 88.0\nmodel = "yaw_roll"\nsource = "p"\n'
                            'levels = { L1 = { max = 0.5 } }\n'
                            '[measures.ra_single_sine]\nspeed_kph = 88.0\nbeside = ["yaw-roll"]\nsource = "p"\n'
                            'levels = { L1 = { max = 2.0 } }\n')
    assert [(m.key, m.model, m.beside) for m in s.measures] == [("hsto_m_roll", "yaw_plane", ()),
                                                                ("ra_single_sine", "yaw_plane", ("yaw_roll",))]
    v = load_vehicle(EXAMPLES / "b_double.toml")
    a = assess(v, s)
    default = measure_set(v, U).to_dict()
    assert a.measures[0].value == pytest.approx(default["hsto_m_roll"], rel=1e-13)
    assert list(a.measures[1].beside) == ["yaw_roll"]
    assert a.measures[1].beside["yaw_roll"] == pytest.approx(default["ra_single_sine_roll"], rel=1e-13)
    assert "yaw-roll: " in a.measures[1].value_text()
    with pytest.raises(SchemeError, match=r"measures.hsto_m.model: hsto_m is undefined on the nonlinear model"):
        loads_scheme(head + '[measures.hsto_m]\nspeed_kph = 88.0\nmodel = "nonlinear"\nsource = "p"\n'
                            'levels = { L1 = { max = 0.5 } }\n')
    with pytest.raises(SchemeError, match=r"measures.lssp_m.model: lssp_m is a measure of the low-speed model only"):
        loads_scheme(head + '[measures.lssp_m]\nmodel = "yaw_roll"\nsource = "p"\nlevels = { L1 = { max = 9 } }\n')
    with pytest.raises(SchemeError, match=r"measures.hsto_m.model: one of yaw_plane, yaw_roll, nonlinear"):
        loads_scheme(head + '[measures.hsto_m]\nspeed_kph = 88.0\nmodel = 3\nsource = "p"\n'
                            'levels = { L1 = { max = 0.5 } }\n')


def test_a_nonlinear_verdicts_evidence_is_the_nonlinear_run():
    from lcvreport.measures.assess import assess
    from lcvreport.measures.evidence import evidence
    from lcvreport.measures.scheme import loads_scheme
    s = loads_scheme('scheme = "axis"\nlevels = ["L1"]\n[measures.ra_single_sine]\nspeed_kph = 88.0\n'
                     'model = "nonlinear"\nsource = "p"\nlevels = { L1 = { max = 2.0 } }\n')
    v = load_vehicle(EXAMPLES / "western_double.toml")
    a = assess(v, s)
    ev = evidence(a, a.measures[0])
    assert ev.model == "nonlinear" and ev.result.response.model.name == "nonlinear"
    assert ev.result.rearward_amplification == pytest.approx(a.measures[0].value, rel=1e-12)
    assert "nonlinear model" in a.measures[0].conditions_text()
    fig = ev.plot()
    assert fig.axes


def test_a_study_computes_the_friction_demand_case_by_case(tmp_path):
    from lcvreport.study.compute import compute_chunk
    from lcvreport.study.spec import study_from_dict
    study = study_from_dict({"vehicle": str(EXAMPLES / "western_double.toml"), "measures": ["stfd", "lssp_m"],
                             "design": {"kind": "grid"},
                             "factors": {"speed_kph": {"values": [80.0]},
                                         "tractor.mass_scale": {"values": [1.0, 1.1]}}})
    cols = compute_chunk(study, np.arange(2))
    stfd = np.asarray(cols["stfd"], dtype=float)
    assert np.all(np.isfinite(stfd)) and stfd[0] != stfd[1]
    from lcvreport.measures.friction_demand import turn_with_tire_forces
    vehicle, _u, _kw = study.case(0)                       # its loads by statics (issue 40)
    assert stfd[0] == pytest.approx(turn_with_tire_forces(vehicle).stfd, rel=1e-12)
    assert math.isfinite(float(cols["lssp_m"][0]))


def test_the_registry_chooses_the_evidence_figure_and_a_new_measure_is_drawn_as_its_value(monkeypatch):
    """Issue 41 item 5: a measure added to the lane change's family with no drawing named in the
    registry is drawn as its value against the limits -- not as HSTO's path with the limit past
    the final offset, nor as an RA band on the acceleration axis."""
    from dataclasses import replace

    from lcvreport.measures import registry
    from lcvreport.measures.assess import assess
    from lcvreport.measures.evidence import evidence
    from lcvreport.measures.scheme import loads_scheme
    v = load_vehicle(EXAMPLES / "b_double.toml")
    a = assess(v, loads_scheme('scheme = "t"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 88.0\n'
                               'source = "test"\nlevels = { L1 = { max = 0.6 } }\n'))
    drawn = evidence(a, a.measures[0])
    assert (drawn.kind, drawn.drawing) == ("lane_change", "offset")
    new = replace(registry.MEASURES["hsto_m"], key="hsto_new_m", evidence="value", label="a new lane-change measure")
    monkeypatch.setitem(registry.MEASURES, "hsto_new_m", new)
    verdict = replace(a.measures[0], key="hsto_new_m")
    ev = evidence(a, verdict)
    assert (ev.kind, ev.drawing, ev.result) == ("value", "value", None)
    fig = ev.plot()
    texts = " ".join(t.get_text() for ax in fig.axes for t in ax.texts + [ax.title, ax.xaxis.label])
    assert "final offset" not in texts and "RA" not in texts
    fig_offset = drawn.plot()
    assert any("final offset" in (line.get_label() or "") for ax in fig_offset.axes for line in ax.get_lines()) or \
        any("final offset" in t.get_text() for ax in fig_offset.axes for t in ax.texts)
