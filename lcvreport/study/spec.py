"""A study file: the base vehicle, the factors, the design, the measures (SPEC section 14).

A study is a TOML file::

    vehicle = "aucnat"                 # a preset, or a vehicle file (relative to the study file)
    measures = ["least_damping_ratio", "critical_speed_kph", "ra_peak", "hsso_m"]

    [design]
    kind = "random"                    # "grid": every combination of the factors' values
    count = 10000                      # random only: how many cases
    seed = 20261130                    # random only: the seed (printed, stored with the results)

    [factors]
    speed_kph = { values = [80.0, 88.0, 100.0] }
    "trailer3.mass_scale" = { distribution = "uniform", low = 0.8, high = 1.2 }
    "tractor.cornering_stiffness_scale" = { distribution = "normal", mean = 1.0, sd = 0.05 }

Factors: ``speed_kph`` (km/h; or ``speed_mps``), ``tire_scale`` (measure_set's factor on every
tire coefficient), and scale factors ``<unit>.mass_scale``, ``<unit>.yaw_inertia_scale`` and
``<unit or axle>.cornering_stiffness_scale`` / ``.aligning_stiffness_scale`` /
``.longitudinal_stiffness_scale`` (a unit name scales all its axles).  A factor has ``values``
(a grid, or in a random design drawn with equal chance), or a ``distribution``: ``uniform``
(``low``, ``high``) or ``normal`` (``mean``, ``sd``).  Cases are numbered from 0 in design order:
the grid in the factors' file order (the last factor fastest); random draws per factor and per
block of 4,096 cases from ``numpy.random.default_rng([seed, factor index, block])``, so any
chunk's cases are drawn without drawing the whole design.

Examples
--------
>>> s = study_from_dict({"vehicle": "aucnat", "measures": ["least_damping_ratio"],
...     "design": {"kind": "grid"}, "factors": {"speed_kph": {"values": [80, 100]},
...     "trailer3.mass_scale": {"values": [0.9, 1.1]}}})
>>> s.n_cases, s.factor_table(range(4))["trailer3.mass_scale"].tolist()
(4, [0.9, 1.1, 0.9, 1.1])
"""
from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..model.vehicle import Vehicle
from ..model.vehicle_file import dumps_vehicle, load_vehicle, loads_vehicle
from ..units import kph_to_mps

#: measures computed batched over the cases (lcvreport.analysis.batch); the others of
#: ``lcv measures`` are computed case by case with measure_set (same numbers, slower)
BATCHED = ("least_damping_ratio", "least_damped_frequency_hz", "critical_speed_kph", "ra_frequency",
           "ra_single_sine", "ra_peak", "ra_peak_frequency_hz", "yaw_damping_coefficient", "hsto_m",
           "ra_lane_change", "hsso_m", "steady_turn_delta_rad")
#: every measure a study can ask for: the scalar keys of ``lcv measures --json``
MEASURES = BATCHED + ("lssp_m",
                      "low_speed_offtracking_m", "max_tail_swing_m", "frontal_swing_m")
DEFAULT_MEASURES = BATCHED
UNIT_SCALES = {"mass_scale": "mass_kg", "yaw_inertia_scale": "yaw_inertia_kg_m2"}
AXLE_SCALES = {"cornering_stiffness_scale": "cornering_stiffness_N_per_rad",
               "aligning_stiffness_scale": "aligning_stiffness_Nm_per_rad",
               "longitudinal_stiffness_scale": "longitudinal_stiffness_N"}
PLAIN_FACTORS = ("speed_kph", "speed_mps", "tire_scale")
MAX_CASES = 10_000_000
#: cases per block of random draws (each block, each factor its own generator)
DRAW_BLOCK = 4096


class StudyError(ValueError):
    """A study file that cannot be run; the message names the key, the value and what is valid."""


@dataclass(frozen=True)
class Factor:
    """One factor: ``values`` (a tuple) or a ``distribution`` with its parameters."""

    name: str
    values: tuple = ()
    distribution: str = ""
    low: float = math.nan
    high: float = math.nan
    mean: float = math.nan
    sd: float = math.nan

    def describe(self) -> str:
        if self.values:
            return f"{self.name}: values {list(self.values)}"
        if self.distribution == "uniform":
            return f"{self.name}: uniform on [{self.low:g}, {self.high:g}]"
        return f"{self.name}: normal, mean {self.mean:g}, sd {self.sd:g}"


@dataclass(frozen=True)
class Study:
    """A parsed, checked study.  ``vehicle`` is the base vehicle; ``source`` the file's text."""

    vehicle: Vehicle
    factors: tuple
    kind: str
    measures: tuple
    count: int = 0
    seed: int | None = None
    speed_kph: float | None = None
    chunk_size: int = 0

    # ------------------------------------------------------------------ cases
    @property
    def n_cases(self) -> int:
        if self.kind == "grid":
            return math.prod(len(f.values) for f in self.factors)
        return self.count

    @property
    def chunk(self) -> int:
        """Cases per chunk: fixed by the study (never by the workers), so that results do not
        depend on how they were run; large enough that the scheduler's ~2 ms per task stays
        below 1 % of a chunk's time (a batched case costs ~2 ms), small enough for progress."""
        if self.chunk_size:
            return self.chunk_size
        return int(min(500, max(50, math.ceil(self.n_cases / 64))))

    @property
    def n_chunks(self) -> int:
        return math.ceil(self.n_cases / self.chunk)

    def _block(self, factor_index: int, block: int) -> np.ndarray:
        """The draws of one factor for the cases of one block (``DRAW_BLOCK`` cases), from
        ``numpy.random.default_rng([seed, factor_index, block])``: any case's values are drawn
        without drawing the whole design (a chunk of 10^7 cases costs its own cases only)."""
        f = self.factors[factor_index]
        n = min(DRAW_BLOCK, self.count - block * DRAW_BLOCK)
        rng = np.random.default_rng([self.seed, factor_index, block])
        if f.values:
            return np.asarray(f.values, dtype=float)[rng.integers(0, len(f.values), n)]
        if f.distribution == "uniform":
            return rng.uniform(f.low, f.high, n)
        return rng.normal(f.mean, f.sd, n)

    def _draws(self, ids: np.ndarray) -> dict:
        """Every factor's draws for the cases ``ids`` of a random design."""
        out = {}
        blocks = np.unique(ids // DRAW_BLOCK)
        for i, f in enumerate(self.factors):
            values = np.empty(ids.size)
            for b in blocks:
                sel = ids // DRAW_BLOCK == b
                values[sel] = self._block(i, int(b))[ids[sel] - b * DRAW_BLOCK]
            out[f.name] = values
        return out

    def check_draws(self) -> None:
        """Refuse a random design that draws a value <= 0 (a normal distribution too wide),
        naming the factor and the first such case; block by block, in constant memory."""
        for i, f in enumerate(self.factors):
            if f.distribution != "normal":
                continue
            for b in range(math.ceil(self.count / DRAW_BLOCK)):
                draws = self._block(i, b)
                bad = np.flatnonzero(~(draws > 0))
                if bad.size:
                    case = b * DRAW_BLOCK + int(bad[0])
                    raise StudyError(f"factors.{f.name}: case {case} draws {draws[bad[0]]:.6g}; every value must be "
                                     "> 0 (narrow the distribution)")

    def factor_table(self, case_ids) -> dict:
        """Every factor's value for the cases ``case_ids``: name -> array (file order)."""
        ids = np.asarray(list(case_ids) if not isinstance(case_ids, np.ndarray) else case_ids, dtype=np.int64)
        bad = ids[(ids < 0) | (ids >= self.n_cases)]
        if bad.size:
            raise StudyError(f"case_id must be in [0, {self.n_cases - 1}], got {int(bad[0])}")
        if self.kind == "random":
            return self._draws(ids)
        sizes = [len(f.values) for f in self.factors]
        out = {}
        rest = ids.copy()
        for f, n in zip(reversed(self.factors), reversed(sizes)):
            out[f.name] = np.asarray(f.values, dtype=float)[rest % n]
            rest //= n
        return {f.name: out[f.name] for f in self.factors}

    # ------------------------------------------------------------------ one case
    def speeds_mps(self, table: dict) -> np.ndarray:
        n = len(next(iter(table.values()))) if table else 1
        if "speed_mps" in table:
            return np.asarray(table["speed_mps"], dtype=float)
        if "speed_kph" in table:
            return kph_to_mps(np.asarray(table["speed_kph"], dtype=float))
        return np.full(n, kph_to_mps(self.speed_kph))

    def batch_parameters(self, table: dict) -> dict:
        """The VariantBatch parameters (absolute SI values) of the cases of ``table``."""
        v = self.vehicle
        out = {}
        for name, arr in table.items():
            if name in PLAIN_FACTORS:
                continue
            owner, key = name.split(".", 1)
            unit = next((u for u in v.units if u.name == owner), None)
            if key in UNIT_SCALES:
                out[f"{owner}.{UNIT_SCALES[key]}"] = getattr(unit, UNIT_SCALES[key]) * arr
            else:
                axles = unit.axles if unit is not None else [a for a in v.axles if a.name == owner]
                for a in axles:
                    pname = f"{a.name}.{AXLE_SCALES[key]}"
                    base = out.get(pname, getattr(a, AXLE_SCALES[key]))
                    out[pname] = base * arr
        return out

    def case(self, case_id: int) -> tuple:
        """(vehicle, speed_mps, kwargs) of one case: ``measure_set(vehicle, speed_mps, **kwargs)``
        computes its row."""
        table = self.factor_table([case_id])
        v = self.vehicle
        units = list(v.units)
        for pname, arr in self.batch_parameters(table).items():
            owner, key = pname.split(".", 1)
            for i, u in enumerate(units):
                if u.name == owner:
                    units[i] = replace(u, **{key: float(arr[0])})
                for j, a in enumerate(u.axles):
                    if a.name == owner:
                        axles = list(units[i].axles)
                        axles[j] = replace(axles[j], **{key: float(arr[0])})
                        units[i] = replace(units[i], axles=tuple(axles))
        kwargs = {"tire_scale": float(table["tire_scale"][0])} if "tire_scale" in table else {}
        return replace(v, units=tuple(units)), float(self.speeds_mps(table)[0]), kwargs

    # ------------------------------------------------------------------ identity
    def to_dict(self) -> dict:
        """The study as a plain document (its vehicle as vehicle-file text): stored with the
        results, and hashed to tell a rerun of the same study from another."""
        return {"vehicle_toml": dumps_vehicle(self.vehicle), "kind": self.kind, "count": self.count,
                "seed": self.seed, "speed_kph": self.speed_kph, "measures": list(self.measures),
                "chunk_size": self.chunk, "factors": [f.__dict__ | {"values": list(f.values)} for f in self.factors]}

    def digest(self) -> str:
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


def _number(where: str, value, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) or \
            (positive and value <= 0):
        raise StudyError(f"{where} must be a finite number{' > 0' if positive else ''}, got {value!r}")
    return float(value)


def _factor(vehicle: Vehicle, name: str, spec) -> Factor:
    where = f"factors.{name}"
    if name not in PLAIN_FACTORS:
        owner, _, key = name.partition(".")
        units = {u.name for u in vehicle.units}
        axles = {a.name for a in vehicle.axles}
        if key in UNIT_SCALES and owner not in units or key in AXLE_SCALES and owner not in units | axles or \
                key not in UNIT_SCALES and key not in AXLE_SCALES:
            raise StudyError(f"{where}: unknown factor; valid: {', '.join(PLAIN_FACTORS)}, <unit>."
                             f"{{{','.join(UNIT_SCALES)}}} (units: {', '.join(sorted(units))}), <unit or axle>."
                             f"{{{','.join(AXLE_SCALES)}}} (axles: {', '.join(sorted(axles))})")
    if not isinstance(spec, dict):
        raise StudyError(f"{where} must be a table with values = [...] or distribution = ..., got {spec!r}")
    unknown = set(spec) - {"values", "distribution", "low", "high", "mean", "sd"}
    if unknown:
        raise StudyError(f"{where}: unknown key {sorted(unknown)[0]!r}; valid: values, distribution, low, high, "
                         "mean, sd")
    if "values" in spec:
        vals = spec["values"]
        if not isinstance(vals, list) or not vals:
            raise StudyError(f"{where}.values must be a non-empty list of numbers, got {vals!r}")
        return Factor(name, tuple(_number(f"{where}.values[{k}]", x, positive=True) for k, x in enumerate(vals)))
    dist = spec.get("distribution")
    if dist == "uniform":
        lo, hi = _number(f"{where}.low", spec.get("low"), True), _number(f"{where}.high", spec.get("high"), True)
        if not lo < hi:
            raise StudyError(f"{where}: low must be below high, got low {lo:g}, high {hi:g}")
        return Factor(name, distribution="uniform", low=lo, high=hi)
    if dist == "normal":
        mean, sd = _number(f"{where}.mean", spec.get("mean"), True), _number(f"{where}.sd", spec.get("sd"), True)
        return Factor(name, distribution="normal", mean=mean, sd=sd)
    raise StudyError(f"{where}.distribution must be uniform or normal (or give values = [...]), got {dist!r}")


def study_from_dict(doc: dict, base: Path | None = None) -> Study:
    """A :class:`Study` from a parsed study document (``base``: the folder vehicle files are relative to)."""
    from ..model.presets import PRESETS, load_preset
    known = {"vehicle", "measures", "design", "factors", "speed_kph", "chunk_size"}
    unknown = set(doc) - known
    if unknown:
        raise StudyError(f"unknown key {sorted(unknown)[0]!r}; valid: {', '.join(sorted(known))}")
    name = doc.get("vehicle")
    if not isinstance(name, str) or not name:
        raise StudyError(f"vehicle must be a preset ({', '.join(PRESETS)}) or a vehicle file, got {name!r}")
    if name in PRESETS:
        vehicle = load_preset(name)
    else:
        path = (base or Path.cwd()) / name
        if not path.is_file():
            raise StudyError(f"vehicle: {name!r} is neither a preset ({', '.join(PRESETS)}) nor a file ({path})")
        vehicle = load_vehicle(path)
    measures = doc.get("measures", list(DEFAULT_MEASURES))
    if not isinstance(measures, list) or not measures or any(m not in MEASURES for m in measures) or \
            len(set(measures)) != len(measures):
        bad = next((m for m in measures if m not in MEASURES), measures) if isinstance(measures, list) else measures
        raise StudyError(f"measures: {bad!r} is not a measure (or is repeated); valid: {', '.join(MEASURES)}")
    design = doc.get("design", {})
    if not isinstance(design, dict):
        raise StudyError(f"design must be a table, got {design!r}")
    unknown = set(design) - {"kind", "count", "seed"}
    if unknown:
        raise StudyError(f"design: unknown key {sorted(unknown)[0]!r}; valid: kind, count, seed")
    kind = design.get("kind", "grid")
    if kind not in ("grid", "random"):
        raise StudyError(f"design.kind must be grid or random, got {kind!r}")
    factors_doc = doc.get("factors", {})
    if not isinstance(factors_doc, dict) or not factors_doc:
        raise StudyError("factors: at least one factor is needed (a table of factor = {values = [...]} or "
                         "{distribution = ...})")
    factors = tuple(_factor(vehicle, n, s) for n, s in factors_doc.items())
    if "speed_kph" in factors_doc and "speed_mps" in factors_doc:
        raise StudyError("factors: give speed_kph or speed_mps, not both")
    speed_kph = None
    if "speed_kph" not in factors_doc and "speed_mps" not in factors_doc:
        speed_kph = _number("speed_kph", doc.get("speed_kph"), positive=True) if "speed_kph" in doc else None
        if speed_kph is None:
            raise StudyError("speed_kph: give the speed (speed_kph = 88.0) or a speed factor")
    count, seed = 0, None
    if kind == "grid":
        if any(not f.values for f in factors):
            f = next(f for f in factors if not f.values)
            raise StudyError(f"factors.{f.name}: a grid design needs values = [...], got a {f.distribution} "
                             "distribution (use design.kind = \"random\")")
    else:
        count = design.get("count")
        if isinstance(count, bool) or not isinstance(count, int) or not 1 <= count <= MAX_CASES:
            raise StudyError(f"design.count must be an integer in [1, {MAX_CASES}], got {count!r}")
        seed = design.get("seed")
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise StudyError(f"design.seed must be an integer >= 0 (random designs are reproducible), got {seed!r}")
    chunk = doc.get("chunk_size", 0)
    if isinstance(chunk, bool) or not isinstance(chunk, int) or not 0 <= chunk <= 100_000:
        raise StudyError(f"chunk_size must be an integer in [0, 100000] (0: chosen), got {chunk!r}")
    study = Study(vehicle, factors, kind, tuple(measures), count, seed, speed_kph, chunk)
    if study.n_cases > MAX_CASES:
        raise StudyError(f"the design has {study.n_cases} cases; at most {MAX_CASES}")
    if kind == "random":
        study.check_draws()         # refuses non-positive draws now, not in a worker
    return study


def load_study(path) -> Study:
    """Read and check a study file (TOML)."""
    path = Path(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise StudyError(f"study file {path} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise StudyError(f"study file {path} cannot be read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise StudyError(f"study file {path} is not valid TOML: {exc}") from None
    return study_from_dict(doc, path.parent)


def study_from_stored(doc: dict) -> Study:
    """The study of :meth:`Study.to_dict` (as stored with the results)."""
    factors = tuple(Factor(**(f | {"values": tuple(f["values"])})) for f in doc["factors"])
    return Study(loads_vehicle(doc["vehicle_toml"]), factors, doc["kind"], tuple(doc["measures"]), doc["count"],
                 doc["seed"], doc["speed_kph"], doc["chunk_size"])
