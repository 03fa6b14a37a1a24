"""The measures an assessment adds (docs/measures.md): the yaw-rate rearward amplification,
the tracking ability on a straight path, and the conditions every manoeuvre is computed under.
Each against an independent computation or the physics it names."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from lcvreport import load_preset, load_vehicle
from lcvreport.measures.amplification import single_sine
from lcvreport.measures.measure_set import measure_set
from lcvreport.measures.offtracking import straight_path
from lcvreport.model.body import body_rectangle, unit_poses
from lcvreport.model.yaw_plane.loads import ResidualSources

from conftest import EXAMPLES

U88 = 88 / 3.6


def test_yaw_rate_ra_tends_to_one_in_a_slow_sine():
    """In a steady turn every unit yaws at the tractor's rate: a very slow single sine gives a
    yaw-rate RA of 1 (to the order of the transient, f * the time constants), and at 0.4 Hz the
    trailers' yaw rates are amplified (a B-train's rear trailer swings more than the tractor)."""
    v = load_preset("tractor_semitrailer")
    slow = single_sine(v, U88, 0.02)
    r = slow.response.peaks_abs(["r1", "r2"])
    assert r[1] / r[0] == pytest.approx(1.0, abs=0.02)
    m = measure_set(load_preset("aucnat"), U88)
    assert m.ra_yaw_rate_single_sine > 1.5


def _band_exact(v, tr, u):
    """The straight-path band from the unit poses with exact trigonometry at the trim's
    articulation angles and the tractor's crab: every body corner projected on the normal of
    the direction of travel (the tractor's heading turned by atan(v1/u))."""
    nu = v.n_units
    theta = tr.state[nu + 1:]
    travel = math.atan2(tr.state[0], u)
    normal = np.array([-math.sin(travel), math.cos(travel)])
    ys = []
    for k, (cg, psi) in enumerate(unit_poses(v, theta)):
        unit = v.units[k]
        ys.extend(body_rectangle(cg, psi, unit.body_front_m, unit.body_rear_m, unit.body_width_m / 2) @ normal)
    return max(ys) - min(ys)


@pytest.mark.parametrize("crossfall", [3.0, -6.0])
@pytest.mark.parametrize("name", ["b_double", "truck_full_trailer", "western_double"])
def test_tasp_is_the_band_of_the_exact_poses(name, crossfall):
    """tasp_m (first order in the angles) against the bodies placed with exact trigonometry:
    the angles are ~1e-3 rad, so the two differ at the order angle^2 * length (~1e-4 m)."""
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    F = ResidualSources(crossfall_percent=crossfall).vector(v)
    sp = straight_path(v, U88, F)
    angles = np.abs(np.concatenate([sp.trim.state[v.n_units + 1:], [sp.trim.state[0] / U88]])).max()
    assert 1e-4 < angles < 0.05
    exact = _band_exact(v, sp.trim, U88)
    assert sp.tasp_m == pytest.approx(exact, abs=30 * angles ** 2 * 30.0)
    assert sp.tasp_m > max(u.body_width_m for u in v.units) + 1e-3        # the crossfall widens the band


def test_tasp_without_a_source_is_the_widest_body_and_doubles_its_excess_with_the_source():
    """Linear in the sources: the band's excess over the widest body... is not linear in general
    (a max of sums), but with one crossfall sign the outermost points stay the same ones, so
    doubling the crossfall doubles the excess."""
    v = load_vehicle(EXAMPLES / "b_double.toml")
    widest = max(u.body_width_m for u in v.units)
    assert straight_path(v, U88).tasp_m == pytest.approx(widest, abs=1e-12)
    e1 = straight_path(v, U88, ResidualSources(crossfall_percent=2.0).vector(v)).tasp_m - widest
    e2 = straight_path(v, U88, ResidualSources(crossfall_percent=4.0).vector(v)).tasp_m - widest
    s1, s2 = math.sin(math.atan(0.02)), math.sin(math.atan(0.04))
    assert e2 / e1 == pytest.approx(s2 / s1, rel=1e-9)


def test_tasp_null_names_the_missing_body_key():
    m = measure_set(_no_body(), U88)
    assert m.tasp_m is None and "body_front_m" in m.reason("tasp_m")


def _no_body():
    import dataclasses
    v = load_preset("tractor_semitrailer")
    units = list(v.units)
    units[1] = dataclasses.replace(units[1], body_front_m=None, body_rear_m=None)
    return dataclasses.replace(v, units=tuple(units))


def test_conditions_change_the_measures_as_their_physics_says():
    """HSTO and the lane change's steer scale with A0 (a linear model: HSTO is exactly linear in
    A0, the overshoot being a difference of responses proportional to A0); HSSO at speed
    ~ 1/R (the steady turn's offtracking at walking pace is -(sum L^2 - ...)/(2R))."""
    v = load_preset("aucnat")
    base = measure_set(v, U88)
    m = measure_set(v, U88, conditions={"lane_change_ay_g": 0.3, "steady_turn_radius_m": 786.0})
    assert m.hsto_m == pytest.approx(2 * base.hsto_m, rel=1e-9)
    assert m.ra_lane_change == pytest.approx(base.ra_lane_change, rel=1e-9)
    assert m.hsso_m == pytest.approx(base.hsso_m / 2, rel=2e-3)
    assert m.ra_single_sine == base.ra_single_sine                    # not conditioned: the same number


def test_bad_conditions_are_refused():
    v = load_preset("aucnat")
    with pytest.raises(KeyError, match="unknown condition 'radius'"):
        measure_set(v, U88, conditions={"radius": 3.0})
    with pytest.raises(ValueError, match=r"steady_turn_radius_m must be in \[20, 10000\] m, got 5"):
        measure_set(v, U88, conditions={"steady_turn_radius_m": 5.0})


def test_lcv_measures_takes_the_conditions():
    args = [sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "aucnat", "--speed-kph", "80",
            "--turn-radius-m", "15", "--turn-angle-deg", "120", "--lane-change-frequency-hz", "0.5", "--json"]
    doc = json.loads(subprocess.run(args, capture_output=True, text=True, check=True).stdout)
    ref = measure_set(load_preset("aucnat"), 80 / 3.6,
                      conditions={"turn_radius_m": 15.0, "turn_angle_deg": 120.0, "lane_change_frequency_hz": 0.5})
    assert doc == json.loads(json.dumps(ref.to_dict()))
    p = subprocess.run(args[:6] + ["--turn-angle-deg", "0"], capture_output=True, text=True)
    assert p.returncode == 2 and p.stderr.strip().count("\n") == 0 and "--turn-angle-deg" in p.stderr
