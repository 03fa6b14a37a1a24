"""Every command of ``lcv`` has its function in the public API (issue 44, item 1): the function of
each command is a name of ``lcvreport.__all__``, and its result's ``to_dict()`` is what the command
prints with ``--json`` (read back through JSON: the CLI's floats are Python's repr, exact).  Commands
that write folders (``fmu``, ``report``) are held to calling their function."""
from __future__ import annotations

import io
import json

import numpy as np
import pytest

import lcvreport
from lcvreport.cli.main import COMMANDS, build_parser, run

from conftest import EXAMPLES

#: ``lcv`` command -> the public function it is the command line of
API_OF = {"presets": "PRESETS", "eig": "modes", "matrices": "system_matrices", "steady": "steady_state",
          "simulate": "respond", "measures": "measure_set", "fmu": "build_fmus", "report": "build_report",
          "tracking stats": "tracking_stats", "tracking place": "place_tires", "turn": "low_speed_turn",
          "turn --model nonlinear": "turn_with_tire_forces", "study": "run_study", "roll": "roll",
          "assess": "assess"}

B_DOUBLE = str(EXAMPLES / "b_double.toml")
SCHEME = str(EXAMPLES.parent / "schemes" / "template.toml")


def _json(*argv) -> object:
    out = io.StringIO()
    assert run(list(argv), out=out) == 0
    return json.loads(out.getvalue())


def _same(api: dict) -> object:
    """What a dict reads as after the CLI's JSON (tuples become lists)."""
    return json.loads(json.dumps(api))


def test_every_command_has_its_public_function():
    sub = build_parser()._subparsers._group_actions[0].choices
    tracking = sub["tracking"]._subparsers._group_actions[0].choices
    commands = {c for c in COMMANDS if c != "tracking"} | {f"tracking {t}" for t in tracking}
    assert commands == {c for c in API_OF if "--" not in c}
    for name in API_OF.values():
        assert name in lcvreport.__all__, name
        assert getattr(lcvreport, name) is not None


def test_eig_matrices_steady_presets():
    v = lcvreport.load_preset("aucnat")
    u = lcvreport.units.kph_to_mps(88.0)
    assert _json("presets", "--json") == {"presets": list(lcvreport.PRESETS)}
    assert _json("eig", "--preset", "aucnat", "--speed-kph", "88", "--json") == _same(lcvreport.modes(v, u).to_dict())
    rv = lcvreport.load_vehicle(B_DOUBLE)
    assert _json("eig", "--vehicle", B_DOUBLE, "--speed-kph", "88", "--model", "yaw-roll", "--tire-scale", "0.9",
                 "--json") == _same(lcvreport.modes(rv, u, 0.9, model="yaw_roll").to_dict())
    doc = _json("matrices", "--preset", "aucnat", "--speed-kph", "88", "--units", "si", "--json")
    M, S = lcvreport.system_matrices(v, u)
    assert doc["M"] == M.tolist() and doc["S"] == S.tolist()
    doc = _json("steady", "--preset", "aucnat", "--speed-kph", "88", "--load", "trailer1", "--json")
    F = lcvreport.load_vector(v, lcvreport.one_percent_rule(v, ["trailer1"], t_sign=1.0))
    x = lcvreport.steady_state(v, u, F)
    assert list(doc["state"].values()) == x.tolist()


def test_simulate_is_respond():
    from lcvreport.manoeuvres.steer import sine
    from lcvreport.model.yaw_plane.loads import ResidualLoads, ResidualSources
    v = lcvreport.load_vehicle(B_DOUBLE)
    doc = _json("simulate", "--vehicle", B_DOUBLE, "--speed-kph", "88", "--steer", "sine:0.01:0.4", "--t-end", "3",
                "--dt", "0.05", "--residual", "a1=200,-50", "--json")
    src = ResidualSources(ResidualLoads({"a1": 200.0}, {"a1": -50.0}))
    r = lcvreport.respond(v, "yaw_plane", sine(0.01, 0.4), lcvreport.units.kph_to_mps(88.0), 3.0, 0.05, sources=src)
    assert doc == _same(r.to_dict())
    doc = _json("simulate", "--vehicle", B_DOUBLE, "--speed-kph", "60", "--steer", "step:0.01", "--t-end", "1",
                "--dt", "0.1", "--model", "nonlinear", "--json")
    r = lcvreport.respond(v, "nonlinear", lcvreport.manoeuvres.steer.step(0.01), lcvreport.units.kph_to_mps(60.0), 1.0, 0.1)
    assert doc == _same(r.to_dict())


def test_measures_is_measure_set():
    v = lcvreport.load_preset("aucnat")
    doc = _json("measures", "--preset", "aucnat", "--speed-kph", "88", "--json")
    assert doc == _same(lcvreport.measure_set(v, lcvreport.units.kph_to_mps(88.0)).to_dict())


def test_roll_turn_tracking():
    v = lcvreport.load_vehicle(B_DOUBLE)
    assert _json("roll", "--vehicle", B_DOUBLE, "--speed-kph", "88", "--json") == \
        _same(lcvreport.roll(v, lcvreport.units.kph_to_mps(88.0)).to_dict())
    assert _json("turn", "--vehicle", B_DOUBLE, "--radius", "11", "--angle-deg", "120", "--json") == \
        _same(lcvreport.low_speed_turn(v, 11.0, 120.0).to_dict())
    assert _json("turn", "--vehicle", B_DOUBLE, "--model", "nonlinear", "--friction-coefficient", "0.7", "--json") == \
        _same(lcvreport.turn_with_tire_forces(v, friction_coefficient=0.7).to_dict())
    a = lcvreport.load_preset("aucnat")
    u = lcvreport.units.kph_to_mps(88.0)
    from lcvreport.tracking.statistics import parse_distribution
    doc = _json("tracking", "stats", "--preset", "aucnat", "--speed-kph", "88", "--conicity", "normal:0:120",
                "--ply-steer", "uniform:-50:50", "--mounting", "random", "--draws", "2000", "--seed", "7", "--json")
    s = lcvreport.tracking_stats(a, u, parse_distribution("normal:0:120", "--conicity"),
                                 parse_distribution("uniform:-50:50", "--ply-steer"),
                                 "random", draws=2000, seed=7)
    assert doc == _same(s.to_dict())
    from lcvreport.tracking.placement import read_measured_tires
    tires = str(EXAMPLES.parent / "tires" / "measured_20.csv")
    doc = _json("tracking", "place", "--preset", "aucnat", "--speed-kph", "88", "--tires", tires,
                "--draws", "300", "--json")
    p = lcvreport.place_tires(a, u, read_measured_tires(tires), draws=300)
    assert doc == _same(p.to_dict())


def test_assess_is_assess():
    doc = _json("assess", "--vehicle", B_DOUBLE, "--scheme", SCHEME, "--json")
    assert doc == _same(lcvreport.assess(B_DOUBLE, SCHEME).to_dict())
    assert set(doc["files"]) == {"vehicle", "scheme"}


def test_study_is_run_study(tmp_path):
    study = tmp_path / "s.toml"
    study.write_text(f'vehicle = "aucnat"\nmeasures = ["least_damping_ratio"]\nspeed_kph = 88.0\n[design]\n'
                     f'kind = "grid"\n[factors]\n"trailer1.mass_scale" = {{ values = [0.8, 1.0] }}\n')
    doc = _json("study", str(study), "--out", str(tmp_path / "cli"), "--json")
    api = lcvreport.run_study(lcvreport.load_study(study), tmp_path / "api", progress=False).to_dict()
    for d in (doc, api):
        d.pop("seconds"), d.pop("out")
    assert doc == _same(api)
    assert lcvreport.read_study(tmp_path / "cli").equals(lcvreport.read_study(tmp_path / "api"))


@pytest.mark.parametrize("command, module, name", [
    (["fmu", "--preset", "aucnat", "--out", "{tmp}"], "lcvreport.fmu.build", "build_vehicle_fmus"),
    (["report", "--preset", "aucnat", "--out", "{tmp}/r", "--no-pdf"], "lcvreport.report.build", "build_assessment"),
])
def test_folder_commands_call_their_function(command, module, name, tmp_path, monkeypatch):
    import importlib
    api = {"build_vehicle_fmus": "build_fmus", "build_assessment": "build_report"}[name]
    assert getattr(lcvreport, api) is getattr(importlib.import_module(module), name)
    calls = []

    class Called(Exception):
        pass

    def spy(*args, **kwargs):
        calls.append((args, kwargs))
        raise Called
    monkeypatch.setattr(importlib.import_module(module), name, spy)
    err = io.StringIO()
    monkeypatch.setattr("sys.stderr", err)
    assert run([c.replace("{tmp}", str(tmp_path)) for c in command], out=io.StringIO()) == 1
    assert len(calls) == 1 and "Called" in err.getvalue()
    assert isinstance(calls[0][0][0], lcvreport.Vehicle)
    assert np.isfinite(calls[0][0][0].units[0].mass_kg)


def test_one_version_everywhere():
    """pyproject.toml, ``lcvreport.__version__``, the installed metadata and ``lcv --version`` agree."""
    import tomllib
    from importlib.metadata import version

    from conftest import ROOT
    wanted = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    assert lcvreport.__version__ == wanted == version("lcvreport")
    out = io.StringIO()
    with pytest.raises(SystemExit):
        import contextlib
        with contextlib.redirect_stdout(out):
            build_parser().parse_args(["--version"])
    assert out.getvalue().split() == ["lcv", "(lcvreport)", wanted]
