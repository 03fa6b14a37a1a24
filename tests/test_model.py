"""The model builder for any chain of units, proven against independent formulations:
the textbook bicycle model (N = 1), Newton-Euler with explicit joint forces (any N,
a B-double, random chains), the unit system the numbers go through."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from conftest import EXAMPLES
from helpers import random_vehicle, speeds, vehicles
from hypothesis import given, settings
from hypothesis import strategies as st

from lcvreport import eigenvalues, modes, steady_state
from lcvreport.analysis.modes import sort_eigenvalues
from lcvreport.model.linear import linear_model
from lcvreport.model.presets import PRESETS, load_preset
from lcvreport.model.vehicle import Axle, Unit, Vehicle
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.model.yaw_plane.equations import system_coefficients, system_matrices
from lcvreport.model.yaw_plane.loads import ResidualLoads, load_vector
from lcvreport.units import SI, THESIS, UnitSystem

SETTINGS = settings(max_examples=40, deadline=None, derandomize=True)


def assert_same_spectrum(a: np.ndarray, b: np.ndarray, rtol: float) -> None:
    """Every eigenvalue of ``a`` within ``rtol`` (of the spectral radius) of its own match in ``b``."""
    from scipy.optimize import linear_sum_assignment
    assert a.size == b.size
    cost = np.abs(a[:, None] - b[None, :])
    i, j = linear_sum_assignment(cost)
    scale = np.abs(b).max()
    assert cost[i, j].max() <= rtol * scale, f"largest mismatch {cost[i, j].max() / scale:.2e} of the radius"


# ---------------------------------------------------------------------------- N = 1: the bicycle model
@SETTINGS
@given(st.floats(6e3, 2e4), st.floats(2e4, 1e5), st.floats(1.0, 3.0), st.floats(1.5, 5.0), st.floats(1e5, 4e5),
       st.floats(1e5, 6e5), speeds)
def test_two_axle_truck_is_the_textbook_bicycle_model(m, I, a, b, Cf, Cr, u):
    """Steady yaw-rate gain r/delta = u / (L + K u^2) with the understeer gradient
    K = m (b/C_f - a/C_r) / L [rad s^2/m] (no aligning moments, single tires)."""
    truck = Vehicle("truck", (Unit("truck", m, I, (Axle("f", a, 2, Cf / 2, 0.0, 0.0, 0.0, steered=True),
                                                      Axle("r", -b, 2, Cr / 2, 0.0, 0.0, 0.0))),))
    co = system_coefficients(truck)
    x = -np.linalg.solve(co.S(u), co.B_delta())          # steady state per rad of steer
    L = a + b
    K = m * (b / Cf - a / Cr) / L
    gain = u / (L + K * u * u)
    assert x[1] == pytest.approx(gain, rel=1e-9)
    # and the single-track equations themselves: m (v' + u r) = F_f + F_r, I r' = a F_f - b F_r
    A_ref = np.array([[-(Cf + Cr) / (m * u), -(Cf * a - Cr * b) / (m * u) - u],
                      [-(Cf * a - Cr * b) / (I * u), -(Cf * a * a + Cr * b * b) / (I * u)]])
    np.testing.assert_allclose(np.linalg.solve(co.M(u), co.S(u)), A_ref, rtol=1e-12)
    assert linear_model(truck).state_names == ("v1", "r1")


# ---------------------------------------------------------------------------- Newton-Euler with joint forces
def newton_euler_eigenvalues(v: Vehicle, u: float, tire_scale: float = 1.0) -> np.ndarray:
    """Eigenvalues of the model written unit by unit with the lateral joint forces L_k as
    unknowns (Newton-Euler; no virtual power, no partial velocities):

        m_i (v_i' + u r_i) = F_i + L_(i-1) - L_i
        I_i r_i'           = N_i + fc_i L_(i-1) - rc_i L_i
        theta_k'           = r_k - r_(k+1)
        0 = c_k(y) = v_(k+1) - v_k - rc_k r_k + fc_(k+1) r_(k+1) - u theta_k

    F_i, N_i from the slip angles alpha = -(v_i + x r_i)/u of every axle (F = C_F alpha,
    aligning moment -C_M alpha, dual term -C_S D^2 r/u per tire).  In y = [v, r, theta]:
    E y' = A y + G L with C y = 0; C y' = 0 gives L, and the motion on the constraint
    manifold y = Z xi (an orthonormal null-space basis of C) has the eigenvalues."""
    n = v.n_units
    size = 3 * n - 1
    iv, ir, it = 0, n, 2 * n
    E, A = np.zeros((size, size)), np.zeros((size, size))
    G, C = np.zeros((size, n - 1)), np.zeros((n - 1, size))
    for i, unit in enumerate(v.units):
        E[iv + i, iv + i] = unit.mass_kg
        A[iv + i, ir + i] = -unit.mass_kg * u
        E[ir + i, ir + i] = unit.yaw_inertia_kg_m2
        for ax in unit.axles:
            cf = tire_scale * ax.tires * ax.cornering_stiffness_N_per_rad
            cm = tire_scale * ax.tires * ax.aligning_stiffness_Nm_per_rad
            cs = tire_scale * ax.tires * ax.longitudinal_stiffness_N * ax.dual_spacing_m ** 2
            x = ax.x_m
            A[iv + i, iv + i] += -cf / u
            A[iv + i, ir + i] += -cf * x / u
            A[ir + i, iv + i] += (-cf * x + cm) / u
            A[ir + i, ir + i] += (-cf * x * x + cm * x - cs) / u
        if i > 0:        # L_(i-1) acts on unit i at its front coupling
            G[iv + i, i - 1] += 1.0
            G[ir + i, i - 1] += unit.front_coupling_m
        if i < n - 1:    # -L_i acts on unit i at its rear coupling
            G[iv + i, i] -= 1.0
            G[ir + i, i] -= unit.rear_coupling_m
    for k in range(n - 1):
        E[it + k, it + k] = 1.0
        A[it + k, ir + k], A[it + k, ir + k + 1] = 1.0, -1.0
        C[k, iv + k + 1], C[k, iv + k] = 1.0, -1.0
        C[k, ir + k], C[k, ir + k + 1] = -v.units[k].rear_coupling_m, v.units[k + 1].front_coupling_m
        C[k, it + k] = -u
    EA, EG = np.linalg.solve(E, A), np.linalg.solve(E, G)
    L = -np.linalg.solve(C @ EG, C @ EA)            # joint forces per state
    Z = scipy.linalg.null_space(C) if n > 1 else np.eye(size)
    return sort_eigenvalues(np.linalg.eigvals(Z.T @ (EA + EG @ L) @ Z))


def test_b_double_equals_the_same_vehicle_built_unit_by_unit_with_joint_forces():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    for u in (5.0, 15.0, 24.4, 33.0):
        ne = newton_euler_eigenvalues(v, u)
        assert ne.size == 2 * v.n_units
        assert_same_spectrum(ne, eigenvalues(v, u), 1e-10)


@pytest.mark.parametrize("name", ["western_double", "truck_full_trailer"])
def test_examples_equal_newton_euler(name):
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    assert_same_spectrum(newton_euler_eigenvalues(v, 24.4, 0.8), eigenvalues(v, 24.4, 0.8), 1e-10)


@SETTINGS
@given(vehicles(2, 7), speeds, st.floats(0.3, 3.0))
def test_any_chain_equals_newton_euler(vehicle, u, s):
    assert_same_spectrum(newton_euler_eigenvalues(vehicle, u, s), eigenvalues(vehicle, u, s), 1e-9)


def test_no_upper_limit_on_the_number_of_units():
    v = random_vehicle(15, np.random.default_rng(3))
    assert v.n_units == 15 and linear_model(v).state_names[-1] == "thetaN"
    lam = eigenvalues(v, 20.0)
    assert lam.size == 30
    assert_same_spectrum(newton_euler_eigenvalues(v, 20.0), lam, 1e-9)
    ms = modes(v, np.array([10.0, 20.0]))
    assert len(ms) == 2 and ms[1].eigenvalues.size == 30


# ---------------------------------------------------------------------------- properties
@SETTINGS
@given(vehicles(1, 7))
def test_stable_at_low_speed_with_positive_stiffnesses(vehicle):
    assert eigenvalues(vehicle, 2.0).real.max() < 0


@SETTINGS
@given(vehicles(1, 7), speeds)
def test_mass_matrix_is_non_singular(vehicle, u):
    M = system_matrices(vehicle, u)[0]
    n = vehicle.n_units + 1
    # the mechanical block is symmetric positive definite, the articulation block is I
    np.testing.assert_allclose(M[:n, :n], M[:n, :n].T, rtol=1e-13, atol=1e-9 * np.abs(M).max())
    assert np.linalg.eigvalsh(M[:n, :n]).min() > 0
    assert np.isfinite(np.linalg.cond(M))


WEIRD = UnitSystem("mm-kN", 1e-3, 1e3, "mm", "kN", "kN*mm", "Gg", "kN*mm*s^2")


@SETTINGS
@given(vehicles(1, 6), speeds, st.sampled_from([THESIS, WEIRD]))
def test_the_model_does_not_depend_on_the_unit_system(vehicle, u, units):
    """Eigenvalues [1/s] are the same whatever system the numbers go through; matrices scale by
    the unit factors."""
    co_si, co_x = system_coefficients(vehicle), system_coefficients(vehicle, units)
    lam_si = sort_eigenvalues(np.linalg.eigvals(np.linalg.solve(co_si.M(u), co_si.S(u))))
    lam_x = sort_eigenvalues(np.linalg.eigvals(np.linalg.solve(co_x.M(u), co_x.S(u))))
    assert_same_spectrum(lam_x, lam_si, 1e-10)
    n = vehicle.n_units
    rows = np.r_[1 / units.force_N, np.full(n, 1 / units.moment_Nm), np.ones(n - 1)]
    cols = np.r_[units.length_m, np.ones(2 * n - 1)]
    np.testing.assert_allclose(co_x.M(u), rows[:, None] * co_si.M(u) * cols[None, :], rtol=1e-12,
                               atol=1e-14 * np.abs(co_x.M(u)).max())


@SETTINGS
@given(vehicles(2, 6), speeds, st.integers(0, 10**6))
def test_steady_state_balances_the_loads(vehicle, u, seed):
    rng = np.random.default_rng(seed)
    loads = ResidualLoads({a: rng.normal(0, 500) for a in vehicle.axle_names},
                          {a: rng.normal(0, 300) for a in vehicle.axle_names})
    F = load_vector(vehicle, loads)
    x = steady_state(vehicle, u, F)
    S = system_matrices(vehicle, u)[1]
    np.testing.assert_allclose(S @ x, -F, rtol=1e-9, atol=1e-10 * np.abs(F).max())
    r = x[1:vehicle.n_units + 1]
    np.testing.assert_allclose(r, r[0], rtol=1e-9, atol=1e-14)   # steady: every unit turns at the same rate


@pytest.mark.parametrize("preset", PRESETS)
def test_presets_geometry_and_signs(preset):
    v = load_preset(preset)
    tractor = v.units[0]
    assert tractor.axles[0].name == "11" and tractor.axles[0].x_m > 0 and tractor.axles[0].steered
    assert all(ax.x_m <= 0 for u in v.units for ax in u.axles if ax.name != "11")
    assert all(u.front_coupling_m > 0 for u in v.units[1:])
    assert v.axles[0].tires == 2 and all(ax.tires == 4 for ax in v.axles[1:])
    assert all(ax.dual_spacing_m == pytest.approx(0.3048) for ax in v.axles[1:])
    n = 2 if preset == "tractor_semitrailer" else 6
    assert v.n_units == n and len(linear_model(v).state_names) == 2 * n
