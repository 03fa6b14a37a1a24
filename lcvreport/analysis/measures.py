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
>>> sorted(m.to_dict())
['ay_gain_per_unit', 'critical_speed_kph', 'least_damped_frequency_hz', 'least_damping_ratio', 'ra_frequency', 'ra_single_sine', 'speed_mps', 'trim']
"""
from __future__ import annotations

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
SINGLE_SINE_STEP_S = 1e-3
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
        Steer angle held from each sample [rad].
    ay : numpy.ndarray, shape (K, N)
        Lateral acceleration of every unit's CG [m/s^2].
    frequency_hz, delta0_rad, speed_mps : float
    vehicle : Vehicle
    """

    time: np.ndarray
    delta: np.ndarray
    ay: np.ndarray
    frequency_hz: float
    delta0_rad: float
    speed_mps: float
    vehicle: Vehicle = field(repr=False, default=None)

    @property
    def rearward_amplification(self) -> float:
        """max|a_N| / max|a_1| [-]."""
        peaks = np.abs(self.ay).max(axis=0)
        return float(peaks[-1] / peaks[0])

    @property
    def peaks(self) -> np.ndarray:
        """max|a_i| per unit [m/s^2]."""
        return np.abs(self.ay).max(axis=0)

    def plot(self, ax=None):
        """Time histories of every unit's a_i (a :class:`matplotlib.figure.Figure`)."""
        from ..report.plotting import plot_single_sine
        return plot_single_sine(self, ax=ax)


def single_sine(vehicle: Vehicle, speed_mps: float, f_hz: float = RA_FREQUENCY_HZ,
                delta0_rad: float = SINGLE_SINE_DELTA0_RAD, tire_scale: float = 1.0,
                step_s: float = SINGLE_SINE_STEP_S, tail_s: float = SINGLE_SINE_TAIL_S) -> SingleSine:
    """The single-sine manoeuvre from rest, exact for the sampled steer (zero-order hold).

    One period of ``delta = delta0 sin(2 pi f t)`` sampled every ``step_s`` and held,
    then straight ahead for ``tail_s``; the lateral accelerations of every unit's CG at
    every sample.

    The response is evaluated in closed form over the modes of ``A = M^-1 S`` (with
    ``mu = exp(lambda h)``, ``z = exp(i 2 pi f h)``, the modal response to the sampled
    sine is ``sum_j mu^(k-1-j) z^j = (z^k - mu^k)/(z - mu)``, and after the sine
    ``xi_k = mu^(k-K) xi_K``), straight onto the outputs, one mode of each complex pair
    (the other is its conjugate).  Equal to stepping the exact discretization (tested);
    falls back to stepping if the eigenvectors are ill-conditioned.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> s = single_sine(load_preset("aucnat"), 24.4444)
    >>> s.ay.shape, round(s.rearward_amplification, 2)
    ((10501, 6), 4.79)
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    f = float(_freq(f_hz))
    RANGES["steer_angle"].check(delta0_rad, "delta0")
    co = system_coefficients(vehicle)
    A, G = co.state_derivative_maps(speed_mps, tire_scale)
    bd = G @ co.B_delta(tire_scale)
    Ca, Da = co.acceleration_maps(speed_mps, tire_scale)
    da = Da @ co.B_delta(tire_scale)
    h = float(step_s)
    n_sine = int(round(1.0 / (f * h)))
    n_total = int(round((1.0 / f + tail_s) / h))
    k = np.arange(n_total + 1)
    t = k * h
    delta = np.where(k < n_sine, delta0_rad * np.sin(2 * np.pi * f * t), 0.0)
    lam, V = np.linalg.eig(A)
    theta = 2 * np.pi * f * h
    zc = np.exp(1j * theta)
    if np.linalg.cond(V) < 1e8 and np.all(np.abs(zc - np.exp(lam * h)) > 1e-9) and np.all(lam != 0):
        # one of each conjugate pair, counted twice; real modes once
        keep = lam.imag >= 0
        weight = np.where(np.abs(lam.imag) > 0, 2.0, 1.0)[keep]
        beta = np.linalg.solve(V, bd)[keep]
        lam_k, W = lam[keep], (Ca @ V)[:, keep].T * weight[:, None]    # modal -> output, (m, N)
        mu = np.exp(lam_k * h)
        g = beta * (mu - 1.0) / lam_k * delta0_rad / 2j
        p, q = 1.0 / (zc - mu), 1.0 / (np.conj(zc) - mu)
        n_after = n_total - n_sine
        E = np.exp(np.outer(np.arange(max(n_sine, n_after) + 1), lam_k * h))       # mu^k, (rows, m)
        ks = k[:n_sine + 1]
        # xi_k = g (z^k p - conj(z)^k q - mu^k (p - q)) for k <= n_sine
        ay_sine = (np.exp(1j * theta * ks)[:, None] * ((g * p) @ W)[None, :]
                   - np.exp(-1j * theta * ks)[:, None] * ((g * q) @ W)[None, :]
                   - E[:n_sine + 1] @ ((g * (p - q))[:, None] * W)).real
        xi_end = g * (zc ** n_sine * p - np.conj(zc) ** n_sine * q - mu ** n_sine * (p - q))
        ay_after = (E[1:n_after + 1] @ (xi_end[:, None] * W)).real
        ay = np.vstack([ay_sine, ay_after]) + delta[:, None] * da
    else:  # pragma: no cover - defective or resonant: step the exact discretization
        from .discretize import augmented_state_matrix, discretize
        Aa, Ga = augmented_state_matrix(co, speed_mps, tire_scale)
        Ad, Gd = discretize(Aa, Ga, h)
        n = vehicle.n_states
        x = np.zeros((k.size, n))
        z = np.zeros(n + 2)
        b = Gd @ co.B_delta(tire_scale)
        for i in range(k.size - 1):
            z = Ad @ z + b * delta[i]
            x[i + 1] = z[:n]
        ay = x @ Ca.T + delta[:, None] * da
    return SingleSine(t, delta, ay, f, float(delta0_rad), float(speed_mps), vehicle)


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


def trim(vehicle: Vehicle, speed_mps: float, F: np.ndarray, tire_scale: float = 1.0) -> Trim:
    """Trimmed straight running under a constant generalized force F (SI).

    Solves ``S x + b delta + F = 0`` with ``r1 = 0`` for ``x`` and ``delta``.
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle)
    S, b = co.S(speed_mps, tire_scale), co.B_delta(tire_scale)
    n = vehicle.n_states
    K = np.zeros((n + 1, n + 1))
    K[:n, :n] = S
    K[:n, n] = b
    K[n, 1] = 1.0                       # r1 = 0
    rhs = np.concatenate([-np.asarray(F, dtype=float), [0.0]])
    sol = np.linalg.solve(K, rhs)
    x, delta = sol[:n], float(sol[n])
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
    """The measures of SPEC section 8 for one vehicle at one speed.

    ``to_dict()`` gives the JSON of ``lcv measures`` (keys fixed by the SPEC).
    """

    vehicle: Vehicle
    speed_mps: float
    tire_scale: float
    least_damping_ratio: float | None
    least_damped_frequency_hz: float | None
    critical_speed_kph: float | None
    ra_frequency: float | None
    ra_single_sine: float | None
    ay_gain_per_unit: list[float] | None
    trim: Trim | None = None
    load_units: tuple[str, ...] = ()
    f_hz: float = RA_FREQUENCY_HZ
    #: measure key -> why it is null (e.g. no steered axle: no steer input to respond to)
    undefined: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The SPEC section 8 JSON document."""
        doc = {"speed_mps": self.speed_mps, "least_damping_ratio": self.least_damping_ratio,
               "least_damped_frequency_hz": self.least_damped_frequency_hz,
               "critical_speed_kph": self.critical_speed_kph, "ra_frequency": self.ra_frequency,
               "ra_single_sine": self.ra_single_sine,
               "ay_gain_per_unit": None if self.ay_gain_per_unit is None else list(self.ay_gain_per_unit)}
        if self.trim is not None:
            doc["trim"] = {"delta_rad": self.trim.delta_rad, "offtracking_m": self.trim.offtracking_m}
        elif "trim" in self.undefined:
            doc["trim"] = None
        return doc

    def rows(self) -> list[dict]:
        """The measures as table rows: name, value, unit, definition, and the key of the
        same number in :meth:`to_dict` (``ay_gain_per_unit[0]`` for list items)."""
        def num(v):
            return "none" if v is None else v
        f = f"{self.f_hz:g} Hz"
        rows = [{"measure": "speed", "value": self.speed_mps, "unit": "m/s",
                 "note": f"{mps_to_kph(self.speed_mps):.1f} km/h", "json_key": "speed_mps"},
                {"measure": "least damping ratio", "value": num(self.least_damping_ratio), "unit": "-",
                 "note": "min −Re λ/|λ| over oscillatory modes", "json_key": "least_damping_ratio"},
                {"measure": "least damped frequency", "value": num(self.least_damped_frequency_hz), "unit": "Hz",
                 "note": "Im λ/2π of that mode", "json_key": "least_damped_frequency_hz"},
                {"measure": "critical speed", "value": num(self.critical_speed_kph), "unit": "km/h",
                 "note": "lowest unstable speed up to 200 km/h (none: stable)", "json_key": "critical_speed_kph"},
                {"measure": f"rearward amplification, {f}", "value": num(self.ra_frequency), "unit": "-",
                 "note": self.undefined.get("ra_frequency", "|G_N| / |G_1|, frequency domain"),
                 "json_key": "ra_frequency"},
                {"measure": "rearward amplification, single sine", "value": num(self.ra_single_sine), "unit": "-",
                 "note": self.undefined.get("ra_single_sine", f"max|a_N| / max|a_1|, {f} single sine"),
                 "json_key": "ra_single_sine"}]
        if self.ay_gain_per_unit is None:
            rows.append({"measure": "lateral acceleration gains", "value": "none", "unit": "m/s²/rad",
                         "note": self.undefined.get("ay_gain_per_unit", ""), "json_key": "ay_gain_per_unit"})
        for k, (name, g) in enumerate(zip(self.vehicle.unit_names, self.ay_gain_per_unit or ())):
            rows.append({"measure": f"lateral acceleration gain, {name}", "value": g, "unit": "m/s²/rad",
                         "note": f"|G_{k + 1}(j2π·{f})|", "json_key": f"ay_gain_per_unit[{k}]"})
        if "trim" in self.undefined:
            rows.append({"measure": "trim", "value": "none", "unit": "", "note": self.undefined["trim"],
                         "json_key": "trim"})
        if self.trim is not None:
            rows.append({"measure": "trim steer angle", "value": self.trim.delta_rad, "unit": "rad",
                         "note": f"1 % rule on {', '.join(self.load_units)}", "json_key": "trim.delta_rad"})
            rows.append({"measure": "trimmed offtracking", "value": self.trim.offtracking_m, "unit": "m",
                         "note": "rearmost axle path − steered axle path, +y", "json_key": "trim.offtracking_m"})
        return rows


def measure_set(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0, load_units=None,
                f_hz: float = RA_FREQUENCY_HZ) -> MeasureSet:
    """Every SPEC section 8 measure of ``vehicle`` at ``speed_mps`` [m/s].

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
    tire_scale : float
    load_units : list of str, optional
        Units carrying the 1 % rule (P along +y, T about +z) for the trim; no trim if None.
    f_hz : float
        Frequency of the RA measures and gains [Hz].
    """
    zeta, f_zeta = least_damping(vehicle, speed_mps, tire_scale)
    units = tuple(load_units) if load_units else ()
    if not vehicle.steered_axles:
        why = "undefined: the vehicle has no steered axle, so no steer input to respond to or trim with"
        undefined = {k: why for k in ("ra_frequency", "ra_single_sine", "ay_gain_per_unit")}
        if units:
            undefined["trim"] = why
        return MeasureSet(vehicle, float(speed_mps), float(tire_scale), zeta, f_zeta,
                          critical_speed(vehicle, tire_scale), None, None, None, None, units, float(f_hz), undefined)
    gains = np.abs(steer_to_acceleration(vehicle, speed_mps, f_hz, tire_scale))
    ss = single_sine(vehicle, speed_mps, f_hz, tire_scale=tire_scale)
    tr = None
    if units:
        F = load_vector(vehicle, one_percent_rule(vehicle, list(units)))
        tr = trim(vehicle, speed_mps, F, tire_scale)
        check_trim(tr)
    return MeasureSet(vehicle, float(speed_mps), float(tire_scale), zeta, f_zeta,
                      critical_speed(vehicle, tire_scale), float(gains[-1] / gains[0]), ss.rearward_amplification,
                      [float(g) for g in gains], tr, units, float(f_hz))


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
