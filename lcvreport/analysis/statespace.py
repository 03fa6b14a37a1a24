"""The model as a state-space system with named signals (SI), and as a python-control
``StateSpace`` so that ``control.frequency_response``, ``bode_plot`` and
``step_response`` work on it.

* states: ``v1`` [m/s], ``r1..rN`` [rad/s], ``thetaA..`` [rad]
* inputs: ``delta`` [rad] (every steered axle), ``P_<axle>`` [N], ``T_<axle>`` [N*m]
* outputs: the states, ``ay1..ayN`` [m/s^2] (lateral acceleration of each unit's CG,
  ``a_i = v_i' + u r_i``), ``y2..yN`` [m] (rear-end offsets from the tractor axis,
  eq. 4.42-4.46 linearized: ``sin Theta ~ Theta``).

Examples
--------
>>> from lcvreport import load_preset, to_statespace
>>> sys = to_statespace(load_preset("tractor_semitrailer"), 22.352)
>>> sys.ninputs, sys.noutputs, sys.nstates
(9, 7, 4)
>>> sys.input_labels[:3]
['delta', 'P_11', 'P_12']
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients
from ..model.yaw_plane.outputs import rear_end_weights


@dataclass(frozen=True)
class StateSpaceMatrices:
    """``x' = A x + B w``, ``y = C x + D w`` with named signals (SI).

    Attributes
    ----------
    A, B, C, D : numpy.ndarray
    states, inputs, outputs : tuple of str
    units_of : dict
        Signal name -> SI unit.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    units_of: dict


def input_names(vehicle: Vehicle) -> tuple[str, ...]:
    """``delta``, ``P_<axle>`` ..., ``T_<axle>`` ... (the columns of :meth:`input_matrix`)."""
    return ("delta",) + tuple(f"P_{a}" for a in vehicle.axle_names) + tuple(f"T_{a}" for a in vehicle.axle_names)


def state_space(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> StateSpaceMatrices:
    """The state-space matrices of the model at one speed [m/s] (SI, named signals)."""
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle)
    n = vehicle.n_units
    A, G = co.state_derivative_maps(speed_mps, tire_scale)
    Bw = co.input_matrix(tire_scale)
    B = G @ Bw
    Ca, Da = co.acceleration_maps(speed_mps, tire_scale)
    # y = W Theta, Theta_k = theta_1 + ... + theta_(k-1): a cumulative sum of the theta states
    cum = np.zeros((n - 1, 2 * n))
    for k in range(n - 1):
        cum[k, n + 1:n + 2 + k] = 1.0
    Cy = rear_end_weights(vehicle) @ cum
    C = np.vstack([np.eye(2 * n), Ca, Cy])
    D = np.vstack([np.zeros((2 * n, Bw.shape[1])), Da @ Bw, np.zeros((n - 1, Bw.shape[1]))])
    states = linear_model(vehicle).state_names
    outputs = states + tuple(f"ay{i}" for i in range(1, n + 1)) + tuple(f"y{k}" for k in range(2, n + 1))
    inputs = input_names(vehicle)
    units_of = {"v1": "m/s", **{f"r{i}": "rad/s" for i in range(1, n + 1)},
                **{s: "rad" for s in states[n + 1:]}, **{f"ay{i}": "m/s^2" for i in range(1, n + 1)},
                **{f"y{k}": "m" for k in range(2, n + 1)}, "delta": "rad",
                **{f"P_{a}": "N" for a in vehicle.axle_names}, **{f"T_{a}": "N*m" for a in vehicle.axle_names}}
    return StateSpaceMatrices(A, B, C, D, states, inputs, outputs, units_of)


def to_statespace(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0):
    """The model at one speed as a ``control.StateSpace`` (python-control), SI, named signals.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    tire_scale : float

    Returns
    -------
    control.StateSpace
        Inputs ``delta, P_<axle>..., T_<axle>...``; outputs the states, ``ay1..ayN``,
        ``y2..yN``; see the module docstring for units.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> sys = to_statespace(load_preset("tractor_semitrailer"), 24.4)
    >>> sys.ninputs > 1, sys.input_labels[0]
    (True, 'delta')
    """
    import control
    m = state_space(vehicle, speed_mps, tire_scale)
    return control.StateSpace(m.A, m.B, m.C, m.D, inputs=list(m.inputs), outputs=list(m.outputs),
                              states=list(m.states), name=vehicle.name)
