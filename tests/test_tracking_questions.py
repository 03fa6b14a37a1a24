"""The thesis chapter on straight-line tracking (issue 18): its claims checked by other means."""
from __future__ import annotations

import math

import numpy as np
import pytest

from lcvreport import load_preset
from lcvreport.tracking.statistics import Distribution, tracking_stats
from lcvreport.tracking.tires import sensitivities, tire_slots
from lcvreport.thesis import tracking_questions as tq
from lcvreport.units import mph_to_mps

U = mph_to_mps(50.0)


def test_the_population_is_labelled_and_on_the_tire_load():
    pop = tq.assumed_population()
    assert pop.label.startswith("ASSUMED")
    v = load_preset("aucnat")
    behind = [a for a in v.axles if a.name[0] != "1"]                   # units 2..6: axles 21..61
    assert pop.tire_load_N == pytest.approx(sum(a.static_load_N for a in behind) / (4 * len(behind)), rel=1e-15)
    assert pop.conicity().b == pytest.approx(0.01 * pop.tire_load_N)


def test_the_offtracking_is_normal_so_the_closed_form_exceedance_holds():
    """Zero-mean normal conicity with random serial sides is normal: the Monte Carlo (the
    package's seed) must equal the Gaussian closed form within 4 standard errors where leaving
    the lane is common (a narrow lane, the population tripled)."""
    v = load_preset("aucnat")
    pop = tq.assumed_population(v)
    s = tracking_stats(v, U, pop.conicity(3.0), pop.ply_steer(3.0), "random", lane_width_m=2.59 + 2 * 0.06,
                       draws=200_000)
    p = tq.gaussian_exceedance(s.offtracking_mean_m, s.offtracking_sd_m, s.margin_m)
    assert 0.05 < p < 0.95
    assert abs(s.exceedance_probability - p) <= 4 * math.sqrt(p * (1 - p) / s.draws)


def test_mounting_claims():
    """Zero-mean conicity: out, in and random have one SD.  A batch leaning one way: random
    mounting adds sum over tires of g^2 mu_c^2 to the variance (by hand from the sensitivities)."""
    m = tq.mounting_study(draws=2_000, sets=2)
    pop = m.population
    sd = {k: s.offtracking_sd_m for k, s in m.fixed.items()}
    a = [k for k in sd if k[0] == "assumed population"]
    assert max(sd[k] for k in a) - min(sd[k] for k in a) <= 1e-15
    v = load_preset("aucnat")
    g = sensitivities(v, U)
    g_tires = np.array([g[0, s.axle] for s in tire_slots(v)])
    mu = tq.BATCH_CONICITY_MEAN_FRACTION * pop.tire_load_N
    batch = [k for k in sd if k[0] != "assumed population"]
    out = [k for k in batch if k[1] == "out"][0]
    rnd = [k for k in batch if k[1] == "random"][0]
    assert sd[rnd] ** 2 == pytest.approx(sd[out] ** 2 + np.sum(g_tires ** 2) * mu ** 2, rel=1e-12)
    # consistent mounting cancels the lean across each axle: the mean is the zero-lean mean
    assert m.fixed[out].offtracking_mean_m == pytest.approx(m.fixed[a[0]].offtracking_mean_m, rel=1e-12)
    assert np.all(np.abs(m.planned_offtracking_m) <= 3e-6)
    assert np.all(np.abs(m.planned_offtracking_m) <= np.abs(m.random_offtracking_m))


def test_crossfall_is_linear_in_the_sine_of_the_slope():
    rows = {r["crossfall_percent"]: r for r in tq.crossfall_beside_conicity(draws=2_000).rows()}
    ratio = rows[2.0]["offtracking_m"] / rows[1.0]["offtracking_m"]
    assert ratio == pytest.approx(math.sin(math.atan(0.02)) / math.sin(math.atan(0.01)), rel=1e-12)


def test_one_percent_rows_name_their_cases():
    rows = tq.one_percent_against_population(draws=2_000).rows()
    assert rows[0]["case"].startswith("1 % rule on trailers 2 and 3")
    assert rows[0]["offtracking_in"] == pytest.approx(rows[0]["offtracking_m"] / 0.0254, rel=1e-15)
