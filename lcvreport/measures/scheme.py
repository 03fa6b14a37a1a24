"""Assessment schemes: which measures a scheme judges, under which conditions, against the
limits of which levels (docs/assessment.md).

A scheme file (TOML) names its levels, most demanding first, and for every measure the
conditions it is computed under and one limit per level, each with its source::

    scheme = "Template scheme (PLACEHOLDER numbers, not a standard)"
    levels = ["L1", "L2"]

    [measures.hsto_m]
    speed_kph = 100.0
    lane_change_ay_g = 0.15
    source = "the standard, clause and edition"
    [measures.hsto_m.levels]
    L1 = { max = 0.6 }
    L2 = { max = 0.8 }

Keys are the measure registry's (:data:`~lcvreport.measures.registry.CRITERIA_KEYS`), the
conditions its :data:`~lcvreport.measures.registry.CONDITIONS` that the measure's family
depends on (``speed_kph`` is required where the measure depends on the speed, the others
default to the values ``docs/measures.md`` defines the measure at).  A limit is ``min``
or ``max`` -- the kind the registry gives the measure (a larger HSTO is worse: a ``max``) --
a number or ``"<factor> * <measure key>"``, with ``abs = true`` on |value| and an optional
``source`` of its own.  No limits are built in.  A measure of the manoeuvres and eigenvalues
may name the model it is taken on (``model = "nonlinear"``; default the yaw plane; ``hsto_m`` with
``model = "yaw_roll"`` is ``hsto_m_roll``) and models whose value is shown beside it, not judged
(``beside = ["nonlinear"]``: where the linear answer stops being true).

Examples
--------
>>> s = loads_scheme('''
... scheme = "example"
... levels = ["L1", "L2"]
... [measures.hsto_m]
... speed_kph = 100.0
... source = "placeholder"
... levels = { L1 = { max = 0.6 }, L2 = { max = 0.8 } }
... ''')
>>> s.measures[0].conditions, s.measures[0].limits["L2"].text()
({'speed_kph': 100.0, 'lane_change_ay_g': 0.15, 'lane_change_frequency_hz': 0.4}, 'hsto_m <= 0.8')
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from ..ranges import RangeError
from ..util.files import FileInputError, loads_toml, read_toml_file
from ..util.text import control_character, listed, named, shown
from .criteria import CriteriaError, Limit, Relative, parse_relative
from .registry import CONDITIONS, CRITERIA_KEYS, MEASURES, canonical, default_condition, model_key, unknown_key_message

#: the keys of a scheme file's top level
TOP_KEYS = ("scheme", "levels", "description", "status", "measures")
#: a scheme's status, printed with every verdict table
STATUSES = ("template", "draft", "published", "user")


class SchemeError(ValueError):
    """A scheme file that cannot be used; the message is one line naming the key."""


def _check_text(where: str, text: str, allow: str = "") -> str:
    """``text`` unless it holds a character a scheme's text may not (a control character -- a
    newline in a level name would forge a line of the verdict table, an ESC a terminal command,
    U+0000 stops xelatex -- a bidirectional override); ``allow``: the line breaks of a free
    description."""
    bad = control_character(text, allow)
    if bad is not None:
        raise SchemeError(f"{where}: text only, got the control character U+{ord(bad):04X} in {shown(text)}")
    return text


@dataclass(frozen=True)
class SchemeMeasure:
    """One measure of a scheme: its registry ``key``, the ``conditions`` it is computed under
    (every condition its family depends on, given or at its default, in the registry's order)
    and one :class:`~lcvreport.measures.criteria.Limit` per level."""

    key: str
    conditions: dict
    limits: dict
    #: the model of the model axis it is taken on (``model = "nonlinear"`` in its entry; default the
    #: yaw plane; a neutral key on the yaw-roll model is its ``*_roll`` key on the default)
    model: str = "yaw_plane"
    #: the models whose value is shown beside the judged one, not judged (``beside = ["nonlinear"]``)
    beside: tuple = ()

    @property
    def speed_kph(self) -> float | None:
        return self.conditions.get("speed_kph")

    @property
    def references(self) -> tuple[str, ...]:
        """The measures its limits are relative to."""
        return tuple(dict.fromkeys(k for lim in self.limits.values() for k in lim.references))


@dataclass(frozen=True)
class Scheme:
    """A scheme file: its name, ``levels`` (most demanding first), ``status`` and measures in
    the file's order."""

    name: str
    levels: tuple[str, ...]
    measures: tuple[SchemeMeasure, ...]
    description: str = ""
    status: str = "user"
    path: str = ""


def load_scheme(path: str | Path) -> Scheme:
    """Read and check a scheme file (see the module docstring).

    Parameters
    ----------
    path : str or pathlib.Path
        A scheme file (TOML, docs/assessment.md).

    Returns
    -------
    Scheme

    Raises
    ------
    SchemeError
        Unreadable file or any key that is not as docs/assessment.md says, in one line naming it.

    Examples
    --------
    >>> s = load_scheme("examples/schemes/template.toml")
    >>> s.levels[0], "stfd" in [m.key for m in s.measures]
    ('L1', True)
    """
    try:
        doc = read_toml_file(path, "scheme file")
    except FileInputError as exc:
        raise SchemeError(str(exc)) from None
    return _scheme(doc, str(path))


def read_scheme_text(path: str | Path) -> str:
    """The text of the scheme file ``path``, checked (:func:`load_scheme`'s refusals)."""
    from ..util.files import read_text_file
    try:
        text = read_text_file(path, "scheme file")
    except FileInputError as exc:
        raise SchemeError(str(exc)) from None
    loads_scheme(text)
    return text


def loads_scheme(text: str) -> Scheme:
    """:func:`load_scheme` of a TOML text.

    Parameters
    ----------
    text : str
        The scheme file's text.

    Returns
    -------
    Scheme

    Raises
    ------
    SchemeError
        Not TOML, or any key that is not as docs/assessment.md says, in one line naming it.

    Examples
    --------
    >>> from pathlib import Path
    >>> s = loads_scheme(Path("examples/schemes/template.toml").read_text(encoding="utf-8"))
    >>> s.name == load_scheme("examples/schemes/template.toml").name
    True
    """
    import tomllib
    try:
        doc = loads_toml(text)
    except (tomllib.TOMLDecodeError, ValueError) as exc:
        raise SchemeError(f"the scheme is not valid TOML: {exc}") from None
    return _scheme(doc, "")


def _scheme(doc: dict, path: str) -> Scheme:
    unknown = [k for k in doc if k not in TOP_KEYS]
    if unknown:
        raise SchemeError(f"{named(unknown[0])}: not a key of a scheme file (keys: {', '.join(TOP_KEYS)})")
    name = doc.get("scheme")
    if not isinstance(name, str) or not name.strip():
        raise SchemeError("scheme: name the scheme (a string: the document, its edition, or 'template')")
    _check_text("scheme", name)
    levels = doc.get("levels")
    if not isinstance(levels, list) or not levels or not all(isinstance(x, str) and x.strip() for x in levels):
        raise SchemeError("levels: a list of level names, most demanding first (e.g. [\"L1\", \"L2\"])")
    for k, level in enumerate(levels):
        _check_text(f"levels[{k}]", level)
    if len(set(levels)) != len(levels):
        twice = next(x for x in levels if levels.count(x) > 1)
        raise SchemeError(f"levels: {shown(twice)} is named twice")
    status = doc.get("status", "user")
    if status not in STATUSES:
        raise SchemeError(f"status: one of {', '.join(STATUSES)}, got {status!r}")
    description = doc.get("description", "")
    if not isinstance(description, str):
        raise SchemeError("description: a string")
    _check_text("description", description, allow="\n\t")
    entries = doc.get("measures")
    if not isinstance(entries, dict) or not entries:
        raise SchemeError("measures: give at least one [measures.<key>] table")
    measures = tuple(_measure(canonical(key), entry, levels) for key, entry in entries.items())
    keys = [m.key for m in measures]
    twice = next((k for k in keys if keys.count(k) > 1), None)
    if twice is not None:
        raise SchemeError(f"measures.{twice}: named twice (once by an alias of an earlier release, or as the "
                          "model-neutral key with model = \"yaw_roll\")")
    known = {m.key: m for m in measures}
    for m in measures:
        for ref in m.references:
            need = [c for c in MEASURES[ref].conditions if c not in m.conditions]
            if need:
                raise SchemeError(f"measures.{m.key}.levels: the limit is relative to {ref}, which depends on "
                                  f"{', '.join(need)}, a condition {m.key} is not computed under")
            if ref in known and any(known[ref].conditions[c] != m.conditions[c] for c in MEASURES[ref].conditions):
                raise SchemeError(f"measures.{m.key}.levels: the limit is relative to {ref}, which the scheme "
                                  f"takes under other conditions; give both the same")
    return Scheme(name.strip(), tuple(levels), measures, description, status, path)


def _measure(key: str, entry, levels: list) -> SchemeMeasure:
    where = f"measures.{key}"
    if key not in MEASURES or MEASURES[key].family is None:
        raise SchemeError(f"{where}: {unknown_key_message(key)}")
    if key not in CRITERIA_KEYS:
        raise SchemeError(f"{where}: {key} is a list (one value per unit or group), not a measure a scheme can "
                          f"limit; the scalar measures: {', '.join(CRITERIA_KEYS)}")
    if not isinstance(entry, dict):
        raise SchemeError(f"{where}: a table (conditions, source, levels)")
    model, beside = _models(key, entry, where)
    key, model = model_key(key, model)
    where = f"measures.{key}"
    m = MEASURES[key]
    allowed = m.conditions
    conditions = {}
    for name, value in entry.items():
        if name in ("source", "levels", "model", "beside"):
            continue
        if name not in allowed:
            what = (f"{key} depends on {', '.join(allowed)}" if allowed else f"{key} depends on no condition")
            kind = "a condition of another measure" if name in CONDITIONS else "not a key of a measure's table"
            raise SchemeError(f"{where}.{named(name)}: {kind}; {what} (and source, levels)")
        try:
            conditions[name] = CONDITIONS[name].check(value, f"{where}.{name}")
        except RangeError as exc:
            raise SchemeError(str(exc)) from None
    for name in allowed:
        if name not in conditions:
            default = default_condition(name, key)
            if default is None:
                raise SchemeError(f"{where}.{name}: give the {CONDITIONS[name].label} [{CONDITIONS[name].unit}] "
                                  f"{key} is taken at")
            conditions[name] = default if CONDITIONS[name].choices else float(default)
    conditions = {c: conditions[c] for c in allowed}
    source = entry.get("source")
    if source is not None and (not isinstance(source, str) or not source.strip()):
        raise SchemeError(f"{where}.source: a string naming the document, its edition and clause")
    if source is not None:
        _check_text(f"{where}.source", source)
    table = entry.get("levels")
    if not isinstance(table, dict) or not table:
        raise SchemeError(f"{where}.levels: give one limit per level ({listed(levels, what='levels')})")
    for name in table:
        if name not in levels:
            raise SchemeError(f"{where}.levels.{named(name)}: not a level of the scheme (levels: "
                              f"{listed([named(x) for x in levels], what='levels')})")
    limits = {}
    for level in levels:
        if level not in table:
            raise SchemeError(f"{where}.levels: no limit for level {level!r}; give one for every level "
                              f"({listed(levels, what='levels')})")
        limits[level] = _limit(key, f"{where}.levels.{level}", table[level], source)
    return SchemeMeasure(key, conditions, limits, model, beside)


def _models(key: str, entry: dict, where: str) -> tuple[str, tuple]:
    """(model, beside) of a scheme entry: ``model`` (one of the models; only a measure of the
    model axis takes one) and ``beside`` (the models whose value is shown beside, a list)."""
    from ..model.base import MODELS
    from .registry import FAMILIES
    family = FAMILIES[MEASURES[key].family]
    axis = family.model == "yaw_plane" and bool(family.requires)
    model = entry.get("model", "yaw_plane")
    if not isinstance(model, str) or model.replace("-", "_") not in MODELS:
        raise SchemeError(f"{where}.model: one of {', '.join(MODELS)}, got {shown(str(model))}")
    model = model.replace("-", "_")
    beside = entry.get("beside", [])
    if isinstance(beside, str):
        beside = [beside]
    if not isinstance(beside, list) or not all(isinstance(b, str) and b.replace("-", "_") in MODELS for b in beside):
        raise SchemeError(f"{where}.beside: a list of models ({', '.join(MODELS)}), got {shown(str(beside))}")
    beside = tuple(dict.fromkeys(b.replace("-", "_") for b in beside if b.replace("-", "_") != model))
    if (model != "yaw_plane" or beside) and not axis:
        raise SchemeError(f"{where}.model: {key} is a measure of the {family.model.replace('_', '-')} model only; "
                          "model and beside are for the measures of the manoeuvres and eigenvalues (docs/model.md)")
    for m in (model, *beside):
        on, why = family.model_for(m)
        if on is None:
            raise SchemeError(f"{where}.{'model' if m == model else 'beside'}: {key} is {why}")
    return model, beside


def _limit(key: str, where: str, spec, source: str | None) -> Limit:
    if not isinstance(spec, dict) or set(spec) - {"min", "max", "abs", "source"}:
        raise SchemeError(f"{where}: expected {{ min = .. or max = .., abs = false, source = \"..\" }}")
    kind = MEASURES[key].limit
    given = [b for b in ("min", "max") if b in spec]
    if not given:
        raise SchemeError(f"{where}: a level without a limit; give {kind or 'min or max'}")
    if kind is not None and given != [kind]:
        worse = "larger" if kind == "max" else "smaller"
        raise SchemeError(f"{where}: {key} is limited by a {kind} (a {worse} value is worse), got "
                          f"{' and '.join(given)}")
    bounds = {}
    for b in given:
        value = spec[b]
        if isinstance(value, str):
            try:
                bounds[b] = parse_relative(key, b, value)
            except CriteriaError as exc:
                raise SchemeError(f"{where}.{b}: {str(exc).split(': ', 1)[-1]}") from None
        elif isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise SchemeError(f"{where}.{b} must be a finite number or \"<factor> * <measure key>\", got {value!r}")
        else:
            bounds[b] = float(value)
    lo, hi = bounds.get("min"), bounds.get("max")
    if isinstance(lo, float) and isinstance(hi, float) and lo > hi:
        raise SchemeError(f"{where}: min {lo:g} is above max {hi:g}")
    src = spec.get("source", source)
    if not isinstance(src, str) or not src.strip():
        raise SchemeError(f"{where}.source: name the document the limit comes from (here or in the measure's "
                          f"table)")
    _check_text(f"{where}.source", src)
    absolute = spec.get("abs", False)
    if not isinstance(absolute, bool):
        raise SchemeError(f"{where}.abs: true or false, got {absolute!r}")
    return Limit(key, lo, hi, src, absolute)


def is_relative(bound) -> bool:
    """Whether a limit's bound is relative to another measure."""
    return isinstance(bound, Relative)
