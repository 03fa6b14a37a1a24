r"""The linear yaw-roll model of any chain of units: M x' = S x + B w (docs/roll.md).

State ``x = [v1, r1..rN, p1..pN, thetaA.., phi1..phiN]``: ``v_i`` the lateral velocity of the
point of unit i's roll axis below its CG, ``p_i = phi_i'`` the roll rate of its sprung mass
(positive about +x: right side down).  The equations are written once, with the principle of
virtual power in the generalized speeds ``q = (v1, r1..rN, p1..pN)`` as the yaw plane's
(:mod:`lcvreport.model.yaw_plane.equations`); the joint constraint at coupling k, both coupling
points at the height ``h_c,k``::

    v_(k+1) = v_k + rc_k r_k - fc_(k+1) r_(k+1) + u theta_k + (h_c,k - h_r,k) p_k - (h_c,k - h_r,k+1) p_(k+1)

so ``v = Jv q + u K theta``, ``r = Jr q``, ``p = Jp q`` and the sprung CG moves at
``v_i + e_i p_i`` (partial velocities ``Js = Jv + E Jp``, ``E = diag(e)``).  With the non-rolling
mass ``m_u = m - m_s`` at the roll axis::

    M_qq = Jv' m_u Jv + Js' m_s Js + Jr' I_z Jr + Jp' I_x Jp - Jr' I_xz Jp - Jp' I_xz Jr
    M_q,theta = u (Jv' m_u + Js' m_s) K,     S_u = -(Jv' m_u + Js' m_s) Jr      (centripetal)
    tire forces at the roll axis: the yaw plane's blocks with this Jv (no roll moment on the sprung mass)
    roll moments: Jp' (Kphi phi - C p),  Kphi = diag(m_s g e - sum K + W terms) - coupling k_c

with ``theta_k' = r_k - r_(k+1)`` and ``phi_i' = p_i``.  Every block is affine in u and 1/u and
the tire blocks linear in the tire scale, as :class:`~lcvreport.model.linear.LinearModel` needs.

Examples
--------
>>> from lcvreport import load_vehicle
>>> from lcvreport.model.linear import linear_model
>>> m = linear_model(load_vehicle("examples/vehicles/b_double.toml"), "yaw_roll")
>>> m.state_names
('v1', 'r1', 'r2', 'r3', 'p1', 'p2', 'p3', 'thetaA', 'thetaB', 'phi1', 'phi2', 'phi3')
>>> m.M(25.0).shape
(12, 12)
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ...units import SI, UnitSystem
from ..linear import LinearCoefficients
from ..vehicle import Vehicle
from ..yaw_plane.equations import kinematic_jacobians
from ..yaw_plane.outputs import point_lateral_map
from ..yaw_plane.states import joint_letter
from .parameters import G_MPS2, RollParameters, roll_parameters


@dataclass(frozen=True, eq=False)
class YawRollCoefficients(LinearCoefficients):
    r"""Speed- and tire-scale-free coefficients of the yaw-roll model of one vehicle (SI).

    Attributes (besides :class:`~lcvreport.model.linear.LinearModel`'s)
    ----------
    roll : RollParameters
    Jv, Jr, Jp : numpy.ndarray, shape (N, 2N+1)
        Partial velocities: roll-axis lateral velocity, yaw rate and roll rate of every unit
        per generalized speed.
    K : numpy.ndarray, shape (N, N-1)
        d v_i / d (u theta_k).
    roll_stiffness : numpy.ndarray, shape (N, N)
        ``Kphi``: the roll moments on the sprung masses per radian of roll [N*m/rad].
    """

    B_eps: np.ndarray
    B_crossfall: np.ndarray
    Jv: np.ndarray
    Jr: np.ndarray
    Jp: np.ndarray
    K: np.ndarray
    roll_stiffness: np.ndarray
    roll: RollParameters

    name = "yaw_roll"

    @property
    def _n(self) -> int:
        return self.vehicle.n_units

    @property
    def theta_index(self) -> int:
        """Index of the first articulation angle in the state."""
        return 2 * self._n + 1

    @property
    def phi_index(self) -> int:
        """Index of ``phi1`` in the state."""
        return 3 * self._n

    @property
    def p_index(self) -> int:
        """Index of ``p1`` in the state."""
        return self._n + 1

    def velocity_map(self, speed_mps: float) -> np.ndarray:
        """``V`` with ``v = V x``: the roll-axis lateral velocity below every unit's CG [m/s]."""
        n, nq = self._n, 2 * self._n + 1
        V = np.zeros((n, self.n_states))
        V[:, :nq] = self.Jv
        V[:, nq:nq + n - 1] = float(speed_mps) * self.K
        return V

    def yaw_rate_map(self) -> np.ndarray:
        """``R`` with ``r = R x``."""
        R = np.zeros((self._n, self.n_states))
        R[:, :2 * self._n + 1] = self.Jr
        return R

    @property
    def state_names(self) -> tuple[str, ...]:
        """``v1, r1..rN, p1..pN, thetaA.., phi1..phiN``."""
        n = self._n
        return (("v1",) + tuple(f"r{i + 1}" for i in range(n)) + tuple(f"p{i + 1}" for i in range(n))
                + tuple(f"theta{joint_letter(k)}" for k in range(n - 1)) + tuple(f"phi{i + 1}" for i in range(n)))

    @property
    def state_units(self) -> tuple[str, ...]:
        n = self._n
        return ("m/s",) + ("rad/s",) * (2 * n) + ("rad",) * (2 * n - 1)

    def heading_rows(self) -> np.ndarray:
        """``Theta_k = psi1 - psi_k`` of units 2..N over ``[x, psi1, Y1]``, shape (N-1, n + 2)."""
        n = self._n
        cum = np.zeros((n - 1, self.n_states + 2))
        for k in range(n - 1):
            cum[k, self.theta_index:self.theta_index + k + 1] = 1.0
        return cum

    def roll_offset_rows(self) -> np.ndarray:
        """The lateral offset [m] of every unit's roll axis from the chain's yaw-plane geometry,
        over the state: row i-1 (units 2..N) sums ``(h_c,k - h_r,k) phi_k - (h_c,k - h_r,k+1) phi_(k+1)``
        over the couplings ahead of unit i; shape (N-1, n)."""
        n, rp = self._n, self.roll
        rows = np.zeros((n - 1, self.n_states))
        acc = np.zeros(self.n_states)
        for k in range(n - 1):
            acc = acc.copy()
            acc[self.phi_index + k] += rp.hc_m[k] - rp.hr_m[k]
            acc[self.phi_index + k + 1] -= rp.hc_m[k] - rp.hr_m[k + 1]
            rows[k] = acc
        return rows

    def point_lateral_map(self, unit: int, x_m: float) -> np.ndarray:
        """The yaw-plane chain's ``c`` over ``[psi1, Y1, Theta_2..]`` (roll-axis points);
        :meth:`point_lateral_row` adds the roll offsets."""
        return point_lateral_map(self.vehicle, unit, x_m)

    def point_lateral_row(self, unit: int, x_m: float) -> np.ndarray:
        """The global lateral position [m] of the roll-axis point at signed x on unit ``unit``
        over ``[x, psi1, Y1]``, first order, shape (n + 2,)."""
        c = self.point_lateral_map(unit, x_m)
        n = self.n_states
        row = c[2:] @ self.heading_rows() if self._n > 1 else np.zeros(n + 2)
        row[n] += c[0]
        row[n + 1] += c[1]
        if unit > 0:
            row[:n] += self.roll_offset_rows()[unit - 1]
        return row

    def axle_force_maps(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(Fx, Fd) with every axle's lateral tire force ``F_y = Fx x + Fd delta`` [N] (residual
        P, and the misalignment's ``s C_F eps``, add to it), shape (n_axles, n) and (n_axles,)."""
        u = float(speed_mps)
        V, R = self.velocity_map(u), self.yaw_rate_map()
        axles, which = self.vehicle.axles, self.vehicle.axle_units
        Fx = np.zeros((len(axles), self.n_states))
        Fd = np.zeros(len(axles))
        for j, (i, a) in enumerate(zip(which, axles)):
            cf = tire_scale * a.cornering_stiffness_axle_N_per_rad
            Fx[j] = -cf * (V[i] + a.x_m * R[i]) / u
            Fd[j] = cf if a.steered else 0.0
        return Fx, Fd

    def load_transfer_maps(self, speed_mps: float, tire_scale: float = 1.0
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Lx, Ld, Lf): the load transfer ``dF_z = (F_z,right - F_z,left)/2 = Lx x + Ld delta + Lf F_y0``
        [N] of every axle, ``(K phi_i + C p_i - h_r,i F_y)/T`` (``F_y0`` the per-axle constant part of
        the tire force: residual P and misalignment), shapes (n_axles, n), (n_axles,), (n_axles, n_axles)."""
        rp = self.roll
        Fx, Fd = self.axle_force_maps(speed_mps, tire_scale)
        i = rp.axle_unit
        hr = rp.hr_m[i]
        Lx = -hr[:, None] * Fx
        Lx[np.arange(i.size), self.phi_index + i] += rp.K_Nm_per_rad
        Lx[np.arange(i.size), self.p_index + i] += rp.C_Nms_per_rad
        Lx /= rp.T_m[:, None]
        return Lx, -hr * Fd / rp.T_m, np.diag(-hr / rp.T_m)

    def ltr_weights(self) -> np.ndarray:
        """``LTR = Wg dF_z``: row g weighs the axles of group g by ``2 / sum F_z0``, shape (groups, n_axles)."""
        rp = self.roll
        g_of = rp.group_of_unit[rp.axle_unit]
        W = np.zeros((len(rp.groups), g_of.size))
        for g in range(len(rp.groups)):
            sel = g_of == g
            W[g, sel] = 2.0 / rp.Fz0_N[sel].sum()
        return W

    def extra_signals(self, speed_mps: float, tire_scale: float = 1.0) -> tuple:
        """The outputs beyond the states and ``ay``: names, and rows over ``x``, over ``x'``, per
        radian of steer and per newton of each axle's constant tire force (see
        :func:`lcvreport.analysis.exact.response`): ``as<i>`` (the sprung CG's lateral acceleration
        ``a_i + e_i p_i'`` [m/s^2]), ``dFz_<axle>`` [N] and ``ltr<g>`` [-]."""
        n, rp = self._n, self.roll
        u = float(speed_mps)
        V, R = self.velocity_map(u), self.yaw_rate_map()
        na = len(self.vehicle.axles)
        Xs, Xd = u * R, V.copy()
        Xd[np.arange(n), self.p_index + np.arange(n)] += rp.e_m
        Lx, Ld, Lf = self.load_transfer_maps(u, tire_scale)
        Wg = self.ltr_weights()
        names = ([f"as{i + 1}" for i in range(n)] + [f"dFz_{a}" for a in self.vehicle.axle_names]
                 + [f"ltr{g + 1}" for g in range(len(rp.groups))])
        X = np.vstack([Xs, Lx, Wg @ Lx])
        XD = np.vstack([Xd, np.zeros((na + len(rp.groups), self.n_states))])
        D = np.r_[np.zeros(n), Ld, Wg @ Ld]
        O = np.vstack([np.zeros((n, na)), Lf, Wg @ Lf])
        return names, X, XD, D, O

    def extra_signal_terms(self) -> dict:
        """The outputs of :meth:`extra_signals` split by how they depend on the speed u [m/s] and
        the tire scale s [-] (what the native FMU assembles at run time)::

            X = X0 + u X1 + (s / u) X2 + s X3,   XD = XD0 + u XD1,   D = s D1,   O

        Keys ``names``, ``X0, X1, X2, X3, XD0, XD1`` (rows x n), ``D1`` (rows,), ``O`` (rows x
        n_axles); :meth:`extra_signals` at (u, s) equals the assembled terms to rounding (a test
        holds them together)."""
        n, rp, ns = self._n, self.roll, self.n_states
        nq = 2 * n + 1
        V0 = np.zeros((n, ns))
        V0[:, :nq] = self.Jv
        Vt = np.zeros((n, ns))
        Vt[:, nq:nq + n - 1] = self.K
        R = self.yaw_rate_map()
        axles, which = self.vehicle.axles, self.vehicle.axle_units
        na = len(axles)
        X0, X2, X3 = (np.zeros((na, ns)) for _ in range(3))
        D1 = np.zeros(na)
        for j, (i, a) in enumerate(zip(which, axles)):
            cf, hr, T = a.cornering_stiffness_axle_N_per_rad, rp.hr_m[i], rp.T_m[j]
            X2[j] = hr * cf * (V0[i] + a.x_m * R[i]) / T
            X3[j] = hr * cf * Vt[i] / T
            X0[j, self.phi_index + i] = rp.K_Nm_per_rad[j] / T
            X0[j, self.p_index + i] = rp.C_Nms_per_rad[j] / T
            D1[j] = -hr * cf / T if a.steered else 0.0
        O = np.diag(-rp.hr_m[rp.axle_unit] / rp.T_m)
        Wg = self.ltr_weights()
        ng = Wg.shape[0]
        XD0 = V0.copy()
        XD0[np.arange(n), self.p_index + np.arange(n)] += rp.e_m
        zeros = lambda rows: np.zeros((rows, ns))  # noqa: E731
        names = ([f"as{i + 1}" for i in range(n)] + [f"dFz_{a}" for a in self.vehicle.axle_names]
                 + [f"ltr{g + 1}" for g in range(ng)])
        return {"names": names,
                "X0": np.vstack([zeros(n), X0, Wg @ X0]), "X1": np.vstack([R, zeros(na + ng)]),
                "X2": np.vstack([zeros(n), X2, Wg @ X2]), "X3": np.vstack([zeros(n), X3, Wg @ X3]),
                "XD0": np.vstack([XD0, zeros(na + ng)]), "XD1": np.vstack([Vt, zeros(na + ng)]),
                "D1": np.r_[np.zeros(n), D1, Wg @ D1], "O": np.vstack([np.zeros((n, na)), O, Wg @ O])}

def roll_moment_matrix(rp: RollParameters) -> np.ndarray:
    """``Kphi`` [N*m/rad]: the roll moment on every sprung mass per radian of roll of every unit
    (gravity ``m_s g e``, suspensions ``-sum K``, couplings ``-k_c`` between neighbours, the coupling
    loads ``+W (h_c - h_r,k)`` ahead and ``-W (h_c - h_r,k+1)`` behind)."""
    n = rp.m_kg.size
    axle_K = np.zeros(n)
    np.add.at(axle_K, rp.axle_unit, rp.K_Nm_per_rad)
    Kphi = np.diag(rp.ms_kg * G_MPS2 * rp.e_m - axle_K)
    for k in range(n - 1):
        kc = rp.kc_Nm_per_rad[k]
        Kphi[k, k] += -kc + rp.W_N[k] * (rp.hc_m[k] - rp.hr_m[k])
        Kphi[k + 1, k + 1] += -kc - rp.W_N[k] * (rp.hc_m[k] - rp.hr_m[k + 1])
        Kphi[k, k + 1] += kc
        Kphi[k + 1, k] += kc
    return Kphi


def roll_jacobian(vehicle: Vehicle, rp: RollParameters) -> np.ndarray:
    """d v_i / d p_j of the joint constraint, shape (N, N)."""
    n = vehicle.n_units
    Jvp = np.zeros((n, n))
    for k in range(n - 1):
        Jvp[k + 1] = Jvp[k]
        Jvp[k + 1, k] += rp.hc_m[k] - rp.hr_m[k]
        Jvp[k + 1, k + 1] -= rp.hc_m[k] - rp.hr_m[k + 1]
    return Jvp


@lru_cache(maxsize=256)
def yaw_roll_coefficients(vehicle: Vehicle, units: UnitSystem = SI) -> YawRollCoefficients:
    """Build the speed-free coefficients of the yaw-roll model of ``vehicle`` (cached; SI only).

    Raises
    ------
    VehicleError
        Missing or invalid roll data (:func:`~lcvreport.model.yaw_roll.parameters.roll_parameters`).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> co = yaw_roll_coefficients(load_vehicle("examples/vehicles/western_double.toml"))
    >>> co.n_states, co.roll.groups
    (16, ((0, 1), (2, 3)))
    """
    if units is not SI:
        raise ValueError("the yaw-roll model is in SI units only")
    return coefficients_from(vehicle, roll_parameters(vehicle))


def coefficients_from(vehicle: Vehicle, rp: RollParameters) -> YawRollCoefficients:
    """The coefficients of ``vehicle`` with the roll data ``rp`` (what :func:`yaw_roll_coefficients`
    builds from the vehicle's own; a test builds limit cases the file ranges forbid, e = 0)."""
    n = vehicle.n_units
    nq = 2 * n + 1
    ns = 4 * n
    th, ph = nq, nq + n - 1
    rear = np.array([0.0 if u.rear_coupling_m is None else u.rear_coupling_m for u in vehicle.units])
    front = np.array([0.0 if u.front_coupling_m is None else u.front_coupling_m for u in vehicle.units])
    Jv0, Jr0, K = kinematic_jacobians(rear, front)
    Jv = np.zeros((n, nq))
    Jr = np.zeros((n, nq))
    Jp = np.zeros((n, nq))
    Jv[:, :n + 1] = Jv0
    Jv[:, n + 1:] = roll_jacobian(vehicle, rp)
    Jr[:, :n + 1] = Jr0
    Jp[:, n + 1:] = np.eye(n)
    Js = Jv + rp.e_m[:, None] * Jp
    mu, ms = rp.m_kg - rp.ms_kg, rp.ms_kg
    Iz = np.array([u.yaw_inertia_kg_m2 for u in vehicle.units])
    mass_rows = Jv.T @ (mu[:, None] * Jv) + Js.T @ (ms[:, None] * Js)
    momentum = Jv.T * mu + Js.T * ms                       # (nq, N): sum of mass x partial velocity

    a, b, c, d = (np.zeros(n) for _ in range(4))
    for i, ax in zip(vehicle.axle_units, vehicle.axles):
        x = ax.x_m
        CF, CM, CSD2 = (ax.cornering_stiffness_axle_N_per_rad, ax.aligning_stiffness_axle_Nm_per_rad,
                        ax.dual_yaw_damping_axle_N_m2)
        a[i] += -CF
        b[i] += -CF * x
        c[i] += -CF * x + CM
        d[i] += -CF * x * x + CM * x - CSD2

    M0, M1, S0, Sinv, Su, Skin = (np.zeros((ns, ns)) for _ in range(6))
    Ixz = rp.Ixz_kg_m2
    M0[:nq, :nq] = (mass_rows + Jr.T @ (Iz[:, None] * Jr) + Jp.T @ (rp.Ix_kg_m2[:, None] * Jp)
                    - Jr.T @ (Ixz[:, None] * Jp) - Jp.T @ (Ixz[:, None] * Jr))
    M0[nq:, nq:] = np.eye(ns - nq)
    M1[:nq, th:ph] = momentum @ K
    Sinv[:nq, :nq] = (Jv.T @ (a[:, None] * Jv) + Jv.T @ (b[:, None] * Jr)
                      + Jr.T @ (c[:, None] * Jv) + Jr.T @ (d[:, None] * Jr))
    S0[:nq, th:ph] = Jv.T @ (a[:, None] * K) + Jr.T @ (c[:, None] * K)
    Su[:nq, :nq] = -momentum @ Jr
    Kphi = roll_moment_matrix(rp)
    axle_C = np.zeros(n)
    np.add.at(axle_C, rp.axle_unit, rp.C_Nms_per_rad)
    Skin[:nq, ph:] = Jp.T @ Kphi
    Skin[:nq, :nq] = -Jp.T @ (axle_C[:, None] * Jp)
    for k in range(n - 1):
        Skin[th + k, 1 + k] = 1.0
        Skin[th + k, 2 + k] = -1.0
    Skin[ph + np.arange(n), n + 1 + np.arange(n)] = 1.0

    axles = vehicle.axles
    B_P, B_T, B_eps = (np.zeros((ns, len(axles))) for _ in range(3))
    Bdelta = np.zeros(ns)
    for col, (i, ax) in enumerate(zip(vehicle.axle_units, axles)):
        B_P[:nq, col] = Jv[i] + ax.x_m * Jr[i]
        B_T[:nq, col] = Jr[i]
        CF, CM = ax.cornering_stiffness_axle_N_per_rad, ax.aligning_stiffness_axle_Nm_per_rad
        B_eps[:nq, col] = CF * Jv[i] + (CF * ax.x_m - CM) * Jr[i]
        if ax.steered:
            Bdelta[:nq] += B_eps[:nq, col]
    B_crossfall = np.zeros(ns)
    B_crossfall[:nq] = momentum @ np.full(n, G_MPS2)
    arrays = (M0, M1, S0, Sinv, Su, Skin, Bdelta, B_P, B_T, B_eps, B_crossfall, Jv, Jr, Jp, K, Kphi)
    for arr in arrays:
        arr.setflags(write=False)
    return YawRollCoefficients(vehicle, SI, *arrays, rp)
