"""Every exported FMI function of every kind of FMU binary, called with a NULL instance and
zero arguments (issue 20: hostile input at every new entry point, the FMI 3.0 API and the
Model Exchange functions included): each returns an error status (void functions return),
nothing crashes -- each binary in a process of its own."""
from __future__ import annotations

import json
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from fmu_support import host_env

HERE = Path(__file__).parent


def _sweep(fmu: Path, tmp_path: Path, version: str) -> dict:
    zipfile.ZipFile(fmu).extractall(tmp_path)
    lib = next((tmp_path / "binaries").glob(f"*/{fmu.stem}.so"))
    p = subprocess.run([sys.executable, str(HERE / "null_sweep.py"), str(lib), version], capture_output=True, text=True,
                       env=host_env(), timeout=120)
    assert p.returncode == 0, p.stderr[-2000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("which", ["LCVNative", "LCVNative3", "LCV", "driver"])
def test_null_instance_everywhere_is_an_error(which, native_fmu, lcv_fmu, tmp_path):
    from conftest import BUILD
    if which == "driver":
        from lcvreport.fmu.driver import build_driver_fmu
        fmu = build_driver_fmu(tmp_path / "drv")
    elif which == "LCVNative3":
        fmu = BUILD / "LCVNative3.fmu"
        if not fmu.exists():
            subprocess.run([sys.executable, "-m", "lcvreport.fmu.build", "--out", str(BUILD)], check=True)
    else:
        fmu = {"LCVNative": native_fmu, "LCV": lcv_fmu}[which]
    statuses = _sweep(fmu, tmp_path / "x", "fmi3" if which.endswith("3") else "fmi2")
    expected = {"LCVNative": 41, "LCVNative3": 71, "LCV": 31, "driver": 41}[which]
    assert len(statuses) == expected, sorted(statuses)
    assert {k: v for k, v in statuses.items() if v not in (3, None)} == {}
    assert [k for k, v in statuses.items() if v is None] == [
        "fmi3FreeInstance" if which.endswith("3") else "fmi2FreeInstance"]
