"""A model from outside the package (issue 41's newcomer experiment, kept as a test): a yaw plane
whose tires saturate (mu F_z tanh(C alpha / (mu F_z)) in place of C alpha), written against the
VehicleModel protocol and registered with one MODELS entry.  Without touching the package it is
integrated (``respond``), simulated by the command line (``--model saturating``, offered by the
parser from MODELS) and measured: the linear families on its linearization, the response families
on its responses, null with the reason where it gives no signal a family reads."""
from __future__ import annotations

import io
import json
from dataclasses import dataclass, field

import numpy as np
import pytest

import lcvreport
from lcvreport.cli.main import run
from lcvreport.manoeuvres.steer import sine
from lcvreport.model import base
from lcvreport.model.linear import linear_model

from conftest import EXAMPLES


@dataclass(eq=False)
class SaturatingYawPlane:
    """Section 2's yaw plane with saturating tires: the difference of the saturated and the linear
    force enters as a lateral force at each axle (the yaw plane's own P columns)."""

    vehicle: object
    friction_coefficient: float = 0.8
    kind: str = field(default="nonlinear", init=False)
    name: str = field(default="saturating", init=False)

    def __post_init__(self):
        self.linear = linear_model(self.vehicle, "yaw_plane")
        self.state_names, self.state_units = self.linear.state_names, self.linear.state_units
        self.input_names = self.linear.input_names
        axles = [(i, a) for i, u in enumerate(self.vehicle.units) for a in u.axles]
        self._unit = np.array([i for i, _ in axles])
        self._x = np.array([a.x_m for _, a in axles])
        self._steered = np.array([a.steered for _, a in axles], dtype=float)
        self._C = np.array([a.cornering_stiffness_N_per_rad for _, a in axles])
        self._Fz = np.array([a.static_load_N for _, a in axles], dtype=float)

    @property
    def n_states(self) -> int:
        return self.linear.n_states

    def zero_input(self):
        return np.zeros(len(self.input_names))

    def derivatives(self, t, x, w, speed_mps, tire_scale=1.0):
        x, w = np.asarray(x, dtype=float), np.asarray(w, dtype=float)        # (n,) or (k, n): a block at once
        V, R = self.linear.velocity_map(speed_mps), self.linear.yaw_rate_map()
        v, r = x @ V.T, x @ R.T
        alpha = (v[..., self._unit] + self._x * r[..., self._unit]) / speed_mps - self._steered * w[..., :1]
        C, cap = tire_scale * self._C, self.friction_coefficient * self._Fz
        extra = -cap * np.tanh(C * alpha / cap) + C * alpha                  # saturated minus linear, along +y
        A, G = self.linear.state_derivative_maps(speed_mps, tire_scale)
        B = self.linear.input_matrix_full(tire_scale)
        return x @ A.T + (w @ B.T) @ G.T + (extra @ B[:, 1:1 + len(C)].T) @ G.T

    def outputs(self, t, x, w, speed_mps, tire_scale=1.0):
        x, w = np.asarray(x, dtype=float), np.asarray(w, dtype=float)
        a = self.derivatives(t, x, w, speed_mps, tire_scale) @ self.linear.velocity_map(speed_mps).T \
            + speed_mps * (x @ self.linear.yaw_rate_map().T)
        out = {name: x[..., k] for k, name in enumerate(self.state_names)}
        out["delta"] = w[..., 0]
        out.update({f"ay{i + 1}": a[..., i] for i in range(a.shape[-1])})
        return out

    def linearize(self, speed_mps=None, tire_scale=1.0):
        return self.linear


def saturating(vehicle, friction_coefficient: float = 0.8):
    return SaturatingYawPlane(vehicle, friction_coefficient)


@pytest.fixture
def registered(monkeypatch):
    monkeypatch.setitem(base.MODELS, "saturating", saturating)          # the one line a newcomer adds
    return lcvreport.load_vehicle(EXAMPLES / "b_double.toml")


def test_it_meets_the_protocol_and_reduces_to_the_yaw_plane(registered):
    v = registered
    m = lcvreport.build_model(v, "saturating")
    assert isinstance(m, base.VehicleModel)
    ratios = []
    for A in (0.0005, 0.005):
        lin = lcvreport.respond(v, "yaw_plane", sine(A, 0.4), 24.4, 6.0, 0.05)
        sat = lcvreport.respond(v, "saturating", sine(A, 0.4), 24.4, 6.0, 0.05)
        ratios.append(1 - sat.peak_abs("ay3") / lin.peak_abs("ay3"))
    assert 0 < ratios[0] < 1e-6 and 0 < ratios[1] < 1e-4          # saturation lowers the peak,
    assert ratios[1] / ratios[0] == pytest.approx(100, rel=0.05)  # by A^2 (tanh's cubic term)


def test_the_command_line_offers_and_runs_it(registered):
    b_double = str(EXAMPLES / "b_double.toml")
    out = io.StringIO()
    assert run(["simulate", "--vehicle", b_double, "--speed-kph", "88", "--model", "saturating", "--steer",
                "sine:0.01:0.4", "--t-end", "3", "--dt", "0.5", "--json"], out=out) == 0
    doc = json.loads(out.getvalue())
    r = lcvreport.respond(registered, "saturating", sine(0.01, 0.4), lcvreport.units.kph_to_mps(88.0), 3.0, 0.5)
    assert doc == json.loads(json.dumps(r.to_dict()))
    out = io.StringIO()
    assert run(["measures", "--vehicle", b_double, "--speed-kph", "88", "--model", "saturating", "--json"],
               out=out) == 0
    doc = json.loads(out.getvalue())
    lin = lcvreport.measure_set(registered, lcvreport.units.kph_to_mps(88.0)).to_dict()
    assert doc["least_damping_ratio"] == lin["least_damping_ratio"]          # its linearization: the yaw plane
    assert doc["ra_single_sine"] == pytest.approx(lin["ra_single_sine"], rel=1e-3)   # its response, nearly linear
    assert doc["hsto_driver_m"] is None and "Y_" in doc["reasons"]["hsto_driver_m"]   # a signal it does not give
