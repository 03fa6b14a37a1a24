"""Straight-line tracking over a tire population: fleet statistics of the trimmed offtracking.

A tire's conicity force points toward its serial side (the side with the DOT code), so it
flips in the vehicle frame with the mounting; its ply steer force does not
(:mod:`lcvreport.tracking.tires`).  The trimmed offtracking and trim steer
(``docs/measures.md#trimmed-straight-running``) are linear in the axle P and T, so their
mean and standard deviation over independent random tires are exact sums; quantiles and
the probability of leaving the lane margin come from a Monte Carlo with a fixed seed.

Examples
--------
>>> from lcvreport import load_preset
>>> s = tracking_stats(load_preset("aucnat"), 24.4444, parse_distribution("normal:0:100", "conicity"), ZERO,
...                    draws=1000)
>>> s.draws, s.seed
(1000, 20110801)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.steady import trim
from ..model.vehicle import Vehicle
from .tires import TrackingError, sensitivities, tire_slots

#: the default lane and body widths [m] (the thesis' 12 ft lane and 102 in trailer)
LANE_WIDTH_M = 3.66


BODY_WIDTH_M = 2.59


#: default Monte Carlo draws and seed
DRAWS = 1_000_000


SEED = 20110801


#: quantiles reported [-]
QUANTILES = (0.01, 0.05, 0.5, 0.95, 0.99)


@dataclass(frozen=True)
class Distribution:
    """``normal:MEAN:SD`` or ``uniform:LO:HI`` (per tire, N or N*m)."""

    kind: str
    a: float
    b: float

    @property
    def mean(self) -> float:
        return self.a if self.kind == "normal" else 0.5 * (self.a + self.b)

    @property
    def variance(self) -> float:
        return self.b ** 2 if self.kind == "normal" else (self.b - self.a) ** 2 / 12.0

    def draw(self, rng: np.random.Generator, shape) -> np.ndarray | float:
        """Draws of ``shape``; a point mass (SD 0, LO = HI) is its value, drawing nothing."""
        if self.variance == 0.0:
            return self.mean
        if self.kind == "normal":
            return rng.normal(self.a, self.b, shape)
        return rng.uniform(self.a, self.b, shape)


ZERO = Distribution("normal", 0.0, 0.0)


def parse_distribution(text: str, what: str) -> Distribution:
    """``normal:MEAN:SD`` (SD >= 0) or ``uniform:LO:HI`` (LO <= HI), finite, |values| <= 1e6."""
    parts = text.split(":")
    try:
        if len(parts) != 3 or parts[0] not in ("normal", "uniform"):
            raise ValueError
        a, b = float(parts[1]), float(parts[2])
    except ValueError:
        raise TrackingError(f"{what}: expected normal:MEAN:SD or uniform:LO:HI, got {text!r}") from None
    if not (math.isfinite(a) and math.isfinite(b)) or max(abs(a), abs(b)) > 1e6:
        raise TrackingError(f"{what}: numbers must be finite and within 1e6, got {text!r}")
    if parts[0] == "normal" and b < 0:
        raise TrackingError(f"{what}: SD must be >= 0, got {b:g}")
    if parts[0] == "uniform" and b < a:
        raise TrackingError(f"{what}: HI must be >= LO, got {text!r}")
    return Distribution(parts[0], a, b)


@dataclass(frozen=True)
class TrackingStats:
    """Trimmed offtracking and trim steer over a tire population (docs/tracking.md)."""

    offtracking_mean_m: float
    offtracking_sd_m: float
    trim_delta_mean_rad: float
    trim_delta_sd_rad: float
    quantiles_m: dict
    exceedance_probability: float
    exceedance_ci95: tuple
    draws: int
    seed: int
    margin_m: float
    samples_m: np.ndarray

    def plot(self, title: str = "Trimmed offtracking over the tire population"):
        """Histogram of the Monte Carlo offtracking with the exact mean and the lane margins."""
        from ..plotting.tracking import fig_offtracking_histogram
        return fig_offtracking_histogram(self, title)

    def to_dict(self) -> dict:
        return {"offtracking_m": {"mean": self.offtracking_mean_m, "sd": self.offtracking_sd_m,
                                  "quantiles": {f"{q:g}": v for q, v in self.quantiles_m.items()}},
                "trim_delta_rad": {"mean": self.trim_delta_mean_rad, "sd": self.trim_delta_sd_rad},
                "exceedance": {"probability": self.exceedance_probability, "ci95": list(self.exceedance_ci95),
                               "draws": self.draws},
                "margin_m": self.margin_m, "seed": self.seed}


def _wilson(k: int, n: int) -> tuple[float, float]:
    """95 % Wilson score interval of a binomial proportion k/n."""
    z = 1.959963984540054
    p = k / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (0.0 if k == 0 else max(0.0, centre - half)), (1.0 if k == n else min(1.0, centre + half))


def tracking_stats(vehicle: Vehicle, speed_mps: float, conicity: Distribution, ply_steer: Distribution,
                   mounting: str = "out", conicity_moment: Distribution = ZERO, ply_steer_moment: Distribution = ZERO,
                   axles: list[str] | None = None, lane_width_m: float = LANE_WIDTH_M,
                   body_width_m: float = BODY_WIDTH_M, draws: int = DRAWS, seed: int = SEED,
                   F_const: np.ndarray | None = None, tire_scale: float = 1.0) -> TrackingStats:
    """Mean and standard deviation (exact) and quantiles and lane exceedance (Monte Carlo)
    of the trimmed offtracking over tires drawn independently from the distributions.

    Parameters
    ----------
    mounting : {"out", "in", "random"}
        Serial side of every tire (random: out or in with probability 1/2 each).
    F_const : numpy.ndarray, optional
        A constant generalized force added (crossfall, misalignment: SI).

    Returns
    -------
    TrackingStats
        The exact mean and SD [m], the Monte Carlo quantiles and lane exceedance, the seed.

    Raises
    ------
    lcvreport.tracking.tires.TrackingError
        A ``mounting`` other than out, in or random, a lane not wider than the body, an axle that is
        not the vehicle's, no tire position to draw.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> s = tracking_stats(load_preset("tractor_semitrailer"), 24.4444, parse_distribution("normal:0:100", "c"),
    ...                    parse_distribution("normal:50:50", "p"), draws=1000)
    >>> s.draws, s.offtracking_sd_m > 0
    (1000, True)
    """
    if mounting not in ("out", "in", "random"):
        raise TrackingError(f"mounting must be out, in or random, got {mounting!r}")
    margin = 0.5 * (lane_width_m - body_width_m)
    if not (math.isfinite(margin) and margin > 0):
        raise TrackingError(f"the lane ({lane_width_m:g} m) must be wider than the body ({body_width_m:g} m)")
    slots = tire_slots(vehicle, axles)
    if not slots:
        raise TrackingError("no tire positions to draw")
    g = sensitivities(vehicle, speed_mps, tire_scale)
    na = len(vehicle.axles)
    gP = np.array([g[:, s.axle] for s in slots])            # (tires, 2): per N of the tire's force on its axle
    gT = np.array([g[:, na + s.axle] for s in slots])
    const = np.zeros(2)
    if F_const is not None:
        tr = trim(vehicle, speed_mps, F_const, tire_scale)
        const = np.array([tr.offtracking_m, tr.delta_rad])
    if mounting == "random":
        Es = np.zeros(len(slots))
    else:
        Es = np.array([s.side if mounting == "out" else -s.side for s in slots])
    # exact moments: per tire X = gP (p + s c) + gT (pm + s cm), tires independent
    mean = const + (gP * (ply_steer.mean + Es * conicity.mean)[:, None]).sum(0) + \
        (gT * (ply_steer_moment.mean + Es * conicity_moment.mean)[:, None]).sum(0)
    var_sc = conicity.variance + (1 - Es ** 2) * conicity.mean ** 2        # Var(s c)
    var_scm = conicity_moment.variance + (1 - Es ** 2) * conicity_moment.mean ** 2
    cov_c_cm = (1 - Es ** 2) * conicity.mean * conicity_moment.mean        # Cov(s c, s cm)
    var = (gP ** 2 * (ply_steer.variance + var_sc)[:, None]).sum(0) + \
        (gT ** 2 * (ply_steer_moment.variance + var_scm)[:, None]).sum(0) + \
        (2 * gP * gT * cov_c_cm[:, None]).sum(0)
    # Monte Carlo in batches (one product per batch)
    rng = np.random.default_rng(seed)
    n_t = len(slots)
    samples = np.empty(draws)
    batch = max(1, min(draws, 2_000_000 // max(n_t, 1)))
    done = 0
    while done < draws:
        b = min(batch, draws - done)
        s = rng.choice((-1.0, 1.0), size=(b, n_t)) if mounting == "random" else np.broadcast_to(Es, (b, n_t))
        P = ply_steer.draw(rng, (b, n_t)) + s * conicity.draw(rng, (b, n_t))
        samples[done:done + b] = np.broadcast_to(P, (b, n_t)) @ gP[:, 0] + const[0]
        if ply_steer_moment is not ZERO or conicity_moment is not ZERO:
            T = ply_steer_moment.draw(rng, (b, n_t)) + s * conicity_moment.draw(rng, (b, n_t))
            samples[done:done + b] += np.broadcast_to(T, (b, n_t)) @ gT[:, 0]
        done += b
    k = int(np.sum(np.abs(samples) > margin))
    return TrackingStats(float(mean[0]), float(math.sqrt(var[0])), float(mean[1]), float(math.sqrt(var[1])),
                         {q: float(v) for q, v in zip(QUANTILES, np.quantile(samples, QUANTILES))},
                         k / draws, _wilson(k, draws), int(draws), int(seed), float(margin), samples)


#: keys of a tracking-statistics specification (``lcv report --tracking-stats``)
STATS_KEYS = ("conicity", "ply_steer", "conicity_moment", "ply_steer_moment", "mounting", "draws", "seed",
              "lane_width_m", "body_width_m")


def parse_stats_spec(text: str) -> dict:
    """``conicity=DIST,ply_steer=DIST,mounting=out|in|random[,conicity_moment=DIST,
    ply_steer_moment=DIST,draws=N,seed=S,lane_width_m=W,body_width_m=B]`` as a checked dict
    (distributions as text, numbers as numbers).

    Examples
    --------
    >>> parse_stats_spec("conicity=normal:0:120,ply_steer=normal:40:60,mounting=random")["mounting"]
    'random'
    """
    spec: dict = {}
    for item in str(text).split(","):
        key, eq, value = item.strip().partition("=")
        if not eq or key not in STATS_KEYS:
            raise TrackingError(f"expected KEY=VALUE with KEY one of {', '.join(STATS_KEYS)}, got {item.strip()!r}")
        if key in spec:
            raise TrackingError(f"{key} is given twice")
        spec[key] = value.strip()
    return check_stats_spec(spec)


def check_stats_spec(spec: dict) -> dict:
    """Check a tracking-statistics specification (see :func:`parse_stats_spec`); return it
    with numbers converted.

    Raises
    ------
    TrackingError
        The key and the value that is wrong, and what is valid.
    """
    if not isinstance(spec, dict):
        raise TrackingError(f"expected a dict with keys {', '.join(STATS_KEYS)}, got {spec!r}")
    unknown = [k for k in spec if k not in STATS_KEYS]
    if unknown:
        raise TrackingError(f"unknown key {unknown[0]!r}; valid: {', '.join(STATS_KEYS)}")
    for key in ("conicity", "ply_steer", "mounting"):
        if key not in spec:
            raise TrackingError(f"{key} is missing (conicity=DIST, ply_steer=DIST and mounting=out|in|random "
                                "are needed)")
    out = dict(spec)
    for key in ("conicity", "ply_steer", "conicity_moment", "ply_steer_moment"):
        if key in out:
            parse_distribution(str(out[key]), key)
    if out["mounting"] not in ("out", "in", "random"):
        raise TrackingError(f"mounting must be out, in or random, got {out['mounting']!r}")
    for key, lo, hi, kind in (("draws", 1, 10_000_000, int), ("seed", 0, 2 ** 63 - 1, int),
                              ("lane_width_m", 0.0, 10.0, float), ("body_width_m", 0.0, 10.0, float)):
        if key not in out:
            continue
        try:
            val = kind(out[key])
            if kind is int and isinstance(out[key], float) and out[key] != val:
                raise ValueError
        except (TypeError, ValueError):
            raise TrackingError(f"{key} must be {'an integer' if kind is int else 'a number'}, got {out[key]!r}") \
                from None
        if not (math.isfinite(val) and (lo <= val <= hi if kind is int else lo < val <= hi)):
            raise TrackingError(f"{key} must be in {'[' if kind is int else '('}{lo:g}, {hi:g}], got {out[key]!r}")
        out[key] = val
    margin = 0.5 * (out.get("lane_width_m", LANE_WIDTH_M) - out.get("body_width_m", BODY_WIDTH_M))
    if margin <= 0:
        raise TrackingError(f"the lane ({out.get('lane_width_m', LANE_WIDTH_M):g} m) must be wider than the body "
                            f"({out.get('body_width_m', BODY_WIDTH_M):g} m)")
    return out


def stats_from_spec(vehicle: Vehicle, speed_mps: float, spec: dict, F_const: np.ndarray | None = None,
                    tire_scale: float = 1.0) -> TrackingStats:
    """:func:`tracking_stats` of a checked specification (:func:`check_stats_spec`)."""
    spec = check_stats_spec(spec)
    dist = {k: parse_distribution(str(spec[k]), k) if k in spec else ZERO
            for k in ("conicity", "ply_steer", "conicity_moment", "ply_steer_moment")}
    return tracking_stats(vehicle, speed_mps, dist["conicity"], dist["ply_steer"], spec["mounting"],
                          dist["conicity_moment"], dist["ply_steer_moment"], None,
                          spec.get("lane_width_m", LANE_WIDTH_M), spec.get("body_width_m", BODY_WIDTH_M),
                          spec.get("draws", DRAWS), spec.get("seed", SEED), F_const, tire_scale)
