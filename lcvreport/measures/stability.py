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
from functools import lru_cache

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
    linear model ``model``; (None, None) if none.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    tire_scale : float
        Factor on every tire coefficient [-].
    model : str
        A linear model (:data:`lcvreport.model.base.LINEAR_MODELS`).

    Returns
    -------
    tuple of (float or None, float or None)
        The least damping ratio [-] and its damped frequency [Hz].

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> zeta, f_hz = least_damping(load_preset("aucnat"), 24.4)
    >>> 0.0 < zeta < 1.0 and f_hz > 0.0
    True
    """
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

    The scan of :func:`first_unstable_speeds` (docs/measures.md#critical-speed): the grid every
    4 km/h looked at every 16 km/h first, opened where doubtful, every 1 km/h where doubtful
    below the first unstable point, bisection to 0.01 km/h, rounded to 0.1 km/h.  An instability
    band narrower than the scan's steps can be missed: :func:`stability_crossings` computes every
    speed where an eigenvalue crosses the imaginary axis, exactly (the tests hold the two together).

    Parameters
    ----------
    vehicle : Vehicle
    tire_scale : float
        Factor on every tire coefficient [-].
    u_min_mps : float
        Lowest speed looked at [m/s].
    u_max_kph : float
        Highest speed looked at [km/h].
    model : str
        A linear model (:data:`lcvreport.model.base.LINEAR_MODELS`).

    Returns
    -------
    float or None
        [km/h], to 0.1 km/h; None if stable up to ``u_max_kph``.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> critical_speed(load_preset("empty"), tire_scale=0.2)
    73.9
    """
    check_tire_scale(tire_scale)
    lo_kph = mps_to_kph(RANGES["u_min"].check(u_min_mps, "u_min"))

    def evaluate(_rows, v_kph):
        A = state_matrix(vehicle, kph_to_mps(np.asarray(v_kph, dtype=float)), tire_scale, model)
        return np.linalg.eigvals(A).real.max(axis=-1)

    out = first_unstable_speeds(evaluate, 1, lo_kph, u_max_kph)[0]
    return None if math.isnan(out) else float(out)


def first_unstable_speeds(evaluate, n_variants: int, lo_kph: float, hi_kph: float) -> np.ndarray:
    """The critical speed [km/h] of each of ``n_variants`` (NaN: none up to ``hi_kph``), rounded
    to 0.1 km/h, from ``evaluate(rows, v_kph) -> max Re(lambda)`` (variant ``rows[k]`` at speed
    ``v_kph[k]``, arrays of one length).

    The scan (docs/measures.md#critical-speed) is defined on the grid of ``ceil((hi - lo) / 4) + 1``
    even points (about every 4 km/h): an interval of it is *doubtful* when ``max Re(lambda)`` at
    either end is above ``-2 x`` the largest change of ``max Re(lambda)`` over that interval and its
    two neighbours; the doubtful intervals are scanned every 1 km/h; the first unstable point
    found and the point before it bracket a bisection to 0.01 km/h.  It is evaluated lazily: the
    grid's every fourth point first, the same doubt rule on that coarse grid opens the groups of
    four intervals worth looking at (each with one point beyond either side, so the rule on the
    4 km/h grid sees what it would see on the whole grid), and the group ending at the first unstable
    coarse point always; only intervals below the first unstable point are refined.  Where an
    instability is not narrower than the coarse grid's doubt margin, this is the whole grid's scan
    exactly (tests/test_critical_speed.py: the same answer as the whole-grid scan on every preset,
    example and random variant tried), with about half its eigenvalue solves."""
    B = n_variants
    grid, coarse, fine, owner, order = _scan_grid(float(lo_kph), float(hi_kph))
    K = grid.size
    sigma = np.full((B, K), np.nan)                      # max Re(lambda) on the grid, NaN: not evaluated

    def fill(mask):                                      # evaluate the grid points mask[b, k] not yet known
        rows, cols = np.nonzero(mask & np.isnan(sigma))
        if rows.size:
            sigma[rows, cols] = evaluate(rows, grid[cols])

    def doubtful(values):                                # the doubt rule on a grid of values (B, J)
        step = np.abs(np.diff(values, axis=1))
        padded = np.concatenate([step[:, :1], step, step[:, -1:]], axis=1)
        with np.errstate(invalid="ignore"):
            slope = np.maximum(np.maximum(padded[:, :-2], padded[:, 1:-1]), padded[:, 2:])
            return np.maximum(values[:, :-1], values[:, 1:]) > -2.0 * slope

    def below_first_unstable(values):                    # intervals at or below the first unstable point
        unstable = values >= 0.0
        first = np.where(unstable.any(axis=1), np.argmax(unstable, axis=1), values.shape[1])
        return np.arange(values.shape[1] - 1)[None, :] < first[:, None]

    # 1. every fourth grid point (and the last)
    pick = np.zeros((B, K), bool)
    pick[:, coarse] = True
    fill(pick)
    sc = sigma[:, coarse]
    # 2. open the doubtful groups below the first unstable coarse point, and the group ending at it
    open_group = below_first_unstable(sc) & (doubtful(sc) | _ends_at_first_unstable(sc))
    want = np.zeros((B, K), bool)
    for g in np.flatnonzero(open_group.any(axis=0)):
        want[np.ix_(np.flatnonzero(open_group[:, g]), np.arange(max(coarse[g] - 1, 0), min(coarse[g + 1] + 2, K)))] = True
    fill(want)
    known = ~np.isnan(sigma)
    # 3. the doubt rule on the 4 km/h grid where all it reads is known, below the first unstable point
    with np.errstate(invalid="ignore"):
        near = doubtful(np.where(known, sigma, np.nan)) & below_first_unstable(np.where(known, sigma, -np.inf))
    use = near[:, owner]                                                                # (B, F)
    fine_vals = np.full(use.shape, -np.inf)
    rows, cols = np.nonzero(use)
    if rows.size:
        fine_vals[rows, cols] = evaluate(rows, fine[cols])
    # 4. the first unstable point and the one before it bracket the bisection
    points = np.concatenate([grid, fine])[order]
    values = np.concatenate([np.where(known, sigma, -np.inf), fine_vals], axis=1)[:, order]
    present = np.concatenate([known, use], axis=1)[:, order]
    flags = (values >= 0.0) & present
    out = np.full(B, np.nan)
    found = flags.any(axis=1)
    first = np.argmax(flags, axis=1)
    out[found & (first == 0)] = np.round(points[0], 1)
    todo = np.flatnonzero(found & (first > 0))
    if todo.size:
        idx = np.arange(points.size)
        prev = np.array([idx[present[b] & (idx < first[b])].max() for b in todo])
        lo, hi = points[prev].astype(float), points[first[todo]].astype(float)
        s_lo, s_hi = values[todo, prev], values[todo, first[todo]]
        lo, hi = _bisect(evaluate, todo, lo, hi, s_lo, s_hi)
        out[todo] = np.round(0.5 * (lo + hi), 1)
    return out


def _bisect(evaluate, rows, lo, hi, s_lo, s_hi, width: float = 0.01):
    """Bisection of each bracket ``[lo, hi]`` (``max Re(lambda)`` < 0 at lo, >= 0 at hi) to ``width``
    [km/h]: at every midpoint, hi moves there where ``max Re(lambda) >= 0``, lo otherwise.  The
    midpoints are evaluated several at a time: the path the bisection would take if the root lay
    where the line through the bracket's ends crosses zero is evaluated in one call, and followed
    as long as every sign it finds is the one predicted -- so the brackets, and the answer, are the
    one-at-a-time bisection's exactly; a wrong prediction starts the next call from there."""
    lo, hi, s_lo, s_hi = (np.array(x, dtype=float) for x in (lo, hi, s_lo, s_hi))
    active = np.flatnonzero(hi - lo > width)
    while active.size:
        # the predicted paths (each to the end), the root where the chord crosses zero
        root = lo[active] + (hi[active] - lo[active]) * (-s_lo[active]) / (s_hi[active] - s_lo[active])
        a, b = lo[active].copy(), hi[active].copy()
        paths = []
        while True:
            go = b - a > width
            if not go.any():
                break
            mid = 0.5 * (a + b)
            paths.append(np.where(go, mid, np.nan))
            up = go & (mid >= root)
            b = np.where(up, mid, b)
            a = np.where(go & ~up, mid, a)
        mids = np.array(paths).T                                      # (active, depth), NaN past a path's end
        r, c = np.nonzero(~np.isnan(mids))
        got = np.full(mids.shape, np.nan)
        got[r, c] = evaluate(rows[active[r]], mids[r, c])
        # replay: follow each path while its signs are the predicted ones
        for k in range(mids.shape[1]):
            live = np.flatnonzero((hi[active] - lo[active] > width) & ~np.isnan(mids[:, k]))
            if not live.size:
                break
            j = active[live]
            mid = 0.5 * (lo[j] + hi[j])
            follows = mid == mids[live, k]                            # still on the predicted path
            if not follows.any():
                break
            j, live, mid = j[follows], live[follows], mid[follows]
            value = got[live, k]
            unstable = value >= 0.0
            hi[j] = np.where(unstable, mid, hi[j])
            s_hi[j] = np.where(unstable, value, s_hi[j])
            lo[j] = np.where(unstable, lo[j], mid)
            s_lo[j] = np.where(unstable, s_lo[j], value)
        active = np.flatnonzero(hi - lo > width)
    return lo, hi


@lru_cache(maxsize=16)
def _scan_grid(lo_kph: float, hi_kph: float):
    """The scan's points for a speed range (read-only): the grid (about every 4 km/h), the indices of
    its every fourth point, the 1 km/h points inside each of its intervals and their interval, and
    the order of grid and fine points together."""
    grid = np.linspace(lo_kph, hi_kph, max(int(math.ceil((hi_kph - lo_kph) / 4.0)) + 1, 2))
    K = grid.size
    coarse = np.unique(np.r_[np.arange(0, K, 4), K - 1])
    fine_of = [np.linspace(grid[i], grid[i + 1], int(math.ceil(grid[i + 1] - grid[i])) + 1)[1:-1] for i in range(K - 1)]
    fine = np.concatenate(fine_of)
    owner = np.concatenate([np.full(f.size, i) for i, f in enumerate(fine_of)])
    order = np.argsort(np.concatenate([grid, fine]), kind="stable")
    for arr in (grid, coarse, fine, owner, order):
        arr.setflags(write=False)
    return grid, coarse, fine, owner, order


def _ends_at_first_unstable(values: np.ndarray) -> np.ndarray:
    """(B, J-1): the interval of each row ending at its first unstable point."""
    unstable = values >= 0.0
    first = np.argmax(unstable, axis=1)
    hit = unstable.any(axis=1) & (first > 0)
    out = np.zeros((values.shape[0], values.shape[1] - 1), bool)
    out[np.flatnonzero(hit), first[hit] - 1] = True
    return out


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
    """The critical speed [km/h] of every variant (NaN: stable up to ``u_max_kph``): the scan of
    :func:`first_unstable_speeds` on all variants at once (each variant evaluates only its own
    points), as :func:`lcvreport.measures.stability.critical_speed` runs it on one."""
    u_max_kph = CRITICAL_SPEED_MAX_KPH if u_max_kph is None else u_max_kph
    lo_kph = mps_to_kph(RANGES["u_min"].check(U_MIN_DEFAULT_MPS if u_min_mps is None else u_min_mps, "u_min"))
    return first_unstable_speeds(lambda rows, v_kph: batch.values_at(rows, v_kph, tire_scale), batch.size, lo_kph,
                                 u_max_kph)


def least_damping_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``least_damping`` family of one case: (values, reasons)."""
    zeta, f_hz = least_damping(case.vehicle, case.speed_mps, case.tire_scale, model=case.model)
    case.shared["least_damping_ratio"] = zeta
    keys = ("least_damping_ratio", "least_damped_frequency_hz")
    return dict(zip(keys, (zeta, f_hz))), ({} if zeta is not None else {k: "no mode oscillates" for k in keys})


def critical_speed_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``critical_speed`` family of one case: (values, reasons)."""
    v = critical_speed(case.vehicle, case.tire_scale, model=case.model)
    why = {} if v is not None else {
        "critical_speed_kph": f"stable at every speed up to {CRITICAL_SPEED_MAX_KPH:g} km/h"}
    return {"critical_speed_kph": v}, why
