"""Studies on the roll keys (docs/roll.md, docs/studies.md): scale factors on CG heights and roll
stiffnesses, the roll measures case by case, each row equal to the measure set of its case."""
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
            assert getattr(row, key) == m.value(key), key
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
