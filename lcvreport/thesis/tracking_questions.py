"""The thesis' open questions on straight-line tracking, answered on AU-NCAT (docs/tracking.md).

The dissertation stops at one deterministic load, 1 % of the axle load, and names what it
could not answer (sections 4.5, 5.5 and chapter VI): the real range of conicity and ply
steer, whether sorting tires helps, and road crown as the confounder of its field test.
This module answers them with :mod:`lcvreport.tracking.statistics` and
:mod:`lcvreport.tracking.placement` on the aucnat preset at the thesis' 50 mph:

* :func:`one_percent_against_population` -- the 1 % rule (trailers 2 and 3, the thesis'
  baseline; and every axle behind the tractor, all one way) against a tire population;
* :func:`population_sensitivity` -- the answers as the assumed population is scaled;
* :func:`mounting_study` -- serial sides all out, all in, at random, and the exact
  mounting plan of drawn tire sets (:func:`lcvreport.tracking.placement.place_tires`);
* :func:`crossfall_beside_conicity` -- road crossfall's trimmed offtracking beside the
  population's spread.

The population is an assumption (no published one was available to the project), read
from ``data/thesis/assumed_tire_population.toml`` and labelled as such wherever shown.

Examples
--------
>>> pop = assumed_population()
>>> pop.label.startswith("ASSUMED")
True
>>> round(pop.tire_load_N, -2)                  # aucnat's mean static tire load behind the tractor
22900.0
"""
from __future__ import annotations

import tomllib
from dataclasses import dataclass
from importlib import resources

import numpy as np

from ..analysis.steady import trim
from ..model.presets import load_preset
from ..model.vehicle import Vehicle
from ..model.yaw_plane.loads import ResidualSources, load_vector, one_percent_rule
from ..tracking.placement import place_tires
from ..tracking.statistics import Distribution, TrackingStats, tracking_stats
from ..tracking.tires import tire_slots
from ..units import m_to_in, mph_to_mps

#: the thesis' speed of chapter V [mph]
SPEED_MPH = 50.0
#: the thesis' baseline loading (Table 5-1, run 4)
BASELINE_UNITS = ("trailer2", "trailer3")


@dataclass(frozen=True)
class Population:
    """A per-tire conicity and ply-steer population as fractions of the static tire load."""

    label: str
    conicity_mean_fraction: float
    conicity_sd_fraction: float
    ply_steer_mean_fraction: float
    ply_steer_sd_fraction: float
    scale_factors: tuple
    crossfall_percent: tuple
    placement_sets: int
    seed: int
    tire_load_N: float

    def conicity(self, scale: float = 1.0) -> Distribution:
        """Conicity force per tire [N], the population scaled by ``scale``."""
        return Distribution("normal", scale * self.conicity_mean_fraction * self.tire_load_N,
                            scale * self.conicity_sd_fraction * self.tire_load_N)

    def ply_steer(self, scale: float = 1.0) -> Distribution:
        """Ply steer force per tire [N], the population scaled by ``scale``."""
        return Distribution("normal", scale * self.ply_steer_mean_fraction * self.tire_load_N,
                            scale * self.ply_steer_sd_fraction * self.tire_load_N)

    def rows(self) -> list[dict]:
        """The population as a table: per tire, fractions and newtons."""
        c, p = self.conicity(), self.ply_steer()
        return [{"quantity": "conicity force per tire", "mean_percent_of_tire_load": 100 * self.conicity_mean_fraction,
                 "sd_percent_of_tire_load": 100 * self.conicity_sd_fraction, "mean_N": c.a, "sd_N": c.b},
                {"quantity": "ply steer force per tire", "mean_percent_of_tire_load": 100 * self.ply_steer_mean_fraction,
                 "sd_percent_of_tire_load": 100 * self.ply_steer_sd_fraction, "mean_N": p.a, "sd_N": p.b}]


def mean_tire_load_N(vehicle: Vehicle) -> float:
    """Mean static load per tire [N] over the axles behind the first unit."""
    axles = [a for j, a in enumerate(vehicle.axles) if vehicle.axle_units[j] >= 1]
    return float(sum(a.static_load_N for a in axles) / sum(a.tires for a in axles))


def assumed_population(vehicle: Vehicle | None = None) -> Population:
    """The assumed population of ``data/thesis/assumed_tire_population.toml`` on ``vehicle``'s
    tire load (default aucnat)."""
    vehicle = vehicle or load_preset("aucnat")
    doc = tomllib.loads(resources.files("lcvreport.data").joinpath("thesis/assumed_tire_population.toml")
                        .read_text(encoding="utf-8"))
    return Population(doc["label"], doc["conicity_mean_fraction"], doc["conicity_sd_fraction"],
                      doc["ply_steer_mean_fraction"], doc["ply_steer_sd_fraction"], tuple(doc["scale_factors"]),
                      tuple(doc["crossfall_percent"]), int(doc["placement_sets"]), int(doc["seed"]),
                      mean_tire_load_N(vehicle))


#: a batch of one make whose conicity leans one way: its mean [fraction of the tire load]
BATCH_CONICITY_MEAN_FRACTION = 0.01


def _stats(vehicle, pop, scale, mounting, draws, F=None, conicity=None) -> TrackingStats:
    return tracking_stats(vehicle, mph_to_mps(SPEED_MPH), conicity or pop.conicity(scale), pop.ply_steer(scale),
                          mounting, draws=draws, seed=pop.seed, F_const=F)


def gaussian_exceedance(mean_m: float, sd_m: float, margin_m: float) -> float:
    """P(|X| > margin) of a normal X: exact for the offtracking when every per-tire term is
    normal (zero-mean conicity makes s * c normal whatever the serial side)."""
    return 10.0 ** log10_gaussian_exceedance(mean_m, sd_m, margin_m)


def log10_gaussian_exceedance(mean_m: float, sd_m: float, margin_m: float) -> float:
    """log10 of :func:`gaussian_exceedance`, from the log tails (no underflow below 1e-308)."""
    from scipy.special import logsumexp
    from scipy.stats import norm
    ln = logsumexp([norm.logsf((margin_m - mean_m) / sd_m), norm.logcdf((-margin_m - mean_m) / sd_m)])
    return float(ln / np.log(10.0))


@dataclass(frozen=True)
class OnePercentAnswer:
    """The 1 % rule beside the population (trimmed offtracking [m], trim steer [rad]): the
    population, its statistics, and a row per load case of the rule."""

    population: Population
    stats: TrackingStats
    rule_rows: list

    def rows(self) -> list[dict]:
        s = self.stats
        out = [dict(r) for r in self.rule_rows]
        out.append({"case": f"population, mounting random: mean (exact)", "offtracking_m": s.offtracking_mean_m,
                    "offtracking_in": m_to_in(s.offtracking_mean_m), "sd_from_population_mean": 0.0,
                    "share_of_margin": abs(s.offtracking_mean_m) / s.margin_m})
        q = max(s.quantiles_m)
        out.append({"case": f"population: {100 * q:g} % quantile (Monte Carlo, {s.draws} draws, seed {s.seed})",
                    "offtracking_m": s.quantiles_m[q], "offtracking_in": m_to_in(s.quantiles_m[q]),
                    "sd_from_population_mean": (s.quantiles_m[q] - s.offtracking_mean_m) / s.offtracking_sd_m,
                    "share_of_margin": abs(s.quantiles_m[q]) / s.margin_m})
        return out


def one_percent_against_population(draws: int = 1_000_000) -> OnePercentAnswer:
    """The trimmed offtracking of the 1 % rule (thesis baseline: trailers 2 and 3; and every
    unit behind the tractor, all one way) beside the assumed population's distribution."""
    v = load_preset("aucnat")
    pop = assumed_population(v)
    s = _stats(v, pop, 1.0, "random", draws)
    u = mph_to_mps(SPEED_MPH)
    rows = []
    for label, units in (("1 % rule on trailers 2 and 3 (the thesis' baseline)", BASELINE_UNITS),
                         ("1 % rule on every unit behind the tractor, all one way", tuple(v.unit_names[1:]))):
        off = trim(v, u, load_vector(v, one_percent_rule(v, list(units)))).offtracking_m
        rows.append({"case": label, "offtracking_m": off, "offtracking_in": m_to_in(off),
                     "sd_from_population_mean": (off - s.offtracking_mean_m) / s.offtracking_sd_m,
                     "share_of_margin": abs(off) / s.margin_m})
    return OnePercentAnswer(population=pop, stats=s, rule_rows=rows)


@dataclass(frozen=True)
class SensitivityAnswer:
    """The population scaled by k: its offtracking SD and the lane exceedance."""

    scales: tuple
    stats: tuple
    population: Population

    def rows(self) -> list[dict]:
        out = []
        for k, s in zip(self.scales, self.stats):
            lo, hi = s.exceedance_ci95
            out.append({"scale": k, "conicity_sd_N": self.population.conicity(k).b,
                        "ply_steer_mean_N": self.population.ply_steer(k).a,
                        "offtracking_mean_m": s.offtracking_mean_m, "offtracking_sd_m": s.offtracking_sd_m,
                        "p_exceed": s.exceedance_probability, "p_exceed_ci95_lo": lo, "p_exceed_ci95_hi": hi,
                        "draws": s.draws,
                        "log10_p_exceed_gaussian": log10_gaussian_exceedance(s.offtracking_mean_m,
                                                                             s.offtracking_sd_m, s.margin_m)})
        return out

    def plot(self):
        from ..plotting.tracking import fig_tracking_sensitivity
        return fig_tracking_sensitivity(self)


def population_sensitivity(draws: int = 1_000_000) -> SensitivityAnswer:
    """The assumed population scaled by each of its ``scale_factors`` (mounting random)."""
    v = load_preset("aucnat")
    pop = assumed_population(v)
    return SensitivityAnswer(pop.scale_factors, tuple(_stats(v, pop, k, "random", draws) for k in pop.scale_factors),
                             pop)


@dataclass(frozen=True)
class MountingAnswer:
    """Serial sides all out / all in / random (exact moments), and drawn tire sets mounted at
    random against their exact mounting plan."""

    fixed: dict
    random_offtracking_m: np.ndarray
    out_offtracking_m: np.ndarray
    planned_offtracking_m: np.ndarray
    population: Population

    def rows(self) -> list[dict]:
        out = [{"mounting": (f"every serial side {m}" if m != "random" else "serial sides at random") + f", {which}",
                "offtracking_mean_m": s.offtracking_mean_m, "offtracking_sd_m": s.offtracking_sd_m,
                "how": "exact over the population"} for (which, m), s in self.fixed.items()]
        n = self.random_offtracking_m.size
        for label, x in (("drawn sets, mounted at random", self.random_offtracking_m),
                         ("drawn sets, in the order drawn, every serial side out", self.out_offtracking_m),
                         ("drawn sets, the exact mounting plan", self.planned_offtracking_m)):
            out.append({"mounting": label, "offtracking_mean_m": float(x.mean()),
                        "offtracking_sd_m": float(x.std(ddof=1)),
                        "how": f"{n} sets of {len(tire_slots(load_preset('aucnat')))} tires, seed {self.population.seed}; "
                               f"largest |offtracking| {np.abs(x).max():.3g} m"})
        return out

    def plot(self):
        from ..plotting.tracking import fig_mounting_study
        return fig_mounting_study(self)


def mounting_study(draws: int = 1_000_000, sets: int | None = None) -> MountingAnswer:
    """Exact moments for fixed and random serial sides; ``sets`` tire sets drawn from the
    population, mounted at random and by :func:`place_tires`."""
    v = load_preset("aucnat")
    pop = assumed_population(v)
    batch = Distribution("normal", BATCH_CONICITY_MEAN_FRACTION * pop.tire_load_N, pop.conicity().b)
    fixed = {(which, m): _stats(v, pop, 1.0, m, draws, conicity=c)
             for which, c in (("assumed population", None),
                              (f"one batch, conicity mean {100 * BATCH_CONICITY_MEAN_FRACTION:g} %", batch))
             for m in ("out", "in", "random")}
    u = mph_to_mps(SPEED_MPH)
    rng = np.random.default_rng(pop.seed)
    slots = tire_slots(v)
    rand, out, plan = [], [], []
    for k in range(pop.placement_sets if sets is None else sets):
        c = pop.conicity().draw(rng, len(slots))
        p = pop.ply_steer().draw(rng, len(slots))
        tires = [dict(id=f"S{k}T{i}", conicity_N=float(c[i]), ply_steer_N=float(p[i])) for i in range(len(slots))]
        pl = place_tires(v, u, tires, draws=1, seed=pop.seed + k)
        plan.append(pl.offtracking_m)
        rand.append(pl.random_offtracking_m[0])
        out.append(pl.as_listed_offtracking_m)
    return MountingAnswer(fixed, np.array(rand), np.array(out), np.array(plan), pop)


@dataclass(frozen=True)
class CrossfallAnswer:
    """Road crossfall's trimmed offtracking beside the population's."""

    rows_: list
    population_sd_m: float

    def rows(self) -> list[dict]:
        return self.rows_


def crossfall_beside_conicity(draws: int = 1_000_000) -> CrossfallAnswer:
    """Trimmed offtracking and trim steer per crossfall of the population's file, with no tire
    residuals and in population SDs."""
    v = load_preset("aucnat")
    pop = assumed_population(v)
    s = _stats(v, pop, 1.0, "random", draws)
    u = mph_to_mps(SPEED_MPH)
    rows = []
    for c in pop.crossfall_percent:
        tr = trim(v, u, ResidualSources(crossfall_percent=c).vector(v))
        rows.append({"crossfall_percent": c, "offtracking_m": tr.offtracking_m, "offtracking_in": m_to_in(
                     tr.offtracking_m), "trim_steer_rad": tr.delta_rad,
                     "in_population_sds": abs(tr.offtracking_m) / s.offtracking_sd_m,
                     "share_of_margin": abs(tr.offtracking_m) / s.margin_m})
    return CrossfallAnswer(rows, s.offtracking_sd_m)
