"""Manoeuvres and the field's measures (SPEC sections 11-12, issue 17), each against an
independent computation: a stiff ODE solve (Radau, rtol 1e-12) of the continuous input,
closed forms, brute-force grids."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from conftest import EXAMPLES
from helpers import chain_on_circle_by_root_finding
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from lcvreport import load_preset, load_vehicle
from lcvreport.analysis.discretize import augmented_state_matrix
from lcvreport.analysis.exact import ManoeuvreError, response
from lcvreport.analysis.frequency import steer_to_acceleration
from lcvreport.analysis.steady import trim
from lcvreport.manoeuvres.steer import (G_MPS2, SteerError, lane_change, lane_change_offset_m, parse_steer, pulse, sine,
                                        step, table)
from lcvreport.measures.amplification import ra_peak
from lcvreport.measures.measure_set import measure_set
from lcvreport.measures.offtracking import HSSO_RADIUS_M, steady_turn
from lcvreport.measures.yaw_damping import ratio_damping, yaw_damping_coefficient
from lcvreport.model.linear import linear_model
from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.model.yaw_plane.loads import ResidualLoads, ResidualSources

U88 = 88 / 3.6


def _radau(vehicle, u, steer, t_eval, F=None):
    """[x, psi1, Y1] at t_eval from an independent Radau solve of the continuous input,
    restarted at the input's breakpoints (where its derivative jumps)."""
    co = system_coefficients(vehicle)
    A, G = augmented_state_matrix(co, u)
    b = G @ co.B_delta()
    g = np.zeros(A.shape[0]) if F is None else G @ F
    t_end = t_eval[-1]
    cuts = sorted({0.0, t_end, *[p.t0 for p in steer.pieces if 0 < p.t0 < t_end]})
    z = np.zeros(A.shape[0])
    out = np.zeros((t_eval.size, A.shape[0]))
    for a, c in zip(cuts[:-1], cuts[1:]):
        sol = solve_ivp(lambda t, x: A @ x + b * steer.delta([t])[0] + g, (a, c), z, method="Radau", rtol=1e-12,
                        atol=1e-16, dense_output=True)
        sel = (t_eval >= a) & (t_eval <= c)
        out[sel] = sol.sol(t_eval[sel]).T
        z = sol.sol(c)
    return out


STEERS = {
    "step": step(0.01),
    "sine": sine(0.01, 0.4),
    "pulse": pulse(0.01, 0.5),
    "csv": table([0.0, 0.4, 1.1, 2.05, 3.0], [0.0, 0.012, -0.004, 0.006, 0.0]),
}


@pytest.mark.parametrize("kind", sorted(STEERS))
@pytest.mark.parametrize("name", ["aucnat", "b_double"])
def test_exact_response_equals_a_stiff_ode_solve_for_every_steer_kind(name, kind):
    v = load_preset(name) if name == "aucnat" else load_vehicle(EXAMPLES / f"{name}.toml")
    steer = STEERS[kind]
    srcs = ResidualSources(ResidualLoads({v.axle_names[-1]: 800.0}, {v.axle_names[-1]: 240.0}),
                           {v.axle_names[-2]: 0.002}, 2.0)
    F = srcs.vector(v)
    r = response(v, U88, steer, 6.0, 0.01, F)
    ref = _radau(v, U88, steer, r.time, F)
    names = list(linear_model(v).state_names) + ["psi1", "Y1"]
    got = np.column_stack([r[n] for n in names])
    scale = np.abs(ref).max(axis=0)
    assert np.max(np.abs(got - ref) / scale) <= 1e-9
    np.testing.assert_allclose(r["delta"], steer.delta(r.time), rtol=0, atol=1e-15)


@pytest.mark.parametrize("name", ["aucnat", "western_double", "truck_full_trailer"])
def test_the_lane_change_puts_the_steered_axle_on_its_final_offset(name):
    v = load_preset(name) if name == "aucnat" else load_vehicle(EXAMPLES / f"{name}.toml")
    steer = lane_change(0.15 * G_MPS2, 0.4)
    r = response(v, U88, steer, 10.5, 0.005)
    axle = max(v.steered_axles, key=lambda a: a.x_m).name
    offset = lane_change_offset_m(steer)
    assert offset == pytest.approx(0.15 * G_MPS2 / (2 * math.pi * 0.4 ** 2), rel=1e-15)
    assert offset == pytest.approx(1.4632, abs=5e-5)
    after = r.time >= 2.5
    assert np.abs(r[f"Y_{axle}"][after] - offset).max() <= 1e-9
    np.testing.assert_allclose(r["a_steer"], steer.delta(r.time), rtol=0, atol=1e-10)


def test_a_lane_change_the_inverse_system_cannot_follow_is_refused(tmp_path):
    text = (EXAMPLES / "b_double.toml").read_text().replace("steered = true\n", "")
    i = text.index('name = "drive1"')
    path = tmp_path / "rear_steer.toml"
    path.write_text(text[:i] + "steered = true\n  " + text[i:])
    v = load_vehicle(path)
    with pytest.raises(ManoeuvreError, match="right-half-plane zero"):
        response(v, U88, lane_change(1.5, 0.4), 5.0, 0.01)
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "simulate", "--vehicle", str(path), "--speed-kph", "88",
                        "--steer", "lane-change:0.15g:0.4"], capture_output=True, text=True)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and "right-half-plane" in p.stderr
    doc = json.loads(subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--vehicle", str(path),
                                     "--speed-kph", "88", "--json"], capture_output=True, text=True).stdout)
    assert doc["hsto_m"] is None and doc["ra_lane_change"] is None and doc["ra_peak"] is not None


@pytest.mark.parametrize("name", ["tractor_semitrailer", "aucnat"])
def test_ra_peak_equals_a_brute_force_grid(name):
    v = load_preset(name)
    p = ra_peak(v, U88)
    f = np.arange(0.1, 2.0 + 5e-6, 1e-5)
    G = np.abs(steer_to_acceleration(v, U88, f))
    ra = G[:, -1] / G[:, 0]
    k = int(np.argmax(ra))
    assert p.value == pytest.approx(ra[k], rel=1e-9)
    assert p.value >= ra[k] * (1 - 1e-14)
    assert abs(p.frequency_hz - f[k]) <= 1e-5


@pytest.mark.parametrize("name", ["tractor_semitrailer", "aucnat", "empty"])
@pytest.mark.parametrize("kph", [60.0, 100.0])
def test_ra_peak_frequency_is_the_vertex_of_an_independent_parabola(name, kph):
    # RA at f and f +- h through steer_to_acceleration (stacked solves, not ra_peak's own
    # factorisation); the parabola's vertex locates the maximum to ~1e-10 Hz (bias from the
    # third derivative ~h^2, rounding ~eps/h); a search on RA's values alone stops ~1e-8 away
    v = load_preset(name)
    u = kph / 3.6
    p = ra_peak(v, u)
    h = 1e-5
    G = np.abs(steer_to_acceleration(v, u, p.frequency_hz + np.array([-h, 0.0, h])))
    r = G[:, -1] / G[:, 0]
    vertex = p.frequency_hz + h * (r[0] - r[2]) / (2 * (r[0] - 2 * r[1] + r[2]))
    assert abs(vertex - p.frequency_hz) <= 1e-9
    assert p.value == pytest.approx(r[1], rel=1e-13)


def test_ra_peak_falls_back_to_a_value_search_where_the_slope_brackets_no_zero(monkeypatch):
    # a slope that is NaN everywhere: the search on RA's values finds the same peak (to its
    # own precision, ~sqrt(eps) of the frequency on a flat maximum)
    import scipy.linalg
    v = load_preset("aucnat")
    p = ra_peak(v, U88)
    monkeypatch.setattr(scipy.linalg, "lu_solve", lambda lu, b: np.full(np.shape(b), np.nan, dtype=complex))
    q = ra_peak(v, U88)
    assert q.value == pytest.approx(p.value, rel=1e-13)
    assert abs(q.frequency_hz - p.frequency_hz) <= 1e-7


def test_the_ratio_method_of_one_damped_mode_is_its_modal_damping_ratio():
    for lam in (-0.3 + 2.0j, -1.2 + 7.5j, -0.05 + 0.9j):
        t = (np.arange(9) * np.pi - np.angle(lam)) / lam.imag        # extrema of exp(sigma t) sin(omega t)
        values = np.exp(lam.real * t) * np.sin(lam.imag * t)
        zeta, P = ratio_damping(values)
        assert zeta == pytest.approx(-lam.real / abs(lam), rel=1e-12)
        assert P.size == min(6, int(np.sum(np.abs(np.diff(values)) >= 0.05 * np.abs(np.diff(values)).max())))


def test_yaw_damping_extrema_equal_those_of_a_stiff_ode_solve():
    """The extrema of each articulation angle after the pulse (zeros of theta' on the
    continuous response) against brentq on a Radau dense output."""
    v = load_preset("tractor_semitrailer")
    ydc = yaw_damping_coefficient(v, U88)
    steer = pulse(0.01, 0.5)
    co = system_coefficients(v)
    A, G = augmented_state_matrix(co, U88)
    b = G @ co.B_delta()
    sol0 = solve_ivp(lambda t, x: A @ x + b * steer.delta([t])[0], (0, 0.5), np.zeros(A.shape[0]), method="Radau",
                     rtol=1e-12, atol=1e-16)
    sol = solve_ivp(lambda t, x: A @ x, (0.5, 40.5), sol0.y[:, -1], method="Radau", rtol=1e-12, atol=1e-16,
                    dense_output=True)
    j = linear_model(v).state_names.index("thetaA")
    dtheta = lambda t: (A @ sol.sol(t))[j]                                         # noqa: E731
    grid = np.linspace(0.5, 40.5, 40001)
    d = np.array([dtheta(t) for t in grid[::10]])
    g = grid[::10]
    roots = [brentq(dtheta, g[k], g[k + 1], xtol=1e-13) for k in range(g.size - 1) if d[k] * d[k + 1] < 0]
    times, values = ydc.extrema[0]
    # the extrema above 1e-6 of the largest (later ones decay to the rounding level of both
    # computations, where their times mean nothing; the method uses those above 5 %)
    n = min(len(roots), int(np.sum(np.abs(values) > 1e-6 * np.abs(values).max())))
    assert n >= 4
    np.testing.assert_allclose(times[:n], roots[:n], rtol=0, atol=1e-9)
    np.testing.assert_allclose(values[:n], [sol.sol(t)[j] for t in roots[:n]], rtol=0,
                               atol=1e-9 * np.abs(values).max())
    assert ydc.value == pytest.approx(ratio_damping([sol.sol(t)[j] for t in roots])[0], rel=1e-8)


@pytest.mark.parametrize("name", ["aucnat", "b_double"])
def test_hsso_equals_a_long_run_holding_the_turns_steer(name):
    v = load_preset(name) if name == "aucnat" else load_vehicle(EXAMPLES / f"{name}.toml")
    turn = steady_turn(v, U88)
    r = response(v, U88, step(turn.delta_rad), 300.0, 0.5)
    co = system_coefficients(v)
    x = np.array([r[n][-1] for n in linear_model(v).state_names])
    omega = r["r1"][-1]
    assert U88 / omega == pytest.approx(HSSO_RADIUS_M, rel=1e-6)        # the radius read off the run
    vel = co.velocity_map(U88) @ x
    steered = max(v.steered_axles, key=lambda a: a.x_m)
    rear = v.units[-1].rearmost_axle
    # the run's sideslips, the chain placed on the circle by root finding (SPEC 12, corrected 2026-12)
    R = chain_on_circle_by_root_finding(v, vel / U88, U88 / omega)
    assert R(v.n_units - 1, rear.x_m) - R(0, steered.x_m) == pytest.approx(turn.hsso_m, rel=1e-6)


def test_trim_with_every_residual_source_holds_the_tractor_straight():
    v = load_preset("aucnat")
    src = ResidualSources(ResidualLoads({"61": 500.0}, {"61": 150.0}), {"41": 0.003, "31": -0.001}, -3.0)
    F = src.vector(v)
    tr = trim(v, U88, F)
    co = system_coefficients(v)
    np.testing.assert_allclose(co.S(U88) @ tr.state + co.B_delta() * tr.delta_rad + F, 0.0,
                               atol=1e-9 * np.abs(F).max())
    assert tr.state[1] == 0.0 or abs(tr.state[1]) < 1e-15
    # misalignment eps on an axle is exactly a steer of eps on that axle alone
    col = v.axle_names.index("41")
    assert np.allclose(co.B_eps[:, col] * 0.003 + co.B_eps[:, v.axle_names.index("31")] * -0.001,
                       F - co.B_P @ src.loads.vectors(v)[0] - co.B_T @ src.loads.vectors(v)[1]
                       - math.sin(math.atan(-0.03)) * co.B_crossfall, rtol=1e-12, atol=0)
    # crossfall: the total lateral force is the weight component of the whole vehicle
    total = sum(u.mass_kg for u in v.units) * 9.80665 * math.sin(math.atan(0.02))
    assert co.B_crossfall[0] * math.sin(math.atan(0.02)) == pytest.approx(total, rel=1e-12)
    m = measure_set(v, U88, sources=src)
    assert m.trim.offtracking_m == pytest.approx(tr.offtracking_m, rel=1e-12)


@pytest.mark.parametrize("args, fragment", [
    (["--residual", "99=1,2"], "unknown axle '99'"),
    (["--residual", "61=1"], "AXLE=P,T"),
    (["--residual", "61=1e9,0"], "must be in [-1e+06, 1e+06] N"),
    (["--misalignment", "61=0.2"], "must be in [-0.05, 0.05] rad"),
    (["--misalignment", "61=0.001,61=0.002"], "given twice"),
    (["--crossfall-percent", "25"], "must be in [-20, 20] %"),
    (["--steer", "sine:0.01"], "sine takes 2 number(s)"),
    (["--steer", "wiggle:1"], "unknown kind 'wiggle'"),
    (["--steer", "pulse:0.01:0"], "pulse duration must be in [0.01, 10] s"),
    (["--steer", "lane-change:5g:0.4"], "lane-change acceleration must be in [-20, 20]"),
    (["--steer", "step:nan"], "must be finite"),
])
def test_bad_manoeuvre_options_are_one_line_and_exit_2(args, fragment):
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "simulate", "--preset", "aucnat", "--speed-kph", "88",
                        "--t-end", "1", "--dt", "0.5", *args], capture_output=True, text=True)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and fragment in p.stderr, p.stderr
    assert p.stdout == ""


@pytest.mark.parametrize("content, fragment", [
    ("time_s,delta_rad\n0,0\n1,0.01\n1,0.02\n", "must increase strictly"),
    ("time_s,delta_rad\n0,0\n1,nan\n", "not finite"),
    ("t,d\n0,0\n", "unknown column 't'; columns: time_s, delta_rad"),
    ("time_s,delta_rad\n0,0\n1,2\n", "must be in [-1, 1] rad"),
])
def test_a_bad_steer_table_is_refused(tmp_path, content, fragment):
    path = tmp_path / "steer.csv"
    path.write_text(content)
    with pytest.raises(SteerError, match=None) as exc:
        parse_steer(f"csv:{path}")
    assert fragment in str(exc.value)
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "simulate", "--preset", "aucnat", "--speed-kph", "88",
                        "--steer", f"csv:{path}"], capture_output=True, text=True)
    assert p.returncode == 2 and fragment in p.stderr and len(p.stderr.strip().splitlines()) == 1


def test_a_speed_sweep_gives_one_row_per_speed_equal_to_single_runs():
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "tractor_semitrailer",
                        "--speed-kph", "60:100:20", "--json"], capture_output=True, text=True)
    docs = json.loads(p.stdout)
    assert [round(d["speed_mps"] * 3.6, 9) for d in docs] == [60.0, 80.0, 100.0]
    one = json.loads(subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset",
                                     "tractor_semitrailer", "--speed-kph", "80", "--json"],
                                    capture_output=True, text=True).stdout)
    assert docs[1] == one
    csv = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "tractor_semitrailer",
                          "--speed-kph", "60:100:20"], capture_output=True, text=True).stdout.strip().splitlines()
    assert len(csv) == 4 and csv[0].startswith("speed_mps,")


def test_criteria_give_verdicts_with_their_source(tmp_path):
    crit = tmp_path / "c.toml"
    crit.write_text('[limits]\nra_single_sine = { max = 1.3, source = "test limit" }\n'
                    'hsto_m = { max = 0.01, source = "test limit 2" }\n'
                    'yaw_damping_coefficient = { min = 0.1, source = "x" }\n')
    doc = json.loads(subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset",
                                     "tractor_semitrailer", "--speed-kph", "88", "--criteria", str(crit), "--json"],
                                    capture_output=True, text=True).stdout)
    v = doc["verdicts"]
    assert v["ra_single_sine"]["verdict"] == ("pass" if doc["ra_single_sine"] <= 1.3 else "fail")
    assert v["hsto_m"]["verdict"] == "fail" and v["hsto_m"]["source"] == "test limit 2"
    crit.write_text('[limits]\nra_single_sine = { max = 1.3 }\n')
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "tractor_semitrailer",
                        "--speed-kph", "88", "--criteria", str(crit)], capture_output=True, text=True)
    assert p.returncode == 2 and "source" in p.stderr


def test_the_example_criteria_file_loads_and_says_it_is_not_a_standard():
    from lcvreport.measures.criteria import load_criteria
    path = EXAMPLES.parent / "criteria" / "example_limits.toml"
    c = load_criteria(path)
    assert c.limits and all("not a standard" in lim.source for lim in c.limits.values())


def test_a_misalignment_of_the_only_steered_axle_is_a_steer_and_crossfall_is_the_weight_component():
    """Independent identities of the new input matrices: eps on the single steered axle
    enters exactly as delta; the crossfall force on a unit is m g sin(atan(c)) at its CG,
    so on a single unit it is a pure lateral force with no moment about the CG."""
    v = load_preset("tractor_semitrailer")
    co = system_coefficients(v)
    steered = [i for i, a in enumerate(v.axles) if a.steered]
    assert len(steered) == 1
    np.testing.assert_array_equal(co.B_eps[:, steered[0]], co.B_delta())
    one = load_vehicle(EXAMPLES / "b_double.toml")
    from lcvreport.model.vehicle import Vehicle
    truck = Vehicle("truck", (one.units[0].__class__(**{**one.units[0].__dict__, "rear_coupling_m": None,
                                                        "rear_coupling_height_m": None,
                                                        "rear_coupling_roll_stiffness_Nm_per_rad": None}),))
    cot = system_coefficients(truck)
    assert cot.B_crossfall[0] == pytest.approx(truck.units[0].mass_kg * 9.80665, rel=1e-15)
    assert cot.B_crossfall[1] == 0.0
