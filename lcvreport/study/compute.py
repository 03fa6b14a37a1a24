"""The measures of a chunk of a study's cases: batched over the cases where the measure has a
batched form (:mod:`lcvreport.analysis.batch`; the roll measures on a batch of the cases' own
vehicles, their yaw-roll coefficients built exactly), case by case with :func:`measure_set` otherwise.

The cases of a chunk are grouped by speed and tire scale (the batch runs at one of each); a
group is one :class:`~lcvreport.analysis.batch.VariantBatch`.  Undefined measures are NaN (the
JSON's null).  Same numbers as ``lcv measures`` of each case (tests/test_study.py: 1e-12
relative), the same numbers whichever process computes a chunk.

Examples
--------
>>> from lcvreport.study.spec import study_from_dict
>>> s = study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m"],
...     "factors": {"trailer1.mass_scale": {"values": [0.8, 1.2]}}})
>>> cols = compute_chunk(s, [0, 1])
>>> list(cols), cols["hsso_m"].shape
(['case_id', 'trailer1.mass_scale', 'hsso_m'], (2,))
"""
from __future__ import annotations

import numpy as np

from ..analysis.batch import VariantBatch
from ..analysis.frequency import RA_FREQUENCY_HZ
from ..measures.registry import BATCHED as BATCH_GROUPS
from ..measures.friction_demand import prefetch_cases
from ..measures.registry import FAMILIES, MeasureCase
from ..model.linear import linear_model
from ..model.yaw_roll.parameters import missing_roll_data
from .spec import BATCHED, ROLL_PARAMETERS, Study

#: the cases computed side by side where a measure's manoeuvre is integrated (the turn with tire
#: forces: :func:`~lcvreport.measures.friction_demand.turns_with_tire_forces`)
BLOCK = 128


def compute_chunk(study: Study, case_ids) -> dict:
    """Columns of the cases ``case_ids``: ``case_id``, every factor, every measure (float64,
    NaN where undefined), in that order."""
    ids = np.asarray(case_ids, dtype=np.int64)
    table = study.factor_table(ids)
    speeds = study.speeds_mps(table) if table else np.full(ids.size, np.nan)
    scales = np.asarray(table.get("tire_scale", np.ones(ids.size)), dtype=float)
    params = study.batch_parameters(table)                  # the scale factors alone: case vehicles start here
    folded = study.batch_parameters(table, payloads=True)   # with the payloads: what the yaw-plane batch takes
    cols = {"case_id": ids}
    cols.update({name: (arr if name == "load_units" else np.asarray(arr, dtype=float)) for name, arr in table.items()})
    for m in study.measures:
        cols[m] = np.full(ids.size, np.nan)
    v = study.vehicle
    # a batch holds one geometry: a payload off its unit's CG moves the CG, so case by case
    batched = set(study.measures) & set(BATCHED) if v.steered_axles and not study.moves_geometry else set()
    if missing_roll_data(v) is not None:          # null case by case, with the missing key named
        batched -= {k for g, keys in BATCH_GROUPS.items() if FAMILIES[g].model == "yaw_roll" for k in keys}
    groups = [g for g, keys in BATCH_GROUPS.items() if batched & set(keys)]
    F = None
    if "trim" in groups:
        F = np.full((ids.size, linear_model(v).n_states), np.nan)           # NaN rows: no source (measure_set's null)
        for k in range(ids.size):
            F[k] = _case_force(study, int(ids[k]))
    if batched:
        keys = np.stack([speeds, scales], axis=1)
        uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
        for g, (u, ts) in enumerate(uniq):
            rows = np.flatnonzero(inverse.ravel() == g)
            values = {k: arr[rows] for k, arr in folded.items()        # the yaw plane reads no roll key
                      if k.split(".", 1)[1] not in ROLL_PARAMETERS}
            batches = {"yaw_plane": VariantBatch(v, values)}
            for group in groups:
                model = FAMILIES[group].model
                if model not in batches:              # every case's own vehicle, its coefficients exact
                    batches[model] = VariantBatch.of_vehicles(
                        v, [study.case_vehicle(params, int(k), table) for k in rows], model)
                case = MeasureCase(v, float(u), float(ts), RA_FREQUENCY_HZ, None if F is None else F[rows])
                arrays = FAMILIES[group].compute_batched(batches[model], case)
                for name, arr in arrays.items():
                    if name in batched:
                        cols[name][rows] = np.broadcast_to(arr, rows.shape)
    made: dict = {}                       # each case's Case made once (its vehicle: 5 ms)

    def case_object(case_id: int):
        if case_id not in made:
            made[case_id] = study.case_object(case_id)
        return made[case_id]

    if study.scheme_toml is not None:
        cols.update(scheme_columns(study, ids, case_object))
    rest = [m for m in study.measures if m not in batched]
    if rest:
        cases = []
        for k, case_id in enumerate(ids):
            if k % BLOCK == 0:             # the next block's turns with tire forces, side by side
                cases = [case_object(int(c)) for c in ids[k:k + BLOCK]]
                prefetch_cases([c.vehicle for c in cases], [c.tire_scale for c in cases], rest)
            values = cases[k % BLOCK].measure_values(rest)   # their families only
            for m in rest:
                value = values.get(m)
                cols[m][k] = np.nan if value is None else float(value)
    return cols


def scheme_columns(study: Study, ids: np.ndarray, case_object=None) -> dict:
    """The assessment of every case against the study's scheme (docs/studies.md#schemes):
    ``scheme.<key>`` each scheme measure's value at its conditions (NaN: not computed),
    ``level.<key>`` the level it reaches and ``level_reached`` the case's ("" for none), each
    case as :meth:`~lcvreport.measures.case.Case.assess` of its case (one case at a time);
    ``case_object(case_id)`` makes a case's :class:`~lcvreport.measures.case.Case` (default
    :meth:`Study.case_object`)."""
    from ..measures.assess import scheme_groups
    case_object = case_object or study.case_object
    scheme = study.scheme
    keys = [m.key for m in scheme.measures]
    cols = {f"scheme.{k}": np.full(ids.size, np.nan) for k in keys}
    levels = {f"level.{k}": [] for k in keys}
    reached = []
    cases = []
    for k, case_id in enumerate(ids):
        if k % BLOCK == 0:                 # the next block: its turns with tire forces, its batched families
            cases = [case_object(int(c)) for c in ids[k:k + BLOCK]]
            for g in scheme_groups(scheme):
                prefetch_cases([c.vehicle for c in cases], [c.tire_scale for c in cases],
                               [r for m in g["members"] for r in (m.key, *m.references)], g["conditions"])
            pre = _batched_scheme_values(study, cases, scheme)
        a = cases[k % BLOCK].assess(scheme, pre[k % BLOCK])
        for m in a.measures:
            cols[f"scheme.{m.key}"][k] = np.nan if m.value is None else float(m.value)
            levels[f"level.{m.key}"].append(m.level_reached or "")
        reached.append(a.level_reached or "")
    cols.update({name: np.array(v, dtype=object) for name, v in levels.items()})
    cols["level_reached"] = np.array(reached, dtype=object)
    return cols


def _batched_scheme_values(study: Study, cases: list, scheme) -> list:
    """Per case, the ``precomputed`` of its assessment: the scheme's batched families over the
    cases of one tire scale without a load case or residual sources (those, and a study that
    moves the geometry, are assessed case by case)."""
    from ..measures.assess import batched_group_values
    pre: list = [None] * len(cases)
    if study.moves_geometry:
        return pre
    scales: dict = {}
    for k, c in enumerate(cases):
        if not c.load_units and c.sources is None:
            scales.setdefault(c.tire_scale, []).append(k)
    for ts, rows in scales.items():
        for k, values in zip(rows, batched_group_values(study.vehicle, [cases[k].vehicle for k in rows], scheme, ts)):
            pre[k] = values
    return pre


def _case_force(study: Study, case_id: int) -> np.ndarray:
    """The generalized force F [SI] of a case's load case and residual sources, as measure_set
    builds it for the trim (with the case's own masses and tire coefficients); NaN if none."""
    from ..model.yaw_plane.loads import load_vector, one_percent_rule
    vehicle, _speed, kwargs = study.case(case_id)
    units, sources = kwargs.get("load_units"), kwargs.get("sources")
    if not units and not sources:
        return np.full(linear_model(vehicle).n_states, np.nan)
    F = np.zeros(linear_model(vehicle).n_states)
    if units:
        F = F + load_vector(vehicle, one_percent_rule(vehicle, list(units)))
    if sources:
        F = F + sources.vector(vehicle, kwargs.get("tire_scale", 1.0))
    return F
