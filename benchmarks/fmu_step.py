"""Benchmark: cost per communication step of the FMUs.

A 10 s run at 1 ms steps (10,000 steps) recording every output under
``fmpy.simulate_fmu``, for

* ``LCV.fmu`` (pythonfmu) and two twins: a **stock pythonfmu FMU** with the same
  variables (a plain ``Fmi2Slave`` written here, built by ``pythonfmu build``, no loader,
  no guards: what any pythonfmu FMU of this interface costs -- the code under test cannot
  influence it), and the interface-only twin (LCV's own slave and loader machinery with no
  model: what the guards cost);
* ``LCVNative.fmu`` (C) and its interface-only twin built from the same interface table
  with ``fmu_src/c/vehicle/model_stub.c`` (``build_native_fmu(..., stub=True)``);
* ``LCVNative.fmu`` in the plain C host of ``tests/c_host.c`` (10^6 steps).

Runs are alternated and the best of ``REPEATS`` is kept; the LCV / stock ratio is printed
from the bests and as the median of the rounds' own ratios (each round runs every FMU back to
back).  Targets: LCV / the stock pythonfmu twin <= 1.3 (issue 32: the guards and the model
together cost less than a third of what pythonfmu itself costs per step); LCVNative's model cost below
fmpy's per-step floor (its twin) and < 1 us/step in the C host.  The speed-up of
LCVNative over LCV under fmpy is printed too; it is bounded by fmpy's own per-step cost,
which the C twin measures.

    python benchmarks/fmu_step.py      (after ./build.sh fmu)
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
STOP, STEP, REPEATS = 10.0, 1e-3, 9

#: the twin's slave module: LCV's variables and machinery, no model
TWIN_SLAVE = '''
import ctypes

from lcvreport.fmu.slave_fmi2 import LCV as _LCV


class LCV(_LCV):
    def do_step(self, current_time, step_size):
        return True

    def get_real(self, vrs):
        return [0.0] * len(vrs)


ctypes.c_ssize_t.from_address(id(globals())).value += 1   # as fmu_src/LCV.py: pythonfmu releases a borrowed ref
'''


def stock_slave_source() -> str:
    """A plain pythonfmu slave with the preset FMU's variables (names, causality,
    variability, start values), nothing computed: written from the interface table's
    names only, with pythonfmu's stock getters and setters."""
    from lcvreport.fmu.interface import preset_interface
    lines = ["from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real", "",
             "", "class LCV(Fmi2Slave):", "    def __init__(self, **kwargs):", "        super().__init__(**kwargs)"]
    for v in preset_interface().variables:
        kind = "Integer" if v.type == "Enumeration" else "Real"
        start = ("1" if v.type == "Enumeration" else repr(v.start)) if v.start is not None else "0.0"
        lines.append(f"        self.{v.name} = {start}")
        lines.append(f"        self.register_variable({kind}({v.name!r}, causality=Fmi2Causality.{v.causality}, "
                     f"variability=Fmi2Variability.{v.variability}))")
    lines += ["", "    def do_step(self, current_time, step_size):", "        return True", ""]
    return "\n".join(lines)


def build_stock_twin(out_dir: Path) -> Path:
    """The stock pythonfmu FMU of :func:`stock_slave_source`, built by ``pythonfmu build``."""
    src = out_dir / "src"
    src.mkdir(parents=True)
    (src / "LCV.py").write_text(stock_slave_source(), encoding="utf-8")
    subprocess.run([sys.executable, "-m", "pythonfmu", "build", "-f", str(src / "LCV.py"), "-d", str(out_dir)],
                   check=True, capture_output=True, cwd=out_dir)
    return out_dir / "LCV.fmu"


def build_python_twin(lcv: Path, out_dir: Path) -> Path:
    """LCV.fmu with its slave module replaced by :data:`TWIN_SLAVE`."""
    twin = out_dir / "LCV.fmu"
    with zipfile.ZipFile(lcv) as src, zipfile.ZipFile(twin, "w", zipfile.ZIP_DEFLATED) as dst:
        for name in src.namelist():
            dst.writestr(name, TWIN_SLAVE.encode() if name == "resources/LCV.py" else src.read(name))
    return twin


def build_native_twin(out_dir: Path) -> Path:
    from lcvreport.fmu.build import build_native_fmu
    from lcvreport.fmu.interface import preset_interface
    return build_native_fmu(preset_interface(), out_dir, "LCVNative", stub=True)


def time_fmpy(fmu: Path, outputs: list[str]) -> float:
    """Seconds of one ``simulate_fmu`` run, timed in a fresh process: pythonfmu imports the
    slave module by its name (``LCV`` for all three Python FMUs here), so two of them in
    one process would share the first one's class and time the same code twice."""
    code = ("import sys, time\nfrom fmpy import simulate_fmu\n"
            f"args = dict(stop_time={STOP!r}, step_size={STEP!r}, output_interval={STEP!r}, output={outputs!r}, "
            "start_values={'preset': 1})\n"
            "simulate_fmu(sys.argv[1], stop_time=0.01, step_size=0.001, start_values={'preset': 1})\n"
            "t0 = time.perf_counter()\nsimulate_fmu(sys.argv[1], **args)\nprint(time.perf_counter() - t0)\n")
    p = subprocess.run([sys.executable, "-c", code, str(fmu)], capture_output=True, text=True, check=True)
    return float(p.stdout.split()[-1])


def c_host_us_per_step(fmu: Path, identifier: str = "LCVNative", vr_in: str = "P61", vr_out: str = "y6") -> float:
    """Per-step time [us] of a native FMU (model identifier ``identifier``) in the C host
    (tests/c_host.c): 10^6 steps of 1 ms with the input ``vr_in`` at 1000 and the output ``vr_out``
    read every step, best of REPEATS."""
    return min(c_host_rounds([(fmu, identifier, vr_in, vr_out)])[0])


def c_host_rounds(fmus: list[tuple], rounds: int = REPEATS) -> list[list[float]]:
    """Per-step times [us] of native FMUs ``(path, identifier, vr_in, vr_out)`` in the C host,
    ``rounds`` rounds each running every FMU once, back to back (so a round's ratios are immune to
    the machine's slow drifts): one list of times per FMU."""
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "c_host"
        subprocess.run(["gcc", "-O2", "-std=c99", "-o", str(exe), str(ROOT / "tests" / "c_host.c"), "-ldl"],
                       check=True)
        commands = []
        for k, (fmu, identifier, vr_in, vr_out) in enumerate(fmus):
            unzipped = Path(tmp) / f"fmu{k}"
            zipfile.ZipFile(fmu).extractall(unzipped)
            root = ET.parse(unzipped / "modelDescription.xml").getroot()
            vr = {sv.get("name"): sv.get("valueReference") for sv in root.iter("ScalarVariable")}
            commands.append([str(exe), str(unzipped), identifier, root.get("guid"), "bench", str(int(1e6)), "0.001",
                             vr[vr_in], vr[vr_out]])
        times = [[] for _ in fmus]
        for _ in range(rounds):
            for k, cmd in enumerate(commands):
                p = subprocess.run(cmd, check=True, capture_output=True, text=True)
                times[k] += [float(line.split()[1]) for line in p.stdout.splitlines() if line.startswith("us_per_step")]
    return times


def main() -> None:
    from lcvreport.fmu.interface import preset_interface
    outputs = [v.name for v in preset_interface().outputs]
    lcv, native = BUILD / "LCV.fmu", BUILD / "LCVNative.fmu"
    if not lcv.exists() or not native.exists():
        sys.exit("build/LCV.fmu or build/LCVNative.fmu missing: run ./build.sh fmu")
    n_steps = int(round(STOP / STEP))
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "py").mkdir()
        (Path(tmp) / "c").mkdir()
        paths = {"LCV.fmu": lcv, "stock pythonfmu twin": build_stock_twin(Path(tmp) / "stock"),
                 "LCV twin (interface only)": build_python_twin(lcv, Path(tmp) / "py"),
                 "LCVNative.fmu": native, "C twin (interface only)": build_native_twin(Path(tmp) / "c")}
        runs: dict[str, list[float]] = {k: [] for k in paths}
        for _ in range(REPEATS):
            for name, path in paths.items():
                runs[name].append(time_fmpy(path, outputs))
    us = {k: min(v) / n_steps * 1e6 for k, v in runs.items()}
    # each round runs every FMU back to back: the ratio of a round is immune to the machine's
    # slow drifts (its load, its clock), the median over the rounds to a round disturbed
    paired = sorted(a / b for a, b in zip(runs["LCV.fmu"], runs["stock pythonfmu twin"]))
    median_ratio = paired[len(paired) // 2]
    print(f"fmpy.simulate_fmu, {n_steps} steps of {STEP * 1e3:g} ms, all {len(outputs)} outputs recorded, "
          f"best of {REPEATS}:")
    for k, v in us.items():
        print(f"  {k:28s} {v:8.2f} us/step")
    print(f"  LCV / stock pythonfmu twin       {us['LCV.fmu'] / us['stock pythonfmu twin']:6.2f}   (best of each; "
          f"median of the rounds' ratios {median_ratio:.2f}; target <= 1.3)")
    print(f"  LCV / its interface-only twin    {us['LCV.fmu'] / us['LCV twin (interface only)']:6.2f}")
    print(f"  guards (interface-only twin - stock) "
          f"{us['LCV twin (interface only)'] - us['stock pythonfmu twin']:6.2f} us/step")
    print(f"  model cost in LCV.fmu            {us['LCV.fmu'] - us['LCV twin (interface only)']:6.2f} us/step")
    print(f"  model cost in LCVNative.fmu      {us['LCVNative.fmu'] - us['C twin (interface only)']:6.2f} us/step")
    print(f"  speed-up LCVNative vs LCV        {us['LCV.fmu'] / us['LCVNative.fmu']:6.1f}x   "
          f"(bounded by fmpy: {us['LCV.fmu'] / us['C twin (interface only)']:.1f}x for a model costing nothing)")
    print(f"  LCVNative.fmu in the C host (10^6 steps of 1 ms) {c_host_us_per_step(native):8.3f} us/step  (target < 1)")


if __name__ == "__main__":
    main()
