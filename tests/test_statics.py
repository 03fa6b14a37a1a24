"""Static axle and coupling loads that follow the masses (issue 40 item 1, docs/vehicle_files.md):
the loads a mass or payload change adds are in equilibrium on every unit (forces and pitch moments,
checked from the coupling loads the model derives, not from the lever rule that made them); a
payload's inertia and CG follow the parallel-axis theorem; a roll study with mass and payload
factors gives, case by case, the SRT of ``lcv roll`` of that case's vehicle written to a file."""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from lcvreport.model.statics import G_MPS2, coupling_loads, load_changes, with_mass, with_payload
from lcvreport.model.vehicle_file import dumps_vehicle, load_vehicle
from lcvreport.study.compute import compute_chunk
from lcvreport.study.spec import StudyError, study_from_dict

from conftest import EXAMPLES

ROLL_EXAMPLES = ("b_double", "western_double")


def _balance(before, after) -> float:
    """The largest residual of the increments' equilibrium over every unit (the mass changed at
    the CG, so the added weight has no moment about it): vertical force and pitch moment, axle
    loads up, the coupling load a unit carries of the units behind down, the coupling load of the
    unit ahead up -- the coupling loads as the roll model derives them from masses and loads."""
    dW = coupling_loads(after) - coupling_loads(before)
    worst = 0.0
    for i, (u0, u1) in enumerate(zip(before.units, after.units)):
        dF = np.array([b.static_load_N - a.static_load_N for a, b in zip(u0.axles, u1.axles)])
        x = np.array([b.x_m for b in u1.axles])
        force = dF.sum() - (u1.mass_kg - u0.mass_kg) * G_MPS2
        moment = dF @ x
        if i > 0:
            force += dW[i - 1]
            moment += dW[i - 1] * u1.front_coupling_m
        if i < before.n_units - 1:
            force -= dW[i]
            moment -= dW[i] * u1.rear_coupling_m
        worst = max(worst, abs(force), abs(moment))
    return worst


@pytest.mark.parametrize("name", ROLL_EXAMPLES + ("truck_full_trailer",))
def test_a_mass_change_is_carried_in_equilibrium_by_every_unit(name):
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    for k, u in enumerate(v.units):
        w = with_mass(v, k, 1.3 * u.mass_kg)
        added = 0.3 * u.mass_kg * G_MPS2
        assert sum(a.static_load_N for a in w.axles) - sum(a.static_load_N for a in v.axles) == \
            pytest.approx(added, rel=1e-12)
        assert _balance(v, w) <= 1e-9 * added * max(1.0, max(abs(a.x_m) for a in w.axles)), (name, u.name)


@pytest.mark.parametrize("name", ROLL_EXAMPLES)
def test_a_weight_anywhere_on_a_unit_is_in_equilibrium(name):
    """load_changes at an arbitrary x: forces and pitch moments of the increments balance."""
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    for k, u in enumerate(v.units):
        for x in (-2.0, 0.0, 1.5):
            delta = load_changes(v, k, 10_000.0, x)
            dW = np.zeros(v.n_units - 1)
            for j in range(v.n_units - 1):          # the units behind joint j carry the weight, less their axles
                behind = 10_000.0 if k > j else 0.0
                dW[j] = behind - sum(d.sum() for d in delta[j + 1:])
            for i, ui in enumerate(v.units):
                xs = np.array([a.x_m for a in ui.axles])
                f = delta[i].sum() - (10_000.0 if i == k else 0.0)
                m = delta[i] @ xs - (10_000.0 * x if i == k else 0.0)
                if i > 0:
                    f += dW[i - 1]
                    m += dW[i - 1] * ui.front_coupling_m
                if i < v.n_units - 1:
                    f -= dW[i]
                    m -= dW[i] * ui.rear_coupling_m
                assert abs(f) <= 1e-8 and abs(m) <= 1e-7, (name, u.name, x, ui.name, f, m)


def test_a_payload_moves_the_cg_and_the_inertia_by_the_parallel_axis_theorem():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    u = v.units[2]
    p, xp, hp, L = 8000.0, 1.2, 2.4, 6.0
    w = with_payload(v, 2, p, xp, hp, L)
    n = w.units[2]
    dx = p * xp / (u.mass_kg + p)
    # the inertia about the old CG, then moved to the new one (the other route of the theorem)
    about_old = u.yaw_inertia_kg_m2 + p * xp ** 2 + p * L ** 2 / 12
    assert n.yaw_inertia_kg_m2 == pytest.approx(about_old - (u.mass_kg + p) * dx ** 2, rel=1e-12)
    assert n.front_coupling_m == pytest.approx(u.front_coupling_m - dx, abs=1e-12)
    ms = u.mass_kg - sum(a.unsprung_mass_kg for a in u.axles)
    assert n.cg_height_m == pytest.approx((ms * u.cg_height_m + p * hp) / (ms + p), rel=1e-12)
    assert n.roll_inertia_kg_m2 == pytest.approx(
        u.roll_inertia_kg_m2 + ms * u.cg_height_m ** 2 + p * hp ** 2 - (ms + p) * n.cg_height_m ** 2, rel=1e-12)
    # the loads carry the payload where it is: the kingpin's share grows with x_p
    ahead = with_payload(v, 2, p, 3.0)
    behind = with_payload(v, 2, p, -3.0)
    assert coupling_loads(ahead)[1] > coupling_loads(behind)[1]


ROLL_STUDY = {"vehicle": "b_double.toml", "speed_kph": 80.0, "measures": ["srt_rrcu_g", "srt_min_g"],
              "design": {"kind": "grid"},
              "factors": {"lead_trailer.mass_scale": {"values": [0.8, 1.25]},
                          "rear_trailer.payload_kg": {"values": [0.0, 6000.0], "height_m": 2.6}}}


def test_a_roll_study_with_mass_and_payload_factors_gives_lcv_rolls_srt_of_each_case(tmp_path):
    study = study_from_dict(ROLL_STUDY, EXAMPLES)
    cols = compute_chunk(study, range(study.n_cases))
    srts = set()
    for k in range(study.n_cases):
        vehicle, _speed, _kw = study.case(k)
        path = tmp_path / f"case{k}.toml"
        path.write_text(dumps_vehicle(vehicle), encoding="utf-8")
        p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "roll", "--vehicle", str(path), "--speed-kph", "80",
                            "--json"], capture_output=True, text=True, timeout=120)
        assert p.returncode == 0, p.stderr
        assert "warning" not in p.stderr                    # masses and loads agree
        doc = json.loads(p.stdout)
        assert cols["srt_rrcu_g"][k] == pytest.approx(doc["srt_rrcu_g"], rel=1e-12)
        assert cols["srt_min_g"][k] == pytest.approx(doc["srt_min_g"], rel=1e-12)
        assert np.all(coupling_loads(vehicle) > 0)          # no coupling pulls up (the -97 kN pintle)
        srts.add(round(doc["srt_rrcu_g"], 9))
    assert len(srts) == 4                                   # each factor moves it


def test_an_untouched_groups_srt_does_not_move_with_another_units_mass():
    """The A-double of the issue: a mass factor on the first trailer leaves the rear group's SRT
    where it is (it moved 0.467 -> 0.482 g when the loads stayed as the file had them)."""
    v = load_vehicle(EXAMPLES / "western_double.toml")
    from lcvreport.measures.rollover import rollover_threshold
    front = v.unit_names[1]
    base = rollover_threshold(v).groups[-1].srt_g
    heavier = rollover_threshold(with_mass(v, front, 1.3 * v.units[1].mass_kg)).groups[-1].srt_g
    assert heavier == pytest.approx(base, rel=1e-12)


def test_a_case_whose_loads_and_masses_disagree_is_refused_by_name(tmp_path):
    text = (EXAMPLES / "b_double.toml").read_text()
    v = load_vehicle(EXAMPLES / "b_double.toml")
    off = v.units[0].axles[0].static_load_N
    text = text.replace(f"static_load_N = {off!r}", f"static_load_N = {0.2 * off!r}", 1)
    (tmp_path / "v.toml").write_text(text)
    doc = dict(ROLL_STUDY, vehicle="v.toml")
    with pytest.raises(StudyError, match=r"case 0: the static axle loads of b_double sum to .* beyond the 5 %"):
        study_from_dict(doc, tmp_path)


def test_payload_factors_are_checked():
    for spec, msg in (({"values": [-1.0]}, r"values\[0\] must be in \[0, 100000\] kg"), ({"values": [1000.0], "x_m": 99.0}, "x_m"),
                      ({"values": [1000.0], "depth_m": 1.0}, "unknown key 'depth_m'")):
        doc = dict(ROLL_STUDY, factors={"rear_trailer.payload_kg": spec})
        with pytest.raises(StudyError, match=msg):
            study_from_dict(doc, EXAMPLES)
