"""Criteria: the user's limits on the measures, and the verdicts (docs/measures.md).

No limits are built in: a criteria file names the standard and its numbers::

    [limits]
    ra_single_sine = { max = 2.0, source = "the standard, clause and edition" }
    yaw_damping_coefficient = { min = 0.15, source = "..." }

A limit may be relative to another measure of the same vehicle, as a factor times its key::

    ra_single_sine_roll = { max = "5.7 * srt_rrcu_g", source = "..." }

(the rearward amplification of the Australian scheme is limited relative to the static
rollover threshold of the rearmost roll-coupled unit); where that measure is null the limit
is not computed, and the verdict says which measure it needed.

Keys are the measure registry's (:data:`lcvreport.measures.registry.CRITERIA_KEYS`: the scalar
keys of ``lcv measures --json``, ``trim.offtracking_m`` for the trim, with an absolute value
when ``abs = true``).  A verdict is ``pass``, ``fail`` or ``not computed`` (the measure is
null: the text says why).  A null that stands for a bound is judged on it: the yaw damping
coefficient of a vehicle whose every joint is heavily damped is at least
``yaw_damping_lower_bound`` (0.6901), the critical speed of a vehicle stable up to 200 km/h
is above 200 km/h: a ``min`` at or below the bound passes.

Examples
--------
>>> c = Criteria({"hsto_m": Limit("hsto_m", None, 0.6, "example", False)})
>>> judge(c, {"hsto_m": 0.5})["hsto_m"]["verdict"]
'pass'
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..util.files import FileInputError, read_toml_file
from .registry import CRITERIA_KEYS, canonical, unknown_key_message

#: keys a limit may name: every scalar measure of the registry (its spelling, as ``lcv measures --json``)
KEYS = CRITERIA_KEYS


class CriteriaError(ValueError):
    """A criteria file that cannot be used; the message names the key."""


@dataclass(frozen=True)
class Relative:
    """A bound that is ``factor`` times another measure ``key`` of the same vehicle."""

    factor: float
    key: str

    def __format__(self, spec: str) -> str:
        return self.key if self.factor == 1.0 else f"{self.factor:g} * {self.key}"


#: a relative bound as a criteria file writes it: "5.7 * srt_rrcu_g" or "srt_rrcu_g"
_RELATIVE = re.compile(r"\s*(?:([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*\*\s*)?([A-Za-z_][A-Za-z0-9_.]*)\s*\Z")


@dataclass(frozen=True)
class Limit:
    """One limit: ``min <= value <= max`` (either may be None, or a :class:`Relative` bound), its
    source, on |value| if ``absolute``."""

    key: str
    min: float | Relative | None
    max: float | Relative | None
    source: str
    absolute: bool = False

    def text(self) -> str:
        v = f"|{self.key}|" if self.absolute else self.key
        if self.min is not None and self.max is not None:
            return f"{self.min:g} <= {v} <= {self.max:g}"
        return f"{v} >= {self.min:g}" if self.min is not None else f"{v} <= {self.max:g}"

    @property
    def references(self) -> tuple[str, ...]:
        """The measures its bounds are relative to."""
        return tuple(b.key for b in (self.min, self.max) if isinstance(b, Relative))

    def resolved(self, lookup) -> "Limit":
        """The limit with every relative bound replaced by ``factor * lookup(key)`` (a number, an
        array, or NaN where the measure is null)."""
        def value(b):
            if not isinstance(b, Relative):
                return b
            x = lookup(b.key)
            with np.errstate(over="ignore", invalid="ignore"):     # 1e308 * 2 is inf: a bound all the same
                return b.factor * (math.nan if x is None else np.asarray(x, dtype=float))
        return Limit(self.key, value(self.min), value(self.max), self.source, self.absolute)


@dataclass(frozen=True)
class Criteria:
    """Limits by measure key."""

    limits: dict

    def source_summary(self) -> str:
        return "; ".join(sorted({lim.source for lim in self.limits.values()}))


def load_criteria(path: str | Path) -> Criteria:
    """Read a criteria file (TOML, ``[limits]`` table).

    Raises
    ------
    CriteriaError
        Unreadable file, unknown keys, a limit without min or max, non-finite numbers, no source.
    """
    try:
        doc = read_toml_file(path, "criteria file")
    except FileInputError as exc:
        raise CriteriaError(str(exc)) from None
    unknown = set(doc) - {"limits", "description"}
    if unknown or not isinstance(doc.get("limits"), dict) or not doc["limits"]:
        raise CriteriaError("needs a [limits] table (and an optional description), nothing else")
    limits = {}
    for key, spec in doc["limits"].items():
        key = canonical(key)                      # a key of an earlier release is its alias
        if key not in KEYS:
            raise CriteriaError(f"limits.{key}: {unknown_key_message(key)}")
        if not isinstance(spec, dict) or set(spec) - {"min", "max", "source", "abs"}:
            raise CriteriaError(f"limits.{key}: expected {{ min = .., max = .., source = \"..\", abs = false }}")
        lo, hi = spec.get("min"), spec.get("max")
        bounds = []
        for name, val in (("min", lo), ("max", hi)):
            if isinstance(val, str):
                bounds.append(parse_relative(key, name, val))
                continue
            if val is not None and (isinstance(val, bool) or not isinstance(val, (int, float)) or
                                    not math.isfinite(val)):
                raise CriteriaError(f"limits.{key}.{name} must be a finite number or \"<factor> * <measure key>\", "
                                    f"got {val!r}")
            bounds.append(None if val is None else float(val))
        lo, hi = bounds
        if lo is None and hi is None:
            raise CriteriaError(f"limits.{key}: give min, max or both")
        if isinstance(lo, float) and isinstance(hi, float) and lo > hi:
            raise CriteriaError(f"limits.{key}: min {lo:g} is above max {hi:g}")
        source = spec.get("source")
        if not isinstance(source, str) or not source.strip():
            raise CriteriaError(f"limits.{key}.source: name the standard the limit comes from")
        limits[key] = Limit(key, lo, hi, source, bool(spec.get("abs", False)))
    return Criteria(limits)


def parse_relative(key: str, name: str, text: str) -> Relative:
    m = _RELATIVE.match(text)
    if m is None:
        raise CriteriaError(f"limits.{key}.{name} must be a number or \"<factor> * <measure key>\" (e.g. "
                            f"\"5.7 * srt_rrcu_g\"), got {text!r}")
    factor = 1.0 if m.group(1) is None else float(m.group(1))
    if not math.isfinite(factor):
        raise CriteriaError(f"limits.{key}.{name}: the factor must be finite, got {m.group(1)!r}")
    ref = canonical(m.group(2))
    if ref not in KEYS:
        raise CriteriaError(f"limits.{key}.{name}: {unknown_key_message(ref)}")
    if ref == key:
        raise CriteriaError(f"limits.{key}.{name}: a limit cannot be relative to its own measure")
    return Relative(factor, ref)


def measure_value(doc: dict, key: str):
    if key.startswith("trim."):
        trim = doc.get("trim")
        return None if trim is None else trim.get(key.split(".", 1)[1])
    return doc.get(key)


def null_lower_bound(doc: dict, key: str) -> float | None:
    """What a null measure is known to be at least, or None: the yaw damping coefficient of a
    vehicle whose every joint is heavily damped (``yaw_damping_lower_bound``), the critical speed
    of a vehicle stable up to the search's end (200 km/h)."""
    if measure_value(doc, key) is not None:
        return None
    return _bound(key, doc.get("yaw_damping_lower_bound"), "critical_speed_kph" in doc)


def _bound(key: str, ydc_bound, has_critical_speed: bool = True):
    from .stability import CRITICAL_SPEED_MAX_KPH
    if key == "yaw_damping_coefficient":
        return ydc_bound
    if key == "critical_speed_kph" and has_critical_speed:
        return CRITICAL_SPEED_MAX_KPH
    return None


def judge_values(lim: Limit, values, lower_bounds=None):
    """The verdicts of one limit on many values (NaN: null), as arrays (judged, passed): a value
    is judged against the limit; a null with a lower bound L (:func:`null_lower_bound`) is judged
    when L decides -- a ``min`` at or below L passes, a ``max`` below L fails -- and not judged
    otherwise.  One rule for ``lcv measures --criteria``, the report and a study's pass rates."""
    x = np.asarray(values, dtype=float)
    if lim.absolute:
        x = np.abs(x)
    if lim.references:
        raise ValueError(f"limit on {lim.key}: resolve its relative bounds first (Limit.resolved)")
    # a bound is known unless NaN (a null measure it is relative to); an infinite one (a relative
    # bound that overflowed) is a bound all the same: every value is below +inf
    bounds_known = ~np.isnan(np.broadcast_to(np.asarray(lim.min if lim.min is not None else 0.0, float), x.shape)) & \
        ~np.isnan(np.broadcast_to(np.asarray(lim.max if lim.max is not None else 0.0, float), x.shape))
    has = np.isfinite(x) & bounds_known
    xv = np.where(has, x, 0.0)
    ok = has & ((lim.min is None) | (xv >= (lim.min if lim.min is not None else 0.0))) & \
        ((lim.max is None) | (xv <= (lim.max if lim.max is not None else 0.0)))
    judged = has.copy()
    if lower_bounds is not None and not lim.absolute:
        L = np.broadcast_to(np.asarray(lower_bounds, dtype=float), x.shape)
        bounded = ~np.isfinite(x) & bounds_known & np.isfinite(L)
        Lv = np.where(bounded, L, 0.0)
        if lim.max is not None:
            fails = bounded & (Lv > lim.max)
            judged |= fails
        if lim.min is not None and lim.max is None:
            passes = bounded & (Lv >= lim.min)
            judged |= passes
            ok |= passes
    return judged, ok


def judge(criteria: Criteria, doc: dict) -> dict:
    """Verdict per limit for a measures document (``MeasureSet.to_dict()``): ``{key:
    {"verdict", "value", "limit", "source", "note"}}``.  A null measure is ``not computed``,
    unless it stands for a lower bound (:func:`null_lower_bound`) that decides the limit
    (:func:`judge_values`)."""
    out = {}
    for key, spec in criteria.limits.items():
        value = measure_value(doc, key)
        bound = null_lower_bound(doc, key)
        lim = spec.resolved(lambda k: measure_value(doc, k))
        judged, ok = judge_values(lim, [math.nan if value is None else value],
                                  [math.nan if bound is None else bound])
        missing = [k for k in spec.references if measure_value(doc, k) is None]
        if judged[0]:
            verdict = "pass" if ok[0] else "fail"
            note = f"{spec.text()} = {lim.text()} ({lim.source})" if spec.references else f"{lim.text()} ({lim.source})"
            note += "" if value is not None else f"; the measure is at least {bound:g}"
        elif missing:
            why = (doc.get("reasons") or {}).get(missing[0])
            verdict, note = "not computed", f"the limit is relative to {missing[0]}, which is null here" + (
                f": {why}" if why else "")
        else:
            why = (doc.get("reasons") or {}).get(key.split(".")[0] if key.startswith("trim.") else key)
            verdict, note = "not computed", f"the measure is null here: {why}" if why else \
                "the measure is null here (see the measures' notes)"
        out[key] = {"verdict": verdict, "value": value, "limit": spec.text(), "source": lim.source, "note": note}
    return out


def lower_bounds_of(table, key: str):
    """The lower bounds of a study table's nulls of ``key`` (NaN where none), as
    :func:`null_lower_bound` gives them for one case."""
    n = len(table)
    ydc = table["yaw_damping_lower_bound"].to_numpy(dtype=float) if "yaw_damping_lower_bound" in table else \
        np.full(n, np.nan)
    b = _bound(key, ydc)
    return np.full(n, np.nan) if b is None else np.broadcast_to(np.asarray(b, dtype=float), (n,))
