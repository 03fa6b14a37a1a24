"""The critical-speed scan as it was before issue 32 (every 4 km/h, 1 km/h in the doubtful
intervals, bisection to 0.01 km/h): the reference the faster scan of
:mod:`lcvreport.measures.stability` must equal to the last printed digit, kept verbatim here
(the benchmarks' baseline too)."""
from __future__ import annotations

import math

import numpy as np

from lcvreport.analysis.modes import state_matrix
from lcvreport.model.linear import check_tire_scale
from lcvreport.ranges import RANGES
from lcvreport.units import kph_to_mps, mps_to_kph

CRITICAL_SPEED_MAX_KPH = 200.0
U_MIN_DEFAULT_MPS = 2.2352


def legacy_critical_speed(vehicle: Vehicle, tire_scale: float = 1.0, u_min_mps: float = U_MIN_DEFAULT_MPS,
                   u_max_kph: float = CRITICAL_SPEED_MAX_KPH, model: str = "yaw_plane") -> float | None:
    """Lowest speed [km/h] in ``(u_min, u_max]`` where ``max Re(lambda) >= 0`` (of the linear
    model ``model``), to 0.1 km/h; None if stable.

    ``max Re(lambda)`` is scanned every 4 km/h; every interval whose ends are not
    clearly stable -- closer to 0 than twice the largest change of ``max Re(lambda)``
    over that interval and its neighbours -- is scanned again every 1 km/h; bisection
    narrows the first unstable speed to 0.01 km/h, rounded to 0.1 km/h.  An instability
    band narrower than 1 km/h can be missed (none of the vehicles here has one); the result
    equals a dense scan (tested).

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



def legacy_critical_speed_batched(batch: VariantBatch, tire_scale: float = 1.0, u_min_mps: float | None = None,
                            u_max_kph: float | None = None) -> np.ndarray:
    """The critical speed [km/h] of every variant (NaN: stable up to ``u_max_kph``), by the
    algorithm of :func:`lcvreport.measures.stability.critical_speed` run on all variants at
    once: the coarse 4 km/h scan, the 1 km/h scan of each variant's own doubtful intervals,
    the bisection to 0.01 km/h, rounded to 0.1 km/h."""
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


