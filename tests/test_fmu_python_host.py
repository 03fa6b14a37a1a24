"""The Python FMU in a Python host (issue 20): the host is left as it was found (sys.path,
meta-path finders, path hooks, __main__'s names) after fmi2FreeInstance, and the FMU runs its
own bundled package even when the host imported another ``lcvreport`` first."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

HERE = Path(__file__).parent


def _host(fmu: Path, *args: str, flags=()) -> dict:
    p = subprocess.run([sys.executable, *flags, str(HERE / "python_host.py"), str(fmu), *args], capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


@pytest.fixture(scope="module")
def reference_r1(native_fmu):
    """r1 after 1 s of a 0.01 rad steer step, from the native FMU (equal to the package's
    exact response, tests/test_fmu.py)."""
    from fmpy import simulate_fmu
    inp = np.array([(0.0, 0.01), (1.0, 0.01)], dtype=[("time", float), ("delta", float)])
    res = simulate_fmu(str(native_fmu), stop_time=1.0, step_size=0.1, output_interval=0.1, input=inp,
                       output=["r1"])
    return float(res["r1"][-1])


@pytest.mark.parametrize("case, flags, fake", [("venv host", (), False), ("host without site-packages", ("-S",), False),
                                               ("host with another lcvreport", (), True)])
def test_the_host_is_left_as_it_was(lcv_fmu, tmp_path, reference_r1, case, flags, fake):
    args = ()
    if fake:
        pkg = tmp_path / "fake" / "lcvreport"
        pkg.mkdir(parents=True)
        (pkg / "__init__.py").write_text("raise_if_used = True\n")
        (pkg / "fmu").mkdir()
        (pkg / "fmu" / "__init__.py").write_text("raise RuntimeError('the host copy was run')\n")
        args = (str(tmp_path / "fake"),)
    out = _host(lcv_fmu, *args, flags=flags)
    assert out["ok"] and not out["messages"], (case, out)
    assert out["changed"] == {"path": [], "meta": [], "hooks": []}, (case, out)
    assert out["main_added"] == [], (case, out)
    assert out["r1"] == pytest.approx(reference_r1, rel=1e-12), case
    if fake:
        assert out["lcvreport"] == str(tmp_path / "fake" / "lcvreport" / "__init__.py")   # still the host's
    if flags:
        assert out["numpy_from"] and "site-packages" in out["numpy_from"]      # the recorded site-packages


TWO_FMUS = r'''
import json, sys
import numpy as np
from fmpy import simulate_fmu
inp = np.array([(0.0, 0.01), (1.0, 0.01)], dtype=[("time", float), ("delta", float)])
out = {}
for fmu in sys.argv[1:]:
    res = simulate_fmu(fmu, stop_time=1.0, step_size=0.1, output_interval=0.1, input=inp)   # extracted, then removed
    out[fmu] = {n: float(res[n][-1]) for n in res.dtype.names}
print(json.dumps(out))
'''


def test_two_python_fmus_in_one_process(lcv_fmu, tmp_path):
    """Two Python FMUs of different vehicles and models, one after the other in one Python process
    (fmpy extracts each and removes it after its run): each runs its own class and package, with
    the outputs it gives in a process of its own.  Both slave modules were named LCV, and pythonfmu
    0.7.0 takes the class from sys.modules: the second ran the first one's class from its removed
    folder and failed to instantiate ('No module named ....model.yaw_roll')."""
    from lcvreport import load_vehicle
    from lcvreport.fmu.build import build_vehicle_fmus
    from conftest import EXAMPLES
    roll = build_vehicle_fmus(load_vehicle(EXAMPLES / "b_double.toml"), tmp_path, kind="python", model="yaw_roll")[0]
    fmus = [str(lcv_fmu), str(roll)]

    def run(*paths):
        p = subprocess.run([sys.executable, "-c", TWO_FMUS, *paths], capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, p.stderr[-3000:]
        return json.loads(p.stdout.strip().splitlines()[-1])

    together = run(*fmus)
    alone = {f: run(f)[f] for f in fmus}
    assert together == alone
    assert "phi1" in together[str(roll)] and "phi1" not in together[str(lcv_fmu)]
