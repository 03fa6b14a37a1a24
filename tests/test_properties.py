"""Property tests over random trains and speeds (hypothesis)."""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from lcvreport.linear import eigenvalues, simulate, steady_state
from lcvreport.loads import ResidualLoads, load_vector
from lcvreport.model import system_coefficients, system_matrices

from helpers import speeds, trains

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True)


@SETTINGS
@given(trains(), speeds, st.floats(0.2, 3.0))
def test_eigenvalues_come_in_conjugate_pairs(train, u, s):
    lam = eigenvalues(train, u, s)
    assert lam.size == 2 * train.n_units
    complex_part = lam[np.abs(lam.imag) > 1e-9 * np.abs(lam).max()]
    np.testing.assert_allclose(np.sort_complex(complex_part), np.sort_complex(complex_part.conj()),
                               rtol=1e-8, atol=1e-10 * np.abs(lam).max())
    for i in range(0, complex_part.size, 2):  # mode order: +Im member first, then its conjugate
        assert complex_part[i].imag > 0
        assert complex_part[i + 1] == np.conj(complex_part[i]) or np.isclose(complex_part[i + 1], np.conj(complex_part[i]))


@SETTINGS
@given(trains(), speeds)
def test_no_residual_loads_stays_at_rest(train, u):
    t = np.linspace(0, 5, 51)
    r = simulate(train, t, u, np.zeros(2 * train.n_units))
    assert np.all(r.states == 0.0)


def _random_loads(train, seed):
    rng = np.random.default_rng(seed)
    return ResidualLoads({a: rng.normal(0, 200) for a in train.axle_names},
                         {a: rng.normal(0, 200) for a in train.axle_names})


@SETTINGS
@given(trains(), speeds, st.integers(0, 10**6))
def test_doubling_P_and_T_doubles_the_response(train, u, seed):
    loads = _random_loads(train, seed)
    t = np.linspace(0, 3, 31)
    r1 = simulate(train, t, u, load_vector(train, loads))
    r2 = simulate(train, t, u, load_vector(train, loads.scaled(2.0)))
    np.testing.assert_allclose(r2.states, 2 * r1.states, rtol=1e-12, atol=1e-14 * np.abs(r1.states).max())
    x1 = steady_state(train, u, load_vector(train, loads))
    x2 = steady_state(train, u, load_vector(train, loads.scaled(2.0)))
    np.testing.assert_allclose(x2, 2 * x1, rtol=1e-12, atol=1e-14 * np.abs(x1).max())


@SETTINGS
@given(trains(1, 1, cm=False), speeds)
def test_tractor_alone_is_the_classic_bicycle_model(train, u):
    """N = 1 without aligning moments: the textbook single-track model
    m (v' + u r) = sum F, I r' = sum a F with F = C (delta - (v + a r)/u)."""
    (tractor,) = train.units
    m, I = tractor.mass, tractor.inertia
    C = np.array([a.CF for a in tractor.axles])
    a = np.array([a.position_in for a in tractor.axles])
    A_ref = np.array([[-C.sum() / (m * u), -(C * a).sum() / (m * u) - u],
                      [-(C * a).sum() / (I * u), -(C * a * a).sum() / (I * u)]])
    b_ref = np.array([C[0] / m, C[0] * a[0] / I])  # steer on axle 11 only
    M, S = system_matrices(train, u)
    np.testing.assert_allclose(np.linalg.solve(M, S), A_ref, rtol=1e-12)
    np.testing.assert_allclose(np.linalg.solve(M, system_coefficients(train).B_delta()), b_ref, rtol=1e-12)
    assert train.state_names == ("v1", "r1")


@SETTINGS
@given(trains(1, 1), speeds)
def test_tractor_alone_with_aligning_moments_and_duals(train, u):
    """N = 1 with the thesis' aligning moment M = -CM alpha and dual term -CS D^2 r/u."""
    (tractor,) = train.units
    m, I, D = tractor.mass, tractor.inertia, train.dual_spacing_in
    ax = tractor.axles
    C = np.array([x.CF for x in ax])
    CM = np.array([x.CM for x in ax])
    CS = np.array([x.CS if x.dual else 0.0 for x in ax])
    a = np.array([x.position_in for x in ax])
    A_ref = np.array([[-C.sum() / (m * u), -(C * a).sum() / (m * u) - u],
                      [(-(C * a).sum() + CM.sum()) / (I * u),
                       (-(C * a * a).sum() + (CM * a).sum() - (CS * D * D).sum()) / (I * u)]])
    M, S = system_matrices(train, u)
    np.testing.assert_allclose(np.linalg.solve(M, S), A_ref, rtol=1e-12)
