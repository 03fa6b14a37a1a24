"""Exactness claims against independent computations: a stiff ODE solve (solve_ivp,
Radau, rtol 1e-11) restarted at every input or speed change, the matrix exponential of
scipy and at 40 digits (mpmath), finite differences of the lateral velocities.

The package integrates nothing: it uses the exponential of the augmented matrix.
Agreement is asked to 1e-9 relative to each signal's peak.
"""
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest
import scipy.linalg
from conftest import EXAMPLES
from scipy.integrate import solve_ivp

from lcvreport.analysis.discretize import Discretizer
from lcvreport.analysis.modal import modal_response
from lcvreport.analysis.response import iter_step_response, simulate, step_response
from lcvreport.analysis.steady import steady_state
from lcvreport.model.linear import linear_model
from lcvreport.model.presets import PRESETS, load_preset
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule
from lcvreport.units import THESIS, mph_to_mps
from lcvreport.util.numerics import expm, solve_scaled

RTOL = 1e-9
U50 = mph_to_mps(50.0)


def reference(vehicle, t_breaks, speeds, forces, t_eval, tire_scale=1.0):
    """Stiff ODE solution on each interval [t_breaks[i], t_breaks[i+1]] with speed and force held."""
    co = system_coefficients(vehicle)
    n = co.n_states
    z = np.zeros(n + 2)
    out = np.zeros((len(t_eval), n + 2))
    for i in range(len(t_breaks) - 1):
        u, f = speeds[i], forces[i]
        M, S = co.M(u), co.S(u, tire_scale)
        # z' = J z + c, written out from M x' = S x + F (no use of the package's augmented matrix)
        J = np.zeros((n + 2, n + 2))
        J[:n, :n] = np.linalg.solve(M, S)
        J[n, 1], J[n + 1, 0], J[n + 1, n] = 1.0, 1.0, u
        c = np.concatenate([np.linalg.solve(M, f), [0.0, 0.0]])

        a, b = t_breaks[i], t_breaks[i + 1]
        mask = (t_eval >= a) & (t_eval <= b)
        times = np.union1d(t_eval[mask], [b])
        sol = solve_ivp(lambda _t, zz, J=J, c=c: J @ zz + c, (a, b), z, method="Radau", rtol=1e-11, atol=1e-16,
                        t_eval=times, jac=lambda _t, _z, J=J: J)
        assert sol.success
        out[mask] = sol.y.T[np.isin(times, t_eval[mask])]
        z = sol.y[:, -1]
    return out


def _assert_close(actual, ref, rtol=RTOL):
    peak = np.abs(ref).max(axis=0)
    peak[peak == 0] = 1.0
    err = np.abs(actual - ref).max(axis=0) / peak
    assert err.max() <= rtol, err


@pytest.mark.parametrize("preset", PRESETS)
def test_constant_input_matches_stiff_ode(preset):
    v = load_preset(preset)
    F = load_vector(v, one_percent_rule(v, list(v.unit_names[1:])))
    r = step_response(v, U50, F, t_end=10.0, n_points=201)
    _assert_close(r.states, reference(v, [0.0, 10.0], [U50], [F], r.time))


@pytest.mark.parametrize("name", ["aucnat", "tractor_semitrailer", "b_double", "truck_full_trailer"])
def test_piecewise_constant_inputs_with_speed_changes(name):
    """Uneven steps, forces and steer changing between intervals, speed changing too."""
    v = load_preset(name) if name in PRESETS else load_vehicle(EXAMPLES / f"{name}.toml")
    co = system_coefficients(v)
    rng = np.random.default_rng(7)
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.7, size=24))])
    speeds = rng.choice([11.2, 22.352, 31.3, 13.4], size=t.size - 1)
    n_ax = len(v.axles)
    w = np.column_stack([rng.normal(0, 0.002, t.size - 1), rng.normal(0, 900, (t.size - 1, n_ax)),
                         rng.normal(0, 250, (t.size - 1, n_ax))])
    forces = np.array([co.input_matrix() @ wi for wi in w])
    r = simulate(v, t, speeds, forces)
    _assert_close(r.states, reference(v, t, speeds, forces, t))


def test_step_size_does_not_change_the_samples(aucnat):
    """Exact ZOH: the 0.5 s samples of a 1 ms run and of a 0.5 s run coincide."""
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]))
    fine = step_response(aucnat, U50, F, 5.0, 5001)
    coarse = step_response(aucnat, U50, F, 5.0, 11)
    np.testing.assert_allclose(fine.states[::500], coarse.states, rtol=1e-9, atol=1e-12 * np.abs(coarse.states).max())


def test_streamed_response_equals_the_stored_one(aucnat):
    """Bit for bit, on a grid whose steps are exact in binary (2^-7 s): lcv simulate streams
    the same numbers simulate() stores."""
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer3"]))
    dt = 2.0 ** -7
    stored = simulate(aucnat, np.arange(385) * dt, U50, F).states
    streamed = np.array([z for _t, z in iter_step_response(aucnat, U50, F, dt, 384)])
    np.testing.assert_array_equal(streamed, stored)


@pytest.mark.parametrize("preset", PRESETS)
def test_steady_state_is_the_long_time_response(preset):
    v = load_preset(preset)
    F = load_vector(v, one_percent_rule(v, [v.unit_names[-1]]))
    r = step_response(v, U50, F, 60.0, 61)
    xss = steady_state(v, U50, F)
    np.testing.assert_allclose(r.states[-1, :linear_model(v).n_states], xss, rtol=1e-9, atol=1e-12 * np.abs(xss).max())


def test_exact_modal_superposition_matches_stiff_ode(aucnat):
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]))
    t = np.linspace(0, 10, 101)
    x = modal_response(aucnat, U50, F, t, method="exact")
    _assert_close(x, reference(aucnat, [0.0, 10.0], [U50], [F], t)[:, :12])


def test_thesis_modal_method_differs(aucnat):
    """Erratum 3: X^T M X = 1, g = X^T F is not exact for non-symmetric M, S."""
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]), "thesis", THESIS)
    t = np.linspace(0, 10, 101)
    exact = step_response(aucnat, U50, load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "trailer3"]),
                                                    "thesis"), 10.0, 101).states[:, :12]
    exact[:, 0] /= THESIS.length_m
    thesis = modal_response(aucnat, U50, F, t, method="thesis", units=THESIS)
    rel = np.abs(thesis - exact).max(axis=0) / np.abs(exact).max(axis=0)
    assert rel.max() > 0.5 and np.all(rel > 1e-3)


def test_discretizer_caches_repeated_speeds(aucnat):
    d = Discretizer(aucnat)
    a, b = d(U50, 0.01), d(U50, 0.01)
    assert a[0] is b[0] and d.cache_size == 1
    d(20.0, 0.01)
    assert d.cache_size == 2


def test_lateral_accelerations_are_the_derivative_of_the_lateral_velocities(aucnat):
    """a_i = v_i' + u r_i: against central differences of v_i = V x along a fine exact run."""
    co = system_coefficients(aucnat)
    F = load_vector(aucnat, one_percent_rule(aucnat, ["trailer2", "tractor"])) + 0.01 * co.B_delta()
    h = 1e-4
    r = step_response(aucnat, U50, F, 2.0, 20001)
    v = r.states[:, :12] @ co.velocity_map(U50).T
    dv = (v[2:] - v[:-2]) / (2 * h)
    a_fd = dv + U50 * r.states[1:-1, 1:7]
    np.testing.assert_allclose(r.lateral_acceleration[1:-1], a_fd, rtol=0, atol=1e-6 * np.abs(a_fd).max())


# ---------------------------------------------------------------------------- the matrix exponentials
def _mp_expm(A: np.ndarray) -> np.ndarray:
    mp.mp.dps = 40
    return np.array(mp.expm(mp.matrix(A.tolist())).tolist(), dtype=float)


@pytest.mark.parametrize("u, h", [(2.2352, 0.02), (22.352, 0.01), (31.3, 0.25)])
def test_numpy_expm_and_scipy_expm_are_both_exact_to_rounding(aucnat, u, h):
    """The FMU engine's numpy expm and scipy's, on the augmented step matrix, each within
    100 eps (of the matrix' largest entry) of a 40-digit exponential of the same matrix."""
    from lcvreport.analysis.discretize import augmented_state_matrix
    A, G = augmented_state_matrix(system_coefficients(aucnat), u)
    n, m = G.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n], big[:n, n:] = A * h, G * h
    exact = _mp_expm(big)
    scale = np.abs(exact).max()
    for name, E in (("numpy", expm(big)), ("scipy", scipy.linalg.expm(big))):
        err = np.abs(E - exact).max() / scale
        assert err <= 100 * np.finfo(float).eps, (name, err)


def test_equilibrated_solve_beats_the_plain_one_at_low_speed(aucnat):
    """M mixes N and N*m rows: at 0.1 m/s the scaled solve of M^-1 S is within 1e-13 of a
    40-digit solve; the point of solve_scaled (see lcvreport.util.numerics)."""
    co = system_coefficients(aucnat, THESIS)
    M, S = co.M(0.1), co.S(0.1)
    mp.mp.dps = 40
    exact = np.array((mp.matrix(M.tolist()) ** -1 * mp.matrix(S.tolist())).tolist(), dtype=float)
    scaled = solve_scaled(M, S)
    err = np.abs(scaled - exact).max(axis=1) / np.abs(exact).max(axis=1)
    assert err.max() < 1e-13, err.max()
