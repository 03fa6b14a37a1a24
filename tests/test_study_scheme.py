"""``lcv study ... --scheme FILE`` (docs/studies.md#schemes): every case assessed against the
scheme, the level each measure and each case reach as columns, and in the study report the
share of cases reaching each level."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from lcvreport import read_study
from lcvreport.measures.assess import assess
from lcvreport.study.spec import load_study

from conftest import EXAMPLES

LCV = [sys.executable, "-m", "lcvreport.cli"]

SCHEME = """
scheme = "study scheme"
levels = ["L1", "L2", "L3"]
[measures.srt_rrcu_g]
source = "test"
levels = { L1 = { min = 0.5 }, L2 = { min = 0.45 }, L3 = { min = 0.3 } }
[measures.hsso_m]
speed_kph = 95.0
source = "test"
levels = { L1 = { max = 0.45 }, L2 = { max = 0.6 }, L3 = { max = 2.0 } }
"""

STUDY = f"""
vehicle = "{(EXAMPLES / 'b_double.toml').as_posix()}"
measures = ["hsso_m"]
speed_kph = 88.0
[design]
kind = "grid"
[factors]
"rear_trailer.cg_height_scale" = {{ values = [0.8, 1.0, 1.25] }}
"rear_trailer.mass_scale" = {{ values = [0.7, 1.0] }}
"""


@pytest.mark.xdist_group("study_scheme")
def test_a_study_with_a_scheme_gives_the_levels_of_each_case(tmp_path):
    study_file, scheme_file = tmp_path / "s.toml", tmp_path / "scheme.toml"
    study_file.write_text(STUDY)
    scheme_file.write_text(SCHEME)
    out, rep = tmp_path / "out", tmp_path / "rep"
    p = subprocess.run(LCV + ["study", str(study_file), "--out", str(out), "--scheme", str(scheme_file),
                              "--report", str(rep), "--no-pdf", "--json"], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    table = read_study(out)
    assert len(table) == 6
    study = load_study(study_file).with_scheme(SCHEME)
    levels = []
    for row in table.itertuples():
        vehicle, _speed, kwargs = study.case(int(row.case_id))
        a = assess(vehicle, study.scheme, **{k: kwargs[k] for k in ("tire_scale",) if k in kwargs})
        assert getattr(row, "level_reached") == (a.level_reached or "")
        for m in a.measures:
            assert table.loc[row.Index, f"level.{m.key}"] == (m.level_reached or "")
            assert table.loc[row.Index, f"scheme.{m.key}"] == m.value
        levels.append(a.level_reached or "none")
    assert len(set(levels)) >= 2                                  # the factors move the cases across levels
    html = (rep / "index.html").read_text()
    assert "Table S-4." in html
    for level in ("L1", "L2", "L3"):
        assert f"<td>{level}</td>" in html or f">{level}<" in html
    shares = (rep / "data" / "table_S-4.csv").read_text().splitlines()
    counts = {line.split(",")[1]: int(line.split(",")[2]) for line in shares[1:5] if line.startswith("the case")}
    assert counts == {lv: levels.count(lv) for lv in ("L1", "L2", "L3", "none")}


def test_a_scheme_with_a_speed_factor_is_refused(tmp_path):
    study_file, scheme_file = tmp_path / "s.toml", tmp_path / "scheme.toml"
    study_file.write_text(STUDY.replace('speed_kph = 88.0\n', '').replace(
        '[factors]\n', '[factors]\nspeed_kph = { values = [80.0, 90.0] }\n'))
    scheme_file.write_text(SCHEME)
    p = subprocess.run(LCV + ["study", str(study_file), "--out", str(tmp_path / "o"), "--scheme", str(scheme_file)],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "speed_kph" in p.stderr
    assert not (tmp_path / "o").exists()
    scheme_file.write_text(SCHEME.replace("min = 0.5", "max = 0.5"))
    q = subprocess.run(LCV + ["study", str(study_file), "--out", str(tmp_path / "o"), "--scheme", str(scheme_file)],
                       capture_output=True, text=True, timeout=60)
    assert q.returncode == 2 and "limited by a min" in q.stderr and q.stderr.count("\n") == 1


def test_the_batched_families_of_a_scheme_give_each_case_its_own_assessment():
    """A scheme study's batch (assess.batched_group_values: the roll, rollover, yaw damping, single
    sine and steady-turn families over the block's vehicles) against assess of each vehicle alone:
    every value to 1e-12 relative, every verdict and level the same."""
    import dataclasses

    from lcvreport.measures.assess import batched_group_values
    from lcvreport.measures.scheme import loads_scheme
    from lcvreport.model.vehicle_file import load_vehicle
    text = (EXAMPLES.parents[1] / "examples" / "schemes" / "template.toml").read_text()
    scheme = loads_scheme(text[:text.index("[measures.stfd]")])
    v = load_vehicle(EXAMPLES / "b_double.toml")
    variants = []
    for mass, stiffness, height in ((1.0, 1.0, 1.0), (0.7, 1.1, 1.2), (1.1, 0.9, 0.85), (0.9, 1.05, 1.3)):
        units = [v.units[0]] + [dataclasses.replace(
            u, mass_kg=u.mass_kg * mass, cg_height_m=u.cg_height_m * height,
            axles=tuple(dataclasses.replace(a, cornering_stiffness_N_per_rad=a.cornering_stiffness_N_per_rad * stiffness)
                        for a in u.axles)) for u in v.units[1:]]
        variants.append(dataclasses.replace(v, units=tuple(units)))
    pre = batched_group_values(v, variants, scheme)
    given = {k for groups in pre for g in groups for k in g}
    assert {"srt_rrcu_g", "yaw_damping_coefficient", "rltr_lane_change", "ra_yaw_rate_single_sine",
            "ra_lane_change_roll", "hsto_m_roll", "hsso_m"} <= given          # the batch did the work
    reached = set()
    for w, p in zip(variants, pre):
        alone, batched = assess(w, scheme).to_dict(), assess(w, scheme, precomputed=p).to_dict()
        for a, b in zip(alone["measures"], batched["measures"]):
            assert (a["value"] is None) == (b["value"] is None), a["key"]
            if a["value"] is not None:
                assert b["value"] == pytest.approx(a["value"], rel=1e-12, abs=1e-15), a["key"]
            assert a["verdicts"] == b["verdicts"] and a["level_reached"] == b["level_reached"]
        assert alone["level_reached"] == batched["level_reached"]
        reached.add(tuple(m["level_reached"] for m in alone["measures"]))
    assert len(reached) >= 2                          # the variants' measures reach different levels
