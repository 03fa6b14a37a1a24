"""The assessment report of one vehicle at one speed: what its notebook shows.

Rows of its tables and its figures, each computed by :mod:`lcvreport.analysis` and
drawn by :mod:`lcvreport.plotting.vehicle`; the notebook ``notebooks/assessment.ipynb``
only lays them out with captions that name the vehicle and the speed.

Examples
--------
>>> a = Assessment.load(preset="tractor_semitrailer", speed_kph=88.0, fast=True)
>>> a.at
'tractor_semitrailer at 88 km/h'
"""
from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..analysis.frequency import RA_FREQUENCY_HZ, steer_to_acceleration
from ..analysis.modes import Modes, modes
from ..analysis.steady import trim
from ..fmu.interface import vehicle_interface
from ..measures.amplification import SingleSine, single_sine
from ..measures.measure_set import MeasureSet, measure_set
from ..measures.stability import SpeedSweep, speed_sweep
from ..model.body import body_extent, unit_poses
from ..model.linear import linear_model
from ..model.presets import load_preset
from ..model.vehicle import Vehicle
from ..model.vehicle_file import load_vehicle
from ..plotting.charts import fig_bars
from ..plotting.frequency import fig_damping_over_speed, fig_frequency, fig_root_locus
from ..plotting.time import fig_lane_change, fig_pulse
from ..plotting.vehicle import fig_mode_shape, fig_vehicle
from ..tracking.tires import AxleSensitivity, conicity_sensitivity
from ..units import kph_to_mps, mps_to_kph

#: speed range of the root locus and of the damping curve [km/h] (docs/reports.md)
SWEEP_KPH = (10.0, 130.0)
#: frequency range of the RA curves [Hz]
RA_CURVE_HZ = (0.1, 2.0)


@dataclass
class Assessment:
    """One vehicle at one speed, with the loads of the trim (optional)."""

    vehicle: Vehicle
    speed_kph: float
    load_units: tuple[str, ...] = ()
    fast: bool = False
    source: str = ""
    _cache: dict = field(default_factory=dict, repr=False)
    sources: object = None          # ResidualSources beyond the 1 % rule (docs/manoeuvres.md)
    criteria: object = None         # Criteria to judge the measures by
    tracking: dict | None = None    # {"tires": mounted tires or None, "stats": a tracking-statistics spec or None}

    @classmethod
    def load(cls, preset: str | None = None, vehicle_file: str | None = None, speed_kph: float = 88.0,
             load_units=None, fast: bool = False, source: str | None = None, residuals: dict | None = None,
             criteria_file: str | None = None, tracking: dict | None = None) -> "Assessment":
        """From a preset name or a vehicle file; ``source`` names it for captions (default:
        the preset or the file's path); ``residuals`` (``P_N``, ``T_Nm``,
        ``misalignment_rad`` by axle, ``crossfall_percent``) and a criteria file optional."""
        from ..measures.criteria import load_criteria
        from ..model.yaw_plane.loads import ResidualLoads, ResidualSources
        vehicle = load_preset(preset) if preset is not None else load_vehicle(vehicle_file)
        res = residuals or {}
        sources = ResidualSources(ResidualLoads(dict(res.get("P_N", {})), dict(res.get("T_Nm", {}))),
                                  dict(res.get("misalignment_rad", {})), float(res.get("crossfall_percent", 0.0)))
        return cls(vehicle, float(speed_kph), tuple(load_units or ()), fast,
                   source or (f"preset {preset}" if preset is not None else str(vehicle_file)),
                   sources=sources if sources else None,
                   criteria=load_criteria(criteria_file) if criteria_file else None,
                   tracking=tracking if tracking and (tracking.get("tires") or tracking.get("stats")) else None)

    @property
    def speed_mps(self) -> float:
        return kph_to_mps(self.speed_kph)

    @property
    def at(self) -> str:
        """``<vehicle> at <speed> km/h`` for captions."""
        return f"{self.vehicle.name} at {self.speed_kph:g} km/h"

    # ------------------------------------------------------------------ data
    def fig_vehicle(self):
        fig = fig_vehicle(self.vehicle, f"{self.vehicle.name}: {self.vehicle.n_units} units")
        poses = unit_poses(self.vehicle)
        rows = []
        for k, ((cg, _psi), u) in enumerate(zip(poses, self.vehicle.units)):
            front, rear, half = body_extent(self.vehicle, k)
            rows.append({"unit": u.name, "item": "CG", "x_m": cg[0], "half_width_m": ""})
            rows.append({"unit": u.name, "item": "drawn body front", "x_m": cg[0] + front, "half_width_m": half})
            rows.append({"unit": u.name, "item": "drawn body rear", "x_m": cg[0] + rear, "half_width_m": half})
            for name, x in (("front coupling", u.front_coupling_m), ("rear coupling", u.rear_coupling_m)):
                if x is not None:
                    rows.append({"unit": u.name, "item": name, "x_m": cg[0] + x, "half_width_m": ""})
            for a in u.axles:
                rows.append({"unit": u.name, "item": f"axle {a.name}", "x_m": cg[0] + a.x_m, "half_width_m": ""})
        fig.lcv_data = rows      # x from the first unit's CG, straight running
        return fig

    def unit_rows(self) -> list[dict]:
        """Units: mass, inertia, couplings, rear end (SI)."""
        v = self.vehicle
        return [{"unit": k + 1, "name": u.name, "mass_kg": u.mass_kg, "yaw_inertia_kg_m2": u.yaw_inertia_kg_m2,
                 "front_coupling_m": "" if u.front_coupling_m is None else u.front_coupling_m,
                 "rear_coupling_m": "" if u.rear_coupling_m is None else u.rear_coupling_m,
                 "rear_end_m": v.rear_end_x_m(k), "axles": len(u.axles)} for k, u in enumerate(v.units)]

    def axle_rows(self) -> list[dict]:
        """Axles: position, tires, per-tire coefficients, dual spacing, steer, load (SI)."""
        return [{"axle": a.name, "unit": self.vehicle.units[i].name, "x_m": a.x_m, "tires": a.tires,
                 "C_F_N_per_rad": a.cornering_stiffness_N_per_rad, "C_M_Nm_per_rad": a.aligning_stiffness_Nm_per_rad,
                 "C_S_N": a.longitudinal_stiffness_N, "D_m": a.dual_spacing_m, "steered": a.steered,
                 "static_load_N": "" if a.static_load_N is None else a.static_load_N}
                for i, a in zip(self.vehicle.axle_units, self.vehicle.axles)]

    # ------------------------------------------------------------------ modes
    @cached_property
    def modes(self) -> Modes:
        return modes(self.vehicle, self.speed_mps)

    def mode_rows(self) -> list[dict]:
        """Eigenvalues [1/s], damped frequency [Hz], damping ratio, time constant [s]; * marks the least damped."""
        k = self.modes.least_damped
        return [{**row, "time_constant_s": float(tc), "least_damped": "*" if k is not None and i in (k, k + 1) else ""}
                for i, (row, tc) in enumerate(zip(self.modes.table(), self.modes.time_constant))]

    def least_damped_modes(self, count: int = 2) -> list[int]:
        """Indices of the ``count`` least damped oscillatory modes (+Im members)."""
        m = self.modes
        idx = np.flatnonzero(m.eigenvalues.imag > 0)
        return [int(i) for i in idx[np.argsort(m.damping_ratio[idx])][:count]]

    def fig_mode(self, index: int):
        fig = fig_mode_shape(self.vehicle, self.modes, index, f"Mode {index + 1}")
        lam = self.modes.eigenvalues[index]
        fig.lcv_data = [{"state": name, "eigenvalue_real_per_s": lam.real, "eigenvalue_imag_per_s": lam.imag,
                         "shape_real": x.real, "shape_imag": x.imag, "shape_magnitude": abs(x),
                         "shape_phase_deg": float(np.degrees(np.angle(x)))}
                        for name, x in zip(self.modes.state_names, self.modes.shapes[:, index])]
        return fig

    # ------------------------------------------------------------------ stability over speed
    @cached_property
    def sweep(self) -> SpeedSweep:
        lo, hi = SWEEP_KPH
        return speed_sweep(self.vehicle, np.linspace(lo, hi, 25 if self.fast else 121))

    def fig_root_locus(self):
        fig = fig_root_locus(self.sweep.speeds_kph, self.sweep.eigenvalues,
                                      f"Root locus of {self.vehicle.name}, {SWEEP_KPH[0]:g}-{SWEEP_KPH[1]:g} km/h",
                                      self.sweep.critical_speed_kph)
        fig.lcv_data = [{"speed_kph": v, "mode": j + 1, "real_per_s": lam.real, "imag_per_s": lam.imag}
                        for v, row in zip(self.sweep.speeds_kph, self.sweep.eigenvalues)
                        for j, lam in enumerate(row)]
        return fig

    def fig_damping(self):
        fig = fig_damping_over_speed(self.sweep.speeds_kph, self.sweep.least_damping_ratio,
                                              self.sweep.max_real, self.vehicle.name, self.sweep.critical_speed_kph,
                                              self.speed_kph)
        fig.lcv_data = [{"speed_kph": v, "least_damping_ratio": z, "max_real_per_s": m}
                        for v, z, m in zip(self.sweep.speeds_kph, self.sweep.least_damping_ratio,
                                           self.sweep.max_real)]
        return fig

    # ------------------------------------------------------------------ rearward amplification
    @cached_property
    def frequencies_hz(self) -> np.ndarray:
        return np.linspace(*RA_CURVE_HZ, 40 if self.fast else 191)

    def fig_ra(self):
        f = self.frequencies_hz
        G = np.abs(steer_to_acceleration(self.vehicle, self.speed_mps, f))
        curves = [(f"RA = |G_{self.vehicle.n_units}| / |G_1|", G[:, -1] / G[:, 0])]
        m = self.measures
        fig = fig_frequency(f, curves, "rearward amplification [-]",
                                     f"Rearward amplification of {self.at}", RA_FREQUENCY_HZ,
                                     peak=(m.ra_peak_frequency_hz, m.ra_peak))
        fig.lcv_data = [{"frequency_hz": fi, "rearward_amplification": ra} for fi, ra in zip(f, G[:, -1] / G[:, 0])]
        return fig

    def fig_gains(self):
        f = self.frequencies_hz
        G = np.abs(steer_to_acceleration(self.vehicle, self.speed_mps, f))
        curves = [(f"|G_{i + 1}| {name}", G[:, i]) for i, name in enumerate(self.vehicle.unit_names)]
        fig = fig_frequency(f, curves, "lateral acceleration per steer angle [m/s²/rad]",
                                     f"Steer-to-lateral-acceleration gains of {self.at}", RA_FREQUENCY_HZ,
                                     logy=True)
        fig.lcv_data = [{"frequency_hz": fi, **{f"gain_{name}_m_per_s2_per_rad": g for name, g in
                                                zip(self.vehicle.unit_names, row)}} for fi, row in zip(f, G)]
        return fig

    def fig_single_sine(self):
        ss = self.single_sine
        fig = ss.plot()
        fig.lcv_data = [{"time_s": t, "steer_angle_rad": d, **{f"ay_{name}_m_per_s2": a for name, a in
                                                                zip(self.vehicle.unit_names, row)}}
                        for t, d, row in zip(ss.time, ss.delta, ss.ay)]
        return fig

    @cached_property
    def single_sine(self) -> SingleSine:
        return single_sine(self.vehicle, self.speed_mps)

    # ------------------------------------------------------------------ measures and conicity
    @cached_property
    def measures(self) -> MeasureSet:
        return measure_set(self.vehicle, self.speed_mps, load_units=list(self.load_units) or None,
                                    sources=self.sources)

    # ------------------------------------------------------------------ manoeuvres (docs/manoeuvres.md, docs/measures.md)
    @cached_property
    def lane_change(self):
        from ..measures.offtracking import lane_change_measures
        return lane_change_measures(self.vehicle, self.speed_mps)

    def fig_lane_change(self):
        lc = self.lane_change
        fig = fig_lane_change(lc, f"Lane change 0.15 g at 0.4 Hz of {self.at}")
        r = lc.response
        fig.lcv_data = [{"time_s": t, "steer_angle_rad": d, f"Y_{lc.steered_axle}_m": a, f"Y_{lc.rear_axle}_m": b,
                         "a_steer_m_per_s2": c, f"ay{self.vehicle.n_units}_m_per_s2": e}
                        for t, d, a, b, c, e in zip(r.time, r["delta"], r[f"Y_{lc.steered_axle}"],
                                                    r[f"Y_{lc.rear_axle}"], r["a_steer"],
                                                    r[f"ay{self.vehicle.n_units}"])]
        return fig

    @cached_property
    def yaw_damping(self):
        from ..measures.yaw_damping import yaw_damping_coefficient
        return yaw_damping_coefficient(self.vehicle, self.speed_mps)

    def fig_pulse(self):
        names = list(linear_model(self.vehicle).state_names[self.vehicle.n_units + 1:])
        y = self.yaw_damping
        fig = fig_pulse(y, names, f"Pulse steer 0.01 rad, 0.5 s: articulation of {self.at} (dots: the "
                                           "extrema the ratio method uses)")
        rows = []
        for name, (t, v), zeta in zip(names, y.extrema, y.per_joint):
            for ti, vi in zip(t, v):
                rows.append({"joint": name, "time_s": ti, "extremum_rad": vi,
                             "joint_ratio_damping": "" if zeta is None else zeta})
        fig.lcv_data = rows
        return fig

    @cached_property
    def steady_turn(self):
        from ..measures.offtracking import steady_turn
        return steady_turn(self.vehicle, self.speed_mps)

    def turn_rows(self) -> list[dict]:
        """Path radius of every axle in the 393 m turn, relative to the steered axle's."""
        t = self.steady_turn
        ref = t.path_radius_m[max(self.vehicle.steered_axles, key=lambda a: a.x_m).name]
        return [{"axle": a.name, "unit": self.vehicle.units[i].name, "path_radius_m": t.path_radius_m[a.name],
                 "outside_the_steered_axle_m": t.path_radius_m[a.name] - ref}
                for i, a in zip(self.vehicle.axle_units, self.vehicle.axles)]

    def verdict_rows(self) -> list[dict]:
        from ..measures.criteria import judge
        doc = self.measures.to_dict()
        return [{"measure": k, "value": "" if v["value"] is None else v["value"], "limit": v["limit"],
                 "verdict": v["verdict"], "source": v["source"]} for k, v in judge(self.criteria, doc).items()]

    @cached_property
    def sensitivity(self) -> list[AxleSensitivity]:
        return conicity_sensitivity(self.vehicle, self.speed_mps)

    def sensitivity_rows(self) -> list[dict]:
        return [{"rank": k + 1, "axle": s.axle, "unit": s.unit,
                 "offtracking_per_kN_of_P_mm": 1e3 * s.offtracking_per_P_m_per_kN,
                 "offtracking_per_kNm_of_T_mm": 1e3 * s.offtracking_per_T_m_per_kNm,
                 "trim_steer_per_kN_of_P_mrad": 1e3 * s.delta_per_P_rad_per_kN,
                 "trim_steer_per_kNm_of_T_mrad": 1e3 * s.delta_per_T_rad_per_kNm}
                for k, s in enumerate(self.sensitivity)]

    def fig_sensitivity(self):
        rows = self.sensitivity
        fig = fig_bars([f"{s.axle} ({s.unit})" for s in rows],
                                 [("per kN of P", np.array([1e3 * s.offtracking_per_P_m_per_kN for s in rows])),
                                  ("per kN·m of T", np.array([1e3 * s.offtracking_per_T_m_per_kNm for s in rows]))],
                                 "trimmed offtracking [mm]", f"Conicity sensitivity of {self.at}, ranked",
                                height=1.2 + 0.32 * len(rows), horizontal=True)
        fig.lcv_data = self.sensitivity_rows()
        return fig

    # ------------------------------------------------------------------ low-speed turn (docs/low_speed_turn.md)
    @cached_property
    def low_speed_turn(self):
        """:class:`lcvreport.measures.low_speed.LowSpeedTurn`, or the reason it is not computed (str)."""
        from ..measures.low_speed import low_speed_turn
        from ..model.body import TurnError
        try:
            return low_speed_turn(self.vehicle)
        except TurnError as exc:
            return str(exc)

    def low_speed_rows(self) -> list[dict]:
        return self.low_speed_turn.rows()

    def fig_swept_path(self):
        return self.low_speed_turn.plot(f"{self.vehicle.name}: low-speed 90° turn, outside steer wheel on R = 12.5 m")

    # ------------------------------------------------------------------ roll (docs/roll.md)
    @cached_property
    def roll(self):
        """:class:`lcvreport.measures.roll.RollSummary` at the report's speed, or why it is not
        computed (str: the missing roll key)."""
        from ..measures.roll import roll_summary
        from ..model.vehicle import VehicleError
        try:
            return roll_summary(self.vehicle, self.speed_mps)
        except VehicleError as exc:
            return f"no roll data: {exc}"

    def roll_threshold_rows(self) -> list[dict]:
        """Per roll-coupled group: its units, SRT [g] and every axle's lift-off [g]."""
        rows = []
        for k, g in enumerate(self.roll.threshold.groups, 1):
            lifts = ", ".join(f"{axle} {at:.3f}" if at is not None else f"{axle} none"
                              for axle, at in g.lift_off_g.items())
            rows.append({"group": k, "units": ", ".join(g.units), "SRT [g]": g.srt_g, "lift-off [g]": lifts,
                         "stable at rest": "yes" if g.stable_at_rest else "no: SRT 0"})
        return rows

    def roll_unit_rows(self) -> list[dict]:
        """Per unit: its roll gain [deg/g] and its group's LTR in the lane change and the single sine."""
        s = self.roll
        group = {u: k for k, g in enumerate(s.threshold.groups) for u in g.units}
        rows = []
        gains = s.roll_gain_deg_per_g or [None] * self.vehicle.n_units
        for name, gain in zip(self.vehicle.unit_names, gains):
            k = group[name]
            rows.append({"unit": name, "group": k + 1, "roll gain [deg/g]": gain,
                         "LTR, lane change [-]": None if s.ltr_lane_change is None else s.ltr_lane_change[k],
                         "LTR, single sine [-]": None if s.ltr_single_sine is None else s.ltr_single_sine[k]})
        return rows

    def roll_mode_rows(self, count: int = 4) -> list[dict]:
        """The ``count`` least damped oscillatory modes of the yaw-roll model at the report's speed."""
        from ..analysis.modes import eigenvalues
        ev = eigenvalues(self.vehicle, self.speed_mps, model="yaw_roll")
        osc = sorted((lam for lam in ev if lam.imag > 0), key=lambda lam: -lam.real / abs(lam))
        return [{"mode": k + 1, "real part [1/s]": lam.real, "frequency [Hz]": lam.imag / (2 * np.pi),
                 "damping ratio [-]": -lam.real / abs(lam)} for k, lam in enumerate(osc[:count])]

    def fig_rollover(self):
        return self.roll.plot()

    def fig_ltr_lane_change(self):
        from ..measures.offtracking import lane_change_measures
        from ..plotting.roll import plot_ltr
        r = lane_change_measures(self.vehicle, self.speed_mps, model="yaw_roll").response
        return plot_ltr(r, len(self.roll.threshold.groups), f"{self.vehicle.name}: load transfer ratio per "
                        f"roll-coupled group, lane change 0.15 g 0.4 Hz at {mps_to_kph(self.speed_mps):.0f} km/h")

    # ------------------------------------------------------------------ straight-line tracking (docs/tracking.md)
    def _tire_force(self) -> np.ndarray:
        """The generalized force of the mounted tires alone (SI)."""
        from ..model.yaw_plane.loads import ResidualSources
        from ..tracking.tires import axle_residuals
        return ResidualSources(axle_residuals(self.vehicle, self.tracking["tires"])).vector(self.vehicle)

    def _other_force(self) -> np.ndarray | None:
        """Every residual source but the mounted tires (SI), or None."""
        if self.sources is None:
            return None
        F = self.sources.vector(self.vehicle)
        if self.tracking and self.tracking.get("tires"):
            F = F - self._tire_force()
        return F

    @cached_property
    def tracking_stats(self):
        """:class:`lcvreport.tracking.statistics.TrackingStats` of the report's specification, or None."""
        from ..tracking.statistics import stats_from_spec
        if not self.tracking or not self.tracking.get("stats") or not self.vehicle.steered_axles:
            return None
        spec = dict(self.tracking["stats"])
        if self.fast:
            spec.setdefault("draws", 20_000)
        return stats_from_spec(self.vehicle, self.speed_mps, spec, self._other_force())

    def tracking_stats_rows(self) -> list[dict]:
        s = self.tracking_stats
        spec = self.tracking["stats"]
        lo, hi = s.exceedance_ci95
        rows = [{"quantity": "population (per tire)", "value": ", ".join(f"{k} {spec[k]}" for k in
                 ("conicity", "ply_steer", "conicity_moment", "ply_steer_moment") if k in spec) +
                 f"; mounting {spec['mounting']}", "unit": "N, N·m", "how": "given"},
                {"quantity": "trimmed offtracking, mean", "value": f"{s.offtracking_mean_m:.6g}", "unit": "m",
                 "how": "exact"},
                {"quantity": "trimmed offtracking, standard deviation", "value": f"{s.offtracking_sd_m:.6g}",
                 "unit": "m", "how": "exact"},
                {"quantity": "trim steer, mean", "value": f"{s.trim_delta_mean_rad:.6g}", "unit": "rad", "how": "exact"},
                {"quantity": "trim steer, standard deviation", "value": f"{s.trim_delta_sd_rad:.6g}", "unit": "rad",
                 "how": "exact"}]
        rows += [{"quantity": f"offtracking, {100 * q:g} % quantile", "value": f"{val:.6g}", "unit": "m",
                  "how": f"Monte Carlo, {s.draws} draws, seed {s.seed}"} for q, val in s.quantiles_m.items()]
        rows.append({"quantity": f"P(|offtracking| > margin {s.margin_m:.4g} m)",
                     "value": f"{s.exceedance_probability:.6g} (95 % CI {lo:.3g} .. {hi:.3g})", "unit": "-",
                     "how": f"Monte Carlo, {s.draws} draws, seed {s.seed}"})
        return rows

    def fig_tracking_histogram(self):
        fig = self.tracking_stats.plot(f"Trimmed offtracking of {self.at} over the tire population")
        s = self.tracking_stats
        edges = np.quantile(s.samples_m, np.linspace(0, 1, 101))
        fig.lcv_data = [{"percentile": k, "offtracking_m": float(e)} for k, e in enumerate(edges)]
        return fig

    def mounted_tire_rows(self) -> list[dict]:
        """The mounted tires and their axles' P and T (SI)."""
        from ..tracking.tires import axle_residuals
        tires = self.tracking["tires"]
        loads = axle_residuals(self.vehicle, tires)
        rows = [{"position": t["position"], "tire": t.get("id", ""), "serial_side": t["serial_side"],
                 "conicity_N": t.get("conicity_N", 0.0), "ply_steer_N": t.get("ply_steer_N", 0.0),
                 "conicity_moment_Nm": t.get("conicity_moment_Nm", 0.0),
                 "ply_steer_moment_Nm": t.get("ply_steer_moment_Nm", 0.0), "axle_P_N": "", "axle_T_Nm": ""}
                for t in tires]
        rows += [{"position": f"axle {a}", "tire": "", "serial_side": "", "conicity_N": "", "ply_steer_N": "",
                  "conicity_moment_Nm": "", "ply_steer_moment_Nm": "", "axle_P_N": loads.P_N[a],
                  "axle_T_Nm": loads.T_Nm.get(a, 0.0)} for a in loads.P_N]
        return rows

    @cached_property
    def placement(self):
        """The mounting plan of the mounted tires over their own positions
        (:func:`lcvreport.tracking.placement.place_tires`), or None."""
        from ..tracking.placement import place_tires
        if not self.tracking or not self.tracking.get("tires") or not self.vehicle.steered_axles:
            return None
        tires = self.tracking["tires"]
        measured = [{"id": t.get("id") or t["position"], **{k: t[k] for k in ("conicity_N", "ply_steer_N",
                    "conicity_moment_Nm", "ply_steer_moment_Nm") if k in t}} for t in tires]
        return place_tires(self.vehicle, self.speed_mps, measured, [t["position"] for t in tires],
                           self._other_force(), draws=2_000 if self.fast else 10_000)

    def placement_rows(self) -> list[dict]:
        by_pos = {t["position"]: t for t in self.tracking["tires"]}
        return [{"position": r["position"], "tire": r["tire"], "serial_side": r["serial_side"],
                 "was": f"{by_pos[r['position']].get('id') or r['position']} "
                        f"{by_pos[r['position']]['serial_side']}"} for r in self.placement.plan]

    def tracking_comparison_rows(self) -> list[dict]:
        """Offtracking of the tires as mounted, as planned and over random placements, against the margin."""
        from ..tracking.statistics import BODY_WIDTH_M, LANE_WIDTH_M
        spec = (self.tracking or {}).get("stats") or {}
        margin = 0.5 * (float(spec.get("lane_width_m", LANE_WIDTH_M)) - float(spec.get("body_width_m", BODY_WIDTH_M)))
        pl = self.placement
        F_other = self._other_force()
        as_mounted = trim(self.vehicle, self.speed_mps, self._tire_force() +
                                   (0 if F_other is None else F_other))
        r = pl.to_dict()["random_placements"]
        return [{"tires": "as mounted (the file)", "offtracking_m": as_mounted.offtracking_m,
                 "trim_steer_rad": as_mounted.delta_rad, "share_of_margin": abs(as_mounted.offtracking_m) / margin},
                {"tires": "the plan", "offtracking_m": pl.offtracking_m, "trim_steer_rad": pl.trim_delta_rad,
                 "share_of_margin": abs(pl.offtracking_m) / margin},
                {"tires": f"random placements, mean ({r['draws']} draws, seed {r['seed']})",
                 "offtracking_m": r["mean"], "trim_steer_rad": "", "share_of_margin": abs(r["mean"]) / margin},
                {"tires": "random placements, standard deviation", "offtracking_m": r["sd"], "trim_steer_rad": "",
                 "share_of_margin": ""}]

    # ------------------------------------------------------------------ summary
    no_steer_note = ("*Not computed: the vehicle has no steered axle, so there is no steer input to respond to "
                     "(rearward amplification, gains, single sine) or to trim with (conicity sensitivity).*")

    def summary_markdown(self) -> str:
        """The first page's summary: the vehicle's description and the headline measures."""
        m = self.measures
        lines = []
        from .tables import md_text
        if self.vehicle.description:
            lines += [f"*{md_text(self.vehicle.name)}*: {md_text(self.vehicle.description)}", ""]
        lines += [f"At {self.speed_kph:g} km/h ({md_text(self.source)}):", ""]
        zeta = "no oscillatory mode" if m.least_damping_ratio is None else \
            f"{m.least_damping_ratio:.3f} at {m.least_damped_frequency_hz:.3f} Hz"
        lines.append(f"- least damping ratio: {zeta}")
        lines.append("- critical speed: " + ("none, stable up to 200 km/h" if m.critical_speed_kph is None
                                             else f"{m.critical_speed_kph:.1f} km/h"))
        if m.ra_frequency is None:
            lines.append("- rearward amplification: not computed (no steered axle)")
        else:
            lines.append(f"- rearward amplification at {m.f_hz:g} Hz: {m.ra_frequency:.3f} (frequency domain), "
                         f"{m.ra_single_sine:.3f} (single sine)")
        if m.trim is not None:
            lines.append(f"- trimmed offtracking under the 1 % rule on {md_text(', '.join(self.load_units))}: "
                         f"{1e3 * m.trim.offtracking_m:.1f} mm (trim steer {1e3 * m.trim.delta_rad:.3f} mrad)")
        return "\n".join(lines)

    # ------------------------------------------------------------------ FMU
    def interface_rows(self) -> list[dict]:
        return vehicle_interface(self.vehicle, self.speed_mps).rows()
