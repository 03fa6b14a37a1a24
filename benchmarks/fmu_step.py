"""Benchmark: cost per communication step of the FMUs under fmpy.simulate_fmu.

A 10 s run at 1 ms steps (10,000 steps) recording every output, for
* ``LCV.fmu`` (pythonfmu, this project),
* an interface-only twin built here: the same variables through the same pythonfmu
  machinery, a ``do_step`` that does nothing -- the framework's own per-step cost,
* ``LCVNative.fmu`` (C) when it exists, under fmpy and under the C host of
  ``tests/c_host.c``.
Runs are alternated and the best of ``REPEATS`` is kept.  Targets: LCV / twin <= 1.5;
LCVNative at least 5x faster than LCV under fmpy and < 1 us/step in the C host.
"""
from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
STOP, STEP, REPEATS = 10.0, 1e-3, 5

TWIN_SOURCE = '''
from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, String
from fmi_xml import UnitReal, finish_model_description
from lcvreport.cosim import INPUTS, OUTPUTS, PARAMETERS


class Twin(Fmi2Slave):
    """Same variables as LCV, no model: do_step does nothing."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.preset = PARAMETERS[0].start
        self.tire_scale = PARAMETERS[1].start
        self.u_min = PARAMETERS[2].start
        self._in = [v.start for v in INPUTS]
        self._out = [v.start for v in OUTPUTS]
        p_kw = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed)
        self.register_variable(String("preset", **p_kw))
        for v in PARAMETERS[1:]:
            self.register_variable(UnitReal(v.name, unit=v.unit, **p_kw))
        for i, v in enumerate(INPUTS):
            self.register_variable(UnitReal(v.name, unit=v.unit, causality=Fmi2Causality.input,
                                            variability=Fmi2Variability.continuous,
                                            getter=lambda i=i: self._in[i],
                                            setter=lambda x, i=i: self._in.__setitem__(i, x)))
        for i, v in enumerate(OUTPUTS):
            self.register_variable(UnitReal(v.name, unit=v.unit, causality=Fmi2Causality.output,
                                            variability=Fmi2Variability.continuous,
                                            initial=Fmi2Initial.calculated, getter=lambda i=i: self._out[i]))

    def do_step(self, current_time, step_size):
        return True

    def to_xml(self, model_options=dict()):
        return finish_model_description(super().to_xml(model_options), list(self.vars.values()), {}, {})
'''


def build_twin(out_dir: Path) -> Path:
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / "Twin.py"
        src.write_text(TWIN_SOURCE)
        shutil.copy(ROOT / "fmu_src" / "fmi_xml.py", tmp)
        subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(src), "-d", str(out_dir),
                        str(Path(tmp) / "fmi_xml.py"), str(ROOT / "lcvreport")],
                       check=True, cwd=tmp, stdout=subprocess.DEVNULL)
    return out_dir / "Twin.fmu"


def build_native_twin(native: Path, out_dir: Path) -> Path:
    """LCVNative.fmu recompiled from its own sources/ with LCV_INTERFACE_ONLY: same
    variables, fmi2DoStep and the output getters do nothing."""
    twin = out_dir / "LCVNative.fmu"
    with tempfile.TemporaryDirectory() as tmp:
        zipfile.ZipFile(native).extractall(tmp)
        lib = Path(tmp) / "binaries" / "linux64" / "LCVNative.so"
        subprocess.run(["gcc", "-std=c99", "-O2", "-fPIC", "-shared", "-fvisibility=hidden", "-DLCV_INTERFACE_ONLY",
                        "-o", str(lib), str(Path(tmp) / "sources" / "lcv_native.c"), "-lm"], check=True)
        with zipfile.ZipFile(native) as src, zipfile.ZipFile(twin, "w", zipfile.ZIP_DEFLATED) as dst:
            for name in src.namelist():
                data = lib.read_bytes() if name.endswith("LCVNative.so") else src.read(name)
                dst.writestr(name, data)
    return twin


def time_fmpy(fmu: Path, outputs: list[str]) -> float:
    from fmpy import simulate_fmu
    t0 = time.perf_counter()
    simulate_fmu(str(fmu), stop_time=STOP, step_size=STEP, output_interval=STEP, output=outputs,
                 start_values={"preset": "aucnat"})
    return time.perf_counter() - t0


def c_host_us_per_step(fmu: Path) -> float | None:
    """Per-step time of LCVNative.fmu in the C host (tests/c_host.c), or None."""
    src = ROOT / "tests" / "c_host.c"
    if not src.exists() or not fmu.exists():
        return None
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "c_host"
        subprocess.run(["gcc", "-O2", "-std=c99", "-o", str(exe), str(src), "-ldl"], check=True)
        unzipped = Path(tmp) / "fmu"
        zipfile.ZipFile(fmu).extractall(unzipped)
        root = ET.parse(unzipped / "modelDescription.xml").getroot()
        guid = root.get("guid")
        vr = {sv.get("name"): sv.get("valueReference") for sv in root.iter("ScalarVariable")}
        best = None
        for _ in range(REPEATS):
            p = subprocess.run([str(exe), str(unzipped), "LCVNative", guid, "bench", str(int(1e6)), "0.001", vr["P61"], vr["y6"]],
                               check=True, capture_output=True, text=True)
            for line in p.stdout.splitlines():
                if line.startswith("us_per_step"):
                    v = float(line.split()[1])
                    best = v if best is None else min(best, v)
    return best


def main() -> None:
    from lcvreport.cosim import OUTPUT_NAMES
    outputs = list(OUTPUT_NAMES)
    lcv = BUILD / "LCV.fmu"
    native = BUILD / "LCVNative.fmu"
    if not lcv.exists():
        sys.exit("build/LCV.fmu missing: run ./build.sh fmu")
    n_steps = int(round(STOP / STEP))
    with tempfile.TemporaryDirectory() as tmp:
        twin = build_twin(Path(tmp))
        runs = {"LCV.fmu": [], "twin (interface only)": []}
        paths = {"LCV.fmu": lcv, "twin (interface only)": twin, "LCVNative.fmu": native}
        if native.exists():
            (Path(tmp) / "ctwin").mkdir()
            paths["C twin (interface only)"] = build_native_twin(native, Path(tmp) / "ctwin")
            runs["LCVNative.fmu"] = []
            runs["C twin (interface only)"] = []
        for name in runs:  # warm up
            time_fmpy(paths[name], outputs)
        for _ in range(REPEATS):
            for name in runs:
                runs[name].append(time_fmpy(paths[name], outputs))
    us = {k: min(v) / n_steps * 1e6 for k, v in runs.items()}
    print(f"fmpy.simulate_fmu, {STOP:g} s at {STEP * 1e3:g} ms ({n_steps} steps), all {len(outputs)} outputs "
          f"recorded, best of {REPEATS}:")
    for k, v in us.items():
        print(f"  {k:24s} {v:8.2f} us/step")
    print(f"  ratio LCV / twin         {us['LCV.fmu'] / us['twin (interface only)']:8.2f}   (target <= 1.5)")
    if "LCVNative.fmu" in us:
        print(f"  speed-up LCVNative vs LCV under fmpy {us['LCV.fmu'] / us['LCVNative.fmu']:6.1f}x  (target >= 5)")
        floor = us["C twin (interface only)"]
        print(f"  fmpy's own floor (C twin)            {floor:6.2f} us/step: no FMU can run faster under fmpy;")
        print(f"    best possible speed-up over LCV.fmu here = {us['LCV.fmu'] / floor:.1f}x")
        print(f"  model cost over its twin: LCV.fmu {us['LCV.fmu'] - us['twin (interface only)']:6.2f} us/step, "
              f"LCVNative.fmu {us['LCVNative.fmu'] - floor:6.2f} us/step")
        c = c_host_us_per_step(native)
        if c is not None:
            print(f"  LCVNative.fmu in the C host (10^6 steps of 1 ms) {c:8.3f} us/step  (target < 1)")


if __name__ == "__main__":
    main()
