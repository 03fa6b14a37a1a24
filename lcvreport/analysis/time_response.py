"""The one time response of the package: :class:`TimeResponse`, every exact response sampled,
with every signal by name and unit.

A response is a chain of pieces (:class:`Segment`); on each, the model, the global position
(psi1, Y1), the input's generator and a constant 1 form one homogeneous linear system
``z' = Mz z`` (``z = [x, psi1, Y1, xi, 1]``), so every signal is a row over z (``c . z``) and
its time derivatives are ``c Mz z`` and ``c Mz^2 z``: the extrema of any signal are located
between the samples on the continuous response (:mod:`lcvreport.analysis.extrema`: a cubic
Hermite interpolant of the derivative through its exact values and slopes, O(dt^4), the value
from a quintic one, O(dt^6)).  The runs that make responses are in
:mod:`lcvreport.analysis.response` (inputs held over intervals) and
:mod:`lcvreport.analysis.exact` (continuous steer inputs).

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.analysis.exact import response
>>> from lcvreport.manoeuvres.steer import sine
>>> r = response(load_preset("tractor_semitrailer"), 24.4444, sine(0.01, 0.4), t_end=10.0, dt=0.01)
>>> r["ay2"].shape, r.units()["ay2"], column("ay2")
((1001,), 'm/s^2', 'ay2_m_per_s2')
>>> round(float(abs(r["ay2"]).max()), 6), round(r.peak_abs("ay2"), 6)   # sampled; located between samples
(0.42677, 0.426772)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from ..model.linear import linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.outputs import rear_end_weights
from ..util.numerics import expm as _expm_checked
from ..util.threads import one_blas_thread
from .discretize import GLOBAL_STATES
from .extrema import hermite_roots, quintic_hermite

#: the unit of every signal by the start of its name (first match): (prefix, column suffix, unit)
SIGNAL_UNITS = (("delta", "rad", "rad"), ("theta", "rad", "rad"), ("psi", "rad", "rad"), ("phi", "rad", "rad"),
                ("ay", "m_per_s2", "m/s^2"), ("as", "m_per_s2", "m/s^2"), ("a_steer", "m_per_s2", "m/s^2"),
                ("dFz_", "N", "N"), ("ltr", "", "-"), ("Y", "m", "m"), ("y", "m", "m"),
                ("v", "m_per_s", "m/s"), ("r", "rad_per_s", "rad/s"), ("p", "rad_per_s", "rad/s"))


def signal_unit(name: str) -> str:
    """The unit of a signal as a person reads it (``"m/s^2"``, ``"rad"``, ``"-"``).

    Examples
    --------
    >>> signal_unit("ay2"), signal_unit("dFz_a11"), signal_unit("ltr1")
    ('m/s^2', 'N', '-')
    """
    return next((u for prefix, _s, u in SIGNAL_UNITS if name.startswith(prefix)), "m")


def column(name: str) -> str:
    """The column header of a signal: its name and unit (``phi2_rad``, ``dFz_a1_N``, ``ltr1``).

    Examples
    --------
    >>> column("ay2"), column("Y_rear"), column("ltr1")
    ('ay2_m_per_s2', 'Y_rear_m', 'ltr1')
    """
    unit = next((s for prefix, s, _u in SIGNAL_UNITS if name.startswith(prefix)), "m")
    return f"{name}_{unit}" if unit else name


def _is_hidden(name: str) -> bool:
    """Rows kept for the rear offsets, not signals."""
    return name.startswith("Theta") or name.startswith("Roff")


@one_blas_thread
def expm(A: np.ndarray) -> np.ndarray:
    """The matrix exponential (:func:`lcvreport.util.numerics.expm`: Al-Mohy & Higham 2009, the
    algorithm of scipy's, without importing scipy.linalg -- 0.2 s of every command's start-up); NaN
    where it is not finite (an unstable run's overflow: the callers refuse non-finite responses)."""
    try:
        return _expm_checked(A)
    except FloatingPointError:
        return np.full(np.shape(A), np.nan)


@dataclass
class Segment:
    """One piece of a response: its dynamics ``z' = Mz z``, the signal rows ``C`` over z, its
    samples ``Z`` (rows: the time points ``k0, k0 + 1, ...`` of the response), and the piece's start ``t0`` and end ``t1`` with z there (``z_end`` None when the response ends
    inside the piece)."""

    Mz: np.ndarray
    C: np.ndarray
    k0: int
    Z: np.ndarray
    t0: float
    z_start: np.ndarray
    z_end: np.ndarray | None = None
    t1: float = math.inf


@dataclass
class TimeResponse:
    """The exact response of one vehicle, sampled, with every signal by name (SI).

    Signals: ``delta`` [rad] (where the run knows the steer), the model's states (``v1`` [m/s],
    ``r1``.. [rad/s], ``theta..`` [rad]; the yaw-roll model's ``p<i>``, ``phi<i>``), ``psi1``
    [rad], ``Y1`` [m], ``ay1..ayN`` [m/s^2] (unit CGs), ``a_steer`` [m/s^2] (the steered axle's
    centre), ``Y_<axle>`` and ``Y_rear`` [m] (global lateral positions, first order), the model's
    further outputs (``as<i>``, ``dFz_<axle>``, ``ltr<g>``), ``y2..yN`` [m] (rear ends from the
    tractor axis).  ``r["ay3"]`` or ``r["ay3_m_per_s2"]``; :meth:`extrema` on the continuous
    response; :meth:`to_pandas`, :meth:`to_rows`, :meth:`plot`.

    Attributes
    ----------
    vehicle : Vehicle
    time : numpy.ndarray, shape (K,)
        [s]
    segments : list of Segment
    speed_mps : float or numpy.ndarray
        Forward speed [m/s]; per sample, shape (K,), when it changes along the run.
    model : str
    tire_scale : float
    steer : SteerInput or None
        The continuous steer input of a manoeuvre.
    label : str

    Examples
    --------
    >>> from lcvreport import load_preset, simulate
    >>> from lcvreport.manoeuvres.steer import sine
    >>> r = simulate(load_preset("aucnat"), 24.4, steer=sine(0.01, 0.4), t_end=5.0)  # doctest: +SKIP
    >>> r["ay6"].shape  # doctest: +SKIP
    """

    vehicle: Vehicle
    time: np.ndarray
    row_names: tuple = field(repr=False)
    segments: list = field(repr=False)
    speed_mps: float | np.ndarray = 0.0
    model: str = "yaw_plane"
    tire_scale: float = 1.0
    steer: object = None
    label: str = ""

    # ------------------------------------------------------------------ names and units
    @property
    def signal_names(self) -> tuple[str, ...]:
        """Every signal, in the order of :meth:`columns`."""
        return tuple(n for n in self.row_names if not _is_hidden(n)) + tuple(
            f"y{k}" for k in range(2, self.vehicle.n_units + 1))

    @property
    def names(self) -> tuple[str, ...]:
        """The states of ``z = [x, psi1, Y1]``: the model's, then psi1, Y1."""
        return linear_model(self.vehicle, self.model).state_names + GLOBAL_STATES

    def units(self) -> dict:
        """``{signal: unit}`` as a person reads it (``"m/s^2"``, ``"rad"``, ``"-"``)."""
        return {n: signal_unit(n) for n in self.signal_names}

    def columns(self) -> list[str]:
        """Column headers with units (``time_s``, ``ay2_m_per_s2`` ...), in the order of :meth:`matrix`."""
        return ["time_s"] + [column(n) for n in self.signal_names]

    # ------------------------------------------------------------------ values
    def __getitem__(self, name: str) -> np.ndarray:
        """A signal by name or by column header (``"ay2"``, ``"ay2_m_per_s2"``, ``"time_s"``)."""
        if name == "time_s":
            return self.time
        name = self._signal(name)
        if name.startswith("y") and name[1:].isdigit():
            return self._rear_offsets()[:, int(name[1:]) - 2]
        j = self._index(name)
        return np.concatenate([seg.Z @ seg.C[j] for seg in self.segments])

    def _signal(self, name: str) -> str:
        if name in self.row_names or (name.startswith("y") and name[1:].isdigit()
                                      and 2 <= int(name[1:]) <= self.vehicle.n_units):
            return name
        for s in self.signal_names:
            if column(s) == name:
                return s
        raise KeyError(f"no signal {name!r}; signals: {', '.join(self.signal_names)}")

    def _index(self, name: str) -> int:
        try:
            return self.row_names.index(name)
        except ValueError:
            raise KeyError(f"no signal {name!r}; signals: {', '.join(self.signal_names)}") from None

    def _rear_offsets(self) -> np.ndarray:
        Theta = self._hidden("Theta")
        y = np.sin(Theta) @ rear_end_weights(self.vehicle).T
        roll = self._hidden("Roff")                  # the yaw-roll model's coupling roll offsets
        return y + roll if roll.shape[1] else y

    def _hidden(self, prefix: str) -> np.ndarray:
        rows = [j for j, n in enumerate(self.row_names) if n.startswith(prefix)]
        if not rows:
            return np.zeros((self.time.size, 0))
        return np.concatenate([seg.Z @ (seg.C[rows].T) for seg in self.segments])

    @property
    def states(self) -> np.ndarray:
        """``[x, psi1, Y1]`` at every sample, shape (K, n + 2)."""
        m = len(self.names)
        return np.concatenate([seg.Z[:, :m] for seg in self.segments])

    @property
    def theta(self) -> np.ndarray:
        """Articulation angles [rad], shape (K, N-1)."""
        names = [n for n in self.names if n.startswith("theta")]
        return self.states[:, [self.names.index(n) for n in names]]

    @property
    def rear_offsets(self) -> np.ndarray:
        """y2..yN [m] (docs/model.md), shape (K, N-1)."""
        return self._rear_offsets()

    @property
    def lateral_acceleration(self) -> np.ndarray:
        """a_i = v_i' + u r_i of every unit's CG [m/s^2], shape (K, N) (docs/measures.md)."""
        return np.column_stack([self[f"ay{i + 1}"] for i in range(self.vehicle.n_units)])

    def final_state(self) -> np.ndarray:
        """[x, psi1, Y1] at the last sample (to continue a run in chunks)."""
        return self.segments[-1].Z[-1, :len(self.names)].copy()

    def matrix(self) -> np.ndarray:
        """Every signal at every sample, columns as :meth:`columns`."""
        keep = [j for j, n in enumerate(self.row_names) if not _is_hidden(n)]
        with np.errstate(over="ignore", invalid="ignore"):     # an overflowed (unstable) run: callers refuse it
            lin = np.concatenate([seg.Z @ seg.C[keep].T for seg in self.segments])
            return np.column_stack([self.time, lin, self._rear_offsets()])

    def to_rows(self, names: list[str] | None = None) -> list[dict]:
        """Rows for a table or CSV: ``time_s`` and the named signals (default all), keyed by
        column header (``{"time_s": 0.0, "ay2_m_per_s2": ...}``)."""
        cols = self.columns()
        M = self.matrix()
        keep = list(range(len(cols))) if names is None else [0] + [
            i for i, s in enumerate(self.signal_names, start=1) if s in names or cols[i] in names]
        return [{cols[i]: float(row[i]) for i in keep} for row in M]

    def to_dict(self) -> dict:
        """The response as ``lcv simulate --json`` prints it: ``{"columns": [...], "rows": [[...], ...]}``,
        the columns with their units (``time_s``, ``ay2_m_per_s2`` ...), one row per sample.

        Returns
        -------
        dict

        Examples
        --------
        >>> from lcvreport import load_preset, respond
        >>> from lcvreport.manoeuvres.steer import step
        >>> d = respond(load_preset("aucnat"), "yaw_plane", step(0.01), 24.4, 1.0, 0.5).to_dict()
        >>> d["columns"][0], len(d["rows"])
        ('time_s', 3)
        """
        return {"columns": self.columns(), "rows": (self.matrix() + 0.0).tolist()}    # + 0.0: no -0

    def to_pandas(self):
        """The response as a :class:`pandas.DataFrame`, one column per signal with its unit in
        the header (``time_s``, ``ay2_m_per_s2`` ...); needs pandas (``lcvreport[study]``)."""
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("to_pandas needs pandas: pip install 'lcvreport[study]'") from None
        return pd.DataFrame(self.matrix(), columns=self.columns())

    # ------------------------------------------------------------------ the continuous response
    def extrema(self, name: str, t_from: float = 0.0, t_to: float = math.inf) -> tuple[np.ndarray, np.ndarray]:
        """Times [s] and values of the local extrema of signal ``name`` in ``[t_from,
        t_to]`` on the continuous response, plus the values at the ends of that window
        and at the input's breakpoints (where the derivative may jump)."""
        return self.extrema_many([name], t_from, t_to)[0]

    def extrema_many(self, names, t_from: float = 0.0, t_to: float = math.inf) -> list:
        """:meth:`extrema` of several signals at once (one product per piece for all of them):
        a list of (times, values), in the order of ``names``."""
        names = [self._signal(n) for n in names]
        js = [self._index(n) for n in names]
        K = len(js)
        times = [[] for _ in js]
        values = [[] for _ in js]
        for seg in self.segments:
            t = self.time[seg.k0:seg.k0 + len(seg.Z)]
            Z = seg.Z
            # the piece's stretches before its first sample and after its last (a piece that starts
            # or ends between samples) are scanned too, from z at the piece's start and end
            if seg.z_start is not None and (t.size == 0 or seg.t0 < t[0]):
                t, Z = np.r_[seg.t0, t], np.vstack([seg.z_start, Z])
            if seg.z_end is not None and math.isfinite(seg.t1) and (t.size == 0 or seg.t1 > t[-1]):
                t, Z = np.r_[t, seg.t1], np.vstack([Z, seg.z_end])
            if t.size == 0:
                continue
            c = seg.C[js].T                                   # (dim, K)
            c1 = seg.Mz.T @ c
            c2 = seg.Mz.T @ c1
            if t.size > 1:
                h = np.diff(t)
                D1 = c1.T @ Z.T                               # the derivatives at the samples: (K, samples)
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
                    Ya, Yb = Z[k] @ W, Z[k1] @ W
                    rows = np.arange(k.size)
                    ya, sa, yb, sb = Ya[rows, sig], Ya[rows, K + sig], Yb[rows, sig], Yb[rows, K + sig]
                    da, db = D1[sig, k], D1[sig, k1]
                    tau = hermite_roots(da, sa, db, sb, h[k])
                    tk = t[k] + tau * h[k]
                    val = quintic_hermite(ya, da, sa, yb, db, sb, h[k], tau)
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
        j = self._index(self._signal(name))
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

    def plot(self, signals: list[str] | None = None, ax=None, **style):
        """Plot signals against time (a :class:`matplotlib.figure.Figure`): default every unit's
        ``ay`` with the steer on a second axis where the run knows it, else the rear offsets.

        Parameters
        ----------
        signals : list of str, optional
        ax : matplotlib Axes, optional
        style : keyword arguments for ``Axes.plot``.
        """
        from ..plotting.time import plot_time_response
        return plot_time_response(self, signals, ax=ax, **style)


@runtime_checkable
class Response(Protocol):
    """What every response offers, whatever made it -- the exact response of a linear model
    (:class:`TimeResponse`) or an integration of any model (:class:`SampledResponse`): signal
    names, the sample times [s], a signal by name or column header (``r["ay2"]``), their units,
    extrema located between the samples, a table and a figure."""

    time: np.ndarray

    @property
    def signal_names(self) -> tuple[str, ...]: ...

    def __getitem__(self, name: str) -> np.ndarray: ...

    def units(self) -> dict: ...

    def extrema(self, name: str, t_from: float = 0.0, t_to: float = math.inf) -> tuple: ...

    def extrema_many(self, names, t_from: float = 0.0, t_to: float = math.inf) -> list: ...

    def to_pandas(self): ...

    def to_rows(self, names=None) -> list: ...

    def plot(self, signals=None, ax=None, **style): ...


class SampledResponse:
    """A response integrated from a model's equations (:func:`lcvreport.analysis.integrate.integrate`):
    the integrator's dense output over every stretch between the steer's breakpoints, sampled; every
    signal of the model (:meth:`~lcvreport.model.base.VehicleModel.outputs`) by name with its unit;
    extrema located on the dense output between the samples (each bracketed by a sign change of
    the sampled slope and refined on the dense output to 1e-10 s).

    Attributes
    ----------
    model : VehicleModel
    time : numpy.ndarray
        [s]
    speed_mps, tire_scale : float
    label : str
    """

    def __init__(self, model, time, pieces, speed_mps, tire_scale, delta_of, w0, label=""):
        self.model, self.time, self.pieces = model, np.asarray(time, dtype=float), pieces
        self.speed_mps, self.tire_scale, self.label = float(speed_mps), float(tire_scale), label
        self.vehicle = model.vehicle
        self._delta_of, self._w0 = delta_of, np.asarray(w0, dtype=float)
        self._linear = model.kind == "linear"
        self._table = self._signals_at(self.time)
        #: the time [s] the run's stop condition ended it, or None (:func:`~lcvreport.analysis.integrate.integrate`)
        self.stopped_at = None
        #: how many evaluations of the model's equations the run took
        self.evaluations = 0
        #: the steer input or law the run was driven by
        self.steer = None

    # ------------------------------------------------------------------ the dense output
    def state_at(self, t) -> np.ndarray:
        """The state at times ``t`` [s] from the dense output, shape (len(t), n)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.empty((t.size, self.pieces[0][2](self.pieces[0][0]).size))
        for k, (a, b, sol) in enumerate(self.pieces):
            last = k == len(self.pieces) - 1
            sel = (t >= a) & ((t < b) | (last & (t <= b + 1e-12)))
            if sel.any():
                out[sel] = sol(t[sel]).T
        return out

    def _signals_at(self, t) -> dict:
        """Every signal at the times ``t``: {name: array} (a nonlinear model's outputs of every
        time in one call: its equations take a batch of states)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        X = self.state_at(t)
        W = np.tile(self._w0, (t.size, 1))
        if getattr(self._delta_of, "vectorized", False):
            W[:, 0] = self._delta_of(t, X.T)
        else:
            W[:, 0] = [self._delta_of(ti, z) for ti, z in zip(t, X)]
        if not self._linear:
            out = self.model.outputs(t, X, W, self.speed_mps, self.tire_scale)
            return {k: np.asarray(val, dtype=float).reshape(t.size) for k, val in out.items()}
        rows = [self._outputs(ti, z, w) for ti, z, w in zip(t, X, W)]
        return {name: np.array([r[name] for r in rows]) for name in rows[0]}

    def _outputs(self, t, z, w) -> dict:
        m = self.model
        if not self._linear:
            return m.outputs(t, z, w, self.speed_mps, self.tire_scale)
        x, psi1, Y1 = z[:-2], z[-2], z[-1]
        out = m.outputs(t, x, w, self.speed_mps, self.tire_scale)
        out["psi1"], out["Y1"] = psi1, Y1
        zz = np.r_[x, psi1, Y1]
        v = self.vehicle
        for i, a in zip(v.axle_units, v.axles):
            out[f"Y_{a.name}"] = float(m.point_lateral_row(i, a.x_m) @ zz)
        last = v.n_units - 1
        out["Y_rear"] = float(m.point_lateral_row(last, v.rear_end_x_m(last)) @ zz)
        return out

    # ------------------------------------------------------------------ names, values, units
    @property
    def signal_names(self) -> tuple[str, ...]:
        return tuple(self._table)

    def units(self) -> dict:
        """``{signal: unit}`` (``"m/s^2"``, ``"rad"``, ``"-"``)."""
        return {n: sampled_unit(n) for n in self.signal_names}

    def columns(self) -> list[str]:
        return ["time_s"] + [sampled_column(n) for n in self.signal_names]

    def __getitem__(self, name: str) -> np.ndarray:
        if name == "time_s":
            return self.time
        if name in self._table:
            return self._table[name]
        for n in self._table:
            if sampled_column(n) == name:
                return self._table[n]
        raise KeyError(f"no signal {name!r}; signals: {', '.join(self.signal_names)}")

    def _name(self, name: str) -> str:
        if name in self._table:
            return name
        for n in self._table:
            if sampled_column(n) == name:
                return n
        raise KeyError(f"no signal {name!r}; signals: {', '.join(self.signal_names)}")

    def value_at(self, name: str, t: float) -> float:
        """The signal ``name`` at time ``t`` [s] (from the dense output)."""
        return float(self._signals_at(np.array([float(t)]))[self._name(name)][0])

    def matrix(self) -> np.ndarray:
        return np.column_stack([self.time] + [self._table[n] for n in self.signal_names])

    def to_rows(self, names=None) -> list[dict]:
        cols = self.columns()
        keep = [0] + [i for i, n in enumerate(self.signal_names, start=1) if names is None or n in names
                      or cols[i] in names]
        M = self.matrix()
        return [{cols[i]: float(row[i]) for i in keep} for row in M]

    to_dict = TimeResponse.to_dict               # columns() and matrix(): the same document

    def to_pandas(self):
        try:
            import pandas as pd
        except ImportError:
            raise ImportError("to_pandas needs pandas: pip install 'lcvreport[study]'") from None
        return pd.DataFrame(self.matrix(), columns=self.columns())

    # ------------------------------------------------------------------ extrema
    def extrema(self, name: str, t_from: float = 0.0, t_to: float = math.inf) -> tuple:
        return self.extrema_many([name], t_from, t_to)[0]

    def extrema_many(self, names, t_from: float = 0.0, t_to: float = math.inf) -> list:
        """Times [s] and values of every local extremum of each signal in ``[t_from, t_to]``, and
        the values at the window's ends: each sampled sign change of the slope refined on the dense
        output (bounded search between the neighbouring samples)."""
        from scipy.optimize import minimize_scalar
        t = self.time
        out = []
        t_to = min(t_to, float(t[-1]))
        for name in names:
            key = self._name(name)
            y = self._table[key]
            times, values = [], []
            for k in range(1, t.size - 1):
                if not (t_from <= t[k] <= t_to):
                    continue
                left, right = y[k] - y[k - 1], y[k + 1] - y[k]
                if (left > 0 >= right) or (left < 0 <= right):
                    sign = 1.0 if left > 0 else -1.0
                    res = minimize_scalar(lambda s: -sign * self.value_at(key, s), bounds=(t[k - 1], t[k + 1]),
                                          method="bounded", options={"xatol": 1e-10})
                    tk = float(res.x)
                    vk = -sign * float(res.fun)
                    if sign * vk < sign * y[k]:                 # the sample itself is the better one
                        tk, vk = float(t[k]), float(y[k])
                    times.append(tk)
                    values.append(vk)
            for tb in (t_from, t_to):
                if t[0] <= tb <= t[-1]:
                    times.append(float(tb))
                    values.append(self.value_at(key, tb))
            order = np.argsort(times)
            out.append((np.asarray(times)[order], np.asarray(values)[order]))
        return out

    def peak_abs(self, name: str, t_from: float = 0.0, t_to: float = math.inf) -> float:
        return float(np.abs(self.extrema(name, t_from, t_to)[1]).max())

    def peaks_abs(self, names, t_from: float = 0.0, t_to: float = math.inf) -> np.ndarray:
        return np.array([float(np.abs(v).max()) for _t, v in self.extrema_many(names, t_from, t_to)])

    def plot(self, signals=None, ax=None, **style):
        """Plot signals against time (default every unit's ``ay``)."""
        from ..plotting.time import plot_time_response
        return plot_time_response(self, signals, ax=ax, **style)


#: the unit of the nonlinear model's signals by their start (first match), beyond the linear ones
SAMPLED_UNITS = (("X", "m_per_s", "m"), ("Fx_", "N", "N"), ("Fy_", "N", "N"), ("fd_", "", "-"),
                 ("u1", "m_per_s", "m/s"))


def sampled_unit(name: str) -> str:
    """A sampled signal's unit: the nonlinear model's forces, friction demand and positions, else
    :func:`signal_unit`."""
    if name.startswith("X"):
        return "m"
    for prefix, _s, unit in SAMPLED_UNITS:
        if name.startswith(prefix):
            return unit
    return signal_unit(name)


def sampled_column(name: str) -> str:
    """A sampled signal's column header (``X2_m``, ``Fy_steer_N``, ``fd_steer``)."""
    if name.startswith("X"):
        return f"{name}_m"
    for prefix, suffix, _u in SAMPLED_UNITS:
        if name.startswith(prefix) and prefix != "X":
            return f"{name}_{suffix}" if suffix else name
    return column(name)
