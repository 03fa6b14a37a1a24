"""Write examples/ssp/lane_change.ssp: a vehicle FMU and the driver FMU in a closed loop.

    python examples/ssp/make_ssp.py [OUT_DIR]        (from the repository root; default examples/ssp/build)

The vehicle is examples/vehicles/western_double.toml as a native FMU (lcv fmu, u starting at
88 km/h), the driver the path-following driver FMU of this repository
(lcvreport.fmu.driver), both FMI 2.0 Co-Simulation.  The System Structure is written with
pyssp-standard (a maintained SSP library): two components, three connections
(vehicle.Y1 -> driver.Y1, vehicle.psi1 -> driver.psi1, driver.delta -> vehicle.delta), a
default experiment of 10 s.  No parameter bindings: every parameter runs at its start value
(the driver's make a 1.5 m lane change from 1 s over 3 s).
"""
from __future__ import annotations

import shutil
import sys
import tempfile
from pathlib import Path

from pyssp_standard.ssd import Component, Connection, Connector, DefaultExperiment, System
from pyssp_standard.ssp import SSP

from lcvreport.fmu.build import build_vehicle_fmus
from lcvreport.fmu.driver import build_driver_fmu
from lcvreport.model.vehicle_file import load_vehicle
from lcvreport.units import kph_to_mps

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
SPEED_KPH = 88.0
STOP_S = 10.0


def _component(name: str, source: str, connectors: list[tuple[str, str]]) -> Component:
    c = Component()
    c.name = name
    c.source = source
    c.component_type = "application/x-fmu-sharedlibrary"
    c.connectors = [Connector(name=n, kind=k) for n, k in connectors]
    return c


def make_ssp(out_dir: Path) -> Path:
    """Build both FMUs and write ``<out_dir>/lane_change.ssp``; return its path."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    vehicle = load_vehicle(ROOT / "examples" / "vehicles" / "western_double.toml")
    with tempfile.TemporaryDirectory() as tmp:
        veh_fmu = build_vehicle_fmus(vehicle, tmp, kind="native", u_start_mps=kph_to_mps(SPEED_KPH))[0]
        drv_fmu = build_driver_fmu(tmp)
        path = out_dir / "lane_change.ssp"
        if path.exists():
            path.unlink()
        with SSP(path, mode="w") as ssp:
            ssp.add_resource(veh_fmu)
            ssp.add_resource(drv_fmu)
            with ssp.system_structure as ssd:
                ssd.name = "lane_change"
                ssd.version = "1.0"
                system = System(name="lane_change")
                system.elements = [
                    _component("vehicle", f"resources/{veh_fmu.name}",
                               [("delta", "input"), ("Y1", "output"), ("psi1", "output")]),
                    _component("driver", f"resources/{drv_fmu.name}",
                               [("Y1", "input"), ("psi1", "input"), ("delta", "output")]),
                ]
                system.connections = [
                    Connection(start_element="vehicle", start_connector="Y1", end_element="driver", end_connector="Y1"),
                    Connection(start_element="vehicle", start_connector="psi1", end_element="driver",
                               end_connector="psi1"),
                    Connection(start_element="driver", start_connector="delta", end_element="vehicle",
                               end_connector="delta"),
                ]
                ssd.system = system
                experiment = DefaultExperiment()
                experiment.start_time, experiment.stop_time = 0.0, STOP_S
                ssd.default_experiment = experiment
    return path


if __name__ == "__main__":
    print(make_ssp(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "build"))
