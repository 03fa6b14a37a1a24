"""Helpers for the FMU tests: build/locate FMUs, drive them by hand, and the
package's exact response for the same held inputs (the reference)."""
from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)

from lcvreport.cosim import INPUT_NAMES, OUTPUT_NAMES
from lcvreport.linear import TimeResponse, rear_displacements, simulate
from lcvreport.loads import ResidualLoads, load_vector
from lcvreport.model import system_coefficients
from lcvreport.presets import load_preset

ROOT = Path(__file__).resolve().parents[1]
BUILD = ROOT / "build"
# conversion factors typed here, independently of lcvreport.units
M_PER_IN = 0.0254
N_PER_LBF = 4.4482216152605
NM_PER_LBF_FT = 1.3558179483314004
AXLES = ("11", "12", "13", "21", "31", "41", "51", "61")


def fmu_path(name: str = "LCV") -> Path:
    """Path of build/<name>.fmu, built by ./build.sh fmu (built here if missing)."""
    path = BUILD / f"{name}.fmu"
    if not path.exists():
        subprocess.run([sys.executable, "-m", "lcvreport.fmu_build", "--out", str(BUILD)], check=True, cwd=ROOT)
    assert path.exists(), f"{path} missing: run ./build.sh fmu"
    return path


class LogCapture:
    """fmi2 callbacks whose logger records (status, category, message)."""

    def __init__(self):
        self.records: list[tuple[int, str, str]] = []

        def log(_env, _instance, status, category, message):
            self.records.append((status, (category or b"").decode(), (message or b"").decode()))

        libc = ctypes.CDLL(None)
        libc.calloc.restype = ctypes.c_void_p
        libc.calloc.argtypes = [ctypes.c_size_t, ctypes.c_size_t]
        libc.free.argtypes = [ctypes.c_void_p]
        self._keep = [fmi2CallbackLoggerTYPE(log), fmi2CallbackAllocateMemoryTYPE(libc.calloc),
                      fmi2CallbackFreeMemoryTYPE(libc.free)]
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger, self.callbacks.allocateMemory, self.callbacks.freeMemory = self._keep

    def messages(self, min_status: int = 0) -> list[str]:
        return [m for s, _c, m in self.records if s >= min_status]


class Slave:
    """An FMU2Slave instance with variable look-up by name and a log capture."""

    _unzipped: dict = {}

    def __init__(self, path: Path, instance: str = "lcv", **start):
        path = Path(path)
        if path not in Slave._unzipped:
            Slave._unzipped[path] = (read_model_description(str(path)), extract(str(path)))
        self.md, unzipdir = Slave._unzipped[path]
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.log = LogCapture()
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance)
        self.fmu.instantiate(callbacks=self.log.callbacks, loggingOn=True)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in start.items():
            if isinstance(v, str):
                self.fmu.setString([self.vr[k]], [v])
            else:
                self.fmu.setReal([self.vr[k]], [float(v)])

    def init(self):
        self.fmu.exitInitializationMode()
        return self

    def set(self, **values):
        self.fmu.setReal([self.vr[k] for k in values], [float(v) for v in values.values()])

    def get(self, names=OUTPUT_NAMES) -> np.ndarray:
        return np.array(self.fmu.getReal([self.vr[n] for n in names]))

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def run_schedule(slave: Slave, steps: list[tuple[float, dict]], t0: float = 0.0) -> np.ndarray:
    """Drive ``slave`` through ``(h, inputs)`` steps; return outputs before and after every step."""
    out = [slave.get()]
    t = t0
    for h, inputs in steps:
        if inputs:
            slave.set(**inputs)
        slave.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        out.append(slave.get())
    return np.array(out)


def held_inputs(steps: list[tuple[float, dict]]) -> list[dict]:
    """The full SI input vector held over each step (inputs keep their value until set)."""
    current = {n: 0.0 for n in INPUT_NAMES}
    current["u"] = 22.352
    held = []
    for _h, inputs in steps:
        current.update(inputs)
        held.append(dict(current))
    return held


def reference_outputs(preset: str, steps: list[tuple[float, dict]], tire_scale: float = 1.0,
                      u_min: float = 2.2352) -> np.ndarray:
    """The package's exact response to the same held inputs, as SI FMU outputs."""
    train = load_preset(preset)
    co = system_coefficients(train)
    names = train.axle_names
    t = np.concatenate([[0.0], np.cumsum([h for h, _ in steps])])
    speeds, forces = [], []
    for w in held_inputs(steps):
        speeds.append(max(w["u"], u_min) / M_PER_IN)
        loads = ResidualLoads({a: w[f"P{a}"] / N_PER_LBF for a in AXLES if a in names},
                              {a: w[f"T{a}"] / NM_PER_LBF_FT for a in AXLES if a in names})
        forces.append(load_vector(train, loads, "consistent") + co.B_delta(tire_scale) * w["delta"])
    r = simulate(train, t, np.array(speeds), np.array(forces), tire_scale=tire_scale)
    return response_to_outputs(r)


def response_to_outputs(r: TimeResponse) -> np.ndarray:
    """SI outputs v1, r1..r6, thetaA..E, y2..y6, psi1, Y1, Y_rear (max_real_eig left out)."""
    n = r.train.n_units
    out = np.zeros((r.time.size, len(OUTPUT_NAMES) - 1))
    out[:, 0] = r["v1"] * M_PER_IN
    out[:, 1:1 + n] = r.states[:, 1:1 + n]
    out[:, 7:7 + n - 1] = r.theta
    out[:, 12:12 + n - 1] = rear_displacements(r.train, r.theta) * M_PER_IN
    out[:, 17] = r["psi1"]
    out[:, 18] = r["Y1"] * M_PER_IN
    out[:, 19] = r["Y_rear"] * M_PER_IN
    return out


#: outputs compared on a common scale: a quantity that is the small residue of cancelling
#: terms (v1 or Y1 when only trailer 3 is loaded) carries rounding errors set by the size of
#: the terms, not by its own size.  Measured: the native and the scipy step matrices are
#: both within 4e-14 (row-relative) of a 40-digit reference, yet Y1 of the two FMUs differed
#: by 6e-9 of Y1's own peak in a clamped low-speed run -- 1e-13 of the lengths' scale.
GROUPS = {"velocity": ("v1",), "rates": tuple(f"r{i}" for i in range(1, 7)),
          "angles": tuple(f"theta{j}" for j in "ABCDE") + ("psi1",),
          "lengths": tuple(f"y{k}" for k in range(2, 7)) + ("Y1", "Y_rear")}


def assert_outputs_close(actual: np.ndarray, ref: np.ndarray, rtol: float = 1e-9):
    """Every output within ``rtol`` of the peak magnitude of its group over the run
    (velocity, yaw rates, angles, lengths: see :data:`GROUPS`)."""
    actual = actual[:, :ref.shape[1]]
    peak = np.abs(ref).max(axis=0)
    scale = np.ones_like(peak)
    for members in GROUPS.values():
        idx = [OUTPUT_NAMES.index(m) for m in members if OUTPUT_NAMES.index(m) < ref.shape[1]]
        scale[idx] = max(peak[idx].max(), 1e-300)
    err = np.abs(actual - ref).max(axis=0) / scale
    worst = int(np.argmax(err))
    assert err.max() <= rtol, f"{OUTPUT_NAMES[worst]}: error {err.max():.3e} of its group's peak"
    assert np.all(np.isfinite(actual))
    if ref.shape[1] == len(OUTPUT_NAMES):  # max_real_eig: its own scale
        np.testing.assert_allclose(actual[:, -1], ref[:, -1], rtol=rtol)


def schedule(rng: np.random.Generator, n_steps: int, step_sizes, changes: int = 6, clamp: bool = False):
    """Random (h, inputs) steps: speed, steer angle, P and T change a few times mid-run."""
    steps = []
    change_at = set(rng.choice(np.arange(1, n_steps), size=changes, replace=False).tolist())
    for k in range(n_steps):
        h = float(rng.choice(step_sizes))
        inputs = {}
        if k == 0 or k in change_at:
            inputs["u"] = float(rng.choice([22.352, 13.4112, 31.2928, 8.9408] + ([1.0, 0.0] if clamp else [])))
            inputs["delta"] = float(rng.normal(0, 2e-3))
            for a in AXLES:
                inputs[f"P{a}"] = float(rng.normal(0, 500.0))
                inputs[f"T{a}"] = float(rng.normal(0, 300.0))
        steps.append((h, inputs))
    return steps


def env_without_python_path() -> dict:
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    return env
