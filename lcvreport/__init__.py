"""lcvreport: linear yaw-plane model of long combination vehicles (A-trains).

Reproduces and audits J. J. Patterson, "Effect of conicity and ply steer on long
combination vehicle yaw plane motion", University of Akron, 2011.

Modules, one job each:

``data``      thesis tables (TOML files with units in the key names)
``vehicle``   parameter-set classes (Axle, Unit, Train)
``presets``   the thesis vehicles built from the tables
``tires``     Appendix D fits of tire coefficients against tire load
``model``     the builder of M, S and input matrices for any N
``linear``    eigen-analysis, exact (zero-order-hold) response, steady state, modal methods
``loads``     residual loads P, T, the 1 % rule, conventions, load configurations
``studies``   chapter III-V studies
``cosim``     the co-simulation engine behind the FMUs
``cli``       the ``lcv`` command
"""
from .linear import Modes, TimeResponse, modes, simulate, steady_state, step_response
from .loads import ResidualLoads, load_vector, one_percent_rule
from .model import system_coefficients, system_matrices
from .presets import PRESETS, load_preset
from .vehicle import Axle, Train, Unit

__all__ = [
    "Axle", "Unit", "Train", "PRESETS", "load_preset", "system_coefficients", "system_matrices",
    "Modes", "modes", "TimeResponse", "simulate", "step_response", "steady_state",
    "ResidualLoads", "one_percent_rule", "load_vector",
]
__version__ = "0.1.0"
