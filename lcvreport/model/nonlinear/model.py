r"""The nonlinear planar model of a combination (docs/nonlinear.md): every unit a
rigid body in the ground plane at any angle, the couplings holonomic (the rear coupling point of
unit i and the front coupling point of unit i+1 coincide at every angle, exact trigonometry), tires
that saturate, unit 1's forward speed held by its driven axles.

**Coordinates.** The ground frame (X forward along the start heading, Y to its right, z down);
unit i's CG at (X_i, Y_i), heading psi_i (nose-right positive), its axes e_i = (cos psi_i, sin
psi_i), n_i = (-sin psi_i, cos psi_i).  Free coordinates (X_1, Y_1, psi_1 ... psi_N); generalized
speeds (u_1, v_1, r_1 ... r_N): unit 1's CG velocity in its axes and every unit's yaw rate.  The
state is ``x = [X1, Y1, psi1 .. psiN, v1, r1 .. rN]`` (2N + 3); u_1 is the manoeuvre's speed
(held: the drive force that holds it is an output, not a state).

**Kinematics.** With a_rk the rear coupling's x on unit k and a_fk the front coupling's, unit i's
CG velocity is ``V_i = u_1 e_1 + v_1 n_1 + sum_k c_ik r_k n_k``, ``c_ik = a_rk [k < i] - a_fk
[2 <= k <= i]``: linear in the speeds, its partial velocities ``W_i[z]`` the coefficients; its
acceleration ``A_i = sum_z W_i[z] z' + u_1 r_1 n_1 - v_1 r_1 e_1 - sum_k c_ik r_k^2 e_k``.

**Equations** (virtual power, the constraint forces eliminated -- Kane's form; section 2 is its
linearization): for every generalized speed z, ``sum_i W_i[z] . (F_i - m_i A_i) + [z = r_i]
(N_i - I_i r_i') = 0``, F_i the tire, residual and crossfall forces on unit i, N_i their moment
about its CG.  The u_1 equation, with u_1' the manoeuvre's (0), gives the drive force D the
driven axles share equally per tire; D enters the others only through the friction each driven
tire has left (the friction ellipse), so the two are solved together by fixed-point iteration.
An independent derivation -- Newton-Euler per unit with the coupling forces as unknowns -- is in
tests/test_nonlinear.py.

**Axles.** Axle j of unit i at x_j moves at (u_i, v_i + x_j r_i) in its unit's axes (u_i, v_i:
the CG's); a steered axle's wheels are turned by delta (and any axle by its misalignment eps), its
slip angle ``alpha_j = atan2(v_w, |u_w|)`` in the wheel's axes.  Its tires share the static load
F_z0,j (``static_load_N``) and the friction coefficient mu; per tire the law of
:mod:`lcvreport.model.nonlinear.tires`; the dual-tire term ``-C_S D^2 r / u`` (u the axle
centre's forward speed) per tire and the residual force P (along the unit's y) and moment T act
on the axle.  Crossfall: ``m_i a_c`` along ground +Y at every CG.

Examples
--------
>>> from lcvreport import load_vehicle
>>> m = nonlinear_model(load_vehicle("examples/vehicles/b_double.toml"))
>>> m.kind, m.state_names[:4], m.n_states
('nonlinear', ('X1', 'Y1', 'psi1', 'psi2'), 9)
>>> import numpy as np
>>> bool(np.allclose(m.derivatives(0.0, np.zeros(9), m.zero_input(), 25.0)[2:], 0.0))   # straight running
True
"""
from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field, fields

import numpy as np

from ..statics import G_MPS2
from ..vehicle import Vehicle, VehicleError
from . import tires as tire_laws

#: the default friction coefficient mu (a condition, ``friction_coefficient``; the standard's to choose)
FRICTION_COEFFICIENT = 0.8
#: the default tire law
TIRE = "saturating"
#: the drive force's fixed-point iteration: relative tolerance and the most iterations
DRIVE_RTOL = 1e-13
DRIVE_ITERATIONS = 60


class TractionError(RuntimeError):
    """A driven axle asked for more longitudinal force than its friction allows (F_x >= mu F_z):
    the speed cannot be held.  ``axle`` names it, ``row`` the state of a batch that asked; the
    integration adds the time."""

    def __init__(self, axle: str, needed_N: float, available_N: float, row: int = 0):
        self.axle, self.needed_N, self.available_N, self.row = axle, needed_N, available_N, row
        super().__init__(f"driven axle {axle} needs {needed_N:.6g} N of longitudinal force per tire, beyond the "
                         f"{available_N:.6g} N its friction allows: the speed cannot be held")


def driven_axles(vehicle: Vehicle) -> list[bool]:
    """Whether each axle (:attr:`Vehicle.axles` order) is driven: the file's ``driven`` where it
    gives it, else every non-steered axle of unit 1."""
    out = []
    for i, a in zip(vehicle.axle_units, vehicle.axles):
        given = getattr(a, "driven", None)
        out.append(bool(given) if given is not None else (i == 0 and not a.steered))
    return out


@dataclass(frozen=True)
class Parameters:
    """The parameters of the model that a variant of one geometry may change, one row per
    variant (V, k): the units' masses ``m`` [kg] and yaw inertias ``I`` [kg m^2] (V, N); per axle
    (V, n_axles) each tire's ``CF`` [N/rad] and ``CM`` [N m/rad], the dual-tire term's
    ``tires_CSD2`` (tires C_S D^2) [N m^2], each tire's static load ``Fz_tire`` [N], its friction
    capacity ``mu_Fz`` [N] and the axle's static load ``Fz0`` [N].  The equations read them per
    state (:meth:`take`: one row per state), so that states of different variants are evaluated
    in one call (:class:`StackedNonlinearModel`)."""

    m: np.ndarray
    I: np.ndarray
    CF: np.ndarray
    CM: np.ndarray
    tires_CSD2: np.ndarray
    Fz_tire: np.ndarray
    mu_Fz: np.ndarray
    Fz0: np.ndarray

    def take(self, rows) -> "Parameters":
        """The parameters of the variants ``rows`` (an index per state)."""
        return Parameters(*(getattr(self, f.name)[rows] for f in fields(self)))

    @staticmethod
    def concatenate(items) -> "Parameters":
        """One row per variant of ``items`` (each of one or more rows)."""
        return Parameters(*(np.concatenate([getattr(p, f.name) for p in items]) for f in fields(Parameters)))


@dataclass(frozen=True, eq=False)
class NonlinearModel:
    """The nonlinear planar model of ``vehicle`` (see the module docstring): ``tire`` (``linear``
    or ``saturating``) and the friction coefficient ``mu``.  Meets
    :class:`lcvreport.model.base.VehicleModel`."""

    vehicle: Vehicle
    tire: str = TIRE
    mu: float = FRICTION_COEFFICIENT
    kind: str = field(default="nonlinear", init=False)
    name: str = field(default="nonlinear", init=False)

    def __post_init__(self):
        v = self.vehicle
        tire_laws.law(self.tire)
        if not (isinstance(self.mu, (int, float)) and not isinstance(self.mu, bool) and 0.0 < self.mu <= 2.0):
            raise ValueError(f"friction_coefficient must be in (0, 2], got {self.mu!r}")
        missing = [(i, a) for i, a in zip(v.axle_units, v.axles) if a.static_load_N is None or a.static_load_N <= 0]
        if missing:
            i, a = missing[0]
            raise VehicleError("static_load_N", "the nonlinear model needs every axle's static_load_N > 0 (its tires "
                               f"share it), got {a.static_load_N!r}", f'units[{i}] "{v.units[i].name}" axles['
                               f'{v.units[i].axles.index(a)}] "{a.name}"')
        N = v.n_units
        set_ = lambda k, val: object.__setattr__(self, k, val)  # noqa: E731 (frozen)
        set_("_N", N)
        c = np.zeros((N, N))
        for i in range(N):
            for k in range(N):
                if k < i:
                    c[i, k] += v.units[k].rear_coupling_m
                if 1 <= k <= i:
                    c[i, k] -= v.units[k].front_coupling_m
        set_("_c", c)
        axles = v.axles
        set_("_au", np.asarray(v.axle_units, dtype=int))
        set_("_x", np.array([a.x_m for a in axles]))
        set_("_tires", np.array([a.tires for a in axles], dtype=float))
        set_("_steered", np.array([a.steered for a in axles], dtype=float))
        driven = np.array(driven_axles(v))
        if not driven.any():
            raise VehicleError("driven", "no axle is driven: unit 1 needs a driven axle (default: its non-steered "
                                         "ones) to hold its speed", f'units[0] "{v.units[0].name}"')
        set_("_driven", driven.astype(float))
        set_("_drive_tires", float((self._tires * self._driven).sum()))
        set_("_law", tire_laws.law(self.tire))
        set_("_linear_tires", self.tire == "linear")
        set_("_Yhat", np.array([0.0, 1.0]))
        S = np.zeros((N, len(axles)))
        S[self._au, np.arange(len(axles))] = 1.0
        set_("_sum_by_unit", S)
        set_("_drive_share", self._driven * self._tires / self._drive_tires)
        Fz0 = np.array([a.static_load_N for a in axles])
        Fz_tire = Fz0 / self._tires
        row = lambda a: np.asarray(a, dtype=float)[None, :]           # noqa: E731 (one variant: one row)
        set_("_p", Parameters(m=row([u.mass_kg for u in v.units]), I=row([u.yaw_inertia_kg_m2 for u in v.units]),
                              CF=row([a.cornering_stiffness_N_per_rad for a in axles]),
                              CM=row([a.aligning_stiffness_Nm_per_rad for a in axles]),
                              tires_CSD2=row(self._tires * [a.longitudinal_stiffness_N * a.dual_spacing_m ** 2
                                                            for a in axles]),
                              Fz_tire=row(Fz_tire), mu_Fz=row(self.mu * Fz_tire), Fz0=row(Fz0)))

    def geometry_key(self) -> tuple:
        """What of the model a variant must share with another to be integrated beside it
        (:class:`StackedNonlinearModel`): everything but :class:`Parameters`."""
        v = self.vehicle
        return (self.tire, self.mu, self._c.tobytes(), self._au.tobytes(), self._x.tobytes(), self._tires.tobytes(),
                self._steered.tobytes(), self._driven.tobytes(), tuple(v.axle_names), v.n_units)

    # ------------------------------------------------------------------ names
    @property
    def n_states(self) -> int:
        return 2 * self._N + 3

    @property
    def state_names(self) -> tuple[str, ...]:
        N = self._N
        return ("X1", "Y1", *(f"psi{i + 1}" for i in range(N)), "v1", *(f"r{i + 1}" for i in range(N)))

    @property
    def state_units(self) -> tuple[str, ...]:
        N = self._N
        return ("m", "m", *(["rad"] * N), "m/s", *(["rad/s"] * N))

    @property
    def input_names(self) -> tuple[str, ...]:
        """``delta`` [rad], every axle's ``P_<axle>`` [N], ``T_<axle>`` [N m], ``eps_<axle>`` [rad]
        and ``a_crossfall`` [m/s^2] (g sin(atan(c/100)))."""
        names = self.vehicle.axle_names
        return ("delta", *(f"P_{a}" for a in names), *(f"T_{a}" for a in names), *(f"eps_{a}" for a in names),
                "a_crossfall")

    def zero_input(self) -> np.ndarray:
        return np.zeros(len(self.input_names))

    def split_input(self, w):
        """(delta, P, T, eps, a_c) of inputs ``w`` (:attr:`input_names`; a leading batch axis kept)."""
        na = len(self.vehicle.axles)
        w = np.asarray(w)
        return (w[..., 0], w[..., 1:1 + na], w[..., 1 + na:1 + 2 * na], w[..., 1 + 2 * na:1 + 3 * na],
                w[..., 1 + 3 * na])

    # ------------------------------------------------------------------ the equations
    # Every array below carries a leading batch axis b (one state per row): a call for one state is
    # a batch of one, and the integrator's Jacobian and the outputs of a whole run are one call.
    def _kinematics(self, x, U):
        N = self._N
        psi = x[:, 2:2 + N]
        v1, r = x[:, 2 + N], x[:, 3 + N:3 + 2 * N]
        cos, sin = np.cos(psi), np.sin(psi)
        e = np.stack([cos, sin], axis=2)                                 # (b, N, 2)
        n = np.stack([-sin, cos], axis=2)
        V = (U * e[:, 0] + v1[:, None] * n[:, 0])[:, None, :] + np.einsum("ik,bk,bkc->bic", self._c, r, n)
        u_b = (V * e).sum(axis=2)
        v_b = (V * n).sum(axis=2)
        return psi, v1, r, e, n, V, u_b, v_b

    def _slips(self, kin, w, s, p):
        """What of the axles' forces does not depend on the drive force: per axle (b, n_axles) the
        slip angle's tangent, the wheels' angle d and its cosine and sine, the forward speed and
        yaw rate of the axle's unit, the steer-independent moments (dual tires, residual T) and
        the residual lateral force P, from the kinematics ``kin`` (:meth:`_kinematics`) and the
        parameters ``p`` (:class:`Parameters`, one row per state)."""
        psi, v1, r, e, n, V, u_b, v_b = kin
        delta, P, T, eps, a_c = self.split_input(w)
        au, xs = self._au, self._x
        ua = u_b[:, au]
        ra = r[:, au]
        va = v_b[:, au] + xs * ra
        d = delta[:, None] * self._steered + eps
        cd, sd = np.cos(d), np.sin(d)
        uw = ua * cd + va * sd
        vw = -ua * sd + va * cd
        tan_a = vw / np.where(uw.real > 0, uw, -uw) if np.iscomplexobj(vw) else vw / np.abs(uw)
        Mz0 = T - s * p.tires_CSD2 * ra / ua
        if self._linear_tires:
            lin = (-s * p.CF * tan_a, s * p.CM * tan_a)
        else:
            lin = None
        return tan_a, d, cd, sd, Mz0, P, lin

    def _axle_forces(self, slips, s, D, p):
        """Per axle (b, n_axles): wheel-frame F_x, F_y [N], body-frame F_x, F_y, the moment about
        the unit's CG of the axle's forces and moments [N m], the wheels' angle; at drive force
        ``D`` (b,) [N], from the axles' slips (:meth:`_slips`)."""
        tan_a, d, cd, sd, Mz0, P, lin = slips
        fx_tire = self._driven * (D[:, None] / self._drive_tires)         # per tire, driven axles share D
        if lin is not None:
            fy, mz = lin
        else:
            ratio = fx_tire / p.mu_Fz
            if np.abs(ratio).max() >= 1.0:
                b, j = (int(k) for k in np.argwhere(np.abs(ratio) >= 1.0)[0])
                raise TractionError(self.vehicle.axles[j].name, abs(fx_tire[b, j]), p.mu_Fz[b, j], b)
            mu_y = self.mu * np.sqrt(1.0 - ratio * ratio)
            fy, mz = tire_laws.saturating(tan_a, s * p.CF, s * p.CM, p.Fz_tire, mu_y)
        Fx_w, Fy_w = self._tires * fx_tire, self._tires * fy
        Mz = self._tires * mz + Mz0
        Fx_b = Fx_w * cd - Fy_w * sd
        Fy_b = Fx_w * sd + Fy_w * cd + P
        return Fx_w, Fy_w, Fx_b, Fy_b, self._x * Fy_b + Mz, d

    def _partials(self, kin, U, dtype):
        """(W, bias): the CGs' partial velocities ``W[b, i, z, :]``, z = (u1, v1, r1..rN), and the
        part of their accelerations not proportional to the generalized accelerations (b, N, 2)."""
        psi, v1, r, e, n, V, u_b, v_b = kin
        B, N, c = psi.shape[0], self._N, self._c
        W = np.empty((B, N, N + 2, 2), dtype=dtype)
        W[:, :, 0] = e[:, None, 0]
        W[:, :, 1] = n[:, None, 0]
        W[:, :, 2:] = c[None, :, :, None] * n[:, None, :, :]
        bias = ((U * r[:, 0])[:, None] * n[:, 0] - (v1 * r[:, 0])[:, None] * e[:, 0])[:, None, :] \
            - np.einsum("ik,bk,bkc->bic", c, r * r, e)                              # (b, N, 2)
        return W, bias

    def _solve_outputs(self, x, w, U, s):
        """What :meth:`outputs` reads of :meth:`_solve`, by the compiled equations where the
        machine has them (the accelerations and the axles' wheel-frame forces; the kinematics by
        numpy, no iteration in them)."""
        eq = _compiled(self) if x.dtype == np.float64 and w.dtype.kind in "fiu" else None
        if eq is None:
            return self._solve(x, w, U, s)
        B = x.shape[0]
        p = self._p.take(np.zeros(B, dtype=int))
        dx, D, got = eq.derivatives(x, w, U, s, p, forces=True)
        if dx is None:
            row, j, needed, available = got
            raise TractionError(self.vehicle.axles[j].name, needed, available, row)
        kin = self._kinematics(x, U)
        W, bias = self._partials(kin, U, np.float64)
        delta, _P, _T, eps, _a_c = self.split_input(w)
        d = delta[:, None] * self._steered + eps
        return dx[:, 2 + self._N:], D, (got[0], got[1], None, None, None, d), kin + (W, bias), p

    def _solve(self, x, w, U, s, p=None):
        """(z_rest', D, axle forces, kinematics) of a batch of states ``x`` (b, n) and inputs ``w``
        (b, n_w): the generalized accelerations (v1', r') and the drive force D that holds u_1 (the
        u_1 equation, solved with the others: D changes the friction the driven tires have left,
        so the two are iterated to a fixed point from D = 0 -- the same start every call, the
        same numbers every call); ``p`` the parameters of each state's variant (:class:`Parameters`,
        one row per state; default this model's)."""
        N = self._N
        kin = self._kinematics(x, U)
        psi, v1, r, e, n, V, u_b, v_b = kin
        a_c = self.split_input(w)[4]
        B = x.shape[0]
        if p is None:
            p = self._p.take(np.zeros(B, dtype=int))
        m = p.m
        dtype = np.result_type(x, w, float)
        W, bias = self._partials(kin, U, dtype)
        Mfull = np.einsum("bi,bizc,biyc->bzy", m, W, W)
        Mfull[:, np.arange(2, N + 2), np.arange(2, N + 2)] += p.I
        Mr = Mfull[:, 1:, 1:]
        au = self._au
        e_au, n_au = e[:, au], n[:, au]
        ext = (m * a_c[:, None])[:, :, None] * self._Yhat - m[:, :, None] * bias
        inertial = np.einsum("bizc,bic->bz", W, ext)
        slips = self._slips(kin, w, s, p)
        Mr_inv = np.linalg.inv(Mr)                      # once for every pass of the drive force
        na = self._x.size
        D = np.zeros(B, dtype=dtype)
        zr = np.empty((B, N + 1), dtype=dtype)
        forces = [np.empty((B, na), dtype=dtype) for _ in range(6)]
        # each state iterates until its own drive force has converged (a state's numbers do not
        # depend on the others of its batch)
        rows = np.arange(B)
        for _ in range(DRIVE_ITERATIONS):
            every = rows.size == B
            pick = (lambda a: a) if every else (lambda a: a[rows])            # noqa: E731
            sl = tuple(None if a is None else (tuple(pick(b) for b in a) if isinstance(a, tuple) else pick(a))
                       for a in slips)
            try:
                Fx_w, Fy_w, Fx_b, Fy_b, moment, d = self._axle_forces(sl, s, D[rows], p if every else p.take(rows))
            except TractionError as exc:                # the row of the batch, not of the pass
                exc.row = int(rows[exc.row])
                raise
            Fa = Fx_b[:, :, None] * pick(e_au) + Fy_b[:, :, None] * pick(n_au)       # per axle, ground
            F = np.einsum("ij,bjc->bic", self._sum_by_unit, Fa)
            rhs = pick(inertial) + np.einsum("bizc,bic->bz", pick(W), F)
            rhs[:, 2:] += np.einsum("bj,ij->bi", moment, self._sum_by_unit)     # not BLAS: row by row
            z = np.einsum("bij,bj->bi", pick(Mr_inv), rhs[:, 1:])
            # the u1 equation: the drive force's generalized force along u1 is D times its
            # direction's projection on e1 (1 for unsteered driven axles); solved for D
            g = (self._drive_share * np.cos(d)).sum(axis=1)
            D_new = D[rows] + (np.einsum("bz,bz->b", pick(Mfull)[:, 0, 1:], z) - rhs[:, 0]) / g
            # with linear tires and the driven axles straight (no steer, no misalignment) the drive
            # force acts in the u1 equation alone: one pass gives it exactly
            decoupled = self._linear_tires & ~np.any(d * self._driven, axis=1)
            done = decoupled | (np.abs(D_new - D[rows]) <= DRIVE_RTOL * np.maximum(1.0, np.abs(D_new)))
            zr[rows], D[rows] = z, D_new
            for out, val in zip(forces, (Fx_w, Fy_w, Fx_b, Fy_b, moment, d)):
                out[rows] = val
            rows = rows[~done]
            if rows.size == 0:
                break
        Fx_w, Fy_w, Fx_b, Fy_b, moment, d = forces
        return zr, D, (Fx_w, Fy_w, Fx_b, Fy_b, moment, d), kin + (W, bias), p

    def _batch(self, x, w):
        """``x``, ``w`` as 2-D batches (rows: states), and whether one state was given."""
        x, w = np.asarray(x), np.asarray(w)
        one = x.ndim == 1
        x2 = np.atleast_2d(x)
        w2 = w if w.ndim == 2 and w.shape[0] == x2.shape[0] else np.broadcast_to(np.atleast_2d(w), (x2.shape[0], w.shape[-1]))
        return x2, w2, one

    def derivatives(self, t: float, x: np.ndarray, w: np.ndarray, speed_mps: float,
                    tire_scale: float = 1.0, params: Parameters | None = None) -> np.ndarray:
        """``x'`` [SI] at state ``x``, inputs ``w`` (:attr:`input_names`), unit 1's forward speed
        ``speed_mps`` [m/s] held, the tire coefficients times ``tire_scale``; ``x`` may be a batch
        (rows: states), ``w`` one input for all of them or one per row; ``params`` each row's
        variant's :class:`Parameters` (one row per state; default this model's: variants of one
        geometry evaluated in one call, :func:`lcvreport.measures.friction_demand.turns_with_tire_forces`).

        Raises
        ------
        TractionError
            A driven axle out of friction: the speed cannot be held.
        """
        x2, w2, one = self._batch(x, w)
        if x2.dtype == np.float64 and w2.dtype.kind in "fiu" and _compiled(self) is not None:
            p = params if params is not None else self._p.take(np.zeros(x2.shape[0], dtype=int))
            dx = self.derivatives_rows(x2, w2, speed_mps, tire_scale, p)
            return dx[0] if one else dx
        return self.derivatives_numpy(t, x, w, speed_mps, tire_scale, params)

    def derivatives_rows(self, x: np.ndarray, w: np.ndarray, speed_mps: float, tire_scale: float,
                         params: Parameters) -> np.ndarray:
        """:meth:`derivatives` of real states ``x`` (B, n) with inputs ``w`` (B, n_w) and each
        row's ``params`` (one row per state), without the conversions: a batch integrator's call
        (compiled where the machine has the library, numpy otherwise).  ``speed_mps`` [m/s].

        Raises
        ------
        TractionError

        Examples
        --------
        >>> from lcvreport.model.presets import load_preset
        >>> m = nonlinear_model(load_preset("tractor_semitrailer"))
        >>> x = np.zeros((2, m.n_states))
        >>> w = np.tile(m.zero_input(), (2, 1))
        >>> w[1, 0] = 0.01                                  # the second state steered 0.01 rad
        >>> dx = m.derivatives_rows(x, w, 20.0, 1.0, m._p.take(np.zeros(2, dtype=int)))
        >>> bool(np.all(dx == m.derivatives(0.0, x, w, 20.0))), bool(dx[1, m.n_states - 2] != 0.0)
        (True, True)
        """
        eq = _compiled(self)
        if eq is None or x.dtype != np.float64:
            return self.derivatives_numpy(0.0, x, w, speed_mps, tire_scale, params)
        dx, _D, failed = eq.derivatives(x, w, float(speed_mps), tire_scale, params)
        if dx is None:
            row, j, needed, available = failed
            raise TractionError(self.vehicle.axles[j].name, needed, available, row)
        return dx

    def derivatives_numpy(self, t: float, x: np.ndarray, w: np.ndarray, speed_mps: float,
                          tire_scale: float = 1.0, params: Parameters | None = None) -> np.ndarray:
        """:meth:`derivatives` by the numpy equations (:meth:`_solve`), whatever the machine has: the
        reference the compiled equations are tested against, and the equations of complex states
        (:meth:`jacobian`'s complex steps)."""
        N = self._N
        x2, w2, one = self._batch(x, w)
        zr, D, _forces, (psi, v1, r, e, n, V, *_rest), _p = self._solve(x2, w2, float(speed_mps), tire_scale, params)
        dx = np.empty((x2.shape[0], 2 * N + 3), dtype=zr.dtype)
        dx[:, 0:2] = V[:, 0]
        dx[:, 2:2 + N] = r
        dx[:, 2 + N:] = zr
        return dx[0] if one else dx

    def outputs(self, t, x: np.ndarray, w: np.ndarray, speed_mps: float, tire_scale: float = 1.0) -> dict:
        """Every signal of ``lcv simulate --model nonlinear`` [SI] (docs/nonlinear.md#outputs):
        ``X<i>``, ``Y<i>`` (CGs), ``psi<i>``, ``u1``, ``v<i>`` (each CG's lateral velocity in its
        unit's axes), ``r<i>``, ``delta``, ``theta<J>`` (joint J = A, B, ..., as the linear models'), ``ay<i>`` (each CG's lateral acceleration
        in its unit's axes), ``a_steer`` (the frontmost steered axle's), ``Fx_<axle>``, ``Fy_<axle>``
        (in the wheel's axes), ``fd_<axle>`` (friction demand), ``Y_<axle>`` (axle centres) and
        ``Y_rear`` (the last unit's rear end, as the linear models'); floats for one state, arrays
        for a batch (rows of ``x``)."""
        x2, w2, one = self._batch(np.asarray(x, dtype=float), np.asarray(w, dtype=float))
        N, U = self._N, float(speed_mps)
        zr, D, (Fx_w, Fy_w, *_f, d), (psi, v1, r, e, n, V, u_b, v_b, W, bias), p = self._solve_outputs(x2, w2, U,
                                                                                                      tire_scale)
        z = np.concatenate([np.zeros((x2.shape[0], 1)), zr], axis=1)     # (u1' = 0, v1', r')
        A = np.einsum("bizc,bz->bic", W, z) + bias                       # CG accelerations (ground)
        P = np.zeros((x2.shape[0], N, 2))
        P[:, 0] = x2[:, :2]
        v = self.vehicle
        for i in range(1, N):
            P[:, i] = P[:, i - 1] + v.units[i - 1].rear_coupling_m * e[:, i - 1] - v.units[i].front_coupling_m * e[:, i]
        out = {}
        for i in range(N):
            out[f"X{i + 1}"], out[f"Y{i + 1}"], out[f"psi{i + 1}"] = P[:, i, 0], P[:, i, 1], psi[:, i]
        out["u1"] = np.full(x2.shape[0], U)
        for i in range(N):
            out[f"v{i + 1}"], out[f"r{i + 1}"] = v_b[:, i], r[:, i]
        out["delta"] = self.split_input(w2)[0].copy()
        for k in range(N - 1):
            out[f"theta{self.vehicle.joint_letters[k]}"] = psi[:, k] - psi[:, k + 1]
        ay = (A * n).sum(axis=2)
        for i in range(N):
            out[f"ay{i + 1}"] = ay[:, i]
        if v.steered_axles:
            xs = max(a.x_m for a in v.steered_axles)
            point = A[:, 0] + xs * (zr[:, 1, None] * n[:, 0] - (r[:, 0] ** 2)[:, None] * e[:, 0])
            out["a_steer"] = (point * n[:, 0]).sum(axis=1)
        fd = np.hypot(Fx_w, Fy_w) / (self.mu * p.Fz0)
        for j, a in enumerate(v.axles):
            out[f"Fx_{a.name}"], out[f"Fy_{a.name}"], out[f"fd_{a.name}"] = Fx_w[:, j], Fy_w[:, j], fd[:, j]
        for j, a in enumerate(v.axles):
            i = self._au[j]
            out[f"Y_{a.name}"] = P[:, i, 1] + a.x_m * e[:, i, 1]
        last = N - 1
        out["Y_rear"] = P[:, last, 1] + v.rear_end_x_m(last) * e[:, last, 1]      # the last unit's rear end
        if one:
            return {k: float(val[0]) for k, val in out.items()}
        return out

    def drive_force(self, x, w, speed_mps: float, tire_scale: float = 1.0) -> float:
        """The drive force D [N] the driven axles share to hold the speed (one state)."""
        x2, w2, _one = self._batch(np.asarray(x, dtype=float), np.asarray(w, dtype=float))
        return float(self._solve(x2, w2, float(speed_mps), tire_scale)[1][0])

    # ------------------------------------------------------------------ the linear model
    def linearize(self, speed_mps: float, tire_scale: float = 1.0):
        """Section 2's model of the vehicle (the yaw plane): this model's linearization at straight
        running with linear tires (tests/test_nonlinear.py holds the Jacobian to it, 1e-9)."""
        from ..linear import linear_model
        return linear_model(self.vehicle, "yaw_plane")

    def jacobian(self, x, w, speed_mps: float, tire_scale: float = 1.0, h: float = 1e-30):
        """(d x'/d x, d x'/d w) at (x, w) by complex steps (exact to rounding; the ``linear`` tire
        law only: the brush tire is not complex-analytic)."""
        x = np.asarray(x, dtype=float)
        w = np.asarray(w, dtype=float)
        nx, nw = x.size, w.size
        J = np.empty((nx, nx))
        for k in range(nx):
            xc = x.astype(complex)
            xc[k] += 1j * h
            J[:, k] = self.derivatives(0.0, xc, w.astype(complex), speed_mps, tire_scale).imag / h
        B = np.empty((nx, nw))
        for k in range(nw):
            wc = w.astype(complex)
            wc[k] += 1j * h
            B[:, k] = self.derivatives(0.0, x.astype(complex), wc, speed_mps, tire_scale).imag / h
        return J, B


_COMPILED: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _compiled(model: NonlinearModel):
    """The compiled equations of ``model`` (:mod:`lcvreport.model.nonlinear.native`), made once per
    model; None where they are not available (the numpy equations then)."""
    try:
        return _COMPILED[model]
    except KeyError:
        from . import native
        eq = _COMPILED[model] = native.compiled(model, DRIVE_ITERATIONS, DRIVE_RTOL)
        return eq


def nonlinear_model(vehicle: Vehicle, tire: str = TIRE, friction_coefficient: float = FRICTION_COEFFICIENT
                    ) -> NonlinearModel:
    """The nonlinear planar model of ``vehicle`` (:class:`NonlinearModel`).

    Parameters
    ----------
    vehicle : Vehicle
        With every axle's ``static_load_N``.
    tire : {"saturating", "linear"}
    friction_coefficient : float
        mu, in (0, 2] (default 0.8).

    Returns
    -------
    NonlinearModel

    Raises
    ------
    VehicleError
        An axle without ``static_load_N``; no driven axle.
    ValueError
        An unknown tire law, mu out of range.

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> m = nonlinear_model(load_vehicle("examples/vehicles/b_double.toml"), "saturating", 0.6)
    >>> m.mu, m.n_states
    (0.6, 9)
    """
    return NonlinearModel(vehicle, tire, float(friction_coefficient) if isinstance(friction_coefficient, (int, float))
                          and not isinstance(friction_coefficient, bool) else friction_coefficient)


__all__ = ["NonlinearModel", "TractionError", "nonlinear_model", "driven_axles", "FRICTION_COEFFICIENT", "G_MPS2",
           "math"]
