"""One case object (issue 41 item 4): built once from the options, a study row or a script, checked
when made, and computing what the functions of the vehicle compute."""
from __future__ import annotations

import io

import pytest

import lcvreport
from lcvreport import Case
from lcvreport.cli.main import run
from lcvreport.measures.measure_set import measure_set, measure_values
from lcvreport.model.yaw_plane.loads import ResidualLoads, ResidualSources

from conftest import EXAMPLES


def test_a_case_computes_what_the_functions_compute():
    v = lcvreport.load_vehicle(EXAMPLES / "b_double.toml")
    src = ResidualSources(ResidualLoads({"a1": 150.0}, {}), {"b2": 0.002})
    case = Case(v, speed_mps=24.4, tire_scale=0.9, model="yaw-roll", load_units=["lead_trailer"],
                sources=src, conditions={"lane_change_ay_g": 0.2, "ra_frequency_hz": 0.5})
    direct = measure_set(v, 24.4, 0.9, ["lead_trailer"], 0.5, src, {"lane_change_ay_g": 0.2}, "yaw_roll")
    assert case.measure_set().to_dict() == direct.to_dict()
    keys = ["hsto_m", "trim.offtracking_m"]
    assert case.measure_values(keys) == measure_values(v, 24.4, keys, 0.9, ["lead_trailer"], 0.5, src,
                                                       {"lane_change_ay_g": 0.2}, model="yaw_roll")
    a = Case(v, tire_scale=0.9).assess(EXAMPLES.parent / "schemes" / "template.toml")
    b = lcvreport.assess(v, EXAMPLES.parent / "schemes" / "template.toml", 0.9)
    assert [m.value for m in a.measures] == [m.value for m in b.measures]


@pytest.mark.parametrize("kwargs, fragment", [
    ({"model": "yaw-pitch"}, "unknown model 'yaw-pitch'"),
    ({"speed_mps": -1.0}, "speed_mps"),
    ({"tire_scale": float("nan")}, "tire_scale"),
    ({"conditions": {"lane_change_ay_g": 5.0}}, "lane_change"),
    ({"conditions": {"wind_mps": 3.0}}, "unknown condition 'wind_mps'"),
    ({"load_units": ["trailer9"]}, "trailer9"),
    ({"load_units": "tractor"}, "load_units must be a list"),
    ({"sources": ResidualSources(ResidualLoads({"nope": 1.0}, {}))}, "nope"),
])
def test_a_case_refuses_bad_input_when_made(kwargs, fragment):
    with pytest.raises((ValueError, KeyError)) as info:
        Case(lcvreport.load_preset("aucnat"), **kwargs)
    assert fragment in str(info.value.args[0]) and "\n" not in str(info.value.args[0])


def test_the_command_line_builds_the_case_once(monkeypatch):
    """``lcv assess`` and ``lcv measures`` read their options into one Case, once (issue 41: the options
    were read three times per lcv assess), and compute from it."""
    import lcvreport.measures.case as case_module
    made = []
    real = case_module.Case.__post_init__

    def counting(self):
        made.append(self)
        real(self)
    monkeypatch.setattr(case_module.Case, "__post_init__", counting)
    out = io.StringIO()
    assert run(["assess", "--vehicle", str(EXAMPLES / "b_double.toml"), "--scheme",
                str(EXAMPLES.parent / "schemes" / "template.toml"), "--tire-scale", "0.95", "--json"], out=out) == 0
    assert len(made) == 1 and made[0].tire_scale == 0.95
    made.clear()
    assert run(["measures", "--preset", "aucnat", "--speed-kph", "80:88:8", "--json"], out=io.StringIO()) == 0
    assert len(made) == 3          # the case of the options, then the same case at each speed of the sweep
    assert [c.speed_mps for c in made[1:]] == pytest.approx([80 / 3.6, 88 / 3.6])


def test_a_study_row_is_a_case(tmp_path):
    from lcvreport.study.spec import study_from_dict
    s = study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m"],
                         "factors": {"trailer1.mass_scale": {"values": [0.8, 1.2]}, "tire_scale": {"values": [0.9]}}})
    c = s.case_object(1)
    vehicle, speed, kwargs = s.case(1)
    assert c.vehicle == vehicle and c.speed_mps == speed and c.tire_scale == kwargs["tire_scale"] == 0.9
    assert c.measure_values(["hsso_m"]) == measure_values(vehicle, speed, ["hsso_m"], **kwargs)
