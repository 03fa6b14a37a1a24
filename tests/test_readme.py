"""The README says what is true: its vehicle file loads and runs, its ranges table is the
one the code enforces, every command it shows exists.  (Its >>> examples run as doctests.)"""
from __future__ import annotations

import json
import re
import subprocess
import sys

from lcvreport.model.vehicle_file import loads_vehicle
from lcvreport.ranges import markdown_table

from conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def _toml_block() -> str:
    return re.search(r"```toml\n(.*?)```", README, re.S).group(1)


def test_the_vehicle_file_example_is_complete_and_runs(tmp_path):
    text = _toml_block()
    v = loads_vehicle(text)
    assert v.name == "my_semi" and v.unit_names == ("tractor", "trailer") and v.units[0].axles[0].steered
    path = tmp_path / "my_semi.toml"
    path.write_text(text)
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "measures", "--vehicle", str(path), "--speed-kph", "88",
                        "--load", "trailer", "--json"], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    doc = json.loads(p.stdout)
    assert doc["critical_speed_kph"] is None and 0 < doc["least_damping_ratio"] < 1   # a sane, stable semi


def test_the_ranges_table_is_the_one_the_code_enforces():
    assert markdown_table() in README


def test_every_command_shown_exists():
    shown = set(re.findall(r"^lcv (\w+)", README, re.M))
    p = subprocess.run([sys.executable, "-m", "lcvreport.cli", "--help"], capture_output=True, text=True)
    listed = set(re.findall(r"^    (\w+) ", p.stdout, re.M))
    assert shown and shown <= listed, shown - listed


def test_the_error_message_shown_is_the_real_one():
    import pytest
    from lcvreport.model.vehicle_file import VehicleFileError
    shown = re.search(r"\(`(units\[1\] \"trailer\" axles\[0\][^`]*)`\)", README).group(1)
    with pytest.raises(VehicleFileError) as err:
        loads_vehicle(_toml_block().replace("tires = 12 ", "tires = 0 "))
    assert str(err.value) == shown
