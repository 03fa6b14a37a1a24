"""Variants of one vehicle in a batch: masses, yaw inertias and tire coefficients as arrays,
the model's matrices and the measures of ``measure_set`` batched over the leading axis (SPEC
section 14, issue 21): damping, critical speed, RA(f), the RA peak, the single sine, the yaw
damping coefficient of the pulse, HSTO and RA of the lane change, HSSO, the trim.  The time
responses are the exact ones of :mod:`lcvreport.analysis.exact` run on 64 variants at a time.

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
>>> zeta, f_hz = b.least_damping(24.0)
>>> zeta.shape
(3,)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients
from ..ranges import RANGES
from ..util.numerics import solve_scaled

#: the coefficients the batch varies, and the parameters it can vary
COEFFICIENTS = ("M0", "M1", "S0", "Sinv", "Su", "Skin", "Bdelta")
UNIT_PARAMETERS = ("mass_kg", "yaw_inertia_kg_m2")
AXLE_PARAMETERS = ("cornering_stiffness_N_per_rad", "aligning_stiffness_Nm_per_rad", "longitudinal_stiffness_N")


#: variants whose time responses are computed together (their samples stay in cache)
RESPONSE_GROUP = 8

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


def ratio_damping_groups(group: np.ndarray, signal: np.ndarray, values: np.ndarray):
    """:func:`lcvreport.measures.yaw_damping.ratio_damping` of many signals at once: ``values``
    holds each signal's extrema in time order, the signals one after the other, labelled by
    ``(group, signal)``.  Returns (zeta, group, signal) of every signal with two kept amplitudes
    or more (the same arithmetic in the same order: equal to the one-signal function to a few ulp,
    numpy's vectorised logarithm and its scalar one differing by an ulp at most).

    Examples
    --------
    >>> import numpy as np
    >>> A = np.exp(-0.3 * np.pi / 2 * np.arange(8)) * (-1.0) ** np.arange(8)
    >>> z, g, s = ratio_damping_groups(np.zeros(8, int), np.zeros(8, int), A)
    >>> from lcvreport.measures.yaw_damping import ratio_damping
    >>> bool(abs(z[0] - ratio_damping(A)[0]) <= 1e-15)
    True
    """
    from ..measures.yaw_damping import YDC_MAX_AMPLITUDES, YDC_MIN_FRACTION
    group, signal, values = np.asarray(group), np.asarray(signal), np.asarray(values, dtype=float)
    empty = (np.zeros(0), np.zeros(0, int), np.zeros(0, int))
    if values.size < 3:
        return empty
    new = np.r_[True, (group[1:] != group[:-1]) | (signal[1:] != signal[:-1])]
    label = np.cumsum(new) - 1                                  # one label per signal
    same = label[1:] == label[:-1]
    P = np.abs(np.diff(values))[same]                           # peak-to-peak amplitudes
    lab = label[1:][same]
    if not P.size:
        return empty
    starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
    pmax = np.maximum.reduceat(P, starts)
    which = np.cumsum(np.r_[True, lab[1:] != lab[:-1]]) - 1   # index into starts
    idx = np.arange(P.size)
    first_max = np.minimum.reduceat(np.where(P == pmax[which], idx, P.size), starts)
    # the free decay starts at each signal's largest amplitude; from it on, those >= 5 % of it
    keep = (idx >= first_max[which]) & (P >= YDC_MIN_FRACTION * pmax[which])
    rank = np.cumsum(keep)
    before = np.r_[0, rank][starts][which]                      # kept amplitudes before the signal's first
    keep &= (rank - before) <= YDC_MAX_AMPLITUDES
    P, lab = P[keep], lab[keep]
    pair = lab[1:] == lab[:-1]
    d = np.log(P[:-1][pair] / P[1:][pair])
    z = d / np.sqrt(np.pi ** 2 + d ** 2)
    zl = lab[:-1][pair]
    if not zl.size:
        return empty
    firsts = np.flatnonzero(np.r_[True, zl[1:] != zl[:-1]])
    counts = np.diff(np.r_[firsts, zl.size])
    sums = np.add.reduceat(z, firsts)
    idx = np.flatnonzero(new)[zl[firsts]]                        # each signal's first element
    return sums / counts, group[idx], signal[idx]


@dataclass
class VariantBatch:
    """``B`` variants of ``vehicle``: ``values`` maps parameter names to arrays of shape (B,) (SI)."""

    vehicle: Vehicle
    values: dict
    coefficients: dict = field(init=False, repr=False)

    def __post_init__(self):
        lengths = {np.shape(v) for v in self.values.values()}
        if len(lengths) > 1 or any(len(s) != 1 for s in lengths):
            raise BatchError(f"every parameter needs an array of one length, got shapes {sorted(lengths)}")
        base = system_coefficients(self.vehicle)
        B = next(iter(lengths))[0] if lengths else 1
        coeffs = {k: np.broadcast_to(getattr(base, k), (B,) + getattr(base, k).shape).copy() for k in COEFFICIENTS}
        for name, arr in self.values.items():
            arr = np.asarray(arr, dtype=float)
            if not np.all(np.isfinite(arr)) or np.any(arr <= 0):
                raise BatchError(f"{name}: every value must be finite and > 0")
            p0 = _nominal(self.vehicle, name)
            step = p0 if p0 > 0 else 1.0
            bumped = system_coefficients(_with(self.vehicle, name, p0 + step))
            for k in COEFFICIENTS:
                d = (getattr(bumped, k) - getattr(base, k)) / step
                coeffs[k] += (arr - p0).reshape((B,) + (1,) * d.ndim) * d
        self.coefficients = coeffs

    @property
    def size(self) -> int:
        return self.coefficients["M0"].shape[0]

    def _subset(self, rows) -> "VariantBatch":
        """The variants ``rows`` as a batch of their own (sharing the coefficients' rows)."""
        sub = object.__new__(VariantBatch)
        sub.vehicle = self.vehicle
        sub.values = {k: np.asarray(a)[rows] for k, a in self.values.items()}
        sub.coefficients = {k: a[rows] for k, a in self.coefficients.items()}
        return sub

    def _in_groups(self, method: str, *args, group: int = 256):
        """``method`` run on groups of ``group`` variants, the results joined: a variant's result
        does not depend on its group (each one's scan and search stop on their own), and groups
        keep the work arrays in cache (at 2000 variants the critical speed took 1.5x longer per
        variant in one piece)."""
        if self.size <= group:
            return getattr(self, method)(*args)
        parts = [getattr(self._subset(slice(i, i + group)), method)(*args) for i in range(0, self.size, group)]
        if isinstance(parts[0], tuple):
            return tuple(np.concatenate([p[k] for p in parts]) for k in range(len(parts[0])))
        return np.concatenate(parts)

    def state_matrix(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """A = M^-1 S of every variant at ``speed_mps`` [m/s], shape (B, 2N, 2N)."""
        c = self.coefficients
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
        return solve_scaled(M, S)

    def eigenvalues(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """Eigenvalues [1/s] of every variant, shape (B, 2N) (unordered)."""
        return np.linalg.eigvals(self.state_matrix(speed_mps, tire_scale))

    def least_damping(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(least damping ratio [-], its damped frequency [Hz]) of every variant over the oscillatory
        modes, as :func:`lcvreport.measures.stability.least_damping` (NaN where none oscillates)."""
        lam = self.eigenvalues(speed_mps, tire_scale)
        osc = lam.imag > 1e-12 * np.maximum(np.abs(lam).max(axis=-1, keepdims=True), 1.0)
        zeta = np.where(osc, -lam.real / np.where(np.abs(lam) > 0, np.abs(lam), 1.0), np.inf)
        k = np.argmin(zeta, axis=-1)
        rows = np.arange(lam.shape[0])
        best = zeta[rows, k]
        f_hz = lam[rows, k].imag / (2 * np.pi)
        none = ~np.isfinite(best)
        return np.where(none, np.nan, best), np.where(none, np.nan, f_hz)

    def max_real(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """Largest real part of the eigenvalues of every variant [1/s] (negative: stable)."""
        return self.eigenvalues(speed_mps, tire_scale).real.max(axis=-1)

    def steer_to_acceleration(self, speed_mps: float, f_hz: float, tire_scale: float = 1.0) -> np.ndarray:
        """G_i(j 2 pi f): gain from the steer angle to every unit's CG lateral acceleration
        [m/s^2 per rad] of every variant, shape (B, N), as
        :func:`lcvreport.analysis.frequency.steer_to_acceleration` (the velocity and yaw-rate
        maps depend on the geometry only, which the batch does not vary)."""
        co = system_coefficients(self.vehicle)
        c = self.coefficients
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
        b = tire_scale * c["Bdelta"]
        w = 2 * np.pi * float(f_hz)
        x = np.linalg.solve(1j * w * M - S, b[..., None])[..., 0]
        return x @ co.velocity_map(u).T * (1j * w) + u * (x @ co.yaw_rate_map().T)

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
        x, delta = self._steady(u, F, 0.0, tire_scale)
        v = self.vehicle
        (uq, xq), (up, xp) = reference_points(v)
        nu = v.n_units
        Theta = np.cumsum(x[:, nu + 1:], axis=1)
        lateral = lambda unit, xx: Theta @ point_lateral_map(v, unit, xx)[2:]  # noqa: E731 (psi1 = Y1 = 0)
        dX = point_longitudinal(v, up, xp) - point_longitudinal(v, uq, xq)
        return delta, lateral(up, xp) - lateral(uq, xq) - dX * x[:, 0] / u

    def _ra_at(self, speed_mps: float, f_hz: np.ndarray, tire_scale: float, rows=None) -> np.ndarray:
        """RA of variant rows[b] (default: every variant) at frequency f_hz[b, j] [Hz], shape (K, J);
        in blocks of frequencies (the same numbers, computed in cache, no page faults: 5x faster at 1000 x 381)."""
        J = f_hz.shape[1]
        block = max(1, 8192 // max(1, f_hz.shape[0]))
        if J > block:
            return np.concatenate([self._ra_at_block(speed_mps, f_hz[:, j:j + block], tire_scale, rows)
                                   for j in range(0, J, block)], axis=1)
        return self._ra_at_block(speed_mps, f_hz, tire_scale, rows)

    def _ra_at_block(self, speed_mps: float, f_hz: np.ndarray, tire_scale: float, rows=None) -> np.ndarray:
        co = system_coefficients(self.vehicle)
        c = {k: (v if rows is None else v[rows]) for k, v in self.coefficients.items()}
        u = float(speed_mps)
        M = (c["M0"] + u * c["M1"])[:, None]
        S = (tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"])[:, None]
        b = np.broadcast_to((tire_scale * c["Bdelta"])[:, None], f_hz.shape + c["Bdelta"].shape[-1:])
        w = (2 * np.pi * f_hz)[..., None, None]
        x = np.linalg.solve(1j * w * M - S, b[..., None])[..., 0]
        G = np.abs(x @ co.velocity_map(u).T * (1j * w[..., 0]) + u * (x @ co.yaw_rate_map().T))
        return G[..., -1] / G[..., 0]

    def _ra_scan(self, speed_mps: float, f_hz: np.ndarray, tire_scale: float) -> np.ndarray:
        """RA of every variant at the frequencies ``f_hz`` (J,), shape (B, J), from each variant's
        modes: x(w) = V diag(1 / (jw - lambda)) V^-1 M^-1 b, O(n) per frequency after one
        eigendecomposition (the exact solves cost O(n^3) per frequency).  It only chooses the
        peak's bracket; every value returned by :meth:`ra_peak` is an exact solve.  Variants whose
        eigenvectors are ill-conditioned (cond(V) > 1e8) are scanned with the exact solves."""
        co = system_coefficients(self.vehicle)
        c = self.coefficients
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
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
            out[bad] = self._ra_at(speed_mps, np.broadcast_to(f_hz, (bad.size, w.size)), tire_scale, bad)
        return out

    def ra_peak(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(max RA(f) over 0.1-2 Hz [-], where [Hz]) of every variant: see :meth:`_ra_peak`
        (groups of 256 variants)."""
        return self._in_groups("_ra_peak", speed_mps, tire_scale)

    def _ra_slope(self, speed_mps: float, x_hz: np.ndarray, tire_scale: float, rows: np.ndarray) -> np.ndarray:
        """d ln RA / d omega of variant rows[k] at x_hz[k] [Hz] (its sign is that of dRA/df), exact:
        ``dz/dw = -(jwM - S)^-1 jM z``, as the one-variant ``ra_peak``."""
        co = system_coefficients(self.vehicle)
        c = {k: v[rows] for k, v in self.coefficients.items()}
        u = float(speed_mps)
        M = c["M0"] + u * c["M1"]
        S = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
        w = 2 * np.pi * np.asarray(x_hz, dtype=float)
        A = 1j * w[:, None, None] * M - S
        z = np.linalg.solve(A, (tire_scale * c["Bdelta"])[..., None].astype(complex))
        dz = np.linalg.solve(A, -1j * (M @ z))
        # products per variant (stacks of 1-row matrices): a variant's numbers do not depend on
        # how many others share the call (a (K, n) @ (n, 2) product may round by K)
        z, dz = np.swapaxes(z, 1, 2), np.swapaxes(dz, 1, 2)                   # (K, 1, n)
        ends = np.array([0, self.vehicle.n_units - 1])
        V, R = co.velocity_map(u)[ends].T, co.yaw_rate_map()[ends].T
        jw = (1j * w)[:, None, None]
        zV = z @ V
        G = (zV * jw + u * (z @ R))[:, 0]
        dG = (dz @ V * jw + 1j * zV + u * (dz @ R))[:, 0]
        g = (G.conj() * dG).real / (G.conj() * G).real
        return g[:, 1] - g[:, 0]

    def _ra_peak(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(max RA(f) over 0.1-2 Hz [-], where [Hz]) of every variant: the 0.005 Hz scan of
        :func:`lcvreport.measures.amplification.ra_peak` (on the variants' modes, :meth:`_ra_scan`),
        then the zero of the exact slope d ln RA / d omega in each variant's best bracket (the
        Illinois variant of regula falsi, to 1e-13 Hz; the one-variant version uses Brent's root
        finder on the same slope), a golden-section search on RA's values where the slope does not
        change sign across the bracket.  Each variant's search stops on its own, so its result does
        not depend on the other variants of the batch."""
        from ..measures.amplification import RA_BAND_HZ
        lo, hi = RA_BAND_HZ
        f = np.linspace(lo, hi, 381)
        values = self._ra_scan(speed_mps, f, tire_scale)
        k = np.argmax(values, axis=1)
        where = f[k].astype(float)
        best = self._ra_at(speed_mps, where[:, None], tire_scale)[:, 0]          # exact at the scan's best
        idx = np.flatnonzero((k > 0) & (k < f.size - 1))
        if idx.size:
            a, c = f[k[idx] - 1].astype(float), f[k[idx] + 1].astype(float)
            ga = self._ra_slope(speed_mps, a, tire_scale, idx)
            gc = self._ra_slope(speed_mps, c, tire_scale, idx)
            root = (ga > 0) & (gc < 0)
            xm = np.empty(idx.size)
            if root.any():
                r = np.flatnonzero(root)
                xm[r] = self._slope_zero(speed_mps, tire_scale, idx[r], a[r], c[r], ga[r], gc[r])
            if (~root).any():
                r = np.flatnonzero(~root)
                xm[r] = self._golden(speed_mps, tire_scale, idx[r], a[r], c[r])
            xm = np.clip(xm, lo, hi)
            vm = self._ra_at(speed_mps, xm[:, None], tire_scale, idx)[:, 0]
            better = vm >= best[idx]
            best[idx] = np.where(better, vm, best[idx])
            where[idx] = np.where(better, xm, where[idx])
        return best, where

    def _slope_zero(self, speed_mps, tire_scale, rows, a, c, ga, gc) -> np.ndarray:
        """The zero of :meth:`_ra_slope` in [a, c] (ga > 0 > gc) of each variant of ``rows``:
        Illinois regula falsi, each variant stopping when its iterate moves less than 1e-13 Hz."""
        a, c, ga, gc = a.copy(), c.copy(), ga.copy(), gc.copy()
        x = c - gc * (c - a) / (gc - ga)                 # the secant's zero (gc < 0 < ga: no 0 / 0)
        side = np.zeros(a.size, int)                     # which end was kept last time (Illinois)
        active = np.arange(a.size)
        for _ in range(100):
            if not active.size:
                break
            xa = x[active]
            g = self._ra_slope(speed_mps, xa, tire_scale, rows[active])
            pos = g > 0
            # replace the end with the same sign; halve the other end's slope when kept twice
            a[active] = np.where(pos, xa, a[active])
            ga[active] = np.where(pos, g, np.where(side[active] == -1, 0.5 * ga[active], ga[active]))
            c[active] = np.where(pos, c[active], xa)
            gc[active] = np.where(pos, np.where(side[active] == 1, 0.5 * gc[active], gc[active]), g)
            side[active] = np.where(pos, 1, -1)
            aa, cc, gaa, gcc = a[active], c[active], ga[active], gc[active]
            with np.errstate(divide="ignore", invalid="ignore"):
                new = cc - gcc * (cc - aa) / (gcc - gaa)
            new = np.where((new > aa) & (new < cc), new, 0.5 * (aa + cc))
            done = (np.abs(new - xa) <= 1e-13) | (g == 0) | (cc - aa <= 1e-13)
            x[active] = np.where(g == 0, xa, new)
            active = active[~done]
        return x

    def _golden(self, speed_mps, tire_scale, idx, a, c) -> np.ndarray:
        """The golden-section search of RA's values over [a, c] of each variant of ``idx``, to 1e-12 Hz."""
        a, c = a.copy(), c.copy()
        g = (math.sqrt(5.0) - 1.0) / 2.0
        x1, x2 = c - g * (c - a), a + g * (c - a)
        both = self._ra_at(speed_mps, np.stack([x1, x2], axis=1), tire_scale, idx)
        f1, f2 = both[:, 0], both[:, 1]
        active = np.flatnonzero(c - a > 1e-12)
        while active.size:
            left = f1[active] > f2[active]                 # the maximum is in [a, x2], else in [x1, c]
            aa, cc = a[active], c[active]
            aa, cc = np.where(left, aa, x1[active]), np.where(left, x2[active], cc)
            new = np.where(left, cc - g * (cc - aa), aa + g * (cc - aa))
            f_new = self._ra_at(speed_mps, new[:, None], tire_scale, idx[active])[:, 0]
            x1n = np.where(left, new, x2[active])
            x2n = np.where(left, x1[active], new)
            f1n = np.where(left, f_new, f2[active])
            f2n = np.where(left, f1[active], f_new)
            a[active], c[active], x1[active], x2[active], f1[active], f2[active] = aa, cc, x1n, x2n, f1n, f2n
            active = active[cc - aa > 1e-12]
        return 0.5 * (a + c)

    def ay_peaks(self, speed_mps: float, steer, t_end: float, dt: float, units=None,
                 tire_scale: float = 1.0) -> np.ndarray:
        """max |a_i(t)| [m/s^2] of the units ``units`` of every variant under ``steer``: see
        :meth:`_ay_peaks` (computed 64 variants at a time: the sampled states stay in cache,
        0.57 ms per variant for the single sine of aucnat against 2.6 ms one by one)."""
        B = self.size
        G = RESPONSE_GROUP
        return np.concatenate([self._ay_peaks(speed_mps, steer, t_end, dt, units, tire_scale,
                                              np.arange(i, min(B, i + G))) for i in range(0, B, G)])

    def _pieces(self, speed_mps: float, steer, t_end: float, dt: float, tire_scale: float, rows: np.ndarray,
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
        n, B = self.vehicle.n_states, rows.size
        m = n + 2 if positions else n
        M = c["M0"] + u * c["M1"]
        S = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
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
            Js = np.zeros(n)
            Js[0], Js[1] = 1.0, steered_point(self.vehicle)
            Cs = np.einsum("k,bkj->bj", Js, A_x)
            Cs[:, 1] += u
            Ds = b_x @ Js
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
                        Z[:, filled:filled + take] = Z[:, :take] @ np.swapaxes(P, 1, 2)
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
    def _between_samples(Z, C, Mz, dt: float, t0: float):
        """The extrema strictly between samples of the signals ``C`` (B, K, dim) over the samples
        ``Z`` (B, count, dim) of one piece starting at sample time ``t0``: zeros of each signal's
        derivative located on its Hermite interpolant, valued by the quintic one (as
        :meth:`~lcvreport.analysis.exact.ManoeuvreResponse.extrema`).  Flat arrays (variant,
        signal, time [s], value) and the signals' values at the last sample (B, K)."""
        from .extrema import _hermite_roots, _quintic
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
        tau = _hermite_roots(da, sa, db, sb, dt)
        val = _quintic(ya, da, sa, yb, db, sb, dt, tau)
        return b_i, s_i, t0 + (k_i + tau) * dt, val, y_last

    def _extremes(self, speed_mps: float, steer, t_end: float, dt: float, signals, tire_scale: float,
                  rows: np.ndarray, positions: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """(largest, smallest) value of the signals over the continuous response on [0, t_end]
        among its extrema, the pieces' ends and the window's ends (as ``extrema``), shape (B, K);
        ``signals(Mz, d_row, ctx)`` gives the signals' rows over z (B, K, dim) for a piece."""
        n_steps = int(round(t_end / dt))
        hi = lo = None
        for Mz, z0, Z, z_end, ka, kb, d_row, ctx in self._pieces(speed_mps, steer, t_end, dt, tire_scale, rows,
                                                                 positions):
            C = signals(Mz, d_row, ctx)
            if hi is None:
                hi = np.full(C.shape[:2], -np.inf)
                lo = np.full(C.shape[:2], np.inf)
            if Z is not None:
                b_i, s_i, _t, val, y_last = self._between_samples(Z, C, Mz, dt, ka * dt)
                np.maximum.at(hi, (b_i, s_i), val)
                np.minimum.at(lo, (b_i, s_i), val)
                if kb == n_steps:                                                  # the window's end
                    hi, lo = np.maximum(hi, y_last), np.minimum(lo, y_last)
            for z in (z0, z_end):                                                  # the piece's ends
                if z is not None:
                    y = np.einsum("bkd,bd->bk", C, z)
                    hi, lo = np.maximum(hi, y), np.minimum(lo, y)
        return hi, lo

    def _ay_rows(self, speed_mps: float, units):
        """``signals`` of :meth:`_extremes`: the CG lateral accelerations of ``units`` (0-based)."""
        co = system_coefficients(self.vehicle)
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
        hi, lo = self._extremes(speed_mps, steer, t_end, dt, self._ay_rows(speed_mps, units), tire_scale, rows,
                                positions=False)                          # accelerations: no psi1, Y1
        return np.maximum(np.abs(hi), np.abs(lo))

    def lane_change(self, speed_mps: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(HSTO [m], the lane change's RA [-]) of every variant, as
        :func:`lcvreport.measures.offtracking.lane_change_measures` (the path-following lane
        change through each variant's inverse system): the last unit's rearmost axle's largest
        overshoot beyond the steered axle's final offset (0 if none), and max|a_N| / max|a_s|.
        NaN where the inverse system is unstable or does not exist, or the steer leaves
        [-1, 1] rad (measure_set's null)."""
        from ..manoeuvres.steer import G_MPS2, lane_change, lane_change_offset_m
        from ..measures.offtracking import DT_S, LANE_CHANGE, LANE_CHANGE_TAIL_S
        from ..model.yaw_plane.outputs import point_lateral_map
        from .exact import steered_point
        v = self.vehicle
        B, nu, n = self.size, v.n_units, v.n_states
        accel_g, f_hz = LANE_CHANGE
        steer = lane_change(accel_g * G_MPS2, f_hz)
        t_end = round((1.0 / f_hz + LANE_CHANGE_TAIL_S) / DT_S) * DT_S
        offset = lane_change_offset_m(steer)
        sign = 1.0 if offset >= 0 else -1.0
        u = float(speed_mps)
        xs = steered_point(v)
        rear = v.units[-1].rearmost_axle
        cmap = point_lateral_map(v, nu - 1, rear.x_m)
        cum = np.zeros((nu - 1, n + 2))
        for k in range(nu - 1):
            cum[k, nu + 1:nu + 2 + k] = 1.0
        y_row = cmap[2:] @ cum if nu > 1 else np.zeros(n + 2)
        y_row[n] += cmap[0]
        y_row[n + 1] += cmap[1]
        ay_rows = self._ay_rows(u, [nu - 1])

        def signals(Mz, d_row, ctx):
            C = np.zeros((Mz.shape[0], 4, Mz.shape[-1]))
            C[:, 0, :n + 2] = y_row                                             # Y of the rear axle
            C[:, 1] = ay_rows(Mz, d_row, ctx)[:, 0]                             # a_N
            C[:, 2] = Mz[:, 0] + xs * Mz[:, 1]                                  # a_s = v1' + x_s r1' + u r1
            C[:, 2, 1] += u
            C[:, 3] = d_row                                                     # the steer (within [-1, 1] rad)
            return C
        hsto, ra = np.full(B, np.nan), np.full(B, np.nan)
        for g in range(0, B, RESPONSE_GROUP):
            rows = np.arange(g, min(B, g + RESPONSE_GROUP))
            ok = self._inverse_stable(u, tire_scale, rows)
            rows = rows[ok]
            if not rows.size:
                continue
            hi, lo = self._extremes(u, steer, t_end, DT_S, signals, tire_scale, rows)
            over = (hi[:, 0] - offset) if sign > 0 else -(lo[:, 0] - offset)
            peak = np.maximum(np.abs(hi), np.abs(lo))
            steer_ok = peak[:, 3] <= RANGES["steer_angle"].high                # else refused (measure_set's null)
            hsto[rows[steer_ok]] = np.maximum(0.0, over[steer_ok])
            ra[rows[steer_ok]] = peak[steer_ok, 1] / peak[steer_ok, 2]
        return hsto, ra

    def _inverse_stable(self, u: float, tire_scale: float, rows: np.ndarray) -> np.ndarray:
        """Which variants of ``rows`` have a stable inverse system from the steered axle's
        lateral acceleration to the steer (the test of :func:`lcvreport.analysis.exact.response`)."""
        from .exact import steered_point
        c = {k: a[rows] for k, a in self.coefficients.items()}
        n = self.vehicle.n_states
        M = c["M0"] + u * c["M1"]
        S = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
        AG = solve_scaled(M, np.concatenate([S, np.broadcast_to(np.eye(n), (rows.size, n, n))], axis=-1))
        A_x, Minv = AG[..., :n], AG[..., n:]
        b = np.einsum("bij,bj->bi", Minv, tire_scale * c["Bdelta"])
        Js = np.zeros(n)
        Js[0], Js[1] = 1.0, steered_point(self.vehicle)
        Cs = np.einsum("k,bkj->bj", Js, A_x)
        Cs[:, 1] += u
        Ds = b @ Js
        exists = np.abs(Ds) >= 1e-12 * np.maximum(1.0, np.abs(Cs).max(axis=1))
        out = np.zeros(rows.size, bool)
        if exists.any():
            k = np.flatnonzero(exists)
            zeros = np.linalg.eigvals(A_x[k] - b[k, :, None] * Cs[k, None, :] / Ds[k, None, None])
            out[k] = zeros.real.max(axis=1) <= 1e-9 * np.maximum(1.0, np.abs(zeros).max(axis=1))
        return out

    def yaw_damping(self, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
        """The yaw damping coefficient [-] of every variant
        (:func:`lcvreport.measures.yaw_damping.yaw_damping_coefficient`: the pulse, each joint's
        extrema from its end to 40 s after on the continuous response, the ratio method, the
        smallest over the joints); NaN where no joint has two amplitudes."""
        from ..manoeuvres.steer import pulse
        from ..measures.yaw_damping import YDC_DT_S, YDC_PULSE, YDC_WINDOW_S
        v = self.vehicle
        B = self.size
        out = np.full(B, np.nan)
        if v.n_units < 2:
            return out
        A, D = YDC_PULSE
        steer = pulse(A, D)
        t_end = round((D + YDC_WINDOW_S) / YDC_DT_S) * YDC_DT_S
        lo, hi = D + 1e-12, D + YDC_WINDOW_S - 1e-12
        joints = v.n_units - 1
        extrema = []
        for g in range(0, B, RESPONSE_GROUP):
            rows = np.arange(g, min(B, g + RESPONSE_GROUP))
            found = []
            for Mz, _z0, Z, _z_end, ka, _kb, _d, (_A, _b, m, n) in self._pieces(speed_mps, steer, t_end, YDC_DT_S,
                                                                               tire_scale, rows, positions=False):
                if Z is None:
                    continue
                C = np.zeros((rows.size, joints, Mz.shape[-1]))                 # theta rows over z
                C[:, np.arange(joints), v.n_units + 1 + np.arange(joints)] = 1.0
                b_i, s_i, t, val, _y = self._between_samples(Z, C, Mz, YDC_DT_S, ka * YDC_DT_S)
                keep = (t > lo) & (t < hi)
                found.append((b_i[keep], s_i[keep], t[keep], val[keep]))
            b_i, s_i, t, val = (np.concatenate(a) for a in zip(*found))
            extrema.append((rows[b_i], s_i, t, val))
        b_i, s_i, t, val = (np.concatenate(a) for a in zip(*extrema))
        order = np.lexsort((t, s_i, b_i))                     # by variant, joint, time
        zeta, b_of, _s = ratio_damping_groups(b_i[order], s_i[order], val[order])
        np.fmin.at(out, b_of, zeta)                            # the smallest over a variant's joints
        return out

    def single_sine(self, speed_mps: float, f_hz: float | None = None, tire_scale: float = 1.0) -> np.ndarray:
        """RA of the single sine [-] of every variant: max|a_N| / max|a_1| on the continuous exact
        response (:func:`lcvreport.measures.amplification.single_sine`: ``delta0 sin(2 pi f t)`` for one
        period, then the tail)."""
        from ..manoeuvres.steer import sine
        from ..measures.amplification import SINGLE_SINE_DELTA0_RAD, SINGLE_SINE_STEP_S, SINGLE_SINE_TAIL_S
        from .frequency import RA_FREQUENCY_HZ, _freq
        f = float(_freq(RA_FREQUENCY_HZ if f_hz is None else f_hz))
        steer = sine(SINGLE_SINE_DELTA0_RAD, f)
        t_end = round((1.0 / f + SINGLE_SINE_TAIL_S) / SINGLE_SINE_STEP_S) * SINGLE_SINE_STEP_S
        peaks = self.ay_peaks(speed_mps, steer, t_end, SINGLE_SINE_STEP_S, [0, self.vehicle.n_units - 1],
                              tire_scale)
        return peaks[:, 1] / peaks[:, 0]

    def _steady(self, u: float, F, r1: float, tire_scale: float) -> tuple[np.ndarray, np.ndarray]:
        """S x + b delta + F = 0 with x[1] = r1 for every variant, as
        :func:`lcvreport.analysis.steady.steady_with_yaw_rate`: (x (B, 2N), delta (B,))."""
        c = self.coefficients
        n = c["M0"].shape[-1]
        B = self.size
        K = np.zeros((B, n + 1, n + 1))
        K[:, :n, :n] = tire_scale * (c["S0"] + c["Sinv"] / u) + c["Skin"] + u * c["Su"]
        K[:, :n, n] = tire_scale * c["Bdelta"]
        K[:, n, 1] = 1.0
        rhs = np.zeros((B, n + 1))
        rhs[:, :n] = -np.broadcast_to(np.asarray(F, dtype=float), (B, n))
        rhs[:, n] = r1
        sol = np.linalg.solve(K, rhs[..., None])[..., 0]
        return sol[:, :n], sol[:, n]

    def steady_turn(self, speed_mps: float, tire_scale: float = 1.0, radius_m: float | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
        """(hsso_m, steer [rad]) of every variant in the steady turn of
        :func:`lcvreport.measures.offtracking.steady_turn` (tractor yaw rate u/R)."""
        from ..measures.offtracking import HSSO_RADIUS_M, chain_on_circle
        R = HSSO_RADIUS_M if radius_m is None else float(radius_m)
        u = float(speed_mps)
        omega = u / R
        v = self.vehicle
        x, delta = self._steady(u, np.zeros(v.n_states), omega, tire_scale)
        beta = x @ system_coefficients(v).velocity_map(u).T / u            # (B, N) CG sideslips
        d = chain_on_circle(v, beta, R)                                     # (B, N) the chain on the circle
        steered = max(v.steered_axles, key=lambda a: a.x_m)
        rear = v.units[-1].rearmost_axle
        radius = lambda unit, xp: np.hypot(xp + beta[:, unit] * d[:, unit], d[:, unit])  # noqa: E731
        return radius(v.n_units - 1, rear.x_m) - radius(0, steered.x_m), delta

    def _max_real_at(self, v_kph: np.ndarray, tire_scale: float) -> np.ndarray:
        """max Re(lambda) of variant b at speed v_kph[b, j] [km/h], shape like v_kph (B, J)."""
        from ..units import kph_to_mps
        c = self.coefficients
        u = kph_to_mps(np.asarray(v_kph, dtype=float))[..., None, None]          # (B, J, 1, 1)
        M = c["M0"][:, None] + u * c["M1"][:, None]
        S = tire_scale * (c["S0"][:, None] + c["Sinv"][:, None] / u) + c["Skin"][:, None] + u * c["Su"][:, None]
        return np.linalg.eigvals(solve_scaled(M, S)).real.max(axis=-1)

    def critical_speed(self, tire_scale: float = 1.0, u_min_mps: float | None = None,
                       u_max_kph: float | None = None) -> np.ndarray:
        """The critical speed [km/h] of every variant (NaN: stable up to ``u_max_kph``): see
        :meth:`_critical_speed` (groups of 256 variants)."""
        return self._in_groups("_critical_speed", tire_scale, u_min_mps, u_max_kph)

    def _critical_speed(self, tire_scale: float = 1.0, u_min_mps: float | None = None,
                        u_max_kph: float | None = None) -> np.ndarray:
        """The critical speed [km/h] of every variant (NaN: stable up to ``u_max_kph``), by the
        algorithm of :func:`lcvreport.measures.stability.critical_speed` run on all variants at
        once: the coarse 4 km/h scan, the 1 km/h scan of each variant's own doubtful intervals,
        the bisection to 0.01 km/h, rounded to 0.1 km/h."""
        from ..measures.stability import CRITICAL_SPEED_MAX_KPH, U_MIN_DEFAULT_MPS
        from ..ranges import RANGES
        from ..units import mps_to_kph
        u_max_kph = CRITICAL_SPEED_MAX_KPH if u_max_kph is None else u_max_kph
        lo_kph = mps_to_kph(RANGES["u_min"].check(U_MIN_DEFAULT_MPS if u_min_mps is None else u_min_mps, "u_min"))
        B = self.size
        coarse = np.linspace(lo_kph, u_max_kph, max(int(math.ceil((u_max_kph - lo_kph) / 4.0)) + 1, 2))
        sigma = self._max_real_at(np.broadcast_to(coarse, (B, coarse.size)), tire_scale)     # (B, K)
        step = np.abs(np.diff(sigma, axis=1))
        padded = np.concatenate([step[:, :1], step, step[:, -1:]], axis=1)
        slope = np.maximum(np.maximum(padded[:, :-2], padded[:, 1:-1]), padded[:, 2:])
        near = np.maximum(sigma[:, :-1], sigma[:, 1:]) > -2.0 * slope                      # (B, K-1)
        # the fine points of every interval; a variant evaluates only those of its own doubtful ones
        fine_of = [np.linspace(coarse[i], coarse[i + 1], int(math.ceil(coarse[i + 1] - coarse[i])) + 1)[1:-1]
                   for i in range(coarse.size - 1)]
        fine = np.concatenate(fine_of)
        owner = np.concatenate([np.full(f.size, i) for i, f in enumerate(fine_of)])
        use = near[:, owner]                                                                # (B, F)
        fine_vals = np.full(use.shape, -np.inf)
        rows, cols = np.nonzero(use)
        if rows.size:
            fine_vals[rows, cols] = self._values_at(rows, fine[cols], tire_scale)
        grid = np.concatenate([coarse, fine])
        order = np.argsort(grid, kind="stable")
        grid = grid[order]
        values = np.concatenate([sigma, fine_vals], axis=1)[:, order]
        present = np.concatenate([np.ones((B, coarse.size), bool), use], axis=1)[:, order]
        flags = (values >= 0.0) & present
        out = np.full(B, np.nan)
        found = flags.any(axis=1)
        first = np.argmax(flags, axis=1)
        at_start = found & (first == 0)
        out[at_start] = np.round(grid[0], 1)
        todo = np.flatnonzero(found & (first > 0))
        if todo.size:
            # the previous evaluated grid point of each variant
            idx = np.arange(grid.size)
            prev = np.array([idx[present[b] & (idx < first[b])].max() for b in todo])
            lo, hi = grid[prev].astype(float), grid[first[todo]].astype(float)
            active = hi - lo > 0.01
            while active.any():
                mid = 0.5 * (lo + hi)
                m = np.flatnonzero(active)
                unstable = self._values_at(todo[m], mid[m], tire_scale) >= 0.0
                hi[m] = np.where(unstable, mid[m], hi[m])
                lo[m] = np.where(unstable, lo[m], mid[m])
                active = hi - lo > 0.01
            out[todo] = np.round(0.5 * (lo + hi), 1)
        return out

    def _values_at(self, variants: np.ndarray, v_kph: np.ndarray, tire_scale: float) -> np.ndarray:
        """max Re(lambda) of variant ``variants[k]`` at ``v_kph[k]`` [km/h], shape (K,)."""
        from ..units import kph_to_mps
        c = self.coefficients
        u = kph_to_mps(np.asarray(v_kph, dtype=float))[:, None, None]
        M = c["M0"][variants] + u * c["M1"][variants]
        S = tire_scale * (c["S0"][variants] + c["Sinv"][variants] / u) + c["Skin"][variants] + u * c["Su"][variants]
        return np.linalg.eigvals(solve_scaled(M, S)).real.max(axis=-1)

    def measure_group(self, name: str, speed_mps: float, tire_scale: float = 1.0, f_hz: float | None = None,
                      F=None) -> tuple:
        """The arrays of one group of :data:`lcvreport.measures.registry.BATCHED` (``name``: the
        method), in the order of its keys.  ``F`` (B, 2N) is every variant's generalized force of
        its residual sources (the trim's; NaN rows: none)."""
        from .frequency import RA_FREQUENCY_HZ
        f_hz = RA_FREQUENCY_HZ if f_hz is None else f_hz
        if name == "critical_speed":
            return (self.critical_speed(tire_scale),)
        if name == "rearward_amplification":
            return (self.rearward_amplification(speed_mps, f_hz, tire_scale),)
        if name == "single_sine":
            return (self.single_sine(speed_mps, f_hz, tire_scale),)
        if name == "yaw_damping":
            from ..measures.yaw_damping import YDC_HEAVY_ZETA
            zeta = self.yaw_damping(speed_mps, tire_scale)
            bound = np.where(np.isnan(zeta) & (self.vehicle.n_units > 1), YDC_HEAVY_ZETA, np.nan)
            return zeta, bound
        if name == "trim":
            if F is None:
                return np.full(self.size, np.nan), np.full(self.size, np.nan)
            F = np.asarray(F, dtype=float)
            out = (np.full(len(F), np.nan), np.full(len(F), np.nan))
            has = np.isfinite(F[:, 0])
            if has.any():                       # a batch of one variant under several forces: one row each
                rows = np.flatnonzero(has) if self.size > 1 else np.zeros(int(has.sum()), int)
                out[0][has], out[1][has] = self._subset(rows).trim(speed_mps, F[has], tire_scale)
            return out
        result = getattr(self, name)(speed_mps, tire_scale)
        return tuple(result)

    def measures(self, speed_mps: float, tire_scale: float = 1.0, f_hz: float | None = None, F=None):
        """The batched measures of every variant as columns (a dict of arrays of length B, ready
        for ``pandas.DataFrame``): a ``case_id``, one column per varied parameter and every
        measure of :data:`lcvreport.measures.registry.BATCHED` under its registry key (the trim's,
        ``trim.delta_rad`` and ``trim.offtracking_m``, with ``F``); NaN where a measure is
        undefined (no oscillatory mode, stable to 200 km/h)."""
        from ..measures.registry import BATCHED
        table = {"case_id": np.arange(self.size)}
        table.update({name: np.asarray(arr, dtype=float) for name, arr in self.values.items()})
        table["speed_mps"] = np.full(self.size, float(speed_mps))
        for group, keys in BATCHED.items():
            if group == "trim" and F is None:
                continue
            for key, arr in zip(keys, self.measure_group(group, speed_mps, tire_scale, f_hz, F)):
                table[key] = np.asarray(arr, dtype=float)
        return table
