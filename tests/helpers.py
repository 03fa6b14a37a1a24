"""Test helpers: random vehicles (hypothesis), the conditioning of a simulated schedule,
and the package's own exact response to a schedule of FMU inputs (the reference)."""
from __future__ import annotations

import dataclasses

from pathlib import Path

import numpy as np
from hypothesis import strategies as st

from lcvreport.analysis.discretize import augmented_state_matrix, discretize
from lcvreport.fmu.engine import LCVEngine
from lcvreport.model.yaw_plane.equations import system_coefficients
from lcvreport.model.vehicle import Axle, Unit, Vehicle

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "vehicles"
EPS = np.finfo(float).eps
#: the factor between a measured condition number times eps and a test tolerance: random
#: perturbation directions underestimate the worst one (~sqrt(n)), two implementations
#: each contribute, and rounding accumulates over the steps of a schedule
KAPPA_SAFETY = 10.0


# ---------------------------------------------------------------------------- random vehicles
def random_vehicle(n_units: int, rng: np.random.Generator, cm: bool = True) -> Vehicle:
    """A physically plausible random chain of ``n_units`` units (SI): tractor, then
    alternating semitrailers and dollies, random axles per unit."""
    units = []
    for k in range(n_units):
        def axle(name, x, tires, steered=False):
            return Axle(name, x, tires, rng.uniform(1.0e5, 3.0e5) if tires == 2 else rng.uniform(0.8e5, 1.4e5),
                        rng.uniform(1e3, 1.0e4) if cm else 0.0, rng.uniform(1e5, 3e5) if cm else 0.0,
                        0.3 if tires > 2 else 0.0, steered, rng.uniform(2e4, 9e4))
        last = k == n_units - 1
        if k == 0:
            axles = (axle("s", rng.uniform(1.5, 3.0), 2, True),) + tuple(
                axle(f"d{j}", -rng.uniform(1.0, 4.0) - 1.3 * j, 4) for j in range(rng.integers(1, 3)))
            units.append(Unit("u1", rng.uniform(5e3, 1.5e4), rng.uniform(2e4, 6e4), axles, None,
                              None if last else -rng.uniform(1.5, 3.0)))
        elif k % 2 == 1:  # semitrailer
            axles = tuple(axle(f"t{k}_{j}", -rng.uniform(2.0, 4.0) - 1.3 * j, 4) for j in range(rng.integers(1, 4)))
            units.append(Unit(f"u{k + 1}", rng.uniform(3e3, 2.5e4), rng.uniform(5e4, 2.5e5), axles,
                              rng.uniform(1.5, 4.0), None if last else -rng.uniform(1.5, 5.0)))
        else:  # converter dolly
            axles = (axle(f"c{k}", -rng.uniform(0.0, 0.3), 4),)
            units.append(Unit(f"u{k + 1}", rng.uniform(700, 2.5e3), rng.uniform(200, 800), axles,
                              rng.uniform(1.5, 2.5), None if last else -rng.uniform(0.0, 0.15)))
    return Vehicle(f"random{n_units}", tuple(units))


@st.composite
def vehicles(draw, min_units: int = 1, max_units: int = 7, cm: bool = True):
    n = draw(st.integers(min_units, max_units))
    seed = draw(st.integers(0, 2**32 - 1))
    return random_vehicle(n, np.random.default_rng(seed), cm=cm)


speeds = st.floats(min_value=2.0, max_value=35.0, allow_nan=False)  # m/s (7..126 km/h)


# ---------------------------------------------------------------------------- schedules
def held_inputs(itf, steps: list[tuple[float, dict]]) -> list[np.ndarray]:
    """The full SI input vector (interface order) held over each step."""
    names = [v.name for v in itf.inputs]
    w = np.array([float(v.start) for v in itf.inputs])
    out = []
    for _h, inputs in steps:
        for k, val in inputs.items():
            w[names.index(k)] = val
        out.append(w.copy())
    return out


def reference_outputs(itf, steps, preset=None, tire_scale: float = 1.0, u_min: float = 2.2352,
                      perturb: tuple | None = None) -> np.ndarray:
    """The package's exact response (scipy's expm of the augmented matrix) to a schedule,
    as FMU outputs before max_real_eig and ay (interface order of the linear and y outputs),
    after every step.  ``perturb = (rng, delta)`` perturbs every coefficient of the
    model and of the input map componentwise by a relative ``delta`` (random signs)."""
    eng = LCVEngine(itf, preset, tire_scale, u_min)
    co, maps = eng.co, eng.maps()
    arrays = {k: np.array(getattr(co, k)) for k in ("M0", "M1", "S0", "Sinv", "Su", "Skin")}
    Bw = maps["Bw"].copy()
    for k, var in enumerate(itf.inputs):
        if var.source[0] == "steer":
            Bw[:, k] *= tire_scale
    if perturb is not None:
        rng, delta = perturb
        for k in arrays:
            arrays[k] *= 1 + delta * rng.choice([-1.0, 1.0], arrays[k].shape)
        Bw *= 1 + delta * rng.choice([-1.0, 1.0], Bw.shape)
    pco = dataclasses.replace(co, **arrays)            # either model: its other fields as they are
    cache = {}
    z = np.zeros(co.n_states + 2)
    rows = []
    for (h, _), w in zip(steps, held_inputs(itf, steps)):
        u = max(w[0], u_min)
        if (u, h) not in cache:
            A, G = augmented_state_matrix(pco, u, tire_scale)
            cache[(u, h)] = discretize(A, G, h)
        Ad, Gd = cache[(u, h)]
        z = Ad @ z + Gd @ (Bw @ w)
        out = maps["C"] @ z + maps["W"] @ np.sin(maps["H"] @ z)
        rows.append(out)
    return np.array(rows)


def output_groups(itf) -> list[list[int]]:
    """Output indices compared on a common scale: velocity, yaw rates, angles, lengths.

    A quantity that is the small residue of cancelling terms (v1 when only trailer 3
    is loaded) carries rounding set by the size of the terms it is made of, so each
    output is compared relative to the peak of its group."""
    groups = {"speed": [], "rate": [], "angle": [], "length": []}
    for o, v in enumerate(itf.outputs):
        if v.quantity in groups and v.source[0] in ("state", "y", "psi1", "Y1", "Y_rear"):
            groups[v.quantity].append(o)
    return [g for g in groups.values() if g]


def group_error(actual: np.ndarray, ref: np.ndarray, itf) -> tuple[float, str]:
    """Largest |actual - ref| relative to the peak of the output's group, and that output's name."""
    worst, name = 0.0, ""
    for g in output_groups(itf):
        scale = max(np.abs(ref[:, g]).max(), 1e-300)
        err = np.abs(actual[:, g] - ref[:, g]).max(axis=0) / scale
        k = int(np.argmax(err))
        if err[k] > worst:
            worst, name = float(err[k]), itf.outputs[g[k]].name
    return worst, name


def schedule_condition(itf, steps, preset=None, tire_scale: float = 1.0, samples: int = 4,
                       delta: float = 1e-8, seed: int = 0) -> float:
    """Measured condition number of a schedule's outputs: the largest group-relative
    output change per relative componentwise perturbation ``delta`` of the model's
    coefficients, over a few random perturbations (the sensitivity any backward-stable
    implementation's rounding is amplified by)."""
    base = reference_outputs(itf, steps, preset, tire_scale)
    rng = np.random.default_rng(seed)
    kappa = 0.0
    for _ in range(samples):
        pert = reference_outputs(itf, steps, preset, tire_scale, perturb=(rng, delta))
        kappa = max(kappa, group_error(pert, base, itf)[0] / delta)
    return kappa


def tolerance(kappa: float) -> float:
    """The tolerance of a comparison of two implementations: KAPPA_SAFETY * kappa * eps."""
    return KAPPA_SAFETY * max(kappa, 1.0) * EPS


def schedule(rng: np.random.Generator, n_steps: int, step_sizes, axles, changes: int = 6, clamp: bool = False,
             P: str = "P{}", T: str = "T{}"):
    """Random (h, inputs) steps: speed, steer angle, P and T change a few times mid-run."""
    steps = []
    change_at = set(rng.choice(np.arange(1, n_steps), size=changes, replace=False).tolist())
    for k in range(n_steps):
        h = float(rng.choice(step_sizes))
        inputs = {}
        if k == 0 or k in change_at:
            inputs["u"] = float(rng.choice([22.352, 13.4112, 31.2928, 8.9408] + ([1.0, 0.0] if clamp else [])))
            inputs["delta"] = float(rng.normal(0, 2e-3))
            for a in axles:
                inputs[P.format(a)] = float(rng.normal(0, 500.0))
                inputs[T.format(a)] = float(rng.normal(0, 300.0))
        steps.append((h, inputs))
    return steps


def chain_on_circle_by_root_finding(vehicle: Vehicle, beta, radius_m: float):
    """An independent construction of SPEC 12's steady-turn geometry (corrected 2026-12), in world
    coordinates with brentq: the turn centre O at the origin; unit 1's axis at R from O (O at
    (-beta_1 R, R) in its frame); every next unit placed so that its front coupling is the point
    of the unit ahead's rear coupling and O lies at (-beta d, d) in its frame, d found by brentq on
    the coupling's radius.  Returns a function radius(unit, x) [m] of any point of any unit."""
    from scipy.optimize import brentq
    beta = np.asarray(beta, dtype=float)

    def rot(phi, p):
        c, s = np.cos(phi), np.sin(phi)
        return np.array([c * p[0] - s * p[1], s * p[0] + c * p[1]])
    cg, phi = [np.array([beta[0] * radius_m, -radius_m])], [0.0]
    for k in range(vehicle.n_units - 1):
        P = cg[k] + rot(phi[k], (vehicle.units[k].rear_coupling_m, 0.0))
        xf, b = vehicle.units[k + 1].front_coupling_m, beta[k + 1]
        rho = float(np.hypot(*P))
        d = brentq(lambda d: (xf + b * d) ** 2 + d * d - rho * rho, 1e-9, 2 * rho + abs(xf) + 1.0, xtol=1e-14)
        local = (xf + b * d, -d)
        ph = np.arctan2(P[1], P[0]) - np.arctan2(local[1], local[0])
        cg.append(P - rot(ph, (xf, 0.0)))
        phi.append(ph)
    return lambda unit, x: float(np.hypot(*(cg[unit] + rot(phi[unit], (x, 0.0)))))


def steady_turn_newton_euler(vehicle: Vehicle, speed_mps: float, yaw_rate: float):
    """An independent steady turn of the linear yaw-plane model: Newton-Euler for every unit with
    the joint forces explicit (not the package's virtual-power builder), every unit at the yaw
    rate ``yaw_rate`` and the forward speed u.  Unknowns: the CG lateral velocities v_i, the
    articulation angles theta_k, the joint forces F_k (on unit k+1 at its front coupling, along
    +y; minus that on unit k) and the steer delta.  Returns (v [m/s] per unit, delta [rad])."""
    n, u, w = vehicle.n_units, float(speed_mps), float(yaw_rate)
    nv, nth, nF = n, n - 1, n - 1
    size = nv + nth + nF + 1
    A, rhs = np.zeros((size, size)), np.zeros(size)
    iv, ith, iF, idl = 0, nv, nv + nth, nv + nth + nF
    row = 0
    for i, unit in enumerate(vehicle.units):
        fy, mz = np.zeros(size), np.zeros(size)      # lateral force and yaw moment about the CG, linear in unknowns
        const_f, const_m = 0.0, 0.0
        for a in unit.axles:
            C, CM, CSD2 = a.cornering_stiffness_axle_N_per_rad, a.aligning_stiffness_axle_Nm_per_rad, \
                a.dual_yaw_damping_axle_N_m2
            # alpha = delta (steered) - (v_i + x w)/u; F = C alpha; M = -CM alpha; dual -CSD2 w / u
            fy[iv + i] -= C / u
            const_f -= C * a.x_m * w / u
            mz[iv + i] -= (C * a.x_m - CM) / u
            const_m -= (C * a.x_m - CM) * a.x_m * w / u + CSD2 * w / u
            if a.steered:
                fy[idl] += C
                mz[idl] += C * a.x_m - CM
        if i > 0:                                    # the joint force from the unit ahead, at the front coupling
            fy[iF + i - 1] += 1.0
            mz[iF + i - 1] += unit.front_coupling_m
        if i < n - 1:                                # its reaction, at the rear coupling
            fy[iF + i] -= 1.0
            mz[iF + i] -= unit.rear_coupling_m
        A[row], rhs[row] = fy, unit.mass_kg * u * w - const_f          # m (v' + u r) = sum F, steady
        A[row + 1], rhs[row + 1] = mz, -const_m                        # I r' = sum M = 0, steady
        row += 2
    for k in range(n - 1):                            # v_(k+1) = v_k + x_r,k w - x_f,k+1 w + u theta_k
        A[row, iv + k + 1], A[row, iv + k], A[row, ith + k] = 1.0, -1.0, -u
        rhs[row] = (vehicle.units[k].rear_coupling_m - vehicle.units[k + 1].front_coupling_m) * w
        row += 1
    sol = np.linalg.solve(A, rhs)
    return sol[iv:iv + nv], float(sol[idl])


#: the child's SIGINT at its default, as in a terminal: a runner started in the background (``cmd &``
#: in a script) passes SIGINT ignored to its children, and Python then installs no Ctrl-C handler
_DEFAULT_SIGINT = "import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); os.execv(sys.argv[1], sys.argv[1:])"


def with_default_sigint(cmd: list) -> list:
    """``cmd`` run with SIGINT at its default disposition whatever this process inherited (the
    Ctrl-C tests test what a user at a terminal gets)."""
    import sys
    return [sys.executable, "-c", _DEFAULT_SIGINT, *[str(c) for c in cmd]]
