r"""The linear yaw-plane model of any chain of units in the thesis form M x' = S x + F.

State (docs/model.md): ``x = [v1, r1..rN, thetaA..]`` with ``theta_k = psi_k - psi_(k+1)``.
The equations are written with the principle of virtual power in the generalized
speeds ``q = (v1, r1..rN)``; this eliminates the joint forces exactly as the thesis
does by hand (eq. 3.14-3.18, Appendix E), for any number of units.

Kinematics (joint constraint, eq. 3.3/4.7, signed couplings of docs/vehicle_files.md)::

    v_(k+1) = v_k + rc_k r_k - fc_(k+1) r_(k+1) + u theta_k

so ``v = Jv q + u K theta`` and ``r = Jr q``.  With per-unit tire force and moment
``F_i = (a_i v_i + b_i r_i)/u``, ``N_i = (c_i v_i + d_i r_i)/u`` the blocks are::

    M = [[Jv' m Jv + Jr' I Jr,  u Jv' m K],  [0, I]]
    S = [[(Jv' a Jv + Jv' b Jr + Jr' c Jv + Jr' d Jr)/u - u Jv' m Jr,
          Jv' a K + Jr' c K],
         [theta_k' = r_k - r_(k+1)]]

Every block is affine in u and 1/u and linear in the tire scale s, which is what
:class:`SystemCoefficients` stores, so that sweeps over speed and tire scale are
array operations.  The coefficients can be expressed in SI (the default: rows in N,
N*m and 1/s; v1 in m/s) or in the thesis' units (lbf, lbf*in; v1 in in/s) to compare
with the printed matrices; the arithmetic is the same, on numbers converted first.

Examples
--------
>>> from lcvreport import load_preset, system_matrices
>>> from lcvreport.units import THESIS, mph_to_mps
>>> M, S = system_matrices(load_preset("tractor_semitrailer"), mph_to_mps(50.0), units=THESIS)
>>> round(float(M[0, 0]), 2)                    # m1 + m2 [lbf*s^2/in], eq. 3.17
211.0
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ...units import SI, UnitSystem
from ..linear import LinearCoefficients, check_speed, check_tire_scale
from ..vehicle import Vehicle
from .outputs import point_lateral_map
from .states import state_names


@dataclass(frozen=True, eq=False)
class SystemCoefficients(LinearCoefficients):
    r"""Speed- and tire-scale-free coefficients of the matrices of one vehicle.

    ``M(u) = M0 + u*M1``;  ``S(u, s) = s*(S0 + Sinv/u) + Skin + u*Su``;
    ``B_delta(s) = s*Bdelta``; ``B_P`` and ``B_T`` are constant.  Here u is in the
    unit system's length unit per second; the methods take ``speed_mps`` [m/s].

    Attributes
    ----------
    vehicle : Vehicle
    units : UnitSystem
        The system the coefficients are expressed in.
    M0, M1, S0, Sinv, Su, Skin : numpy.ndarray, shape (2N, 2N)
    Bdelta : numpy.ndarray, shape (2N,)
        Generalized force per radian of steer angle at tire scale 1.
    B_P : numpy.ndarray, shape (2N, n_axles)
        Generalized force per force unit of residual lateral force P (along +y), per axle.
    B_T : numpy.ndarray, shape (2N, n_axles)
        Generalized force per moment unit of residual aligning moment T (about +z), per axle.
    B_eps : numpy.ndarray, shape (2N, n_axles)
        Generalized force per radian of misalignment (thrust angle) of each axle at tire
        scale 1: the axle's slip angle gains +eps (docs/manoeuvres.md).
    B_crossfall : numpy.ndarray, shape (2N,)
        Generalized force per unit of sin(atan(crossfall)): m_i g at every unit's CG, along +y.
    Jv, Jr : numpy.ndarray, shape (N, N+1)
        Partial velocities: lateral velocity and yaw rate of every unit per generalized speed.
    K : numpy.ndarray, shape (N, N-1)
        d v_i / d (u theta_k): 1 for every joint ahead of unit i.
    """

    Jv: np.ndarray
    Jr: np.ndarray
    K: np.ndarray
    B_eps: np.ndarray = None
    B_crossfall: np.ndarray = None

    name = "yaw_plane"

    def velocity_map(self, speed_mps: float) -> np.ndarray:
        """``V`` with ``v = V x``: the CG lateral velocity of every unit [length/s] from the
        state (``[Jv, u K]``), shape (N, 2N)."""
        u = float(self.units.speed(speed_mps))
        n = self.vehicle.n_units
        V = np.zeros((n, 2 * n))
        V[:, :n + 1] = self.Jv
        V[:, n + 1:] = u * self.K
        return V

    def yaw_rate_map(self) -> np.ndarray:
        """``R`` with ``r = R x``, shape (N, 2N)."""
        n = self.vehicle.n_units
        R = np.zeros((n, 2 * n))
        R[:, :n + 1] = self.Jr
        return R

    @property
    def state_names(self) -> tuple[str, ...]:
        """``v1, r1..rN, thetaA..`` (joints lettered from the front)."""
        return state_names(self.vehicle.n_units)

    @property
    def state_units(self) -> tuple[str, ...]:
        n = self.vehicle.n_units
        return ("m/s",) + ("rad/s",) * n + ("rad",) * (n - 1)

    def heading_rows(self) -> np.ndarray:
        """``Theta_k = psi1 - psi_k`` of units 2..N over ``[x, psi1, Y1]``: the sums of the
        articulation angles ahead of each unit, shape (N-1, n + 2)."""
        nu, n = self.vehicle.n_units, self.n_states
        cum = np.zeros((nu - 1, n + 2))
        for k in range(nu - 1):
            cum[k, nu + 1:nu + 2 + k] = 1.0
        return cum

    def point_lateral_map(self, unit: int, x_m: float) -> np.ndarray:
        """``c`` with the point's global lateral position ``c . [psi1, Y1, Theta_2..Theta_N]`` [m]
        (first order): :func:`lcvreport.model.yaw_plane.outputs.point_lateral_map`."""
        return point_lateral_map(self.vehicle, unit, x_m)

    def point_lateral_row(self, unit: int, x_m: float) -> np.ndarray:
        """The global lateral position [m] of the point at signed x on unit ``unit`` (0-based)
        over ``[x, psi1, Y1]``, first order, shape (n + 2,)."""
        c = self.point_lateral_map(unit, x_m)
        row = c[2:] @ self.heading_rows() if self.vehicle.n_units > 1 else np.zeros(self.n_states + 2)
        n = self.n_states
        row[n] += c[0]
        row[n + 1] += c[1]
        return row


def kinematic_jacobians(rear: np.ndarray, front: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial velocities of the joint constraint chain.

    Parameters
    ----------
    rear : numpy.ndarray, shape (N,)
        Signed x of each unit's rear coupling (0 on the last: unused).
    front : numpy.ndarray, shape (N,)
        Signed x of each unit's front coupling (0 on the first: unused).

    Returns
    -------
    Jv, Jr : numpy.ndarray, shape (N, N+1)
        Lateral velocity and yaw rate of every unit per generalized speed (v1, r1..rN).
    K : numpy.ndarray, shape (N, N-1)
        d v_i / d (u theta_k): 1 for every joint ahead of unit i.
    """
    n = rear.size
    Jv = np.zeros((n, n + 1))
    Jr = np.zeros((n, n + 1))
    K = np.zeros((n, n - 1))
    Jv[:, 0] = 1.0
    for i in range(n):
        Jr[i, 1 + i] = 1.0
        for j in range(i):
            # unit j ahead of unit i: its rear coupling, and its front coupling if it has one
            Jv[i, 1 + j] += rear[j] - front[j]
            K[i, j] = 1.0
        Jv[i, 1 + i] -= front[i]
    return Jv, Jr, K


@lru_cache(maxsize=256)
def system_coefficients(vehicle: Vehicle, units: UnitSystem = SI) -> SystemCoefficients:
    """Build the speed-free coefficient matrices of ``vehicle`` (cached per vehicle).

    Parameters
    ----------
    vehicle : Vehicle
    units : UnitSystem
        :data:`lcvreport.units.SI` (default) or :data:`lcvreport.units.THESIS`.

    Returns
    -------
    SystemCoefficients

    Examples
    --------
    >>> from lcvreport import load_preset, system_coefficients
    >>> co = system_coefficients(load_preset("aucnat"))
    >>> co.n_states, co.B_P.shape                 # 12 states, 8 axles
    (12, (12, 8))
    """
    L, Fu = units.length_m, units.force_N
    n = vehicle.n_units
    nq = n + 1
    ns = 2 * n
    m = np.array([u.mass_kg for u in vehicle.units]) / units.mass_kg
    inertia = np.array([u.yaw_inertia_kg_m2 for u in vehicle.units]) / units.inertia_kg_m2
    rear = np.array([0.0 if u.rear_coupling_m is None else u.rear_coupling_m for u in vehicle.units]) / L
    front = np.array([0.0 if u.front_coupling_m is None else u.front_coupling_m for u in vehicle.units]) / L
    Jv, Jr, K = kinematic_jacobians(rear, front)

    # per-unit tire sums times u: F_i u = a v_i + b r_i, N_i u = c v_i + d r_i (tire scale 1)
    a, b, c, d = (np.zeros(n) for _ in range(4))
    axles = vehicle.axles
    which = vehicle.axle_units
    for i, ax in zip(which, axles):
        x = ax.x_m / L
        CF = ax.cornering_stiffness_axle_N_per_rad / Fu
        CM = ax.aligning_stiffness_axle_Nm_per_rad / (Fu * L)
        CSD2 = ax.dual_yaw_damping_axle_N_m2 / (Fu * L * L)
        # slip angle alpha = delta - (v + x r)/u; F = CF alpha; M = -CM alpha; dual term -CS D^2 r/u
        a[i] += -CF
        b[i] += -CF * x
        c[i] += -CF * x + CM
        d[i] += -CF * x * x + CM * x - CSD2

    M0 = np.zeros((ns, ns))
    M1 = np.zeros((ns, ns))
    M0[:nq, :nq] = Jv.T @ (m[:, None] * Jv) + Jr.T @ (inertia[:, None] * Jr)
    M0[nq:, nq:] = np.eye(n - 1)
    M1[:nq, nq:] = Jv.T @ (m[:, None] * K)

    Sinv = np.zeros((ns, ns))
    S0 = np.zeros((ns, ns))
    Su = np.zeros((ns, ns))
    Skin = np.zeros((ns, ns))
    Sinv[:nq, :nq] = (Jv.T @ (a[:, None] * Jv) + Jv.T @ (b[:, None] * Jr)
                      + Jr.T @ (c[:, None] * Jv) + Jr.T @ (d[:, None] * Jr))
    S0[:nq, nq:] = Jv.T @ (a[:, None] * K) + Jr.T @ (c[:, None] * K)
    Su[:nq, :nq] = -Jv.T @ (m[:, None] * Jr)
    for k in range(n - 1):
        Skin[nq + k, 1 + k] = 1.0
        Skin[nq + k, 2 + k] = -1.0

    B_P = np.zeros((ns, len(axles)))
    B_T = np.zeros((ns, len(axles)))
    B_eps = np.zeros((ns, len(axles)))
    Bdelta = np.zeros(ns)
    for col, (i, ax) in enumerate(zip(which, axles)):
        x = ax.x_m / L
        B_P[:nq, col] = Jv[i] + x * Jr[i]
        B_T[:nq, col] = Jr[i]
        CF = ax.cornering_stiffness_axle_N_per_rad / Fu
        CM = ax.aligning_stiffness_axle_Nm_per_rad / (Fu * L)
        # an angle added to the slip angle: F = CF angle at the axle, aligning moment -CM angle
        B_eps[:nq, col] = CF * Jv[i] + (CF * x - CM) * Jr[i]
        if ax.steered:
            Bdelta[:nq] += B_eps[:nq, col]
    g = 9.80665 / L                                   # standard gravity in the unit system
    B_crossfall = np.zeros(ns)
    B_crossfall[:nq] = Jv.T @ (m * g)
    arrays = (M0, M1, S0, Sinv, Su, Skin, Bdelta, B_P, B_T, Jv, Jr, K, B_eps, B_crossfall)
    for arr in arrays:
        arr.setflags(write=False)
    return SystemCoefficients(vehicle, units, *arrays)


def system_matrices(vehicle: Vehicle, speed_mps: float | np.ndarray, tire_scale: float | np.ndarray = 1.0,
                    units: UnitSystem = SI) -> tuple[np.ndarray, np.ndarray]:
    """Matrices M and S of eq. 3.8 / 4.12 at a forward speed.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float or array
        Forward speed u [m/s] (50 mph = 22.352 m/s).
    tire_scale : float or array
        Chapter V factor on every tire coefficient [-].
    units : UnitSystem
        SI (default) or :data:`lcvreport.units.THESIS` (lbf, in, s) for the printed matrices.

    Returns
    -------
    M, S : numpy.ndarray, shape (..., 2N, 2N)

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> M, S = system_matrices(load_preset("aucnat"), 22.352)
    >>> M.shape, S.shape
    ((12, 12), (12, 12))
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle, units)
    return co.M(speed_mps), co.S(speed_mps, tire_scale)
