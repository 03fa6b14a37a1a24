r"""The standard yaw-plane performance measures at one speed (SPEC section 8), SI.

* Lateral acceleration of unit i's CG: ``a_i = v_i' + u r_i``.
* **Least damping ratio**: the smallest ``-Re(lambda)/|lambda|`` over eigenvalues with
  ``Im(lambda) > 0``, and that mode's damped frequency ``Im(lambda)/2 pi`` [Hz]; None
  when no mode oscillates.
* **Critical speed**: the lowest speed in ``(u_min, 200 km/h]`` where the largest real
  part of the eigenvalues is >= 0, to 0.1 km/h (a 1 km/h scan, then bisection); None
  when stable throughout.
* **Rearward amplification, frequency domain**: ``RA(f) = |G_N(j 2 pi f)| / |G_1(j 2 pi f)|``,
  ``G_i`` the transfer function from the steer angle to ``a_i``.
* **Rearward amplification, single sine** (SAE J2179 / ISO 14791 style): ``delta(t) =
  delta0 sin(2 pi f t)`` for ``0 <= t <= 1/f``, then 0, from rest;
  ``RA = max|a_N| / max|a_1|`` over ``0 .. 1/f + 8 s``, exact (zero-order hold, 1 ms
  steps, delta sampled at the start of each step), evaluated in closed form over the
  modes (the same numbers as 10,500 exact steps, in a fraction of the time).
* **Trimmed straight running**: the steady state of ``M x' = S x + b delta + F`` with
  ``r1 = 0`` (the driver holds the tractor straight against the residual forces):
  ``delta_trim`` [rad] and the offtracking [m], the lateral offset (positive toward
  +y) between the path of the rearmost axle of the last unit and the path of the
  frontmost steered axle (frontmost axle of unit 1 if none is steered), to first
  order: every point then moves with velocity (u, v1) in the tractor frame.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.units import kph_to_mps
>>> m = measure_set(load_preset("aucnat"), kph_to_mps(88.0), load_units=["trailer2", "trailer3"])
>>> sorted(m.to_dict())[:6]
['ay_gain_per_unit', 'critical_speed_kph', 'frontal_swing_m', 'hsso_m', 'hsto_m', 'least_damped_frequency_hz']
"""
from __future__ import annotations

import functools

import math
from dataclasses import dataclass, field

import numpy as np

from ..model.builder import check_speed, check_tire_scale, system_coefficients
from ..model.loads import load_vector, one_percent_rule
from ..model.vehicle import Vehicle
from ..ranges import RANGES, RangeError
from ..units import kph_to_mps, mps_to_kph
from .geometry import point_lateral_map, point_longitudinal
from .modes import eigenvalues, state_matrix

#: the frequency of the RA measures [Hz]
RA_FREQUENCY_HZ = 0.4
#: upper end of the critical-speed search [km/h]
CRITICAL_SPEED_MAX_KPH = 200.0
#: lower end of the critical-speed search: the FMUs' default u_min (5 mph) [m/s]
U_MIN_DEFAULT_MPS = 2.2352
#: resolution of the critical speed [km/h]
CRITICAL_SPEED_RESOLUTION_KPH = 0.1
#: single sine: step [s], time after the sine [s], default amplitude [rad]
SINGLE_SINE_STEP_S = 2e-3
SINGLE_SINE_TAIL_S = 8.0
SINGLE_SINE_DELTA0_RAD = 0.01


def _freq(f_hz):
    f = np.asarray(f_hz, dtype=float)
    RANGES["frequency"].check(float(f.min()) if f.size else 0.0, "frequency")
    RANGES["frequency"].check(float(f.max()) if f.size else 0.0, "frequency")
    return f


def steer_to_acceleration(vehicle: Vehicle, speed_mps: float, f_hz, tire_scale: float = 1.0) -> np.ndarray:
    """``G_i(j 2 pi f)``: complex gain from the steer angle to the lateral acceleration of
    every unit's CG [m/s^2 per rad], shape (..., N) for frequencies of shape (...).

    Computed from ``x = (j w M - S)^-1 b_delta`` and ``a = (j w V + u R) x``, with no
    state-space conversion (the state-space form of :mod:`.statespace` is tested
    against it).
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    f = _freq(f_hz)
    co = system_coefficients(vehicle)
    M, S, b = co.M(speed_mps), co.S(speed_mps, tire_scale), co.B_delta(tire_scale)
    V, R = co.velocity_map(speed_mps), co.yaw_rate_map()
    w = 2 * np.pi * f[..., None, None]
    x = np.linalg.solve(1j * w * M - S, np.broadcast_to(b, f.shape + b.shape)[..., None])[..., 0]
    return x @ V.T * (1j * 2 * np.pi * f[..., None]) + speed_mps * (x @ R.T)


def rearward_amplification(vehicle: Vehicle, speed_mps: float, f_hz=RA_FREQUENCY_HZ, tire_scale: float = 1.0):
    """``RA(f) = |G_N| / |G_1|`` [-] at one or many frequencies [Hz]."""
    G = np.abs(steer_to_acceleration(vehicle, speed_mps, f_hz, tire_scale))
    ra = G[..., -1] / G[..., 0]
    return float(ra) if np.ndim(ra) == 0 else ra


def least_damping(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> tuple[float | None, float | None]:
    """(least damping ratio [-], its damped frequency [Hz]) over the oscillatory modes; (None, None) if none."""
    lam = eigenvalues(vehicle, speed_mps, tire_scale)
    osc = lam[lam.imag > 1e-12 * max(np.abs(lam).max(), 1.0)]
    if osc.size == 0:
        return None, None
    zeta = -osc.real / np.abs(osc)
    k = int(np.argmin(zeta))
    return float(zeta[k]), float(osc[k].imag / (2 * np.pi))


def critical_speed(vehicle: Vehicle, tire_scale: float = 1.0, u_min_mps: float = U_MIN_DEFAULT_MPS,
                   u_max_kph: float = CRITICAL_SPEED_MAX_KPH) -> float | None:
    """Lowest speed [km/h] in ``(u_min, u_max]`` where ``max Re(lambda) >= 0``, to 0.1 km/h; None if stable.

    ``max Re(lambda)`` is scanned every 4 km/h; every interval whose ends are not
    clearly stable -- closer to 0 than twice the largest change of ``max Re(lambda)``
    over that interval and its neighbours -- is scanned again every 1 km/h; bisection narrows the first unstable speed to 0.01 km/h, rounded to
    0.1 km/h.  An instability band narrower than 1 km/h can be missed (none of the
    vehicles here has one); the result equals a dense scan (tested).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> critical_speed(load_preset("empty"), tire_scale=0.2)
    73.9
    """
    check_tire_scale(tire_scale)
    lo_kph = mps_to_kph(RANGES["u_min"].check(u_min_mps, "u_min"))

    def max_real(v_kph):
        A = state_matrix(vehicle, kph_to_mps(np.asarray(v_kph, dtype=float)), tire_scale)
        return np.linalg.eigvals(A).real.max(axis=-1)

    coarse = np.linspace(lo_kph, u_max_kph, max(int(math.ceil((u_max_kph - lo_kph) / 4.0)) + 1, 2))
    sigma = max_real(coarse)
    # local change of max Re(lambda) per interval: the largest over it and its neighbours;
    # a function changing by at most that much rises at most half of it above the
    # interval's ends: twice that margin decides which intervals are scanned finely
    step = np.abs(np.diff(sigma))
    padded = np.concatenate([step[:1], step, step[-1:]])
    slope = np.maximum(np.maximum(padded[:-2], padded[1:-1]), padded[2:])
    near = np.flatnonzero(np.maximum(sigma[:-1], sigma[1:]) > -2.0 * slope)
    fine = np.concatenate([np.linspace(coarse[i], coarse[i + 1], int(math.ceil(coarse[i + 1] - coarse[i])) + 1)[1:-1]
                           for i in near] or [np.empty(0)])
    grid = np.concatenate([coarse, fine])
    order = np.argsort(grid, kind="stable")
    values = np.concatenate([sigma, max_real(fine) if fine.size else fine])
    grid, values = grid[order], values[order]
    flags = values >= 0.0
    if not flags.any():
        return None
    i = int(np.argmax(flags))
    if i == 0:
        return round(float(grid[0]), 1)
    lo, hi = float(grid[i - 1]), float(grid[i])
    while hi - lo > 0.01:
        mid = 0.5 * (lo + hi)
        if max_real(mid) >= 0.0:
            hi = mid
        else:
            lo = mid
    return round(0.5 * (lo + hi), 1)


@dataclass(frozen=True)
class SingleSine:
    """A single-sine steer manoeuvre and the lateral accelerations it produces.

    Attributes
    ----------
    time : numpy.ndarray, shape (K,)
        Sample times from the start of the steer [s].
    delta : numpy.ndarray, shape (K,)
        Steer angle (the continuous sine) at the samples [rad] (computed on access).
    ay : numpy.ndarray, shape (K, N)
        Lateral acceleration of every unit's CG at the samples [m/s^2] (computed on access).
    frequency_hz, delta0_rad, speed_mps : float
    vehicle : Vehicle
    peaks : numpy.ndarray, shape (N,)
        max|a_i| per unit on the continuous response [m/s^2] (between the samples).
    response : lcvreport.analysis.exact.ManoeuvreResponse
        The exact response the samples come from.
    """

    time: np.ndarray
    frequency_hz: float
    delta0_rad: float
    speed_mps: float
    vehicle: Vehicle = field(repr=False, default=None)
    peaks: np.ndarray = None
    response: object = field(repr=False, default=None)

    @property
    def delta(self) -> np.ndarray:
        """Steer angle at the samples [rad]."""
        return self.response["delta"]

    @property
    def ay(self) -> np.ndarray:
        """Lateral acceleration of every unit's CG at the samples, shape (K, N) [m/s^2]."""
        return np.column_stack([self.response[f"ay{i + 1}"] for i in range(self.vehicle.n_units)])

    @property
    def rearward_amplification(self) -> float:
        """max|a_N| / max|a_1| [-] on the continuous response."""
        return float(self.peaks[-1] / self.peaks[0])

    def plot(self, ax=None):
        """Time histories of every unit's a_i (a :class:`matplotlib.figure.Figure`)."""
        from ..report.plotting import plot_single_sine
        return plot_single_sine(self, ax=ax)


def single_sine(vehicle: Vehicle, speed_mps: float, f_hz: float = RA_FREQUENCY_HZ,
                delta0_rad: float = SINGLE_SINE_DELTA0_RAD, tire_scale: float = 1.0,
                step_s: float = SINGLE_SINE_STEP_S, tail_s: float = SINGLE_SINE_TAIL_S) -> SingleSine:
    """The single-sine manoeuvre from rest (SPEC sections 8 and 11): the continuous steer
    ``delta = delta0 sin(2 pi f t)`` for ``0 <= t <= 1/f``, then straight ahead for
    ``tail_s``; the exact response (:func:`lcvreport.analysis.exact.response`), sampled
    every ``step_s``, its peaks located on the continuous response.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> s = single_sine(load_preset("aucnat"), 24.4444)
    >>> s.ay.shape, round(s.rearward_amplification, 2)
    ((5251, 6), 4.79)
    """
    from .exact import response
    from .manoeuvres import sine
    f = float(_freq(f_hz))
    steer = sine(delta0_rad, f)
    t_end = round((1.0 / f + tail_s) / step_s) * step_s
    r = response(vehicle, speed_mps, steer, t_end, step_s, tire_scale=tire_scale)
    peaks = r.peaks_abs([f"ay{i + 1}" for i in range(vehicle.n_units)])
    return SingleSine(r.time, f, float(delta0_rad), float(speed_mps), vehicle, peaks, r)


@dataclass(frozen=True)
class Trim:
    """Trimmed straight running under residual loads.

    Attributes
    ----------
    delta_rad : float
        Steer angle that holds the tractor straight (r1 = 0) [rad].
    offtracking_m : float
        Lateral offset of the rearmost axle's path from the steered axle's path [m], +y positive.
    state : numpy.ndarray, shape (2N,)
        The trimmed state (v1 m/s, r = 0, theta rad).
    """

    delta_rad: float
    offtracking_m: float
    state: np.ndarray


def reference_points(vehicle: Vehicle) -> tuple[tuple[int, float], tuple[int, float]]:
    """((unit, x) of the frontmost steered axle (or frontmost axle of unit 1),
    (unit, x) of the rearmost axle of the last unit), 0-based units, x [m]."""
    first = vehicle.steered_axles or vehicle.units[0].axles
    q = max(first, key=lambda a: a.x_m)
    last = vehicle.n_units - 1
    return (0, q.x_m), (last, vehicle.units[last].rearmost_axle.x_m)


def steady_with_yaw_rate(vehicle: Vehicle, speed_mps: float, F, r1: float, tire_scale: float = 1.0
                         ) -> tuple[np.ndarray, float]:
    """The steady state and steer angle with the tractor's yaw rate held at ``r1`` [rad/s]:
    ``S x + b delta + F = 0`` with ``x[1] = r1`` (the trim: r1 = 0; a steady turn: u/R).

    Returns
    -------
    x : numpy.ndarray, shape (2N,)
    delta : float
        [rad]
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle)
    S, b = co.S(speed_mps, tire_scale), co.B_delta(tire_scale)
    n = vehicle.n_states
    K = np.zeros((n + 1, n + 1))
    K[:n, :n] = S
    K[:n, n] = b
    K[n, 1] = 1.0
    rhs = np.concatenate([-np.asarray(F, dtype=float), [float(r1)]])
    sol = np.linalg.solve(K, rhs)
    return sol[:n], float(sol[n])


def trim(vehicle: Vehicle, speed_mps: float, F: np.ndarray, tire_scale: float = 1.0) -> Trim:
    """Trimmed straight running under a constant generalized force F (SI).

    Solves ``S x + b delta + F = 0`` with ``r1 = 0`` for ``x`` and ``delta``.
    """
    x, delta = steady_with_yaw_rate(vehicle, speed_mps, F, 0.0, tire_scale)
    (uq, xq), (up, xp) = reference_points(vehicle)
    nu = vehicle.n_units
    Theta = np.cumsum(x[nu + 1:])
    lateral = lambda unit, xx: float(point_lateral_map(vehicle, unit, xx)[2:] @ Theta)  # noqa: E731 (psi1 = Y1 = 0)
    dX = point_longitudinal(vehicle, up, xp) - point_longitudinal(vehicle, uq, xq)
    offtracking = lateral(up, xp) - lateral(uq, xq) - dX * x[0] / speed_mps
    return Trim(delta, float(offtracking), x)


@dataclass(frozen=True)
class SpeedSweep:
    """Eigenvalues over a range of speeds (root locus) with the least damping and the stability margin.

    Attributes
    ----------
    speeds_kph : numpy.ndarray, shape (K,)
    eigenvalues : numpy.ndarray, shape (K, 2N)
        [1/s], mode order.
    critical_speed_kph : float or None
    """

    speeds_kph: np.ndarray
    eigenvalues: np.ndarray
    critical_speed_kph: float | None

    @property
    def least_damping_ratio(self) -> np.ndarray:
        """Least damping ratio over the oscillatory modes per speed [-] (NaN where none oscillates)."""
        lam = self.eigenvalues
        osc = lam.imag > 1e-12 * np.maximum(np.abs(lam).max(axis=-1, keepdims=True), 1.0)
        zeta = np.where(osc, -lam.real / np.where(np.abs(lam) > 0, np.abs(lam), 1.0), np.inf)
        out = zeta.min(axis=-1)
        return np.where(np.isfinite(out), out, np.nan)

    @property
    def max_real(self) -> np.ndarray:
        """Largest real part per speed [1/s]."""
        return self.eigenvalues.real.max(axis=-1)


def speed_sweep(vehicle: Vehicle, speeds_kph, tire_scale: float = 1.0) -> SpeedSweep:
    """Eigenvalues at every speed [km/h] (batched) and the critical speed."""
    v = np.asarray(speeds_kph, dtype=float)
    return SpeedSweep(v, eigenvalues(vehicle, kph_to_mps(v), tire_scale), critical_speed(vehicle, tire_scale))


@dataclass(frozen=True)
class AxleSensitivity:
    """Trimmed straight running per unit residual load on one axle.

    Attributes
    ----------
    axle, unit : str
    offtracking_per_P_m_per_kN, offtracking_per_T_m_per_kNm : float
        Trimmed offtracking [m] per kN of P (along +y) and per kN*m of T (about +z).
    delta_per_P_rad_per_kN, delta_per_T_rad_per_kNm : float
        Trim steer angle [rad] per kN of P and per kN*m of T.
    """

    axle: str
    unit: str
    offtracking_per_P_m_per_kN: float
    offtracking_per_T_m_per_kNm: float
    delta_per_P_rad_per_kN: float
    delta_per_T_rad_per_kNm: float

    @property
    def largest_m(self) -> float:
        """The larger |offtracking| of 1 kN of P and 1 kN*m of T [m] (the ranking key)."""
        return max(abs(self.offtracking_per_P_m_per_kN), abs(self.offtracking_per_T_m_per_kNm))


def conicity_sensitivity(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> list[AxleSensitivity]:
    """Trimmed offtracking and trim steer per unit P and T on each axle, ranked by |offtracking|, largest first."""
    co = system_coefficients(vehicle)
    out = []
    for col, (i, ax) in enumerate(zip(vehicle.axle_units, vehicle.axles)):
        tp = trim(vehicle, speed_mps, co.B_P[:, col] * 1e3, tire_scale)
        tt = trim(vehicle, speed_mps, co.B_T[:, col] * 1e3, tire_scale)
        out.append(AxleSensitivity(ax.name, vehicle.units[i].name, tp.offtracking_m, tt.offtracking_m,
                                   tp.delta_rad, tt.delta_rad))
    return sorted(out, key=lambda a: a.largest_m, reverse=True)


@dataclass(frozen=True)
class MeasureSet:
    """Every measure of :data:`lcvreport.analysis.registry.MEASURES` for one vehicle at one
    speed, by keyword (the registry's keys; ``trim`` holds ``trim.delta_rad`` and
    ``trim.offtracking_m``).  ``to_dict()`` gives the JSON of ``lcv measures``, in the
    registry's order, with ``reasons`` for every null; ``rows()`` the text and report table.
    """

    vehicle: Vehicle
    speed_mps: float
    tire_scale: float = 1.0
    least_damping_ratio: float | None = None
    least_damped_frequency_hz: float | None = None
    critical_speed_kph: float | None = None
    ra_frequency: float | None = None
    ra_single_sine: float | None = None
    ay_gain_per_unit: list[float] | None = None
    trim: Trim | None = None
    load_units: tuple[str, ...] = ()
    f_hz: float = RA_FREQUENCY_HZ
    #: measure key -> why it is null (e.g. no steered axle: no steer input to respond to)
    undefined: dict = field(default_factory=dict)
    ra_peak: float | None = None
    ra_peak_frequency_hz: float | None = None
    yaw_damping_coefficient: float | None = None
    yaw_damping_lower_bound: float | None = None
    hsto_m: float | None = None
    ra_lane_change: float | None = None
    hsso_m: float | None = None
    steady_turn_delta_rad: float | None = None
    sources: object = None
    lssp_m: float | None = None
    low_speed_offtracking_m: float | None = None
    max_tail_swing_m: float | None = None
    frontal_swing_m: float | None = None

    def value(self, key: str):
        """The value of the registry key ``key`` (None where undefined)."""
        if key.startswith("trim."):
            return None if self.trim is None else getattr(self.trim, key.split(".", 1)[1])
        value = getattr(self, key)
        return list(value) if isinstance(value, (list, tuple)) else value

    def reason(self, key: str) -> str | None:
        """Why the measure ``key`` is null (None when it has a value)."""
        if self.value(key) is not None:
            return None
        if key.startswith("trim."):
            return self.undefined.get("trim", "no residual source was given (--load, --residual, "
                                              "--misalignment, --crossfall-percent, --tires)")
        if key == "critical_speed_kph":
            return self.undefined.get(key, f"stable at every speed up to {CRITICAL_SPEED_MAX_KPH:g} km/h")
        if key == "least_damping_ratio" or key == "least_damped_frequency_hz":
            return self.undefined.get(key, "no mode oscillates")
        if key == "yaw_damping_lower_bound":
            return "the yaw damping coefficient has a value (the bound is only given when every joint is " \
                   "heavily damped)" if self.yaw_damping_coefficient is not None else \
                self.undefined.get("yaw_damping_coefficient", "")
        return self.undefined.get(key, "undefined")

    def to_dict(self) -> dict:
        """The JSON of ``lcv measures`` (SPEC sections 8, 12, 16): the registry's keys in its order
        (a dotted key nested: ``trim`` holds ``delta_rad`` and ``offtracking_m``, present with a
        residual source), and ``reasons``: {key: why it is null} for every null."""
        from .registry import MEASURES
        doc, reasons = {}, {}
        for key in MEASURES:
            if key.startswith("trim."):
                if self.trim is None and "trim" not in self.undefined:
                    continue                         # no residual source: no trim (SPEC 8)
                doc["trim"] = None if self.trim is None else {"delta_rad": self.trim.delta_rad,
                                                              "offtracking_m": self.trim.offtracking_m}
                if self.trim is None:
                    reasons["trim"] = self.reason(key)
                continue
            doc[key] = self.value(key)
            if doc[key] is None:
                reasons[key] = self.reason(key)
        doc["reasons"] = reasons
        return doc

    def rows(self) -> list[dict]:
        """The measures as table rows: name, value, unit, definition (or why it is null), and
        the key of the same number in :meth:`to_dict` (``ay_gain_per_unit[0]`` for list items)."""
        from .registry import MEASURES
        f = f"{self.f_hz:g} Hz"
        rows = []
        for key, m in MEASURES.items():
            value = self.value(key)
            if key == "speed_mps":
                rows.append({"measure": m.label, "value": value, "unit": m.unit,
                             "note": f"{mps_to_kph(self.speed_mps):.1f} km/h", "json_key": key})
            elif m.shape == "per_unit":
                if value is None:
                    rows.append({"measure": m.label + "s", "value": "none", "unit": m.unit,
                                 "note": self.reason(key), "json_key": key})
                for k, (name, g) in enumerate(zip(self.vehicle.unit_names, value or ())):
                    rows.append({"measure": f"{m.label}, {name}", "value": g, "unit": m.unit,
                                 "note": f"|G_{k + 1}(j2π·{f})|", "json_key": f"{key}[{k}]"})
            elif key.startswith("trim."):
                if self.trim is not None:
                    what = "; ".join(x for x in (f"1 % rule on {', '.join(self.load_units)}" if self.load_units
                                                 else "", self.sources.describe() if self.sources else "") if x)
                    rows.append({"measure": m.label, "value": value, "unit": m.unit,
                                 "note": what if key == "trim.delta_rad" else m.definition, "json_key": key})
                elif "trim" in self.undefined and key == "trim.delta_rad":
                    rows.append({"measure": "trim", "value": "none", "unit": "", "note": self.undefined["trim"],
                                 "json_key": "trim"})
            else:
                note = m.definition if value is not None else self.reason(key)
                if key in ("ra_frequency", "ra_single_sine"):
                    note = note.replace("0.4 Hz", f)
                rows.append({"measure": m.label.replace("0.4 Hz", f), "value": "none" if value is None else value,
                             "unit": m.unit, "note": note, "json_key": key})
        return rows


@functools.lru_cache(maxsize=64)
def low_speed_measures(vehicle: Vehicle) -> tuple[dict, dict]:
    """The SPEC section 16 measures of ``vehicle`` (independent of speed and tire scale: cached
    per vehicle) and, for each that is null, why: (values, reasons)."""
    from .low_speed_turn import TurnError, low_speed_turn
    try:
        t = low_speed_turn(vehicle)
    except TurnError as exc:
        return {}, {k: f"undefined: {exc}" for k in LOW_SPEED_KEYS}
    values = {"lssp_m": t.lssp_m, "low_speed_offtracking_m": t.low_speed_offtracking_m,
              "max_tail_swing_m": t.max_tail_swing_m, "frontal_swing_m": t.frontal_swing_m}
    return values, {k: f"undefined: {why}" for k, why in t.undefined.items()}


#: the low-speed measures' keys (a second model: computed per vehicle, cached)
LOW_SPEED_KEYS = ("lssp_m", "low_speed_offtracking_m", "max_tail_swing_m", "frontal_swing_m")


def measure_set(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0, load_units=None,
                f_hz: float = RA_FREQUENCY_HZ, sources=None) -> MeasureSet:
    """Every measure of the registry (SPEC sections 8, 12, 16) of ``vehicle`` at ``speed_mps`` [m/s].

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
    tire_scale : float
    load_units : list of str, optional
        Units carrying the 1 % rule (P along +y, T about +z) for the trim.
    f_hz : float
        Frequency of the RA measures and gains [Hz].
    sources : lcvreport.model.loads.ResidualSources, optional
        Further residual sources for the trim (per-axle P and T, misalignment, crossfall);
        with ``load_units`` the 1 % rule adds to them.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> m = measure_set(load_preset("tractor_semitrailer"), 24.4444)
    >>> sorted(m.to_dict())[:4]
    ['ay_gain_per_unit', 'critical_speed_kph', 'frontal_swing_m', 'hsso_m']
    """
    from . import field_measures as fm
    from .exact import ManoeuvreError
    zeta, f_zeta = least_damping(vehicle, speed_mps, tire_scale)
    units = tuple(load_units) if load_units else ()
    has_sources = bool(units) or bool(sources)
    low, low_why = low_speed_measures(vehicle)
    undefined = dict(low_why)
    common = dict(vehicle=vehicle, speed_mps=float(speed_mps), tire_scale=float(tire_scale),
                  least_damping_ratio=zeta, least_damped_frequency_hz=f_zeta,
                  critical_speed_kph=critical_speed(vehicle, tire_scale), load_units=units, f_hz=float(f_hz),
                  sources=sources, **low)
    if not vehicle.steered_axles:
        from .registry import MEASURES
        why = "undefined: the vehicle has no steered axle, so no steer input to respond to or trim with"
        undefined.update({k: why for k, m in MEASURES.items() if m.needs == "steer"})
        if has_sources:
            undefined["trim"] = why
        return MeasureSet(undefined=undefined, **common)
    gains = np.abs(steer_to_acceleration(vehicle, speed_mps, f_hz, tire_scale))
    # only the numbers are kept: each manoeuvre's response (up to a megabyte of samples) is freed
    # before the next one is computed (a smaller heap, which malloc does not hand back and fault in)
    ra_ss = single_sine(vehicle, speed_mps, f_hz, tire_scale=tire_scale).rearward_amplification
    tr = None
    if has_sources:
        F = np.zeros(vehicle.n_states)
        if units:
            F = F + load_vector(vehicle, one_percent_rule(vehicle, list(units)))
        if sources:
            F = F + sources.vector(vehicle, tire_scale)
        tr = trim(vehicle, speed_mps, F, tire_scale)
        check_trim(tr)
    peak = fm.ra_peak(vehicle, speed_mps, tire_scale)
    ydc = fm._yaw_damping(vehicle, speed_mps, tire_scale, zeta)
    ydc_value, ydc_bound = ydc.value, ydc.lower_bound
    if ydc_value is None:
        undefined["yaw_damping_coefficient"] = f"undefined: {ydc.why}"
    del ydc
    try:
        lc = fm.lane_change_measures(vehicle, speed_mps, tire_scale)
        hsto, ra_lc = lc.hsto_m, lc.ra_lane_change
        del lc
    except ManoeuvreError as exc:
        hsto = ra_lc = None
        undefined["hsto_m"] = undefined["ra_lane_change"] = f"undefined: {exc}"
    turn = fm.steady_turn(vehicle, speed_mps, tire_scale)
    return MeasureSet(ra_frequency=float(gains[-1] / gains[0]), ra_single_sine=ra_ss,
                      ay_gain_per_unit=[float(g) for g in gains], trim=tr, undefined=undefined,
                      ra_peak=peak.value, ra_peak_frequency_hz=peak.frequency_hz,
                      yaw_damping_coefficient=ydc_value, yaw_damping_lower_bound=ydc_bound, hsto_m=hsto,
                      ra_lane_change=ra_lc, hsso_m=turn.hsso_m, steady_turn_delta_rad=turn.delta_rad, **common)


def check_trim(tr: Trim) -> None:
    """Refuse a trim outside the ranges table: a trim steer beyond [-1, 1] rad is no longer
    a small angle, and the linear model's answer means nothing (a unit typo, such as a
    cornering stiffness in kN/rad, is the usual cause).

    Raises
    ------
    RangeError
    """
    r = RANGES["steer_angle"]
    if not r.contains(tr.delta_rad):
        raise RangeError("trim.delta_rad", f"the trim steer angle {tr.delta_rad:.4g} rad is outside {r.text()}: the "
                                           "linear model does not hold there; check the vehicle file's units "
                                           "(cornering stiffness per tire in N/rad, masses in kg)")
