"""The static rollover threshold (docs/roll.md#static-rollover-threshold): its closed forms, a
brute-force equilibrium search that knows nothing of the event algorithm, and ``lcv roll``."""
from __future__ import annotations

import itertools
import json
import math
from dataclasses import replace

import numpy as np
import pytest

from lcvreport import load_vehicle
from lcvreport.cli.main import run
from lcvreport.model.vehicle import Axle, Unit, Vehicle
from lcvreport.model.yaw_roll.parameters import roll_parameters
from lcvreport.measures.rollover import rollover_threshold

from conftest import ROOT

G = 9.80665
EXAMPLES = ("b_double", "western_double", "truck_full_trailer")


def _one_axle(K, m=12000.0, h=1.8, hr=0.6, track=2.2, dual=0.3, mu=0.0):
    ax = Axle("a", 0.0, 4, 1.5e5, 0.0, 0.0, dual, static_load_N=m * G, track_width_m=track,
              roll_stiffness_Nm_per_rad=K, roll_damping_Nms_per_rad=1e4, unsprung_mass_kg=mu)
    unit = Unit("u", m, 5e4, (ax,), cg_height_m=h, roll_axis_height_m=hr, roll_inertia_kg_m2=8e3)
    return Vehicle("one", (unit,))


@pytest.mark.parametrize("K", [5e5, 1.2e6, 4e6, 3e7])
def test_one_unit_one_axle_lifts_at_the_closed_form(K):
    m, h, hr, T = 12000.0, 1.8, 0.6, 2.2 - 0.3
    e = h - hr
    t = rollover_threshold(_one_axle(K, m, h, hr))
    closed = T / (2 * (hr + e * K / (K - m * G * e)))
    g = t.groups[0]
    assert g.srt_g == pytest.approx(closed, rel=1e-13)
    assert g.lift_off_g == {"a": g.srt_g}


def test_a_rigid_suspension_gives_half_the_track_over_the_cg_height():
    m, h, T = 12000.0, 1.8, 1.9
    t = rollover_threshold(_one_axle(1e10, m, h))
    # K -> inf: T/(2h); at K = 1e10 the closed form differs from it by e m g e/K / h ~ 1e-5
    assert t.srt_min_g == pytest.approx(T / (2 * h), rel=2e-5)


def test_a_group_that_cannot_hold_its_weight_at_rest_has_srt_zero():
    m, h, hr = 12000.0, 1.8, 0.6
    weak = m * G * (h - hr) * 0.9                            # K below m g e
    t = rollover_threshold(_one_axle(weak, m, h, hr))
    assert t.srt_min_g == 0.0 and not t.groups[0].stable_at_rest
    assert t.groups[0].lift_off_g == {"a": None}


# ---------------------------------------------------------------- brute force
def _balance(rp, vehicle, units, lifted, phi, a):
    """The roll balance of every unit of the group (docs/roll.md), written out: outward roll phi,
    a = a_y [m/s^2], the axles in ``lifted`` at their lift-off moment."""
    out = []
    for k, i in enumerate(units):
        f = rp.ms_kg[i] * rp.e_m[i] * (a + G * phi[k])
        if i < vehicle.n_units - 1:                          # the rear coupling carries W (+)
            f += rp.W_N[i] * (rp.hc_m[i] - rp.hr_m[i]) * (a / G + phi[k])
            if i + 1 in units:
                f -= rp.kc_Nm_per_rad[i] * (phi[k] - phi[k + 1])
        if i > 0:                                           # the front coupling (-)
            f -= rp.W_N[i - 1] * (rp.hc_m[i - 1] - rp.hr_m[i]) * (a / G + phi[k])
            if i - 1 in units:
                f += rp.kc_Nm_per_rad[i - 1] * (phi[k - 1] - phi[k])
        for j in np.flatnonzero(rp.axle_unit == i):
            Fy = rp.Fz0_N[j] * a / G
            M = rp.Fz0_N[j] * rp.T_m[j] / 2 - rp.hr_m[i] * Fy if j in lifted else rp.K_Nm_per_rad[j] * phi[k]
            f -= M
        out.append(f)
    return np.array(out)


def _stable_equilibrium(rp, vehicle, units, a):
    """The lifted set and phi of a stable equilibrium at a, by trying every lifted set (brute
    force), or None if there is none."""
    axles = [j for j in range(rp.axle_unit.size) if rp.axle_unit[j] in units]
    n = len(units)
    for size in range(len(axles) + 1):
        for lifted in itertools.combinations(axles, size):
            lifted = set(lifted)
            f0 = _balance(rp, vehicle, units, lifted, np.zeros(n), a)
            J = np.column_stack([_balance(rp, vehicle, units, lifted, np.eye(n)[c], a) - f0 for c in range(n)])
            if np.linalg.eigvalsh(-(J + J.T) / 2).min() <= 0:       # not stable
                continue
            phi = np.linalg.solve(J, -f0)
            ok = True
            for j in axles:
                k = units.index(rp.axle_unit[j])
                margin = rp.K_Nm_per_rad[j] * phi[k] + rp.hr_m[rp.axle_unit[j]] * rp.Fz0_N[j] * a / G \
                    - rp.Fz0_N[j] * rp.T_m[j] / 2
                if (j in lifted and margin < -1e-9 * rp.Fz0_N[j]) or (j not in lifted and margin > 1e-9 * rp.Fz0_N[j]):
                    ok = False
                    break
            if ok:
                return lifted, phi
    return None


def _bisect(pred, lo, hi, iters=44):
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if pred(mid) else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize("name", [pytest.param("b_double", marks=pytest.mark.slow), "western_double",
                                  "truck_full_trailer"])
def test_the_threshold_and_the_lift_offs_are_the_brute_force_equilibria(name):
    """Every lifted set tried at each a_y of a bisection (2^9 for the B-double's group: 23 s, slow)."""
    v = load_vehicle(ROOT / "examples" / "vehicles" / f"{name}.toml")
    rp = roll_parameters(v)
    t = rollover_threshold(v)
    for units, g in zip(rp.groups, t.groups):
        units = list(units)
        srt = _bisect(lambda a: _stable_equilibrium(rp, v, units, a * G) is not None, 0.0, 2.0)
        assert g.srt_g == pytest.approx(srt, abs=1e-9)
        for j in [j for j in range(rp.axle_unit.size) if rp.axle_unit[j] in units]:
            name_j = v.axle_names[j]

            def lifted(a, j=j):
                eq = _stable_equilibrium(rp, v, units, a * G)
                return eq is None or j in eq[0]
            at = _bisect(lambda a: not lifted(a), 0.0, srt + 1e-6)
            if at >= srt - 1e-8:                             # lifts with (or after) the last event
                assert g.lift_off_g[name_j] is None or g.lift_off_g[name_j] == pytest.approx(g.srt_g, abs=1e-12)
            else:
                assert g.lift_off_g[name_j] == pytest.approx(at, abs=1e-9), name_j


def test_an_a_double_is_as_strong_as_its_weakest_group():
    v = load_vehicle(ROOT / "examples" / "vehicles" / "western_double.toml")
    t = rollover_threshold(v)
    assert len(t.groups) == 2                                # the dolly's drawbar is roll-free
    assert t.srt_min_g == min(g.srt_g for g in t.groups) and t.srt_rrcu_g == t.groups[-1].srt_g
    # a stiffer rear group does not change the front group's threshold: the drawbar carries no roll moment
    stiffer = replace(v, units=v.units[:2] + tuple(replace(u, axles=tuple(
        replace(a, roll_stiffness_Nm_per_rad=3 * a.roll_stiffness_Nm_per_rad) for a in u.axles)) for u in v.units[2:]))
    t2 = rollover_threshold(stiffer)
    assert t2.groups[0].srt_g == t.groups[0].srt_g and t2.groups[1].srt_g > t.groups[1].srt_g


# ---------------------------------------------------------------- the CLI
def _lcv(capsys, *argv):
    code = run(list(argv))
    cap = capsys.readouterr()
    return code, cap.out, cap.err


def test_lcv_roll_json_has_the_documented_keys(capsys):
    code, out, err = _lcv(capsys, "roll", "--vehicle", str(ROOT / "examples/vehicles/western_double.toml"),
                          "--speed-kph", "88", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert list(doc) == ["speed_mps", "groups", "srt_min_g", "srt_rrcu_g", "roll_gain_deg_per_g", "ltr_lane_change",
                         "rltr_lane_change", "ltr_single_sine", "roll_least_damping_ratio", "roll_critical_speed_kph",
                         "reasons"]
    assert [list(g) for g in doc["groups"]] == [["units", "srt_g", "lift_off_g"]] * 2
    assert doc["speed_mps"] == pytest.approx(88 / 3.6)
    assert [g["units"] for g in doc["groups"]] == [["tractor", "trailer1"], ["dolly", "trailer2"]]
    for g in doc["groups"]:
        assert max(x for x in g["lift_off_g"].values() if x is not None) == g["srt_g"]
    assert list(doc["roll_gain_deg_per_g"]) == ["tractor", "trailer1", "dolly", "trailer2"]
    assert all(x < 0 for x in doc["roll_gain_deg_per_g"].values())      # every unit rolls out of the turn
    assert len(doc["ltr_lane_change"]) == 2 and doc["rltr_lane_change"] == doc["ltr_lane_change"][-1]
    assert len(doc["ltr_single_sine"]) == 2 and 0 < doc["roll_least_damping_ratio"] < 1


def test_lcv_roll_names_the_missing_key(capsys):
    code, out, err = _lcv(capsys, "roll", "--preset", "aucnat", "--speed-kph", "88")
    assert code == 2 and out == ""
    assert err.strip() == ('lcv: error: argument --preset aucnat: units[0] "tractor": missing roll key '
                           "'cg_height_m' (docs/roll.md): the yaw-roll model needs it")


@pytest.mark.parametrize("edit, message", [
    ({"units": {0: {"roll_axis_height_m": 1.2}}}, 'units[0] "prime_mover": roll_axis_height_m must be below cg_height_m'),
    ({"axles": {"steer": {"track_width_m": 0.2, "dual_spacing_m": 0.3}}},
     'axles[0] "steer": the load-transfer track track_width_m - dual_spacing_m must be > 0'),
    ({"axles": {"a1": {"static_load_N": 0.0}}}, 'axles[0] "a1": static_load_N must be > 0 for roll'),
    ({"units": {1: {"cg_height_m": 6.0}}}, 'units[1] "lead_trailer": cg_height_m must be in (0, 5] m, got 6'),
    ({"axles": {"b2": {"roll_stiffness_Nm_per_rad": -1.0}}}, 'axles[1] "b2": roll_stiffness_Nm_per_rad must be in'),
])
def test_bad_roll_data_is_one_line_naming_unit_axle_and_key(capsys, tmp_path, edit, message):
    import tomllib
    from lcvreport.model.vehicle_file import loads_vehicle  # noqa: F401 (the file is read by the CLI)
    doc = tomllib.loads((ROOT / "examples/vehicles/b_double.toml").read_text())
    for i, keys in edit.get("units", {}).items():
        doc["units"][i].update(keys)
    for name, keys in edit.get("axles", {}).items():
        for u in doc["units"]:
            for a in u["axles"]:
                if a["name"] == name:
                    a.update(keys)
    path = tmp_path / "v.toml"
    path.write_text(_dump(doc))
    code, out, err = _lcv(capsys, "roll", "--vehicle", str(path), "--speed-kph", "80")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert message in err, err


def _dump(doc) -> str:
    """A TOML writer enough for a vehicle file."""
    def val(x):
        return json.dumps(x) if isinstance(x, str) else ("true" if x is True else "false" if x is False else repr(x))
    lines = [f"{k} = {val(v)}" for k, v in doc.items() if k != "units"]
    for u in doc["units"]:
        lines.append("[[units]]")
        lines += [f"{k} = {val(v)}" for k, v in u.items() if k != "axles"]
        for a in u["axles"]:
            lines.append("[[units.axles]]")
            lines += [f"{k} = {val(v)}" for k, v in a.items()]
    return "\n".join(lines) + "\n"


def test_static_loads_that_disagree_with_the_masses_warn_once(capsys, tmp_path):
    import tomllib
    doc = tomllib.loads((ROOT / "examples/vehicles/b_double.toml").read_text())
    for a in doc["units"][2]["axles"]:
        a["static_load_N"] *= 1.3
    path = tmp_path / "v.toml"
    path.write_text(_dump(doc))
    code, out, err = _lcv(capsys, "roll", "--vehicle", str(path), "--speed-kph", "80", "--json")
    assert code == 0
    lines = [x for x in err.splitlines() if "static axle loads" in x]
    assert len(lines) == 1 and "+9.6 %" in lines[0], err
    assert math.isfinite(json.loads(out)["srt_min_g"])


def test_the_roll_measures_are_null_with_the_missing_key_named(capsys):
    code, out, err = _lcv(capsys, "measures", "--preset", "tractor_semitrailer", "--speed-kph", "80", "--json")
    assert code == 0
    doc = json.loads(out)
    for key in ("srt_g", "srt_rrcu_g", "srt_min_g", "roll_least_damping_ratio", "ltr_lane_change", "hsto_m_roll",
                "roll_gain_deg_per_g", "ra_single_sine_roll", "ra_lane_change_roll", "rltr_lane_change",
                "ltr_single_sine", "roll_critical_speed_kph"):
        assert doc[key] is None
        assert "missing roll key 'cg_height_m'" in doc["reasons"][key]


def test_lcv_roll_plot_writes_a_new_figure(capsys, tmp_path):
    fig = tmp_path / "tilt.png"
    code, out, err = _lcv(capsys, "roll", "--vehicle", str(ROOT / "examples/vehicles/b_double.toml"),
                          "--speed-kph", "80", "--plot", str(fig))
    assert code == 0 and fig.stat().st_size > 10000 and f"wrote {fig}" in out
    code, out, err = _lcv(capsys, "roll", "--vehicle", str(ROOT / "examples/vehicles/b_double.toml"),
                          "--speed-kph", "80", "--plot", str(fig))
    assert code == 2 and "exists" in err
