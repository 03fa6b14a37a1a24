"""One case: what a computation of a vehicle is given -- the vehicle, its model, the speed, the tire
scale, the manoeuvres' conditions, the load case and the residual sources -- checked once when it is
made (by the command line from its options, by a study from each row, by a script by hand) and
handed whole to the measures, the assessment and the responses (docs/model.md#one-case).

Examples
--------
>>> from lcvreport import Case, load_preset
>>> c = Case(load_preset("tractor_semitrailer"), speed_mps=24.4, conditions={"steady_turn_radius_m": 300.0})
>>> c.measure_set().hsso_m == c.measure_values(["hsso_m"])["hsso_m"]
True
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Mapping

from ..model.vehicle import Vehicle
from ..ranges import RANGES
from .registry import CONDITIONS


@dataclass(frozen=True)
class Case:
    """What one computation of a vehicle is given, checked when it is made.

    Attributes
    ----------
    vehicle : Vehicle
    speed_mps : float or None
        Forward speed [m/s]; None where the computation takes none (an assessment: the scheme
        gives each measure's speed).
    tire_scale : float
        Factor on every tire coefficient [-].
    model : str
        A key of :data:`lcvreport.model.base.MODELS` (the command line's ``yaw-roll`` too).
    conditions : dict
        The manoeuvres' conditions by :data:`~lcvreport.measures.registry.CONDITIONS` key, each in
        the registry's unit (``ra_frequency_hz`` [Hz] among them; the speed is :attr:`speed_mps`,
        the crossfall a residual source); a condition not given is at its default.
    load_units : tuple of str
        Units carrying the 1 % rule (a residual source of the trim and the straight path).
    sources : lcvreport.model.yaw_plane.loads.ResidualSources or None
        Further residual sources: per-axle P [N] and T [N*m], misalignment [rad], crossfall [%].
    options : dict
        The model's options (the nonlinear model's ``tire``: ``"saturating"`` or ``"linear"``).

    Raises
    ------
    lcvreport.VehicleError, lcvreport.model.base.ModelError, lcvreport.ranges.RangeError, KeyError
        One line naming the parameter, the value and what is valid.

    Examples
    --------
    >>> from lcvreport import Case, load_preset
    >>> c = Case(load_preset("aucnat"), speed_mps=24.4, model="yaw-plane", load_units=["trailer1"])
    >>> c.model, c.load_units, c.f_hz
    ('yaw_plane', ('trailer1',), 0.4)
    """

    vehicle: Vehicle
    speed_mps: float | None = None
    tire_scale: float = 1.0
    model: str = "yaw_plane"
    conditions: Mapping[str, Any] = field(default_factory=dict)
    load_units: tuple = ()
    sources: Any = None
    options: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        from ..model.base import check_model
        from ..model.vehicle import check_vehicle
        from ..model.yaw_plane.loads import check_unit_names
        from .measure_set import check_conditions

        def put(key, value):                       # a frozen dataclass: its own checks normalize it
            object.__setattr__(self, key, value)
        check_vehicle(self.vehicle)
        put("model", check_model(self.model))
        if self.speed_mps is not None:
            put("speed_mps", RANGES["speed"].check(self.speed_mps, "speed_mps"))
        put("tire_scale", RANGES["tire_scale"].check(self.tire_scale, "tire_scale"))
        conditions = dict(self.conditions or {})
        f_hz = conditions.pop("ra_frequency_hz", None)
        conditions = check_conditions(conditions)
        if f_hz is not None:
            conditions["ra_frequency_hz"] = CONDITIONS["ra_frequency_hz"].check(f_hz)
        put("conditions", conditions)
        units = self.load_units
        put("load_units", tuple(check_unit_names(self.vehicle, units)) if units or isinstance(units, str) else ())
        if self.sources is not None:
            self.sources.vector(self.vehicle, self.tire_scale)        # every axle the vehicle's, every value in range
            if not self.sources:
                put("sources", None)
        put("options", dict(self.options or {}))

    # ------------------------------------------------------------------ what it is
    @property
    def f_hz(self) -> float:
        """The frequency of the RA measures and gains [Hz] (the condition ``ra_frequency_hz``)."""
        return float(self.conditions.get("ra_frequency_hz", CONDITIONS["ra_frequency_hz"].default))

    def replace(self, **changes) -> "Case":
        """This case with ``changes``, checked again (``case.replace(speed_mps=25.0)``)."""
        return dataclasses.replace(self, **changes)

    def manoeuvre_conditions(self) -> dict:
        """The conditions :func:`~lcvreport.measures.measure_set.measure_set` takes by name (all
        but the RA frequency, its ``f_hz``)."""
        return {k: v for k, v in self.conditions.items() if k != "ra_frequency_hz"}

    def model_object(self):
        """The model (:func:`lcvreport.model.base.build_model`) of the vehicle with the case's options."""
        from ..model.base import build_model
        return build_model(self.vehicle, self.model, **self.options)

    def force(self):
        """The generalized force [SI] of the load case and the residual sources on the yaw-plane
        model (what the trim is computed against); None when the case has neither."""
        from .measure_set import residual_force
        return residual_force(self.vehicle, self.load_units, self.sources, self.tire_scale)

    def _speed(self) -> float:
        if self.speed_mps is None:
            raise ValueError("speed_mps: this computation needs a speed and the case has none")
        return self.speed_mps

    def _subject(self):
        """What the measures take: the vehicle (and the model's name), or the model object when
        the model has options."""
        return (self.model_object(), None) if self.options else (self.vehicle, self.model)

    # ------------------------------------------------------------------ what it computes
    def measure_set(self):
        """Every measure of the registry of this case (:func:`~lcvreport.measures.measure_set.measure_set`).

        Returns
        -------
        MeasureSet
        """
        from .measure_set import measure_set
        subject, model = self._subject()
        return measure_set(subject, self._speed(), self.tire_scale, self.load_units or None, self.f_hz,
                           self.sources, self.manoeuvre_conditions(), model)

    def measure_values(self, keys, reasons: dict | None = None) -> dict:
        """The values of the registry keys ``keys`` only (:func:`~lcvreport.measures.measure_set.measure_values`).

        Returns
        -------
        dict
            ``{key: value or None}``; ``reasons``, a dict, receives why each null is null.
        """
        from .measure_set import measure_values
        subject, model = self._subject()
        return measure_values(subject, self._speed(), keys, self.tire_scale, self.load_units or None, self.f_hz,
                              self.sources, self.manoeuvre_conditions(), reasons, model)

    def assess(self, scheme, precomputed: list | None = None):
        """Every measure of ``scheme`` at its own conditions, judged per level
        (:func:`~lcvreport.measures.assess.assess`): the case's vehicle, tire scale, load case and
        residual sources (the scheme gives each measure's speed and conditions); ``precomputed``
        as :func:`~lcvreport.measures.assess.assess`'s (a study's batch).

        Returns
        -------
        SchemeAssessment
        """
        from .assess import assess
        return assess(self.vehicle, scheme, self.tire_scale, self.load_units or None, self.sources, precomputed)

    def respond(self, steer, t_end: float, dt: float):
        """The response of the case's model to ``steer`` from rest at its speed, sampled every
        ``dt`` to ``t_end`` [s] (:func:`~lcvreport.analysis.respond.respond`), with the load case
        and the residual sources.

        Returns
        -------
        TimeResponse or SampledResponse
        """
        import numpy as np

        from ..analysis.respond import respond
        from ..model.base import LINEAR_MODELS
        F = None
        if self.load_units and self.model not in LINEAR_MODELS:
            raise ValueError(f"load_units: the 1 % rule is a linear model's load case, not the {self.model} model's; "
                             "give its residual sources (sources)")
        if self.load_units:
            from ..model.yaw_plane.loads import load_vector, one_percent_rule
            F = np.asarray(load_vector(self.vehicle, one_percent_rule(self.vehicle, list(self.load_units)),
                                       model=self.model))
        return respond(self.vehicle, self.model, steer, self._speed(), t_end, dt, self.tire_scale, F=F,
                       sources=self.sources, options=self.options)
