"""Manoeuvres: steer inputs as continuous functions of time (docs/manoeuvres.md).

Each steer input is a sequence of :class:`Piece` objects: on ``[t0, t1)`` the input is
``h . xi(t)`` with ``xi' = E xi`` -- a constant, a line, a sinusoid -- so that the
response to it is exact (the exponential of the state matrix augmented with ``E``,
:mod:`lcvreport.analysis.exact`), not a sampled approximation.

=====================  ================================================================
``step:A``             delta = A for t >= 0
``sine:A:F``           delta = A sin(2 pi F t) for 0 <= t <= 1/F, then 0 (single sine)
``pulse:A:D``          delta = A sin(pi t / D) for 0 <= t <= D, then 0 (half sine)
``csv:FILE``           columns ``time_s,delta_rad``, linear between samples, held after
``lane-change:A0:F``   the steer that makes the steered axle's lateral acceleration
                       A0 sin(2 pi F t) for 0 <= t <= 1/F, then 0 (A0 in m/s^2, or
                       with a ``g`` suffix in g: ``0.15g``)
``driver:A0:F[:K:T]``  the preview driver in closed loop following the lane change's
                       path: delta = K (Y_path(t) - (Y1 + u T psi1)), the path point
                       the tractor reaches T seconds later (gain K [rad/m], default
                       0.2; preview T [s], default 0.5)
=====================  ================================================================

Examples
--------
>>> s = parse_steer("sine:0.01:0.4")
>>> s.kind, s.end_s
('sine', 2.5)
>>> float(s.delta([0.625])[0])
0.01
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..ranges import RANGES, RangeError
from ..util.files import FileInputError, read_csv

#: standard gravity [m/s^2]
G_MPS2 = 9.80665
#: the largest number of rows of a steer table
MAX_TABLE_ROWS = 1_000_000
#: the largest steer table file [bytes] (10^6 rows of two numbers of full precision)
TABLE_MAX_BYTES = 64 << 20


class SteerError(ValueError):
    """A steer specification that cannot be used; the message names the part and the range."""


@dataclass(frozen=True)
class Piece:
    """The input on ``[t0, t1)``: ``h . xi(t)`` with ``xi' = E xi`` and ``xi(t0) = xi0``."""

    t0: float
    t1: float
    E: np.ndarray
    h: np.ndarray
    xi0: np.ndarray

    def value(self, t) -> np.ndarray:
        """The input at times ``t`` in the piece (closed form for constants, lines and
        sinusoids; the exponential otherwise)."""
        tau = np.atleast_1d(np.asarray(t, dtype=float)) - self.t0
        E, h, x0 = self.E, self.h, self.xi0
        if E.shape == (1, 1) and E[0, 0] == 0.0:
            return np.full(tau.shape, h[0] * x0[0])
        if E.shape == (2, 2) and E[0, 0] == E[0, 1] == E[1, 1] == 0.0 and E[1, 0] == 1.0:
            return h[0] * x0[0] + h[1] * (x0[1] + tau * x0[0])
        if E.shape == (2, 2) and E[0, 0] == E[1, 1] == 0.0 and E[0, 1] == -E[1, 0]:
            w = E[0, 1]
            c, s = np.cos(w * tau), np.sin(w * tau)
            return h[0] * (x0[0] * c + x0[1] * s) + h[1] * (x0[1] * c - x0[0] * s)
        from scipy.linalg import expm
        return np.array([h @ expm(E * ti) @ x0 for ti in tau])


def _constant(t0: float, t1: float, value: float) -> Piece:
    return Piece(t0, t1, np.zeros((1, 1)), np.array([value]), np.array([1.0]))


def _sinusoid(t0: float, t1: float, amplitude: float, omega: float, phase: float = 0.0) -> Piece:
    """amplitude * sin(omega (t - t0) + phase) on [t0, t1)."""
    E = np.array([[0.0, omega], [-omega, 0.0]])          # xi = [sin, cos](omega (t - t0) + phase)
    return Piece(t0, t1, E, np.array([amplitude, 0.0]), np.array([math.sin(phase), math.cos(phase)]))


def _line(t0: float, t1: float, value: float, slope: float) -> Piece:
    """value + slope (t - t0) on [t0, t1)."""
    E = np.array([[0.0, 0.0], [1.0, 0.0]])               # xi = [1, t - t0]
    return Piece(t0, t1, E, np.array([value, slope]), np.array([1.0, 0.0]))


@dataclass(frozen=True)
class SteerInput:
    """A steer input (or, for the lane change, a prescribed lateral acceleration).

    Attributes
    ----------
    kind : str
        ``step``, ``sine``, ``pulse``, ``csv`` or ``lane-change``.
    pieces : tuple of Piece
        The input in time order; the last one extends to infinity.
    end_s : float
        When the input ends (the sine's period, the pulse's duration, the last table
        time; 0 for a step) [s].
    spec : str
        The text it was parsed from.
    amplitude : float
        A (rad) or A0 (m/s^2 for a lane change).
    frequency_hz : float
        F for sine and lane change, else NaN.
    """

    kind: str
    pieces: tuple
    end_s: float
    spec: str
    amplitude: float = 0.0
    frequency_hz: float = float("nan")
    prescribes_acceleration: bool = field(default=False)
    #: the preview driver's (gain [rad/m], preview time [s]) when the pieces are its reference
    #: path [m] (``driver:``), else None
    driver: tuple | None = None

    def delta(self, t) -> np.ndarray:
        """The input's value at times ``t`` [s] (rad; m/s^2 for a lane change)."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        out = np.zeros(t.shape)
        for p in self.pieces:
            sel = (t >= p.t0) & (t < p.t1)
            if sel.any():
                out[sel] = p.value(t[sel])
        return out


def step(amplitude_rad: float) -> SteerInput:
    """``delta = A`` for t >= 0."""
    A = RANGES["steer_angle"].check(amplitude_rad, "step amplitude")
    return SteerInput("step", (_constant(0.0, math.inf, A),), 0.0, f"step:{A:g}", A)


def sine(amplitude_rad: float, frequency_hz: float) -> SteerInput:
    """The single sine: ``delta = A sin(2 pi F t)`` for ``0 <= t <= 1/F``, then 0."""
    A = RANGES["steer_angle"].check(amplitude_rad, "sine amplitude")
    F = RANGES["frequency"].check(frequency_hz, "sine frequency")
    T = 1.0 / F
    return SteerInput("sine", (_sinusoid(0.0, T, A, 2 * math.pi * F), _constant(T, math.inf, 0.0)), T,
                      f"sine:{A:g}:{F:g}", A, F)


def pulse(amplitude_rad: float, duration_s: float) -> SteerInput:
    """The half-sine pulse: ``delta = A sin(pi t / D)`` for ``0 <= t <= D``, then 0."""
    A = RANGES["steer_angle"].check(amplitude_rad, "pulse amplitude")
    D = RANGES["pulse_duration"].check(duration_s, "pulse duration")
    return SteerInput("pulse", (_sinusoid(0.0, D, A, math.pi / D), _constant(D, math.inf, 0.0)), D,
                      f"pulse:{A:g}:{D:g}", A)


def table(time_s, delta_rad, source: str = "table") -> SteerInput:
    """Steer angle from samples: linear between them, held after the last (0 before the
    first, which must be at t = 0 or later).

    Raises
    ------
    SteerError
        Times not strictly increasing, non-finite values, or angles out of range.
    """
    t = np.asarray(time_s, dtype=float)
    d = np.asarray(delta_rad, dtype=float)
    if t.ndim != 1 or t.size < 1 or t.shape != d.shape:
        raise SteerError(f"{source}: needs one time_s and one delta_rad per row, at least one row")
    if t.size > MAX_TABLE_ROWS:
        raise SteerError(f"{source}: {t.size} rows; at most {MAX_TABLE_ROWS}")
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(d))):
        k = int(np.flatnonzero(~(np.isfinite(t) & np.isfinite(d)))[0])
        raise SteerError(f"{source}: row {k + 1} is not finite (time_s={t[k]!r}, delta_rad={d[k]!r})")
    if t[0] < 0:
        raise SteerError(f"{source}: time_s must start at 0 or later, got {t[0]:g}")
    if np.any(np.diff(t) <= 0):
        k = int(np.flatnonzero(np.diff(t) <= 0)[0])
        raise SteerError(f"{source}: time_s must increase strictly; row {k + 2} ({t[k + 1]:g} s) does not come "
                         f"after row {k + 1} ({t[k]:g} s)")
    r = RANGES["steer_angle"]
    if not np.all((d >= r.low) & (d <= r.high)):
        k = int(np.flatnonzero(~((d >= r.low) & (d <= r.high)))[0])
        raise SteerError(f"{source}: delta_rad in row {k + 1} must be in {r.text()}, got {d[k]:g}")
    pieces = []
    if t[0] > 0:
        pieces.append(_constant(0.0, float(t[0]), 0.0))
    for k in range(t.size - 1):
        pieces.append(_line(float(t[k]), float(t[k + 1]), float(d[k]), float((d[k + 1] - d[k]) / (t[k + 1] - t[k]))))
    pieces.append(_constant(float(t[-1]), math.inf, float(d[-1])))
    return SteerInput("csv", tuple(pieces), float(t[-1]), f"csv:{source}", float(np.abs(d).max()))


def read_table(path: str | Path) -> SteerInput:
    """A steer table from a CSV file with the header ``time_s,delta_rad`` (a regular file of
    at most :data:`TABLE_MAX_BYTES`, :func:`lcvreport.util.files.read_csv`)."""
    try:
        rows = read_csv(path, "steer table", ("time_s", "delta_rad"), max_bytes=TABLE_MAX_BYTES)
    except FileInputError as exc:
        raise SteerError(f"csv:{exc}") from None
    t, d = [], []
    for k, row in rows:
        try:
            t.append(float(row["time_s"]))
            d.append(float(row["delta_rad"]))
        except ValueError:
            raise SteerError(f"csv:{path}: line {k} is not two numbers: {row['time_s']},{row['delta_rad']!r}") \
                from None
    return table(t, d, source=str(path))


def lane_change(accel_mps2: float, frequency_hz: float) -> SteerInput:
    """The path-following lane change: the steered axle's lateral acceleration is
    ``A0 sin(2 pi F t)`` for ``0 <= t <= 1/F``, then 0; the axle ends on a straight line
    offset by ``A0 / (2 pi F^2)`` [m].  The steer is found from the inverse system
    (:func:`lcvreport.analysis.exact.response`)."""
    A0 = RANGES["lateral_acceleration"].check(accel_mps2, "lane-change acceleration")
    F = RANGES["frequency"].check(frequency_hz, "lane-change frequency")
    T = 1.0 / F
    return SteerInput("lane-change", (_sinusoid(0.0, T, A0, 2 * math.pi * F), _constant(T, math.inf, 0.0)), T,
                      f"lane-change:{A0:g}:{F:g}", A0, F, prescribes_acceleration=True)


#: the preview driver of ``driver:``: gain [rad/m] and preview time [s]
DRIVER_GAIN_RAD_PER_M = 0.2
DRIVER_PREVIEW_S = 0.5


def driver_lane_change(accel_mps2: float, frequency_hz: float, gain_rad_per_m: float = DRIVER_GAIN_RAD_PER_M,
                       preview_s: float = DRIVER_PREVIEW_S) -> SteerInput:
    """The closed-loop lane change: a preview driver steers ``delta = K (Y_path(t) - (Y1 + u T
    psi1))`` -- the lateral position the tractor's CG would reach T seconds ahead on its heading
    against the path there -- along the lane change's path ``Y_path`` (lateral acceleration
    A0 sin(2 pi F s) for 0 <= s <= 1/F of path time s, the path point reached T later: the
    tractor enters the lane change at t = T).  The pieces are the path [m]; the response is exact
    for the closed loop (:func:`lcvreport.analysis.exact.response`)."""
    A0 = RANGES["lateral_acceleration"].check(accel_mps2, "driver lane-change acceleration")
    F = RANGES["frequency"].check(frequency_hz, "driver lane-change frequency")
    K = RANGES["driver_gain"].check(gain_rad_per_m, "driver gain")
    T_p = RANGES["driver_preview"].check(preview_s, "driver preview")
    T, w = 1.0 / F, 2 * math.pi * F
    # Y_path = A0/w (t - sin(w t)/w) on [0, T): a line and a sinusoid together; then the offset
    line, sinus = _line(0.0, T, 0.0, A0 / w), _sinusoid(0.0, T, -A0 / w ** 2, w)
    E = np.zeros((4, 4))
    E[:2, :2], E[2:, 2:] = line.E, sinus.E
    path = Piece(0.0, T, E, np.r_[line.h, sinus.h], np.r_[line.xi0, sinus.xi0])
    return SteerInput("driver", (path, _constant(T, math.inf, A0 / (w * F))), T,
                      f"driver:{A0:g}:{F:g}:{K:g}:{T_p:g}", A0, F, driver=(K, T_p))


def lane_change_offset_m(steer: SteerInput) -> float:
    """The final lateral offset of the steered axle in a lane change, A0 / (2 pi F^2) [m]."""
    return steer.amplitude / (2 * math.pi * steer.frequency_hz ** 2)


def _number(text: str, what: str, spec: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise SteerError(f"steer {spec!r}: {what} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise SteerError(f"steer {spec!r}: {what} must be finite, got {text!r}")
    return value


def parse_steer(spec: str) -> SteerInput:
    """A steer input from its text (the table in the module docstring).

    Raises
    ------
    SteerError
        Naming the part of ``spec`` that is wrong and what is valid.
    """
    kinds = "step:A, sine:A:F, pulse:A:D, csv:FILE, lane-change:A0:F, driver:A0:F[:K:T]"
    kind, _, rest = spec.partition(":")
    parts = rest.split(":") if rest else []
    try:
        if kind == "csv":
            if not rest:
                raise SteerError(f"steer {spec!r}: csv needs a file, csv:FILE")
            return read_table(rest)
        expected = {"step": 1, "sine": 2, "pulse": 2, "lane-change": 2, "driver": 2}
        if kind not in expected:
            raise SteerError(f"steer {spec!r}: unknown kind {kind!r}; valid: {kinds}")
        if kind == "driver" and len(parts) in (2, 4):
            a = parts[0].strip()
            A0 = _number(a[:-1], "A0 [g]", spec) * G_MPS2 if a.lower().endswith("g") else \
                _number(a, "A0 [m/s^2]", spec)
            extra = [_number(parts[2], "K [rad/m]", spec), _number(parts[3], "T [s]", spec)] if len(parts) == 4 else []
            return driver_lane_change(A0, _number(parts[1], "F [Hz]", spec), *extra)
        if kind == "driver":
            raise SteerError(f"steer {spec!r}: driver takes A0:F or A0:F:K:T; valid: {kinds}")
        if len(parts) != expected[kind]:
            raise SteerError(f"steer {spec!r}: {kind} takes {expected[kind]} number(s); valid: {kinds}")
        if kind == "step":
            return step(_number(parts[0], "A [rad]", spec))
        if kind == "sine":
            return sine(_number(parts[0], "A [rad]", spec), _number(parts[1], "F [Hz]", spec))
        if kind == "pulse":
            return pulse(_number(parts[0], "A [rad]", spec), _number(parts[1], "D [s]", spec))
        a = parts[0].strip()
        A0 = _number(a[:-1], "A0 [g]", spec) * G_MPS2 if a.lower().endswith("g") else _number(a, "A0 [m/s^2]", spec)
        return lane_change(A0, _number(parts[1], "F [Hz]", spec))
    except RangeError as exc:
        raise SteerError(f"steer {spec!r}: {exc}") from None
