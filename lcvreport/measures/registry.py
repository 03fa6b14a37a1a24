"""Every measure once: its key, label, unit, definition, where it is defined, the model it is
computed on, the kind of limit a standard puts on it, and the functions that compute it --
for one vehicle and over a batch of variants.

``lcv measures`` (text, CSV, JSON), ``--criteria``, studies, the report tables and
:func:`~lcvreport.measures.measure_set.measure_set` read these tables; criteria files and
studies accept exactly their keys (one spelling each: the JSON's, with a dot for a nested key
such as ``trim.offtracking_m``).

The table is the data file ``lcvreport/data/measures.toml``.  Measures computed together (one
manoeuvre, one analysis) form a **family**
(:data:`FAMILIES`): its ``scalar`` function maps a :class:`MeasureCase` to the values of its
keys and the reason of every null; its ``batched`` function gives the family's scalar keys
over the variants of a :class:`~lcvreport.analysis.batch.VariantBatch`, one array per key, in
order (keyword arguments taken from the case by name: ``speed_mps``, ``tire_scale``,
``f_hz``, ``F``).  Adding a measure is its function, one entry here and its test; a
measure of another model (``model="yaw_roll"``) registers the same way.

=============================  ==========  ==========================================
field of :class:`Measure`      example     what
=============================  ==========  ==========================================
``key``                        ``hsso_m``  the key of ``lcv measures --json`` (and criteria, studies)
``label``                                  the row label of the text and report tables
``unit``                       ``m``       SI unit (``-``: dimensionless)
``definition``                             one line: what it is
``doc``                                    the section of ``docs/measures.md`` that defines it
``family``                     steady_turn the family that computes it (None: a condition)
``limit``                      ``max``     the kind of limit a standard sets (None: none)
``shape``                      scalar      ``scalar`` or ``per_unit`` (a list, front to rear)
=============================  ==========  ==========================================

Examples
--------
>>> MEASURES["hsso_m"].unit, MEASURES["hsso_m"].limit, MEASURES["hsso_m"].model
('m', 'max', 'yaw_plane')
>>> "trim.offtracking_m" in CRITERIA_KEYS, "speed_mps" in CRITERIA_KEYS
(True, False)
>>> FAMILIES["steady_turn"].keys
('hsso_m', 'steady_turn_delta_rad')
"""
from __future__ import annotations

import importlib
import inspect
from collections.abc import Mapping
from importlib import resources
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:                                # annotations only: the registry imports no model
    from ..model.vehicle import Vehicle

#: why a measure computed on request is null in a measure set that did not ask for it
ON_REQUEST = ("computed on request (it takes seconds): lcv measures --model nonlinear, a scheme or a study that "
              "names it, or measure_values with its key")
#: the integration tolerance of a measure's manoeuvre on a model that is not linear: its measures
#: agree with rtol 1e-8's to 1e-7 relative (tests/test_model_axis.py), at half the evaluations
MEASURE_RTOL = 1e-6
#: why the lane change of the inverse system is null on a model that is not linear
INVERSE_ONLY = ("undefined on the {model} model: the lane change prescribes the steered axle's acceleration through the "
                "inverse system, which only a linear model has; the closed-loop lane change (hsto_driver_m) is this "
                "model's")
#: why the steady-state families are null on a model other than the yaw plane
STEADY_ONLY = ("not computed on the {model} model: the steady turn, the straight path and the trim solve the yaw "
               "plane's steady-state equations (docs/measures.md); lcv measures without --model gives them")


def model_of_family(family: "Family", model: str) -> tuple[str | None, str | None]:
    """The model ``family`` is computed on when a case's model is ``model`` (a key of
    :data:`lcvreport.model.base.MODELS`), or None with the reason: a family of a fixed model
    (the low-speed turn, the roll families, the friction demand) on its own; one of the model
    axis by what it ``requires`` -- ``linear``: a linear model itself, another model's
    linearization at straight running (the nonlinear model's is the yaw plane: docs/nonlinear.md
    #reduction-checks); ``response``: the model itself; ``inverse``: a linear model only;
    ``steady``: the yaw plane only.

    Examples
    --------
    >>> model_of_family(FAMILIES["least_damping"], "nonlinear")
    ('yaw_plane', None)
    >>> model_of_family(FAMILIES["lane_change"], "nonlinear")[0] is None
    True
    """
    if family.model != "yaw_plane" or not family.requires:
        return family.model, None
    linear = model in ("yaw_plane", "yaw_roll")
    if family.requires == "linear":
        return (model if linear else "yaw_plane"), None
    if family.requires == "response":
        return model, None
    if family.requires == "inverse":
        return (model, None) if linear else (None, INVERSE_ONLY.format(model=model.replace("_", "-")))
    return (model, None) if model == "yaw_plane" else (None, STEADY_ONLY.format(model=model.replace("_", "-")))


#: why a family whose equations are singular for the vehicle is null
NO_STEADY_STATE = ("undefined: its equations have no solution for this vehicle (singular: a unit whose tires cannot "
                   "hold both its lateral force and its yaw moment, such as a rigid unit on one axle)")
#: why a measure that needs a steer input is null on a vehicle without a steered axle
NO_STEER = "undefined: the vehicle has no steered axle, so no steer input to respond to or trim with"


@dataclass
class MeasureCase:
    """What the families are computed from: ``vehicle``, ``speed_mps`` [m/s], ``tire_scale``
    [-], the frequency of the RA measures ``f_hz`` [Hz], ``F`` the generalized force of the
    residual sources [SI] (None: no source was given; over a batch, one row per variant, NaN
    rows: none), and ``shared`` results one family hands to another (the least damping ratio
    the yaw damping coefficient compares with, the trim's full state)."""

    vehicle: "Vehicle"
    speed_mps: float
    tire_scale: float
    f_hz: float
    F: Any = None
    shared: dict = field(default_factory=dict)
    #: the conditions other than the speed (:data:`CONDITIONS` keys); a key not given takes
    #: its default (``ra_frequency_hz`` is ``f_hz``)
    conditions: dict = field(default_factory=dict)
    #: the model the family is computed on (a key of :data:`lcvreport.model.base.MODELS`; the
    #: measure set sets it per family: :func:`model_of_family`)
    model: str = "yaw_plane"
    #: the model's options (the nonlinear model's ``tire``)
    options: dict = field(default_factory=dict)

    def model_options(self) -> dict:
        """The options :func:`lcvreport.model.base.build_model` takes for :attr:`model`: the
        nonlinear model's tire law and its friction coefficient (the condition)."""
        if self.model != "nonlinear":
            return {}
        return {"tire": self.options.get("tire", "saturating"),
                "friction_coefficient": self.condition("friction_coefficient"), "rtol": MEASURE_RTOL}

    def condition(self, key: str, measure: str | None = None):
        """The value of the condition ``key`` in its unit (:data:`CONDITIONS`); a choice (an RA
        reference point) as its name; not given: ``measure``'s default where the registry gives
        the measure one, else the condition's."""
        if key == "ra_frequency_hz":
            return self.f_hz
        if key == "speed_kph":
            from ..units import mps_to_kph
            return mps_to_kph(self.speed_mps)
        value = self.conditions.get(key)
        if value is None:
            return default_condition(key, measure)
        return value if CONDITIONS[key].choices else float(value)


def _resolve(ref: str):
    module, _, name = ref.partition(":")
    return getattr(importlib.import_module(f"{__package__}.{module}"), name)


@dataclass(frozen=True)
class Family:
    """Measures computed together: ``scalar`` and ``batched`` are ``"module:function"`` of
    :mod:`lcvreport.measures` (loaded on first use, so reading the registry loads no model);
    ``needs`` is what the vehicle or the call must have: ``steer`` (a steered axle),
    ``sources`` (a residual source), ``geometry`` (the body keys the turn checks itself)."""

    name: str
    scalar: str
    batched: str | None = None
    model: str = "yaw_plane"
    needs: str = ""
    #: the conditions it depends on (:data:`CONDITIONS` keys, ``speed_kph`` first if any)
    conditions: tuple = ()
    #: computed only when asked for (by key, a scheme, a study, its model's ``lcv measures``), not in
    #: every measure set: the nonlinear model's turn takes seconds
    on_request: bool = False
    #: what it needs of the model (a family of the model axis, ``model = "yaw_plane"``): ``linear``,
    #: ``response``, ``inverse`` or ``steady`` (:func:`model_of_family`); "" for a family of a fixed model
    requires: str = ""

    def model_for(self, model: str) -> tuple[str | None, str | None]:
        """(the model this family is computed on when the case's model is ``model``, or None; why
        not, or None): see :func:`model_of_family`."""
        return model_of_family(self, model)

    @property
    def keys(self) -> tuple[str, ...]:
        """The family's measures, in the registry's order."""
        return tuple(k for k, m in MEASURES.items() if m.family == self.name)

    @property
    def batched_keys(self) -> tuple[str, ...]:
        """The keys the batched function gives (the scalar ones), in order."""
        return tuple(k for k in self.keys if MEASURES[k].shape == "scalar") if self.batched else ()

    def batched_parameters(self) -> tuple[str, ...]:
        """The names its batched function takes (``F``: a residual force; empty: no batched form)."""
        return tuple(inspect.signature(_resolve(self.batched)).parameters) if self.batched else ()

    def applies(self, case: MeasureCase) -> bool:
        """Whether the family is computed at all (a trim only with a residual source)."""
        return self.needs != "sources" or case.F is not None

    def compute(self, case: MeasureCase) -> tuple[dict, dict]:
        """({key: value or None}, {key: why it is null}) of one vehicle; a family whose equations
        have no solution for this vehicle (a singular steady state) is null with that reason."""
        import numpy as np
        if self.needs in ("steer", "sources") and not case.vehicle.steered_axles:
            if self.needs == "sources":
                return {k: None for k in self.keys}, {"trim": NO_STEER}
            return {k: None for k in self.keys}, {k: NO_STEER for k in self.keys}
        try:
            return _resolve(self.scalar)(case)
        except np.linalg.LinAlgError:
            why = NO_STEADY_STATE
            return {k: None for k in self.keys}, ({"trim": why} if self.needs == "sources" else
                                                  {k: why for k in self.keys})

    def compute_batched(self, batch, case: MeasureCase) -> dict:
        """``{key: array (B,)}`` for every key of :attr:`batched_keys`, NaN where undefined.  The
        batched function returns a mapping by key (a positional tuple is read against
        :attr:`batched_keys` only when its length is theirs: a key added to the family and not to
        the function is refused, never a column shifted onto another key)."""
        fn = _resolve(self.batched)
        names = inspect.signature(fn).parameters
        kwargs = {k: getattr(case, k) for k in ("speed_mps", "tire_scale", "f_hz", "F") if k in names}
        kwargs.update({k: case.condition(k) for k in self.conditions if k in names and not CONDITIONS[k].choices})
        kwargs.update({k: case.conditions.get(k) for k in self.conditions if k in names and CONDITIONS[k].choices})
        out = fn(batch, **kwargs)
        keys = self.batched_keys
        if isinstance(out, Mapping):
            missing = [k for k in keys if k not in out]
            if missing:
                raise TypeError(f"family {self.name}: its batched function {self.batched} gives no {', '.join(missing)}")
            return {k: out[k] for k in keys}
        out = out if isinstance(out, tuple) else (out,)
        if len(out) != len(keys):
            raise TypeError(f"family {self.name}: its batched function {self.batched} gives {len(out)} arrays for "
                            f"{len(keys)} keys ({', '.join(keys)}); return a mapping by key")
        return dict(zip(keys, out))


@dataclass(frozen=True, eq=False)
class Measure:
    """One measure (see the module docstring for the fields)."""

    key: str
    label: str
    unit: str
    definition: str
    doc: str
    family: str | None = None
    limit: str | None = None
    shape: str = "scalar"
    #: the conditions it depends on, where fewer than its family's (None: the family's)
    own_conditions: tuple | None = None
    #: the name the performance-based standards give it ("" where they give none)
    standard: str = ""
    #: the defaults of conditions where the measure's differs from the condition's
    defaults: dict = field(default_factory=dict)
    #: what the toolkit's number leaves out of the standard's measure ("" for nothing): printed
    #: wherever it is judged (TASP: the steady part only)
    caveat: str = ""
    #: how the assessment report draws its evidence (measures.toml's header): "value" where the
    #: registry names no drawing
    evidence: str = "value"

    @property
    def title(self) -> str:
        """The measure as a verdict page names it: the standard's words, else the label."""
        return self.standard or self.label[:1].upper() + self.label[1:]

    @property
    def model(self) -> str:
        """The model it is computed on (its family's)."""
        return FAMILIES[self.family].model if self.family else "yaw_plane"

    @property
    def needs(self) -> str:
        return FAMILIES[self.family].needs if self.family else ""

    @property
    def conditions(self) -> tuple:
        """The conditions it depends on (its own where the registry gives them, else its family's;
        the speed's key first)."""
        if self.own_conditions is not None:
            return self.own_conditions
        return FAMILIES[self.family].conditions if self.family else ()

    @property
    def batched(self) -> str | None:
        """The batched family that gives it over variants, or None."""
        return self.family if self.family and self.key in FAMILIES[self.family].batched_keys else None

    @property
    def doc_url(self) -> str:
        """Where a reader of the repository finds the definition."""
        return f"docs/measures.md#{self.doc}"


@dataclass(frozen=True)
class Condition:
    """What a measure is computed under: ``key`` (with its unit, as a scheme file and ``lcv
    measures`` write it), ``label``, ``unit``, the ``range`` of :data:`lcvreport.ranges.RANGES`
    bounding it (in ``unit``, except the speed's, in m/s), its ``default`` (None: must be given)."""

    key: str
    label: str
    unit: str
    range: str
    definition: str
    default: float | str | None = None
    #: the short name of a verdict table ("A0 0.15 g"; empty: the value and unit alone)
    short: str = ""
    #: the values of a condition that is a choice (an RA reference point), not a number
    choices: tuple = ()

    @property
    def option(self) -> str:
        """The ``lcv measures`` option that sets it."""
        return "--" + self.key.replace("_", "-")

    def check(self, value, name: str | None = None):
        """``value`` as a float (a choice: as its name), or :class:`lcvreport.ranges.RangeError`
        naming ``name``."""
        from ..ranges import RANGES, RangeError
        from ..units import MPS_PER_KPH
        if self.choices:
            if not isinstance(value, str) or value not in self.choices:
                shown = repr(value) if len(repr(value)) <= 60 else repr(value)[:57] + "..."
                raise RangeError(name or self.key, f"{name or self.key} must be one of {', '.join(self.choices)}, "
                                                   f"got {shown}")
            return value
        factor = 1.0 / MPS_PER_KPH if self.key == "speed_kph" else 1.0
        return RANGES[self.range].check(value, name or self.key, factor=factor, unit=self.unit)


def default_condition(key: str, measure: str | None = None):
    """The value the condition ``key`` takes when not given: ``measure``'s own default where the
    registry gives one (the RA measures' reference points), else the condition's.

    Examples
    --------
    >>> default_condition("ra_denominator", "ra_single_sine_roll"), default_condition("ra_denominator",
    ...                                                                            "ra_lane_change_roll")
    ('cg', 'steer_axle')
    """
    if measure is not None and key in MEASURES[measure].defaults:
        return MEASURES[measure].defaults[key]
    return CONDITIONS[key].default


def _load(text: str) -> tuple[dict, dict, dict]:
    """(CONDITIONS, FAMILIES, MEASURES) from the registry's data file."""
    import tomllib
    doc = tomllib.loads(text)
    conditions = {key: Condition(key, **{k: tuple(v) if k == "choices" else v for k, v in entry.items()})
                  for key, entry in doc["conditions"].items()}
    families = {name: Family(name, **{k: tuple(v) if k == "conditions" else v for k, v in entry.items()})
                for name, entry in doc["families"].items()}
    measures = {m["key"]: Measure(**{k: v for k, v in m.items() if k != "conditions"},
                                  own_conditions=tuple(m["conditions"]) if "conditions" in m else None)
                for m in doc["measures"]}
    return conditions, families, measures


#: the conditions, the families (in the order measure_set computes them) and the measures (in
#: the order of ``lcv measures --json``): the data file ``lcvreport/data/measures.toml``
CONDITIONS, FAMILIES, MEASURES = _load(resources.files(__package__.partition(".")[0]).joinpath(
    "data", "measures.toml").read_text(encoding="utf-8"))

#: the keys a criteria file or a study may name: every scalar measure (not the speed, a condition)
CRITERIA_KEYS = tuple(k for k, m in MEASURES.items() if m.shape == "scalar" and m.family is not None)
#: the batched families and the keys each gives, in order (studies compute these over cases)
BATCHED = {name: f.batched_keys for name, f in FAMILIES.items() if f.batched}
#: keys of earlier releases: the key they are now (read as it, :func:`canonical`)
RENAMED = {"trim_delta_rad": "trim.delta_rad", "trim_offtracking_m": "trim.offtracking_m"}
#: names that are not measures but look like one: the key meant (a hint, not read as it --
#: ``tail_swing_m`` is ``lcv turn``'s per-unit table)
HINTS = {"tail_swing_m": "max_tail_swing_m"}
#: both, for the messages
ALIASES = {**RENAMED, **HINTS}
#: the keys that carry their model in their name: (model-neutral key, model) -> today's key.  Each
#: is the neutral key on that model (``measure_set(v, u, model="yaw_roll")["hsto_m"]`` is the
#: default's ``hsto_m_roll``); the named keys stay, so every scheme, study and JSON consumer of an
#: earlier release keeps working (docs/model.md#the-model-object).
MODEL_KEYS = {("least_damping_ratio", "yaw_roll"): "roll_least_damping_ratio",
              ("critical_speed_kph", "yaw_roll"): "roll_critical_speed_kph",
              ("ra_single_sine", "yaw_roll"): "ra_single_sine_roll",
              ("ra_lane_change", "yaw_roll"): "ra_lane_change_roll",
              ("hsto_m", "yaw_roll"): "hsto_m_roll"}


def model_key(key: str, model: str) -> tuple[str, str]:
    """(key, model) of a measure taken on ``model``: a model-neutral key on the yaw-roll model is
    today's key of it (:data:`MODEL_KEYS`: ``("hsto_m", "yaw_roll")`` -> ``("hsto_m_roll",
    "yaw_plane")``, the yaw-roll family computing it whatever the axis), any other as given.

    Examples
    --------
    >>> model_key("hsto_m", "yaw_roll"), model_key("hsto_driver_m", "nonlinear")
    (('hsto_m_roll', 'yaw_plane'), ('hsto_driver_m', 'nonlinear'))
    """
    named = MODEL_KEYS.get((key, model))
    return (named, "yaw_plane") if named is not None else (key, model)


def canonical(key: str) -> str:
    """The registry's key of ``key``: a key of an earlier release (``trim_delta_rad``) is an alias
    of today's (``trim.delta_rad``), read wherever a key is (criteria, schemes, studies); any other
    key as it is (an unknown one is refused by its reader).

    Examples
    --------
    >>> canonical("trim_delta_rad"), canonical("hsso_m")
    ('trim.delta_rad', 'hsso_m')
    """
    return RENAMED.get(key, key) if isinstance(key, str) else key


def unknown_key_message(key: str, valid=CRITERIA_KEYS) -> str:
    """The one line for a key that is not a measure: the key to use, if it is a known misspelling."""
    hint = ALIASES.get(key)
    if hint is not None:
        return f"{key!r} is not a measure key; the key is {hint!r}"
    return f"unknown measure {key!r}; valid: {', '.join(valid)}"


def unit_of(key: str, default: str = "1") -> str:
    """The SI unit of a measure or condition column (``default`` for a factor, a scale)."""
    if key in MEASURES:
        return MEASURES[key].unit
    return {"speed_kph": "km/h", "speed_mps": "m/s"}.get(key, default)
