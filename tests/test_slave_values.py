"""The Python FMUs' slave answers GetReal from what the last step gave (lcvreport/fmu/slave_core.py):
the fast path of a repeated request is the general path's answer, whatever sequence type the vrs
come in, and an input set after the step is seen at once by the outputs that feed it through."""
from __future__ import annotations

import json

import numpy as np

from lcvreport.fmu.interface import preset_interface
from lcvreport.fmu.slave_fmi2 import LCV


def _slave(tmp_path):
    (tmp_path / "lcv_fmu.json").write_text(json.dumps({"mode": "presets"}))
    s = LCV(instance_name="x", resources=str(tmp_path))
    s.exit_initialization_mode()
    return s


def test_a_repeated_request_is_answered_as_the_first(tmp_path):
    s = _slave(tmp_path)
    itf = preset_interface()
    outs = [v.value_reference for v in itf.outputs]
    some = outs[3:9] + [itf.by_name["u"].value_reference, itf.by_name["tire_scale"].value_reference]
    s.set_real([itf.by_name["delta"].value_reference], [0.01])
    for _ in range(3):
        s.do_step(0.0, 0.05)
        for vrs in (outs, some, outs[::-1]):
            first = s.get_real(list(vrs))
            assert s.get_real(list(vrs)) == first                   # the fast path
            assert s.get_real(np.array(vrs)) == first               # an array: the general path
            assert s.get_real(tuple(vrs)) == first
    assert np.any(np.array(s.get_real(outs)) != 0.0)


def test_an_input_set_after_the_step_reaches_the_feedthrough_outputs(tmp_path):
    s = _slave(tmp_path)
    itf = preset_interface()
    outs = [v.value_reference for v in itf.outputs]
    ay1 = [v.name for v in itf.outputs].index("ay1")
    s.do_step(0.0, 0.05)
    before = s.get_real(outs)
    s.get_real(outs)                                               # the request is remembered
    s.set_real([itf.by_name["delta"].value_reference], [0.02])
    after = s.get_real(outs)
    assert after[ay1] != before[ay1]                               # ay feels the steer at once
    states = [k for k, v in enumerate(itf.outputs) if v.source[0] == "state"]
    assert [after[k] for k in states] == [before[k] for k in states]   # the state did not move
    assert s.get_real(outs) == after
