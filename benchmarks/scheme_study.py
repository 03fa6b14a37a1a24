"""Benchmark: assessments at study speed (issue 43) -- one run times, on the B-double with the same
factors (every trailer's mass and every unit's cornering stiffness varied), a plain study of 400
cases (the template scheme's measures, batched where they have a batched form) and a scheme study
of 40 cases (``lcv study --scheme``: every case assessed), per case; the scheme study with the
template scheme as shipped (40 and 128 cases: a block of turns side by side) and without its ``stfd`` entry (the nonlinear model's turn with tire
forces); and ``assess`` of one new variant in process, without and with ``stfd``: new masses, new
bodies (wider: the turns' run is shared, their swept paths new), a new geometry (a coupling moved).  One process, one BLAS thread, the study's
own chunk function (no Dask start-up in the times).  Last, ``lcv assess`` of the B-double as a
command (11 runs, start-up and shutdown included), beside the floor no code of ours can move:
a Python that imports numpy, scipy.linalg and scipy.integrate and exits.

    python benchmarks/scheme_study.py
"""
from __future__ import annotations

import os
import subprocess
import sys

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")    # before numpy is imported

import time  # noqa: E402
from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from lcvreport.measures.assess import assess  # noqa: E402
from lcvreport.measures.scheme import loads_scheme  # noqa: E402
from lcvreport.model.vehicle_file import load_vehicle  # noqa: E402
from lcvreport.study.compute import compute_chunk  # noqa: E402
from lcvreport.study.spec import study_from_dict  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
VEHICLE = ROOT / "examples" / "vehicles" / "b_double.toml"
TEMPLATE = (ROOT / "examples" / "schemes" / "template.toml").read_text(encoding="utf-8")
NO_STFD = TEMPLATE[:TEMPLATE.index("[measures.stfd]")]
FACTORS = {"lead_trailer.mass_scale": {"distribution": "uniform", "low": 0.7, "high": 1.1},
           "rear_trailer.mass_scale": {"distribution": "uniform", "low": 0.7, "high": 1.1},
           "prime_mover.cornering_stiffness_scale": {"distribution": "normal", "mean": 1.0, "sd": 0.08},
           "rear_trailer.cornering_stiffness_scale": {"distribution": "normal", "mean": 1.0, "sd": 0.08}}


def study(count: int, scheme: str | None):
    keys = [m.key for m in loads_scheme(TEMPLATE).measures if m.key != "stfd"]
    s = study_from_dict({"vehicle": str(VEHICLE), "measures": keys, "speed_kph": 88.0,
                         "design": {"kind": "random", "count": count, "seed": 43}, "factors": FACTORS})
    return s.with_scheme(scheme) if scheme else s


def per_case(s, count: int) -> float:
    t0 = time.perf_counter()
    compute_chunk(s, np.arange(count))
    return (time.perf_counter() - t0) / count


def main() -> None:
    from machine import machine_line       # (benchmarks/machine.py: a time is read with its machine)
    print(machine_line())
    v = load_vehicle(VEHICLE)
    names = [u.name for u in v.units]
    for f in list(FACTORS):
        unit = f.split(".")[0]
        if unit != "speed_kph" and unit not in names:
            raise SystemExit(f"{f}: no unit {unit!r} in {names}")
    plain = per_case(study(400, None), 400)
    no_stfd = per_case(study(40, NO_STFD), 40)
    shipped = per_case(study(40, TEMPLATE), 40)
    block = per_case(study(128, TEMPLATE), 128)
    print(f"plain study, 400 cases: {plain * 1e3:.1f} ms per case")
    print(f"scheme study, 40 cases, template without stfd: {no_stfd * 1e3:.1f} ms per case, "
          f"{no_stfd / plain:.1f}x the plain study (target <= 5x)")
    print(f"scheme study, 40 cases, template as shipped (stfd: the nonlinear turn, 40 side by side): "
          f"{shipped * 1e3:.0f} ms per case, {shipped / plain:.1f}x")
    print(f"scheme study, 128 cases (one block of turns side by side), template as shipped: {block * 1e3:.0f} ms per "
          f"case, {block / plain:.1f}x")
    print(f"10^4 cases of the template scheme on two cores, extrapolated: without stfd "
          f"{1e4 * no_stfd / 2 / 60:.1f} min, as shipped {1e4 * block / 2 / 60:.1f} min (target <= 5 min)")
    for j, (name, text) in enumerate((("template without stfd", NO_STFD),
                                      ("template as shipped (stfd: its turn with tire forces)", TEMPLATE))):
        scheme = loads_scheme(text)
        assess(v, scheme)                                   # the vehicle's first assessment: caches warm
        masses = assess_times(scheme, [mass_variant(v, 1.01 + 0.01 * k + 0.1 * j) for k in range(7)])
        widths = assess_times(scheme, [width_variant(v, 0.01 * (k + 1) + 0.1 * j) for k in range(3)])   # new to the caches
        hitches = assess_times(scheme, [hitch_variant(v, 0.01 * (k + 1) + 0.1 * j) for k in range(3)])
        print(f"assess, {name}: a new mass variant median {np.median(masses) * 1e3:.0f} ms (best "
              f"{min(masses) * 1e3:.0f}, worst {max(masses) * 1e3:.0f} of 7); new bodies (body width) median "
              f"{np.median(widths) * 1e3:.0f} ms of 3; a new geometry (the first coupling moved) median "
              f"{np.median(hitches) * 1e3:.0f} ms of 3 (target <= 200 ms)")
    lcv = [sys.executable, "-m", "lcvreport.cli", "assess", "--vehicle", str(VEHICLE),
           "--scheme", str(ROOT / "examples" / "schemes" / "template.toml")]
    floor = [sys.executable, "-c", "import numpy, scipy.linalg, scipy.integrate"]
    for name, argv in (("lcv assess (B-double, template) as a command", lcv),
                       ("the floor: python importing numpy, scipy.linalg, scipy.integrate", floor)):
        times = command_times(argv, 11)
        print(f"{name}: median {np.median(times) * 1e3:.0f} ms (best {min(times) * 1e3:.0f}, worst "
              f"{max(times) * 1e3:.0f} of 11){' (target <= 500 ms)' if argv is lcv else ''}")


def command_times(argv, runs: int) -> list:
    """The wall time of each of ``runs`` runs of the command ``argv`` [s] (after one unmeasured
    run: the files in the page cache)."""
    subprocess.run(argv, check=True, capture_output=True, cwd=ROOT)
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        subprocess.run(argv, check=True, capture_output=True, cwd=ROOT)
        times.append(time.perf_counter() - t0)
    return times


def mass_variant(v, factor: float):
    """``v`` with every unit's mass times ``factor``."""
    return replace(v, units=tuple(replace(u, mass_kg=u.mass_kg * factor) for u in v.units))


def width_variant(v, more_m: float):
    """``v`` with every unit's body ``more_m`` [m] wider (a new geometry for the turn's caches)."""
    return replace(v, units=tuple(replace(u, body_width_m=(u.body_width_m or 2.5) + more_m) for u in v.units))


def hitch_variant(v, back_m: float):
    """``v`` with unit 1's rear coupling ``back_m`` [m] further back (a new geometry: every turn anew)."""
    u1 = v.units[0]
    return replace(v, units=(replace(u1, rear_coupling_m=u1.rear_coupling_m - back_m), *v.units[1:]))


def assess_times(scheme, vehicles) -> list:
    """The time of ``assess`` of each of ``vehicles`` [s]."""
    times = []
    for w in vehicles:
        t0 = time.perf_counter()
        assess(w, scheme)
        times.append(time.perf_counter() - t0)
    return times

if __name__ == "__main__":
    main()
