"""Where the linear answer stops: HSTO and rearward amplification of the closed-loop lane change
(``hsto_driver_m``, ``ra_lane_change_driver``: the preview driver on the lane change's path,
docs/measures.md) over the lane change's lateral acceleration A0 from 0.05 to 0.4 g, on the linear
yaw-plane model and on the nonlinear planar model (saturating brush tires, mu 0.8,
docs/nonlinear.md), for every example vehicle at 88 km/h.

Writes ``docs/figures/nonlinear_lane_change.csv`` (one row per vehicle, model and A0) and
``docs/figures/nonlinear_lane_change.png``; docs/nonlinear.md shows both.

    python examples/nonlinear_lane_change.py
"""
from __future__ import annotations

import csv
import os
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lcvreport.measures.measure_set import measure_values  # noqa: E402
from lcvreport.model.vehicle_file import load_vehicle  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "figures"
SPEED_MPS = 88 / 3.6
A0_G = (0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4)
NAMES = ("b_double", "western_double", "truck_full_trailer")
MODELS = ("yaw_plane", "nonlinear")
KEYS = ("hsto_driver_m", "ra_lane_change_driver")


def compute() -> list[dict]:
    rows = []
    for name in NAMES:
        v = load_vehicle(ROOT / "examples" / "vehicles" / f"{name}.toml")
        for model in MODELS:
            for a0 in A0_G:
                why: dict = {}
                vals = measure_values(v, SPEED_MPS, KEYS, conditions={"lane_change_ay_g": a0}, model=model,
                                      reasons=why)
                rows.append({"vehicle": name, "model": model, "lane_change_ay_g": a0,
                             **{k: ("" if vals[k] is None else repr(float(vals[k]))) for k in KEYS},
                             "reason": "; ".join(why.values())})
                print(name, model, a0, vals)
    return rows


def draw(rows: list[dict]):
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    colours = dict(zip(NAMES, ("C0", "C1", "C2")))
    for ax, key, label in zip(axes, KEYS, ("HSTO, closed-loop driver [m]", "rearward amplification, closed-loop [-]")):
        for name in NAMES:
            for model, style in zip(MODELS, ("--", "-")):
                pts = [(r["lane_change_ay_g"], float(r[key])) for r in rows
                       if r["vehicle"] == name and r["model"] == model and r[key] != ""]
                if pts:
                    x, y = np.array(pts).T
                    ax.plot(x, y, style, marker="o", ms=3, color=colours[name],
                            label=f"{name}, {model.replace('_', ' ')}")
        ax.set_xlabel("lane change lateral acceleration A0 [g]")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("Linear yaw plane (dashed) and nonlinear planar model (solid, brush tires, mu 0.8), 88 km/h")
    fig.tight_layout()
    return fig


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    rows = compute()
    with open(OUT / "nonlinear_lane_change.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fig = draw(rows)
    fig.savefig(OUT / "nonlinear_lane_change.png", dpi=110, metadata={"Software": None})
    print(f"wrote {OUT / 'nonlinear_lane_change.csv'} and {OUT / 'nonlinear_lane_change.png'}")


if __name__ == "__main__":
    main()
