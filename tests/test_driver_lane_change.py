"""The closed-loop lane change ``driver:A0:F:K:T`` (docs/measures.md#closed-loop-lane-change):
the exact response of the loop against a stiff ODE solve of the same loop, its limits, the
measures it gives, and one line for a loop that cannot be driven."""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from lcvreport import load_vehicle
from lcvreport.analysis.discretize import augmented_state_matrix
from lcvreport.analysis.exact import ManoeuvreError, response
from lcvreport.manoeuvres.steer import G_MPS2, SteerError, driver_lane_change, parse_steer
from lcvreport.measures.measure_set import measure_set
from lcvreport.model.linear import linear_model

from conftest import EXAMPLES

U = 88 / 3.6
LCV = [sys.executable, "-m", "lcvreport.cli"]


def _path(t, A0, F):
    """The lane change's path [m], written out: lateral acceleration A0 sin(2 pi F s), 0 <= s <= 1/F."""
    w, T = 2 * math.pi * F, 1.0 / F
    t = np.asarray(t, dtype=float)
    inside = A0 / w * (t - np.sin(w * t) / w)
    return np.where(t < 0, 0.0, np.where(t < T, inside, A0 / (w * F)))


@pytest.mark.parametrize("name,K,T", [("b_double", 0.2, 0.5), ("truck_full_trailer", 0.1, 0.8)])
def test_the_closed_loop_is_exact_against_a_stiff_ode_solve(name, K, T):
    """The loop x' = A x + b K (path(t) - Y1 - u T psi1) integrated by Radau at rtol 1e-12,
    piece by piece of the path (its second derivative jumps at 1/F), against the exact response:
    1e-8 of the offset on every state (the solver's tolerance, accumulated over 12 s)."""
    from scipy.integrate import solve_ivp
    v = load_vehicle(EXAMPLES / f"{name}.toml")
    A0, F = 0.15 * G_MPS2, 0.4
    steer = driver_lane_change(A0, F, K, T)
    r = response(v, U, steer, 12.0, 0.01)
    co = linear_model(v)
    n = co.n_states
    A, G = augmented_state_matrix(co, U, 1.0)
    b = G @ co.B_delta(1.0)

    def f(t, z):
        delta = K * (_path(t, A0, F) - z[n + 1] - U * T * z[n])
        return A @ z + b * delta

    z, out = np.zeros(n + 2), []
    t_grid = r.time
    for lo, hi in ((0.0, 1.0 / F), (1.0 / F, 12.0)):
        sel = (t_grid >= lo - 1e-12) & (t_grid <= hi + 1e-12)
        sol = solve_ivp(f, (lo, hi), z, method="Radau", rtol=1e-12, atol=1e-14, t_eval=t_grid[sel], dense_output=True)
        out.append(sol.y.T if lo == 0.0 else sol.y.T[1:])
        z = sol.sol(hi)
    Z = np.concatenate(out)
    names = list(co.state_names) + ["psi1", "Y1"]
    exact = np.column_stack([r[nm] for nm in names])
    scale = A0 / (2 * math.pi * F ** 2)
    assert np.abs(exact - Z).max() <= 1e-8 * scale
    delta = K * (_path(t_grid, A0, F) - Z[:, n + 1] - U * T * Z[:, n])
    np.testing.assert_allclose(r["delta"], delta, atol=1e-9 * np.abs(delta).max())
    # the loop settles on the path's final offset, straight (12 s: within 0.1 % of the offset and the peak steer)
    assert r["Y1"][-1] == pytest.approx(scale, abs=1e-3 * scale) and abs(r["delta"][-1]) < 1e-3 * np.abs(delta).max()


def test_closed_loop_measures_are_linear_in_A0_and_named_in_the_registry():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    base = measure_set(v, U)
    double = measure_set(v, U, conditions={"lane_change_ay_g": 0.3})
    assert double.hsto_driver_m == pytest.approx(2 * base.hsto_driver_m, rel=1e-9)
    assert double.ra_lane_change_driver == pytest.approx(base.ra_lane_change_driver, rel=1e-9)
    other = measure_set(v, U, conditions={"driver_gain_rad_per_m": 0.05, "driver_preview_s": 1.0})
    assert other.hsto_driver_m != base.hsto_driver_m               # the driver is a condition


def test_an_unstable_loop_is_refused_in_one_line():
    v = load_vehicle(EXAMPLES / "western_double.toml")
    with pytest.raises(ManoeuvreError, match="closed loop is unstable"):
        response(v, U, driver_lane_change(1.5, 0.4, 1.0, 0.0), 10.0, 0.01)
    m = measure_set(v, U, conditions={"driver_gain_rad_per_m": 1.0, "driver_preview_s": 0.0})
    assert m.hsto_driver_m is None and "closed loop is unstable" in m.reason("hsto_driver_m")
    p = subprocess.run(LCV + ["simulate", "--vehicle", str(EXAMPLES / "western_double.toml"), "--speed-kph", "88",
                              "--steer", "driver:0.15g:0.4:1:0"], capture_output=True, text=True, timeout=60)
    assert p.returncode == 2 and p.stderr.count("\n") == 1 and "unstable" in p.stderr


def test_lcv_simulate_drives_the_lane_change():
    p = subprocess.run(LCV + ["simulate", "--vehicle", str(EXAMPLES / "b_double.toml"), "--speed-kph", "88",
                              "--steer", "driver:0.15g:0.4", "--t-end", "10", "--dt", "0.05"],
                       capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    rows = p.stdout.strip().splitlines()
    head = rows[0].split(",")
    last = dict(zip(head, map(float, rows[-1].split(","))))
    assert len(rows) == 202 and last["Y1_m"] == pytest.approx(0.15 * G_MPS2 / (2 * math.pi * 0.16), abs=0.01)


@pytest.mark.parametrize("spec,message", [("driver:0.15g", "driver takes A0:F or A0:F:K:T"),
                                          ("driver:0.15g:0.4:0:0.5", "driver gain must be in (0, 1] rad/m"),
                                          ("driver:0.15g:0.4:0.1:9", "driver preview must be in [0, 5] s"),
                                          ("driver:0.15g:0.4:x:0.5", "K [rad/m] must be a number")])
def test_bad_driver_specs_name_the_part(spec, message):
    with pytest.raises(SteerError, match=None) as exc:
        parse_steer(spec)
    assert message in str(exc.value)
