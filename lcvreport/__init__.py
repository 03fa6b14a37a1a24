"""lcvreport: linear yaw-plane dynamics of long combination vehicles.

A tractor or truck pulling any chain of trailers, dollies and full trailers, in the
thesis form ``M x' = S x + F`` (J. J. Patterson, "Effect of conicity and ply steer on
long combination vehicle yaw plane motion", University of Akron, 2011), with the
thesis reproduced and audited, the standard yaw-plane measures, FMUs and reports.

Where things live (the folders are the layers; each imports only the ones above it)
----------------------------------------------------------------------------------
``units``, ``ranges``    conversion factors and unit systems; the one table of valid
                         ranges of every parameter and input
``util/``                helpers with no physics:
    ``cache``            an LRU cache (discretizations, output maps)
    ``numerics``         numpy-only numerics: equilibrated solve, expm
    ``threads``          one BLAS thread at the entry points (LCV_BLAS_THREADS to change it)
    ``files``            the one guarded reader of every file a user hands in (regular files, a size limit, UTF-8)
``model/``               **the model core** (numpy only):
    ``vehicle``          Axle, Unit, Vehicle (SI parameter sets, validated)
    ``vehicle_file``     vehicle files (TOML, SI): load_vehicle, dumps_vehicle
    ``presets``          the six thesis vehicles, shipped as vehicle files
    ``builder``          M, S and the input matrices of any chain (SI or thesis units)
    ``loads``            residual loads P, T; the 1 % rule; load conventions
    ``low_speed``        the second model: low-speed plane kinematics (pull points, heading law; scipy)
    ``plausibility``     warnings for legal but implausible numbers (unit typos)
``analysis/``            **linear analysis** (numpy, scipy):
    ``modes``            eigenvalues, damping, mode shapes
    ``steady``           steady state -S^-1 F
    ``geometry``         rear-end offsets (eq. 4.42-4.46), global positions
    ``manoeuvres``       steer inputs as continuous functions (step, sine, pulse, table, lane change)
    ``exact``            exact response to them (augmented exponential), extrema between samples
    ``field_measures``   RA peak, yaw damping (PBS style), HSTO, HSSO (SPEC 12)
    ``low_speed_turn``   the low-speed 90° turn: swept width, offtracking, tail and frontal swing (SPEC 16)
    ``driver``           a path-following driver with preview, the closed loop of vehicle and driver
    ``batch``            variants of a vehicle in a batch: matrices and damping over the leading axis
    ``registry``         every measure once: key, label, unit, definition, limit kind, how it is batched
    ``criteria``         the user's limits and the verdicts
    ``tracking``         per-tire conicity and ply steer, fleet statistics of the trimmed offtracking
    ``placement``        which measured tire goes where: the exact mounting plan (a mixed-integer program)
    ``discretize``       exact zero-order-hold discretization, its cache
    ``response``         TimeResponse, simulate, step_response (exact)
    ``modal``            modal superposition, exact and the thesis' method
    ``statespace``       named state space; to_statespace (python-control)
    ``measures``         RA, damping, critical speed, single sine, trim
    ``closed_loop``      sampled steering feedback (what a co-simulation computes)
``thesis/``              **the reproduction of the dissertation**:
    ``tables``           its tables and gaps (data files in ``data/thesis``)
    ``tires``            cubic fits of the tire coefficients against load
    ``vehicles``         the presets built from the tables, as vehicle files
    ``configurations``   per-tire residual forces (Figures 3-6..3-8, 4-9..4-11)
    ``studies``          the chapter III-V runs, in both readings
    ``tracking_questions`` chapter VI's open questions on straight-line tracking, answered on AU-NCAT
    ``audit``            every published number against its recomputation
``fmu/``                 **the FMUs**:
    ``interface``        the one interface table (SPEC sections 5 and 9)
    ``model_description`` modelDescription.xml from that table
    ``model_description3`` the FMI 3.0 modelDescription.xml and buildDescription.xml
    ``driver``           the driver FMU (FMI 2.0 CS and ME, C99) of analysis.driver
    ``engine``           the co-simulation engine (numpy only)
    ``slave_core``       what the Python FMUs compute, FMI calls by value reference onto the engine
    ``slave``            the FMI 2.0 slave class: the core behind pythonfmu
    ``slave3``           the FMI 3.0 slave class: the core behind pythonfmu3
    ``build``            builders of the pythonfmu and the C FMU (sources in the
                         repository's ``fmu_src/``, installed as ``lcvreport.fmu_src``)
``study/``               **studies at scale** (SPEC section 14; pandas, pyarrow, dask on use):
    ``spec``             the study file: vehicle, factors, design, measures; the cases
    ``compute``          the measures of a chunk of cases, batched over the cases
    ``run``              ``lcv study``: chunks on Dask, Parquet written atomically, resume
    ``results``          ``read_study`` (one table) and ``study_case`` (a row as a measure_set call)
    ``summary``          spread of the measures, pass rates against criteria (the study report)
``report/``              **the reports** (notebooks in ``notebooks/``, installed as
                         ``lcvreport.notebooks``):
    ``plotting``         figures (matplotlib), units on every axis
    ``reporting``        captions, tables (HTML, LaTeX), CSV of every table and figure
    ``assessment``       what the assessment report of one vehicle shows
    ``build``            papermill + nbconvert: the thesis report, the assessment report
``cli``                  the ``lcv`` command (``_entry``: its console script, one BLAS thread first)

Units
-----
SI at every public interface: speeds ``speed_mps`` [m/s], lengths [m], forces [N],
moments [N*m], states ``v1`` [m/s], ``r`` [rad/s], ``theta`` [rad].  Names of
dimensional numbers carry their unit (``mass_kg``, ``x_m``, ``speed_mps``,
``offtracking_m``); the thesis reproduction asks for matrices in the thesis' units
explicitly (``units=lcvreport.units.THESIS``: in, lbf, s).  Joints are lettered A, B,
C ... as in thesis Table 3-2 (``thetaA``); the FMUs of SPEC section 9 number them.

Examples
--------
>>> import lcvreport
>>> v = lcvreport.load_preset("aucnat")
>>> m = lcvreport.modes(v, lcvreport.units.kph_to_mps(88.0))
>>> m.stable
True
"""
from __future__ import annotations

import importlib

from . import ranges, units

__version__ = "0.2.0"

#: public name -> module that defines it (loaded on first use: importing the package
#: loads numpy only, so the FMU engine's embedded interpreter stays light)
_API = {
    "Axle": "model.vehicle", "Unit": "model.vehicle", "Vehicle": "model.vehicle", "VehicleError": "model.vehicle",
    "load_vehicle": "model.vehicle_file", "loads_vehicle": "model.vehicle_file",
    "VehicleFileError": "model.vehicle_file", "dumps_vehicle": "model.vehicle_file",
    "PRESETS": "model.presets", "load_preset": "model.presets",
    "system_coefficients": "model.builder", "system_matrices": "model.builder",
    "ResidualLoads": "model.loads", "one_percent_rule": "model.loads", "load_vector": "model.loads",
    "Modes": "analysis.modes", "modes": "analysis.modes", "eigenvalues": "analysis.modes",
    "steady_state": "analysis.steady",
    "TimeResponse": "analysis.response", "simulate": "analysis.response", "step_response": "analysis.response",
    "to_statespace": "analysis.statespace",
    "measure_set": "analysis.measures", "rearward_amplification": "analysis.measures",
    "critical_speed": "analysis.measures", "least_damping": "analysis.measures", "single_sine": "analysis.measures",
    "trim": "analysis.measures",
    "read_study": "study.results", "study_case": "study.results", "load_study": "study.spec",
    "run_study": "study.run",
}
__all__ = sorted(_API) + ["ranges", "units"]


def __getattr__(name: str):
    if name in _API:
        value = getattr(importlib.import_module(f".{_API[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'lcvreport' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_API))
