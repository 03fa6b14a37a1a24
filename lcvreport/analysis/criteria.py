"""Criteria: the user's limits on the measures, and the verdicts (SPEC section 12).

No limits are built in: a criteria file names the standard and its numbers::

    [limits]
    ra_single_sine = { max = 2.0, source = "the standard, clause and edition" }
    yaw_damping_coefficient = { min = 0.15, source = "..." }

Keys are the ``lcv measures --json`` keys (``trim.offtracking_m`` for the trim, with an
absolute value when ``abs = true``).  A verdict is ``pass``, ``fail`` or ``not computed``
(the measure is null: the text says why).

Examples
--------
>>> c = Criteria({"hsto_m": Limit("hsto_m", None, 0.6, "example", False)})
>>> judge(c, {"hsto_m": 0.5})["hsto_m"]["verdict"]
'pass'
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from ..util.files import FileInputError, loads_toml, read_text_file
from .measures import FIELD_KEYS

#: keys a limit may name
KEYS = ("least_damping_ratio", "least_damped_frequency_hz", "critical_speed_kph", "ra_frequency", "ra_single_sine",
        "trim.delta_rad", "trim.offtracking_m") + FIELD_KEYS


class CriteriaError(ValueError):
    """A criteria file that cannot be used; the message names the key."""


@dataclass(frozen=True)
class Limit:
    """One limit: ``min <= value <= max`` (either may be None), its source, on |value| if ``absolute``."""

    key: str
    min: float | None
    max: float | None
    source: str
    absolute: bool = False

    def text(self) -> str:
        v = f"|{self.key}|" if self.absolute else self.key
        if self.min is not None and self.max is not None:
            return f"{self.min:g} <= {v} <= {self.max:g}"
        return f"{v} >= {self.min:g}" if self.min is not None else f"{v} <= {self.max:g}"


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
        doc = loads_toml(read_text_file(path, "criteria file"))
    except FileInputError as exc:
        raise CriteriaError(str(exc)) from None
    except tomllib.TOMLDecodeError as exc:
        raise CriteriaError(f"not valid TOML: {exc}") from None
    except ValueError as exc:           # an integer beyond Python's digit limit: its line and key
        raise CriteriaError(str(exc)) from None
    unknown = set(doc) - {"limits", "description"}
    if unknown or not isinstance(doc.get("limits"), dict) or not doc["limits"]:
        raise CriteriaError("needs a [limits] table (and an optional description), nothing else")
    limits = {}
    for key, spec in doc["limits"].items():
        if key not in KEYS:
            raise CriteriaError(f"limits.{key}: unknown measure; valid: {', '.join(KEYS)}")
        if not isinstance(spec, dict) or set(spec) - {"min", "max", "source", "abs"}:
            raise CriteriaError(f"limits.{key}: expected {{ min = .., max = .., source = \"..\", abs = false }}")
        lo, hi = spec.get("min"), spec.get("max")
        for name, val in (("min", lo), ("max", hi)):
            if val is not None and (isinstance(val, bool) or not isinstance(val, (int, float)) or
                                    not math.isfinite(val)):
                raise CriteriaError(f"limits.{key}.{name} must be a finite number, got {val!r}")
        if lo is None and hi is None:
            raise CriteriaError(f"limits.{key}: give min, max or both")
        if lo is not None and hi is not None and lo > hi:
            raise CriteriaError(f"limits.{key}: min {lo} is above max {hi}")
        source = spec.get("source")
        if not isinstance(source, str) or not source.strip():
            raise CriteriaError(f"limits.{key}.source: name the standard the limit comes from")
        limits[key] = Limit(key, None if lo is None else float(lo), None if hi is None else float(hi), source,
                            bool(spec.get("abs", False)))
    return Criteria(limits)


def _value(doc: dict, key: str):
    if key.startswith("trim."):
        trim = doc.get("trim")
        return None if trim is None else trim.get(key.split(".", 1)[1])
    return doc.get(key)


def judge(criteria: Criteria, doc: dict) -> dict:
    """Verdict per limit for a measures document (``MeasureSet.to_dict()``): ``{key:
    {"verdict", "value", "limit", "source", "note"}}``."""
    out = {}
    for key, lim in criteria.limits.items():
        value = _value(doc, key)
        if value is None:
            verdict, note = "not computed", "the measure is null here (see the measures' notes)"
        else:
            x = abs(value) if lim.absolute else value
            ok = (lim.min is None or x >= lim.min) and (lim.max is None or x <= lim.max)
            verdict, note = ("pass" if ok else "fail"), f"{lim.text()} ({lim.source})"
        out[key] = {"verdict": verdict, "value": value, "limit": lim.text(), "source": lim.source, "note": note}
    return out
