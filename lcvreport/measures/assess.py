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

import numpy as np

from ..model.vehicle import Vehicle
from ..units import kph_to_mps
from ..util.threads import one_blas_thread
from .criteria import Criteria, judge
from .registry import CONDITIONS, MEASURES
from .scheme import Scheme

#: the speed a measure that does not depend on it is computed at [km/h] (it plays no part)
NO_SPEED_KPH = 88.0


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
    bounds: dict = dataclasses.field(default_factory=dict)

    @property
    def unit(self) -> str:
        return MEASURES[self.key].unit

    @property
    def label(self) -> str:
        return MEASURES[self.key].label

    def conditions_text(self) -> str:
        """The conditions as a person reads them: ``100 km/h, A0 0.15 g, F 0.4 Hz``."""
        parts = []
        for k, v in self.conditions.items():
            c = CONDITIONS[k]
            unit = "°" if c.unit == "deg" else f" {c.unit}"
            parts.append(f"{c.short} {v:g}{unit}".strip())
        if parts:
            return ", ".join(parts)
        return "quasi-static" if MEASURES[self.key].family == "rollover" else "-"

    def to_dict(self) -> dict:
        return {"key": self.key, "conditions": dict(self.conditions), "value": self.value,
                "verdicts": dict(self.verdicts), "level_reached": self.level_reached, "reason": self.reason,
                "unit": self.unit, "limits": dict(self.limits)}


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

    def evidence(self, key: str):
        """The :class:`~lcvreport.measures.evidence.Evidence` of the measure ``key``."""
        from .evidence import evidence
        return evidence(self, next(m for m in self.measures if m.key == key))

    def to_dict(self) -> dict:
        """``{"scheme", "levels", "measures": [{"key", "conditions", "value", "verdicts",
        "level_reached", "reason", "unit", "limits"}], "level_reached"}`` (docs/assessment.md)."""
        return {"scheme": self.scheme.name, "levels": list(self.scheme.levels),
                "measures": [m.to_dict() for m in self.measures], "level_reached": self.level_reached}

    def rows(self) -> list[dict]:
        """The verdict table: one row per measure -- the measure, its conditions, the value and
        unit, the verdict at every level, the level it reaches -- and a last row for the vehicle."""
        rows = []
        for m in self.measures:
            row = {"measure": m.label, "key": m.key, "conditions": m.conditions_text(),
                   "value": "none" if m.value is None else f"{m.value:.4g}", "unit": m.unit}
            row.update({level: m.verdicts[level] for level in self.scheme.levels})
            row["level reached"] = m.level_reached or "none"
            rows.append(row)
        last = {"measure": "the vehicle", "key": "", "conditions": "", "value": "", "unit": ""}
        last.update({level: "pass" if all(m.verdicts[level] == "pass" for m in self.measures) else "fail"
                     for level in self.scheme.levels})
        last["level reached"] = self.level_reached or "none"
        rows.append(last)
        return rows

    def table(self):
        """:meth:`rows` as a :class:`pandas.DataFrame`."""
        import pandas as pd
        return pd.DataFrame(self.rows())


def _groups(scheme: Scheme) -> list[dict]:
    """Measures whose conditions agree, merged: [{"conditions", "members"}] in the file's order."""
    groups = []
    for m in scheme.measures:
        for g in groups:
            if all(g["conditions"].get(k, v) == v for k, v in m.conditions.items()):
                g["conditions"].update(m.conditions)
                g["members"].append(m)
                break
        else:
            groups.append({"conditions": dict(m.conditions), "members": [m]})
    return groups


@one_blas_thread
def assess(vehicle: Vehicle, scheme: Scheme, tire_scale: float = 1.0, load_units=None, sources=None
           ) -> SchemeAssessment:
    """Every measure of ``scheme`` of ``vehicle`` at its conditions, judged per level.

    Parameters
    ----------
    vehicle : Vehicle
    scheme : lcvreport.measures.scheme.Scheme
    tire_scale : float
    load_units : list of str, optional
        Units carrying the 1 % rule: a residual source of the trim and the straight path.
    sources : lcvreport.model.yaw_plane.loads.ResidualSources, optional
        Further residual sources (the crossfall is the scheme's condition ``crossfall_percent``).

    Returns
    -------
    SchemeAssessment
    """
    from ..model.yaw_plane.loads import ResidualSources
    from .measure_set import measure_values
    if sources is not None and sources.crossfall_percent:
        raise ValueError("the crossfall is a condition of the scheme (crossfall_percent), not a source here")
    verdicts = {}
    for g in _groups(scheme):
        cond = g["conditions"]
        speed = kph_to_mps(cond.get("speed_kph", NO_SPEED_KPH))
        f_hz = cond.get("ra_frequency_hz", CONDITIONS["ra_frequency_hz"].default)
        src = dataclasses.replace(sources or ResidualSources(), crossfall_percent=cond.get("crossfall_percent", 0.0))
        others = {k: v for k, v in cond.items() if k not in ("speed_kph", "ra_frequency_hz", "crossfall_percent")}
        keys = list(dict.fromkeys([k for m in g["members"] for k in (m.key, *m.references)]))
        if "yaw_damping_coefficient" in keys:
            keys.append("yaw_damping_lower_bound")
        reasons = {}
        values = measure_values(vehicle, speed, keys, tire_scale, load_units, f_hz, src if src else None,
                                others, reasons=reasons)
        doc = dict(values)
        if any(k.startswith("trim.") for k in keys):
            doc["trim"] = None if values.get("trim.offtracking_m") is None else {
                "delta_rad": values.get("trim.delta_rad"), "offtracking_m": values.get("trim.offtracking_m")}
            why = reasons.get("trim.offtracking_m") or reasons.get("trim.delta_rad")
            if why:
                reasons["trim"] = why
        doc["reasons"] = reasons
        for m in g["members"]:
            verdicts[m.key] = _verdict(m, doc, scheme.levels)
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
    return SchemeAssessment(vehicle, scheme, measures, reached, reason, float(tire_scale),
                            tuple(load_units) if load_units else (), sources)


def _verdict(m, doc: dict, levels) -> MeasureVerdict:
    judged = {level: judge(Criteria({m.key: m.limits[level]}), doc)[m.key] for level in levels}
    verdicts = {level: j["verdict"] for level, j in judged.items()}
    notes = {level: j["note"] for level, j in judged.items()}
    value = judged[levels[0]]["value"]
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
    bounds = {}
    for level in levels:
        lim = m.limits[level].resolved(lambda k: doc.get(k))
        bounds[level] = tuple(None if b is None or not np.isfinite(b) else float(b) for b in (lim.min, lim.max))
    return MeasureVerdict(m.key, dict(m.conditions), value, verdicts, limits, notes, reached, reason, bounds)
