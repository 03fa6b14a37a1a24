"""scipy's Radau over many variants side by side (lcvreport.analysis.radau_batch): each variant
takes scipy's steps to its tolerance, its run is the same bit for bit alone and in a batch, a
variant that fails or stops leaves the others as they were; the turn with tire forces of a batch
equals each vehicle's alone (bit for bit) and scipy's solve_ivp of the same equations."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lcvreport.analysis.radau_batch import RowFailure, radau_batch
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLES

MUS = np.array([1.0, 30.0, 1000.0])


def _vdp(t, Y, rows):
    """van der Pol, stiffness mu per variant."""
    mu = MUS[rows]
    return np.stack([Y[:, 1], mu * (1 - Y[:, 0] ** 2) * Y[:, 1] - Y[:, 0]], axis=1)


def _alone(k):
    return lambda t, Y, rows: _vdp(t, Y, np.full_like(rows, k))


def test_each_variant_takes_scipys_steps_and_reaches_its_values():
    y0 = np.tile([2.0, 0.0], (MUS.size, 1))
    runs = radau_batch(_vdp, 0.0, y0, 6.0, 1e-6, 1e-9)
    for k, mu in enumerate(MUS):
        ref = solve_ivp(lambda t, y: [y[1], mu * (1 - y[0] ** 2) * y[1] - y[0]], (0.0, 6.0), [2.0, 0.0],
                        method="Radau", rtol=1e-6, atol=1e-9, dense_output=True)
        assert runs[k].status == 0
        # the same method and controller: the step counts agree to a step or two (the Jacobian is
        # a plain forward difference here, scipy's an adaptive one)
        assert abs(len(runs[k].t) - (ref.t.size - 1)) <= 2
        t = np.linspace(0.0, 6.0, 61)
        scale = np.abs(ref.sol(t)).max(axis=1)
        assert np.abs(runs[k].sol(t) - ref.sol(t)).max(axis=1) / scale == pytest.approx([0, 0], abs=1e-4)
        # and to the solution itself (no closed form: scipy at rtol 1e-11)
        tight = solve_ivp(lambda t, y: [y[1], mu * (1 - y[0] ** 2) * y[1] - y[0]], (0.0, 6.0), [2.0, 0.0],
                          method="Radau", rtol=1e-11, atol=1e-13)
        assert np.abs(runs[k].sol(6.0) - tight.y[:, -1]).max() < 2e-4 * max(1.0, np.abs(tight.y[:, -1]).max())


def test_a_variant_alone_and_in_a_batch_is_the_same_bit_for_bit():
    y0 = np.tile([2.0, 0.0], (MUS.size, 1))
    runs = radau_batch(_vdp, 0.0, y0, 6.0, 1e-6, 1e-9)
    t = np.linspace(0.0, 6.0, 601)
    for k in range(MUS.size):
        solo = radau_batch(_alone(k), 0.0, y0[k:k + 1], 6.0, 1e-6, 1e-9)[0]
        assert solo.t == runs[k].t
        assert np.array_equal(solo.sol(t), runs[k].sol(t))


def test_a_failing_variant_leaves_the_others_as_they_were():
    def fun(t, Y, rows):
        bad = np.flatnonzero((rows == 1) & (t > 0.5))
        if bad.size:
            raise RowFailure(int(bad[0]), "variant 1 gave up")
        return _vdp(t, Y, rows)

    y0 = np.tile([2.0, 0.0], (MUS.size, 1))
    runs = radau_batch(fun, 0.0, y0, 3.0, 1e-6, 1e-9)
    assert runs[1].status == -1 and "variant 1 gave up" in runs[1].message and "at t = 0.5" in runs[1].message
    clean = radau_batch(_vdp, 0.0, y0, 3.0, 1e-6, 1e-9)
    t = np.linspace(0.0, 3.0, 31)
    for k in (0, 2):
        assert runs[k].status == 0 and np.array_equal(runs[k].sol(t), clean[k].sol(t))


def test_the_stop_condition_ends_a_run_where_scipys_event_does():
    k = np.array([1.0, 2.0, 0.1])
    fun = lambda t, Y, rows: -k[rows, None] * Y                          # noqa: E731
    stop = lambda t, Y, rows: Y[:, 0] - 0.5                              # noqa: E731
    runs = radau_batch(fun, 0.0, np.ones((3, 1)), 2.0, 1e-8, 1e-12, stop=stop)
    # y = exp(-k t) falls through 0.5 at ln 2 / k: inside the run for k = 1 and 2, not for 0.1
    assert runs[0].status == 1 and runs[0].stopped_at == pytest.approx(np.log(2.0), abs=1e-8)
    assert runs[1].status == 1 and runs[1].stopped_at == pytest.approx(np.log(2.0) / 2, abs=1e-8)
    assert runs[2].status == 0 and runs[2].stopped_at is None


def test_the_evaluation_budget_ends_a_run_with_a_message_not_a_hang():
    runs = radau_batch(_vdp, 0.0, np.array([[2.0, 0.0]]), 6.0, 1e-6, 1e-9, max_evaluations=20)
    assert runs[0].status == -1 and "after 20 evaluations" in runs[0].message


def _variant(v, trailer_mass, stiffness):
    units = [v.units[0]]
    for u in v.units[1:]:
        units.append(dataclasses.replace(u, mass_kg=u.mass_kg * trailer_mass, axles=tuple(
            dataclasses.replace(a, cornering_stiffness_N_per_rad=a.cornering_stiffness_N_per_rad * stiffness)
            for a in u.axles)))
    return dataclasses.replace(v, units=tuple(units))


def test_the_turns_of_a_batch_are_each_vehicles_own_bit_for_bit():
    from lcvreport.measures.friction_demand import turns_with_tire_forces
    v = load_vehicle(EXAMPLES / "b_double.toml")
    vs = [v, _variant(v, 0.8, 1.1), _variant(v, 1.05, 0.9)]
    batch = turns_with_tire_forces(vs)
    for k in (0, 2):
        solo = turns_with_tire_forces([vs[k]])[0]
        assert solo.stfd == batch[k].stfd and solo.friction_demand == batch[k].friction_demand
        t = solo.response.time
        assert np.array_equal(solo.response.state_at(t), batch[k].response.state_at(t))
    assert len({b.stfd for b in batch}) == 3                # three vehicles, three answers


@pytest.mark.slow
def test_the_turn_equals_scipys_solve_ivp_of_the_same_equations():
    """The batch integrator against scipy's (lcvreport.analysis.integrate: solve_ivp, Radau) on the
    turn's own equations, both at rtol 1e-8: the friction demands agree to 1e-7."""
    import math

    from lcvreport.analysis.integrate import integrate
    from lcvreport.measures.friction_demand import (PATH_GAIN_RAD_PER_M, SAMPLES_PER_M, PathFollowing,
                                                    turn_with_tire_forces)
    from lcvreport.measures.low_speed import low_speed_turn
    from lcvreport.model.nonlinear.model import nonlinear_model
    from lcvreport.units import kph_to_mps
    v = load_vehicle(EXAMPLES / "western_double.toml")
    ours = turn_with_tire_forces(v, rtol=1e-8)
    kin = low_speed_turn(v).run
    steer_axle = max((a for a in v.units[0].axles if a.steered), key=lambda a: a.x_m)
    U = kph_to_mps(5.0)
    follow = PathFollowing(nonlinear_model(v), kin, steer_axle, PATH_GAIN_RAD_PER_M, U)
    x0 = np.zeros(len(follow.state_names))
    x0[0], x0[1] = -steer_axle.x_m, -steer_axle.track_width_m / 2
    dt = 1.0 / (SAMPLES_PER_M * U)
    n = max(int(math.ceil(kin.path.s_end / U / dt)), 200)
    ref = integrate(follow, follow, U, n * dt, dt, x0=x0, rtol=1e-8, stop=follow.lost)
    assert ref.stopped_at is None and ours.response.stopped_at is None
    for a in v.axles:
        assert ours.friction_demand[a.name] == pytest.approx(float(np.max(ref[f"fd_{a.name}"])), abs=1e-7)
    t = ref.time
    assert np.abs(ours.response.state_at(t)[:, :2] - ref.state_at(t)[:, :2]).max() < 1e-6     # positions [m]


def test_a_study_blocks_prefetched_turns_are_the_ones_its_cases_ask_for(monkeypatch):
    """prefetch_cases computes a block's turns under the keys that each case's assessment looks
    up: the cases then compute no turn of their own (a key that did not match would be silently
    slow, each case integrating its turn alone)."""
    from lcvreport.measures import friction_demand as fd
    from lcvreport.measures.case import Case
    from lcvreport.measures.scheme import loads_scheme
    v = load_vehicle(EXAMPLES / "b_double.toml")
    vs = [_variant(v, 0.85, 1.0), _variant(v, 0.95, 1.05)]
    scheme = loads_scheme("""
scheme = "stfd"
levels = ["L1"]
[measures.stfd]
turn_speed_kph = 5.0
friction_coefficient = 0.7
source = "test"
levels = { L1 = { max = 0.8 } }
""")
    fd.turn_with_tire_forces.cache_clear()
    fd.prefetch_cases(vs, [1.0, 1.0], ["stfd"], {"turn_speed_kph": 5.0, "friction_coefficient": 0.7})
    calls = []
    real = fd.turns_with_tire_forces
    monkeypatch.setattr(fd, "turns_with_tire_forces", lambda *a, **k: calls.append(a) or real(*a, **k))
    values = [Case(w).assess(scheme).measures[0].value for w in vs]
    assert calls == [] and all(0.0 < x < 1.0 for x in values)
