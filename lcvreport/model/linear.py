r"""The model seam: what the analysis, the measures, the FMUs and the studies need of any linear
model of a vehicle, and the table of the models there are.

A linear model is ``M(u) x' = S(u, s) x + B w`` at forward speed u and tire scale s, with
coefficients affine in u and 1/u::

    M(u) = M0 + u M1,   S(u, s) = s (S0 + Sinv / u) + Skin + u Su,   B_delta(s) = s Bdelta

(tire forces scale with s; inertia and kinematic terms do not), the input ``w = [delta,
P_axles, T_axles]`` (rad, N, N*m) with the misalignment and crossfall columns ``B_eps`` and
``B_crossfall``, and the maps from the state to every unit's lateral velocity and yaw rate,
from which the lateral accelerations ``a_i = v_i' + u r_i`` follow.  Its states are named
with units (:attr:`LinearModel.state_names`, :attr:`LinearModel.state_units`); the first two
are always unit 1's lateral velocity ``v1`` [m/s] and yaw rate ``r1`` [rad/s], which is all the
global position (``psi1' = r1``, ``Y1' = v1 + u psi1``) needs.

Models (:data:`MODELS`): ``yaw_plane`` (the thesis model, :mod:`lcvreport.model.yaw_plane`);
a new linear model is a folder beside it whose builder returns a :class:`LinearModel`, and one
entry here.  The low-speed kinematic model (:mod:`lcvreport.model.low_speed`) is not linear and
is a sibling of its own.

Examples
--------
>>> from lcvreport import load_preset
>>> m = linear_model(load_preset("tractor_semitrailer"))
>>> m.kind, m.name, m.n_states, m.state_names
('linear', 'yaw_plane', 4, ('v1', 'r1', 'r2', 'thetaA'))
>>> m.state_units
('m/s', 'rad/s', 'rad/s', 'rad')
>>> linear_model(load_preset("aucnat"), "yaw_plane").M(24.0).shape
(12, 12)
"""
from __future__ import annotations

import importlib
from dataclasses import dataclass

import numpy as np

from ..util.numerics import solve_scaled
from .base import check_speed, check_tire_scale  # noqa: F401  (their home is the model object's module)

#: the linear models: name -> "module:builder" (relative to this package); the builder takes
#: (vehicle, units) and returns a LinearModel
MODELS = {"yaw_plane": "yaw_plane.equations:system_coefficients",
          "yaw_roll": "yaw_roll.equations:yaw_roll_coefficients"}
#: the spelling of the command line (``--model yaw-plane``) for each model
CLI_NAMES = {name: name.replace("_", "-") for name in MODELS}
#: (A, G) pairs kept per model by :meth:`LinearModel.state_derivative_maps`
MAPS_KEPT = 8


class ModelError(ValueError):
    """An unknown model name; the message lists the valid ones."""


def check_model(name: str) -> str:
    """``name`` if it is a linear model (``yaw_plane``; the CLI's ``yaw-plane`` too), else
    :class:`ModelError` naming the valid ones."""
    key = str(name).replace("-", "_")
    if key not in MODELS:
        raise ModelError(f"unknown model {name!r}; valid: {', '.join(CLI_NAMES.values())}")
    return key


def linear_model(vehicle, model: str = "yaw_plane", units=None) -> "LinearModel":
    """The linear model ``model`` of ``vehicle`` (cached per vehicle by its builder).

    Parameters
    ----------
    vehicle : Vehicle
    model : str
        A key of :data:`MODELS`.
    units : UnitSystem, optional
        :data:`lcvreport.units.SI` (default) or :data:`lcvreport.units.THESIS`.
    """
    module, _, builder = MODELS[check_model(model)].partition(":")
    build = getattr(importlib.import_module(f"{__package__}.{module}"), builder)
    return build(vehicle) if units is None else build(vehicle, units)


def stiffness(coefficients, speed_mps, tire_scale=1.0):
    """``S(u, s) = s (S0 + Sinv / u) + Skin + u Su`` of any holder of the coefficients -- a
    :class:`LinearModel`, or a batch's arrays with a leading variant axis (a mapping or an object
    with ``S0, Sinv, Skin, Su``) -- broadcasting ``speed_mps`` [m/s] and ``tire_scale`` against
    the coefficients' leading axes (the one place the formula is written)."""
    get = coefficients.__getitem__ if isinstance(coefficients, dict) else lambda k: getattr(coefficients, k)
    u, s = speed_mps, tire_scale
    return s * (get("S0") + get("Sinv") / u) + get("Skin") + u * get("Su")


class LinearModel:
    """The interface of a linear model (see the module docstring), a
    :class:`~lcvreport.model.base.VehicleModel` of kind ``"linear"``.  Subclasses are frozen
    dataclasses holding ``vehicle``, ``units`` and the coefficients ``M0, M1, S0, Sinv, Su, Skin``
    (n, n), ``Bdelta`` (n,), ``B_P, B_T, B_eps`` (n, n_axles), ``B_crossfall`` (n,), and define
    :attr:`name`, :attr:`state_names`, :attr:`state_units`, :meth:`velocity_map`,
    :meth:`yaw_rate_map` and :meth:`point_lateral_map`."""

    kind = "linear"

    @property
    def input_names(self) -> tuple[str, ...]:
        """``delta`` [rad], every axle's ``P_<axle>`` [N], ``T_<axle>`` [N m], ``eps_<axle>``
        [rad], and ``a_crossfall`` [m/s^2] (g sin(atan(c/100))): the columns of
        :meth:`input_matrix_full` (the nonlinear model's inputs, the same)."""
        names = self.vehicle.axle_names
        return ("delta", *(f"P_{a}" for a in names), *(f"T_{a}" for a in names), *(f"eps_{a}" for a in names),
                "a_crossfall")

    def input_matrix_full(self, tire_scale: float = 1.0) -> np.ndarray:
        """B over every input of :attr:`input_names` (SI): the steer's and the misalignments'
        scale with the tire coefficients, P, T and the crossfall do not."""
        g = 9.80665 / self.units.length_m                # standard gravity in the unit system
        return np.column_stack([self.B_delta(tire_scale), self.B_P, self.B_T, tire_scale * self.B_eps,
                                self.B_crossfall / g])

    def derivatives(self, t: float, x: np.ndarray, w: np.ndarray, speed_mps: float,
                    tire_scale: float = 1.0) -> np.ndarray:
        """``x' = M(u)^-1 (S(u, s) x + B w)`` [SI] (``w`` over :attr:`input_names`)."""
        A, G = self.state_derivative_maps(speed_mps, tire_scale)
        return A @ np.asarray(x, dtype=float) + G @ (self.input_matrix_full(tire_scale) @ np.asarray(w, dtype=float))

    def outputs(self, t: float, x: np.ndarray, w: np.ndarray, speed_mps: float, tire_scale: float = 1.0) -> dict:
        """The states by name, ``delta`` and every unit's lateral acceleration ``ay<i> = v_i' + u r_i``
        [SI] at one instant."""
        x = np.asarray(x, dtype=float)
        xd = self.derivatives(t, x, w, speed_mps, tire_scale)
        u = float(self.units.speed(float(speed_mps)))
        a = self.velocity_map(speed_mps) @ xd + u * (self.yaw_rate_map() @ x)
        out = dict(zip(self.state_names, x.tolist()))
        out["delta"] = float(np.asarray(w)[0])
        out.update({f"ay{i + 1}": float(ai) for i, ai in enumerate(a)})
        return out

    def linearize(self, speed_mps: float = None, tire_scale: float = 1.0) -> "LinearModel":
        """A linear model is its own linearization."""
        return self

    @property
    def n_states(self) -> int:
        """Number of states n."""
        return self.M0.shape[0]

    @property
    def state_names(self) -> tuple[str, ...]:  # pragma: no cover - every model defines it
        raise NotImplementedError

    @property
    def state_units(self) -> tuple[str, ...]:  # pragma: no cover - every model defines it
        raise NotImplementedError

    def _u(self, speed_mps):
        return self.units.speed(np.asarray(speed_mps, dtype=float))[..., None, None]

    def M(self, speed_mps: float | np.ndarray) -> np.ndarray:
        """Mass matrix at forward speed [m/s]; broadcasts over arrays of speed."""
        return self.M0 + self._u(speed_mps) * self.M1

    def S(self, speed_mps: float | np.ndarray, tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
        """Stiffness matrix at forward speed [m/s] and tire scale [-]; broadcasts."""
        return stiffness(self, self._u(speed_mps), np.asarray(tire_scale, dtype=float)[..., None, None])

    def B_delta(self, tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
        """Generalized force per radian of steer angle (force and moment units per rad)."""
        return np.asarray(tire_scale, dtype=float)[..., None] * self.Bdelta

    def input_matrix(self, tire_scale: float = 1.0) -> np.ndarray:
        """B for ``w = [delta, P_axles..., T_axles...]`` (rad, force unit, moment unit)."""
        return np.column_stack([self.B_delta(tire_scale), self.B_P, self.B_T])

    def velocity_map(self, speed_mps: float) -> np.ndarray:  # pragma: no cover - every model defines it
        """``V`` with ``v = V x``: every unit's lateral velocity from the state, shape (N, n)."""
        raise NotImplementedError

    def yaw_rate_map(self) -> np.ndarray:  # pragma: no cover - every model defines it
        """``R`` with ``r = R x``, shape (N, n)."""
        raise NotImplementedError

    def point_lateral_map(self, unit: int, x_m: float) -> np.ndarray:  # pragma: no cover
        """The lateral position of the point ``x_m`` [m] of unit ``unit`` (0-based) over
        ``[psi1, Y1, x]`` (a map of length n + 2)."""
        raise NotImplementedError

    def articulation_rows(self) -> np.ndarray:
        """Rows picking the articulation angles ``theta_k`` out of the state, shape (N-1, n)."""
        nu = self.vehicle.n_units
        idx = [self.state_names.index(name) for name in self.state_names if name.startswith("theta")]
        rows = np.zeros((nu - 1, self.n_states))
        rows[np.arange(nu - 1), idx] = 1.0
        return rows

    def roll_offset_rows(self) -> np.ndarray | None:
        """Rows over the state of the lateral offsets [m] a model adds to units 2..N beyond the
        yaw-plane chain geometry (the yaw-roll model's roll of the couplings), or None."""
        return None

    def extra_signals(self, speed_mps: float, tire_scale: float = 1.0) -> tuple:
        """Outputs beyond the states and the ``ay``: ``(names, X, XD, D, O)`` with
        ``y = X x + XD x' + D delta + O F_y0`` (``F_y0`` each axle's constant tire force, N).
        None for the yaw plane; the yaw-roll model's roll outputs."""
        n, na = self.n_states, len(self.vehicle.axles)
        return [], np.zeros((0, n)), np.zeros((0, n)), np.zeros(0), np.zeros((0, na))

    def extra_signal_terms(self) -> dict:
        """:meth:`extra_signals` split by speed and tire scale (``X = X0 + u X1 + (s/u) X2 + s X3``,
        ``XD = XD0 + u XD1``, ``D = s D1``, ``O``); no rows for the yaw plane."""
        n, na = self.n_states, len(self.vehicle.axles)
        z = np.zeros((0, n))
        return {"names": [], "X0": z, "X1": z, "X2": z, "X3": z, "XD0": z, "XD1": z, "D1": np.zeros(0),
                "O": np.zeros((0, na))}

    def state_derivative_maps(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(A, G) with ``x' = A x + G F``: ``A = M^-1 S``, ``G = M^-1`` (equilibrated solve).

        For one speed and tire scale the result is kept (the last :data:`MAPS_KEPT` pairs,
        read-only arrays): a measure set asks for the same maps some twenty times."""
        scalar = np.ndim(speed_mps) == 0 and np.ndim(tire_scale) == 0
        if scalar:
            key = (float(speed_mps), float(tire_scale))
            memo = self.__dict__.setdefault("_maps_memo", {})
            hit = memo.get(key)
            if hit is not None:
                return hit
        n = self.n_states
        AG = solve_scaled(self.M(speed_mps), np.hstack([self.S(speed_mps, tire_scale), np.eye(n)]))
        A, G = AG[:, :n], AG[:, n:]
        if scalar:
            A.setflags(write=False)
            G.setflags(write=False)
            if len(memo) >= MAPS_KEPT:
                try:                                    # the oldest out (another thread may be at it too)
                    memo.pop(next(iter(memo)), None)
                except (RuntimeError, StopIteration):
                    pass
            memo[key] = (A, G)
        return A, G

    def acceleration_maps(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(Ca, Da) with the lateral accelerations of the unit CGs ``a = Ca x + Da F``
        (``a_i = v_i' + u r_i``), shape (N, n) each."""
        A, G = self.state_derivative_maps(speed_mps, tire_scale)
        V = self.velocity_map(speed_mps)
        u = float(self.units.speed(speed_mps))
        return V @ A + u * self.yaw_rate_map(), V @ G


@dataclass(frozen=True, eq=False)
class LinearCoefficients(LinearModel):
    """The coefficients every linear model holds (see :class:`LinearModel`): the vehicle, the unit
    system, ``M0, M1, S0, Sinv, Su, Skin`` (n, n), ``Bdelta`` (n,), ``B_P``, ``B_T`` (n, n_axles);
    a model's class adds its own fields after these."""

    vehicle: object
    units: object
    M0: np.ndarray
    M1: np.ndarray
    S0: np.ndarray
    Sinv: np.ndarray
    Su: np.ndarray
    Skin: np.ndarray
    Bdelta: np.ndarray
    B_P: np.ndarray
    B_T: np.ndarray

