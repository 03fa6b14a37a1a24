"""The model object (issue 41, docs/model.md#the-model-object): the linear models meet the
protocol, their derivatives are their linearization, and one implicit integration of any model
(``analysis/integrate.py``) gives, on the linear models, their exact responses -- rtol 1e-8 puts
every signal within 1e-6 of its peak -- for every steer input of docs/manoeuvres.md, with and
without residual sources."""
from __future__ import annotations

import numpy as np
import pytest

from lcvreport.analysis.exact import response
from lcvreport.analysis.integrate import integrate
from lcvreport.manoeuvres.steer import parse_steer, table
from lcvreport.model.base import MODELS, VehicleModel, build_model
from lcvreport.model.linear import linear_model
from lcvreport.model.presets import load_preset
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.model.yaw_plane.loads import ResidualLoads, ResidualSources

from conftest import EXAMPLES

STEERS = ("step:0.005", "sine:0.01:0.4", "pulse:0.01:0.5", "csv", "lane-change:0.15g:0.4", "driver:0.15g:0.4")


def _steer(spec):
    if spec == "csv":
        return table([0.0, 0.7, 1.5, 2.2], [0.0, 0.01, -0.006, 0.0], source="test table")
    return parse_steer(spec)


@pytest.mark.parametrize("name, model", [("tractor_semitrailer", "yaw_plane"), ("b_double", "yaw_plane"),
                                         ("b_double", "yaw_roll")])
def test_the_linear_models_meet_the_protocol_and_their_derivatives_are_their_linearization(name, model):
    v = load_preset(name) if name == "tractor_semitrailer" else load_vehicle(EXAMPLES / f"{name}.toml")
    m = build_model(v, model)
    assert isinstance(m, VehicleModel) and m.kind == "linear" and m.name == model and m.linearize(20.0) is m
    assert m is linear_model(v, model)
    rng = np.random.default_rng(3)
    x, w = rng.normal(size=m.n_states), rng.normal(size=len(m.input_names)) * 1e-2
    A, G = m.state_derivative_maps(20.0, 1.1)
    B = m.input_matrix_full(1.1)
    ref = A @ x + G @ (B @ w)
    assert np.allclose(m.derivatives(0.0, x, w, 20.0, 1.1), ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    # the input columns are the sources' generalized forces (the exact response's F)
    src = ResidualSources(ResidualLoads({v.axle_names[-1]: 900.0}, {v.axle_names[-1]: 70.0}),
                          {v.axle_names[1]: 0.002}, 3.0)
    from lcvreport.analysis.integrate import input_vector
    assert np.allclose(B @ input_vector(m, 0.0, src, 1.1), src.vector(v, 1.1, model), rtol=1e-12, atol=1e-9)
    assert sorted(MODELS) == ["nonlinear", "yaw_plane", "yaw_roll"]


CASES = [("tractor_semitrailer", "yaw_plane"), ("b_double", "yaw_roll")]


@pytest.mark.parametrize("spec", STEERS)
@pytest.mark.parametrize("name, model", CASES)
def test_integrating_a_linear_model_gives_its_exact_response(name, model, spec):
    v = load_preset(name) if name == "tractor_semitrailer" else load_vehicle(EXAMPLES / f"{name}.toml")
    u, t_end, dt = 22.0, 8.0, 0.02
    steer = _steer(spec)
    src = ResidualSources(ResidualLoads({v.axle_names[-1]: 500.0}, {}), {}, 1.0) if spec == "step:0.005" else None
    exact = response(v, u, steer, t_end, dt, F=None if src is None else src.vector(v, 1.0, model), model=model)
    m = build_model(v, model)
    if steer.prescribes_acceleration:                      # the inverse system's steer, integrated open loop
        def run_steer(t, _x, r=exact):
            return r.value_at("delta", min(t, t_end))
        got = integrate(m, run_steer, u, t_end, dt, sources=src)
    else:
        got = integrate(m, steer, u, t_end, dt, sources=src)
    names = [*m.state_names, "psi1", "Y1", *(f"ay{i + 1}" for i in range(v.n_units)), "Y_rear",
             f"Y_{v.units[-1].rearmost_axle.name}"]
    for sig in names:
        ref = exact[sig]
        peak = np.abs(ref).max()
        err = np.abs(got[sig] - ref).max()
        assert err <= 1e-6 * peak, (sig, err / peak)
    # extrema located on the dense output agree with the exact ones
    k = f"ay{v.n_units}"
    assert got.peak_abs(k) == pytest.approx(exact.peak_abs(k), rel=1e-6)
