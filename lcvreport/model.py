r"""The linear yaw-plane model of an A-train in the thesis form M x' = S x + F.

State (thesis order, SPEC section 2): ``x = [v1, r1..rN, thetaA..]`` with
``theta_k = psi_k - psi_(k+1)``.  The equations are written with the principle of
virtual power in the generalized speeds ``q = (v1, r1..rN)``; this eliminates the
joint forces exactly as the thesis does by hand (eq. 3.14-3.18, Appendix E), for any
number of units N.

Kinematics (joint constraint, eq. 3.3/4.7)::

    v_(k+1) = v_k - b_k r_k - f_(k+1) r_(k+1) + u theta_k

so ``v = Jv q + u K theta`` and ``r = Jr q``.  With per-unit tire force and moment
``F_i = (a_i v_i + b_i r_i)/u``, ``N_i = (c_i v_i + d_i r_i)/u`` the blocks are::

    M = [[Jv' m Jv + Jr' I Jr,  u Jv' m K],  [0, I]]
    S = [[(Jv' a Jv + Jv' b Jr + Jr' c Jv + Jr' d Jr)/u - u Jv' m Jr,
          Jv' a K + Jr' c K],
         [theta_k' = r_k - r_(k+1)]]

Every block is affine in u and 1/u and linear in the tire scale s, which is what
:class:`SystemCoefficients` stores, so that sweeps over speed and tire scale are
array operations.  Units: in, lbf, s (M rows in lbf*s^2/in ..., S in lbf ...).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .vehicle import Train


@dataclass(frozen=True, eq=False)
class SystemCoefficients:
    r"""Speed- and tire-scale-free coefficients of the thesis matrices of one train.

    ``M(u) = M0 + u*M1``;  ``S(u, s) = s*(S0 + Sinv/u) + Skin + u*Su``;
    ``B_delta(s) = s*Bdelta``; ``B_P`` and ``B_T`` are constant.

    Attributes
    ----------
    train : Train
    M0, M1 : numpy.ndarray, shape (n, n)
        Mass matrix parts [thesis units; M1 per in/s].
    S0, Sinv, Su, Skin : numpy.ndarray, shape (n, n)
        Stiffness parts: tire part independent of u, tire part times 1/u [per s/in],
        inertial part times u, and the articulation kinematics rows.
    Bdelta : numpy.ndarray, shape (n,)
        Generalized force per radian of steer angle at tire scale 1 [lbf/rad, lbf*in/rad].
    B_P : numpy.ndarray, shape (n, n_axles)
        Generalized force per lbf of residual lateral force P (along +y) at each axle.
    B_T : numpy.ndarray, shape (n, n_axles)
        Generalized force per lbf*in of residual aligning moment T (about +z) at each axle.
    """

    train: Train
    M0: np.ndarray
    M1: np.ndarray
    S0: np.ndarray
    Sinv: np.ndarray
    Su: np.ndarray
    Skin: np.ndarray
    Bdelta: np.ndarray
    B_P: np.ndarray
    B_T: np.ndarray

    @property
    def n_states(self) -> int:
        """Number of thesis states 2N."""
        return self.M0.shape[0]

    def M(self, speed: float | np.ndarray) -> np.ndarray:
        """Mass matrix at forward speed ``speed`` [in/s]; broadcasts over arrays of speed."""
        u = np.asarray(speed, dtype=float)[..., None, None]
        return self.M0 + u * self.M1

    def S(self, speed: float | np.ndarray, tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
        """Stiffness matrix at ``speed`` [in/s] and ``tire_scale`` [-]; broadcasts."""
        u = np.asarray(speed, dtype=float)[..., None, None]
        s = np.asarray(tire_scale, dtype=float)[..., None, None]
        return s * (self.S0 + self.Sinv / u) + self.Skin + u * self.Su

    def B_delta(self, tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
        """Generalized force per radian of steer angle [lbf/rad, lbf*in/rad]."""
        s = np.asarray(tire_scale, dtype=float)[..., None]
        return s * self.Bdelta

    def input_matrix(self, tire_scale: float = 1.0) -> np.ndarray:
        """Input matrix B for ``w = [delta, P_axles..., T_axles...]`` (rad, lbf, lbf*in)."""
        return np.column_stack([self.B_delta(tire_scale), self.B_P, self.B_T])


def kinematic_jacobians(train: Train) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Partial velocities of the joint constraint chain.

    Returns
    -------
    Jv : numpy.ndarray, shape (N, N+1)
        d v_i / d q, q = (v1, r1..rN) [-, in].
    Jr : numpy.ndarray, shape (N, N+1)
        d r_i / d q [-].
    K : numpy.ndarray, shape (N, N-1)
        d v_i / d (u theta_k) [-]: 1 for every joint ahead of unit i.
    """
    units = train.units
    n = len(units)
    Jv = np.zeros((n, n + 1))
    Jr = np.zeros((n, n + 1))
    K = np.zeros((n, n - 1))
    Jv[:, 0] = 1.0
    for i in range(n):
        Jr[i, 1 + i] = 1.0
        for j in range(i):
            # unit j (ahead of i): its rear joint b_j, and its front joint f_j if it has one
            Jv[i, 1 + j] -= units[j].rear_joint_in + units[j].front_joint_in
            K[i, j] = 1.0
        Jv[i, 1 + i] -= units[i].front_joint_in
    return Jv, Jr, K


def _unit_tire_sums(train: Train) -> tuple[np.ndarray, ...]:
    """Per-unit sums times u: F_i*u = a v + b r, N_i*u = c v + d r (tire scale 1)."""
    D2 = train.dual_spacing_in ** 2
    n = train.n_units
    a = np.zeros(n)
    b = np.zeros(n)
    c = np.zeros(n)
    d = np.zeros(n)
    for i, unit in enumerate(train.units):
        for ax in unit.axles:
            x = ax.position_in
            # slip angle alpha = delta - (v + x r)/u; F = CF alpha; M = -CM alpha (restoring)
            a[i] += -ax.CF
            b[i] += -ax.CF * x
            c[i] += -ax.CF * x + ax.CM
            d[i] += -ax.CF * x * x + ax.CM * x - (ax.CS * D2 if ax.dual else 0.0)
    return a, b, c, d


@lru_cache(maxsize=256)
def system_coefficients(train: Train) -> SystemCoefficients:
    """Build the speed-free coefficient matrices of ``train`` (cached per train).

    Parameters
    ----------
    train : Train

    Returns
    -------
    SystemCoefficients
    """
    n = train.n_units
    nq = n + 1
    ns = 2 * n
    Jv, Jr, K = kinematic_jacobians(train)
    m = np.array([u.mass for u in train.units])
    inertia = np.array([u.inertia for u in train.units])
    a, b, c, d = _unit_tire_sums(train)

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

    axles = train.axles
    B_P = np.zeros((ns, len(axles)))
    B_T = np.zeros((ns, len(axles)))
    Bdelta = np.zeros(ns)
    for col, ax in enumerate(axles):
        i = ax.unit - 1
        B_P[:nq, col] = Jv[i] + ax.position_in * Jr[i]
        B_T[:nq, col] = Jr[i]
        if ax.steer:
            # F = CF*delta at the steer axle, aligning moment -CM*delta
            Bdelta[:nq] += ax.CF * Jv[i] + (ax.CF * ax.position_in - ax.CM) * Jr[i]
    for arr in (M0, M1, S0, Sinv, Su, Skin, Bdelta, B_P, B_T):
        arr.setflags(write=False)
    return SystemCoefficients(train, M0, M1, S0, Sinv, Su, Skin, Bdelta, B_P, B_T)


def system_matrices(train: Train, speed: float | np.ndarray,
                    tire_scale: float | np.ndarray = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Thesis matrices M and S of eq. 3.8 / 4.12.

    Parameters
    ----------
    train : Train
    speed : float or array
        Forward speed u [in/s] (50 mph = 880 in/s).
    tire_scale : float or array
        Chapter V factor on every tire coefficient [-].

    Returns
    -------
    M, S : numpy.ndarray, shape (..., 2N, 2N)
        In thesis units (lbf, in, s).
    """
    check_speed(speed)
    check_tire_scale(tire_scale)
    co = system_coefficients(train)
    return co.M(speed), co.S(speed, tire_scale)


def state_matrix(train: Train, speed: float | np.ndarray, tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
    """A = M^-1 S [1/s and mixed units], broadcast over speed and tire scale."""
    M, S = system_matrices(train, speed, tire_scale)
    return np.linalg.solve(M, S)


def check_speed(speed: float | np.ndarray, name: str = "speed") -> None:
    """Raise ``ValueError`` unless every speed is finite and positive."""
    u = np.asarray(speed, dtype=float)
    if not np.all(np.isfinite(u)) or np.any(u <= 0):
        raise ValueError(f"{name} must be finite and > 0 (forward speed), got {speed!r}")


def check_tire_scale(tire_scale: float | np.ndarray, name: str = "tire_scale") -> None:
    """Raise ``ValueError`` unless every tire scale is finite and positive."""
    s = np.asarray(tire_scale, dtype=float)
    if not np.all(np.isfinite(s)) or np.any(s <= 0):
        raise ValueError(f"{name} must be finite and > 0, got {tire_scale!r}")
