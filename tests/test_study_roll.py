"""Studies on the roll keys (docs/roll.md, docs/studies.md): scale factors on CG heights and roll
stiffnesses, the roll measures batched over the cases (each case's yaw-roll coefficients built
exactly), each row the measure set of its case to 1e-12 relative (as tests/test_study.py holds the
yaw-plane ones: two computations, the batch's and the case's)."""
from __future__ import annotations

import numpy as np
import pytest

from lcvreport.measures.measure_set import measure_set
from lcvreport.study.results import read_study, study_case
from lcvreport.study.run import run_study
from lcvreport.study.spec import StudyError, study_from_dict

from conftest import EXAMPLES

ROLL = {"vehicle": str(EXAMPLES / "b_double.toml"), "speed_kph": 88.0,
        "measures": ["srt_min_g", "rltr_lane_change", "roll_least_damping_ratio", "least_damping_ratio"],
        "factors": {"rear_trailer.cg_height_scale": {"values": [0.9, 1.0, 1.1]},
                    "rear_trailer.roll_stiffness_scale": {"values": [0.8, 1.25]}}}


def test_a_roll_study_gives_each_case_its_measure_set(tmp_path):
    study = study_from_dict(ROLL)
    run_study(study, tmp_path / "out", workers=1, progress=False)
    table = read_study(tmp_path / "out")
    assert len(table) == 6
    for row in table.itertuples():
        vehicle, speed, kwargs = study_case(tmp_path / "out", row.case_id)
        m = measure_set(vehicle, speed, **kwargs)
        for key in ROLL["measures"]:
            assert getattr(row, key) == pytest.approx(m.value(key), rel=1e-12, abs=0), key
    # a higher rear trailer CG lowers the threshold (same roll stiffness)
    srt = table.pivot_table(index="rear_trailer.roll_stiffness_scale", columns="rear_trailer.cg_height_scale",
                            values="srt_min_g")
    assert np.all(np.diff(srt.to_numpy(), axis=1) < 0)


def test_a_roll_factor_on_a_vehicle_without_roll_data_is_one_line():
    with pytest.raises(StudyError, match=r"factors.trailer3.cg_height_scale: trailer3 has no cg_height_m"):
        study_from_dict({"vehicle": "aucnat", "measures": ["srt_min_g"],
                         "factors": {"trailer3.cg_height_scale": {"values": [1.1]}}})


def test_a_cg_pushed_below_its_roll_axis_is_refused_before_computing():
    doc = dict(ROLL, factors={"rear_trailer.cg_height_scale": {"values": [1.0, 0.3]}})
    with pytest.raises(StudyError, match=r"case 1 puts the CG of rear_trailer at 0.615 m, not above its roll axis"):
        study_from_dict(doc)                      # checked when the study is read, before anything is computed


def test_roll_measures_batched_over_cg_heights_equal_each_variant():
    """The roll family and the threshold over variants whose CG heights differ (a parameter the
    yaw-roll model is not affine in: each variant's coefficients are built exactly), on an A-double
    with a roll-free drawbar (two roll-coupled groups: rltr is the rear one's), against
    measure_values of each variant -- the one-vehicle code path -- to 1e-12 relative."""
    from dataclasses import replace

    from lcvreport import load_vehicle
    from lcvreport.analysis.batch import VariantBatch
    from lcvreport.measures.measure_set import measure_values
    from lcvreport.measures.registry import FAMILIES
    from lcvreport.measures.roll import roll_batched, rollover_batched
    v = load_vehicle(EXAMPLES / "western_double.toml")
    variants = [replace(v, units=tuple(replace(u, cg_height_m=u.cg_height_m * s) if i >= 1 else u
                                       for i, u in enumerate(v.units))) for s in (0.9, 1.0, 1.15)]
    batch = VariantBatch.of_vehicles(v, variants, "yaw_roll")
    got = {**roll_batched(batch, 24.0), **rollover_batched(batch)}
    assert list(got) == list(FAMILIES["roll"].batched_keys + FAMILIES["rollover"].batched_keys)
    assert set(got) == {"roll_least_damping_ratio", "roll_critical_speed_kph", "ra_single_sine_roll",
                        "ra_lane_change_roll", "hsto_m_roll", "rltr_lane_change", "srt_rrcu_g", "srt_min_g"}
    for k, variant in enumerate(variants):
        ref = measure_values(variant, 24.0, list(got))
        for key, arr in got.items():
            if ref[key] is None:
                assert np.isnan(arr[k]), (k, key)
            else:
                assert arr[k] == pytest.approx(ref[key], rel=1e-12, abs=0), (k, key)
    assert np.all(np.diff(got["srt_min_g"]) < 0)                # higher CGs, lower thresholds


def test_a_batch_of_vehicles_shares_the_geometry():
    from dataclasses import replace

    from lcvreport import load_vehicle
    from lcvreport.analysis.batch import BatchError, VariantBatch
    v = load_vehicle(EXAMPLES / "b_double.toml")
    moved = replace(v, units=(replace(v.units[0], rear_coupling_m=v.units[0].rear_coupling_m - 0.1),) + v.units[1:])
    with pytest.raises(BatchError, match="variant 1 does not share the geometry of b_double"):
        VariantBatch.of_vehicles(v, [v, moved], "yaw_roll")
