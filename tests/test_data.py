"""Thesis data files, presets and the Appendix D tire fits."""
from __future__ import annotations

import numpy as np
import pytest

from lcvreport import data
from lcvreport.presets import PRESETS, load_preset, train_from_axle_loads
from lcvreport.tires import FIT_RANGE_LBF, tire_fit, tire_properties


@pytest.mark.parametrize("config", data.CONFIGURATIONS)
def test_gvw_is_the_sum_of_axle_loads(config):
    table = data.mass_table(config)
    assert sum(table[r]["axle_load_lbf"] for r in data.TABLE_ROWS) == table["gvw_lbf"]
    assert load_preset(config).gross_weight_lbf == table["gvw_lbf"]


@pytest.mark.parametrize("config", data.CONFIGURATIONS)
def test_tire_load_is_axle_load_over_tires(config):
    table = data.mass_table(config)
    for row in data.TABLE_ROWS:
        n = 2 if row == "tractor_steer" else 8 if row == "tractor_tandem" else 4
        assert abs(table[row]["axle_load_lbf"] / n - table[row]["tire_load_lbf"]) <= 0.5


def test_every_table_d_value_is_on_the_fitted_curves():
    """Figures D.1-D.3 recovered: the cubic fits reproduce every printed value to 0.1 %."""
    fit = tire_fit()
    for row in data.appendix_d_rows():
        cf, cm, cs = fit.evaluate(row["tire_load_lbf"])
        assert cf == pytest.approx(row["CF_lbf_per_rad"], rel=1e-3)
        assert cm == pytest.approx(row["CM_lbf_in_per_rad"], rel=1e-3)
        if "CS_lbf_per_rad" in row:
            assert cs == pytest.approx(row["CS_lbf_per_rad"], rel=1e-3)


def test_tire_fit_refuses_loads_outside_the_tables():
    lo, hi = FIT_RANGE_LBF
    for bad in (lo - 1, hi + 1, float("nan")):
        with pytest.raises(ValueError, match="tire_load_lbf"):
            tire_properties(bad)


def test_train_from_axle_loads_matches_the_table_train():
    a = load_preset("aucnat")
    loads = {r: data.mass_table("aucnat")[r]["axle_load_lbf"] for r in data.TABLE_ROWS}
    b = train_from_axle_loads("aucnat", loads)
    for x, y in zip(a.axles, b.axles):
        assert y.CF == pytest.approx(x.CF, rel=2e-3)
        assert y.CM == pytest.approx(x.CM, rel=2e-3)
        assert y.CS == pytest.approx(x.CS, rel=2e-3)


@pytest.mark.parametrize("preset", PRESETS)
def test_presets_geometry_and_signs(preset):
    t = load_preset(preset)
    assert t.units[0].axles[0].name == "11" and t.units[0].axles[0].position_in > 0
    assert all(ax.position_in <= 0 for u in t.units for ax in u.axles if ax.name != "11")
    assert all(u.front_joint_in > 0 for u in t.units[1:])
    assert t.axles[0].tires == 2 and all(ax.tires == 4 for ax in t.axles[1:])
    assert t.dual_spacing_in == 12.0
    n = 2 if preset == "tractor_semitrailer" else 6
    assert t.n_units == n and len(t.state_names) == 2 * n


def test_aucnat_table_values_per_axle():
    t = load_preset("aucnat")
    ax = {a.name: a for a in t.axles}
    assert ax["11"].CF == 2 * 30322 and ax["11"].CM == 2 * 73452 and ax["11"].CS == 0
    assert ax["12"].CF == 4 * 27998 and ax["13"].CS == 4 * 54145 and ax["12"].load_lbf == 41550 / 2
    assert t.units[-1].rear_joint_in == 155.28  # x6F, SPEC gap
    assert load_preset("tractor_semitrailer").units[-1].rear_joint_in == 187.83  # x2B, eq. 3.43


def test_unknown_names_are_refused_with_the_valid_ones():
    with pytest.raises(KeyError, match="aucnat"):
        load_preset("aucnatt")
    with pytest.raises(KeyError, match="trailer3"):
        load_preset("aucnat").unit("trailer4")
    with pytest.raises(ValueError, match="aucnat"):
        load_preset("empty", masses="unrounded")


def test_units_module_factors():
    from lcvreport import units
    assert units.mph_to_in_per_s(50) == pytest.approx(880.0, rel=1e-15)
    assert units.MPS_PER_MPH == pytest.approx(0.44704, rel=1e-15)
    assert units.lbf_to_n(1.0) == pytest.approx(4.4482216152605)
