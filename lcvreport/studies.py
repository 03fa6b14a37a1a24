"""The studies of chapters III-V, each computed in two readings.

*As published*: the thesis load convention (moment rows in lbf*ft against matrices
in lbf*in), the thesis' modal method (``X^T M X = 1``, ``g = X^T F``) and the thesis'
end time of 1 s, whose value is what the thesis calls steady state.

*Corrected*: unit-consistent loads, the exact (zero-order-hold) response, at least
10 s, and the true steady state ``-S^-1 F``.

The response of interest is the lateral displacement of the rear end of the last
unit (y6 for the triple, y2 for the tractor-semitrailer) [in].
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from .linear import eigenvalues, modal_response, rear_displacements, steady_state, step_response
from .loads import load_vector, one_percent_rule
from .presets import load_preset
from .units import mph_to_in_per_s
from .vehicle import Train

#: the thesis' end time, called steady state in chapter V [s]
THESIS_END_TIME = 1.0
#: end time of the corrected reading [s] (SPEC erratum 4: at least 10 s)
CORRECTED_END_TIME = 10.0


@dataclass(frozen=True)
class Run:
    """One simulation of a parametric study.

    Attributes
    ----------
    label : str
        Name in the thesis table (``"Trailer 2 & 3"``, ``"30 mph"``, ...).
    train : Train
    speed_mph : float
        Forward speed [mph].
    tire_scale : float
        Factor on the tire coefficients [-].
    units : tuple of str
        Units whose axles carry P and T (1 % rule, P along +y).
    t_sign : float
        +1: T about +z (eq. 4.17); -1: T about -z (eq. 3.34).
    fraction : float
        Residual load as a fraction of the axle load (0.01 in the thesis).
    """

    label: str
    train: Train
    speed_mph: float
    tire_scale: float = 1.0
    units: tuple[str, ...] = ("trailer2", "trailer3")
    t_sign: float = 1.0
    fraction: float = 0.01

    @property
    def speed(self) -> float:
        """Forward speed [in/s]."""
        return mph_to_in_per_s(self.speed_mph)

    def forces(self, convention: str) -> np.ndarray:
        """Generalized force of this run's loads in ``convention`` (thesis units)."""
        loads = one_percent_rule(self.train, list(self.units), self.t_sign, self.fraction)
        return load_vector(self.train, loads, convention)

    @property
    def output(self) -> str:
        """Name of the response of interest (rear end of the last unit)."""
        return f"y{self.train.n_units}"


@dataclass
class RunResult:
    """A run solved in both readings (lengths in in, times in s).

    Attributes
    ----------
    run : Run
    t_published, y_published : numpy.ndarray
        As published: thesis convention, thesis modal method, 0..1 s.
    t_corrected, y_corrected : numpy.ndarray
        Corrected: consistent convention, exact response, 0..``t_end``.
    y_exact_thesis_loads : numpy.ndarray
        Exact response to the thesis-convention loads on ``t_corrected`` (isolates
        the effect of the modal method from that of the load units).
    eigenvalues : numpy.ndarray
        [1/s], mode order.
    """

    run: Run
    t_published: np.ndarray
    y_published: np.ndarray
    t_corrected: np.ndarray
    y_corrected: np.ndarray
    y_exact_thesis_loads: np.ndarray
    steady_thesis_loads: float
    steady_corrected: float
    eigenvalues: np.ndarray

    @property
    def published_steady(self) -> float:
        """What the thesis calls steady state: the as-published value at 1 s [in]."""
        return float(self.y_published[-1])

    @property
    def published_peak(self) -> float:
        """Largest |y| of the as-published reading [in]."""
        return float(np.abs(self.y_published).max())

    @property
    def corrected_peak(self) -> float:
        """Largest |y| of the corrected reading [in]."""
        return float(np.abs(self.y_corrected).max())

    @property
    def stable(self) -> bool:
        """All eigenvalues in the left half plane."""
        return bool(np.all(self.eigenvalues.real < 0))

    def row(self) -> dict:
        """One table row with units in the keys."""
        return {"run": self.run.label, "speed_mph": self.run.speed_mph, "tire_scale": self.run.tire_scale,
                "preset": self.run.train.name, "loaded_units": " ".join(self.run.units),
                "published_y_at_1s_in": self.published_steady, "published_peak_in": self.published_peak,
                "true_steady_thesis_loads_in": self.steady_thesis_loads,
                "corrected_steady_in": self.steady_corrected, "corrected_peak_in": self.corrected_peak,
                "max_real_eig_per_s": float(self.eigenvalues.real.max())}


def solve_run(run: Run, t_end: float = CORRECTED_END_TIME, n_points: int = 1001) -> RunResult:
    """Solve ``run`` in both readings.

    Parameters
    ----------
    run : Run
    t_end : float
        End time of the corrected reading [s], >= 10 recommended.
    n_points : int
        Output points of each time history.
    """
    train = run.train
    n = train.n_units
    F_thesis = run.forces("thesis")
    F_cons = run.forces("consistent")
    t_pub = np.linspace(0.0, THESIS_END_TIME, n_points)
    x_pub = modal_response(train, run.speed, F_thesis, t_pub, run.tire_scale, method="thesis")
    y_pub = rear_displacements(train, x_pub[:, n + 1:])[:, -1]
    r_cons = step_response(train, run.speed, F_cons, t_end, n_points, run.tire_scale)
    r_thes = step_response(train, run.speed, F_thesis, t_end, n_points, run.tire_scale)
    ss = [float(rear_displacements(train, steady_state(train, run.speed, F, run.tire_scale)[n + 1:])[-1])
          for F in (F_thesis, F_cons)]
    return RunResult(run, t_pub, y_pub, r_cons.time, r_cons[run.output], r_thes[run.output], ss[0], ss[1],
                     eigenvalues(train, run.speed, run.tire_scale))


@dataclass
class Study:
    """A parametric study: its thesis table number, runs and results."""

    name: str
    table: str
    parameter: str
    runs: list[Run]
    baseline: str
    t_end: float = CORRECTED_END_TIME
    n_points: int = 1001
    results: list[RunResult] = field(default_factory=list)

    def solve(self) -> "Study":
        """Solve every run (in place) and return self."""
        self.results = [solve_run(r, self.t_end, self.n_points) for r in self.runs]
        return self

    def result(self, label: str) -> RunResult:
        """The result of the run called ``label``."""
        for res in self.results:
            if res.run.label == label:
                return res
        raise KeyError(label)

    def rows(self) -> list[dict]:
        """Table rows, one per run."""
        return [r.row() for r in self.results]

    def ranked(self, reading: str = "corrected") -> list[RunResult]:
        """Results ranked by steady state, largest first (the thesis' Figures 5-4, 5-8 ...)."""
        key = {"corrected": lambda r: abs(r.steady_corrected), "published": lambda r: abs(r.published_steady),
               "thesis_loads": lambda r: abs(r.steady_thesis_loads)}[reading]
        return sorted(self.results, key=key, reverse=True)

    def relative_change(self, reading: str = "corrected") -> list[tuple[str, float]]:
        """Steady state change of every run relative to the baseline run [%] (Figure 5-20)."""
        pick = {"corrected": lambda r: r.steady_corrected, "published": lambda r: r.published_steady,
                "thesis_loads": lambda r: r.steady_thesis_loads}[reading]
        base = pick(self.result(self.baseline))
        return [(r.run.label, 100.0 * (pick(r) - base) / base) for r in self.results]


LOCATION_RUNS = (("Trailer 1", ("trailer1",)), ("Trailer 2", ("trailer2",)), ("Trailer 3", ("trailer3",)),
                 ("Trailer 2 & 3", ("trailer2", "trailer3")),
                 ("Trailer 1, 2, & 3", ("trailer1", "trailer2", "trailer3")),
                 ("Trailer 3, Dolly 2", ("trailer3", "dolly2")),
                 ("Trailer 2 & 3, Dolly 1 & 2", ("trailer2", "trailer3", "dolly1", "dolly2")),
                 ("Trailer 3, Dolly 1 & 2", ("trailer3", "dolly1", "dolly2")))
SPEEDS_MPH = (70.0, 60.0, 50.0, 40.0, 30.0)
MASS_PRESETS = (("AU-NCAT", "aucnat"), ("Legal Max", "legal_max"), ("Loaded, Loaded, Empty", "loaded_loaded_empty"),
                ("Empty, Empty, Loaded", "empty_empty_loaded"), ("Empty", "empty"))
TIRE_SCALES = (0.6, 0.8, 1.0, 1.2, 1.4)


def location_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-1: conicity force/moment location, AU-NCAT, UMTRI tires, 50 mph."""
    train = load_preset("aucnat")
    runs = [Run(label, train, 50.0, 1.0, units) for label, units in LOCATION_RUNS]
    return Study("location", "5-1", "Conicity Force/Moment Location", runs, "Trailer 2 & 3", t_end, n_points).solve()


def speed_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-2: forward velocity 70..30 mph, loads on trailers 2 and 3."""
    train = load_preset("aucnat")
    runs = [Run(f"{v:g} mph", train, v) for v in SPEEDS_MPH]
    return Study("speed", "5-2", "Velocity", runs, "50 mph", t_end, n_points).solve()


def mass_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-3: the five mass configurations (and their tires) at 30 mph."""
    runs = [Run(label, load_preset(p), 30.0) for label, p in MASS_PRESETS]
    return Study("mass", "5-3", "Mass", runs, "AU-NCAT", t_end, n_points).solve()


def tire_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-4: tire property scale 0.6..1.4, AU-NCAT, 30 mph."""
    train = load_preset("aucnat")
    runs = [Run(f"{s:g}x", train, 30.0, s) for s in TIRE_SCALES]
    return Study("tires", "5-4", "Tires", runs, "1x", t_end, n_points).solve()


def exaggerated_runs() -> tuple[Run, Run]:
    """Figure 5-21: the baseline of the tire study against an exaggerated vehicle:
    masses, inertias and axle loads x2 (overloaded by a factor of 2), tires at 10 %
    of the AU-NCAT coefficients, residual loads 5 % of the (doubled) axle loads."""
    base = Run("Baseline (AU-NCAT, 1x tires, 1 %)", load_preset("aucnat"), 30.0)
    heavy = load_preset("aucnat").scaled_mass(2.0)
    exaggerated = Run("Overloaded x2, tires 10 %, residual 5 %", replace(heavy, name="aucnat_x2"), 30.0,
                      tire_scale=0.1, fraction=0.05)
    return base, exaggerated


@dataclass
class Chapter3:
    """Chapter III: the tractor-semitrailer at 50 mph, loads on the trailer 1 axle."""

    n_points: int = 1001
    t_end: float = CORRECTED_END_TIME

    @cached_property
    def train(self) -> Train:
        return load_preset("tractor_semitrailer")

    @cached_property
    def run(self) -> Run:
        # eq. 3.34: T turning the same way as the moment of P about the trailer CG (about -z)
        return Run("Trailer 1", self.train, 50.0, 1.0, ("trailer1",), t_sign=-1.0)

    @cached_property
    def result(self) -> RunResult:
        return solve_run(self.run, self.t_end, self.n_points)

    def states(self, reading: str) -> tuple[np.ndarray, np.ndarray]:
        """(time [s], thesis states) of a reading: ``published`` or ``corrected``."""
        return states_of(self.run, reading, self.t_end, self.n_points)


def states_of(run: Run, reading: str, t_end: float, n_points: int) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and thesis states of ``run`` in a reading (``published``: modal method,
    thesis loads, 1 s; ``corrected``: exact, consistent loads, ``t_end``)."""
    if reading == "published":
        t = np.linspace(0.0, THESIS_END_TIME, n_points)
        return t, modal_response(run.train, run.speed, run.forces("thesis"), t, run.tire_scale, method="thesis")
    if reading == "corrected":
        r = step_response(run.train, run.speed, run.forces("consistent"), t_end, n_points, run.tire_scale)
        return r.time, r.states[:, :2 * run.train.n_units]
    raise ValueError(f"reading must be 'published' or 'corrected', got {reading!r}")


def unstable_example() -> tuple[Train, float, float]:
    """Figure 3-3: the tractor-semitrailer with the trailer mass (and yaw inertia) x10
    and every tire coefficient /10, at 50 mph: (train, speed [in/s], tire scale)."""
    t = load_preset("tractor_semitrailer")
    trailer = replace(t.units[1], mass=10 * t.units[1].mass, inertia=10 * t.units[1].inertia)
    return replace(t, units=(t.units[0], trailer), name="trailer mass x10"), mph_to_in_per_s(50.0), 0.1


def correlation_run(speed_mph: float = 18.5) -> Run:
    """Section 4.5: AU-NCAT as tested, loads on every trailer and dolly axle."""
    return Run("Correlation", load_preset("aucnat"), speed_mph, 1.0,
               ("trailer1", "dolly1", "trailer2", "dolly2", "trailer3"))
