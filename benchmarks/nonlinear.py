"""Benchmark: the nonlinear planar model (SPEC 18, docs/nonlinear.md) against section 18's targets,
beside what the same work costs on the linear model and a straightforward twin written here.

- the 90 degree turn at 5 km/h of a 6-unit combination (the ``legal_max`` preset) with the
  path-following law (``turn_with_tire_forces``): target <= 1 s;
- a 12 s single sine (0.01 rad, 0.4 Hz) at 88 km/h on the western double through ``integrate``:
  target <= 0.3 s; beside it the same run through scipy's ``solve_ivp`` (Radau, the same tolerances)
  on a right-hand side written here in plain numpy from the model's ``derivatives`` one state at a
  time (what a user writing it beside the package would run), and the linear model's exact response;
- the nonlinear family's measures of one vehicle (``measure_values(..., model="nonlinear")`` of
  the response keys and the friction demand): target <= 2 s;
- what dominates: the count of evaluations of the equations and the cost of one.

Each timing is the best of ``REPEATS`` in one process, one BLAS thread, the caches cleared between
repeats (a new vehicle each time would time the same).

    python benchmarks/nonlinear.py
"""
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")    # before numpy is imported

import time  # noqa: E402

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

from lcvreport import load_preset  # noqa: E402
from lcvreport.analysis.exact import response  # noqa: E402
from lcvreport.analysis.integrate import integrate  # noqa: E402
from lcvreport.manoeuvres.steer import sine  # noqa: E402
from lcvreport.measures import friction_demand, low_speed  # noqa: E402
from lcvreport.measures.measure_set import measure_values  # noqa: E402
from lcvreport.model.nonlinear.model import nonlinear_model  # noqa: E402
from lcvreport.model.vehicle_file import load_vehicle  # noqa: E402

REPEATS = 3
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def best(fn, repeats: int = REPEATS, clear=()) -> tuple[float, object]:
    out, times = None, []
    for _ in range(repeats):
        for c in clear:
            c.cache_clear()
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    caches = (friction_demand.turn_with_tire_forces, low_speed.low_speed_turn)
    six = load_preset("legal_max")
    t_turn, turn = best(lambda: friction_demand.turn_with_tire_forces(six), clear=caches)
    t_kin, _ = best(lambda: low_speed.low_speed_turn(six), clear=caches)
    print(f"90 deg turn, 5 km/h, {six.name} ({six.n_units} units): {t_turn:.2f} s (target <= 1 s); "
          f"stfd {turn.stfd:.4f}, path error {turn.path_error_max_m * 1e3:.1f} mm; "
          f"{turn.response.evaluations} evaluations; "
          f"the kinematic turn alone {t_kin:.2f} s")

    v = load_vehicle(os.path.join(ROOT, "examples", "vehicles", "western_double.toml"))
    m = nonlinear_model(v)
    u = 88 / 3.6
    t_sine, r = best(lambda: integrate(m, sine(0.01, 0.4), u, 12.0, 0.01))
    x, w = np.zeros(m.n_states), m.zero_input()
    n_eval = 2000
    t0 = time.perf_counter()
    for _ in range(n_eval):
        m.derivatives(0.0, x, w, u)
    per_eval = (time.perf_counter() - t0) / n_eval
    X = np.zeros((m.n_states, 40))
    t0 = time.perf_counter()
    for _ in range(200):
        m.derivatives(0.0, X.T, w, u)
    per_batch = (time.perf_counter() - t0) / 200

    steer = sine(0.01, 0.4)

    def plain():                                 # the straightforward twin: one state per call
        def rhs(t, z):
            ww = w.copy()
            ww[0] = float(steer.delta(t)[0])
            return m.derivatives(t, z, ww, u)
        for a, b in ((0.0, 2.5), (2.5, 12.0)):
            sol = solve_ivp(rhs, (a, b), np.zeros(m.n_states) if a == 0 else sol.y[:, -1], method="Radau",
                            rtol=1e-8, atol=1e-10)
        return sol
    t_plain, _ = best(plain, repeats=1)
    t_exact, _ = best(lambda: response(v, u, sine(0.01, 0.4), 12.0, 0.01))
    print(f"12 s single sine, 88 km/h, {v.name}: {t_sine:.2f} s through integrate (target <= 0.3 s), "
          f"{r.evaluations} evaluations; plain solve_ivp twin {t_plain:.2f} s; the linear model's exact response "
          f"{t_exact * 1e3:.1f} ms")
    print(f"  one evaluation of the equations: {per_eval * 1e6:.0f} us; a batch of 40 states: "
          f"{per_batch * 1e6:.0f} us ({per_batch / per_eval / 40:.2f} of 40 single calls)")
    keys = ["ra_single_sine", "hsto_m", "ra_lane_change_driver", "yaw_damping_coefficient", "stfd",
            "friction_demand_drive"]
    b = load_vehicle(os.path.join(ROOT, "examples", "vehicles", "b_double.toml"))
    t_meas, vals = best(lambda: measure_values(b, u, keys, model="nonlinear"), repeats=1, clear=caches)
    print(f"the nonlinear family's measures of {b.name}: {t_meas:.2f} s (target <= 2 s): "
          + ", ".join(f"{k} {vals[k]:.4g}" if vals[k] is not None else f"{k} null" for k in keys))


if __name__ == "__main__":
    main()
