"""``lcv assess`` and scheme files (docs/assessment.md): each measure at its own conditions,
the same numbers ``lcv measures`` gives at those conditions one by one, verdicts per level,
the level reached, and one line for every bad scheme before anything is computed."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest

from lcvreport import load_preset, load_vehicle
from lcvreport.measures.assess import assess
from lcvreport.measures.scheme import SchemeError, load_scheme, loads_scheme

from conftest import EXAMPLES, ROOT

LCV = [sys.executable, "-m", "lcvreport.cli"]
TEMPLATE = ROOT / "examples" / "schemes" / "template.toml"

#: conditions no example, test or default uses (a "hidden" scheme), each measure its own
HIDDEN = """
scheme = "hidden"
levels = ["A", "B"]
[measures.hsto_m]
speed_kph = 73.3
lane_change_ay_g = 0.21
lane_change_frequency_hz = 0.33
source = "test"
levels = { A = { max = 0.3 }, B = { max = 3.0 } }
[measures.ra_lane_change]
speed_kph = 73.3
lane_change_ay_g = 0.21
lane_change_frequency_hz = 0.33
source = "test"
levels = { A = { max = 1.0 }, B = { max = 3.0 } }
[measures.hsso_m]
speed_kph = 91.7
steady_turn_radius_m = 611.0
source = "test"
levels = { A = { max = 0.3 }, B = { max = 3.0 } }
[measures.ra_yaw_rate_single_sine]
speed_kph = 67.1
ra_frequency_hz = 0.29
source = "test"
levels = { A = { max = 1.0 }, B = { max = 4.0 } }
[measures.ra_single_sine]
speed_kph = 67.1
ra_frequency_hz = 0.29
source = "test"
levels = { A = { max = 1.0 }, B = { max = 4.0 } }
[measures.yaw_damping_coefficient]
speed_kph = 91.7
source = "test"
levels = { A = { min = 0.3 }, B = { min = 0.1 } }
[measures.lssp_m]
turn_radius_m = 14.2
turn_angle_deg = 137.0
source = "test"
levels = { A = { max = 7.0 }, B = { max = 12.0 } }
[measures.frontal_swing_m]
turn_radius_m = 14.2
turn_angle_deg = 137.0
source = "test"
levels = { A = { max = 0.5 }, B = { max = 1.0 } }
[measures.tasp_m]
speed_kph = 91.7
crossfall_percent = -2.7
source = "test"
levels = { A = { max = 2.6 }, B = { max = 3.0 } }
[measures."trim.offtracking_m"]
speed_kph = 91.7
crossfall_percent = -2.7
source = "test"
levels = { A = { max = 0.05, abs = true }, B = { max = 0.5, abs = true } }
[measures.srt_rrcu_g]
source = "test"
levels = { A = { min = 0.5 }, B = { min = 0.35 } }
[measures.rltr_lane_change]
speed_kph = 77.0
lane_change_ay_g = 0.12
lane_change_frequency_hz = 0.45
source = "test"
levels = { A = { max = 0.3 }, B = { max = 0.9 } }
[measures.ra_lane_change_roll]
speed_kph = 77.0
lane_change_ay_g = 0.12
lane_change_frequency_hz = 0.45
source = "test"
levels = { A = { max = "2 * srt_rrcu_g" }, B = { max = "8 * srt_rrcu_g" } }
"""

#: the lcv measures option of every condition
OPTION = {"speed_kph": "--speed-kph", "ra_frequency_hz": "--ra-frequency-hz", "lane_change_ay_g": "--lane-change-ay-g",
          "lane_change_frequency_hz": "--lane-change-frequency-hz", "steady_turn_radius_m": "--steady-turn-radius-m",
          "turn_radius_m": "--turn-radius-m", "turn_angle_deg": "--turn-angle-deg",
          "crossfall_percent": "--crossfall-percent", "ra_numerator": "--ra-numerator",
          "ra_denominator": "--ra-denominator"}


def _run(args, **kw):
    return subprocess.run(LCV + args, capture_output=True, text=True, **kw)


@pytest.mark.parametrize("name", ["b_double", "truck_full_trailer"])
def test_a_hidden_scheme_gives_the_numbers_of_lcv_measures_one_by_one(tmp_path, name):
    scheme = tmp_path / "hidden.toml"
    scheme.write_text(HIDDEN)
    vehicle = str(EXAMPLES / f"{name}.toml")
    p = _run(["assess", "--vehicle", vehicle, "--scheme", str(scheme), "--json"])
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["scheme"] == "hidden" and doc["levels"] == ["A", "B"]
    assert [m["key"] for m in doc["measures"]] == [m.key for m in load_scheme(scheme).measures]
    cache = {}
    for m in doc["measures"]:
        cond = m["conditions"]
        args = ["measures", "--vehicle", vehicle, "--json"]
        for k, v in cond.items():
            args += [OPTION[k], v if isinstance(v, str) else repr(v)]
        if "speed_kph" not in cond:
            args += ["--speed-kph", "88"]                     # a measure the speed plays no part in
        key = tuple(args)
        if key not in cache:
            q = _run(args)
            assert q.returncode == 0, q.stderr
            cache[key] = json.loads(q.stdout)
        ref = cache[key]
        expected = ref["trim"]["offtracking_m"] if m["key"] == "trim.offtracking_m" else ref[m["key"]]
        assert m["value"] == expected, (m["key"], cond)
        assert set(m["verdicts"]) == {"A", "B"} and m["verdicts"]["B"] in ("pass", "fail")
    # the conditions are the ones the scheme gave, nothing else
    hsto = next(m for m in doc["measures"] if m["key"] == "hsto_m")
    assert hsto["conditions"] == {"speed_kph": 73.3, "lane_change_ay_g": 0.21, "lane_change_frequency_hz": 0.33}
    srt = next(m for m in doc["measures"] if m["key"] == "srt_rrcu_g")
    assert srt["conditions"] == {}


def test_verdicts_and_levels_follow_the_limits():
    """On aucnat (no roll data) at 100 km/h: HSSO 0.6 m or so; a measure that passes only the
    second level reaches it; the SRT is not computed (no roll data, the key named) and the
    vehicle then reaches no level; without it the vehicle reaches the last level every
    measure passes."""
    v = load_preset("aucnat")
    text = textwrap.dedent("""
        scheme = "levels"
        levels = ["L1", "L2", "L3"]
        [measures.hsso_m]
        speed_kph = 100.0
        source = "t"
        levels = { L1 = { max = 0.1 }, L2 = { max = 5.0 }, L3 = { max = 5.0 } }
        [measures.lssp_m]
        source = "t"
        levels = { L1 = { max = 1.0 }, L2 = { max = 2.0 }, L3 = { max = 20.0 } }
        """)
    a = assess(v, loads_scheme(text))
    hsso, lssp = a.measures
    assert hsso.verdicts == {"L1": "fail", "L2": "pass", "L3": "pass"} and hsso.level_reached == "L2"
    assert "fails L1: hsso_m <= 0.1" in hsso.reason
    assert lssp.level_reached == "L3" and a.level_reached == "L3"
    with_srt = text + '[measures.srt_rrcu_g]\nsource = "t"\nlevels = { L1 = { min = 0.3 }, L2 = { min = 0.3 }, ' \
                      'L3 = { min = 0.3 } }\n'
    b = assess(v, loads_scheme(with_srt))
    srt = b.measures[-1]
    assert srt.value is None and set(srt.verdicts.values()) == {"not computed"} and srt.level_reached is None
    assert "cg_height_m" in srt.reason and b.level_reached is None and "srt_rrcu_g" in b.reason


def test_a_relative_limit_takes_the_other_measure_and_a_null_bound_decides():
    """RA relative to the SRT: the bound is factor * SRT of the same vehicle; the yaw damping
    coefficient of a vehicle whose every joint is heavily damped is null with its lower bound,
    which passes a min at or below it."""
    v = load_vehicle(EXAMPLES / "b_double.toml")
    a = assess(v, loads_scheme("""
        scheme = "r"
        levels = ["L1"]
        [measures.ra_lane_change_roll]
        speed_kph = 88.0
        source = "t"
        levels = { L1 = { max = "2.0 * srt_rrcu_g" } }
        """.replace("\n        ", "\n")))
    from lcvreport.measures.measure_set import measure_set
    from lcvreport.units import kph_to_mps
    m = measure_set(v, kph_to_mps(88.0))
    ra = a.measures[0]
    assert ra.value == m.ra_lane_change_roll
    assert ra.verdicts["L1"] == ("pass" if m.ra_lane_change_roll <= 2.0 * m.srt_rrcu_g else "fail")
    assert f"{2.0 * m.srt_rrcu_g:g}" in ra.notes["L1"]
    ydc = """
        scheme = "y"
        levels = ["L1", "L2"]
        [measures.yaw_damping_coefficient]
        speed_kph = 30.0
        source = "t"
        levels = { L1 = { min = 0.8 }, L2 = { min = 0.5 } }
        """.replace("\n        ", "\n")
    y = assess(load_preset("tractor_semitrailer"), loads_scheme(ydc)).measures[0]
    assert y.value is None                                  # every joint heavily damped: at least 0.6901
    # L1's 0.8 is above the bound (undecided), L2's 0.5 below it (passed): it reaches L2 at least
    assert y.verdicts == {"L1": "not computed", "L2": "pass"} and y.level_reached == "L2"
    assert "0.6901" in y.reason


def test_the_template_assesses_every_example_and_prints_the_table():
    for name in ("b_double", "western_double", "truck_full_trailer"):
        p = _run(["assess", "--vehicle", str(EXAMPLES / f"{name}.toml"), "--scheme", str(TEMPLATE)])
        assert p.returncode == 0 and not p.stderr, p.stderr
        lines = p.stdout.splitlines()
        assert "TEMPLATE" in lines[0] and "L1" in lines[2] and "reached" in lines[2]
        assert sum(1 for line in lines if line.startswith("  ") and line.split()[0] in
                   {m.key for m in load_scheme(TEMPLATE).measures}) >= 11
        assert any(line.startswith("  level reached by the vehicle:") for line in lines)


BAD = [
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto]\nspeed_kph = 80.0\nsource = "s"\nlevels = { L1 = { max = 1.0 } }',
     "measures.hsto: unknown measure 'hsto'"),
    ('scheme = "x"\nlevels = ["L1", "L2"]\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\n'
     'levels = { L1 = { max = 1.0 } }', "measures.hsto_m.levels: no limit for level 'L2'"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\nlevels = { L1 = {} }',
     "measures.hsto_m.levels.L1: a level without a limit"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\nlevels = { L1 = { min = 1.0 } }',
     "measures.hsto_m.levels.L1: hsto_m is limited by a max (a larger value is worse), got min"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.srt_rrcu_g]\nsource = "s"\nlevels = { L1 = { max = 1.0 } }',
     "srt_rrcu_g is limited by a min"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 900.0\nsource = "s"\nlevels = { L1 = { max = 1.0 } }',
     "measures.hsto_m.speed_kph must be in [0.36, 252] km/h, got 900"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nlane_change_ay_g = 5.0\nsource = "s"\n'
     'levels = { L1 = { max = 1.0 } }', "measures.hsto_m.lane_change_ay_g must be in (0, 2] g, got 5"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nturn_radius_m = 12.0\nsource = "s"\n'
     'levels = { L1 = { max = 1.0 } }', "measures.hsto_m.turn_radius_m: a condition of another measure"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nsource = "s"\nlevels = { L1 = { max = 1.0 } }',
     "measures.hsto_m.speed_kph: give the forward speed"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.ay_gain_per_unit]\nspeed_kph = 80.0\nsource = "s"\n'
     'levels = { L1 = { max = 1.0 } }', "is a list"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nlevels = { L1 = { max = 1.0 } }',
     "measures.hsto_m.levels.L1.source"),
    ('scheme = "x"\nlevels = ["L1"]\nlimits = 3\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\n'
     'levels = { L1 = { max = 1.0 } }', "limits: not a key of a scheme file"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\n'
     'levels = { L1 = { max = 1.0 }, L9 = { max = 1.0 } }', "measures.hsto_m.levels.L9: not a level"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\n'
     'levels = { L1 = { max = "2 * hsso_m" } }', "relative to hsso_m, which depends on steady_turn_radius_m"),
    ('scheme = "x"\nlevels = []\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\nlevels = { L1 = { max = 1.0 } }',
     "levels: a list of level names"),
    ('scheme = "x"\nlevels = ["L1"]\n[measures.hsto_m]\nspeed_kph = 80.0\nsource = "s"\n'
     'levels = { L1 = { max = nan } }', "measures.hsto_m.levels.L1.max must be a finite number"),
]


@pytest.mark.parametrize("text,message", BAD)
def test_a_bad_scheme_is_one_line_naming_the_key_before_anything_is_computed(tmp_path, text, message):
    with pytest.raises(SchemeError, match=None) as exc:
        loads_scheme(text)
    assert message in str(exc.value) and "\n" not in str(exc.value)
    f = tmp_path / "s.toml"
    f.write_text(text)
    p = _run(["assess", "--preset", "aucnat", "--scheme", str(f)], timeout=60)
    assert p.returncode == 2 and p.stdout == "", p.stderr
    assert p.stderr.count("\n") == 1 and message in p.stderr and "--scheme" in p.stderr


def test_a_scheme_on_a_fifo_is_refused_without_reading(tmp_path):
    fifo = tmp_path / "scheme.toml"
    os.mkfifo(fifo)
    p = _run(["assess", "--preset", "aucnat", "--scheme", str(fifo)], timeout=30)
    assert p.returncode == 2 and "FIFO" in p.stderr and p.stderr.count("\n") == 1
