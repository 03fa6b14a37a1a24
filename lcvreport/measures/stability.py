"""Stability over speed: the least damping ratio, the critical speed and the speed sweep
(definitions: ``docs/measures.md#least-damping-ratio``, ``#critical-speed``).

* **Least damping ratio**: the smallest ``-Re(lambda)/|lambda|`` over the eigenvalues with
  ``Im(lambda) > 0``, and that mode's damped frequency ``Im(lambda)/2 pi`` [Hz]; None when no
  mode oscillates.
* **Critical speed**: the lowest speed in ``(u_min, 200 km/h]`` where the largest real part
  of the eigenvalues is >= 0, to 0.1 km/h (a 4 km/h scan, a 1 km/h scan of the doubtful
  intervals, then bisection); None when stable throughout.

Examples
--------
>>> from lcvreport import load_preset
>>> zeta, f_hz = least_damping(load_preset("aucnat"), 24.4444)
>>> round(zeta, 3), round(f_hz, 3)
(0.349, 1.047)
>>> critical_speed(load_preset("aucnat")) is None
True
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.batch import VariantBatch
from ..analysis.modes import eigenvalues, state_matrix
from ..model.linear import check_tire_scale
from ..model.vehicle import Vehicle
from ..ranges import RANGES
from ..units import kph_to_mps, mps_to_kph
from ..util.threads import one_blas_thread
from .registry import MeasureCase

#: upper end of the critical-speed search [km/h]
CRITICAL_SPEED_MAX_KPH = 200.0


#: lower end of the critical-speed search: the FMUs' default u_min (5 mph) [m/s]
U_MIN_DEFAULT_MPS = 2.2352


def least_damping(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0,
                  model: str = "yaw_plane") -> tuple[float | None, float | None]:
    """(least damping ratio [-], its damped frequency [Hz]) over the oscillatory modes of the
    linear model ``model``; (None, None) if none."""
    lam = eigenvalues(vehicle, speed_mps, tire_scale, model)
    osc = lam[lam.imag > 1e-12 * max(np.abs(lam).max(), 1.0)]
    if osc.size == 0:
        return None, None
    zeta = -osc.real / np.abs(osc)
    k = int(np.argmin(zeta))
    return float(zeta[k]), float(osc[k].imag / (2 * np.pi))


@one_blas_thread
def critical_speed(vehicle: Vehicle, tire_scale: float = 1.0, u_min_mps: float = U_MIN_DEFAULT_MPS,
                   u_max_kph: float = CRITICAL_SPEED_MAX_KPH, model: str = "yaw_plane") -> float | None:
    """Lowest speed [km/h] in ``(u_min, u_max]`` where ``max Re(lambda) >= 0`` (of the linear
    model ``model``), to 0.1 km/h; None if stable.

    ``max Re(lambda)`` is scanned every 4 km/h; every interval whose ends are not
    clearly stable -- closer to 0 than twice the largest change of ``max Re(lambda)``
    over that interval and its neighbours -- is scanned again every 1 km/h; bisection
    narrows the first unstable speed to 0.01 km/h, rounded to 0.1 km/h.  An instability
    band narrower than 1 km/h can be missed (none of the vehicles here has one); the result
    equals a dense scan (tested).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> critical_speed(load_preset("empty"), tire_scale=0.2)
    73.9
    """
    check_tire_scale(tire_scale)
    lo_kph = mps_to_kph(RANGES["u_min"].check(u_min_mps, "u_min"))

    def max_real(v_kph):
        A = state_matrix(vehicle, kph_to_mps(np.asarray(v_kph, dtype=float)), tire_scale, model)
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


def least_damping_batched(batch: VariantBatch, speed_mps: float,
                          tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(least damping ratio [-], its damped frequency [Hz]) of every variant over the oscillatory
    modes, as :func:`lcvreport.measures.stability.least_damping` (NaN where none oscillates)."""
    lam = batch.eigenvalues(speed_mps, tire_scale)
    osc = lam.imag > 1e-12 * np.maximum(np.abs(lam).max(axis=-1, keepdims=True), 1.0)
    zeta = np.where(osc, -lam.real / np.where(np.abs(lam) > 0, np.abs(lam), 1.0), np.inf)
    k = np.argmin(zeta, axis=-1)
    rows = np.arange(lam.shape[0])
    best = zeta[rows, k]
    f_hz = lam[rows, k].imag / (2 * np.pi)
    none = ~np.isfinite(best)
    return np.where(none, np.nan, best), np.where(none, np.nan, f_hz)


def critical_speed_batched(batch: VariantBatch, tire_scale: float = 1.0, u_min_mps: float | None = None,
                           u_max_kph: float | None = None) -> np.ndarray:
    """The critical speed [km/h] of every variant (NaN: stable up to ``u_max_kph``): see
    :func:`_critical_speed_batched` (groups of 256 variants)."""
    return batch.in_groups(_critical_speed_batched, tire_scale, u_min_mps, u_max_kph)


def _critical_speed_batched(batch: VariantBatch, tire_scale: float = 1.0, u_min_mps: float | None = None,
                            u_max_kph: float | None = None) -> np.ndarray:
    """The critical speed [km/h] of every variant (NaN: stable up to ``u_max_kph``), by the
    algorithm of :func:`lcvreport.measures.stability.critical_speed` run on all variants at
    once: the coarse 4 km/h scan, the 1 km/h scan of each variant's own doubtful intervals,
    the bisection to 0.01 km/h, rounded to 0.1 km/h."""
    from ..ranges import RANGES
    from ..units import mps_to_kph
    u_max_kph = CRITICAL_SPEED_MAX_KPH if u_max_kph is None else u_max_kph
    lo_kph = mps_to_kph(RANGES["u_min"].check(U_MIN_DEFAULT_MPS if u_min_mps is None else u_min_mps, "u_min"))
    B = batch.size
    coarse = np.linspace(lo_kph, u_max_kph, max(int(math.ceil((u_max_kph - lo_kph) / 4.0)) + 1, 2))
    sigma = batch.max_real_at(np.broadcast_to(coarse, (B, coarse.size)), tire_scale)     # (B, K)
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
        fine_vals[rows, cols] = batch.values_at(rows, fine[cols], tire_scale)
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
            unstable = batch.values_at(todo[m], mid[m], tire_scale) >= 0.0
            hi[m] = np.where(unstable, mid[m], hi[m])
            lo[m] = np.where(unstable, lo[m], mid[m])
            active = hi - lo > 0.01
        out[todo] = np.round(0.5 * (lo + hi), 1)
    return out


def least_damping_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``least_damping`` family of one case: (values, reasons)."""
    zeta, f_hz = least_damping(case.vehicle, case.speed_mps, case.tire_scale)
    case.shared["least_damping_ratio"] = zeta
    keys = ("least_damping_ratio", "least_damped_frequency_hz")
    return dict(zip(keys, (zeta, f_hz))), ({} if zeta is not None else {k: "no mode oscillates" for k in keys})


def critical_speed_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``critical_speed`` family of one case: (values, reasons)."""
    v = critical_speed(case.vehicle, case.tire_scale)
    why = {} if v is not None else {
        "critical_speed_kph": f"stable at every speed up to {CRITICAL_SPEED_MAX_KPH:g} km/h"}
    return {"critical_speed_kph": v}, why
