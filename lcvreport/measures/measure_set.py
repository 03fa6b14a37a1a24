"""Every measure of one vehicle at one speed: :func:`measure_set` computes the registry's
measures (:mod:`lcvreport.measures.registry`) and :class:`MeasureSet` holds them, by key,
with the reason for every one that is undefined.

The families are computed by their own modules (stability, amplification, yaw damping,
offtracking, the low-speed turn, the trim of :mod:`lcvreport.analysis.steady`); the
definitions are in ``docs/measures.md``.  Lateral acceleration of unit i's CG:
``a_i = v_i' + u r_i``, SI throughout.

Examples
--------
>>> from lcvreport import load_preset
>>> from lcvreport.units import kph_to_mps
>>> m = measure_set(load_preset("aucnat"), kph_to_mps(88.0), load_units=["trailer2", "trailer3"])
>>> sorted(m.to_dict())[:6]
['ay_gain_per_unit', 'critical_speed_kph', 'frontal_swing_m', 'hsso_m', 'hsto_m', 'least_damped_frequency_hz']
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..analysis.frequency import RA_FREQUENCY_HZ, steer_to_acceleration
from ..analysis.steady import Trim, check_trim, trim
from ..model.vehicle import Vehicle
from ..model.yaw_plane.loads import load_vector, one_percent_rule
from ..units import mps_to_kph
from .amplification import single_sine
from .low_speed import low_speed_measures
from .stability import CRITICAL_SPEED_MAX_KPH, critical_speed, least_damping


@dataclass(frozen=True)
class MeasureSet:
    """Every measure of :data:`lcvreport.measures.registry.MEASURES` for one vehicle at one
    speed, by keyword (the registry's keys; ``trim`` holds ``trim.delta_rad`` and
    ``trim.offtracking_m``).  ``to_dict()`` gives the JSON of ``lcv measures``, in the
    registry's order, with ``reasons`` for every null; ``rows()`` the text and report table.
    """

    vehicle: Vehicle
    speed_mps: float
    tire_scale: float = 1.0
    least_damping_ratio: float | None = None
    least_damped_frequency_hz: float | None = None
    critical_speed_kph: float | None = None
    ra_frequency: float | None = None
    ra_single_sine: float | None = None
    ay_gain_per_unit: list[float] | None = None
    trim: Trim | None = None
    load_units: tuple[str, ...] = ()
    f_hz: float = RA_FREQUENCY_HZ
    #: measure key -> why it is null (e.g. no steered axle: no steer input to respond to)
    undefined: dict = field(default_factory=dict)
    ra_peak: float | None = None
    ra_peak_frequency_hz: float | None = None
    yaw_damping_coefficient: float | None = None
    yaw_damping_lower_bound: float | None = None
    hsto_m: float | None = None
    ra_lane_change: float | None = None
    hsso_m: float | None = None
    steady_turn_delta_rad: float | None = None
    sources: object = None
    lssp_m: float | None = None
    low_speed_offtracking_m: float | None = None
    max_tail_swing_m: float | None = None
    frontal_swing_m: float | None = None

    def value(self, key: str):
        """The value of the registry key ``key`` (None where undefined)."""
        if key.startswith("trim."):
            return None if self.trim is None else getattr(self.trim, key.split(".", 1)[1])
        value = getattr(self, key)
        return list(value) if isinstance(value, (list, tuple)) else value

    def reason(self, key: str) -> str | None:
        """Why the measure ``key`` is null (None when it has a value)."""
        if self.value(key) is not None:
            return None
        if key.startswith("trim."):
            return self.undefined.get("trim", "no residual source was given (--load, --residual, "
                                              "--misalignment, --crossfall-percent, --tires)")
        if key == "critical_speed_kph":
            return self.undefined.get(key, f"stable at every speed up to {CRITICAL_SPEED_MAX_KPH:g} km/h")
        if key == "least_damping_ratio" or key == "least_damped_frequency_hz":
            return self.undefined.get(key, "no mode oscillates")
        if key == "yaw_damping_lower_bound":
            return "the yaw damping coefficient has a value (the bound is only given when every joint is " \
                   "heavily damped)" if self.yaw_damping_coefficient is not None else \
                self.undefined.get("yaw_damping_coefficient", "")
        return self.undefined.get(key, "undefined")

    def to_dict(self) -> dict:
        """The JSON of ``lcv measures`` (SPEC sections 8, 12, 16): the registry's keys in its order
        (a dotted key nested: ``trim`` holds ``delta_rad`` and ``offtracking_m``, present with a
        residual source), and ``reasons``: {key: why it is null} for every null."""
        from .registry import MEASURES
        doc, reasons = {}, {}
        for key in MEASURES:
            if key.startswith("trim."):
                if self.trim is None and "trim" not in self.undefined:
                    continue                         # no residual source: no trim (SPEC 8)
                doc["trim"] = None if self.trim is None else {"delta_rad": self.trim.delta_rad,
                                                              "offtracking_m": self.trim.offtracking_m}
                if self.trim is None:
                    reasons["trim"] = self.reason(key)
                continue
            doc[key] = self.value(key)
            if doc[key] is None:
                reasons[key] = self.reason(key)
        doc["reasons"] = reasons
        return doc

    def rows(self) -> list[dict]:
        """The measures as table rows: name, value, unit, definition (or why it is null), and
        the key of the same number in :meth:`to_dict` (``ay_gain_per_unit[0]`` for list items)."""
        from .registry import MEASURES
        f = f"{self.f_hz:g} Hz"
        rows = []
        for key, m in MEASURES.items():
            value = self.value(key)
            if key == "speed_mps":
                rows.append({"measure": m.label, "value": value, "unit": m.unit,
                             "note": f"{mps_to_kph(self.speed_mps):.1f} km/h", "json_key": key})
            elif m.shape == "per_unit":
                if value is None:
                    rows.append({"measure": m.label + "s", "value": "none", "unit": m.unit,
                                 "note": self.reason(key), "json_key": key})
                for k, (name, g) in enumerate(zip(self.vehicle.unit_names, value or ())):
                    rows.append({"measure": f"{m.label}, {name}", "value": g, "unit": m.unit,
                                 "note": f"|G_{k + 1}(j2π·{f})|", "json_key": f"{key}[{k}]"})
            elif key.startswith("trim."):
                if self.trim is not None:
                    what = "; ".join(x for x in (f"1 % rule on {', '.join(self.load_units)}" if self.load_units
                                                 else "", self.sources.describe() if self.sources else "") if x)
                    rows.append({"measure": m.label, "value": value, "unit": m.unit,
                                 "note": what if key == "trim.delta_rad" else m.definition, "json_key": key})
                elif "trim" in self.undefined and key == "trim.delta_rad":
                    rows.append({"measure": "trim", "value": "none", "unit": "", "note": self.undefined["trim"],
                                 "json_key": "trim"})
            else:
                note = m.definition if value is not None else self.reason(key)
                if key in ("ra_frequency", "ra_single_sine"):
                    note = note.replace("0.4 Hz", f)
                rows.append({"measure": m.label.replace("0.4 Hz", f), "value": "none" if value is None else value,
                             "unit": m.unit, "note": note, "json_key": key})
        return rows


def measure_set(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0, load_units=None,
                f_hz: float = RA_FREQUENCY_HZ, sources=None) -> MeasureSet:
    """Every measure of the registry (SPEC sections 8, 12, 16) of ``vehicle`` at ``speed_mps`` [m/s].

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
    tire_scale : float
    load_units : list of str, optional
        Units carrying the 1 % rule (P along +y, T about +z) for the trim.
    f_hz : float
        Frequency of the RA measures and gains [Hz].
    sources : lcvreport.model.yaw_plane.loads.ResidualSources, optional
        Further residual sources for the trim (per-axle P and T, misalignment, crossfall);
        with ``load_units`` the 1 % rule adds to them.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> m = measure_set(load_preset("tractor_semitrailer"), 24.4444)
    >>> sorted(m.to_dict())[:4]
    ['ay_gain_per_unit', 'critical_speed_kph', 'frontal_swing_m', 'hsso_m']
    """
    from ..analysis.exact import ManoeuvreError
    from .amplification import ra_peak
    from .offtracking import lane_change_measures, steady_turn
    from .yaw_damping import _yaw_damping
    zeta, f_zeta = least_damping(vehicle, speed_mps, tire_scale)
    units = tuple(load_units) if load_units else ()
    has_sources = bool(units) or bool(sources)
    low, low_why = low_speed_measures(vehicle)
    undefined = dict(low_why)
    common = dict(vehicle=vehicle, speed_mps=float(speed_mps), tire_scale=float(tire_scale),
                  least_damping_ratio=zeta, least_damped_frequency_hz=f_zeta,
                  critical_speed_kph=critical_speed(vehicle, tire_scale), load_units=units, f_hz=float(f_hz),
                  sources=sources, **low)
    if not vehicle.steered_axles:
        from .registry import MEASURES
        why = "undefined: the vehicle has no steered axle, so no steer input to respond to or trim with"
        undefined.update({k: why for k, m in MEASURES.items() if m.needs == "steer"})
        if has_sources:
            undefined["trim"] = why
        return MeasureSet(undefined=undefined, **common)
    gains = np.abs(steer_to_acceleration(vehicle, speed_mps, f_hz, tire_scale))
    # only the numbers are kept: each manoeuvre's response (up to a megabyte of samples) is freed
    # before the next one is computed (a smaller heap, which malloc does not hand back and fault in)
    ra_ss = single_sine(vehicle, speed_mps, f_hz, tire_scale=tire_scale).rearward_amplification
    tr = None
    if has_sources:
        F = np.zeros(vehicle.n_states)
        if units:
            F = F + load_vector(vehicle, one_percent_rule(vehicle, list(units)))
        if sources:
            F = F + sources.vector(vehicle, tire_scale)
        tr = trim(vehicle, speed_mps, F, tire_scale)
        check_trim(tr)
    peak = ra_peak(vehicle, speed_mps, tire_scale)
    ydc = _yaw_damping(vehicle, speed_mps, tire_scale, zeta)
    ydc_value, ydc_bound = ydc.value, ydc.lower_bound
    if ydc_value is None:
        undefined["yaw_damping_coefficient"] = f"undefined: {ydc.why}"
    del ydc
    try:
        lc = lane_change_measures(vehicle, speed_mps, tire_scale)
        hsto, ra_lc = lc.hsto_m, lc.ra_lane_change
        del lc
    except ManoeuvreError as exc:
        hsto = ra_lc = None
        undefined["hsto_m"] = undefined["ra_lane_change"] = f"undefined: {exc}"
    turn = steady_turn(vehicle, speed_mps, tire_scale)
    return MeasureSet(ra_frequency=float(gains[-1] / gains[0]), ra_single_sine=ra_ss,
                      ay_gain_per_unit=[float(g) for g in gains], trim=tr, undefined=undefined,
                      ra_peak=peak.value, ra_peak_frequency_hz=peak.frequency_hz,
                      yaw_damping_coefficient=ydc_value, yaw_damping_lower_bound=ydc_bound, hsto_m=hsto,
                      ra_lane_change=ra_lc, hsso_m=turn.hsso_m, steady_turn_delta_rad=turn.delta_rad, **common)
