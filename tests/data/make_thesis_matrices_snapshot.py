"""Snapshot of the thesis-unit matrices built by commit 7c31b7f (before the SI core)."""
import numpy as np
from lcvreport.presets import PRESETS, load_preset
from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.loads import one_percent_rule, load_vector
out = {}
speeds_in_per_s = np.array([88.0, 528.0, 880.0, 1232.0])  # 5, 30, 50, 70 mph
for name in PRESETS:
    for masses in ("table", "unrounded"):
        if masses == "unrounded" and name not in ("aucnat", "tractor_semitrailer"):
            continue
        t = load_preset(name, masses=masses)
        co = system_coefficients(t)
        key = f"{name}/{masses}"
        out[f"{key}/M"] = co.M(speeds_in_per_s)
        out[f"{key}/S"] = co.S(speeds_in_per_s, 1.0)
        out[f"{key}/S_scale0.8"] = co.S(speeds_in_per_s, 0.8)
        out[f"{key}/B_delta"] = co.B_delta(1.0)
        out[f"{key}/B_P"] = co.B_P
        out[f"{key}/B_T"] = co.B_T
        units = [u.name for u in t.units[1:]]
        out[f"{key}/F_consistent"] = load_vector(t, one_percent_rule(t, units), "consistent")
        out[f"{key}/F_thesis"] = load_vector(t, one_percent_rule(t, units), "thesis")
out["speeds_in_per_s"] = speeds_in_per_s
np.savez_compressed("tests/data/thesis_matrices_7c31b7f.npz", **out)
print(len(out), "arrays")
