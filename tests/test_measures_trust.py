"""Measures an assessor can trust (issue 29): HSSO chained through the couplings, YDC on the free
decay, the low-speed turn with the outside wheel on the circle and its sector unwrapped, every
``--help``, one spelling of every measure in criteria and studies, Model Exchange at a host's
default tolerance, FMUs of one and of fifty units.  Each against a computation of its own: the
exact geometry of a chain on a circle, a Newton-Euler steady state with explicit joint forces, a
closed form, an independent implementation of the corrected SPEC 12, a brute-force sampling."""
from __future__ import annotations

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES, TOOLS
from helpers import chain_on_circle_by_root_finding, random_vehicle, steady_turn_newton_euler

from lcvreport import PRESETS, load_preset, load_vehicle
from lcvreport.measures.low_speed import low_speed_turn
from lcvreport.measures.offtracking import HSSO_RADIUS_M, steady_turn
from lcvreport.measures.yaw_damping import ratio_damping, yaw_damping_coefficient
from lcvreport.model.linear import linear_model
from lcvreport.model.vehicle import Axle, Unit, Vehicle

ROOT = Path(__file__).resolve().parents[1]
LCV = [sys.executable, "-m", "lcvreport.cli"]


def _all():
    return [(p, load_preset(p)) for p in ("aucnat", "tractor_semitrailer")] + \
        [(n, load_vehicle(EXAMPLES / f"{n}.toml")) for n in ("western_double", "b_double", "truck_full_trailer")]


# ---------------------------------------------------------------------------- HSSO
def _single_axle_chain(L, k, x_steer=2.0):
    """Units with one unsteered axle each (the tractor also a steered one): unit 1's axle L[0]
    behind its steered axle, unit i's axle L[i] behind its front coupling; rear couplings k[i]
    behind the axle (negative: ahead of it)."""
    units, n = [], len(L)
    for i in range(n):
        pull = x_steer if i == 0 else 1.0
        ax = Axle(f"a{i}", pull - L[i], 4, 1.2e5, 0.0, 0.0, 0.0)
        axles = (Axle("s", x_steer, 2, 2.0e5, 0.0, 0.0, 0.0, steered=True), ax) if i == 0 else (ax,)
        rear = ax.x_m - k[i] if i < n - 1 else None
        units.append(Unit(f"u{i}", 6000.0 if i == 0 else 12000.0, 3.0e4 if i == 0 else 1.5e5, axles,
                          None if i == 0 else pull, rear))
    return Vehicle("chain", tuple(units))


@pytest.mark.parametrize("L, k", [([4.0, 9.0], [-0.5]), ([3.5, 7.0, 1.5, 7.0], [-1.0, 0.3, -0.2]),
                                  ([5.0, 8.0, 8.0], [0.8, 0.5])])
def test_hsso_at_walking_pace_is_the_exact_geometry_of_a_chain_on_a_circle(L, k):
    """At 0.1 m/s the tires barely slip (~1e-6 rad): every axle's lateral line passes through the
    turn centre.  From the steered axle's radius R_s the exact chain on a circle gives the rear
    axle's sqrt(R_s^2 - sum L^2 + sum k^2): HSSO equals it, and the SPEC's first-order kinematic
    form -(sum L^2 - sum k^2 - e^2)/(2R), to 1e-3 of itself -- the linear model's small angles
    put the centre at (-beta d, d) instead of on the axle line, a second-order difference (SPEC
    12: ~1e-3 of HSSO at 393 m; 4-5e-4 measured).  The first version's HSSO (every axis at
    u/Omega) read ~0 for every trailer."""
    v = _single_axle_chain(L, k + [0.0])
    t = steady_turn(v, 0.1)
    R_s = t.path_radius_m["s"]
    exact = math.sqrt(R_s ** 2 - sum(x * x for x in L) + sum(x * x for x in k)) - R_s
    assert t.hsso_m == pytest.approx(exact, rel=1e-3)
    first_order = -(sum(x * x for x in L) - sum(x * x for x in k)) / (2 * HSSO_RADIUS_M)
    assert t.hsso_m == pytest.approx(first_order, rel=1e-3)
    assert t.hsso_m < -0.05                       # the trailers' geometric offtracking is there


@pytest.mark.parametrize("name, v", _all(), ids=[n for n, _ in _all()])
@pytest.mark.parametrize("kph", [0.5, 60.0, 100.0])
def test_hsso_equals_an_independent_steady_state_and_geometry(name, v, kph):
    """The steady state from Newton-Euler with explicit joint forces (not the package's builder),
    its sideslips v_i/u, and the chain placed on the circle in world coordinates by brentq (not the
    closed-form root): HSSO and every axle's path radius to 1e-9 relative."""
    u = kph / 3.6
    t = steady_turn(v, u)
    vel, delta = steady_turn_newton_euler(v, u, u / HSSO_RADIUS_M)
    assert delta == pytest.approx(t.delta_rad, rel=1e-9)
    radius = chain_on_circle_by_root_finding(v, vel / u, HSSO_RADIUS_M)
    for i, a in zip(v.axle_units, v.axles):
        assert radius(i, a.x_m) == pytest.approx(t.path_radius_m[a.name], rel=1e-12)
    steered = max(v.steered_axles, key=lambda a: a.x_m)
    ref = radius(v.n_units - 1, v.units[-1].rearmost_axle.x_m) - radius(0, steered.x_m)
    # a difference of two 393 m radii: 1e-12 of a radius is ~4e-10 m
    assert abs(t.hsso_m - ref) <= 1e-9 + 1e-9 * abs(ref)


def test_hsso_of_the_tractor_semitrailer_is_its_textbook_low_speed_value():
    """The semi at walking pace: its effective axles at x0_i = -beta_i R (SPEC 12), L_1 = steer -
    x0_1, k_1 = x0_1 - fifth wheel, L_2 = kingpin - x0_2, e_2 = rear axle - x0_2."""
    v = load_preset("tractor_semitrailer")
    u = 0.1
    t = steady_turn(v, u)
    vel, _ = steady_turn_newton_euler(v, u, u / HSSO_RADIUS_M)
    x0 = -vel / u * HSSO_RADIUS_M
    steer = max(v.steered_axles, key=lambda a: a.x_m).x_m
    L1, k1 = steer - x0[0], x0[0] - v.units[0].rear_coupling_m
    L2, e2 = v.units[1].front_coupling_m - x0[1], v.units[1].rearmost_axle.x_m - x0[1]
    closed = -(L1 ** 2 + L2 ** 2 - k1 ** 2 - e2 ** 2) / (2 * HSSO_RADIUS_M)
    assert t.hsso_m == pytest.approx(closed, rel=1e-3)


def test_the_report_turn_table_is_the_hsso_geometry():
    from lcvreport.report.assessment import Assessment
    a = Assessment.load(vehicle_file=str(EXAMPLES / "b_double.toml"), speed_kph=88.0, fast=True)
    rows = {r["axle"]: r for r in a.turn_rows()}
    t = steady_turn(a.vehicle, 88 / 3.6)
    for name, r in t.path_radius_m.items():
        assert rows[name]["path_radius_m"] == pytest.approx(r, rel=1e-15)


# ---------------------------------------------------------------------------- YDC
ZETA_5 = math.log(20) / math.sqrt(math.pi ** 2 + math.log(20) ** 2)


def _ydc_by_the_corrected_spec(v, u):
    """SPEC 12 as corrected, written again: the exact pulse response sampled every 1 ms, each
    articulation angle's extrema from parabolas through three samples, peak-to-peak amplitudes,
    the free decay from the largest, those >= 5 % of it, the first six, the mean zeta of
    consecutive pairs, the smallest over the joints."""
    from lcvreport.analysis.exact import response
    from lcvreport.manoeuvres.steer import pulse
    r = response(v, u, pulse(0.01, 0.5), 40.5, 1e-3)
    t = r.time
    zetas = []
    for k in range(v.n_units - 1):
        y = r[linear_model(v).state_names[v.n_units + 1 + k]]
        i = np.flatnonzero((np.diff(np.sign(np.diff(y))) != 0) & (t[1:-1] > 0.5) & (t[1:-1] < 40.5))
        ext = []
        for j in i + 1:
            a, b, c = y[j - 1], y[j], y[j + 1]
            den = a - 2 * b + c
            s = 0.5 * (a - c) / den if den != 0 else 0.0
            ext.append(b - 0.25 * (a - c) * s)
        P = np.abs(np.diff(ext))
        if P.size == 0:
            continue
        P = P[int(np.argmax(P)):]
        P = P[P >= 0.05 * P[0]][:6]
        if P.size < 2:
            continue
        d = np.log(P[:-1] / P[1:])
        zetas.append(float(np.mean(d / np.sqrt(np.pi ** 2 + d ** 2))))
    return min(zetas) if zetas else None


@pytest.mark.parametrize("name, v", _all(), ids=[n for n, _ in _all()])
@pytest.mark.parametrize("kph", [60.0, 80.0, 100.0])
def test_ydc_equals_an_independent_implementation_of_the_corrected_spec(name, v, kph):
    u = kph / 3.6
    got = yaw_damping_coefficient(v, u)
    ref = _ydc_by_the_corrected_spec(v, u)
    if ref is None:
        assert got.value is None and got.lower_bound == pytest.approx(ZETA_5, rel=1e-15)
    else:
        assert got.value == pytest.approx(ref, rel=1e-6), (got.value, ref)


def test_a_small_forced_extremum_before_the_main_peak_is_not_the_free_decay():
    """A small extremum just after the pulse, then the free decay of one mode: the coefficient is
    the mode's damping ratio (the first version paired the small one with the main peak)."""
    lam = -0.3 + 2.0j
    t = (np.arange(8) * np.pi - np.angle(lam)) / lam.imag
    decay = np.exp(lam.real * t) * np.sin(lam.imag * t)
    values = np.r_[0.02 * decay[0], 0.0, decay]            # the forced wiggle, then the free decay
    zeta, P = ratio_damping(values)
    assert zeta == pytest.approx(-lam.real / abs(lam), rel=1e-12)
    from lcvreport.measures.yaw_damping import ratio_damping_groups
    z, _g, _s = ratio_damping_groups(np.zeros(values.size, int), np.zeros(values.size, int), values)
    assert z[0] == pytest.approx(zeta, rel=1e-15)


def test_ydc_over_speed_follows_the_modal_damping_of_the_a_double():
    """Western double (an A-double): YDC from 60 to 100 km/h falls as the modal least damping
    ratio falls, never jumping to a fifth of its neighbours (the first version read 0.04 at 60 km/h
    on a 30 m A-double decaying x85 per half cycle)."""
    v = load_vehicle(EXAMPLES / "western_double.toml")
    ydc = [yaw_damping_coefficient(v, k / 3.6).value for k in (60, 70, 80, 90, 100)]
    assert all(x is not None and 0.2 < x < 0.6 for x in ydc), ydc
    assert all(b < 1.25 * a for a, b in zip(ydc, ydc[1:])), ydc


def test_a_heavily_damped_vehicle_has_a_null_ydc_with_its_lower_bound_and_criteria_judge_it(tmp_path):
    v = load_vehicle(EXAMPLES / "b_double.toml")
    y = yaw_damping_coefficient(v, 60 / 3.6)
    assert y.value is None and y.lower_bound == pytest.approx(ZETA_5, rel=1e-15) and "heavily damped" in y.why
    assert round(ZETA_5, 4) == 0.6901
    for limit, verdict in ((0.5, "pass"), (0.6901, "pass"), (0.8, "not computed")):
        crit = tmp_path / f"c{limit}.toml"
        crit.write_text(f'[limits]\nyaw_damping_coefficient = {{ min = {limit}, source = "test" }}\n')
        p = subprocess.run(LCV + ["measures", "--vehicle", str(EXAMPLES / "b_double.toml"), "--speed-kph", "60",
                                  "--criteria", str(crit), "--json"], capture_output=True, text=True)
        doc = json.loads(p.stdout)
        assert doc["yaw_damping_coefficient"] is None and doc["yaw_damping_lower_bound"] == pytest.approx(ZETA_5)
        assert "heavily damped" in doc["reasons"]["yaw_damping_coefficient"]
        assert doc["verdicts"]["yaw_damping_coefficient"]["verdict"] == verdict, (limit, doc["verdicts"])


def test_a_single_unit_has_no_joint_and_no_bound():
    v = Vehicle("truck", (Unit("truck", 12000.0, 6.0e4, (Axle("f", 2.5, 2, 2e5, 0.0, 0.0, 0.0, steered=True),
                                                        Axle("r", -3.0, 8, 1.5e5, 0.0, 0.0, 0.0))),))
    y = yaw_damping_coefficient(v, 24.0)
    assert y.value is None and y.lower_bound is None and y.why.startswith("no joint")


def test_a_stable_vehicle_passes_a_critical_speed_minimum(tmp_path):
    crit = tmp_path / "c.toml"
    crit.write_text('[limits]\ncritical_speed_kph = { min = 120.0, source = "test" }\n')
    p = subprocess.run(LCV + ["measures", "--preset", "aucnat", "--speed-kph", "88", "--criteria", str(crit), "--json"],
                       capture_output=True, text=True)
    doc = json.loads(p.stdout)
    assert doc["critical_speed_kph"] is None and doc["verdicts"]["critical_speed_kph"]["verdict"] == "pass"


# ---------------------------------------------------------------------------- the low-speed turn
TRACK = 2.0


def _turn_chain(L, k, body_width=2.5):
    """Single-axle units for the turn (track 2 m): unit 1 steered at x = 1, its axle L[0] behind."""
    units, n = [], len(L)
    for i in range(n):
        pull = 1.0 if i == 0 else 0.0
        ax = Axle(f"a{i}", pull - L[i], 2, 1.5e5, 0.0, 0.0, 0.0, track_width_m=TRACK)
        axles = (Axle("s", 1.0, 2, 1.5e5, 0.0, 0.0, 0.0, steered=True, track_width_m=TRACK), ax) if i == 0 else (ax,)
        rear = ax.x_m - k[i] if i < n - 1 else None
        xs = [a.x_m for a in axles] + [pull] + ([rear] if rear is not None else [])
        units.append(Unit(f"u{i}", 1000.0, 1000.0, axles, None if i == 0 else 0.0, rear,
                          body_front_m=max(xs) + 0.5, body_rear_m=min(xs) - 0.5, body_width_m=body_width))
    return Vehicle("chain", tuple(units))


@pytest.mark.parametrize("L, k, R", [([4.0], [0.0], 12.5), ([3.0, 6.0], [-0.5, 0.0], 12.5),
                                     ([3.5, 5.0, 1.0, 5.0], [-1.0, 0.2, -0.3, 0.0], 20.0)])
def test_the_outside_wheel_runs_on_the_circle_and_the_steady_measures_are_the_closed_forms(L, k, R):
    """720 degrees: the steered axle's outside wheel on R throughout the arc (1e-9 m); at the arc's
    end its centre on R_s = sqrt(L_1^2 + (sqrt(R^2 - L_1^2) - h)^2) and the last axle on
    sqrt(R_s^2 - sum(L^2 - k^2)) (1e-6 m); the front outer corner on the closed form of the frontal
    swing; the measures at least these (the transient cuts in further)."""
    v = _turn_chain(L, k)
    t = low_speed_turn(v, radius_m=R, angle_deg=720.0)
    run, c, h = t.run, t.run.path.centre, TRACK / 2
    s = np.linspace(0.0, run.path.arc_end_s, 2001)
    wheel = run.unit_points(s, 0, [1.0], [-h])[:, 0]
    assert np.max(np.abs(np.hypot(*(wheel - c).T) - R)) <= 1e-9
    end = [run.path.arc_end_s]
    rho = math.sqrt(R ** 2 - L[0] ** 2) - h                 # O's distance from unit 1's axis
    R_s = math.hypot(L[0], rho)
    assert float(np.hypot(*(run.unit_points(end, 0, [1.0], [0.0])[0, 0] - c))) == pytest.approx(R_s, abs=1e-6)
    total = sum(x * x for x in L) - sum(x * x for x in k[:-1])
    last = v.n_units - 1
    rear = float(np.hypot(*(run.unit_points(end, last, [v.units[last].axles[-1].x_m], [0.0])[0, 0] - c)))
    assert rear == pytest.approx(math.sqrt(R_s ** 2 - total), abs=1e-6)
    assert t.low_speed_offtracking_m >= R_s - math.sqrt(R_s ** 2 - total) - 1e-6   # the steady state, or more
    u1 = v.units[0]
    corner = math.hypot(u1.body_front_m - u1.axles[1].x_m, rho + u1.body_width_m / 2) - R
    got = float(np.hypot(*(run.unit_points(end, 0, [u1.body_front_m], [-u1.body_width_m / 2])[0, 0] - c))) - R
    assert got == pytest.approx(corner, abs=1e-6) and t.frontal_swing_m >= corner - 1e-6


def test_the_b_double_outside_wheel_ends_on_the_circle():
    """The first version put the steered axle's centre on R - track/2: its outside wheel then
    ended 7.0 cm inside the 12.5 m circle (issue 29); now it is on it."""
    v = load_vehicle(EXAMPLES / "b_double.toml")
    t = low_speed_turn(v)
    steer = max((a for a in v.units[0].axles if a.steered), key=lambda a: a.x_m)
    s = np.linspace(0.0, t.run.path.arc_end_s, 500)
    w = t.run.unit_points(s, 0, [steer.x_m], [-steer.track_width_m / 2])[:, 0]
    assert np.max(np.abs(np.hypot(*(w - t.run.path.centre).T) - 12.5)) <= 1e-9


@pytest.mark.parametrize("name", ["tractor_semitrailer", "western_double", "truck_full_trailer"])
def test_turns_past_180_degrees_never_count_the_exit_and_converge_to_the_steady_turn(name):
    """270, 300, 360, 720 and 3600 degrees: the swept width and offtracking grow toward the steady
    turn's (never the exit's 25 m, as the first version read at 300 degrees), the tail swing is the
    entry's whatever the angle (the first read 38.8 m at 270 degrees)."""
    v = load_preset(name) if name in PRESETS else load_vehicle(EXAMPLES / f"{name}.toml")
    turns = [low_speed_turn(v, angle_deg=a) for a in (90, 270, 300, 360, 720, 3600)]
    lssp = [t.lssp_m for t in turns]
    off = [t.low_speed_offtracking_m for t in turns]
    assert all(b >= a - 1e-6 for a, b in zip(lssp[1:], lssp[2:])), lssp
    assert all(b >= a - 1e-6 for a, b in zip(off[1:], off[2:])), off
    assert lssp[-1] - lssp[-2] <= 1e-3 and lssp[-1] < 2 * lssp[0], lssp
    assert all(t.tail_swing_m == pytest.approx(turns[0].tail_swing_m, abs=1e-9) for t in turns), \
        [t.tail_swing_m for t in turns]


def test_an_extreme_on_the_sectors_edge_is_located_on_the_edge():
    """A 20 degree turn: the front outer corner is still swinging out when it reaches the sector's
    edge; the frontal swing is its value there -- against a brute-force 0.1 mm sampling of the
    corner's radius restricted to its angle, not the last 5 cm sample."""
    v = load_preset("tractor_semitrailer")
    t = low_speed_turn(v, angle_deg=20.0)
    u1 = v.units[0]

    def corner(s):
        return t.run.unit_points(np.atleast_1d(s), 0, [u1.body_front_m], [-u1.body_width_m / 2])[:, 0] - \
            t.run.path.centre
    s = np.arange(0.0, t.run.path.s_end, 1e-3)
    p = corner(s)
    phi = np.arctan2(p[:, 0], -p[:, 1])
    inside = (phi >= 0) & (phi <= math.radians(20.0))
    k = int(np.argmax(np.where(inside, np.hypot(p[:, 0], p[:, 1]), -np.inf)))
    assert not inside[k + 1]                          # the largest sample is the last one in the sector
    lo, hi = s[k], s[k + 1]                           # the edge, by plain bisection on the angle
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        q = corner(mid)[0]
        lo, hi = (mid, hi) if math.atan2(q[0], -q[1]) <= math.radians(20.0) else (lo, mid)
    edge = float(np.hypot(*corner(lo)[0])) - 12.5
    assert t.frontal_swing_m == pytest.approx(edge, abs=1e-9)
    assert edge - (float(np.hypot(*p[k])) - 12.5) > 1e-7     # more than the last sample: located on the edge


@pytest.mark.parametrize("args", [["--preset", "aucnat", "--radius", "6"], ["--preset", "aucnat", "--angle-deg", "0.001"],
                                  ["--vehicle", str(EXAMPLES / "b_double.toml"), "--angle-deg", "360"]])
def test_a_turn_the_vehicle_cannot_make_gives_a_line_saying_why(args):
    p = subprocess.run(LCV + ["turn", *args, "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["lssp_m"] is None and doc["reasons"]["lssp_m"]
    p = subprocess.run(LCV + ["turn", *args], capture_output=True, text=True)
    assert p.returncode == 0 and "not computed: " in p.stdout and "inf" not in p.stdout, p.stdout + p.stderr


def test_tight_turns_a_vehicle_can_make_give_numbers():
    for name, radius in (("tractor_semitrailer", "6"), ("western_double", "6")):
        v = ["--preset", name] if name in PRESETS else ["--vehicle", str(EXAMPLES / f"{name}.toml")]
        p = subprocess.run(LCV + ["turn", *v, "--radius", radius, "--json"], capture_output=True, text=True)
        doc = json.loads(p.stdout)
        assert p.returncode == 0 and all(doc[k] is not None for k in ("lssp_m", "low_speed_offtracking_m"))


def test_the_turn_angle_has_one_range_for_the_api_and_the_cli():
    from lcvreport.model.body import TurnError
    v = load_preset("tractor_semitrailer")
    assert low_speed_turn(v, angle_deg=3600.0).lssp_m > 0
    for bad in (0.0, 3600.5, float("nan")):
        with pytest.raises(TurnError, match=r"angle_deg must be in \(0, 3600\] deg"):
            low_speed_turn(v, angle_deg=bad)
        p = subprocess.run(LCV + ["turn", "--preset", "tractor_semitrailer", "--angle-deg", str(bad)],
                           capture_output=True, text=True)
        assert p.returncode == 2 and "(0, 3600] deg" in p.stderr and len(p.stderr.strip().splitlines()) == 1


# ---------------------------------------------------------------------------- --help, criteria, reasons
def _commands():
    import argparse

    from lcvreport.cli.main import build_parser
    out = []

    def walk(parser, prefix):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    out.append(prefix + [name])
                    walk(sub, prefix + [name])
    walk(build_parser(), [])
    return out


@pytest.mark.parametrize("cmd", _commands(), ids=lambda c: " ".join(c))
def test_every_command_and_subcommand_has_a_help(cmd):
    p = subprocess.run(LCV + cmd + ["--help"], capture_output=True, text=True)
    assert p.returncode == 0 and p.stdout.startswith("usage: lcv") and p.stderr == "", p.stderr


def test_every_scalar_the_json_prints_can_be_judged(tmp_path):
    """lssp_m and the other low-speed measures, the trim (one spelling: the JSON's), the bound."""
    from lcvreport.measures.registry import CRITERIA_KEYS
    lines = ["[limits]"] + [f'"{k}" = {{ max = 1e9, source = "all" }}' for k in CRITERIA_KEYS]
    crit = tmp_path / "c.toml"
    crit.write_text("\n".join(lines) + "\n")
    p = subprocess.run(LCV + ["measures", "--preset", "aucnat", "--speed-kph", "88", "--load", "trailer3",
                              "--criteria", str(crit), "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    from lcvreport.measures.registry import MEASURES
    printed = {k for k, v in doc.items() if (isinstance(v, (int, float)) or v is None)
               and MEASURES[k].shape == "scalar"} - {"speed_mps"}
    printed |= {f"trim.{k}" for k in doc["trim"]}
    assert printed <= set(doc["verdicts"]) == set(CRITERIA_KEYS)
    assert doc["verdicts"]["lssp_m"]["verdict"] == "pass" and doc["verdicts"]["trim.offtracking_m"]["verdict"] == "pass"


@pytest.mark.parametrize("key, hint", [("tail_swing_m", "max_tail_swing_m")])
def test_a_misspelt_measure_names_the_key_to_use(tmp_path, key, hint):
    crit = tmp_path / "c.toml"
    crit.write_text(f'[limits]\n{key} = {{ max = 1.0, source = "x" }}\n')
    p = subprocess.run(LCV + ["measures", "--preset", "aucnat", "--speed-kph", "88", "--criteria", str(crit)],
                       capture_output=True, text=True)
    assert p.returncode == 2 and f"the key is {hint!r}" in p.stderr
    study = tmp_path / "s.toml"
    study.write_text(f'vehicle = "aucnat"\nspeed_kph = 88.0\nmeasures = ["{key}"]\n[factors]\n'
                     'speed_kph = {values = [80.0]}\n')
    p = subprocess.run(LCV + ["study", str(study), "--out", str(tmp_path / "o")], capture_output=True, text=True)
    assert p.returncode == 2 and f"the key is {hint!r}" in p.stderr


def test_a_key_of_the_last_release_is_read_as_todays(tmp_path):
    """trim_offtracking_m (0.2.x) is trim.offtracking_m: an alias, in a criteria file and a study
    (issue 40 item 14; it was refused with a hint)."""
    crit = tmp_path / "c.toml"
    crit.write_text('[limits]\ntrim_offtracking_m = { max = 1.0, abs = true, source = "x" }\n')
    p = subprocess.run(LCV + ["measures", "--preset", "aucnat", "--speed-kph", "88", "--load", "trailer2",
                              "--criteria", str(crit), "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert json.loads(p.stdout)["verdicts"]["trim.offtracking_m"]["verdict"] == "pass"


def test_a_study_judges_the_trim_the_criteria_file_names(tmp_path):
    """The trim in a study and in a criteria file is one key: the study report's pass rates hold
    the trim's limit (the first version dropped it silently)."""
    from lcvreport.measures.criteria import load_criteria
    from lcvreport.study.results import read_study
    from lcvreport.study.run import run_study
    from lcvreport.study.spec import study_from_dict
    from lcvreport.study.summary import pass_rates
    out = tmp_path / "s"
    run_study(study_from_dict({"vehicle": "aucnat", "speed_kph": 88.0, "measures": ["trim.offtracking_m", "hsso_m"],
                               "factors": {"load_units": {"values": [["trailer3"], ["trailer2", "trailer3"]]}}}), out)
    crit = tmp_path / "c.toml"
    crit.write_text('[limits]\n"trim.offtracking_m" = { max = 0.5, abs = true, source = "x" }\n')
    rates = pass_rates(read_study(out), load_criteria(crit), [])
    assert [r["limit"] for r in rates.overall if "trim" in str(r["limit"])], rates.overall


def test_every_null_in_the_json_carries_its_reason():
    p = subprocess.run(LCV + ["measures", "--preset", "aucnat", "--speed-kph", "88", "--json"], capture_output=True,
                       text=True)
    doc = json.loads(p.stdout)
    nulls = [k for k, v in doc.items() if v is None]
    assert "critical_speed_kph" in nulls and all(doc["reasons"].get(k) for k in nulls), (nulls, doc["reasons"])


# ---------------------------------------------------------------------------- FMUs
def test_model_exchange_at_fmusims_default_tolerance_is_within_1_percent(tmp_path, all_example_fmus, native_fmu):
    """Every state has a nominal of its physical scale: fmusim's CVODE at its default tolerance
    follows the exact response to a steer step (0.01 rad from rest, 6 s) within 1 % of every
    lateral acceleration's and state's peak (with nominals of 1 it read ay3 23 % off; 1.4 % on
    the western double)."""
    from fmu_support import host_env, interface_of

    from lcvreport.analysis.exact import response
    from lcvreport.manoeuvres.steer import step
    for fmu, vehicle in [(native_fmu, load_preset("aucnat"))] + \
            [(all_example_fmus[n]["native"], load_vehicle(EXAMPLES / f"{n}.toml")) for n in ("western_double",
                                                                                              "b_double")]:
        with open(tmp_path / "in.csv", "w", newline="") as f:
            f.write("time,delta\n0,0.01\n6,0.01\n")
        out = tmp_path / "out.csv"
        p = subprocess.run([str(TOOLS / "fmusim"), "--interface-type", "me", "--solver", "cvode", "--stop-time", "6",
                            "--output-interval", "0.05", "--input-file", str(tmp_path / "in.csv"), "--output-file",
                            str(out), str(fmu)], capture_output=True, text=True, env=host_env(), timeout=300)
        assert p.returncode == 0, p.stdout + p.stderr
        rows = list(csv.DictReader(open(out)))
        itf = interface_of(fmu)
        r = response(vehicle, float(itf.by_name["u"].start), step(0.01), 6.0, 0.05)
        letters = {f"theta{k + 1}": v for k, v in enumerate(linear_model(vehicle).state_names[vehicle.n_units + 1:])}
        names = [f"ay{i + 1}" for i in range(vehicle.n_units)] + [f"r{i + 1}" for i in range(vehicle.n_units)] + \
            ([f"theta{k + 1}" for k in range(vehicle.n_units - 1)] if not itf.preset_mode else
             list(linear_model(vehicle).state_names[vehicle.n_units + 1:]))
        for name in names:
            got = np.array([float(x[name]) for x in rows])
            ref = r[letters.get(name, name) if not itf.preset_mode else name]
            assert np.max(np.abs(got - ref)) <= 0.01 * np.max(np.abs(ref)), (fmu.name, name)


@pytest.mark.parametrize("n_units", [1, 50])
def test_fmus_of_one_and_of_fifty_units_are_built(tmp_path, n_units):
    from lcvreport.model.vehicle_file import dumps_vehicle
    if n_units == 1:
        v = Vehicle("rigid_truck", (Unit("truck", 12000.0, 6.0e4, (Axle("f", 2.5, 2, 2e5, 5e3, 0.0, 0.0, steered=True),
                                                                  Axle("r", -3.0, 8, 1.5e5, 5e3, 2e5, 0.33))),))
    else:
        v = random_vehicle(50, np.random.default_rng(3))
    path = tmp_path / "v.toml"
    path.write_text(dumps_vehicle(v))
    for fmi in ("2", "3"):
        p = subprocess.run(LCV + ["fmu", "--vehicle", str(path), "--out", str(tmp_path / f"f{fmi}"), "--fmi", fmi],
                           capture_output=True, text=True, timeout=600)
        assert p.returncode == 0, p.stderr
        assert len(list((tmp_path / f"f{fmi}").glob("*.fmu"))) == 2


def test_an_fmi3_python_fmu_of_a_name_ending_in_a_digit_cannot_be_misread(tmp_path):
    text = (EXAMPLES / "b_double.toml").read_text().replace('name = "b_double"', 'name = "nu4_bdouble26"')
    path = tmp_path / "v.toml"
    path.write_text(text)
    p = subprocess.run(LCV + ["fmu", "--vehicle", str(path), "--out", str(tmp_path / "f"), "--fmi", "3"],
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    assert sorted(q.name for q in (tmp_path / "f").iterdir()) == ["nu4_bdouble26Native3.fmu", "nu4_bdouble26_fmi3.fmu"]


def test_the_fmu_gives_hsto_through_every_axles_lateral_position(all_example_fmus):
    """Y_<axle> of every axle: in a steer step the FMU's equals the package's exact path of the
    axle's centre (the FMU steps exactly for inputs held over the step)."""
    from fmpy import simulate_fmu

    from lcvreport.analysis.exact import response
    from lcvreport.manoeuvres.steer import step
    v = load_vehicle(EXAMPLES / "b_double.toml")
    r = response(v, 22.352, step(0.01), 5.0, 0.01)
    res = simulate_fmu(str(all_example_fmus["b_double"]["native"]), stop_time=5.0, output_interval=0.01,
                       start_values={"delta": 0.01}, output=[f"Y_{a.name}" for a in v.axles])
    for a in v.axles:
        ref = r[f"Y_{a.name}"]
        assert np.max(np.abs(res[f"Y_{a.name}"] - ref)) <= 1e-9 * np.max(np.abs(ref)), a.name


# ---------------------------------------------------------------------------- the definitions are where the reader is
def _anchors(path):
    import re
    return {re.sub(r"[^a-z0-9 -]", "", line.lstrip("#").strip().lower()).replace(" ", "-")
            for line in path.read_text().splitlines() if line.startswith("#")}


def test_every_measure_is_defined_in_docs():
    from lcvreport.measures.registry import MEASURES
    anchors = _anchors(ROOT / "docs" / "measures.md")
    missing = {k: m.doc for k, m in MEASURES.items() if m.doc not in anchors}
    assert not missing, missing
    text = (ROOT / "docs" / "measures.md").read_text()
    assert all(f"`{k}`" in text for k in MEASURES), [k for k in MEASURES if f"`{k}`" not in text]


def test_readers_are_pointed_to_documents_they_have():
    """The README, every help text and the report notebooks cite docs/ pages, not a specification
    a reader of the repository does not have; every docs/ page they name exists."""
    import re
    texts = {"README.md": (ROOT / "README.md").read_text()}
    texts.update({p.name: p.read_text() for p in (ROOT / "notebooks").glob("*.ipynb")})
    texts.update({" ".join(c): subprocess.run(LCV + c + ["--help"], capture_output=True, text=True).stdout
                  for c in _commands()})
    for name, text in texts.items():
        assert not re.search(r"SPEC (section|erratum|sections|\d)", text), name
        for page in re.findall(r"docs/([a-z_]+\.md)", text):
            assert (ROOT / "docs" / page).exists(), (name, page)
