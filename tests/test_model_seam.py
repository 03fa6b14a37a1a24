"""The model seam: analysis, measures and batches take any registered linear model; the yaw
plane is the default and the first implementation."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import lcvreport.model.linear as linear
from lcvreport import load_preset
from lcvreport.analysis.batch import VariantBatch
from lcvreport.analysis.exact import response
from lcvreport.analysis.frequency import rearward_amplification
from lcvreport.analysis.modes import eigenvalues, modes
from lcvreport.analysis.steady import steady_state
from lcvreport.manoeuvres.steer import sine
from lcvreport.measures.amplification import single_sine
from lcvreport.measures.stability import critical_speed, least_damping, least_damping_batched
from lcvreport.model.linear import LinearModel, ModelError, check_model, linear_model
from lcvreport.model.yaw_plane.equations import system_coefficients

U = 24.0


def test_the_yaw_plane_is_the_default_linear_model():
    v = load_preset("aucnat")
    m = linear_model(v)
    assert isinstance(m, LinearModel) and m is system_coefficients(v) and m.name == "yaw_plane" and m.kind == "linear"
    assert len(m.state_names) == len(m.state_units) == m.n_states == 2 * v.n_units
    assert linear_model(v, "yaw-plane") is m                     # the command line's spelling


def test_an_unknown_model_is_refused_in_one_line():
    with pytest.raises(ModelError, match=r"unknown model 'roll'; valid: yaw-plane"):
        check_model("roll")
    with pytest.raises(ModelError):
        eigenvalues(load_preset("aucnat"), U, model="roll")


def _heavy(vehicle):
    """The vehicle with every yaw inertia doubled: what the toy model computes on."""
    return replace(vehicle, units=tuple(replace(u, yaw_inertia_kg_m2=2 * u.yaw_inertia_kg_m2) for u in vehicle.units))


def _toy(vehicle, units=None):
    """A second linear model registered through the seam: the yaw plane of the heavier vehicle,
    carrying the original vehicle (what the analysis is handed)."""
    return replace(system_coefficients(_heavy(vehicle)), vehicle=vehicle)


@pytest.fixture
def toy(monkeypatch):
    import sys
    monkeypatch.setitem(linear.MODELS, "toy", "toy_model:build")
    mod = type(sys)("lcvreport.model.toy_model")
    mod.build = _toy
    monkeypatch.setitem(sys.modules, "lcvreport.model.toy_model", mod)
    return "toy"


def test_analysis_and_measures_run_on_any_registered_model(toy):
    v = load_preset("aucnat")
    h = _heavy(v)
    np.testing.assert_array_equal(eigenvalues(v, U, model=toy), eigenvalues(h, U))
    assert modes(v, U, model=toy).max_real == modes(h, U).max_real
    F = np.zeros(v.n_units * 2)
    F[0] = 1000.0
    np.testing.assert_array_equal(steady_state(v, U, F, model=toy), steady_state(h, U, F))
    assert rearward_amplification(v, U, model=toy) == rearward_amplification(h, U)
    assert least_damping(v, U, model=toy) == least_damping(h, U)
    assert critical_speed(v, 0.3, model=toy) == critical_speed(h, 0.3)
    assert single_sine(v, U, model=toy).rearward_amplification == single_sine(h, U).rearward_amplification
    r, rh = response(v, U, sine(0.01, 0.4), 5.0, 0.01, model=toy), response(h, U, sine(0.01, 0.4), 5.0, 0.01)
    np.testing.assert_array_equal(r["ay6"], rh["ay6"])
    b = VariantBatch(v, {"trailer3.mass_kg": np.array([v.units[5].mass_kg])}, model=toy)
    np.testing.assert_allclose(least_damping_batched(b, U)[0], [least_damping(h, U)[0]], rtol=1e-12)
    # and the default is untouched by the registration
    assert eigenvalues(v, U)[0] != eigenvalues(h, U)[0]
