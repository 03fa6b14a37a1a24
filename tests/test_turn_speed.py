"""The low-speed turn, fast and once (issue 43 item 1): the dense output evaluated in one pass
(bit for bit scipy's), the extremes refined by vectorized zooms (equal to a scalar search on the
dense output to 1e-9 m), the turn shared by variants of one geometry (bit for bit a fresh
computation)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from lcvreport import load_preset, load_vehicle
from lcvreport.measures import low_speed as ls
from lcvreport.model.low_speed.kinematics import DenseHeadings

from conftest import EXAMPLES


def test_the_stacked_dense_output_is_scipys_bit_for_bit():
    rng = np.random.default_rng(2)
    sol = solve_ivp(lambda t, y: np.array([np.sin(3 * t) * y[1], -y[0] + np.cos(t)]), (0.0, 7.0), [1.0, 0.0],
                    method="DOP853", rtol=1e-10, atol=1e-12, dense_output=True).sol
    t = np.concatenate([rng.uniform(0.0, 7.0, 500), sol.ts, [0.0, 7.0]])
    np.testing.assert_array_equal(DenseHeadings(sol)(t), sol(t))
    np.testing.assert_array_equal(DenseHeadings(sol)(3.3), sol(3.3))


def _scalar_extreme(probe, value, sign, s, centre, lo, hi, refine=True):
    """The extreme as a scalar search finds it: scipy's bounded Brent between the grid's
    neighbours, brentq on the sector's edges, one point of the dense output per evaluation
    (the implementation before issue 43, kept here as the reference)."""
    from scipy.optimize import brentq
    pts = probe.points(s)
    phi = ls._unwrapped(pts, centre, probe.heading(s))
    vals = value(pts)
    inside = (phi >= lo) & (phi <= hi)
    if not inside.any():
        return None

    def phi_at(x):
        xs = np.array([x])
        return float(ls._unwrapped(probe.points(xs), centre, probe.heading(xs))[0])

    def val_at(x):
        return float(value(probe.points(np.array([x])))[0])
    best = None

    def offer(v, x):
        nonlocal best
        if best is None or sign * v > sign * best[0]:
            best = (v, x)
    k = np.flatnonzero(inside)
    for run in np.split(k, np.flatnonzero(np.diff(k) > 1) + 1):
        i0, i1 = int(run[0]), int(run[-1])
        j = i0 + int(np.argmax(sign * vals[i0:i1 + 1]))
        offer(float(vals[j]), float(s[j]))
        if i0 < j < i1:
            res = minimize_scalar(lambda x: -sign * val_at(x), bounds=(s[j - 1], s[j + 1]), method="bounded",
                                  options={"xatol": 1e-10})
            if lo <= phi_at(res.x) <= hi:
                offer(-sign * float(res.fun), float(res.x))
        for a, b, inner in ((i0 - 1, i0, i0), (i1, i1 + 1, i1)):
            if a < 0 or b >= s.size:
                continue
            out = a if inner == b else b
            edge = lo if phi[out] < lo else hi
            x = brentq(lambda x: phi_at(x) - edge, s[a], s[b], xtol=1e-13)
            offer(val_at(x), x)
    return best


@pytest.mark.parametrize("name,angle", [("legal_max", 90.0), ("b_double", 180.0), ("truck_full_trailer", 360.0),
                                        ("tractor_semitrailer", 1440.0)])
def test_the_measures_are_the_scalar_searchs_to_a_nanometre(name, angle, monkeypatch):
    v = load_vehicle(EXAMPLES / f"{name}.toml") if (EXAMPLES / f"{name}.toml").exists() else load_preset(name)
    ls.low_speed_turn.cache_clear()
    fast = ls.low_speed_turn(v, angle_deg=angle)
    ls.low_speed_turn.cache_clear()
    monkeypatch.setattr(ls, "_extreme", _scalar_extreme)
    monkeypatch.setattr(ls, "MARGIN_M", float("inf"))                # every probe searched
    ref = ls.low_speed_turn(v, angle_deg=angle)
    ls.low_speed_turn.cache_clear()
    for key in ("lssp_m", "low_speed_offtracking_m", "frontal_swing_m"):
        assert getattr(fast, key) == pytest.approx(getattr(ref, key), abs=1e-9), key
    for unit, value in ref.tail_swing_m.items():
        assert fast.tail_swing_m[unit] == pytest.approx(value, abs=1e-9), unit
    assert fast.where["outermost"] == ref.where["outermost"] and fast.where["innermost"] == ref.where["innermost"]


def test_variants_of_one_geometry_share_the_turn_bit_for_bit():
    v = load_vehicle(EXAMPLES / "b_double.toml")
    heavy = replace(v, units=tuple(replace(u, mass_kg=1.2 * u.mass_kg, yaw_inertia_kg_m2=1.3 * u.yaw_inertia_kg_m2)
                                   for u in v.units))
    ls.low_speed_turn.cache_clear()
    fresh = ls.low_speed_turn(heavy).to_dict()
    ls.low_speed_turn.cache_clear()
    first = ls.low_speed_turn(v)
    shared = ls.low_speed_turn(heavy)
    assert shared.run is first.run and shared.vehicle is heavy        # computed once, handed to each
    assert shared.to_dict() == fresh                                  # the same numbers as its own
    stiffer = replace(v, units=tuple(replace(u, axles=tuple(replace(a, cornering_stiffness_N_per_rad=
                                                                    a.cornering_stiffness_N_per_rad * (1.5 if k else 1.0))
                                                            for k, a in enumerate(u.axles))) for u in v.units))
    assert ls.low_speed_turn(stiffer).run is not first.run              # the heading law reads their shares
    scaled = replace(v, units=tuple(replace(u, axles=tuple(replace(a, cornering_stiffness_N_per_rad=
                                                                   a.cornering_stiffness_N_per_rad * (0.9 + 0.05 * i))
                                                           for a in u.axles)) for i, u in enumerate(v.units)))
    assert ls.low_speed_turn(scaled).run is first.run                   # each unit's scaled together: not their scale
    ls.low_speed_turn.cache_clear()
    assert ls.low_speed_turn(scaled).to_dict() == dict(first.to_dict(), **{"vehicle": scaled.name}) or \
        ls.low_speed_turn(scaled).to_dict() == first.to_dict()          # and computed afresh, bit for bit the same
