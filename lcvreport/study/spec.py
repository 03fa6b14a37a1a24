"""A study file: the base vehicle, the factors, the design, the measures (docs/studies.md).

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
tire coefficient), scale factors ``<unit>.mass_scale``, ``<unit>.yaw_inertia_scale`` and
``<unit or axle>.cornering_stiffness_scale`` / ``.aligning_stiffness_scale`` /
``.longitudinal_stiffness_scale`` (a unit name scales all its axles), and on a vehicle with roll
data ``<unit>.cg_height_scale``, ``.roll_inertia_scale``, ``.coupling_roll_stiffness_scale``,
``<unit or axle>.roll_stiffness_scale``, ``.roll_damping_scale``; load cases ``load_units``
(values: lists of units carrying the 1 % rule, ``[]`` for none); residual sources ``P_<axle>_N``,
``T_<axle>_Nm``, ``eps_<axle>_rad`` (misalignment) and ``crossfall_percent`` (docs/manoeuvres.md;
they act on the trim measures ``trim.delta_rad`` and ``trim.offtracking_m``).  A factor has ``values``
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
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..measures.registry import BATCHED as _BATCH_GROUPS
from ..measures.registry import CRITERIA_KEYS, canonical, unknown_key_message
from ..measures.registry import FAMILIES as _FAMILIES
from ..model.vehicle import Vehicle, VehicleError
from ..model.vehicle_file import dumps_vehicle, load_vehicle, loads_vehicle
from ..ranges import RANGES, RangeError
from ..units import kph_to_mps
from .factors import (AXLE_SCALES, PAYLOAD, PLAIN_FACTORS, RESIDUALS, ROLL_PARAMETERS, UNIT_SCALES,  # noqa: F401
                      Factor, StudyError, parse_factor, factor_number, factor_scales, factor_values, load_label, residual_axle,
                      residual_key)

#: measures computed batched over the cases (lcvreport.analysis.batch, the registry's BATCHED groups);
#: (the roll measures on the cases' own vehicles); the others of the registry are computed case by
#: case with measure_set (same numbers, slower)
BATCHED = tuple(k for keys in _BATCH_GROUPS.values() for k in keys)
#: every measure a study can ask for: the scalar keys of the measure registry
MEASURES = tuple(CRITERIA_KEYS)
#: the trim's measures: need a residual source (a load case or a residual-source factor)
TRIM = _BATCH_GROUPS["trim"]
#: a study's measures when it names none: the yaw-plane ones computed batched (the roll measures,
#: batched too, are asked for by name: they need the roll keys)
DEFAULT_MEASURES = tuple(k for g, keys in _BATCH_GROUPS.items() if _FAMILIES[g].model == "yaw_plane" for k in keys
                         if k not in TRIM and k != "yaw_damping_lower_bound")
MAX_CASES = 10_000_000
#: cases per block of random draws (each block, each factor its own generator)
DRAW_BLOCK = 4096


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
    #: the text of a scheme file every case is assessed against (``lcv study --scheme``), or None
    scheme_toml: str | None = None

    @property
    def scheme(self):
        """The :class:`~lcvreport.measures.scheme.Scheme` of :attr:`scheme_toml` (None without one)."""
        if self.scheme_toml is None:
            return None
        from ..measures.scheme import loads_scheme
        return loads_scheme(self.scheme_toml)

    def with_scheme(self, text: str) -> "Study":
        """The study with every case assessed against the scheme file ``text`` (the level each
        measure and the case reach as columns, docs/studies.md#schemes).

        Raises
        ------
        lcvreport.measures.scheme.SchemeError
            A bad scheme.
        StudyError
            A factor the scheme fixes itself: the speed (each measure's ``speed_kph``) or the
            crossfall (a condition).
        """
        from ..measures.scheme import loads_scheme
        loads_scheme(text)
        for f in self.factors:
            if f.name in ("speed_kph", "speed_mps", "crossfall_percent"):
                what = "speed" if f.name.startswith("speed") else "crossfall"
                raise StudyError(f"factors.{f.name}: the scheme fixes each measure's {what} itself; a study with "
                                 f"--scheme varies the vehicle, not the {what}")
        return replace(self, scheme_toml=text)

    @property
    def columns(self) -> list[str]:
        """The results' columns, in order: ``case_id``, the factors, the measures, and with a
        scheme ``scheme.<key>`` and ``level.<key>`` per scheme measure and ``level_reached``."""
        cols = ["case_id"] + [f.name for f in self.factors] + list(self.measures)
        if self.scheme_toml is not None:
            keys = [m.key for m in self.scheme.measures]
            cols += [f"scheme.{k}" for k in keys] + [f"level.{k}" for k in keys] + ["level_reached"]
        return cols

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
            return factor_values(f)[rng.integers(0, len(f.values), n)]
        if f.distribution == "uniform":
            return rng.uniform(f.low, f.high, n)
        return rng.normal(f.mean, f.sd, n)

    def _draws(self, ids: np.ndarray) -> dict:
        """Every factor's draws for the cases ``ids`` of a random design."""
        out = {}
        blocks = np.unique(ids // DRAW_BLOCK)
        for i, f in enumerate(self.factors):
            values = np.empty(ids.size, dtype=object if f.name == "load_units" else float)
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
            key = residual_key(f.name)
            lo, hi = (RANGES[key].low, RANGES[key].high) if key else (0.0, math.inf)
            for b in range(math.ceil(self.count / DRAW_BLOCK)):
                draws = self._block(i, b)
                bad = np.flatnonzero(~((draws > lo) if not key else ((draws >= lo) & (draws <= hi))))
                if bad.size:
                    case = b * DRAW_BLOCK + int(bad[0])
                    valid = f"in [{lo:g}, {hi:g}]" if key else "> 0"
                    raise StudyError(f"factors.{f.name}: case {case} draws {draws[bad[0]]:.6g}; every value must be "
                                     f"{valid} (narrow the distribution)")

    def check_cases(self) -> None:
        """Refuse a study any of whose cases is outside the ranges table -- a speed, a tire
        scale, a residual source, or a unit's mass or inertia or an axle's tire coefficient
        after its scale factors -- naming the factor, the first such case and the range;
        block by block (:data:`DRAW_BLOCK` cases), in constant memory, before anything is
        computed (a model far outside the ranges gives numbers that mean nothing)."""
        from ..ranges import GYRATION_PER_REACH_MIN, VEHICLE
        n = self.n_cases
        if not self.factors:
            return
        for start in range(0, n, DRAW_BLOCK):
            ids = np.arange(start, min(n, start + DRAW_BLOCK))
            table = self.factor_table(ids)
            speeds = self.speeds_mps(table)
            r = RANGES["speed"]
            bad = np.flatnonzero(~((speeds >= r.low) & (speeds <= r.high)))
            if bad.size:
                name = "speed_mps" if "speed_mps" in table else "speed_kph"
                value = table[name][bad[0]] if name in table else self.speed_kph
                raise StudyError(f"factors.{name}: case {int(ids[bad[0]])} has {value:.6g}; a speed must be in "
                                 f"{r.text()} ({r.text(3.6, 'km/h')})")
            for name, arr in table.items():
                key = "tire_scale" if name == "tire_scale" else residual_key(name)
                if key is None:
                    continue
                vals = np.asarray(arr, dtype=float)
                r = RANGES[key]
                ok = (vals > r.low) if r.low_open else (vals >= r.low)
                bad = np.flatnonzero(~(ok & (vals <= r.high)))
                if bad.size:
                    raise StudyError(f"factors.{name}: case {int(ids[bad[0]])} has {vals[bad[0]]:.6g}; it must be in "
                                     f"{r.text()} ({r.description})")
            params = self.batch_parameters(table, payloads=True)
            for pname, vals in params.items():
                owner, key = pname.split(".", 1)
                r = VEHICLE[key]
                vals = np.asarray(vals, dtype=float)
                ok = (vals > r.low) if r.low_open else (vals >= r.low)
                bad = np.flatnonzero(~(ok & (vals <= r.high) & np.isfinite(vals)))
                if bad.size:
                    k = int(bad[0])
                    used = [f.name for f in self.factors if f.name in table and factor_scales(self.vehicle, f.name, pname)]
                    given = ", ".join(f"{f} = {float(table[f][k]):.6g}" for f in used)
                    raise StudyError(f"factors.{used[0] if used else pname}: case {int(ids[k])} makes {pname} "
                                     f"{vals[k]:.6g} {r.unit} ({given}); {key} must be in {r.text()}")
            self._check_load_balance(ids, params)
            for u in self.vehicle.units:
                h = params.get(f"{u.name}.cg_height_m")
                if h is not None and u.roll_axis_height_m is not None:
                    bad = np.flatnonzero(~(np.asarray(h, dtype=float) > u.roll_axis_height_m))
                    if bad.size:
                        i = int(bad[0])
                        raise StudyError(f"factors.{u.name}.cg_height_scale: case {int(ids[i])} puts the CG of "
                                         f"{u.name} at {float(h[i]):.6g} m, not above its roll axis "
                                         f"({u.roll_axis_height_m:g} m)")
                m = np.asarray(params.get(f"{u.name}.mass_kg", u.mass_kg), dtype=float)
                inertia = np.asarray(params.get(f"{u.name}.yaw_inertia_kg_m2", u.yaw_inertia_kg_m2), dtype=float)
                reach = max(abs(x) for x in [a.x_m for a in u.axles] + [u.front_coupling_m, u.rear_coupling_m]
                            if x is not None)
                with np.errstate(invalid="ignore", divide="ignore"):
                    k = np.sqrt(np.maximum(inertia, 0.0) / np.where(m > 0, m, np.nan))
                bad = np.flatnonzero(np.broadcast_to(k < GYRATION_PER_REACH_MIN * reach, ids.shape))
                if bad.size:
                    i = int(bad[0])
                    used = [f.name for f in self.factors
                            if f.name in (f"{u.name}.mass_scale", f"{u.name}.yaw_inertia_scale")]
                    raise StudyError(f"factors.{used[0] if used else u.name}: case {int(ids[i])} gives {u.name} a "
                                     f"radius of gyration sqrt(I/m) of {float(np.broadcast_to(k, ids.shape)[i]):.3g} m, "
                                     f"below {GYRATION_PER_REACH_MIN:g} of its {reach:.3g} m reach (its eigenvalues "
                                     "would not be reliable)")

    def _check_load_balance(self, ids: np.ndarray, params: dict) -> None:
        """Refuse a case whose static axle loads and masses disagree by more than the roll model's
        5 % (docs/roll.md): the loads follow the masses by statics (:meth:`case_vehicle`), so this
        is the base vehicle's disagreement carried into a case -- named, never computed silently."""
        from ..model.statics import G_MPS2, has_static_loads
        from ..model.yaw_roll.parameters import LOAD_BALANCE_TOLERANCE
        v = self.vehicle
        from ..model.yaw_roll.parameters import missing_roll_data
        if not has_static_loads(v) or not any(self.measures_of_model("yaw_roll")) or missing_roll_data(v):
            return                                # (without roll data the roll measures are null anyway)
        base = sum(u.mass_kg for u in v.units)
        masses = sum(np.asarray(params.get(f"{u.name}.mass_kg", u.mass_kg), dtype=float) for u in v.units)
        loads = sum(a.static_load_N for a in v.axles) + G_MPS2 * (masses - base)    # statics moves every kilogram
        off = np.broadcast_to(loads / (G_MPS2 * masses) - 1.0, ids.shape)
        bad = np.flatnonzero(np.abs(off) > LOAD_BALANCE_TOLERANCE)
        if bad.size:
            k = int(bad[0])
            raise StudyError(f"case {int(ids[k])}: the static axle loads of {v.name} sum to "
                             f"{float(np.broadcast_to(loads, ids.shape)[k]):.6g} N, its masses weigh "
                             f"{float(G_MPS2 * np.broadcast_to(masses, ids.shape)[k]):.6g} N "
                             f"({100 * float(off[k]):+.1f} %, beyond the {100 * LOAD_BALANCE_TOLERANCE:g} % the roll "
                             "measures allow): fix the vehicle file's static_load_N")

    def measures_of_model(self, model: str) -> list[str]:
        """The study's measures (and its scheme's) computed on ``model``."""
        from ..measures.registry import MEASURES as REGISTRY
        keys = list(self.measures) + ([m.key for m in self.scheme.measures] if self.scheme_toml else [])
        return [k for k in keys if REGISTRY[k].model == model]

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
            out[f.name] = factor_values(f)[rest % n]
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

    @property
    def payloads(self) -> dict:
        """{unit name: its payload factor} (``<unit>.payload_kg``)."""
        return {f.name.split(".", 1)[0]: f for f in self.factors if f.name.endswith("." + PAYLOAD)}

    @property
    def moves_geometry(self) -> bool:
        """Whether a payload off its unit's CG moves the CG (every position of the unit changes):
        such a study is computed case by case (a batch holds one geometry)."""
        return any(f.x_m != 0.0 for f in self.payloads.values())

    def batch_parameters(self, table: dict, payloads: bool = False) -> dict:
        """The scaled parameters (absolute SI values) of the cases of ``table``; with ``payloads``
        each unit's payload folded in -- its mass and yaw inertia (parallel axes), and with roll
        data its CG height and roll inertia -- what a batch of the yaw plane and the range checks
        take (without: the scale factors alone, what :meth:`case_vehicle` starts from)."""
        v = self.vehicle
        out = {}
        for name, arr in table.items():
            if name in PLAIN_FACTORS or residual_key(name) or name.endswith("." + PAYLOAD):
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
        if payloads:
            for owner, f in self.payloads.items():
                u = next(x for x in v.units if x.name == owner)
                p = np.asarray(table[f.name], dtype=float)
                m = np.asarray(out.get(f"{owner}.mass_kg", u.mass_kg), dtype=float)
                dx = p * f.x_m / (m + p)
                inertia = np.asarray(out.get(f"{owner}.yaw_inertia_kg_m2", u.yaw_inertia_kg_m2), dtype=float)
                out[f"{owner}.mass_kg"] = m + p
                out[f"{owner}.yaw_inertia_kg_m2"] = inertia + m * dx ** 2 + p * (f.x_m - dx) ** 2 + p * f.length_m ** 2 / 12
                if u.cg_height_m is not None:
                    h = np.asarray(out.get(f"{owner}.cg_height_m", u.cg_height_m), dtype=float)
                    hp = h if math.isnan(f.height_m) else f.height_m
                    ms = m - sum(a.unsprung_mass_kg or 0.0 for a in u.axles)
                    h_new = (ms * h + p * hp) / (ms + p)
                    out[f"{owner}.cg_height_m"] = h_new
                    if u.roll_inertia_kg_m2 is not None:
                        ix = np.asarray(out.get(f"{owner}.roll_inertia_kg_m2", u.roll_inertia_kg_m2), dtype=float)
                        out[f"{owner}.roll_inertia_kg_m2"] = ix + ms * (h - h_new) ** 2 + p * (hp - h_new) ** 2
        return out

    def case(self, case_id: int) -> tuple:
        """(vehicle, speed_mps, kwargs) of one case: ``measure_set(vehicle, speed_mps, **kwargs)``
        computes its row."""
        table = self.factor_table([case_id])
        kwargs = {"tire_scale": float(table["tire_scale"][0])} if "tire_scale" in table else {}
        if "load_units" in table and table["load_units"][0] != "none":
            kwargs["load_units"] = table["load_units"][0].split("+")
        sources = self.sources({k: a[:1] for k, a in table.items()}, 0)
        if sources:
            kwargs["sources"] = sources
        return self.case_vehicle(self.batch_parameters(table), 0, table), float(self.speeds_mps(table)[0]), kwargs

    def case_object(self, case_id: int):
        """The :class:`~lcvreport.measures.case.Case` of one case (its vehicle, speed -- None where the
        study has none --, tire scale, load case and residual sources): what its row is computed from.

        Examples
        --------
        >>> from lcvreport.study.spec import study_from_dict
        >>> s = study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m"],
        ...     "factors": {"trailer1.mass_scale": {"values": [0.8, 1.2]}}})
        >>> c = s.case_object(1)
        >>> round(c.speed_mps * 3.6, 6), c.vehicle.units[1].mass_kg > s.vehicle.units[1].mass_kg
        (88.0, True)
        """
        import math

        from ..measures.case import Case
        vehicle, speed_mps, kwargs = self.case(case_id)
        return Case(vehicle, None if math.isnan(speed_mps) else speed_mps, kwargs.get("tire_scale", 1.0),
                    load_units=tuple(kwargs.get("load_units") or ()), sources=kwargs.get("sources"))

    def case_vehicle(self, params: dict, k: int, table: dict | None = None) -> Vehicle:
        """The vehicle of row ``k`` of the scaled parameters ``params`` (:meth:`batch_parameters`,
        without payloads) and, with the factor ``table``, its payloads: every scaled parameter
        set, a unit's mass changed at its CG and its payload placed with the static axle loads
        moved by statics (:mod:`lcvreport.model.statics`: masses and loads move together)."""
        from ..model.statics import with_mass, with_payload
        units = list(self.vehicle.units)
        masses = {}
        for pname, arr in params.items():
            owner, key = pname.split(".", 1)
            if key == "mass_kg":
                masses[owner] = float(arr[k])
                continue
            for i, u in enumerate(units):
                if u.name == owner:
                    units[i] = replace(u, **{key: float(arr[k])})
                for j, a in enumerate(u.axles):
                    if a.name == owner:
                        axles = list(units[i].axles)
                        axles[j] = replace(axles[j], **{key: float(arr[k])})
                        units[i] = replace(units[i], axles=tuple(axles))
        vehicle = replace(self.vehicle, units=tuple(units))
        for owner, mass in masses.items():
            vehicle = with_mass(vehicle, owner, mass)
        if table is not None:
            for owner, f in self.payloads.items():
                p = float(np.asarray(table[f.name], dtype=float)[k])
                if p:
                    vehicle = with_payload(vehicle, owner, p, f.x_m, None if math.isnan(f.height_m) else f.height_m,
                                           f.length_m)
        return vehicle

    def sources(self, table: dict, k: int):
        """The residual sources (docs/manoeuvres.md) of row ``k`` of ``table``: a
        :class:`~lcvreport.model.yaw_plane.loads.ResidualSources` (empty when the study has none)."""
        from ..model.yaw_plane.loads import ResidualLoads, ResidualSources
        P, T, eps, cross = {}, {}, {}, 0.0
        for name, arr in table.items():
            key = residual_key(name)
            if key == "crossfall":
                cross = float(arr[k])
            elif key:
                {"residual_force": P, "residual_moment": T, "misalignment": eps}[key][residual_axle(name)] = \
                    float(arr[k])
        return ResidualSources(ResidualLoads({a: x for a, x in P.items() if x}, {a: x for a, x in T.items() if x}),
                               {a: x for a, x in eps.items() if x}, cross)

    # ------------------------------------------------------------------ identity
    def to_dict(self) -> dict:
        """The study as a plain document (its vehicle as vehicle-file text): stored with the
        results, and hashed to tell a rerun of the same study from another."""
        doc = {"vehicle_toml": dumps_vehicle(self.vehicle), "kind": self.kind, "count": self.count,
               "seed": self.seed, "speed_kph": self.speed_kph, "measures": list(self.measures),
               "chunk_size": self.chunk, "factors": [f.__dict__ | {"values": list(f.values)} for f in self.factors]}
        if self.scheme_toml is not None:          # (absent otherwise: earlier studies keep their digest)
            doc["scheme_toml"] = self.scheme_toml
        return doc

    def digest(self) -> str:
        return hashlib.sha256(json.dumps(self.to_dict(), sort_keys=True).encode()).hexdigest()


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
        if not path.exists():
            raise StudyError(f"vehicle: {name!r} is neither a preset ({', '.join(PRESETS)}) nor a file ({path})")
        try:
            vehicle = load_vehicle(path)
        except VehicleError as exc:
            raise StudyError(f"vehicle {name!r}: {exc}") from None
    measures = doc.get("measures", list(DEFAULT_MEASURES))
    if isinstance(measures, list):                     # keys of an earlier release are their aliases
        measures = [canonical(m) for m in measures]
        if "yaw_damping_coefficient" in measures and "yaw_damping_lower_bound" not in measures:
            # a heavily damped case's YDC is null with a bound: judged on it whether listed or not
            measures.insert(measures.index("yaw_damping_coefficient") + 1, "yaw_damping_lower_bound")
    if not isinstance(measures, list) or not measures or any(m not in MEASURES for m in measures) or \
            len(set(measures)) != len(measures):
        bad = next((m for m in measures if m not in MEASURES), None) if isinstance(measures, list) else None
        if isinstance(bad, str):
            raise StudyError(f"measures: {unknown_key_message(bad, MEASURES)}")
        raise StudyError(f"measures must be a list of distinct measure keys, got {measures!r}; valid: "
                         f"{', '.join(MEASURES)}")
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
    try:
        factors = tuple(parse_factor(vehicle, n, s) for n, s in factors_doc.items())
    except RangeError as exc:
        raise StudyError(str(exc.args[0] if exc.args else exc)) from None
    if "speed_kph" in factors_doc and "speed_mps" in factors_doc:
        raise StudyError("factors: give speed_kph or speed_mps, not both")
    speed_kph = None
    if "speed_kph" not in factors_doc and "speed_mps" not in factors_doc:
        speed_kph = factor_number("speed_kph", doc.get("speed_kph"), positive=True) if "speed_kph" in doc else None
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
    study.check_cases()             # every case inside the ranges table, before anything is computed
    return study


def load_study(path) -> Study:
    """Read and check a study file (TOML).

    Parameters
    ----------
    path : str or pathlib.Path
        A study file (TOML, docs/studies.md).

    Returns
    -------
    Study

    Raises
    ------
    StudyError
        Unreadable file or any key that is not as docs/studies.md says (one line naming it).

    Examples
    --------
    >>> s = load_study("examples/studies/aucnat_loads.toml")
    >>> s.n_cases, s.measures[0]
    (10000, 'least_damping_ratio')
    """
    from ..util.files import FileInputError, read_toml_file
    path = Path(path)
    try:
        doc = read_toml_file(path, "study file")
    except FileInputError as exc:
        raise StudyError(str(exc)) from None
    return study_from_dict(doc, path.parent)


def study_from_stored(doc: dict) -> Study:
    """The study of :meth:`Study.to_dict` (as stored with the results)."""
    factors = tuple(Factor(**(f | {"values": tuple(tuple(x) if isinstance(x, list) else x for x in f["values"])}))
                    for f in doc["factors"])
    return Study(loads_vehicle(doc["vehicle_toml"]), factors, doc["kind"], tuple(doc["measures"]), doc["count"],
                 doc["seed"], doc["speed_kph"], doc["chunk_size"], doc.get("scheme_toml"))
