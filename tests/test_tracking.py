"""Straight-line tracking (SPEC section 13, issue 18, first part): per-tire residuals and
fleet statistics against hand-derived cases, an independent moment computation, a
Monte Carlo and the closed-form Gaussian exceedance."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.stats import norm

from lcvreport import load_preset, load_vehicle
from lcvreport.analysis.steady import trim
from lcvreport.tracking.tires import TrackingError, axle_residuals, serial_sign, slots_of
from lcvreport.tracking.statistics import parse_distribution, tracking_stats
from lcvreport.model.yaw_plane.equations import system_coefficients

from conftest import EXAMPLES

U88 = 88 / 3.6


def _tire(position, c, p, side, cm=0.0, pm=0.0):
    return dict(position=position, conicity_N=c, ply_steer_N=p, conicity_moment_Nm=cm, ply_steer_moment_Nm=pm,
                serial_side=side)


@pytest.mark.parametrize("side_l, side_r, P", [("out", "out", 60.0), ("in", "in", 60.0), ("out", "in", -140.0),
                                               ("in", "out", 260.0)])
def test_a_single_axle_both_sides(side_l, side_r, P):
    """Conicity 100 N toward the serial side, ply steer 30 N along +y: both out or both in,
    conicity cancels and ply steer doubles; left out (-y) + right in (-y): 60 - 200."""
    v = load_preset("tractor_semitrailer")
    r = axle_residuals(v, [_tire("11:left", 100.0, 30.0, side_l, cm=10.0, pm=2.0),
                           _tire("11:right", 100.0, 30.0, side_r, cm=10.0, pm=2.0)])
    assert r.P_N == {"11": P}
    assert r.T_Nm == {"11": pytest.approx(4.0 + (P - 60.0) / 10.0)}


def test_every_dual_slot_and_mounting():
    v = load_preset("tractor_semitrailer")
    assert slots_of(4) == ("left_outer", "left_inner", "right_inner", "right_outer")
    signs = {(slot, m): serial_sign(slot, m, 4) for slot in slots_of(4) for m in ("out", "in")}
    assert signs == {("left_outer", "out"): -1.0, ("left_outer", "in"): 1.0, ("left_inner", "out"): -1.0,
                     ("left_inner", "in"): 1.0, ("right_inner", "out"): 1.0, ("right_inner", "in"): -1.0,
                     ("right_outer", "out"): 1.0, ("right_outer", "in"): -1.0}
    axle = [a.name for a in v.axles if a.tires == 4][0]
    mounted = [_tire(f"{axle}:{s}", 50.0 * (k + 1), 10.0, m) for k, (s, m) in
               enumerate(zip(slots_of(4), ("out", "in", "out", "in")))]
    # -50 + 100 + 150 - 200 conicity, 4 x 10 ply steer
    assert axle_residuals(v, mounted).P_N == {axle: pytest.approx(40.0 + (-50 + 100 + 150 - 200))}
    with pytest.raises(TrackingError, match="filled twice"):
        axle_residuals(v, mounted + mounted[:1])
    with pytest.raises(TrackingError, match="has the slots"):
        axle_residuals(v, [_tire(f"{axle}:left", 1.0, 1.0, "out")])


def _independent_moments(v, slots_axles, c, p, cm, pm, Es):
    """Mean and SD of the offtracking from the axle loads' mean vector and covariance
    matrix and one trim per axle load (not the module's per-tire sums)."""
    names = v.axle_names
    co = system_coefficients(v)
    n = len(names)
    mu = np.zeros(2 * n)
    cov = np.zeros((2 * n, 2 * n))
    for axle, s in zip(slots_axles, Es):
        j = names.index(axle)
        mu[j] += p.mean + s * c.mean
        mu[n + j] += pm.mean + s * cm.mean
        var_s = 1.0 - s * s                           # Var(s): 0 fixed, 1 random
        cov[j, j] += p.variance + c.variance * (s * s + var_s) + var_s * c.mean ** 2
        cov[n + j, n + j] += pm.variance + cm.variance * (s * s + var_s) + var_s * cm.mean ** 2
        cov[j, n + j] += var_s * c.mean * cm.mean
        cov[n + j, j] += var_s * c.mean * cm.mean
    g = np.array([trim(v, U88, col).offtracking_m for col in np.column_stack([co.B_P, co.B_T]).T])
    return float(g @ mu), float(math.sqrt(g @ cov @ g))


@pytest.mark.parametrize("mounting", ["out", "random"])
def test_exact_mean_and_sd_equal_an_independent_computation_and_a_monte_carlo(mounting):
    v = load_preset("aucnat")
    c, p = parse_distribution("normal:30:120", "c"), parse_distribution("uniform:-20:90", "p")
    cm, pm = parse_distribution("normal:5:8", "cm"), parse_distribution("normal:-2:3", "pm")
    s = tracking_stats(v, U88, c, p, mounting, cm, pm, draws=1_000_000, seed=7)
    slots = [(a.name, slot) for i, a in zip(v.axle_units, v.axles) if i >= 1 for slot in
             slots_of(a.tires)]
    from lcvreport.tracking.tires import _side
    Es = [0.0 if mounting == "random" else _side(slot, v.axles[v.axle_names.index(ax)].tires) for ax, slot in slots]
    mean, sd = _independent_moments(v, [ax for ax, _ in slots], c, p, cm, pm, Es)
    assert s.offtracking_mean_m == pytest.approx(mean, rel=1e-9)
    assert s.offtracking_sd_m == pytest.approx(sd, rel=1e-9)
    se = sd / math.sqrt(s.draws)
    assert abs(s.samples_m.mean() - mean) <= 4 * se
    assert abs(s.samples_m.std() - sd) <= 4 * sd / math.sqrt(2 * s.draws)


def test_the_printed_interval_covers_the_closed_form_gaussian_exceedance():
    """Ply steer only, normal, fixed mounting: the offtracking is normal, and
    P(|O| > m) = Phi((-m - mu)/sigma) + 1 - Phi((m - mu)/sigma)."""
    v = load_vehicle(EXAMPLES / "western_double.toml")
    zero = parse_distribution("normal:0:0", "c")
    s = tracking_stats(v, U88, zero, parse_distribution("normal:2000:9000", "p"), "out", draws=200_000, seed=3)
    mu, sigma, m = s.offtracking_mean_m, s.offtracking_sd_m, s.margin_m
    exact = norm.cdf((-m - mu) / sigma) + norm.sf((m - mu) / sigma)
    assert 0.01 < exact < 0.5
    lo, hi = s.exceedance_ci95
    assert lo <= exact <= hi
    assert s.margin_m == pytest.approx((3.66 - 2.59) / 2)


@pytest.mark.parametrize("args, fragment", [
    (["--conicity", "normal:0"], "normal:MEAN:SD or uniform:LO:HI"),
    (["--conicity", "uniform:5:1"], "HI must be >= LO"),
    (["--conicity", "normal:0:nan"], "finite"),
    (["--axles", "99"], "unknown axle '99'"),
    (["--draws", "0"], "--draws"),
    (["--lane-width-m", "2.0"], "wider than the body"),
])
def test_bad_tracking_arguments_are_one_line_exit_2(args, fragment):
    base = {"--conicity": "normal:0:100", "--ply-steer": "normal:30:40"}
    for k, val in zip(args[::2], args[1::2]):
        base[k] = val
    flat = [x for kv in base.items() for x in kv if kv[0] in ("--conicity", "--ply-steer")] + \
        [x for kv in zip(args[::2], args[1::2]) for x in kv if kv[0] not in ("--conicity", "--ply-steer")]
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "tracking", "stats", "--preset", "aucnat",
                        "--speed-kph", "88", "--mounting", "random", "--draws", "1000", *flat],
                       capture_output=True, text=True)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and fragment in p.stderr, p.stderr


def test_lcv_tracking_stats_json():
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "tracking", "stats", "--preset", "aucnat",
                        "--speed-kph", "88", "--conicity", "normal:0:100", "--ply-steer", "normal:30:40",
                        "--mounting", "random", "--draws", "20000", "--crossfall-percent", "2", "--json"],
                       capture_output=True, text=True)
    doc = json.loads(p.stdout)
    assert set(doc) >= {"offtracking_m", "trim_delta_rad", "exceedance", "margin_m"}
    assert set(doc["offtracking_m"]) == {"mean", "sd", "quantiles"} and doc["exceedance"]["draws"] == 20000
    assert len(doc["exceedance"]["ci95"]) == 2


@pytest.mark.parametrize("suffix", [".csv", ".toml"])
def test_tires_file_gives_the_axle_loads_a_hand_computation_gives(tmp_path, suffix):
    """Left outer serial side out (-y): 30 - 120; right outer in (-y): -10 - 80; axle 61 P = -180 N,
    T = (2 - 8) + (1 - 6) = -11 N*m: the same measures as --residual 61=-180,-11."""
    path = tmp_path / f"tires{suffix}"
    if suffix == ".csv":
        path.write_text("position,conicity_N,ply_steer_N,serial_side,conicity_moment_Nm,ply_steer_moment_Nm\n"
                        "61:left_outer,120,30,out,8,2\n61:right_outer,80,-10,in,6,1\n")
    else:
        path.write_text('[[tires]]\nposition = "61:left_outer"\nconicity_N = 120.0\nply_steer_N = 30.0\n'
                        'serial_side = "out"\nconicity_moment_Nm = 8.0\nply_steer_moment_Nm = 2.0\n'
                        '[[tires]]\nposition = "61:right_outer"\nconicity_N = 80.0\nply_steer_N = -10.0\n'
                        'serial_side = "in"\nconicity_moment_Nm = 6.0\nply_steer_moment_Nm = 1.0\n')
    run = lambda *a: json.loads(subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset",  # noqa
                                                "aucnat", "--speed-kph", "88", *a, "--json"],
                                               capture_output=True, text=True).stdout)
    assert run("--tires", str(path))["trim"] == run("--residual", "61=-180,-11")["trim"]


@pytest.mark.parametrize("content, fragment", [
    ("position,conicity_N,ply_steer_N\n61:left_outer,1,2\n", "missing column 'serial_side'"),
    ("position,conicity_N,ply_steer_N,serial_side\n61:left_outer,x,2,out\n", "must be a number"),
    ("position,conicity_N,ply_steer_N,serial_side\n61:left_outer,1,2,up\n", "serial_side must be out or in"),
    ("position,conicity_N,ply_steer_N,serial_side\n99:left,1,2,out\n", "unknown axle '99'"),
    ("position,conicity_N,ply_steer_N,serial_side\n61:left_outer,inf,2,out\n", "finite"),
])
def test_a_bad_tires_file_is_one_line_exit_2(tmp_path, content, fragment):
    path = tmp_path / "tires.csv"
    path.write_text(content)
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--preset", "aucnat", "--speed-kph", "88",
                        "--tires", str(path)], capture_output=True, text=True)
    assert p.returncode == 2 and len(p.stderr.strip().splitlines()) == 1 and fragment in p.stderr, p.stderr


def test_the_statistics_plot_themselves_with_the_margin_and_the_mean():
    v = load_vehicle(EXAMPLES / "western_double.toml")
    zero = parse_distribution("normal:0:0", "c")
    s = tracking_stats(v, U88, zero, parse_distribution("normal:2000:9000", "p"), "out", draws=20_000, seed=3)
    fig = s.plot()
    ax = fig.axes[0]
    assert ax.get_xlabel() == "trimmed offtracking [m]"
    xs = sorted(line.get_xdata()[0] for line in ax.get_lines())
    assert xs == pytest.approx(sorted([-s.margin_m, s.offtracking_mean_m, s.margin_m]))
