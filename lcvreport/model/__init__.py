"""The model core: vehicles (SI parameter sets and vehicle files), presets, the builder
of M, S and the input matrices for any chain of units, residual loads.  numpy only."""
from .yaw_plane.equations import SystemCoefficients, system_coefficients, system_matrices
from .yaw_plane.loads import CONVENTIONS, ResidualLoads, load_vector, one_percent_rule
from .presets import PRESETS, load_preset
from .vehicle import Axle, Unit, Vehicle, VehicleError
from .vehicle_file import VehicleFileError, load_vehicle, loads_vehicle

__all__ = ["Axle", "Unit", "Vehicle", "VehicleError", "VehicleFileError", "load_vehicle", "loads_vehicle",
           "PRESETS", "load_preset", "SystemCoefficients", "system_coefficients", "system_matrices",
           "ResidualLoads", "one_percent_rule", "load_vector", "CONVENTIONS"]
