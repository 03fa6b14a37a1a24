"""The yaw-plane measures of SPEC section 8, each against an independent computation:
steady-state gains, long exact sine runs, a stepped single sine, a dense eigenvalue
scan, the trim equations, a long exact run with the trim steer held, python-control."""
from __future__ import annotations

import json
import subprocess
import sys

import control
import numpy as np
import pytest
from conftest import EXAMPLE_NAMES, EXAMPLES

from lcvreport.analysis.discretize import augmented_state_matrix, discretize
from lcvreport.analysis.frequency import rearward_amplification, steer_to_acceleration
from lcvreport.analysis.modes import eigenvalues
from lcvreport.analysis.response import simulate
from lcvreport.analysis.statespace import to_statespace
from lcvreport.analysis.steady import reference_points, steady_state, trim
from lcvreport.measures.amplification import single_sine
from lcvreport.measures.measure_set import measure_set
from lcvreport.measures.stability import U_MIN_DEFAULT_MPS, critical_speed, least_damping
from lcvreport.model.linear import linear_model
from lcvreport.model.presets import PRESETS, load_preset
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule
from lcvreport.model.yaw_plane.outputs import global_lateral, point_longitudinal
from lcvreport.tracking.tires import conicity_sensitivity
from lcvreport.units import kph_to_mps, mps_to_kph

U88 = kph_to_mps(88.0)


def _vehicle(name):
    return load_preset(name) if name in PRESETS else load_vehicle(EXAMPLES / f"{name}.toml")


# ---------------------------------------------------------------------------- frequency domain
def test_ra_at_low_frequency_tends_to_the_steady_state_gain_ratio(semi):
    """G_i(0) is the steady-state lateral acceleration per rad of steer, u r_i of -S^-1 b (every
    unit turns at the same rate: the ratio is 1); RA(f) approaches it as f^2."""
    co = system_coefficients(semi)
    x = steady_state(semi, U88, co.B_delta())
    a_ss = U88 * x[1:semi.n_units + 1]
    ratio = abs(a_ss[-1] / a_ss[0])
    assert ratio == pytest.approx(1.0, rel=1e-12)
    d1 = rearward_amplification(semi, U88, 0.01) - ratio
    d2 = rearward_amplification(semi, U88, 0.02) - ratio
    assert abs(d1) < 1e-3
    assert d2 / d1 == pytest.approx(4.0, rel=0.02)          # second order in f


def sine_run(v, f: float, delta0: float, T: float, h: float):
    """The exact response to a continuous sine steer: the model augmented with the
    oscillator s' = w c, c' = -w s (delta = delta0 s), stepped by the exponential of the
    whole (autonomous) system.  Returns time [s] and the lateral accelerations [m/s^2]."""
    import scipy.linalg
    co = system_coefficients(v)
    n = linear_model(v).n_states
    A, G = co.state_derivative_maps(U88)
    Ca, Da = co.acceleration_maps(U88)
    b = G @ co.B_delta()
    w = 2 * np.pi * f
    big = np.zeros((n + 2, n + 2))
    big[:n, :n], big[:n, n] = A, delta0 * b
    big[n, n + 1], big[n + 1, n] = w, -w
    E = scipy.linalg.expm(big * h)
    z = np.zeros(n + 2)
    z[n + 1] = 1.0                          # s = sin(wt) = 0, c = cos(wt) = 1 at t = 0
    t = np.arange(int(round(T / h)) + 1) * h
    a = np.zeros((t.size, v.n_units))
    for k in range(t.size):
        a[k] = Ca @ z[:n] + Da @ co.B_delta() * delta0 * z[n]
        z = E @ z
    return t, a


@pytest.mark.parametrize("name", ["aucnat", "western_double", "truck_full_trailer"])
def test_ra_equals_the_amplitude_ratio_of_a_long_exact_sine_run(name):
    """A 0.4 Hz sine steer for 30 s, exact (see sine_run): after the transients, the amplitude
    ratio of a_N to a_1 (projected on the fundamental) is RA(0.4 Hz), the amplitudes the gains."""
    v = _vehicle(name)
    f, T = 0.4, 30.0
    t, a = sine_run(v, f, 0.01, T, 0.01)
    tail = t >= T - 10.0          # four whole periods, transients gone (slowest time constant < 2 s)
    basis = np.column_stack([np.sin(2 * np.pi * f * t[tail]), np.cos(2 * np.pi * f * t[tail])])
    amp = np.linalg.norm(np.linalg.lstsq(basis, a[tail], rcond=None)[0], axis=0)
    assert amp[-1] / amp[0] == pytest.approx(rearward_amplification(v, U88), rel=1e-7)
    gains = np.abs(steer_to_acceleration(v, U88, f))
    np.testing.assert_allclose(amp / 0.01, gains, rtol=1e-7)


@pytest.mark.parametrize("name", ["tractor_semitrailer", "b_double"])
def test_to_statespace_agrees_with_the_measures(name):
    v = _vehicle(name)
    sys_ = to_statespace(v, U88)
    f = np.array([0.1, 0.4, 1.3])
    resp = control.frequency_response(sys_, 2 * np.pi * f)
    for i in range(v.n_units):
        ay = sys_.output_labels.index(f"ay{i + 1}")
        G = resp.magnitude[ay, sys_.input_labels.index("delta")] * np.exp(
            1j * resp.phase[ay, sys_.input_labels.index("delta")])
        np.testing.assert_allclose(G, steer_to_acceleration(v, U88, f)[:, i], rtol=1e-10)
    # the DC gain of the states is the steady state
    x_ss = steady_state(v, U88, system_coefficients(v).B_delta())
    dc = control.dcgain(sys_)[:linear_model(v).n_states, 0]
    np.testing.assert_allclose(dc, x_ss, rtol=1e-9, atol=1e-12 * np.abs(x_ss).max())


def test_to_statespace_step_response_is_the_package_response(semi):
    """control.step_response on the named system against the exact response to P on axle 21."""
    sys_ = to_statespace(semi, U88)
    t = np.linspace(0, 5, 501)
    resp = control.step_response(sys_, T=t, input=sys_.input_labels.index("P_21"))
    co = system_coefficients(semi)
    r = simulate(semi, t, U88, co.B_P[:, 3])
    for name in ("thetaA", "ay2", "y2"):
        got = np.asarray(resp.outputs[sys_.output_labels.index(name)]).ravel()
        ref = r[name] if name != "y2" else r.theta[:, 0] * (semi.units[1].front_coupling_m - semi.rear_end_x_m(1))
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-6 * np.abs(ref).max())


# ---------------------------------------------------------------------------- single sine
@pytest.mark.parametrize("name", ["aucnat", "b_double"])
def test_single_sine_is_the_response_to_the_continuous_sine_with_its_peaks_between_samples(name):
    """SPEC 8 since section 11: the continuous sine (not 1 ms samples of it), the response
    equal to a stiff ODE solve (Radau, rtol 1e-12), the peaks of |a_i| on the continuous
    response: equal to a golden-section search on the ODE's dense output."""
    from scipy.integrate import solve_ivp
    from scipy.optimize import minimize_scalar
    v = _vehicle(name)
    ss = single_sine(v, U88)
    co = system_coefficients(v)
    A, G = co.state_derivative_maps(U88)
    b = G @ co.B_delta()
    Ca, Da = co.acceleration_maps(U88)
    da = Da @ co.B_delta()
    f = 0.4
    delta = lambda t: 0.01 * np.sin(2 * np.pi * f * t) if t <= 1 / f else 0.0      # noqa: E731
    sols = []
    x0 = np.zeros(linear_model(v).n_states)
    for a, c in ((0.0, 1 / f), (1 / f, ss.time[-1])):
        sol = solve_ivp(lambda t, x: A @ x + b * delta(t), (a, c), x0, method="Radau", rtol=1e-12, atol=1e-16,
                        dense_output=True)
        sols.append(sol)
        x0 = sol.sol(c)

    def ay(t):
        sol = sols[0] if t <= 1 / f else sols[1]
        return Ca @ sol.sol(t) + da * delta(t)

    ref = np.array([ay(t) for t in ss.time])
    np.testing.assert_allclose(ss.ay, ref, rtol=0, atol=1e-9 * np.abs(ref).max())
    for i in (0, v.n_units - 1):
        k = int(np.argmax(np.abs(ref[:, i])))
        res = minimize_scalar(lambda t: -abs(ay(t)[i]), bounds=(ss.time[k - 1], ss.time[k + 1]), method="bounded",
                              options={"xatol": 1e-10})
        assert ss.peaks[i] == pytest.approx(-res.fun, rel=1e-9)
        assert ss.peaks[i] >= np.abs(ref[:, i]).max()


def test_single_sine_ra_does_not_depend_on_the_amplitude(aucnat):
    ras = [single_sine(aucnat, U88, delta0_rad=d).rearward_amplification for d in (1e-4, 0.01, 0.2)]
    np.testing.assert_allclose(ras, ras[0], rtol=1e-12)


# ---------------------------------------------------------------------------- damping and critical speed
@pytest.mark.parametrize("name, tire_scale", [("empty", 0.2), ("legal_max", 0.2), ("empty", 0.05)])
def test_critical_speed_equals_a_dense_eigenvalue_scan(name, tire_scale):
    v = load_preset(name)
    crit = critical_speed(v, tire_scale)
    lo = mps_to_kph(U_MIN_DEFAULT_MPS)
    scan = np.arange(lo, 200.0, 0.01)
    unstable = eigenvalues(v, kph_to_mps(scan), tire_scale).real.max(axis=-1) >= 0
    first = scan[np.argmax(unstable)]
    assert unstable.any() and crit is not None
    assert abs(crit - first) <= 0.06, (crit, first)


@pytest.mark.parametrize("name", ["aucnat", "tractor_semitrailer"] + list(EXAMPLE_NAMES))
def test_stable_vehicles_have_no_critical_speed(name):
    v = _vehicle(name)
    assert critical_speed(v) is None
    assert eigenvalues(v, kph_to_mps(np.linspace(8.1, 200, 50))).real.max() < 0


def test_least_damping_is_the_least_damped_oscillatory_mode(aucnat):
    zeta, f = least_damping(aucnat, U88)
    lam = eigenvalues(aucnat, U88)
    osc = lam[lam.imag > 0]
    k = np.argmin(-osc.real / np.abs(osc))
    assert zeta == pytest.approx(-osc[k].real / abs(osc[k]), rel=1e-12)
    assert f == pytest.approx(osc[k].imag / (2 * np.pi), rel=1e-12)


# ---------------------------------------------------------------------------- trim
@pytest.mark.parametrize("name", ["aucnat", "tractor_semitrailer"] + list(EXAMPLE_NAMES))
def test_trimmed_state_is_straight_and_steady(name):
    v = _vehicle(name)
    F = load_vector(v, one_percent_rule(v, [v.unit_names[-1], v.unit_names[0]]))
    tr = trim(v, U88, F)
    co = system_coefficients(v)
    xdot = np.linalg.solve(co.M(U88), co.S(U88) @ tr.state + co.B_delta() * tr.delta_rad + F)
    scale = np.abs(np.linalg.solve(co.M(U88), F)).max()
    assert np.abs(xdot).max() <= 1e-12 * scale
    np.testing.assert_allclose(tr.state[1:v.n_units + 1], 0.0, atol=1e-15)   # r1 = 0, so every r = 0


@pytest.mark.parametrize("name", ["aucnat", "b_double", "truck_full_trailer"])
def test_trimmed_offtracking_equals_a_long_exact_run_with_the_trim_steer_held(name):
    """Global lateral paths from a 120 s exact run with delta_trim held: the rearmost axle passes
    the steered axle's track offset by the trimmed offtracking (first order)."""
    v = _vehicle(name)
    co = system_coefficients(v)
    F = load_vector(v, one_percent_rule(v, [v.unit_names[-1]]))
    tr = trim(v, U88, F)
    t = np.linspace(0, 120, 241)
    r = simulate(v, t, U88, F + co.B_delta() * tr.delta_rad)
    (uq, xq), (up, xp) = reference_points(v)
    YQ = global_lateral(v, uq, xq, r["psi1"], r["Y1"], r.theta)
    YP = global_lateral(v, up, xp, r["psi1"], r["Y1"], r.theta)
    Vy = (YQ[-1] - YQ[-2]) / (t[-1] - t[-2])                   # every point drifts at the same rate
    delay = (point_longitudinal(v, uq, xq) - point_longitudinal(v, up, xp)) / U88
    path_offset = YP[-1] + Vy * delay - YQ[-1]                 # where P is when it reaches Q's present spot
    assert path_offset == pytest.approx(tr.offtracking_m, rel=1e-6)
    assert abs(tr.offtracking_m) > 1e-4


# ---------------------------------------------------------------------------- the measure set and lcv measures
SPEC_KEYS = {"speed_mps", "least_damping_ratio", "least_damped_frequency_hz", "critical_speed_kph", "ra_frequency",
             "ra_single_sine", "ay_gain_per_unit", "ra_peak", "ra_peak_frequency_hz", "yaw_damping_coefficient",
             "hsto_m", "ra_lane_change", "hsso_m", "steady_turn_delta_rad",
             "lssp_m", "low_speed_offtracking_m", "max_tail_swing_m", "frontal_swing_m",
             "yaw_damping_lower_bound",     # SPEC 12 (corrected 2026-12): YDC of a heavily damped vehicle
             "reasons",                     # issue 29: why each null is null
             # SPEC 17: the roll measures (null, with the missing key named, without roll data)
             "srt_g", "srt_rrcu_g", "srt_min_g", "roll_least_damping_ratio", "roll_critical_speed_kph",
             "ra_single_sine_roll", "ltr_single_sine", "ra_lane_change_roll", "hsto_m_roll", "ltr_lane_change",
             "rltr_lane_change", "roll_gain_deg_per_g",
             # the assessment's measures (docs/measures.md): yaw-rate RA, tracking on a straight path
             "ra_yaw_rate_single_sine", "tasp_m", "hsto_driver_m", "ra_lane_change_driver",
             # SPEC 18: the friction demand of the turn with tire forces (on request: null, with the reason)
             "stfd", "friction_demand_drive", "path_error_max_m"}


@pytest.mark.parametrize("source", [["--preset", "aucnat"]] + [["--vehicle", str(EXAMPLES / f"{n}.toml")]
                                                               for n in EXAMPLE_NAMES])
def test_lcv_measures_prints_every_spec_key(source):
    v = load_preset(source[1]) if source[0] == "--preset" else load_vehicle(source[1])
    load = "trailer2,trailer3" if source[0] == "--preset" else v.unit_names[-1]
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", *source, "--speed-kph", "88", "--load", load,
                        "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert set(doc) == SPEC_KEYS | {"trim"} and set(doc["trim"]) == {"delta_rad", "offtracking_m"}
    ref = measure_set(v, U88, load_units=load.split(",")).to_dict()
    assert doc == json.loads(json.dumps(ref))
    assert len(doc["ay_gain_per_unit"]) == v.n_units
    gains = np.abs(steer_to_acceleration(v, U88, 0.4))
    np.testing.assert_allclose(doc["ay_gain_per_unit"], gains, rtol=1e-12)
    assert doc["ra_frequency"] == pytest.approx(gains[-1] / gains[0], rel=1e-12)


def test_lcv_measures_without_load_has_no_trim():
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "empty", "--speed-mph", "55",
                        "--tire-scale", "0.2", "--json"], capture_output=True, text=True)
    doc = json.loads(p.stdout)
    assert set(doc) == SPEC_KEYS and doc["critical_speed_kph"] == pytest.approx(73.9, abs=0.05)


def test_conicity_sensitivity_is_linear_and_ranked(aucnat):
    rows = conicity_sensitivity(aucnat, U88)
    assert len(rows) == len(aucnat.axles)
    keys = [r.largest_m for r in rows]
    assert keys == sorted(keys, reverse=True)
    co = system_coefficients(aucnat)
    col = aucnat.axle_names.index(rows[0].axle)
    tr = trim(aucnat, U88, co.B_P[:, col] * 2500.0)      # 2.5 kN: 2.5x the per-kN number
    assert tr.offtracking_m == pytest.approx(2.5 * rows[0].offtracking_per_P_m_per_kN, rel=1e-10)


def test_measure_sets_from_threads_equal_the_serial_ones():
    # the per-vehicle caches (the state maps of the last speeds, the vehicle's hash) are shared
    # by threads: sets computed by 4 threads at 12 speeds equal the serial ones exactly
    from concurrent.futures import ThreadPoolExecutor
    v = load_preset("tractor_semitrailer")
    speeds = [12.0 + 1.5 * k for k in range(12)]             # more speeds than the maps kept
    serial = [measure_set(v, u).to_dict() for u in speeds]
    with ThreadPoolExecutor(4) as pool:
        threaded = list(pool.map(lambda u: measure_set(v, u).to_dict(), speeds * 2))
    assert threaded == serial * 2
