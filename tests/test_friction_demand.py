"""The low-speed turn with tire forces and the friction demand (issue 42, docs/nonlinear.md,
docs/measures.md#friction-demand): at walking pace with stiff linear tires the nonlinear model's
paths converge to the kinematic model's; a steady circle equals the algebraic steady state solved
from the equations written out; a rigid truck's tandem meets the closed-form scrub balance; the
friction demand is the tire forces' share of the friction; the CLI and the registry give them."""
from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys

import numpy as np
import pytest

from lcvreport.analysis.integrate import integrate
from lcvreport.manoeuvres.steer import step
from lcvreport.measures.friction_demand import turn_with_tire_forces
from lcvreport.model.nonlinear.model import nonlinear_model
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLE_NAMES, EXAMPLES

LCV = [sys.executable, "-m", "lcvreport.cli"]


def _stiff(model, factor=1e4):
    """The model with every cornering stiffness times ``factor`` (a test of the limit only: a
    vehicle file cannot hold such numbers)."""
    object.__setattr__(model, "_p", dataclasses.replace(model._p, CF=model._p.CF * factor))
    return model


def _lumped(vehicle):
    """``vehicle`` with every towed unit's axles lumped into one at the kinematic model's
    effective position d0 = sum C d^2 / sum C d from its pull point (docs/low_speed_turn.md) with
    their summed stiffness and load: the same kinematic run, and no towed group whose scrub
    pushes on the unit ahead."""
    import dataclasses
    units = [vehicle.units[0]]
    for u in vehicle.units[1:]:
        d = np.array([a.x_m - u.front_coupling_m for a in u.axles])
        C = np.array([a.cornering_stiffness_axle_N_per_rad for a in u.axles])
        a0 = u.axles[0]
        one = dataclasses.replace(
            a0, name=a0.name + "_lumped", x_m=float(u.front_coupling_m + (C * d * d).sum() / (C * d).sum()),
            cornering_stiffness_N_per_rad=float(C.sum()) / a0.tires, static_load_N=sum(a.static_load_N for a in u.axles),
            longitudinal_stiffness_N=0.0, dual_spacing_m=0.0)
        units.append(dataclasses.replace(u, axles=(one,)))
    return dataclasses.replace(vehicle, units=tuple(units))


def _path_difference(v, gain):
    t = turn_with_tire_forces(v, angle_deg=90.0, speed_kph=5.0, tire="linear", path_gain_rad_per_m=gain)
    kin = t.kinematic.run
    s = np.linspace(0.0, min(t.turn.run.s_end, kin.s_end) * 0.98, 400)
    worst = 0.0
    for k, u in enumerate(v.units):
        for a in u.axles:
            got = t.turn.run.unit_points(s, k, [a.x_m], [0.0])[:, 0]
            ref = kin.unit_points(s, k, [a.x_m], [0.0])[:, 0]
            worst = max(worst, float(np.abs(got - ref).max()))
    return worst


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_at_walking_pace_with_stiff_tires_the_paths_are_the_kinematic_models(name, monkeypatch):
    """Every C_F x 1e4 at 5 km/h: every axle centre's path within 5 mm of the kinematic model's on
    the 90 deg turn -- where the kinematic model's rule holds.  Its rule places each unit's
    effective axle by the unit's own moment balance (d0 = sum C d^2 / sum C d); a towed
    multi-axle group's net scrub force (sum F_j != 0 by Cauchy-Schwarz) pushes through the
    coupling on the unit ahead and moves that unit's centre of rotation, which the rule leaves
    out: 75 mm on the B-double's tri-axle groups, 25 mm on the truck and full trailer
    (docs/nonlinear.md#reduction-checks).  With the towed groups lumped into the single axle
    the rule puts there (the same kinematic run), the paths agree."""
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    import lcvreport.measures.friction_demand as fdm
    real = fdm.nonlinear_model
    monkeypatch.setattr(fdm, "nonlinear_model", lambda *a, **k: _stiff(real(*a, **k)))
    lumped = _lumped(v)
    assert _path_difference(lumped, 10.0) <= 0.005                 # within 5 mm on the 90 deg turn
    if any(len(u.axles) > 1 for u in v.units[1:]):
        assert _path_difference(v, 10.0) > 0.01                    # the rule's own omission, not noise


def test_a_steady_circle_is_the_algebraic_steady_state():
    """Constant steer and speed: the run settles on the steady state a root finder gives from the
    steady equations -- every unit turning at one rate about one centre, its forces and moment in
    balance with its centripetal inertia (the Newton-Euler equations of tests/test_nonlinear.py
    with zero accelerations in the units' turning frame)."""
    from scipy.optimize import fsolve
    from test_nonlinear import newton_euler
    v = load_vehicle(EXAMPLES / "b_double.toml")
    N = v.n_units
    m = nonlinear_model(v)
    U, delta = 15.0, 0.02
    run = integrate(m, step(delta), U, 60.0, 0.5, rtol=1e-11, atol=1e-13)
    x_end = run.state_at([60.0])[0]
    w = m.zero_input()
    w[0] = delta

    def steady(p):                         # p = [v1, Omega, theta_1..theta_(N-1)]: x' has v1' = r' = 0
        v1, omega, theta = p[0], p[1], p[2:]
        psi = -np.r_[0.0, np.cumsum(theta)]
        x = np.r_[0.0, 0.0, psi, v1, np.full(N, omega)]
        xd, _D = newton_euler(v, x, w, U)
        return np.r_[xd[2 + N], xd[3 + N:]]

    guess = np.r_[x_end[2 + N], x_end[3 + N], -np.diff(x_end[2:2 + N])]
    p = fsolve(steady, guess, xtol=1e-14)
    assert np.abs(steady(p)).max() < 1e-10
    got = np.r_[x_end[2 + N], x_end[3 + N:], -np.diff(x_end[2:2 + N])]
    ref = np.r_[p[0], np.full(N, p[1]), p[2:]]
    assert np.abs(got - ref).max() <= 1e-8 * np.abs(ref).max(), np.abs(got - ref) / np.abs(ref).max()


def tandem_closed_form(truck, U):
    """x0 [m]: the point of a rigid truck's axis with no lateral velocity in a steady turn at
    ``U`` [m/s] with linear tires, written out (docs/nonlinear.md#tandem-scrub): A x0 + B = 0 with
    A = sum_r C_j (x_j - x_s) - sum_r C_M,j + (C_M,s / C_s) sum_r C_j and
    B = -sum_r C_j (x_j - x_s) x_j + sum_r C_M,j x_j - sum_all C_S,j D_j^2
        - (C_M,s / C_s)(m U^2 + sum_r C_j x_j) + x_s m U^2
    (r: the unsteered axles, s: the steer axle; per-axle sums over the tires)."""
    steer = next(a for a in truck.axles if a.steered)
    rear = [a for a in truck.axles if not a.steered]
    C = {a.name: a.tires * a.cornering_stiffness_N_per_rad for a in truck.axles}
    CM = {a.name: a.tires * a.aligning_stiffness_Nm_per_rad for a in truck.axles}
    CSD2 = sum(a.tires * a.longitudinal_stiffness_N * a.dual_spacing_m ** 2 for a in truck.axles)
    xs, m = steer.x_m, truck.mass_kg
    k = CM[steer.name] / C[steer.name]
    A = sum(C[a.name] * (a.x_m - xs) for a in rear) - sum(CM[a.name] for a in rear) + k * sum(C[a.name] for a in rear)
    B = (-sum(C[a.name] * (a.x_m - xs) * a.x_m for a in rear) + sum(CM[a.name] * a.x_m for a in rear) - CSD2
         - k * (m * U ** 2 + sum(C[a.name] * a.x_m for a in rear)) + xs * m * U ** 2)
    return -B / A, C


def test_a_rigid_trucks_tandem_meets_the_closed_form_scrub_balance():
    """docs/nonlinear.md#tandem-scrub: a rigid truck turning steadily at walking pace turns about
    the point x0 of its axis given in closed form by its moment balance about the steer axle
    (the tandem's scrub forces, every aligning and dual-tire moment, the centripetal inertia);
    then each unsteered axle carries F_j = -C_j (x_j - x0) / d exactly (d = U / r), the two
    axles of the tandem push opposite ways, and the steer axle carries the rest.  The closed form
    takes the steer axle's force along the truck's y; the difference is O(delta^2): shown at two
    steer angles."""
    import dataclasses
    full = load_vehicle(EXAMPLES / "truck_full_trailer.toml")
    truck = dataclasses.replace(full.units[0], rear_coupling_m=None, rear_coupling_height_m=None,
                                rear_coupling_roll_stiffness_Nm_per_rad=None)
    v = dataclasses.replace(full, name="rigid_truck", units=(truck,))
    m = nonlinear_model(v, tire="linear")
    U = 1.0
    x0, C = tandem_closed_form(truck, U)
    rear = [a for a in truck.axles if not a.steered]
    steer = next(a for a in truck.axles if a.steered)
    worst = {}
    for delta in (0.02, 0.005):
        run = integrate(m, step(delta), U, 120.0, 1.0)
        x = run.state_at([120.0])[0]
        out = m.outputs(0.0, x, np.r_[delta, np.zeros(len(m.input_names) - 1)], U)
        v_lat, omega = x[3], x[-1]
        d = U / omega
        worst[delta] = max(abs(out[f"Fy_{a.name}"] / (-C[a.name] * (a.x_m - x0) / d) - 1) for a in rear)
        assert -v_lat / omega == pytest.approx(x0, abs=1e-5)
        assert out[f"Fy_{steer.name}"] * math.cos(delta) == pytest.approx(
            -sum(out[f"Fy_{a.name}"] for a in rear) + truck.mass_kg * U ** 2 / d, rel=1e-6)
        assert out[f"Fy_{rear[0].name}"] * out[f"Fy_{rear[-1].name}"] < 0        # the tandem scrubs
    assert worst[0.02] < 1e-6 and worst[0.005] < worst[0.02] / 8, worst          # O(delta^2): 3.8e-7, 2.4e-8


def test_the_friction_demand_is_the_tire_forces_share_of_the_friction():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    t = turn_with_tire_forces(v, angle_deg=90.0)
    r = t.response
    for a in v.axles:
        fd = np.hypot(r[f"Fx_{a.name}"], r[f"Fy_{a.name}"]) / (0.8 * a.static_load_N)
        assert np.allclose(r[f"fd_{a.name}"], fd, rtol=1e-12)
        assert t.friction_demand[a.name] == pytest.approx(fd.max(), rel=1e-12)
    assert t.stfd == t.friction_demand["steer"] and t.path_error_max_m <= 0.05
    assert 0.05 < t.stfd < 1.0 and 0.05 < t.friction_demand_drive < 1.0
    assert t.turn.lssp_m == pytest.approx(t.kinematic.lssp_m, abs=0.1)


def test_lcv_turn_with_tire_forces_and_its_refusals(tmp_path):
    p = subprocess.run(LCV + ["turn", "--vehicle", str(EXAMPLES / "b_double.toml"), "--model", "nonlinear", "--json"],
                       capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert set(doc["friction_demand"]) == set(load_vehicle(EXAMPLES / "b_double.toml").axle_names)
    assert doc["stfd"] == max(doc["friction_demand"][a] for a in ("steer",))
    for bad, what in ((["--friction-coefficient", "0"], "friction"), (["--speed-kph", "-3"], "speed")):
        q = subprocess.run(LCV + ["turn", "--vehicle", str(EXAMPLES / "b_double.toml"), "--model", "nonlinear", *bad],
                           capture_output=True, text=True, timeout=60)
        assert q.returncode == 2 and q.stderr.count("\n") == 1 and what in q.stderr, q.stderr
    q = subprocess.run(LCV + ["turn", "--preset", "aucnat", "--speed-kph", "5"], capture_output=True, text=True, timeout=60)
    assert q.returncode == 2 and "nonlinear" in q.stderr


def test_a_run_that_loses_traction_stops_naming_the_axle_and_the_time():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    p = subprocess.run(LCV + ["simulate", "--vehicle", str(EXAMPLES / "b_double.toml"), "--speed-kph", "60", "--model",
                              "nonlinear", "--friction-coefficient", "0.3", "--steer", "step:0.1", "--t-end", "5"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2 and p.stderr.count("\n") == 1, p.stderr
    assert "at t = " in p.stderr and "driven axle" in p.stderr and v.name


def test_the_law_holds_the_path_and_the_turns_tolerance_is_the_strict_ones():
    """The path-following law's integral term removes the steady error a proportional law leaves
    (the steer slip the tandem's scrub needs over K: 0.13-0.18 m on the examples at K = 0.5);
    the turn's integration tolerance (TURN_RTOL, 1e-5) gives the friction demands of rtol 1e-7
    to its own order (measured 2.6e-6 on the western double)."""
    from lcvreport.measures.friction_demand import LOST_PATH_M, PATH_ERROR_MAX_M, TURN_RTOL
    from lcvreport.model.presets import load_preset
    v = load_preset("tractor_semitrailer")
    t = turn_with_tire_forces(v, angle_deg=90.0)
    e = t.response["path_error"]
    assert t.path_error_max_m <= PATH_ERROR_MAX_M and abs(e[-1]) < 1e-3 * PATH_ERROR_MAX_M
    strict = turn_with_tire_forces(v, angle_deg=90.0, rtol=1e-7)
    assert TURN_RTOL > 1e-7
    for key in ("stfd", "friction_demand_drive", "path_error_max_m"):       # to the tolerance's order
        assert getattr(t, key) == pytest.approx(getattr(strict, key), rel=2e-5), key
    # too fast for the circle: the combination leaves the path; the run stops there, with a reason
    fast = turn_with_tire_forces(load_vehicle(EXAMPLES / "western_double.toml"), angle_deg=90.0, speed_kph=30.0)
    assert fast.stfd is None and fast.friction_demand_drive is None and fast.turn is None
    assert fast.path_error_max_m >= LOST_PATH_M and "left the path" in fast.undefined["stfd"]
    assert fast.response.stopped_at is not None and fast.response.time[-1] <= fast.response.stopped_at


def test_on_a_path_that_comes_back_over_itself_the_heading_places_the_point():
    """A full circle's exit runs over its approach and its laps coincide: a point near the start
    is on the approach while the heading is the approach's, on the exit after the lap; on a
    four-lap arc the lap is the heading's (the turn's law reads unit 1's heading, unwrapped)."""
    from lcvreport.manoeuvres.paths import StraightArcPath
    from lcvreport.measures.friction_demand import path_coordinates
    R = 12.5
    lap = StraightArcPath(R, 2 * math.pi, 20.0)
    assert path_coordinates(lap, -1.0, 0.2, heading_rad=0.0) == (-1.0, 0.2)
    s, e = path_coordinates(lap, 1.0, 0.2, heading_rad=2 * math.pi)
    assert (s, e) == (pytest.approx(2 * math.pi * R + 1.0, abs=1e-12), pytest.approx(0.2, abs=1e-12))
    s, e = path_coordinates(lap, 1.0, 0.2, heading_rad=0.1)           # just into the arc: its first lap
    assert s == pytest.approx(R * math.atan2(1.0, R - 0.2), abs=1e-12) and e == pytest.approx(R - math.hypot(1.0, R - 0.2))
    four = StraightArcPath(R, 8 * math.pi, 20.0)
    X, Y = R * math.sin(1.0), R * (1 - math.cos(1.0))                  # on the circle at 1 rad
    for k in range(4):
        s, e = path_coordinates(four, X, Y, heading_rad=1.0 + 2 * math.pi * k + 0.4)   # the heading a little off
        assert s == pytest.approx(R * (1.0 + 2 * math.pi * k), abs=1e-9) and abs(e) < 1e-12
    # without a heading, every piece counts (a path that does not come back over itself needs none)
    quarter = StraightArcPath(R, math.pi / 2, 20.0)
    assert path_coordinates(quarter, R + 0.3, R + 5.0) == (pytest.approx(R * math.pi / 2 + 5.0), pytest.approx(-0.3))   # right of it


def test_a_long_turn_settles_on_the_steady_circle_of_its_radius():
    """Four laps (1440 deg) of the tractor-semitrailer with tire forces: on the last lap the run
    is the steady circle a root finder gives from the Newton-Euler equations (tests/test_nonlinear.py)
    with the outside steer wheel at the turn's radius -- every unit at one yaw rate, unit 1's
    lateral velocity, the articulation and the steer.  (The run once stopped at its start: the
    exit of a turn past 360 deg runs over the approach and the law took the exit for the place.)"""
    from scipy.optimize import fsolve
    from test_nonlinear import newton_euler
    from lcvreport.measures.friction_demand import TURN_RTOL
    from lcvreport.model.presets import load_preset
    v = load_preset("tractor_semitrailer")
    N, R = v.n_units, 12.5
    t = turn_with_tire_forces(v, radius_m=R, angle_deg=1440.0)
    assert t.stfd is not None and t.path_error_max_m < 0.05
    r, follow = t.response, t.follow
    U = r.speed_mps
    heading = -r.state_at(r.time)[:, 2]
    tk = float(np.interp(7 * math.pi, heading, r.time))                # three and a half laps into the arc
    x_run = r.state_at([tk])[0]
    delta_run = float(follow(np.array([tk]), x_run[:, None])[0])
    steer = next(a for a in v.units[0].axles if a.steered)
    m = nonlinear_model(v)

    def steady(p):                           # p = [v1, Omega, theta_1..theta_(N-1), delta]
        v1, omega, theta, delta = p[0], p[1], p[2:N + 1], p[N + 1]
        x = np.r_[0.0, 0.0, -np.r_[0.0, np.cumsum(theta)], v1, np.full(N, omega)]
        w = m.zero_input()
        w[0] = delta
        xd, _D = newton_euler(v, x, w, U)
        xc, yc = -v1 / omega, U / omega      # the centre of the turn in unit 1's axes (x forward, y right)
        radius = math.hypot(steer.x_m - xc, steer.track_width_m / 2 - yc)
        return np.r_[xd[2 + N], xd[3 + N:], radius - R]

    guess = np.r_[x_run[2 + N], x_run[3 + N], -np.diff(x_run[2:2 + N]), delta_run]
    p = fsolve(steady, guess, xtol=1e-13)
    assert np.abs(steady(p)).max() < 1e-9
    got = np.r_[x_run[2 + N], x_run[3 + N:3 + 2 * N], -np.diff(x_run[2:2 + N]), delta_run]
    ref = np.r_[p[0], np.full(N, p[1]), p[2:N + 1], p[N + 1]]
    assert np.abs(got - ref).max() <= TURN_RTOL * np.abs(ref).max()     # measured 1.8e-6 of each


def test_a_b_double_past_three_quarter_turns_is_refused_by_its_traction():
    """At 12.5 m the B-double's rear trailer winds in towards a jackknife (the kinematic turn
    reaches 95 deg of articulation at 300 deg); with tire forces the drive axle cannot pull it
    round past ~265 deg: the run stops naming the axle and the time, and the registry's family
    gives no friction demand with that reason -- never a number, never the run stuck at its start."""
    from lcvreport.analysis.integrate import IntegrationError
    v = load_vehicle(EXAMPLES / "b_double.toml")
    with pytest.raises(IntegrationError, match=r"at t = 3\d\.\d+ s: driven axle drive1 needs .* the speed cannot be held"):
        turn_with_tire_forces(v, angle_deg=360.0)
    assert turn_with_tire_forces(v, angle_deg=250.0).stfd is not None


def test_a_vehicle_that_differs_only_in_its_bodies_shares_the_run_and_reads_its_own_bodies():
    """The run of the turn with tire forces reads the bodies only through the overall length (the
    exit straight): a variant with wider bodies finds the run computed for the vehicle, and its
    answer equals the one computed for it alone, bit for bit -- friction demands, path error, the
    poses -- with the swept path of its own bodies.  A longer rear overhang (a longer vehicle) is
    a new run."""
    v = load_vehicle(EXAMPLES / "b_double.toml")
    wider = dataclasses.replace(v, units=tuple(dataclasses.replace(u, body_width_m=u.body_width_m + 0.2)
                                               for u in v.units))
    last = v.units[-1]
    longer = dataclasses.replace(v, units=(*v.units[:-1], dataclasses.replace(last, body_rear_m=last.body_rear_m - 0.5)))
    turn_with_tire_forces.cache_clear()
    base = turn_with_tire_forces(v)
    shared = turn_with_tire_forces(wider)
    assert shared.response is base.response and shared.vehicle is wider          # the run found, not recomputed
    assert turn_with_tire_forces(longer).response is not base.response
    turn_with_tire_forces.cache_clear()
    alone = turn_with_tire_forces(wider)
    assert alone.response is not base.response
    assert (shared.stfd, shared.friction_demand_drive, shared.path_error_max_m, shared.friction_demand) == \
        (alone.stfd, alone.friction_demand_drive, alone.path_error_max_m, alone.friction_demand)
    r, q = shared.response, alone.response
    assert np.array_equal(r.time, q.time) and np.array_equal(r.state_at(r.time), q.state_at(q.time))
    assert shared.turn.to_dict() == alone.turn.to_dict()
    assert shared.turn.lssp_m > base.turn.lssp_m + 0.1                           # its own, wider bodies
    assert shared.kinematic.to_dict() == alone.kinematic.to_dict()
