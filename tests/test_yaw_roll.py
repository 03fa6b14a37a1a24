"""The yaw-roll model (docs/roll.md): against an independent Newton-Euler derivation with explicit
coupling and roll-axis forces, the reduction to the yaw plane, the decoupled roll mode's closed
form, and a stiff ODE solve of the Newton-Euler equations."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lcvreport import load_vehicle
from lcvreport.analysis.exact import response
from lcvreport.manoeuvres.steer import sine
from lcvreport.model.linear import linear_model
from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.model.yaw_roll.equations import coefficients_from
from lcvreport.model.yaw_roll.parameters import roll_parameters

from conftest import ROOT

G = 9.80665
EXAMPLES = ("b_double", "western_double", "truck_full_trailer")


def _vehicle(name):
    v = load_vehicle(ROOT / "examples" / "vehicles" / f"{name}.toml")
    # a yaw-roll product and uneven dampers, so that every term of the equations is exercised (a
    # product a body can have: I_xz^2 < I_x I_z, which a vehicle file must meet)
    units = tuple(replace(u, yaw_roll_product_kg_m2=(-1) ** i * min(300.0 * (i + 1), 0.05 * (
        u.roll_inertia_kg_m2 * u.yaw_inertia_kg_m2) ** 0.5)) for i, u in enumerate(v.units))
    return replace(v, units=units)


def newton_euler(vehicle, u, x, delta, P=None, a_c=0.0):
    """x' of the yaw-roll model written independently: every unit is a sprung mass and a
    non-rolling part (axles, unsprung masses) joined at the roll axis by a lateral force R_i
    and the suspensions' roll moment; neighbours are joined at the couplings by a lateral force
    Y_k (on unit k+1, along +y) and the coupling's roll moment; the static coupling loads W_k
    act at the coupling points.  Unknowns: every unit's v_i', r_i', p_i', R_i and every Y_k,
    from the 4N balances of forces and moments and the N-1 differentiated joint constraints."""
    rp = roll_parameters(vehicle)
    n = vehicle.n_units
    r = x[1:n + 1]
    p = x[n + 1:2 * n + 1]
    th = x[2 * n + 1:3 * n]
    phi = x[3 * n:]
    rear = [uu.rear_coupling_m or 0.0 for uu in vehicle.units]
    front = [uu.front_coupling_m or 0.0 for uu in vehicle.units]
    hc, hr, h, e = rp.hc_m, rp.hr_m, rp.h_m, rp.e_m
    ms, mu = rp.ms_kg, rp.m_kg - rp.ms_kg
    v = np.zeros(n)
    v[0] = x[0]
    for k in range(n - 1):
        v[k + 1] = (v[k] + rear[k] * r[k] - front[k + 1] * r[k + 1] + u * th[k] + (hc[k] - hr[k]) * p[k]
                    - (hc[k] - hr[k + 1]) * p[k + 1])
    Fy, Mz = np.zeros(n), np.zeros(n)
    K_unit, C_unit = np.zeros(n), np.zeros(n)
    P = np.zeros(len(vehicle.axles)) if P is None else P
    for j, (i, a) in enumerate(zip(vehicle.axle_units, vehicle.axles)):
        alpha = (delta if a.steered else 0.0) - (v[i] + a.x_m * r[i]) / u
        F = a.cornering_stiffness_axle_N_per_rad * alpha + P[j]
        Fy[i] += F
        Mz[i] += a.x_m * F - a.aligning_stiffness_axle_Nm_per_rad * alpha - a.dual_yaw_damping_axle_N_m2 * r[i] / u
        K_unit[i] += rp.K_Nm_per_rad[j]
        C_unit[i] += rp.C_Nms_per_rad[j]
    W = np.r_[rp.W_N, 0.0]                                # W_k on the unit ahead of joint k (none behind the last)
    Wf = np.r_[0.0, rp.W_N]                               # the load from the front coupling (up), none on unit 1
    hcf = np.r_[0.0, hc]
    hcr = np.r_[hc, 0.0]
    # unknowns z = [a (= v'), r', p', R, Y]
    nz = 5 * n - 1
    iA, iR, iP, iRx, iY = 0, n, 2 * n, 3 * n, 4 * n
    Mat = np.zeros((nz, nz))
    rhs = np.zeros(nz)
    row = 0
    for i in range(n):
        def Y(k, coef, row=None):
            if 0 <= k < n - 1:
                Mat[row, iY + k] += coef
        # sprung mass, lateral: ms (a + u r + e p') = R + Y_(i-1) - Y_i + ms a_c
        Mat[row, iA + i] = ms[i]
        Mat[row, iP + i] = ms[i] * e[i]
        Mat[row, iRx + i] = -1.0
        Y(i - 1, -1.0, row)
        Y(i, +1.0, row)
        rhs[row] = -ms[i] * u * r[i] + ms[i] * a_c
        row += 1
        # non-rolling part, lateral: mu (a + u r) = sum F - R + mu a_c
        Mat[row, iA + i] = mu[i]
        Mat[row, iRx + i] = 1.0
        rhs[row] = Fy[i] - mu[i] * u * r[i] + mu[i] * a_c
        row += 1
        # the whole unit's yaw about its CG: Iz r' - Ixz p' = tire moments + fc Y_(i-1) - rc Y_i
        Mat[row, iR + i] = vehicle.units[i].yaw_inertia_kg_m2
        Mat[row, iP + i] = -rp.Ixz_kg_m2[i]
        Y(i - 1, -front[i], row)
        Y(i, +rear[i], row)
        rhs[row] = Mz[i]
        row += 1
        # the sprung mass's roll about its own CG (x forward, z down; forces below the CG at z > 0):
        # R at the roll axis (e below), Y at the couplings (h - h_c below), the vertical support
        # Z = ms g + W_i - W_(i-1) at the roll axis and the coupling loads, displaced laterally by the roll
        Mat[row, iP + i] = rp.Ix_kg_m2[i]
        Mat[row, iR + i] = -rp.Ixz_kg_m2[i]
        Mat[row, iRx + i] = e[i]
        Y(i - 1, +(h[i] - hcf[i]), row)
        Y(i, -(h[i] - hcr[i]), row)
        Z = ms[i] * G + W[i] - Wf[i]
        moment = e[i] * phi[i] * Z - K_unit[i] * phi[i] - C_unit[i] * p[i]
        moment += -(h[i] - hcr[i]) * W[i] * phi[i] + (h[i] - hcf[i]) * Wf[i] * phi[i]
        if i < n - 1:
            moment -= rp.kc_Nm_per_rad[i] * (phi[i] - phi[i + 1])
        if i > 0:
            moment -= rp.kc_Nm_per_rad[i - 1] * (phi[i] - phi[i - 1])
        rhs[row] = moment
        row += 1
    for k in range(n - 1):
        # a_(k+1) = a_k + rc r_k' - fc r_(k+1)' + u (r_k - r_(k+1)) + (hc - hr_k) p_k' - (hc - hr_(k+1)) p_(k+1)'
        Mat[row, iA + k + 1] = 1.0
        Mat[row, iA + k] = -1.0
        Mat[row, iR + k] = -rear[k]
        Mat[row, iR + k + 1] = front[k + 1]
        Mat[row, iP + k] = -(hc[k] - hr[k])
        Mat[row, iP + k + 1] = hc[k] - hr[k + 1]
        rhs[row] = u * (r[k] - r[k + 1])
        row += 1
    z = np.linalg.solve(Mat, rhs)
    return np.r_[z[iA], z[iR:iR + n], z[iP:iP + n], r[:-1] - r[1:], p], z


def _linear_maps(f, n_states, n_inputs):
    """(A, B) of a linear function f(x, w) by unit vectors (it is linear: exact)."""
    A = np.column_stack([f(np.eye(n_states)[j], np.zeros(n_inputs)) for j in range(n_states)])
    B = np.column_stack([f(np.zeros(n_states), np.eye(n_inputs)[j]) for j in range(n_inputs)])
    return A, B


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_model_is_the_newton_euler_equations(name):
    v = _vehicle(name)
    u = 24.0
    co = linear_model(v, "yaw_roll")
    na = len(v.axles)

    def f(x, w):
        return newton_euler(v, u, x, w[0], P=w[1:1 + na], a_c=w[-1])[0]

    A_ne, B_ne = _linear_maps(f, co.n_states, 2 + na)
    A, Gm = co.state_derivative_maps(u)
    B = Gm @ np.column_stack([co.B_delta(), co.B_P, co.B_crossfall / G])     # B_crossfall is per g of a_c
    # entries are sums of products of the physical parameters, and A = M^-1 S with M of condition
    # ~1e4: to 1e-12 of each row's largest entry (2.6e-15 measured)
    for got, ref in ((A, A_ne), (B, B_ne)):
        scale = np.abs(ref).max(axis=1, keepdims=True)
        assert np.all(np.abs(got - ref) <= 1e-12 * scale), np.max(np.abs(got - ref) / np.where(scale > 0, scale, 1))


def test_the_load_transfer_is_the_axle_balance():
    """dF_z of an axle from its own free body (suspension moment, tire force at the ground about
    the roll centre, vertical loads at +-T/2) against the model's output rows."""
    v = _vehicle("b_double")
    u = 22.0
    co = linear_model(v, "yaw_roll")
    rng = np.random.default_rng(7)
    x = rng.normal(scale=0.01, size=co.n_states)
    delta = 0.004
    names, X, XD, D, _O = co.extra_signals(u)
    A, Gm = co.state_derivative_maps(u)
    xdot = A @ x + Gm @ co.B_delta() * delta
    out = dict(zip(names, X @ x + XD @ xdot + D * delta))
    rp = roll_parameters(v)
    n = v.n_units
    vv = co.velocity_map(u) @ x
    r = x[1:n + 1]
    for j, (i, a) in enumerate(zip(v.axle_units, v.axles)):
        Fy = a.cornering_stiffness_axle_N_per_rad * ((delta if a.steered else 0.0) - (vv[i] + a.x_m * r[i]) / u)
        M = rp.K_Nm_per_rad[j] * x[3 * n + i] + rp.C_Nms_per_rad[j] * x[n + 1 + i]
        assert out[f"dFz_{a.name}"] == pytest.approx((M - rp.hr_m[i] * Fy) / rp.T_m[j], rel=1e-12, abs=1e-9)
    # a_s = a + e p' on every unit; the group's LTR
    a = co.acceleration_maps(u)[0] @ x + co.acceleration_maps(u)[1] @ co.B_delta() * delta
    for i in range(n):
        assert out[f"as{i + 1}"] == pytest.approx(a[i] + rp.e_m[i] * xdot[n + 1 + i], rel=1e-12)
    ltr = 2 * sum(out[f"dFz_{ax}"] for ax in v.axle_names) / rp.Fz0_N.sum()
    assert out["ltr1"] == pytest.approx(ltr, rel=1e-12)


def test_the_load_transfers_balance_the_whole_units_roll_moment():
    """The physics, not the formula: about the unit's centre line at the ground, the wheels'
    vertical loads (sum of T dF_z), the sprung weight displaced by its roll and the d'Alembert
    moments of both masses and of the sprung mass's rotation balance at every instant:
    sum T dF_z = m_s g e phi - h m_s a_s - h_r m_u a - I_x p' + I_xz r' (one unit, random state
    and steer, a yaw-roll product included; the tire forces act at the ground and put no moment)."""
    v = _vehicle("b_double").truncated(1)
    u = 19.0
    co = linear_model(v, "yaw_roll")
    rp = roll_parameters(v)
    rng = np.random.default_rng(11)
    for _ in range(5):
        x = rng.normal(scale=0.02, size=co.n_states)
        delta = float(rng.normal(scale=0.01))
        names, X, XD, D, _O = co.extra_signals(u)
        A, Gm = co.state_derivative_maps(u)
        xdot = A @ x + Gm @ co.B_delta() * delta
        out = dict(zip(names, X @ x + XD @ xdot + D * delta))
        Ca, Da = co.acceleration_maps(u)
        a = float(Ca[0] @ x + Da[0] @ co.B_delta() * delta)
        phi, p_dot, r_dot = x[3], xdot[2], xdot[1]
        ms, mu = rp.ms_kg[0], rp.m_kg[0] - rp.ms_kg[0]
        a_s = a + rp.e_m[0] * p_dot
        moment = (ms * G * rp.e_m[0] * phi - rp.h_m[0] * ms * a_s - rp.hr_m[0] * mu * a - rp.Ix_kg_m2[0] * p_dot
                  + rp.Ixz_kg_m2[0] * r_dot)
        wheels = sum(rp.T_m[j] * out[f"dFz_{name}"] for j, name in enumerate(v.axle_names))
        # terms of ~1e4 N*m cancelling to the result: to 1e-9 of the largest term
        scale = max(abs(ms * G * rp.e_m[0] * phi), abs(rp.h_m[0] * ms * a_s), abs(rp.Ix_kg_m2[0] * p_dot))
        assert abs(wheels - moment) <= 1e-9 * scale, (wheels, moment)


def _reduced(vehicle):
    """Roll data with e = 0, the couplings at the roll axes, no yaw-roll product: W terms vanish."""
    rp = roll_parameters(vehicle)
    n = vehicle.n_units
    h = np.full(n, 1.0)
    return replace(rp, h_m=h, hr_m=h.copy(), e_m=np.zeros(n), hc_m=np.ones(n - 1), Ixz_kg_m2=np.zeros(n))


@pytest.mark.parametrize("name", EXAMPLES)
def test_with_no_roll_lever_the_yaw_rows_are_the_yaw_plane_model(name):
    v = _vehicle(name)
    co = coefficients_from(v, _reduced(v))
    yp = system_coefficients(v)
    n = v.n_units
    yaw = np.r_[0:n + 1, 2 * n + 1:3 * n]                 # v1, r, theta in the yaw-roll state
    roll = np.r_[n + 1:2 * n + 1, 3 * n:4 * n]             # p, phi
    for u in (8.0, 24.0, 33.0):
        M, S = co.M(u), co.S(u, 0.7)
        Myp, Syp = yp.M(u), yp.S(u, 0.7)
        for got, ref in ((M[np.ix_(yaw, yaw)], Myp), (S[np.ix_(yaw, yaw)], Syp)):
            np.testing.assert_allclose(got, ref, rtol=1e-13, atol=1e-13 * np.abs(ref).max())
        for blk in (M[np.ix_(yaw, roll)], M[np.ix_(roll, yaw)], S[np.ix_(yaw, roll)], S[np.ix_(roll, yaw)]):
            assert np.all(blk == 0.0)
    np.testing.assert_allclose(co.Bdelta[yaw], yp.Bdelta, rtol=1e-14)
    assert np.all(co.Bdelta[roll] == 0.0)


def test_the_decoupled_roll_mode_is_the_closed_form():
    """One unit, no roll lever: I_x phi'' + C phi' + K phi = 0, lambda = (-C +- sqrt(C^2 - 4 I_x K)) / (2 I_x)."""
    v = _vehicle("b_double").truncated(1)
    rp = _reduced(v)
    co = coefficients_from(v, rp)
    A, _G = co.state_derivative_maps(20.0)
    ev = np.linalg.eigvals(A)
    Ix, K, C = rp.Ix_kg_m2[0], rp.K_Nm_per_rad.sum(), rp.C_Nms_per_rad.sum()
    closed = np.roots([Ix, C, K])
    for lam in closed:
        assert np.min(np.abs(ev - lam)) <= 1e-10 * abs(lam)


@pytest.mark.parametrize("name", ("b_double", "western_double"))
def test_the_exact_response_is_the_stiff_ode_solution_of_the_newton_euler_equations(name):
    v = _vehicle(name)
    u = 25.0
    A0, f = 0.01, 0.4
    r = response(v, u, sine(A0, f), 6.0, 0.05, model="yaw_roll")
    n = v.n_units
    rp = roll_parameters(v)

    def delta(t):
        return A0 * np.sin(2 * np.pi * f * t) if t <= 1 / f else 0.0

    # the Newton-Euler equations are linear: their matrices by unit vectors, then a stiff solve of
    # [x, psi1, Y1]' (Radau, its Jacobian given)
    A_ne, b_ne = _linear_maps(lambda x, w: newton_euler(v, u, x, w[0])[0], 4 * n, 1)
    Aa = np.zeros((4 * n + 2, 4 * n + 2))
    Aa[:4 * n, :4 * n] = A_ne
    Aa[4 * n, 1] = 1.0
    Aa[4 * n + 1, 0], Aa[4 * n + 1, 4 * n] = 1.0, u
    ba = np.r_[b_ne[:, 0], 0.0, 0.0]
    sol = solve_ivp(lambda t, z: Aa @ z + ba * delta(t), (0.0, 6.0), np.zeros(4 * n + 2), method="Radau",
                    t_eval=r.time, rtol=1e-11, atol=1e-14, jac=Aa, first_step=1e-4, max_step=0.01)
    assert sol.success
    X = sol.y.T
    for i in range(n):
        ref = X[:, 3 * n + i]
        assert np.max(np.abs(r[f"phi{i + 1}"] - ref)) <= 1e-7 * np.max(np.abs(ref))
    # the NE solution's a_1 = v1' + u r1
    a1 = (X[:, :4 * n] @ A_ne.T + np.outer([delta(t) for t in r.time], b_ne[:, 0]))[:, 0] + u * X[:, 1]
    assert np.max(np.abs(r["ay1"] - a1)) <= 1e-7 * np.max(np.abs(a1))
    assert rp.groups and np.max(np.abs(r["ltr1"])) > 0


def test_a_roll_axis_at_the_cg_and_unsprung_masses_above_the_mass_are_refused():
    from lcvreport.model.vehicle import VehicleError
    v = load_vehicle(ROOT / "examples" / "vehicles" / "b_double.toml")
    u = v.units[0]
    with pytest.raises(VehicleError, match=r"roll_axis_height_m must be below cg_height_m \(1.1 m\), got 1.1 m"):
        replace(u, roll_axis_height_m=1.1)
    heavy = tuple(replace(a, unsprung_mass_kg=5000.0) for a in u.axles)
    with pytest.raises(VehicleError, match=r"unsprung_mass_kg of the axles sum to 15000 kg, at or above the "
                                           r"unit's mass_kg 11400 kg"):
        replace(u, axles=heavy)
