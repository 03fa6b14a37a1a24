"""Exact response to continuous steer inputs and constant residual sources (docs/manoeuvres.md).

On each piece of the input (:mod:`lcvreport.manoeuvres.steer`) the model, the global
position (psi1, Y1), the input's generator ``xi' = E xi`` and a constant 1 form one
homogeneous linear system ``z' = Mz z``::

    z = [x, psi1, Y1, xi, 1],   Mz = [[A_aug, b h, g], [0, E, 0], [0, 0, 0]]

so ``z(t + s) = exp(Mz s) z(t)`` exactly, for any s.  Samples on a uniform grid take one
exponential per piece and a doubling scan (``Z[k:2k] = Z[0:k] Phi^k``, log2 K products).
Every output is linear in z (``c . z``), so its time derivatives are ``c Mz z`` and
``c Mz^2 z``: the extrema of an output are located between the samples on the
continuous response (a cubic Hermite interpolant of the derivative through its exact
values and slopes at two samples, whose error is O(dt^4)), and their values from a
quintic Hermite interpolant (O(dt^6)).

The lane change prescribes the steered axle's lateral acceleration ``a_s`` instead of
the steer: ``a_s = C_s x + D_s delta + f_s`` (``D_s != 0``: direct feed-through), so
``delta = (a_s - C_s x - f_s) / D_s`` and the model is driven by ``a_s`` through
``A - b C_s / D_s`` (the inverse system).  Its eigenvalues are the zeros of the
transfer function from the steer to ``a_s``; one in the right half plane makes the
manoeuvre impossible for a driver to follow, and it is refused.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.manoeuvres.steer import sine
>>> r = response(load_preset("tractor_semitrailer"), 24.4444, sine(0.01, 0.4), t_end=10.0, dt=0.01)
>>> r.time.shape, r["ay2"].shape
((1001,), (1001,))
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..manoeuvres.steer import SteerInput
from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.outputs import rear_end_weights
from ..util.numerics import expm as _expm_checked
from ..util.threads import one_blas_thread
from .discretize import augmented_state_matrix
from .extrema import _hermite_roots, _quintic, _scan


class ManoeuvreError(ValueError):
    """A manoeuvre the vehicle cannot perform (e.g. an unstable inverse system)."""


@dataclass
class _Segment:
    """One piece on the sample grid: the augmented matrix, its output rows, the samples."""

    Mz: np.ndarray
    C: np.ndarray                 # (signals, dim): every linear output from z
    k0: int                       # first sample index in the piece
    Z: np.ndarray                 # (samples, dim)
    t0: float                     # the piece's start [s]
    z_start: np.ndarray           # z at t0
    z_end: np.ndarray | None = None
    t1: float = math.inf


@dataclass
class ManoeuvreResponse:
    """The exact response of one vehicle to one manoeuvre, sampled on a uniform grid.

    Signals (SI) by name: ``delta`` [rad], the states (``v1``, ``r1``.., ``theta..``),
    ``psi1`` [rad], ``Y1`` [m], ``ay1..ayN`` [m/s^2] (unit CGs), ``a_steer`` [m/s^2]
    (the steered axle's centre), ``Y_<axle>`` [m] (every axle centre's global lateral
    position, first order), ``y2..yN`` [m] (rear ends from the tractor axis).  Use
    ``r["ay3"]``, :meth:`extrema`, :meth:`plot`, :meth:`to_rows`.
    """

    vehicle: Vehicle
    speed_mps: float
    steer: SteerInput
    time: np.ndarray
    signal_names: tuple
    segments: list = field(repr=False)
    _y_rows: np.ndarray = field(repr=False, default=None)
    _H: np.ndarray = field(repr=False, default=None)

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "time_s":
            return self.time
        if name.startswith("y") and name[1:].isdigit():
            k = int(name[1:])
            return self._rear_offsets()[:, k - 2]
        j = self._index(name)
        return np.concatenate([seg.Z @ seg.C[j] for seg in self.segments])

    def _index(self, name: str) -> int:
        try:
            return self.signal_names.index(name)
        except ValueError:
            raise KeyError(f"no signal {name!r}; signals: {', '.join(self.signal_names)}, y2..") from None

    def _rear_offsets(self) -> np.ndarray:
        Theta = self._hidden("Theta")
        y = np.sin(Theta) @ rear_end_weights(self.vehicle).T
        roll = self._hidden("Roff")                  # the yaw-roll model's coupling roll offsets
        return y + roll if roll.shape[1] else y

    def _hidden(self, prefix: str) -> np.ndarray:
        rows = [j for j, n in enumerate(self.signal_names) if n.startswith(prefix)]
        if not rows:
            return np.zeros((self.time.size, 0))
        return np.concatenate([seg.Z @ (seg.C[rows].T) for seg in self.segments])

    def columns(self) -> list[str]:
        """Output columns with units, in the order of :meth:`matrix`."""
        out = ["time_s"]
        for n in self.signal_names:
            if not _is_hidden(n):
                out.append(_column(n))
        out += [f"y{k}_m" for k in range(2, self.vehicle.n_units + 1)]
        return out

    def matrix(self) -> np.ndarray:
        """Every signal at every sample, columns as :meth:`columns`."""
        keep = [j for j, n in enumerate(self.signal_names) if not _is_hidden(n)]
        with np.errstate(over="ignore", invalid="ignore"):     # an overflowed (unstable) run: callers refuse it
            lin = np.concatenate([seg.Z @ seg.C[keep].T for seg in self.segments])
            return np.column_stack([self.time, lin, self._rear_offsets()])

    def to_rows(self, names: list[str] | None = None) -> list[dict]:
        """Rows for a table or CSV (``time_s`` and the named signals, default all)."""
        cols = self.columns()
        M = self.matrix()
        keep = list(range(len(cols))) if names is None else [0] + [
            i for i, c in enumerate(cols) if c.rsplit("_", 1)[0] in names or c in names]
        return [{cols[i]: float(row[i]) for i in keep} for row in M]

    def extrema(self, name: str, t_from: float = 0.0, t_to: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        """Times [s] and values of the local extrema of signal ``name`` in ``[t_from,
        t_to]`` on the continuous response, plus the values at the ends of that window
        and at the input's breakpoints (where the derivative may jump)."""
        return self.extrema_many([name], t_from, t_to)[0]

    def extrema_many(self, names, t_from: float = 0.0, t_to: float = math.inf) -> list:
        """:meth:`extrema` of several signals at once (one product per piece for all of them):
        a list of (times, values), in the order of ``names``."""
        js = [self._index(n) for n in names]
        K = len(js)
        times = [[] for _ in js]
        values = [[] for _ in js]
        for seg in self.segments:
            t = self.time[seg.k0:seg.k0 + len(seg.Z)]
            if t.size == 0:
                continue
            c = seg.C[js].T                                   # (dim, K)
            c1 = seg.Mz.T @ c
            c2 = seg.Mz.T @ c1
            dt = t[1] - t[0] if t.size > 1 else 0.0
            if t.size > 1:
                D1 = c1.T @ seg.Z.T                           # the derivatives at the samples: (K, samples)
                pos = D1 > 0
                # a sign change of the derivative (one side > 0, the other <= 0: a flat stretch of
                # zeros is none), in an interval that reaches into the window
                change = pos[:, :-1] != pos[:, 1:]
                if t[0] < t_from or t[-1] > t_to:
                    change &= (t[1:] >= t_from) & (t[:-1] <= t_to)
                sig, k = np.divmod(np.flatnonzero(change), t.size - 1)   # by signal, then by time
                if k.size:
                    k1 = k + 1
                    W = np.concatenate([c, c2], axis=1)       # values and second derivatives, at the ends only
                    Ya, Yb = seg.Z[k] @ W, seg.Z[k1] @ W
                    rows = np.arange(k.size)
                    ya, sa, yb, sb = Ya[rows, sig], Ya[rows, K + sig], Yb[rows, sig], Yb[rows, K + sig]
                    da, db = D1[sig, k], D1[sig, k1]
                    tau = _hermite_roots(da, sa, db, sb, dt)
                    tk = t[k] + tau * dt
                    val = _quintic(ya, da, sa, yb, db, sb, dt, tau)
                    keep = (tk >= t_from) & (tk <= t_to)
                    sig, tk, val = sig[keep], tk[keep], val[keep]
                    bounds = np.searchsorted(sig, np.arange(K + 1))
                    for s_ in range(K):
                        lo, hi = bounds[s_], bounds[s_ + 1]
                        if hi > lo:
                            times[s_].extend(tk[lo:hi].tolist())
                            values[s_].extend(val[lo:hi].tolist())
            # the piece's own ends
            for tb, zb in ((seg.t0, seg.z_start), (seg.t1, seg.z_end)):
                if zb is not None and t_from <= tb <= t_to and math.isfinite(tb):
                    vb = zb @ c
                    for s in range(K):
                        times[s].append(tb)
                        values[s].append(float(vb[s]))
        out = []
        for s, name in enumerate(names):                      # the ends of the window
            for tb in (t_from, min(t_to, self.time[-1])):
                if self.time[0] <= tb <= self.time[-1]:
                    times[s].append(tb)
                    values[s].append(self.value_at(name, tb))
            order = np.argsort(times[s])
            out.append((np.asarray(times[s])[order], np.asarray(values[s])[order]))
        return out

    def value_at(self, name: str, t: float) -> float:
        """The exact value of signal ``name`` at time ``t`` [s] (within the sampled span)."""
        j = self._index(name)
        if not self.time[0] <= t <= self.time[-1]:
            raise ValueError(f"t = {t} s is outside the response [{self.time[0]}, {self.time[-1]}] s")
        for seg in self.segments:
            if seg.t0 <= t < seg.t1 or seg is self.segments[-1]:
                ts = self.time[seg.k0:seg.k0 + len(seg.Z)]
                k = int(np.searchsorted(ts, t, side="right")) - 1
                t_base, z = (seg.t0, seg.z_start) if k < 0 else (ts[k], seg.Z[k])
                if t == t_base:                         # a sample (or the piece's start): no exponential
                    return float(seg.C[j] @ z)
                return float(seg.C[j] @ expm(seg.Mz * (t - t_base)) @ z)
        raise ValueError(f"t = {t} s is outside the response")  # pragma: no cover

    def peak_abs(self, name: str, t_from: float = 0.0, t_to: float = math.inf) -> float:
        """max |signal| over ``[t_from, t_to]`` on the continuous response."""
        _t, v = self.extrema(name, t_from, t_to)
        return float(np.abs(v).max())

    def peaks_abs(self, names, t_from: float = 0.0, t_to: float = math.inf) -> np.ndarray:
        """:meth:`peak_abs` of several signals at once."""
        return np.array([float(np.abs(v).max()) for _t, v in self.extrema_many(names, t_from, t_to)])

    def plot(self, signals: list[str] | None = None, ax=None):
        """Plot signals against time (default: the steer and every unit's ay)."""
        from ..plotting.time import plot_manoeuvre
        return plot_manoeuvre(self, signals, ax)


#: the unit of every signal, by the start of its name (first match); ``ltr<g>`` is dimensionless
_UNITS = (("delta", "rad"), ("theta", "rad"), ("psi", "rad"), ("phi", "rad"), ("ay", "m_per_s2"),
          ("as", "m_per_s2"), ("a_steer", "m_per_s2"), ("dFz_", "N"), ("ltr", ""), ("Y", "m"), ("v", "m_per_s"),
          ("r", "rad_per_s"), ("p", "rad_per_s"))


def _column(name: str) -> str:
    """The column header of a signal: its name and unit (``phi2_rad``, ``dFz_a1_N``, ``ltr1``)."""
    unit = next((u for prefix, u in _UNITS if name.startswith(prefix)), "m")
    return f"{name}_{unit}" if unit else name


def _is_hidden(name: str) -> bool:
    """Rows kept for the rear offsets, not output columns."""
    return name.startswith("Theta") or name.startswith("Roff")


def steered_point(vehicle: Vehicle) -> float:
    """Signed x [m] of the frontmost steered axle on the first unit."""
    if not vehicle.steered_axles:
        raise ManoeuvreError(f"{vehicle.name} has no steered axle: no steer input to apply")
    return max(a.x_m for a in vehicle.steered_axles)


def _steer_axle_maps(vehicle, speed_mps, tire_scale, model: str = "yaw_plane"):
    """x' = A x + b delta (+ G F); a_s = Cs x + Ds delta (+ Js G F)."""
    co = linear_model(vehicle, model)
    A, G = co.state_derivative_maps(speed_mps, tire_scale)
    b = G @ co.B_delta(tire_scale)
    xs = steered_point(vehicle)
    Js = np.zeros(A.shape[0])
    Js[0], Js[1] = 1.0, xs                      # v_s = v1 + x_s r1
    Cs = Js @ A
    Cs[1] += float(speed_mps)                   # a_s = v_s' + u r1
    return A, b, Cs, float(Js @ b)


@one_blas_thread
def expm(A: np.ndarray) -> np.ndarray:
    """The matrix exponential (:func:`lcvreport.util.numerics.expm`: Al-Mohy & Higham 2009, the
    algorithm of scipy's, without importing scipy.linalg -- 0.2 s of every command's start-up); NaN
    where it is not finite (an unstable run's overflow: the callers refuse non-finite responses)."""
    try:
        return _expm_checked(A)
    except FloatingPointError:
        return np.full(np.shape(A), np.nan)


def response(vehicle: Vehicle, speed_mps: float, steer: SteerInput, t_end: float, dt: float,
             F: np.ndarray | None = None, tire_scale: float = 1.0, t_start: float = 0.0,
             state: np.ndarray | None = None, model: str = "yaw_plane",
             axle_force_N: np.ndarray | None = None) -> ManoeuvreResponse:
    """The exact response from rest to ``steer`` (continuous) and the constant
    generalized force ``F`` (residual sources, SI), sampled every ``dt`` to ``t_end``.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    steer : SteerInput
        See :mod:`lcvreport.manoeuvres.steer`; a lane change is solved through the
        inverse system.
    t_end, dt : float
        End time and output step [s]; ``dt`` must divide ``t_end``.
    F : numpy.ndarray, optional
        Constant generalized force (n,) of the residual sources, SI: :func:`lcvreport.load_vector` or
        :meth:`lcvreport.model.yaw_plane.loads.ResidualSources.vector`.
    tire_scale : float
    t_start, state : float, numpy.ndarray, optional
        Start later than 0 from ``state`` = [x, psi1, Y1] at ``t_start`` (a run in
        chunks); the samples are then ``t_start + k dt``.
    model : str
        The linear model (:data:`lcvreport.model.linear.MODELS`; default the yaw plane):
        its states, and the positions, accelerations and further outputs it defines
        (:meth:`~lcvreport.model.linear.LinearModel.extra_signals`: the yaw-roll model's
        ``as<i>``, ``dFz_<axle>``, ``ltr<g>``).
    axle_force_N : numpy.ndarray, optional
        Each axle's constant lateral tire force of the residual sources [N] (P plus the
        misalignment's ``s C_F eps``): the load transfer outputs include it.

    Raises
    ------
    ManoeuvreError
        No steered axle; a lane change whose inverse system is unstable.
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    u = float(speed_mps)
    span = t_end - t_start
    n_steps = int(round(span / dt))
    if n_steps < 1 or abs(n_steps * dt - span) > 1e-9 * max(span, 1.0):
        raise ValueError(f"dt = {dt:g} s must divide t_end - t_start = {span:g} s")
    co = linear_model(vehicle, model)
    n = co.n_states
    nu = vehicle.n_units
    m = n + 2
    Aa, Ga = augmented_state_matrix(co, u, tire_scale)
    F = np.zeros(n) if F is None else np.asarray(F, dtype=float)
    gF = Ga @ F                                           # constant forcing of [x, psi1, Y1]
    bd_x = Ga @ co.B_delta(tire_scale)
    Ca, Da = co.acceleration_maps(u, tire_scale)
    da = Da @ co.B_delta(tire_scale)
    aF = Da @ F
    lane = steer.prescribes_acceleration
    if lane:
        A_x, b, Cs, Ds = _steer_axle_maps(vehicle, u, tire_scale, model)
        if abs(Ds) < 1e-12 * max(1.0, np.abs(Cs).max()):
            raise ManoeuvreError("lane change: the steer does not reach the steered axle's lateral acceleration "
                                 "directly; the inverse system does not exist")
        zeros = np.linalg.eigvals(A_x - np.outer(b, Cs) / Ds)
        if zeros.real.max() > 1e-9 * max(1.0, np.abs(zeros).max()):
            worst = zeros[np.argmax(zeros.real)]
            raise ManoeuvreError(f"lane change at {u * 3.6:.1f} km/h: the inverse system is unstable (a right-half-"
                                 f"plane zero of the steer-to-axle-acceleration transfer function at "
                                 f"{worst.real:.4g}{worst.imag:+.4g}j 1/s): no steer makes the steered axle "
                                 "follow the path; the manoeuvre is refused")
        fs = float(np.r_[1.0, steered_point(vehicle)] @ (co.state_derivative_maps(u, tire_scale)[1] @ F)[:2])
    driver = steer.driver
    if driver is not None:
        if not vehicle.steered_axles:
            raise ManoeuvreError(f"{steer.spec}: the vehicle has no steered axle for the driver to steer")
        closed = Aa.copy()
        closed[:, n + 1] -= driver[0] * bd_x
        closed[:, n] -= driver[0] * u * driver[1] * bd_x
        poles = np.linalg.eigvals(closed)
        if poles.real.max() > 1e-9 * max(1.0, np.abs(poles).max()):
            worst = poles[np.argmax(poles.real)]
            raise ManoeuvreError(f"{steer.spec} at {u * 3.6:.1f} km/h: the driver's closed loop is unstable (a pole at "
                                 f"{worst.real:.4g}{worst.imag:+.4g}j 1/s): lower the gain K or lengthen the preview "
                                 "T; the manoeuvre is refused")
    # signal rows over [x, psi1, Y1] (before the input's own part): states, psi1, Y1, ay, a_steer, Y_axles, Theta
    names = list(co.state_names) + ["psi1", "Y1"]
    V_ay = np.zeros((nu, m))
    V_ay[:, :n] = Ca
    names_ay = [f"ay{i + 1}" for i in range(nu)]
    xs = steered_point(vehicle) if vehicle.steered_axles else None
    Y_rows, Y_names = [], []
    cum = co.heading_rows()
    for i, unit in enumerate(vehicle.units):
        for a in unit.axles:
            Y_rows.append(co.point_lateral_row(i, a.x_m))
            Y_names.append(f"Y_{a.name}")
    ex_names, EX, EXD, ED, EO = co.extra_signals(u, tire_scale)
    ex_const = EO @ (np.zeros(len(vehicle.axles)) if axle_force_N is None else np.asarray(axle_force_N, float))
    roll_rows = co.roll_offset_rows()
    hidden_roll = [] if roll_rows is None else [f"Roff{k + 2}" for k in range(nu - 1)]
    ne = len(ex_names)
    signal_names = tuple(["delta"] + names + names_ay + ["a_steer"] + Y_names + list(ex_names) +
                         [f"Theta{k + 2}" for k in range(nu - 1)] + hidden_roll)
    segments = []
    t_grid = t_start + np.arange(n_steps + 1) * dt
    z_state = np.zeros(m) if state is None else np.asarray(state, dtype=float)   # [x, psi1, Y1]
    for piece in steer.pieces:
        if piece.t0 > t_end + 1e-12:
            break
        if piece.t1 <= t_start + 1e-12 * max(1.0, t_start):
            continue
        if piece.t0 < t_start:                     # the piece began before this run: move its generator on
            piece = type(piece)(t_start, piece.t1, piece.E, piece.h, expm(piece.E * (t_start - piece.t0)) @ piece.xi0)
        p = piece.E.shape[0]
        dim = m + p + 1
        Mz = np.zeros((dim, dim))
        if lane:
            # x' = (A - b Cs/Ds) x + b (a_s - fs)/Ds + G F; psi1, Y1 as before
            Mz[:m, :m] = Aa
            Mz[:n, :n] = A_x - np.outer(b, Cs) / Ds
            Mz[:n, m:m + p] = np.outer(b, piece.h) / Ds
            Mz[:m, -1] = gF
            Mz[:n, -1] -= b * fs / Ds
        elif driver is not None:
            # the preview driver: delta = K (path - Y1 - u T psi1), the path generated by the piece
            d_row = np.zeros(dim)
            d_row[m:m + p] = driver[0] * piece.h
            d_row[n + 1] = -driver[0]
            d_row[n] = -driver[0] * u * driver[1]
            Mz[:m, :m] = Aa
            Mz[:m] += np.outer(bd_x, d_row)
            Mz[:m, -1] = gF
        else:
            Mz[:m, :m] = Aa
            Mz[:m, m:m + p] = np.outer(bd_x, piece.h)
            Mz[:m, -1] = gF
        Mz[m:m + p, m:m + p] = piece.E
        # output rows over z = [x, psi1, Y1, xi, 1]
        if lane:
            d_row = np.zeros(dim)
            d_row[:n] = -Cs / Ds
            d_row[m:m + p] = piece.h / Ds
            d_row[-1] = -fs / Ds
        elif driver is None:
            d_row = np.zeros(dim)
            d_row[m:m + p] = piece.h
        # rows: the steer, the states and psi1, Y1, ay of every unit, a_steer, Y of every axle, Theta
        C = np.zeros((1 + m + nu + 1 + len(Y_rows) + ne + (nu - 1) * (1 + bool(hidden_roll)), dim))
        C[0] = d_row
        C[1:1 + m, :m] = np.eye(m)
        r0 = 1 + m
        C[r0:r0 + nu, :m] = V_ay
        C[r0:r0 + nu] += np.outer(da, d_row)
        C[r0:r0 + nu, -1] += aF
        r0 += nu
        if xs is not None:
            # a_s = v1' + x_s r1' + u r1: from the state derivative
            C[r0] = Mz[0] + xs * Mz[1]
            C[r0, 1] += u
        r0 += 1
        if Y_rows:
            C[r0:r0 + len(Y_rows), :m] = Y_rows
        r0 += len(Y_rows)
        if ne:
            # y = X x + XD x' + D delta + O F_y0, x' from the augmented dynamics' first n rows
            C[r0:r0 + ne, :n] = EX
            C[r0:r0 + ne] += EXD @ Mz[:n]
            C[r0:r0 + ne] += np.outer(ED, d_row)
            C[r0:r0 + ne, -1] += ex_const
        r0 += ne
        C[r0:r0 + nu - 1, :m] = cum
        if hidden_roll:
            C[r0 + nu - 1:r0 + 2 * (nu - 1), :n] = roll_rows
        z0 = np.r_[z_state, piece.xi0, 1.0]
        t1 = min(piece.t1, math.inf)
        ka = int(math.ceil((piece.t0 - t_start) / dt - 1e-9))
        kb = n_steps if t1 > t_end + 1e-12 else int(math.ceil((t1 - t_start) / dt - 1e-9)) - 1
        count = kb - ka + 1
        if count > 0:
            ta = t_start + ka * dt
            za = z0 if abs(ta - piece.t0) <= 1e-12 * max(1.0, piece.t0) else expm(Mz * (ta - piece.t0)) @ z0
            Phi = expm(Mz * dt)
            Z = _scan(Phi, za, count)
            z_end = expm(Mz * (t1 - (t_start + kb * dt))) @ Z[-1] \
                if math.isfinite(t1) and t1 <= t_end + 1e-12 else None
        else:
            Z = np.zeros((0, dim))
            z_end = expm(Mz * (t1 - piece.t0)) @ z0 if math.isfinite(t1) else None
        segments.append(_Segment(Mz, C, ka, Z, piece.t0, z0, z_end, t1))
        if z_end is None:
            break
        z_state = z_end[:m]
    return ManoeuvreResponse(vehicle, u, steer, t_grid, signal_names, segments)


def check_lane_change_steer(r: ManoeuvreResponse, peak_rad: float | None = None) -> None:
    """Refuse a lane change whose steer -- the output of the inverse system, not an input the
    user gave -- leaves the steer range of the ranges table ([-1, 1] rad: far beyond the small
    angles of the linear model), naming the peak steer it would need.  ``peak_rad`` is max|delta|
    when the caller has it (else it is located on the continuous response).

    Raises
    ------
    ManoeuvreError
    """
    from ..ranges import RANGES
    if not r.steer.prescribes_acceleration and r.steer.driver is None:
        return
    peak = float(r.peaks_abs(["delta"])[0]) if peak_rad is None else float(peak_rad)
    rng = RANGES["steer_angle"]
    if not peak <= rng.high:
        raise ManoeuvreError(f"{r.steer.spec} at {r.speed_mps * 3.6:.4g} km/h needs a peak steer of {peak:.4g} rad, "
                             f"outside the steer range {rng.text()} (the linear model's small angles): lower A0 or "
                             "the frequency, or raise the speed; the manoeuvre is refused")


def final_state(r: ManoeuvreResponse) -> np.ndarray:
    """[x, psi1, Y1] at the last sample of ``r`` (to continue a run in chunks)."""
    seg = r.segments[-1]
    m = r.signal_names.index("Y1")               # delta, the n states, psi1, Y1: z = [x, psi1, Y1] is n + 2 long
    return seg.Z[-1, :m].copy()
