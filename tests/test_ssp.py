"""The SSP example (issue 20, SPEC section 15): examples/ssp/make_ssp.py writes a vehicle +
driver .ssp with pyssp-standard; libcosim and ecos run it with no parameter bindings (the
driver's start values make the lane change) to the numbers of a Jacobi master written here,
and within the co-simulation's coupling error of the package's continuous closed loop."""
from __future__ import annotations

import importlib.util
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from lcvreport.manoeuvres.drivers import DEFAULT
from lcvreport.analysis.closed_loop import closed_loop
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.units import kph_to_mps

from conftest import EXAMPLES, ROOT

H, N = 0.01, 1000


@pytest.fixture(scope="module")
def ssp(tmp_path_factory):
    spec = importlib.util.spec_from_file_location("make_ssp", ROOT / "examples" / "ssp" / "make_ssp.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.make_ssp(tmp_path_factory.mktemp("ssp"))


def _ecos(path):
    from ecospy import EcosSimulation
    with EcosSimulation(ssp_path=str(path), step_size=H) as sim:
        sim.init()
        out = [sim.get_real("vehicle::Y1")]
        for _ in range(N):
            sim.step(1)
            out.append(sim.get_real("vehicle::Y1"))
    return np.array(out)


def _libcosim(path):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimObserver import CosimObserver
    ex = CosimExecution.from_ssp_file(str(path), step_size=int(round(H * 1e9)))
    obs = CosimObserver.create_last_value()
    ex.add_observer(obs)
    name = lambda x: x.decode() if isinstance(x, bytes) else x  # noqa: E731
    idx = {name(s.name): s.index for s in ex.slave_infos()}
    vr = {name(v.name): v.reference for v in ex.slave_variables(idx["vehicle"])}
    out = [0.0]
    for _ in range(N):
        ex.step(1)
        out.append(obs.last_real_values(idx["vehicle"], [vr["Y1"]])[0])
    return np.array(out)


def _hand_master(path, tmp_path):
    """Jacobi: read every output, set every input, step both, every H (the driver's delta
    is read before its inputs change: a step's delay through the direct feedthrough)."""
    zipfile.ZipFile(path).extractall(tmp_path)
    slaves = {}
    for comp, fmu in (("vehicle", "western_doubleNative.fmu"), ("driver", "PreviewDriver.fmu")):
        f = tmp_path / "resources" / fmu
        md = read_model_description(str(f))
        s = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(f)), modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=comp)
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        slaves[comp] = (s, {v.name: v.valueReference for v in md.modelVariables})
    (veh, vv), (drv, dv) = slaves["vehicle"], slaves["driver"]
    out = [veh.getReal([vv["Y1"]])[0]]
    for k in range(N):
        y = veh.getReal([vv["Y1"], vv["psi1"]])               # every output first (Jacobi) ...
        delta = drv.getReal([dv["delta"]])
        drv.setReal([dv["Y1"], dv["psi1"]], y)                # ... then every input
        veh.setReal([vv["delta"]], delta)
        veh.doStep(k * H, H)
        drv.doStep(k * H, H)
        out.append(veh.getReal([vv["Y1"]])[0])
    for s, _ in slaves.values():
        s.terminate()
        s.freeInstance()
    return np.array(out)


def test_the_ssp_has_two_fmus_three_connections_and_no_bindings(ssp):
    names = zipfile.ZipFile(ssp).namelist()
    assert {"SystemStructure.ssd", "resources/western_doubleNative.fmu", "resources/PreviewDriver.fmu"} <= set(names)
    ssd = zipfile.ZipFile(ssp).read("SystemStructure.ssd").decode()
    assert ssd.count("<ssd:Connection ") == 3 and "ParameterBinding" not in ssd


def test_libcosim_and_ecos_run_it_as_a_hand_written_master(ssp, tmp_path):
    hand = _hand_master(ssp, tmp_path)
    ecos = _ecos(ssp)
    libcosim = _libcosim(ssp)
    scale = np.abs(hand).max()
    assert scale > 1.0                                         # the lane change of the driver's start values
    assert np.abs(ecos - hand).max() <= 1e-12 * scale
    assert np.abs(libcosim - hand).max() <= 1e-12 * scale
    # and the package's continuous closed loop, within the co-simulation's coupling error
    ref = closed_loop(load_vehicle(EXAMPLES / "western_double.toml"), kph_to_mps(88.0), DEFAULT, N * H, H)
    err = np.abs(hand - ref.Y1_m).max()
    assert 1e-5 < err < 0.02, err
