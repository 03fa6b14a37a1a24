"""Benchmark: roll (docs/roll.md) -- ``lcv roll`` of a 6-unit vehicle with start-up, and the roll
measure set against the yaw-plane measure set of the same vehicle.

The 6-unit vehicle is the AU-NCAT triple with the examples' assumed roll data
(``examples/vehicles/make_examples.py``: ROLL_UNITS, ROLL_AXLES), written to a temporary file.
The comparison is the same vehicle without its roll keys (the roll families then return at
once): what the roll families add to ``measure_set``.  Best of ``REPEATS``; one BLAS thread.
Targets (issue 31): ``lcv roll`` <= 0.5 s with start-up; the roll measure set <= 3x the yaw-plane one;
the native yaw-roll FMU's step <= 2x the yaw-plane one (the 6-unit vehicle's FMUs of both models
in the plain C host of ``tests/c_host.c``, 10^6 steps of 1 ms with a residual force on the rear axle).
Also the roll measures of a study batched over variants (the rear trailer's CG height and the
trailers' roll stiffness scaled: each variant's yaw-roll coefficients built exactly) beside the loop
of the one-variant calls (``measure_values``) on the same variants, with the largest difference.

    python benchmarks/roll.py
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")    # before numpy is imported

import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "vehicles"))

import make_examples  # noqa: E402

from lcvreport import load_preset  # noqa: E402
from lcvreport.measures.measure_set import measure_set  # noqa: E402
from lcvreport.model.vehicle_file import dumps_vehicle  # noqa: E402

REPEATS = 5
SPEED_MPS = 88 / 3.6


def triple_with_roll():
    """AU-NCAT with the examples' assumed roll data (fifth wheels roll-coupled, drawbars roll-free)."""
    roll = make_examples.ROLL_UNITS
    roll.update({"tractor": roll["tractor"], "trailer1": roll["trailer1"], "dolly1": roll["dolly"],
                 "trailer2": (2.00, 0.75, 2.4, (0.90, 0.0)), "dolly2": roll["dolly"], "trailer3": roll["trailer2"]})
    return make_examples.with_roll(load_preset("aucnat"))


def without_roll(vehicle):
    keys = dict.fromkeys(("cg_height_m", "roll_axis_height_m", "roll_inertia_kg_m2", "rear_coupling_height_m",
                          "rear_coupling_roll_stiffness_Nm_per_rad"))
    return replace(vehicle, units=tuple(replace(u, **keys, axles=tuple(replace(
        a, roll_stiffness_Nm_per_rad=None, roll_damping_Nms_per_rad=None, unsprung_mass_kg=None) for a in u.axles))
        for u in vehicle.units))


def best(fn, repeats=REPEATS):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    v = triple_with_roll()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "triple_roll.toml"
        path.write_text(dumps_vehicle(v), encoding="utf-8")
        cmd = [sys.executable, "-m", "lcvreport.cli", "roll", "--vehicle", str(path), "--speed-kph", "88", "--json"]
        wall = best(lambda: subprocess.run(cmd, check=True, capture_output=True))
        start = best(lambda: subprocess.run([sys.executable, "-m", "lcvreport.cli", "presets"], check=True,
                                            capture_output=True))
    print(f"lcv roll, 6 units, with start-up: {wall:.3f} s (target <= 0.5 s); lcv presets (start-up alone) "
          f"{start:.3f} s")
    plain = without_roll(v)
    # fresh vehicle objects each time: nothing cached between repeats
    t_roll = best(lambda: measure_set(replace(v, name=f"r{time.perf_counter_ns()}"), SPEED_MPS))
    t_yaw = best(lambda: measure_set(replace(plain, name=f"p{time.perf_counter_ns()}"), SPEED_MPS))
    print(f"measure_set with roll {t_roll * 1e3:.1f} ms, without {t_yaw * 1e3:.1f} ms: ratio {t_roll / t_yaw:.2f} "
          "(target <= 3; both include the low-speed turn)")
    from lcvreport.measures.registry import FAMILIES, MeasureCase

    def families(names, vehicle):
        case = MeasureCase(replace(vehicle, name=f"f{time.perf_counter_ns()}"), SPEED_MPS, 1.0, 0.4)
        for name in names:
            FAMILIES[name].compute(case)
    roll = ("rollover", "roll")
    yaw = tuple(n for n in FAMILIES if n not in roll + ("low_speed_turn", "trim"))
    t_r, t_y = best(lambda: families(roll, v)), best(lambda: families(yaw, v))
    print(f"the roll families alone {t_r * 1e3:.1f} ms, the yaw-plane families but the turn {t_y * 1e3:.1f} ms: "
          f"ratio {t_r / t_y:.2f}")
    batched_roll(v)
    plane, roll = native_step_rounds(v)
    ratios = sorted(r / p for p, r in zip(plane, roll))
    print(f"native FMU step in the C host, 6 units, {len(plane)} interleaved rounds: yaw-plane {min(plane):.3f} us, "
          f"yaw-roll {min(roll):.3f} us (best of each): ratio {min(roll) / min(plane):.2f}; median of the rounds' "
          f"ratios {ratios[len(ratios) // 2]:.2f} (target <= 2)")
    plane_i, roll_i = native_step_instructions(v)
    print(f"native FMU step, instructions counted by callgrind (deterministic: the same counts on a loaded "
          f"machine): yaw-plane {plane_i:.0f}, yaw-roll {roll_i:.0f} per step: ratio {roll_i / plane_i:.2f} "
          "(target <= 2)")


def batched_roll(vehicle, count: int = 128) -> None:
    """The study's roll measures over ``count`` variants: batched against the loop of one-variant calls."""
    import numpy as np

    from lcvreport.analysis.batch import VariantBatch
    from lcvreport.measures.measure_set import measure_values
    from lcvreport.measures.registry import FAMILIES
    from lcvreport.measures.roll import roll_batched, rollover_batched
    rng = np.random.default_rng(7)
    h, k = rng.uniform(0.9, 1.1, count), rng.uniform(0.8, 1.2, count)

    def variant(i):
        last = len(vehicle.units) - 1
        return replace(vehicle, name=f"v{i}", units=tuple(replace(
            u, cg_height_m=u.cg_height_m * (h[i] if j == last else 1.0), axles=tuple(replace(
                a, roll_stiffness_Nm_per_rad=a.roll_stiffness_Nm_per_rad * (k[i] if j > 0 else 1.0)) for a in u.axles))
            for j, u in enumerate(vehicle.units)))
    keys = FAMILIES["roll"].batched_keys + FAMILIES["rollover"].batched_keys
    warm = VariantBatch.of_vehicles(vehicle, [variant(0)], "yaw_roll")        # both paths' first-use costs out
    roll_batched(warm, SPEED_MPS), rollover_batched(warm), measure_values(variant(0), SPEED_MPS, list(keys))
    t = time.perf_counter()
    batch = VariantBatch.of_vehicles(vehicle, [variant(i) for i in range(count)], "yaw_roll")
    both = {**roll_batched(batch, SPEED_MPS), **rollover_batched(batch)}
    got = np.column_stack([both[key] for key in keys])
    t_batch = time.perf_counter() - t
    some = range(0, count, 8)
    t = time.perf_counter()
    ref = np.array([[row[key] for key in keys] for row in (measure_values(variant(i), SPEED_MPS, list(keys))
                                                           for i in some)], dtype=float)
    t_loop = (time.perf_counter() - t) / len(some) * count
    diff = np.nanmax(np.abs(got[list(some)] - ref) / np.abs(ref))
    print(f"roll measures ({', '.join(keys)}) of {count} variants, 6 units: batched {t_batch * 1e3 / count:.1f} ms "
          f"per variant, the one-variant calls {t_loop * 1e3 / count:.1f} ms: ratio {t_batch / t_loop:.2f}; "
          f"largest difference {diff:.1e} relative")


def native_step_rounds(vehicle, rounds: int = 9) -> tuple[list, list]:
    """Per-step times [us] of the vehicle's native FMUs of both models in tests/c_host.c, in
    ``rounds`` interleaved rounds (10^6 steps of 1 ms each, a residual force on the rear axle,
    ``Y_rear`` read every step)."""
    from fmu_step import c_host_rounds               # benchmarks/: the C-host timing, one definition
    from lcvreport.fmu.build import build_vehicle_fmus
    with tempfile.TemporaryDirectory() as tmp:
        fmus = [(build_vehicle_fmus(vehicle, Path(tmp) / model, kind="native", model=model)[0], f"{vehicle.name}Native",
                 f"P_{vehicle.axles[-1].name}", "Y_rear") for model in ("yaw_plane", "yaw_roll")]
        plane, roll = c_host_rounds(fmus, rounds)
    return plane, roll

def native_step_instructions(vehicle, steps: tuple[int, int] = (10_000, 30_000)) -> tuple[float, float]:
    """Instructions per step of the vehicle's native FMUs of both models in tests/c_host.c, counted
    by valgrind's callgrind (the difference of two runs of ``steps`` steps: start-up cancels)."""
    import re
    import xml.etree.ElementTree as ET
    import zipfile

    from lcvreport.fmu.build import build_vehicle_fmus
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        exe = Path(tmp) / "c_host"
        subprocess.run(["gcc", "-O2", "-std=c99", "-o", str(exe), str(ROOT / "tests" / "c_host.c"), "-ldl"],
                       check=True)
        for model in ("yaw_plane", "yaw_roll"):
            fmu = build_vehicle_fmus(vehicle, Path(tmp) / model, kind="native", model=model)[0]
            unzipped = Path(tmp) / model / "x"
            zipfile.ZipFile(fmu).extractall(unzipped)
            root = ET.parse(unzipped / "modelDescription.xml").getroot()
            vr = {sv.get("name"): sv.get("valueReference") for sv in root.iter("ScalarVariable")}
            counts = []
            for n in steps:
                p = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp}/cg.out", str(exe),
                                    str(unzipped), f"{vehicle.name}Native", root.get("guid"), "bench", str(n), "0.001",
                                    vr[f"P_{vehicle.axles[-1].name}"], vr["Y_rear"]], capture_output=True, text=True,
                                   check=True)
                counts.append(int(re.search(r"Collected : (\d+)", p.stderr).group(1)))
            out.append((counts[1] - counts[0]) / (steps[1] - steps[0]))
    return out[0], out[1]


if __name__ == "__main__":
    main()
