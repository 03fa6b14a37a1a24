"""Exactness claims against an independent stiff ODE solve (solve_ivp, Radau, rtol 1e-11).

The reference integrates M x' = S x + F, psi1' = r1, Y1' = v1 + u psi1 directly,
restarting at every input or speed change; the package uses the exponential of the
augmented matrix.  Agreement is asked to 1e-9 relative to each signal's peak.
"""
from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lcvreport.linear import Discretizer, modal_response, simulate, steady_state, step_response
from lcvreport.loads import load_vector, one_percent_rule
from lcvreport.model import system_coefficients
from lcvreport.presets import PRESETS, load_preset

RTOL = 1e-9


def reference(train, t_breaks, speeds, forces, t_eval, tire_scale=1.0):
    """Stiff ODE solution on each interval [t_breaks[i], t_breaks[i+1]] with speed and force held."""
    co = system_coefficients(train)
    n = co.n_states
    z = np.zeros(n + 2)
    out = np.zeros((len(t_eval), n + 2))
    for i in range(len(t_breaks) - 1):
        u, f = speeds[i], forces[i]
        M, S = co.M(u), co.S(u, tire_scale)

        def rhs(_t, zz, M=M, S=S, f=f, u=u):
            dx = np.linalg.solve(M, S @ zz[:n] + f)
            return np.concatenate([dx, [zz[1], zz[0] + u * zz[n]]])

        a, b = t_breaks[i], t_breaks[i + 1]
        mask = (t_eval >= a) & (t_eval <= b)
        sol = solve_ivp(rhs, (a, b), z, method="Radau", rtol=1e-11, atol=1e-16,
                        t_eval=t_eval[mask], dense_output=False)
        assert sol.success
        out[mask] = sol.y.T
        z = solve_ivp(rhs, (a, b), z, method="Radau", rtol=1e-11, atol=1e-16).y[:, -1]
    return out


def _assert_close(actual, ref):
    peak = np.abs(ref).max(axis=0)
    peak[peak == 0] = 1.0
    err = np.abs(actual - ref).max(axis=0) / peak
    assert err.max() <= RTOL, err


@pytest.mark.parametrize("preset", PRESETS)
def test_constant_input_matches_stiff_ode(preset):
    train = load_preset(preset)
    units = [u.name for u in train.units[1:]]
    F = load_vector(train, one_percent_rule(train, units), "consistent")
    r = step_response(train, 880.0, F, t_end=10.0, n_points=201)
    ref = reference(train, [0.0, 10.0], [880.0], [F], r.time)
    _assert_close(r.states, ref)


@pytest.mark.parametrize("preset", ["aucnat", "tractor_semitrailer", "empty"])
def test_piecewise_constant_inputs_with_speed_changes(preset):
    """Uneven steps, forces and steer changing between intervals, speed changing too."""
    train = load_preset(preset)
    co = system_coefficients(train)
    rng = np.random.default_rng(7)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.7, size=24))])
    speeds = rng.choice([440.0, 880.0, 1232.0, 528.0], size=t.size - 1)
    n_ax = len(train.axles)
    w = np.column_stack([rng.normal(0, 0.002, t.size - 1), rng.normal(0, 200, (t.size - 1, n_ax)),
                         rng.normal(0, 2000, (t.size - 1, n_ax))])
    forces = np.array([co.input_matrix() @ wi for wi in w])
    r = simulate(train, t, speeds, forces)
    ref = reference(train, t, speeds, forces, t)
    _assert_close(r.states, ref)


def test_step_size_does_not_change_the_samples(aucnat):
    """Exact ZOH: the 0.5 s samples of a 1 ms run and of a 0.5 s run coincide."""
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]))
    fine = step_response(aucnat, 880.0, F, 5.0, 5001)
    coarse = step_response(aucnat, 880.0, F, 5.0, 11)
    np.testing.assert_allclose(fine.states[::500], coarse.states, rtol=1e-9, atol=1e-12 * np.abs(coarse.states).max())


@pytest.mark.parametrize("preset", PRESETS)
def test_steady_state_is_the_long_time_response(preset):
    train = load_preset(preset)
    F = load_vector(train, one_percent_rule(train, [train.units[-1].name]))
    r = step_response(train, 880.0, F, 60.0, 61)
    xss = steady_state(train, 880.0, F)
    n = 2 * train.n_units
    np.testing.assert_allclose(r.states[-1, :n], xss, rtol=1e-9, atol=1e-12 * np.abs(xss).max())


def test_exact_modal_superposition_matches_stiff_ode(aucnat):
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]))
    t = np.linspace(0, 10, 101)
    x = modal_response(aucnat, 880.0, F, t, method="exact")
    ref = reference(aucnat, [0.0, 10.0], [880.0], [F], t)[:, :12]
    _assert_close(x, ref)


def test_thesis_modal_method_differs(aucnat):
    """Erratum 3: X^T M X = 1, g = X^T F is not exact for non-symmetric M, S."""
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]), "thesis")
    t = np.linspace(0, 10, 101)
    exact = step_response(aucnat, 880.0, F, 10.0, 101).states[:, :12]
    thesis = modal_response(aucnat, 880.0, F, t, method="thesis")
    peak = np.abs(exact).max(axis=0)
    rel = np.abs(thesis - exact).max(axis=0) / peak
    assert rel.max() > 0.5  # off by the order of the signal itself
    assert np.all(rel > 1e-3)


def test_discretizer_caches_repeated_speeds(aucnat):
    d = Discretizer(aucnat)
    a = d(880.0, 0.01)
    b = d(880.0, 0.01)
    assert a[0] is b[0] and d.cache_size == 1
    d(700.0, 0.01)
    assert d.cache_size == 2
