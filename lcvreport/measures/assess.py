"""An assessment against a scheme: every measure of the scheme at its own conditions, judged
against the limits of every level, the level each measure reaches and the level the vehicle
reaches (docs/assessment.md).

Measures whose conditions agree (the same speed, and the same value of every condition both
depend on) are computed together, each family once
(:func:`~lcvreport.measures.measure_set.measure_values`); a limit relative to another measure
takes that measure under the same conditions.  A measure **reaches** the first level, in the
scheme's order (most demanding first), whose limit it passes; the vehicle reaches the first
level every measure passes.  A measure that is null is ``not computed`` at every level, with
its reason, and the vehicle then reaches no level.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.measures.scheme import loads_scheme
>>> s = loads_scheme('''
... scheme = "example"
... levels = ["L1", "L2"]
... [measures.hsso_m]
... speed_kph = 100.0
... source = "placeholder"
... levels = { L1 = { max = 0.5 }, L2 = { max = 1.0 } }
... ''')
>>> a = assess(load_preset("aucnat"), s)
>>> a.measures[0].verdicts, a.level_reached
({'L1': 'fail', 'L2': 'pass'}, 'L2')
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..model.vehicle import Vehicle
from ..units import kph_to_mps
from ..util.threads import one_blas_thread
from .criteria import Criteria, judge
from .registry import CONDITIONS, MEASURES
from .scheme import Scheme

#: the speed a measure that does not depend on it is computed at [km/h] (it plays no part)
NO_SPEED_KPH = 88.0


#: the RA reference points as a verdict table names them
POINTS = {"sprung_cg": "the rearmost unit's sprung CG", "roll_axis": "the rearmost unit's roll axis",
          "steer_axle": "the steered axle", "cg": "unit 1's CG"}
#: the verdicts as a verdict table writes them (a failure in capitals, to stand out)
VERDICT_WORDS = {"pass": "pass", "fail": "FAIL", "not computed": "n/c"}


@dataclass(frozen=True)
class MeasureVerdict:
    """One measure of the scheme: its value under its ``conditions``, the verdict and the
    limit's text per level, the level it reaches (None: none, ``reason`` says why)."""

    key: str
    conditions: dict
    value: float | None
    verdicts: dict
    limits: dict
    notes: dict
    level_reached: str | None
    reason: str | None
    #: every level's bounds as numbers, relative ones resolved: {level: (min or None, max or None)}
    #: (finite ones: what a drawing can show)
    bounds: dict = dataclasses.field(default_factory=dict)
    #: what a null value is known to be at least (the yaw damping coefficient of a vehicle whose
    #: every joint is heavily damped), else None
    lower_bound: float | None = None
    #: per level, how far inside its limit the value is (negative: how far outside), in the
    #: measure's unit; None where not computed or judged on the lower bound
    margins: dict = dataclasses.field(default_factory=dict)
    #: per level, the limit as numbers with every relative bound resolved: ``{"min", "max"}``
    #: (None where the level sets none or the bound is no finite number: relative to a null
    #: measure, or overflowed -- :attr:`limit_texts` says which)
    resolved: dict = dataclasses.field(default_factory=dict)
    #: per level, the resolved limit as a reader reads it (``<= 5.7 × 0.4799 = 2.736``)
    limit_texts: dict = dataclasses.field(default_factory=dict)
    #: the model it was taken on (the scheme entry's ``model``)
    model: str = "yaw_plane"
    #: the value on each model the scheme asked for beside it (``beside``), not judged: {model: value or None}
    beside: dict = dataclasses.field(default_factory=dict)

    @property
    def unit(self) -> str:
        return MEASURES[self.key].unit

    @property
    def label(self) -> str:
        return MEASURES[self.key].label

    @property
    def title(self) -> str:
        """The measure in the standards' words (:attr:`Measure.title`)."""
        return MEASURES[self.key].title

    def value_text(self, digits: int = 4) -> str:
        """The value as a verdict table shows it: the number, ``>= 0.6901 (every joint heavily
        damped)`` for a null known by its lower bound, or ``none``."""
        if self.value is not None:
            others = "".join(f" ({m.replace('_', '-')}: {'none' if b is None else f'{b:.{digits}g}'})"
                             for m, b in self.beside.items())
            return f"{self.value:.{digits}g}{others}"
        if self.lower_bound is not None:
            why = " (every joint heavily damped)" if self.key == "yaw_damping_coefficient" else ""
            return f">= {self.lower_bound:.{digits}g}{why}"
        return "none"

    def cell(self, level: str) -> str:
        """The verdict table's cell of ``level``: the verdict, the limit as a number (a relative
        one resolved) and the signed margin (``FAIL <= 0.5 (-0.02521)``: positive inside the
        limit, negative outside)."""
        word = VERDICT_WORDS[self.verdicts[level]]
        if self.verdicts[level] == "not computed":
            return word
        b = self.resolved.get(level) or {}
        bound = " and ".join(f"{sign} {b[k]:.4g}" for k, sign in (("min", ">="), ("max", "<=")) if b.get(k) is not None)
        if not bound:                                   # an infinite bound: the text says how
            bound = self.limit_texts[level].rsplit(" = ", 1)[-1]
        bound = ("|x| " if self.limits[level].startswith("|") else "") + bound
        margin = self.margins.get(level)
        how = f"value {self.value_text()}" if margin is None else f"{margin:+.4g}"
        return f"{word} {bound} ({how})"

    def conditions_text(self) -> str:
        """The conditions as a person reads them: ``100 km/h, A0 0.15 g, F 0.4 Hz``."""
        parts = []
        for k, v in self.conditions.items():
            c = CONDITIONS[k]
            if c.choices:
                parts.append(f"{c.short} {POINTS.get(v, v)}")
                continue
            unit = "°" if c.unit == "deg" else f" {c.unit}"
            parts.append(f"{c.short} {v:g}{unit}".strip())
        if self.model != "yaw_plane":
            parts.append(f"{self.model.replace('_', '-')} model")
        if parts:
            return ", ".join(parts)
        return "quasi-static" if MEASURES[self.key].family == "rollover" else "-"

    def to_dict(self) -> dict:
        """The measure's entry of ``lcv assess --json`` (docs/assessment.md)."""
        return {"key": self.key, "standard": MEASURES[self.key].standard, "label": self.label,
                "caveat": MEASURES[self.key].caveat or None,
                "conditions": dict(self.conditions), "value": self.value, "lower_bound": self.lower_bound,
                "verdicts": dict(self.verdicts), "level_reached": self.level_reached, "reason": self.reason,
                "unit": self.unit, "limits": dict(self.limits),
                "limits_resolved": {level: dict(b) for level, b in self.resolved.items()},
                "margins": dict(self.margins),
                **({"model": self.model} if self.model != "yaw_plane" else {}),
                **({"beside": dict(self.beside)} if self.beside else {})}


@dataclass(frozen=True)
class SchemeAssessment:
    """The assessment of ``vehicle`` against ``scheme`` (see the module docstring).
    ``to_dict()`` is the JSON of ``lcv assess --json``; ``rows()`` the verdict table."""

    vehicle: Vehicle
    scheme: Scheme
    measures: tuple[MeasureVerdict, ...]
    level_reached: str | None
    reason: str | None
    tire_scale: float = 1.0
    load_units: tuple = ()
    #: the residual sources beyond the 1 % rule (the crossfall: each measure's condition)
    sources: object = None
    #: the files assessed, as ``lcv assess`` read them: {"vehicle": {"name", "sha256"}, "scheme":
    #: {...}} (empty for an assessment of objects)
    files: dict = dataclasses.field(default_factory=dict)

    def evidence(self, key: str):
        """The :class:`~lcvreport.measures.evidence.Evidence` of the measure ``key``."""
        from .evidence import evidence
        return evidence(self, next(m for m in self.measures if m.key == key))

    def with_files(self, vehicle: tuple[str, bytes] | None = None, scheme: tuple[str, bytes] | None = None
                   ) -> "SchemeAssessment":
        """The assessment naming the files it read: ``(name, bytes)`` of the vehicle file and the
        scheme file (their SHA-256 goes into the JSON and the report)."""
        import hashlib
        files = dict(self.files)
        for kind, item in (("vehicle", vehicle), ("scheme", scheme)):
            if item is not None:
                files[kind] = {"name": item[0], "sha256": hashlib.sha256(item[1]).hexdigest()}
        return dataclasses.replace(self, files=files)

    def to_dict(self) -> dict:
        """The JSON of ``lcv assess --json`` (docs/assessment.md): the scheme, its levels, the
        vehicle, lcvreport's version, the files' SHA-256, every measure (value, lower bound,
        verdicts, resolved limits, margins, reason), the level the vehicle reaches and why not
        the first."""
        from ..version import __version__
        return {"scheme": self.scheme.name, "status": self.scheme.status, "levels": list(self.scheme.levels),
                "vehicle": self.vehicle.name, "lcvreport_version": __version__,
                "files": {k: dict(v) for k, v in self.files.items()}, "tire_scale": self.tire_scale,
                "measures": [m.to_dict() for m in self.measures], "level_reached": self.level_reached,
                "reason": self.reason}

    def level_columns(self) -> dict:
        """{column key of :meth:`rows`: the level's name} -- the level columns carry keys of
        their own, so that a level named ``value`` or ``L1_kph`` is a level, not a column of the
        table or a unit suffix."""
        return {f"verdict at level {k + 1}": level for k, level in enumerate(self.scheme.levels)}

    def rows(self) -> list[dict]:
        """The verdict table: one row per measure -- the measure in the standard's words and its
        key, its conditions, the value and unit, per level the verdict with the resolved limit and
        the margin (:meth:`level_columns` names those columns), the level it reaches -- and a last
        row for the vehicle."""
        cols = self.level_columns()
        rows = []
        for m in self.measures:
            caveat = MEASURES[m.key].caveat
            row = {"measure": f"{m.title} ({m.key})" + (f"; {caveat.split(':')[0]}" if caveat else ""),
                   "key": m.key, "conditions": m.conditions_text(),
                   "value": m.value_text(), "unit": m.unit}
            row.update({col: m.cell(level) for col, level in cols.items()})
            row["level reached"] = m.level_reached or "none"
            rows.append(row)
        last = {"measure": "the vehicle", "key": "", "conditions": "", "value": "", "unit": ""}
        last.update({col: "pass" if all(m.verdicts[level] == "pass" for m in self.measures) else "FAIL"
                     for col, level in cols.items()})
        last["level reached"] = self.level_reached or "none"
        rows.append(last)
        return rows

    def limit_rows(self) -> list[dict]:
        """The limits, one row per measure: its conditions, every level's limit as the scheme
        writes it (resolved where relative) and its source -- once when every level shares it."""
        rows = []
        for sm, m in zip(self.scheme.measures, self.measures):
            row = {"measure": f"{m.title} ({m.key})", "conditions": m.conditions_text()}
            row.update({col: m.limit_texts[level] for col, level in self.level_columns().items()})
            sources = list(dict.fromkeys(sm.limits[level].source for level in self.scheme.levels))
            row["source"] = sources[0] if len(sources) == 1 else "; ".join(
                f"{level}: {sm.limits[level].source}" for level in self.scheme.levels)
            rows.append(row)
        return rows

    def table(self):
        """:meth:`rows` as a :class:`pandas.DataFrame`."""
        import pandas as pd
        return pd.DataFrame(self.rows())


def scheme_groups(scheme: Scheme) -> list[dict]:
    """Measures whose conditions agree, merged: [{"conditions", "members", "model"}] in the file's
    order (each group's measures computed together)."""
    groups = []
    for m in scheme.measures:
        for g in groups:
            if g["model"] == m.model and all(g["conditions"].get(k, v) == v for k, v in m.conditions.items()):
                g["conditions"].update(m.conditions)
                g["members"].append(m)
                break
        else:
            groups.append({"conditions": dict(m.conditions), "members": [m], "model": m.model})
    return groups


@one_blas_thread
def assess(vehicle: Vehicle, scheme: Scheme, tire_scale: float = 1.0, load_units=None, sources=None,
           precomputed: list | None = None) -> SchemeAssessment:
    """Every measure of ``scheme`` of ``vehicle`` at its conditions, judged per level.

    Parameters
    ----------
    vehicle : Vehicle or path
        The vehicle, or a vehicle file's path (read and checked: :func:`lcvreport.load_vehicle`).
    scheme : lcvreport.measures.scheme.Scheme or path
        The scheme, or a scheme file's path (read and checked: :func:`~lcvreport.measures.scheme.load_scheme`).
        A file given by its path is named in the result with its SHA-256, as ``lcv assess``
        names it (:meth:`SchemeAssessment.with_files`).
    tire_scale : float
    load_units : list of str, optional
        Units carrying the 1 % rule: a residual source of the trim and the straight path.
    sources : lcvreport.model.yaw_plane.loads.ResidualSources, optional
        Further residual sources (the crossfall is the scheme's condition ``crossfall_percent``).
    precomputed : list of dict, optional
        Per group of :func:`scheme_groups`, values already computed for this vehicle
        ({key: value}: a study's batch, :func:`batched_group_values`); the rest is computed here.

    Returns
    -------
    SchemeAssessment

    Raises
    ------
    lcvreport.VehicleError, lcvreport.VehicleFileError, lcvreport.measures.scheme.SchemeError
        A vehicle or scheme that is not valid (one line naming the key).
    lcvreport.util.files.FileInputError
        A file given by its path that is missing, not a regular file or too large.
    ValueError
        A crossfall among ``sources`` (it is the scheme's condition).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> a = assess(load_vehicle("examples/vehicles/b_double.toml"), "examples/schemes/template.toml")
    >>> [m.key for m in a.measures][:2], a.scheme.name
    (['srt_rrcu_g', 'yaw_damping_coefficient'], 'Template scheme (PLACEHOLDER limits, not a standard)')
    """
    from ..model.vehicle import check_vehicle
    from ..model.yaw_plane.loads import ResidualSources
    from .measure_set import measure_values
    files = {}
    if isinstance(vehicle, str) or hasattr(vehicle, "__fspath__"):        # a vehicle file's path: read it
        from ..model.vehicle_file import load_vehicle
        from ..util.files import read_file_bytes
        vehicle, files["vehicle"] = load_vehicle(vehicle), (Path(vehicle).name, read_file_bytes(vehicle, "vehicle file"))
    check_vehicle(vehicle)
    if isinstance(scheme, str) or hasattr(scheme, "__fspath__"):          # a scheme file's path: read it
        from ..util.files import read_file_bytes
        from .scheme import load_scheme
        scheme, files["scheme"] = load_scheme(scheme), (Path(scheme).name, read_file_bytes(scheme, "scheme file"))
    if not isinstance(scheme, Scheme):
        raise TypeError(f"scheme must be a Scheme (lcvreport.measures.scheme.load_scheme(path)) or a scheme file's "
                        f"path, got the {type(scheme).__name__}")
    if sources is not None and sources.crossfall_percent:
        raise ValueError("the crossfall is a condition of the scheme (crossfall_percent), not a source here")
    verdicts = {}
    for gi, g in enumerate(scheme_groups(scheme)):
        cond = g["conditions"]
        speed = kph_to_mps(cond.get("speed_kph", NO_SPEED_KPH))
        f_hz = cond.get("ra_frequency_hz", CONDITIONS["ra_frequency_hz"].default)
        src = dataclasses.replace(sources or ResidualSources(), crossfall_percent=cond.get("crossfall_percent", 0.0))
        others = {k: v for k, v in cond.items() if k not in ("speed_kph", "ra_frequency_hz", "crossfall_percent")}
        keys = list(dict.fromkeys([k for m in g["members"] for k in (m.key, *m.references)]))
        if "yaw_damping_coefficient" in keys:
            keys.append("yaw_damping_lower_bound")
        if any(k.startswith("trim.") for k in keys):           # the trim is one result: both of its keys
            keys += [k for k in ("trim.delta_rad", "trim.offtracking_m") if k not in keys]
        reasons = {}
        given = precomputed[gi] if precomputed else {}
        rest = [k for k in keys if k not in given]
        values = measure_values(vehicle, speed, rest, tire_scale, load_units, f_hz, src if src else None,
                                others, reasons=reasons, model=g["model"]) if rest else {}
        values = {k: given[k] if k in given else values[k] for k in keys}
        doc = dict(values)
        if any(k.startswith("trim.") for k in keys):
            doc["trim"] = None if values.get("trim.delta_rad") is None else {
                "delta_rad": values.get("trim.delta_rad"), "offtracking_m": values.get("trim.offtracking_m")}
            why = reasons.get("trim.offtracking_m") or reasons.get("trim.delta_rad")
            if why:
                reasons["trim"] = why
        doc["reasons"] = reasons
        for m in g["members"]:
            verdicts[m.key] = _verdict(m, doc, scheme.levels)
            if m.beside:                      # the value on other models, shown beside, not judged
                beside = {b: measure_values(vehicle, speed, [m.key], tire_scale, load_units, f_hz,
                                            src if src else None, others, model=b)[m.key] for b in m.beside}
                verdicts[m.key] = dataclasses.replace(verdicts[m.key], beside=beside)
    measures = tuple(verdicts[m.key] for m in scheme.measures)
    reached = next((level for level in scheme.levels if all(m.verdicts[level] == "pass" for m in measures)), None)
    reason = None
    if reached is None:
        nc = [m.key for m in measures if m.level_reached is None and "not computed" in m.verdicts.values()]
        fails = [m.key for m in measures if m.level_reached is None and m.key not in nc]
        parts = ([f"not computed: {', '.join(nc)}"] if nc else []) + ([f"fails every level: {', '.join(fails)}"]
                                                                     if fails else [])
        reason = "; ".join(parts) if parts else "no level is passed by every measure"
    elif reached != scheme.levels[0]:
        first = scheme.levels[0]
        reason = "fails " + first + ": " + ", ".join(m.key for m in measures if m.verdicts[first] != "pass")
    a = SchemeAssessment(vehicle, scheme, measures, reached, reason, float(tire_scale),
                         tuple(load_units) if load_units else (), sources)
    return a.with_files(files.get("vehicle"), files.get("scheme")) if files else a


def batched_group_values(vehicle: Vehicle, variants, scheme: Scheme, tire_scale: float = 1.0) -> list:
    """What of ``scheme``'s groups (:func:`scheme_groups`) has a batched form, for every vehicle of
    ``variants`` (of ``vehicle``'s geometry) at once: per variant, per group, ``{key: value}`` --
    the ``precomputed`` of :func:`assess`, which computes the rest.  A family is batched where the
    registry gives it a batched function that reads no residual force (no trim, no crossfall) on
    the yaw-plane or yaw-roll model; a variant's value that the batch leaves undefined (NaN) is
    not given (:func:`assess` computes it, with its reason), but for the yaw damping coefficient's
    lower bound, which the batch leaves NaN exactly where the coefficient is defined (None
    there).  Each value equals :func:`assess`'s own to 1e-12 (tests/test_study_scheme.py).

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> from lcvreport.measures.scheme import load_scheme
    >>> v = load_vehicle("examples/vehicles/b_double.toml")
    >>> s = load_scheme("examples/schemes/template.toml")
    >>> pre = batched_group_values(v, [v], s)
    >>> a = assess(v, s, precomputed=pre[0])
    >>> a.to_dict()["measures"][0]["value"] == assess(v, s).to_dict()["measures"][0]["value"]
    True
    """
    from ..analysis.batch import BatchError, VariantBatch
    from .measure_set import check_conditions
    from .registry import FAMILIES, MeasureCase, model_of_family
    variants = list(variants)
    out = [[{} for _ in scheme_groups(scheme)] for _ in variants]
    batches = {}
    for gi, g in enumerate(scheme_groups(scheme)):
        cond = g["conditions"]
        keys = list(dict.fromkeys([k for m in g["members"] for k in (m.key, *m.references)]))
        if "yaw_damping_coefficient" in keys:
            keys.append("yaw_damping_lower_bound")
        speed = kph_to_mps(cond.get("speed_kph", NO_SPEED_KPH))
        f_hz = cond.get("ra_frequency_hz", CONDITIONS["ra_frequency_hz"].default)
        others = check_conditions({k: v for k, v in cond.items()
                                   if k not in ("speed_kph", "ra_frequency_hz", "crossfall_percent")})
        for name, family in FAMILIES.items():
            asked = [k for k in keys if MEASURES[k].family == name]
            if not asked or not family.batched or any(k not in family.batched_keys for k in asked) \
                    or "crossfall_percent" in family.conditions:
                continue
            model, _why = model_of_family(family, g["model"])
            if model not in ("yaw_plane", "yaw_roll") or "F" in family.batched_parameters():
                continue
            if family.needs == "steer" and not vehicle.steered_axles:
                continue
            case = MeasureCase(vehicle, speed, float(tire_scale), float(f_hz), None, conditions=others, model=model)
            if not family.applies(case):
                continue
            if model not in batches:
                try:
                    batches[model] = VariantBatch.of_vehicles(vehicle, variants, model)
                except (BatchError, ValueError):                # not one geometry: case by case
                    batches[model] = None
            if batches[model] is None:
                continue
            arrays = family.compute_batched(batches[model], case)
            for b in range(len(variants)):
                got = {k: float(arrays[k][b]) for k in asked}
                if name == "yaw_damping" and np.isfinite(got.get("yaw_damping_coefficient", np.nan)):
                    got["yaw_damping_lower_bound"] = None if np.isnan(got.get("yaw_damping_lower_bound", 0.0)) \
                        else got["yaw_damping_lower_bound"]
                if all(v is None or np.isfinite(v) for v in got.values()):
                    out[b][gi].update(got)
    return out


def _verdict(m, doc: dict, levels) -> MeasureVerdict:
    from .criteria import null_lower_bound
    judged = {level: judge(Criteria({m.key: m.limits[level]}), doc)[m.key] for level in levels}
    verdicts = {level: j["verdict"] for level, j in judged.items()}
    notes = {level: j["note"] for level, j in judged.items()}
    value = judged[levels[0]]["value"]
    lower = null_lower_bound(doc, m.key)
    reached = next((level for level in levels if verdicts[level] == "pass"), None)
    if any(v == "not computed" for v in verdicts.values()):
        reason = next(notes[level] for level in levels if verdicts[level] == "not computed")
    elif reached is None:
        reason = f"fails every level; {levels[-1]}: {notes[levels[-1]]}"
    elif reached != levels[0]:
        before = levels[levels.index(reached) - 1]
        reason = f"fails {before}: {notes[before]}"
    else:
        reason = None
    limits = {level: m.limits[level].text() for level in levels}
    bounds, resolved, margins, texts = {}, {}, {}, {}
    for level in levels:
        spec = m.limits[level]
        lim = spec.resolved(lambda k: doc.get(k))
        nums = tuple(None if b is None else float(b) for b in (lim.min, lim.max))
        bounds[level] = tuple(None if b is None or not np.isfinite(b) else b for b in nums)
        resolved[level] = {"min": bounds[level][0], "max": bounds[level][1]}
        texts[level] = _limit_text(spec, nums, doc)
        margins[level] = _margin(value, nums, spec.absolute) if verdicts[level] != "not computed" else None
    return MeasureVerdict(m.key, dict(m.conditions), value, verdicts, limits, notes, reached, reason, bounds,
                          lower, margins, resolved, texts, getattr(m, "model", "yaw_plane"))


def _margin(value, bounds: tuple, absolute: bool) -> float | None:
    """How far inside its bounds ``value`` is (negative: outside), or None for a null value."""
    if value is None:
        return None
    x = abs(value) if absolute else value
    lo, hi = bounds
    gaps = ([x - lo] if lo is not None else []) + ([hi - x] if hi is not None else [])
    with np.errstate(invalid="ignore"):
        g = float(min(gaps))
    return g if np.isfinite(g) else None


def _limit_text(spec, bounds: tuple, doc: dict) -> str:
    """A level's limit as a reader reads it: ``<= 0.6``, ``>= 0.15``, and a relative bound with
    its factor, the measure's value and the product (``<= 5.7 × 0.4799 = 2.736``)."""
    from .criteria import Relative, measure_value
    v = f"|{spec.key}|" if spec.absolute else ""
    parts = []
    for sign, b, num in ((">=", spec.min, bounds[0]), ("<=", spec.max, bounds[1])):
        if b is None:
            continue
        if isinstance(b, Relative):
            ref = measure_value(doc, b.key)
            shown = "null" if ref is None else f"{ref:.4g}"
            result = "not computed" if num is None or np.isnan(num) else f"{num:.4g}"
            parts.append(f"{sign} {b.factor:g} × {b.key} = {b.factor:g} × {shown} = {result}")
        else:
            parts.append(f"{sign} {num:.4g}")
    return (v + " " if v else "") + " and ".join(parts)
