"""Variants of one vehicle in a batch: masses, yaw inertias and tire coefficients as arrays,
and what the model gives over the leading axis -- its matrices, eigenvalues, frequency
responses, steady states, the trim, and the exact responses to steer inputs piece by piece
with their extrema between samples (those of :mod:`lcvreport.analysis.exact`, computed
:data:`RESPONSE_GROUP` variants at a time).  The measures over a batch are the families'
batched functions (:mod:`lcvreport.measures`, :func:`lcvreport.measures.measure_set.batch_measures`).

Every coefficient of the model (M0, M1, S0, Sinv, Su, Skin, B_delta) is affine in each unit's
mass and yaw inertia and in each axle's per-tire C_F, C_M and C_S (positions held): the batch
is the nominal coefficients plus, for every varied parameter, its change times the
coefficients' derivative, which is exact (a difference of two builds at the nominal and at
twice the nominal value).  No Python loop runs per variant; one runs per varied parameter.

Parameter names: ``<unit>.mass_kg``, ``<unit>.yaw_inertia_kg_m2``,
``<axle>.cornering_stiffness_N_per_rad``, ``<axle>.aligning_stiffness_Nm_per_rad``,
``<axle>.longitudinal_stiffness_N`` (unit and axle names of the vehicle).

Examples
--------
>>> import numpy as np
>>> from lcvreport import load_preset
>>> v = load_preset("aucnat")
>>> b = VariantBatch(v, {"trailer3.mass_kg": v.units[5].mass_kg * np.array([0.8, 1.0, 1.2])})
>>> b.eigenvalues(24.0).shape
(3, 12)
>>> b.rearward_amplification(24.0, 0.4).shape
(3,)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..model.linear import linear_model, stiffness
from ..model.vehicle import Vehicle
from ..util.numerics import rowwise, solve_scaled

#: the coefficients the batch varies, and the parameters it can vary
COEFFICIENTS = ("M0", "M1", "S0", "Sinv", "Su", "Skin", "Bdelta")
#: the coefficients of the stiffness S(u, s) (:func:`lcvreport.model.linear.stiffness`)
STIFFNESS = ("S0", "Sinv", "Su", "Skin")
UNIT_PARAMETERS = ("mass_kg", "yaw_inertia_kg_m2")
AXLE_PARAMETERS = ("cornering_stiffness_N_per_rad", "aligning_stiffness_Nm_per_rad", "longitudinal_stiffness_N")


#: variants whose time responses are computed together: 16, measured against 8, 12, 24 and 32 on
#: aucnat at 88 km/h (the lane change and the single sine 15-20 % faster than at 8, the yaw damping
#: pulse's 8000 samples about even).  A variant's values do not depend on the group it is computed
#: in (tests/test_batch.py: bit for bit in groups of 16, 5 and 1).
RESPONSE_GROUP = 16

#: eigenvector condition number above which the RA scan of a variant uses exact solves
SCAN_COND_MAX = 1e8


class BatchError(ValueError):
    """An unknown parameter, arrays of different lengths, a value that is not positive and finite."""


def _with(vehicle: Vehicle, name: str, value: float) -> Vehicle:
    owner, _, key = name.partition(".")
    units = list(vehicle.units)
    for i, u in enumerate(units):
        if key in UNIT_PARAMETERS and u.name == owner:
            units[i] = replace(u, **{key: value})
            return replace(vehicle, units=tuple(units))
        if key in AXLE_PARAMETERS:
            for j, a in enumerate(u.axles):
                if a.name == owner:
                    axles = list(u.axles)
                    axles[j] = replace(a, **{key: value})
                    units[i] = replace(u, axles=tuple(axles))
                    return replace(vehicle, units=tuple(units))
    valid = [f"{u.name}.{k}" for u in vehicle.units for k in UNIT_PARAMETERS] + \
        [f"{a.name}.{k}" for a in vehicle.axles for k in AXLE_PARAMETERS]
    raise BatchError(f"unknown parameter {name!r}; valid: {', '.join(valid)}")


def _steered_axle_rows(A_x: np.ndarray, b_x: np.ndarray, x_s: float, u: float) -> tuple[np.ndarray, np.ndarray]:
    """The steered axle's lateral acceleration ``a_s = Cs x + Ds delta`` of every variant (``v_s = v1 +
    x_s r1``, ``a_s = v_s' + u r1``): ``Cs`` (B, n), ``Ds`` (B,) from ``x' = A_x x + b_x delta``.

    Written as the two terms, not as a product with ``[1, x_s, 0, ...]``: BLAS computes ``b_x @ J``
    by a dot product for one variant and by a matrix-vector product for several, and on a machine
    with AVX-512 the latter fuses ``b1 + x_s b2`` into one rounding (FMA) -- a variant's steer
    would then depend on how many variants share its group (tests/test_batch.py)."""
    Cs = A_x[:, 0, :] + x_s * A_x[:, 1, :]
    Cs[:, 1] += u
    return Cs, b_x[:, 0] + x_s * b_x[:, 1]


def _nominal(vehicle: Vehicle, name: str) -> float:
    owner, _, key = name.partition(".")
    for u in vehicle.units:
        if key in UNIT_PARAMETERS and u.name == owner:
            return float(getattr(u, key))
        for a in u.axles:
            if key in AXLE_PARAMETERS and a.name == owner:
                return float(getattr(a, key))
    _with(vehicle, name, 0.0)                     # raises with the valid names
    raise AssertionError  # pragma: no cover




@dataclass
class VariantBatch:
    """``B`` variants of ``vehicle``: ``values`` maps parameter names to arrays of shape (B,) (SI);
    ``model`` is the linear model they are computed on (:data:`lcvreport.model.linear.MODELS`)."""

    vehicle: Vehicle
    values: dict
    model: str = "yaw_plane"
    coefficients: dict = field(init=False, repr=False)
    #: the variants as vehicles when the batch was built of them (:meth:`of_vehicles`)
    variants: tuple | None = field(default=None, init=False, repr=False)

    def __post_init__(self):
        lengths = {np.shape(v) for v in self.values.values()}
        if len(lengths) > 1 or any(len(s) != 1 for s in lengths):
            raise BatchError(f"every parameter needs an array of one length, got shapes {sorted(lengths)}")
        base = linear_model(self.vehicle, self.model)
        B = next(iter(lengths))[0] if lengths else 1
        coeffs = {k: np.broadcast_to(getattr(base, k), (B,) + getattr(base, k).shape).copy() for k in COEFFICIENTS}
        for name, arr in self.values.items():
            arr = np.asarray(arr, dtype=float)
            if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
                raise BatchError(f"{name}: every value must be finite and > 0")
            p0 = _nominal(self.vehicle, name)
            step = p0 if p0 > 0 else 1.0
            bumped = linear_model(_with(self.vehicle, name, p0 + step), self.model)
            for k in COEFFICIENTS:
                d = (getattr(bumped, k) - getattr(base, k)) / step
                coeffs[k] += (arr - p0).reshape((B,) + (1,) * d.ndim) * d
        self.coefficients = coeffs

    @classmethod
    def of_vehicles(cls, vehicle: Vehicle, variants, model: str = "yaw_plane", values: dict | None = None
                    ) -> "VariantBatch":
        """The variants given as vehicles, each one's coefficients built exactly (any parameter, also
        one the model is not affine in: a CG height enters the yaw-roll model squared).  They must
        share ``vehicle``'s geometry -- every map from the state to velocities, yaw rates and
        positions, which the batch takes from ``vehicle`` -- else :class:`BatchError`.  ``values``:
        the varied parameters, for the tables (optional)."""
        variants = tuple(variants)
        if not variants:
            raise BatchError("a batch needs at least one variant")
        base = linear_model(vehicle, model)
        models = [linear_model(v, model) for v in variants]
        maps = lambda m: (m.velocity_map(1.0), m.yaw_rate_map(), m.heading_rows(),  # noqa: E731
                          m.roll_offset_rows() if m.roll_offset_rows() is not None else np.zeros(0))
        ref = maps(base)
        for k, m in enumerate(models):
            if any(a.shape != b.shape or not np.array_equal(a, b) for a, b in zip(maps(m), ref)):
                raise BatchError(f"variant {k} does not share the geometry of {vehicle.name} (the batch's maps "
                                 "from the state to velocities and positions are the nominal vehicle's)")
        batch = object.__new__(cls)
        batch.vehicle, batch.model, batch.variants = vehicle, model, variants
        batch.values = {} if values is None else {k: np.asarray(a) for k, a in values.items()}
        batch.coefficients = {k: np.stack([getattr(m, k) for m in models]) for k in COEFFICIENTS}
        return batch

    def vehicles(self) -> tuple:
        """The variants as vehicles (the nominal vehicle with each variant's values)."""
        if self.variants is not None:
            return self.variants
        out = []
        for b in range(self.size):
            v = self.vehicle
            for name, arr in self.values.items():
                v = _with(v, name, float(np.asarray(arr)[b]))
            out.append(v)
        return tuple(out)

    def on_model(self, model: str) -> "VariantBatch":
        """The same variants on another linear model (their coefficients built exactly)."""
        if model == self.model:
            return self
        return VariantBatch.of_vehicles(self.vehicle, self.vehicles(), model, self.values)

    @property
    def size(self) -> int:
        return self.coefficients["M0"].shape[0]

    def subset(self, rows) -> "VariantBatch":
        """The variants ``rows`` as a batch of their own (sharing the coefficients' rows)."""
        sub = object.__new__(VariantBatch)
        sub.vehicle = self.vehicle
        sub.model = self.model
        sub.values = {k: np.asarray(a)[rows] for k, a in self.values.items()}
        sub.coefficients = {k: a[rows] for k, a in self.coefficients.items()}
        sub.variants = None if self.variants is None else tuple(np.asarray(self.variants, dtype=object)[rows])
        return sub

    def in_groups(self, fn, *args, group: int = 256):
        """``fn(batch, *args)`` run on groups of ``group`` variants, the results joined: a variant's
        result does not depend on its group (each one's scan and search stop on their own), and
        groups keep the work arrays in cache (at 2000 variants the critical speed took 1.5x longer
        per variant in one piece)."""
        if self.size <= group:
            return fn(self, *args)
        parts = [fn(self.subset(slice(i, i + group)), *args) for i in range(0, self.size, group)]
        if isinstance(parts[0], tuple):
            return tuple(np.concatenate([p[k] for p in parts]) for k in range(len(parts[0])))
        return np.concatenate(parts)

    def state_matrix(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """A = M^-1 S of every variant at ``speed_mps`` [m/s], shape (B, 2N, 2N)."""
        c = self.coefficients
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = stiffness(c, u, tire_scale)
        return solve_scaled(M, S)

    def eigenvalues(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """Eigenvalues [1/s] of every variant, shape (B, 2N) (unordered)."""
        return np.linalg.eigvals(self.state_matrix(speed_mps, tire_scale))

    def max_real(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """Largest real part of the eigenvalues of every variant [1/s] (negative: stable)."""
        return self.eigenvalues(speed_mps, tire_scale).real.max(axis=-1)

    def steer_to_acceleration(self, speed_mps: float, f_hz: float, tire_scale: float = 1.0) -> np.ndarray:
        """G_i(j 2 pi f): gain from the steer angle to every unit's CG lateral acceleration
        [m/s^2 per rad] of every variant, shape (B, N), as
        :func:`lcvreport.analysis.frequency.steer_to_acceleration` (the velocity and yaw-rate
        maps depend on the geometry only, which the batch does not vary)."""
        co = linear_model(self.vehicle, self.model)
        c = self.coefficients
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = stiffness(c, u, tire_scale)
        b = tire_scale * c["Bdelta"]
        w = 2 * np.pi * float(f_hz)
        x = np.linalg.solve(1j * w * M - S, b[..., None])[..., 0]
        # products per variant: a study's chunks never change a variant's numbers
        return rowwise(x, co.velocity_map(u).T) * (1j * w) + u * rowwise(x, co.yaw_rate_map().T)

    def rearward_amplification(self, speed_mps: float, f_hz: float, tire_scale: float = 1.0) -> np.ndarray:
        """RA(f) = |G_N| / |G_1| [-] of every variant, shape (B,)."""
        G = np.abs(self.steer_to_acceleration(speed_mps, f_hz, tire_scale))
        return G[:, -1] / G[:, 0]

    def trim(self, speed_mps: float, F, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(trim steer [rad], trimmed offtracking [m]) of every variant under the generalized
        force ``F`` (SI; shape (2N,) for all or (B, 2N)), as :func:`lcvreport.analysis.steady.trim`.
        F is taken as given: residual P and T map to it through the geometry alone, but a
        crossfall's m g depends on the masses the batch varies -- build its F per variant."""
        from ..model.yaw_plane.outputs import point_lateral_map, point_longitudinal
        from .steady import reference_points
        u = float(speed_mps)
        x, delta = self.steady(u, F, 0.0, tire_scale)
        v = self.vehicle
        (uq, xq), (up, xp) = reference_points(v)
        nu = v.n_units
        Theta = np.cumsum(x[:, nu + 1:], axis=1)
        lateral = lambda unit, xx: rowwise(Theta, point_lateral_map(v, unit, xx)[2:])  # noqa: E731 (psi1 = Y1 = 0)
        dX = point_longitudinal(v, up, xp) - point_longitudinal(v, uq, xq)
        return delta, lateral(up, xp) - lateral(uq, xq) - dX * x[:, 0] / u

    def ra_at(self, speed_mps: float, f_hz: np.ndarray, tire_scale: float, rows=None) -> np.ndarray:
        """RA of variant rows[b] (default: every variant) at frequency f_hz[b, j] [Hz], shape (K, J);
        in blocks of frequencies (the same numbers, computed in cache, no page faults: 5x faster at 1000 x 381)."""
        J = f_hz.shape[1]
        block = max(1, 8192 // max(1, f_hz.shape[0]))
        if J > block:
            return np.concatenate([self._ra_at_block(speed_mps, f_hz[:, j:j + block], tire_scale, rows)
                                   for j in range(0, J, block)], axis=1)
        return self._ra_at_block(speed_mps, f_hz, tire_scale, rows)

    def _ra_at_block(self, speed_mps: float, f_hz: np.ndarray, tire_scale: float, rows=None) -> np.ndarray:
        co = linear_model(self.vehicle, self.model)
        c = {k: (v if rows is None else v[rows]) for k, v in self.coefficients.items()}
        u = float(speed_mps)
        M = (c["M0"] + u * c["M1"])[:, None]
        S = stiffness(c, u, tire_scale)[:, None]
        b = np.broadcast_to((tire_scale * c["Bdelta"])[:, None], f_hz.shape + c["Bdelta"].shape[-1:])
        w = (2 * np.pi * f_hz)[..., None, None]
        x = np.linalg.solve(1j * w * M - S, b[..., None])[..., 0]
        G = np.abs(rowwise(x, co.velocity_map(u).T) * (1j * w[..., 0]) + u * rowwise(x, co.yaw_rate_map().T))
        return G[..., -1] / G[..., 0]

    def ra_scan(self, speed_mps: float, f_hz: np.ndarray, tire_scale: float) -> np.ndarray:
        """RA of every variant at the frequencies ``f_hz`` (J,), shape (B, J), from each variant's
        modes: x(w) = V diag(1 / (jw - lambda)) V^-1 M^-1 b, O(n) per frequency after one
        eigendecomposition (the exact solves cost O(n^3) per frequency).  It only chooses the
        peak's bracket; every value returned by :meth:`ra_peak` is an exact solve.  Variants whose
        eigenvectors are ill-conditioned (cond(V) > 1e8) are scanned with the exact solves."""
        co = linear_model(self.vehicle, self.model)
        c = self.coefficients
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = stiffness(c, u, tire_scale)
        A = solve_scaled(M, S)
        b = np.linalg.solve(M, (tire_scale * c["Bdelta"])[..., None])[..., 0]
        lam, V = np.linalg.eig(A)
        beta = np.linalg.solve(V, b[..., None].astype(complex))[..., 0]                # (B, n)
        maps = np.stack([co.velocity_map(u)[[0, -1]], co.yaw_rate_map()[[0, -1]]])      # (2, 2, n)
        coef = np.einsum("pkn,bni,bi->bpki", maps, V, beta)                             # (B, 2, 2, n)
        w = 2 * np.pi * np.asarray(f_hz, dtype=float)
        out = np.empty((self.size, w.size))
        for j0 in range(0, w.size, 64):
            jw = 1j * w[j0:j0 + 64]
            h = 1.0 / (jw[None, :, None] - lam[:, None, :])                             # (B, J, n)
            g = np.einsum("bjn,bpkn->bpkj", h, coef)                                    # (B, 2, 2, J)
            G = np.abs(jw * g[:, 0] + u * g[:, 1])                                      # (B, 2, J)
            out[:, j0:j0 + 64] = G[:, 1] / G[:, 0]
        bad = np.flatnonzero(np.linalg.cond(V) > SCAN_COND_MAX)
        if bad.size:
            out[bad] = self.ra_at(speed_mps, np.broadcast_to(f_hz, (bad.size, w.size)), tire_scale, bad)
        return out

    def ay_peaks(self, speed_mps: float, steer, t_end: float, dt: float, units=None,
                 tire_scale: float = 1.0) -> np.ndarray:
        """max |a_i(t)| [m/s^2] of the units ``units`` of every variant under ``steer``: see
        :meth:`_ay_peaks` (computed :data:`RESPONSE_GROUP` variants at a time: the sampled
        states stay in cache)."""
        B = self.size
        G = RESPONSE_GROUP
        return np.concatenate([self._ay_peaks(speed_mps, steer, t_end, dt, units, tire_scale,
                                              np.arange(i, min(B, i + G))) for i in range(0, B, G)])

    def pieces(self, speed_mps: float, steer, t_end: float, dt: float, tire_scale: float, rows: np.ndarray,
                positions: bool = True):
        """The exact response of the variants ``rows`` from rest to ``steer`` (not a lane change),
        piece by piece as :func:`lcvreport.analysis.exact.response` computes it: yields per piece
        ``(Mz, z0, Z, z_end, ka, kb, d_row, ctx)`` with the augmented matrices (B, dim, dim) over
        ``z = [x, psi1, Y1, xi, 1]``, the state at the piece's start, the samples ``ka..kb`` (B,
        count, dim; None if the piece holds no sample), the state at its end (None: it lasts past
        t_end), the steer's row over z, and ``ctx`` (A_x, bd_x, m, n).  ``positions=False`` leaves
        psi1 and Y1 out (``z = [x, xi, 1]``, m = n): they integrate x and feed nothing back, and
        signals of x and the steer alone (accelerations, articulation angles) do not need them."""
        from scipy.linalg import expm
        c = {k: a[rows] for k, a in self.coefficients.items()}
        u = float(speed_mps)
        n, B = linear_model(self.vehicle, self.model).n_states, rows.size
        m = n + 2 if positions else n
        M = c["M0"] + u * c["M1"]
        S = stiffness(c, u, tire_scale)
        AG = solve_scaled(M, np.concatenate([S, np.broadcast_to(np.eye(n), (B, n, n))], axis=-1))
        A_x, Minv = AG[..., :n], AG[..., n:]
        Aa = np.zeros((B, m, m))
        Aa[:, :n, :n] = A_x
        if positions:
            Aa[:, n, 1] = 1.0
            Aa[:, n + 1, 0] = 1.0
            Aa[:, n + 1, n] = u
        bd_x = np.zeros((B, m))
        bd_x[:, :n] = np.einsum("bij,bj->bi", Minv, tire_scale * c["Bdelta"])
        ctx = (A_x, bd_x, m, n)
        lane = steer.prescribes_acceleration
        if lane:                     # the inverse system: x' = (A - b Cs/Ds) x + b a_s / Ds (no residual force)
            from .exact import steered_point
            b_x = bd_x[:, :n]
            Cs, Ds = _steered_axle_rows(A_x, b_x, steered_point(self.vehicle), u)
            ctx = (A_x, bd_x, m, n, Cs, Ds)
        n_steps = int(round(t_end / dt))
        z_state = np.zeros((B, m))
        for piece in steer.pieces:
            if piece.t0 > t_end + 1e-12:
                break
            p = piece.E.shape[0]
            dim = m + p + 1
            Mz = np.zeros((B, dim, dim))
            Mz[:, :m, :m] = Aa
            if lane:
                Mz[:, :n, :n] = A_x - b_x[:, :, None] * Cs[:, None, :] / Ds[:, None, None]
                Mz[:, :n, m:m + p] = b_x[:, :, None] * piece.h[None, None, :] / Ds[:, None, None]
                d_row = np.zeros((B, dim))             # the steer: (a_s - Cs x) / Ds
                d_row[:, :n] = -Cs / Ds[:, None]
                d_row[:, m:m + p] = piece.h[None, :] / Ds[:, None]
            else:
                Mz[:, :m, m:m + p] = bd_x[:, :, None] * piece.h[None, None, :]
                d_row = np.zeros(dim)
                d_row[m:m + p] = piece.h
            Mz[:, m:m + p, m:m + p] = piece.E
            z0 = np.concatenate([z_state, np.broadcast_to(piece.xi0, (B, p)), np.ones((B, 1))], axis=1)
            if not np.any(piece.h):
                # no input (the tail after a pulse, a sine, a lane change): [xi, 1] reach neither x nor
                # the signals (no residual force here), so the piece runs on [x, (psi1, Y1)] alone
                Mz, z0 = np.ascontiguousarray(Mz[:, :m, :m]), z0[:, :m]
                d_row = d_row[..., :m]
                dim = m
            t1 = piece.t1
            ka = int(math.ceil(piece.t0 / dt - 1e-9))
            kb = n_steps if t1 > t_end + 1e-12 else int(math.ceil(t1 / dt - 1e-9)) - 1
            count = kb - ka + 1
            z_end, Z = None, None
            if count > 0:
                ta = ka * dt
                za = z0 if abs(ta - piece.t0) <= 1e-12 * max(1.0, piece.t0) else \
                    np.einsum("bij,bj->bi", expm(Mz * (ta - piece.t0)), z0)
                P = expm(Mz * dt)
                Z = np.empty((B, count, dim))                                  # powers by doubling
                Z[:, 0] = za
                filled = 1
                with np.errstate(over="ignore", invalid="ignore"):
                    while filled < count:
                        take = min(filled, count - filled)
                        # written in place (no temporary: half the time at 8000 samples), the same products
                        np.matmul(Z[:, :take], np.swapaxes(P, 1, 2), out=Z[:, filled:filled + take])
                        filled += take
                        if filled < count:
                            P = P @ P
                if math.isfinite(t1) and t1 <= t_end + 1e-12:
                    z_end = np.einsum("bij,bj->bi", expm(Mz * (t1 - kb * dt)), Z[:, -1])
            elif math.isfinite(t1):
                z_end = np.einsum("bij,bj->bi", expm(Mz * (t1 - piece.t0)), z0)
            yield Mz, z0, Z, z_end, ka, kb, d_row, ctx
            if z_end is None:
                break
            z_state = z_end[:, :m]

    @staticmethod
    def between_samples(Z, C, Mz, dt: float, t0: float):
        """The extrema strictly between samples of the signals ``C`` (B, K, dim) over the samples
        ``Z`` (B, count, dim) of one piece starting at sample time ``t0``: zeros of each signal's
        derivative located on its Hermite interpolant, valued by the quintic one (as
        :meth:`~lcvreport.analysis.exact.ManoeuvreResponse.extrema`).  Flat arrays (variant,
        signal, time [s], value) and the signals' values at the last sample (B, K)."""
        from .extrema import hermite_roots, quintic_hermite
        C1 = C @ Mz
        C2 = C1 @ Mz
        K = C.shape[1]
        D1 = Z @ np.swapaxes(C1, 1, 2)                                     # the derivatives: (B, count, K)
        pos = D1 > 0
        change = pos[:, :-1] != pos[:, 1:]                                 # a sign change, or a zero then a rise
        b_i, rest = np.divmod(np.flatnonzero(change), change.shape[1] * K)   # (faster than a 3-d nonzero)
        k_i, s_i = np.divmod(rest, K)
        y_last = np.einsum("bkd,bd->bk", C, Z[:, -1])
        if not b_i.size:
            return b_i, s_i, np.zeros(0), np.zeros(0), y_last
        k1 = k_i + 1
        Za, Zb = Z[b_i, k_i], Z[b_i, k1]                                   # the samples around each zero
        c, c2 = C[b_i, s_i], C2[b_i, s_i]
        ya, yb = np.einsum("nd,nd->n", Za, c), np.einsum("nd,nd->n", Zb, c)
        sa, sb = np.einsum("nd,nd->n", Za, c2), np.einsum("nd,nd->n", Zb, c2)
        da, db = D1[b_i, k_i, s_i], D1[b_i, k1, s_i]
        tau = hermite_roots(da, sa, db, sb, dt)
        val = quintic_hermite(ya, da, sa, yb, db, sb, dt, tau)
        return b_i, s_i, t0 + (k_i + tau) * dt, val, y_last

    def extremes(self, speed_mps: float, steer, t_end: float, dt: float, signals, tire_scale: float,
                  rows: np.ndarray, positions: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(largest, smallest) value of the signals over the continuous response on [0, t_end]
        among its extrema, the pieces' ends and the window's ends (as ``extrema``), shape (B, K);
        ``signals(Mz, d_row, ctx)`` gives the signals' rows over z (B, K, dim) for a piece."""
        n_steps = int(round(t_end / dt))
        hi = lo = None
        for Mz, z0, Z, z_end, ka, kb, d_row, ctx in self.pieces(speed_mps, steer, t_end, dt, tire_scale, rows,
                                                                 positions):
            C = signals(Mz, d_row, ctx)
            if hi is None:
                hi = np.full(C.shape[:2], -np.inf)
                lo = np.full(C.shape[:2], np.inf)
            if Z is not None:
                b_i, s_i, _t, val, y_last = self.between_samples(Z, C, Mz, dt, ka * dt)
                np.maximum.at(hi, (b_i, s_i), val)
                np.minimum.at(lo, (b_i, s_i), val)
                if kb == n_steps:                                                  # the window's end
                    hi, lo = np.maximum(hi, y_last), np.minimum(lo, y_last)
            for z in (z0, z_end):                                                  # the piece's ends
                if z is not None:
                    y = np.einsum("bkd,bd->bk", C, z)
                    hi, lo = np.maximum(hi, y), np.minimum(lo, y)
        return hi, lo

    def ay_rows(self, speed_mps: float, units):
        """``signals`` of :meth:`_extremes`: the CG lateral accelerations of ``units`` (0-based)."""
        co = linear_model(self.vehicle, self.model)
        u = float(speed_mps)
        Vmap, Rmap = co.velocity_map(u)[units], co.yaw_rate_map()[units]

        def rows(Mz, d_row, ctx):
            A_x, bd_x, n = ctx[0], ctx[1], ctx[3]
            C = np.zeros((Mz.shape[0], len(units), Mz.shape[-1]))
            C[:, :, :n] = np.einsum("kn,bnj->bkj", Vmap, A_x) + u * Rmap
            da = np.einsum("kn,bn->bk", Vmap, bd_x[:, :n])
            C += da[:, :, None] * (d_row if d_row.ndim == 1 else d_row[:, None, :])
            return C
        return rows

    def _ay_peaks(self, speed_mps: float, steer, t_end: float, dt: float, units, tire_scale: float,
                  rows: np.ndarray) -> np.ndarray:
        units = list(range(self.vehicle.n_units)) if units is None else list(units)
        hi, lo = self.extremes(speed_mps, steer, t_end, dt, self.ay_rows(speed_mps, units), tire_scale, rows,
                                positions=False)                          # accelerations: no psi1, Y1
        return np.maximum(np.abs(hi), np.abs(lo))

    def inverse_stable(self, u: float, tire_scale: float, rows: np.ndarray) -> np.ndarray:
        """Which variants of ``rows`` have a stable inverse system from the steered axle's
        lateral acceleration to the steer (the test of :func:`lcvreport.analysis.exact.response`)."""
        from .exact import steered_point
        c = {k: a[rows] for k, a in self.coefficients.items()}
        n = linear_model(self.vehicle, self.model).n_states
        M = c["M0"] + u * c["M1"]
        S = stiffness(c, u, tire_scale)
        AG = solve_scaled(M, np.concatenate([S, np.broadcast_to(np.eye(n), (rows.size, n, n))], axis=-1))
        A_x, Minv = AG[..., :n], AG[..., n:]
        b = np.einsum("bij,bj->bi", Minv, tire_scale * c["Bdelta"])
        Cs, Ds = _steered_axle_rows(A_x, b, steered_point(self.vehicle), u)
        exists = np.abs(Ds) >= 1e-12 * np.maximum(1.0, np.abs(Cs).max(axis=1))
        out = np.zeros(rows.size, bool)
        if exists.any():
            k = np.flatnonzero(exists)
            zeros = np.linalg.eigvals(A_x[k] - b[k, :, None] * Cs[k, None, :] / Ds[k, None, None])
            out[k] = zeros.real.max(axis=1) <= 1e-9 * np.maximum(1.0, np.abs(zeros).max(axis=1))
        return out

    def steady(self, u: float, F, r1: float, tire_scale: float) -> tuple[np.ndarray, np.ndarray]:
        """S x + b delta + F = 0 with x[1] = r1 for every variant, as
        :func:`lcvreport.analysis.steady.steady_with_yaw_rate`: (x (B, 2N), delta (B,))."""
        c = self.coefficients
        n = c["M0"].shape[-1]
        B = self.size
        K = np.zeros((B, n + 1, n + 1))
        K[:, :n, :n] = stiffness(c, u, tire_scale)
        K[:, :n, n] = tire_scale * c["Bdelta"]
        K[:, n, 1] = 1.0
        rhs = np.zeros((B, n + 1))
        rhs[:, :n] = -np.broadcast_to(np.asarray(F, dtype=float), (B, n))
        rhs[:, n] = r1
        sol = np.linalg.solve(K, rhs[..., None])[..., 0]
        return sol[:, :n], sol[:, n]

    def max_real_at(self, v_kph: np.ndarray, tire_scale: float) -> np.ndarray:
        """max Re(lambda) of variant b at speed v_kph[b, j] [km/h], shape like v_kph (B, J)."""
        from ..units import kph_to_mps
        c = self.coefficients
        u = kph_to_mps(np.asarray(v_kph, dtype=float))[..., None, None]          # (B, J, 1, 1)
        M = c["M0"][:, None] + u * c["M1"][:, None]
        S = stiffness({k: c[k][:, None] for k in STIFFNESS}, u, tire_scale)
        return np.linalg.eigvals(solve_scaled(M, S)).real.max(axis=-1)

    def values_at(self, variants: np.ndarray, v_kph: np.ndarray, tire_scale: float) -> np.ndarray:
        """max Re(lambda) of variant ``variants[k]`` at ``v_kph[k]`` [km/h], shape (K,)."""
        from ..units import kph_to_mps
        c = self.coefficients
        u = kph_to_mps(np.asarray(v_kph, dtype=float))[:, None, None]
        M = c["M0"][variants] + u * c["M1"][variants]
        S = stiffness({k: c[k][variants] for k in STIFFNESS}, u, tire_scale)
        return np.linalg.eigvals(solve_scaled(M, S)).real.max(axis=-1)

