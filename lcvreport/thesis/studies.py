"""The studies of chapters III-V, each computed in two readings.

*As published*: the thesis load convention (moment rows in lbf*ft against matrices
in lbf*in), the thesis' modal method (``X^T M X = 1``, ``g = X^T F``) and the thesis'
end time of 1 s, whose value is what the thesis calls steady state.

*Corrected*: unit-consistent loads, the exact (zero-order-hold) response, at least
10 s, and the true steady state ``-S^-1 F``.

The response of interest is the lateral displacement of the rear end of the last
unit (y6 for the triple, y2 for the tractor-semitrailer), shown in inches as the
thesis does.  The model runs in SI; the as-published reading runs the thesis' modal
method in the thesis' units, where its (not unit-invariant) normalization was made.

Examples
--------
>>> st = tire_study(n_points=11, t_end=10.0)
>>> [r.run.label for r in st.ranked()][0]        # softest tires, largest steady state
'0.6x'
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from ..analysis.modal import modal_response
from ..analysis.modes import eigenvalues
from ..analysis.response import step_response
from ..analysis.steady import steady_state
from ..model.presets import load_preset
from ..model.vehicle import Vehicle
from ..model.yaw_plane.loads import load_vector, one_percent_rule
from ..model.yaw_plane.outputs import rear_offsets
from ..units import SI, THESIS, UnitSystem, m_to_in, mph_to_mps

#: the thesis' end time, called steady state in chapter V [s]
THESIS_END_TIME = 1.0
#: end time of the corrected reading [s] (docs/thesis.md, erratum 4: at least 10 s)
CORRECTED_END_TIME = 10.0


@dataclass(frozen=True)
class Run:
    """One simulation of a parametric study.

    Attributes
    ----------
    label : str
        Name in the thesis table (``"Trailer 2 & 3"``, ``"30 mph"``, ...).
    vehicle : Vehicle
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
    vehicle: Vehicle
    speed_mph: float
    tire_scale: float = 1.0
    units: tuple[str, ...] = ("trailer2", "trailer3")
    t_sign: float = 1.0
    fraction: float = 0.01

    @property
    def speed_mps(self) -> float:
        """Forward speed [m/s]."""
        return mph_to_mps(self.speed_mph)

    def forces(self, convention: str, units: UnitSystem = SI) -> np.ndarray:
        """Generalized force of this run's loads in ``convention``, expressed in ``units``."""
        loads = one_percent_rule(self.vehicle, list(self.units), self.t_sign, self.fraction)
        return load_vector(self.vehicle, loads, convention, units)

    @property
    def output(self) -> str:
        """Name of the response of interest (rear end of the last unit)."""
        return f"y{self.vehicle.n_units}"


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

    def series(self, reading: str = "corrected") -> tuple[str, np.ndarray, np.ndarray, dict]:
        """(label, time [s], y [in], line style) of one reading, for :func:`lcvreport.plotting.time.fig_time`:
        ``corrected`` (solid), ``published`` (dashed), ``thesis_loads`` (exact response to the thesis loads, dotted)."""
        if reading == "corrected":
            return self.run.label, self.t_corrected, self.y_corrected, {}
        if reading == "published":
            return f"{self.run.label} (as published)", self.t_published, self.y_published, {"ls": "--", "lw": 0.8}
        if reading == "thesis_loads":
            return f"{self.run.label} (exact, thesis loads)", self.t_corrected, self.y_exact_thesis_loads, {"ls": ":"}
        raise ValueError(f"reading must be corrected, published or thesis_loads, got {reading!r}")

    def steady(self, reading: str = "corrected") -> float:
        """Steady state of a reading [in]: corrected, thesis_loads (true steady states) or published (at 1 s)."""
        return {"corrected": self.steady_corrected, "thesis_loads": self.steady_thesis_loads,
                "published": self.published_steady}[reading]

    def plot(self, readings=("corrected", "published"), title: str = ""):
        """This run's time histories in the given readings (a Figure)."""
        from ..plotting.time import fig_time
        return fig_time([self.series(r) for r in readings], f"{self.run.output} [in]", title or self.run.label,
                        hlines=[("true steady state (corrected)", self.steady_corrected)])

    def row(self) -> dict:
        """One table row with units in the keys."""
        return {"run": self.run.label, "speed_mph": self.run.speed_mph, "tire_scale": self.run.tire_scale,
                "preset": self.run.vehicle.name, "loaded_units": " ".join(self.run.units),
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
    vehicle = run.vehicle
    n = vehicle.n_units
    F_thesis = run.forces("thesis")
    F_cons = run.forces("consistent")
    t_pub, x_pub = states_of(run, "published", t_end, n_points)
    y_pub = m_to_in(rear_offsets(vehicle, x_pub[:, n + 1:])[:, -1])
    r_cons = step_response(vehicle, run.speed_mps, F_cons, t_end, n_points, run.tire_scale)
    r_thes = step_response(vehicle, run.speed_mps, F_thesis, t_end, n_points, run.tire_scale)
    ss = [float(m_to_in(rear_offsets(vehicle, steady_state(vehicle, run.speed_mps, F, run.tire_scale)[n + 1:])[-1]))
          for F in (F_thesis, F_cons)]
    return RunResult(run, t_pub, y_pub, r_cons.time, m_to_in(r_cons[run.output]), m_to_in(r_thes[run.output]),
                     ss[0], ss[1], eigenvalues(vehicle, run.speed_mps, run.tire_scale))


#: result columns of the chapter V tables (units in the names)
RESULT_COLUMNS = ("published_y_at_1s_in", "published_peak_in", "true_steady_thesis_loads_in", "corrected_steady_in",
                  "corrected_peak_in", "max_real_eig_per_s")


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
        """Results ranked by |steady state|, largest first (the thesis' Figures 5-4, 5-8 ...)."""
        return sorted(self.results, key=lambda r: abs(r.steady(reading)), reverse=True)

    def relative_change(self, reading: str = "corrected") -> list[tuple[str, float]]:
        """Steady state change of every run relative to the baseline run [%] (Figure 5-20)."""
        base = self.result(self.baseline).steady(reading)
        return [(r.run.label, 100.0 * (r.steady(reading) - base) / base) for r in self.results]

    def series(self, *readings: str) -> list[tuple]:
        """Every run's :meth:`RunResult.series` in each reading (readings outer, runs inner)."""
        return [r.series(reading) for reading in (readings or ("corrected",)) for r in self.results]

    def eigenvalue_sets(self) -> list[tuple[str, np.ndarray]]:
        """(label, eigenvalues [1/s]) per run, for :func:`lcvreport.plotting.frequency.fig_eigenvalues`."""
        return [(r.run.label, r.eigenvalues) for r in self.results]

    def plot_responses(self, readings=("corrected",), title: str = "", **kw):
        """The runs' y6 time histories [in] (a Figure); keywords go to ``fig_time``."""
        from ..plotting.time import fig_time
        return fig_time(self.series(*readings), "y6 [in]", title or self.parameter, **kw)

    def plot_eigenvalues(self, title: str = "", upper: bool = False, connect_mode: int | None = None):
        """The runs' eigenvalues (a Figure)."""
        from ..plotting.frequency import fig_eigenvalues
        return fig_eigenvalues(self.eigenvalue_sets(), title or f"Eigenvalues: {self.parameter}", upper, connect_mode)

    def plot_ranked(self, groups=(("corrected", "steady state, corrected"),
                                  ("thesis_loads", "steady state, thesis loads")), rank_by: str = "corrected",
                    title: str = "", peaks: bool = False):
        """Bar chart of |steady state| [in] per run, ranked (a Figure)."""
        from ..plotting.charts import fig_bars
        ranked = self.ranked(rank_by)
        bars = [("max transient, corrected", np.array([r.corrected_peak for r in ranked]))] if peaks else []
        bars += [(label, np.array([abs(r.steady(reading)) for r in ranked])) for reading, label in groups]
        return fig_bars([r.run.label for r in ranked], bars, "|y6| [in]", title or f"Ranked by {rank_by} steady state")

    def table_rows(self, columns: dict) -> list[dict]:
        """Table rows: ``columns`` (name -> function of a RunResult) then the result columns of :data:`RESULT_COLUMNS`."""
        return [{"run": i + 1, **{k: f(r) for k, f in columns.items()},
                 **{k: v for k, v in r.row().items() if k in RESULT_COLUMNS}} for i, r in enumerate(self.results)]


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
    vehicle = load_preset("aucnat")
    runs = [Run(label, vehicle, 50.0, 1.0, units) for label, units in LOCATION_RUNS]
    return Study("location", "5-1", "Conicity Force/Moment Location", runs, "Trailer 2 & 3", t_end, n_points).solve()


def speed_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-2: forward velocity 70..30 mph, loads on trailers 2 and 3."""
    vehicle = load_preset("aucnat")
    runs = [Run(f"{v:g} mph", vehicle, v) for v in SPEEDS_MPH]
    return Study("speed", "5-2", "Velocity", runs, "50 mph", t_end, n_points).solve()


def mass_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-3: the five mass configurations (and their tires) at 30 mph."""
    runs = [Run(label, load_preset(p), 30.0) for label, p in MASS_PRESETS]
    return Study("mass", "5-3", "Mass", runs, "AU-NCAT", t_end, n_points).solve()


def tire_study(n_points: int = 1001, t_end: float = CORRECTED_END_TIME) -> Study:
    """Table 5-4: tire property scale 0.6..1.4, AU-NCAT, 30 mph."""
    vehicle = load_preset("aucnat")
    runs = [Run(f"{s:g}x", vehicle, 30.0, s) for s in TIRE_SCALES]
    return Study("tires", "5-4", "Tires", runs, "1x", t_end, n_points).solve()


def exaggerated_runs() -> tuple[Run, Run]:
    """Figure 5-21: the baseline of the tire study against an exaggerated vehicle:
    masses, inertias and axle loads x2 (overloaded by a factor of 2), tires at 10 %
    of the AU-NCAT coefficients, residual loads 5 % of the (doubled) axle loads."""
    base = Run("Baseline (AU-NCAT, 1x tires, 1 %)", load_preset("aucnat"), 30.0)
    heavy = load_preset("aucnat").scaled_mass(2.0, name="aucnat_x2")
    exaggerated = Run("Overloaded x2, tires 10 %, residual 5 %", heavy, 30.0, tire_scale=0.1, fraction=0.05)
    return base, exaggerated


@dataclass
class Chapter3:
    """Chapter III: the tractor-semitrailer at 50 mph, loads on the trailer 1 axle."""

    n_points: int = 1001
    t_end: float = CORRECTED_END_TIME

    speed_mph: float = 50.0

    @cached_property
    def vehicle(self) -> Vehicle:
        return load_preset("tractor_semitrailer")

    @cached_property
    def run(self) -> Run:
        # eq. 3.34: T turning the same way as the moment of P about the trailer CG (about -z)
        return Run("Trailer 1", self.vehicle, self.speed_mph, 1.0, ("trailer1",), t_sign=-1.0)

    @cached_property
    def result(self) -> RunResult:
        return solve_run(self.run, self.t_end, self.n_points)

    def states(self, reading: str, units: UnitSystem = SI) -> tuple[np.ndarray, np.ndarray]:
        """(time [s], states) of a reading: ``published`` or ``corrected``; v1 in ``units``."""
        return states_of(self.run, reading, self.t_end, self.n_points, units)


def states_of(run: Run, reading: str, t_end: float, n_points: int, units: UnitSystem = SI
              ) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and states of ``run`` in a reading (``published``: the thesis' modal
    method in thesis units, thesis loads, 1 s; ``corrected``: exact, consistent loads,
    ``t_end``).  v1 is returned in ``units`` (m/s or in/s); r, theta in rad/s, rad."""
    n2 = 2 * run.vehicle.n_units
    if reading == "published":
        t = np.linspace(0.0, THESIS_END_TIME, n_points)
        x = modal_response(run.vehicle, run.speed_mps, run.forces("thesis", THESIS), t, run.tire_scale,
                           method="thesis", units=THESIS)
        x[:, 0] *= THESIS.length_m / units.length_m
        return t, x
    if reading == "corrected":
        r = step_response(run.vehicle, run.speed_mps, run.forces("consistent"), t_end, n_points, run.tire_scale)
        x = r.states[:, :n2].copy()
        x[:, 0] /= units.length_m
        return r.time, x
    raise ValueError(f"reading must be 'published' or 'corrected', got {reading!r}")


def unstable_example(speed_mph: float = 50.0) -> tuple[Vehicle, float, float]:
    """Figure 3-3: the tractor-semitrailer with the trailer mass (and yaw inertia) x10
    and every tire coefficient /10: (vehicle, speed [m/s], tire scale)."""
    t = load_preset("tractor_semitrailer")
    trailer = replace(t.units[1], mass_kg=10 * t.units[1].mass_kg, yaw_inertia_kg_m2=10 * t.units[1].yaw_inertia_kg_m2)
    return replace(t, units=(t.units[0], trailer), name="trailer_mass_x10"), mph_to_mps(speed_mph), 0.1


def correlation_run(speed_mph: float = 18.5) -> Run:
    """Section 4.5: AU-NCAT as tested, loads on every trailer and dolly axle."""
    return Run("Correlation", load_preset("aucnat"), speed_mph, 1.0,
               ("trailer1", "dolly1", "trailer2", "dolly2", "trailer3"))
