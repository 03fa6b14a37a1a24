"""What a study's table says: the spread of each measure, and how many cases pass a criteria
file's limits -- overall and along each factor (the study report's tables; drawing is in
:mod:`lcvreport.plotting.vehicle`).

Examples
--------
>>> import pandas as pd
>>> from lcvreport.measures.criteria import Criteria, Limit
>>> t = pd.DataFrame({"case_id": [0, 1, 2, 3], "speed_kph": [80.0, 80.0, 100.0, 100.0],
...                   "hsso_m": [0.1, 0.2, 0.4, None]})
>>> quantile_rows(t, ["hsso_m"])[0]["undefined"]
1
>>> p = pass_rates(t, Criteria({"hsso_m": Limit("hsso_m", None, 0.3, "example", False)}), ["speed_kph"])
>>> p.overall[0]["passed"], p.overall[0]["judged"]
(2, 3)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..measures.criteria import judge_values, lower_bounds_of

QUANTILES = (0.0, 0.05, 0.5, 0.95, 1.0)


def quantile_rows(table, measures) -> list[dict]:
    """Per measure: cases with a value, undefined (null) cases, and its 0/5/50/95/100 % quantiles."""
    rows = []
    for m in measures:
        x = table[m].to_numpy(dtype=float)
        ok = x[np.isfinite(x)]
        row = {"measure": m, "cases": int(ok.size), "undefined": int(x.size - ok.size)}
        for q in QUANTILES:
            row[f"q{int(q * 100)}"] = float(np.quantile(ok, q)) if ok.size else math.nan
        rows.append(row)
    return rows


def wilson(passed: int, n: int, z: float = 1.959963984540054) -> tuple:
    """The Wilson score 95 % interval of a pass rate ``passed / n``."""
    if n == 0:
        return math.nan, math.nan
    p = passed / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return max(0.0, c - h), min(1.0, c + h)


@dataclass
class PassRates:
    """Pass rates of a study against limits: ``overall`` rows (per limit and all together) and
    ``by_factor[factor]`` = (bin centres, {limit key or "all": pass rate per bin})."""

    overall: list
    by_factor: dict

    def plot(self):
        from ..measures.registry import unit_of
        from ..plotting.study import study_pass_rates
        return study_pass_rates(self, {f: unit_of(f) for f in self.by_factor})


def pass_rates(table, criteria, factors, bins: int = 8) -> PassRates:
    """Judge every case by every limit of ``criteria`` whose measure the table has: pass, fail,
    or not judged (the measure undefined).  Along each factor: the pass rate in ``bins`` bins of
    equal count (or per value, for a factor of few values)."""
    limits = [lim for key, lim in criteria.limits.items() if key in table.columns]
    verdict = {}
    overall = []
    judged_all = np.ones(len(table), bool)
    pass_all = np.ones(len(table), bool)
    for spec in limits:
        x = table[spec.key].to_numpy(dtype=float)
        lim = spec.resolved(lambda k: table[k].to_numpy(dtype=float) if k in table else None)
        judged, ok = judge_values(lim, x, lower_bounds_of(table, lim.key))   # the verdicts of lcv measures
        verdict[lim.key] = (judged, ok)
        judged_all &= judged
        pass_all &= ok
        lo, hi = wilson(int(ok.sum()), int(judged.sum()))
        overall.append({"limit": spec.text(), "judged": int(judged.sum()), "passed": int(ok.sum()),
                        "pass_rate": ok.sum() / judged.sum() if judged.sum() else math.nan, "ci95_low": lo,
                        "ci95_high": hi, "source": lim.source})
    if len(limits) > 1:
        lo, hi = wilson(int(pass_all.sum()), int(judged_all.sum()))
        overall.append({"limit": "all of the above", "judged": int(judged_all.sum()), "passed": int(pass_all.sum()),
                        "pass_rate": pass_all.sum() / judged_all.sum() if judged_all.sum() else math.nan,
                        "ci95_low": lo, "ci95_high": hi, "source": ""})
        verdict["all"] = (judged_all, pass_all)
    by_factor = {}
    for f in factors:
        x = table[f].to_numpy(dtype=float)
        distinct = np.unique(x)
        if distinct.size <= bins:
            centres, which = distinct, np.searchsorted(distinct, x)
        else:
            edges = np.quantile(x, np.linspace(0, 1, bins + 1))
            which = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, bins - 1)
            centres = np.array([np.median(x[which == b]) if np.any(which == b) else np.nan for b in range(bins)])
        rates = {}
        for key, (judged, ok) in verdict.items():
            rates[key] = np.array([ok[(which == b) & judged].sum() / max(1, ((which == b) & judged).sum())
                                   if ((which == b) & judged).any() else np.nan for b in range(centres.size)])
        by_factor[f] = (centres, rates)
    return PassRates(overall, by_factor)


def level_shares(table, scheme) -> list[dict]:
    """The share of a study's cases reaching each level of ``scheme`` (the columns of
    ``lcv study --scheme``, docs/studies.md#schemes): per level, in the scheme's order (most
    demanding first), the cases whose ``level_reached`` is that level, and those reaching it or
    a more demanding one; then the cases reaching no level; a row per measure follows with the
    cases each measure takes to each level.

    Examples
    --------
    >>> import pandas as pd
    >>> from lcvreport.measures.scheme import loads_scheme
    >>> s = loads_scheme('scheme = "s"\\nlevels = ["L1", "L2"]\\n[measures.lssp_m]\\nsource = "p"\\n'
    ...                  'levels = { L1 = { max = 7.0 }, L2 = { max = 9.0 } }')
    >>> t = pd.DataFrame({"level_reached": ["L1", "L2", "", "L2"], "level.lssp_m": ["L1", "L2", "", "L2"]})
    >>> [(r["level"], r["cases"], r["at least"]) for r in level_shares(t, s)][:3]
    [('L1', 1, 1), ('L2', 2, 3), ('none', 1, 4)]
    """
    n = len(table)
    rows = []
    reached = table["level_reached"].astype(str).to_numpy()
    cumulative = 0
    for level in [*scheme.levels, ""]:
        count = int((reached == level).sum())
        cumulative += count
        rows.append({"what": "the case", "level": level or "none", "cases": count,
                     "share": count / n if n else math.nan, "at least": cumulative,
                     "share at least": cumulative / n if n else math.nan})
    for m in scheme.measures:
        col = table[f"level.{m.key}"].astype(str).to_numpy()
        cumulative = 0
        for level in [*scheme.levels, ""]:
            count = int((col == level).sum())
            cumulative += count
            rows.append({"what": m.key, "level": level or "none", "cases": count,
                         "share": count / n if n else math.nan, "at least": cumulative,
                         "share at least": cumulative / n if n else math.nan})
    return rows
