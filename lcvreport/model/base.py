r"""The model object: one protocol every model of a vehicle meets, the table of the models there
are, and :func:`build_model` (docs/model.md#the-model-object).

A **model** of a vehicle is an object with a ``kind`` (``"linear"``: equations ``M(u) x' = S(u, s)
x + B w``, exact responses; ``"nonlinear"``: any ``x' = f(t, x, w)``), the ``vehicle`` it is of, its
``name`` (a key of :data:`MODELS`), named states with units, named inputs, and

- ``derivatives(t, x, w, speed_mps, tire_scale)`` -> ``x'`` (SI),
- ``outputs(t, x, w, speed_mps, tire_scale)`` -> ``{signal: value}`` (SI),
- ``linearize(speed_mps, tire_scale)`` -> a :class:`~lcvreport.model.linear.LinearModel` (a
  linear model is its own linearization; the nonlinear model's is section 2's at straight running).

What a model is *asked* -- a response to a manoeuvre, its measures -- is computed above this
layer from these: :func:`lcvreport.analysis.respond.respond` gives a linear model's exact
response and integrates any other (:mod:`lcvreport.analysis.integrate`); the measure registry
says per family what it needs of a model (``linear``: its linearization; ``response``: a
response; ``inverse``: the inverse system of a linear model).  (MODELS.md puts ``respond`` on the
model; the layers put analysis above the model, so it is a function of the model there: the
model layer stays numpy-only and free of scipy.)

A new model is a folder ``model/<name>/`` whose builder takes a vehicle and returns an object
meeting :class:`VehicleModel`, and one entry of :data:`MODELS`.

Examples
--------
>>> from lcvreport import load_preset
>>> m = build_model(load_preset("tractor_semitrailer"), "yaw_plane")
>>> isinstance(m, VehicleModel), m.kind, m.name, m.state_names
(True, 'linear', 'yaw_plane', ('v1', 'r1', 'r2', 'thetaA'))
>>> sorted(MODELS)
['nonlinear', 'yaw_plane', 'yaw_roll']
"""
from __future__ import annotations

import importlib
from typing import Protocol, runtime_checkable

import numpy as np

from ..ranges import check_array

#: the models: name -> "module:builder" (relative to :mod:`lcvreport.model`), the builder taking a
#: vehicle and returning a :class:`VehicleModel` (imported on first use: reading the table loads no model)
MODELS = {"yaw_plane": "yaw_plane.equations:system_coefficients",
          "yaw_roll": "yaw_roll.equations:yaw_roll_coefficients",
          "nonlinear": "nonlinear.model:nonlinear_model"}
#: the linear ones (exact responses, eigenvalues, frequency responses)
LINEAR_MODELS = ("yaw_plane", "yaw_roll")
#: the others (integrated; any angle: the low-speed turn with tire forces)
NONLINEAR_MODELS = tuple(m for m in MODELS if m not in LINEAR_MODELS)
#: the spelling of the command line (``--model yaw-plane``) of each model
CLI_NAMES = {name: name.replace("_", "-") for name in MODELS}


class ModelError(ValueError):
    """An unknown model name; the message lists the valid ones."""


@runtime_checkable
class VehicleModel(Protocol):
    """What every model of a vehicle offers (see the module docstring)."""

    kind: str
    name: str
    vehicle: object

    @property
    def state_names(self) -> tuple[str, ...]: ...

    @property
    def state_units(self) -> tuple[str, ...]: ...

    @property
    def input_names(self) -> tuple[str, ...]: ...

    def derivatives(self, t: float, x: np.ndarray, w: np.ndarray, speed_mps: float,
                    tire_scale: float = 1.0) -> np.ndarray: ...

    def outputs(self, t: float, x: np.ndarray, w: np.ndarray, speed_mps: float,
                tire_scale: float = 1.0) -> dict: ...

    def linearize(self, speed_mps: float, tire_scale: float = 1.0): ...


def check_model(name: str, allowed=None) -> str:
    """``name`` if it is a model of :data:`MODELS` (the CLI's ``yaw-plane`` too) and, with
    ``allowed``, one of those; else :class:`ModelError` naming the valid ones."""
    key = str(name).replace("-", "_")
    valid = tuple(MODELS) if allowed is None else tuple(allowed)
    if key not in valid:
        raise ModelError(f"unknown model {name!r}; valid: {', '.join(k.replace('_', '-') for k in valid)}")
    return key


def build_model(vehicle, name: str = "yaw_plane", **options) -> VehicleModel:
    """The model ``name`` (:data:`MODELS`) of ``vehicle``; ``options`` go to its builder (the
    nonlinear model's tire law and friction coefficient).

    Parameters
    ----------
    vehicle : Vehicle
    name : {"yaw_plane", "yaw_roll", "nonlinear"}
        The command line's spelling (``yaw-plane``) too.
    **options
        The nonlinear model's ``tire`` ({"saturating", "linear"}) and ``friction_coefficient``.

    Returns
    -------
    VehicleModel
        A :class:`~lcvreport.model.linear.LinearModel` for the linear models.

    Raises
    ------
    ModelError
        An unknown model.

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> m = build_model(load_vehicle("examples/vehicles/b_double.toml"), "nonlinear", friction_coefficient=0.6)
    >>> m.kind, m.state_names[:3]
    ('nonlinear', ('X1', 'Y1', 'psi1'))
    """
    from .vehicle import check_vehicle
    check_vehicle(vehicle)
    entry = MODELS[check_model(name)]
    if callable(entry):                         # a model registered from outside: its builder itself
        build = entry
    else:
        module, _, builder = entry.partition(":")
        build = getattr(importlib.import_module(f"{__package__}.{module}"), builder)
    return build(vehicle, **options) if options else build(vehicle)


def check_speed(speed_mps, name: str = "speed") -> np.ndarray:
    """Raise :class:`lcvreport.ranges.RangeError` unless every speed [m/s] is in range."""
    return check_array("speed", speed_mps, name)


def check_tire_scale(tire_scale, name: str = "tire_scale") -> np.ndarray:
    """Raise :class:`lcvreport.ranges.RangeError` unless every tire scale is in range."""
    return check_array("tire_scale", tire_scale, name)
