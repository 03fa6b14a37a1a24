"""Driving FMUs from the tests: fmpy's FMU2Slave with a log capture and look-up by name,
the C host, and running a schedule of inputs."""
from __future__ import annotations

import ctypes
import os
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE)

from lcvreport.fmu.interface import preset_interface, vehicle_interface
from lcvreport.model.vehicle_file import loads_vehicle


def interface_of(path: Path):
    """The interface table an FMU was built from (preset FMUs: SPEC 5; else its vehicle)."""
    names = zipfile.ZipFile(path).namelist()
    root = ET.fromstring(zipfile.ZipFile(path).read("modelDescription.xml"))
    if "resources/vehicle.toml" in names:
        u_start = next(float(sv[0].get("start")) for sv in root.iter("ScalarVariable") if sv.get("name") == "u")
        names = {sv.get("name") for sv in root.iter("ScalarVariable")}
        model = "yaw_roll" if "phi1" in names else "nonlinear" if "friction_coefficient" in names else "yaw_plane"
        return vehicle_interface(loads_vehicle(zipfile.ZipFile(path).read("resources/vehicle.toml").decode()),
                                 u_start, model)
    if any(sv.get("name") == "preset" for sv in root.iter("ScalarVariable")):
        return preset_interface()
    raise AssertionError(f"{path}: not an FMU of this project")


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
        self.md, self.unzipdir = Slave._unzipped[path]
        self.itf = interface_of(path)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.outputs = [v.name for v in self.itf.outputs]
        self.log = LogCapture()
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.unzipdir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance)
        self.fmu.instantiate(callbacks=self.log.callbacks, loggingOn=True)
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        for k, v in start.items():
            if isinstance(v, str):               # preset by name: the String path FMUs keep accepting
                self.fmu.setString([self.vr[k]], [v])
            elif isinstance(v, int) and not isinstance(v, bool):   # preset, the Enumeration
                self.fmu.setInteger([self.vr[k]], [v])
            else:
                self.fmu.setReal([self.vr[k]], [float(v)])

    def init(self):
        self.fmu.exitInitializationMode()
        return self

    def set(self, **values):
        self.fmu.setReal([self.vr[k] for k in values], [float(v) for v in values.values()])

    def get(self, names=None) -> np.ndarray:
        return np.array(self.fmu.getReal([self.vr[n] for n in (names or self.outputs)]))

    def free(self):
        self.fmu.terminate()
        self.fmu.freeInstance()


def run_schedule(slave: Slave, steps: list[tuple[float, dict]], t0: float = 0.0) -> np.ndarray:
    """Drive ``slave`` through ``(h, inputs)`` steps; return every output after every step."""
    out = []
    t = t0
    for h, inputs in steps:
        if inputs:
            slave.set(**inputs)
        slave.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        t += h
        out.append(slave.get())
    return np.array(out)


def unzip(path: Path, dest: Path) -> tuple[Path, str, dict]:
    """Extract an FMU; return the folder, its guid and the value references by name."""
    zipfile.ZipFile(path).extractall(dest)
    root = ET.parse(dest / "modelDescription.xml").getroot()
    vr = {sv.get("name"): int(sv.get("valueReference")) for sv in root.iter("ScalarVariable")}
    return dest, root.get("guid"), vr


def host_env() -> dict:
    """The environment of a plain C host: nothing of the test's Python leaks in."""
    return {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "PYTHONPATH", "PYTHONHOME",
                                                             "VIRTUAL_ENV")}


def run_host(c_host: Path, unzipped: tuple, identifier: str, script: str, timeout: float = 300,
             wrapper: list[str] | None = None, env: dict | None = None) -> subprocess.CompletedProcess:
    d, guid, _ = unzipped
    return subprocess.run([*(wrapper or []), str(c_host), str(d), identifier, guid, "script"], input=script,
                          capture_output=True, text=True, env=env or host_env(), timeout=timeout)


def host_values(stdout: str) -> np.ndarray:
    return np.array([line.split()[2:] for line in stdout.splitlines() if line.startswith("values")], dtype=float)


def host_statuses(stdout: str) -> list[int]:
    return [int(line.split()[1]) for line in stdout.splitlines() if line.startswith("status")]
