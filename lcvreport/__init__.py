"""lcvreport: linear yaw-plane and yaw-roll dynamics of long combination vehicles.

A tractor or truck pulling any chain of trailers, dollies and full trailers, in the
thesis form ``M x' = S x + F`` (J. J. Patterson, "Effect of conicity and ply steer on
long combination vehicle yaw plane motion", University of Akron, 2011), with the
thesis reproduced and audited, the standard yaw-plane measures, FMUs and reports.

Where things live (a folder is a layer; each imports only the ones above it)
---------------------------------------------------------------------------
``_moved``               the module paths of 0.2.x that moved in 0.3.0, still importable (CHANGELOG.md)
``version``              the package's version (``__version__``)
``units``, ``ranges``    conversion factors and unit systems; the one table of valid
                         ranges of every parameter and input
``util/``                helpers with no physics:
    ``cache``            an LRU cache (discretizations, output maps)
    ``numerics``         numpy-only numerics: equilibrated solve, expm
    ``threads``          one BLAS thread at the entry points (LCV_BLAS_THREADS to change it)
    ``files``            the one guarded reader of every file a user hands in (regular files, a size limit, UTF-8)
    ``text``             what a user's text may hold (no control characters) and how a message quotes it
    ``compiled``         the package's C sources compiled on this machine, cached, loaded (ctypes)
    ``interrupts``       Ctrl-C and SIGTERM the interpreter swallowed still end a command as interrupted
    ``startup``          a command's start-up and shutdown: numpy's unused subpackages lazy, no collection of the imports
``model/``               **what a vehicle is, and the models of it** (numpy only):
    ``vehicle``          Axle, Unit, Vehicle (SI parameter sets, validated)
    ``vehicle_file``     vehicle files (TOML, SI): load_vehicle, dumps_vehicle
    ``presets``          the six thesis vehicles, shipped as vehicle files
    ``plausibility``     warnings for legal but implausible numbers (unit typos)
    ``statics``          static axle and coupling loads that follow the masses (mass factors, payloads)
    ``base``             the model object: the VehicleModel protocol, MODELS, build_model
    ``body``             the body of every unit: kind, extent, corners, overall length, poses
    ``linear``           the model seam: LinearModel (what analysis needs of any linear model), MODELS
    ``yaw_plane/``       the linear yaw-plane model of the thesis, ``M x' = S x + F``:
        ``equations``    M, S and the input matrices of any chain (SI or thesis units)
        ``states``       the state names and the joint letters
        ``outputs``      point and rear-end lateral positions (eq. 4.42-4.46)
        ``loads``        residual loads P, T and their sources; the 1 % rule; load conventions
    ``yaw_roll/``        the linear yaw-roll model (docs/roll.md), a second LinearModel:
        ``parameters``   the roll data checked, sprung masses, coupling loads, roll-coupled groups
        ``equations``    M, S and the input matrices with roll rates and roll angles; load transfer outputs
    ``low_speed/``       the low-speed kinematic model:
        ``kinematics``   pull points, the heading law, the integration along a path (scipy)
    ``nonlinear/``       the nonlinear planar model (docs/nonlinear.md): any angle, saturating tires:
        ``model``        the planar multibody chain, Kane's equations, the held speed, outputs
        ``native``       the equations compiled (equations.c, ctypes): the same numbers, ~6x faster a call
        ``tires``        the tire laws, linear and brush, vectorized over the axles
``manoeuvres/``          **what the driver and the road do**, independent of any model:
    ``steer``            steer inputs as continuous functions (step, sine, pulse, table, lane change)
    ``paths``            the paths of the low-speed model (straight, straight-arc-straight)
    ``drivers``          the path-following preview driver
``plotting/``            **figures** (matplotlib): they draw, they never compute; units on every axis
    ``style``            page width, fonts, palette, a figure without pyplot state, figure data
    ``vehicle``          top views, mode shapes, steady states
    ``time``             time histories, the single sine, the lane change, the pulse
    ``frequency``        eigenvalues, root loci, damping over speed, frequency responses
    ``low_speed``        the swept path of the low-speed turn
    ``tracking``         offtracking histogram, axle sensitivities, mounting study
    ``study``            scatter and pass rates of a study
    ``roll``             the a_y - phi curve of the static rollover threshold
    ``assessment``       an assessment's evidence with every level's limit drawn on it
    ``charts``           grouped bars and fitted curves
``analysis/``            **analysis of the models** (numpy, scipy):
    ``modes``            eigenvalues, damping, mode shapes
    ``steady``           steady state -S^-1 F, the steady state with a held yaw rate, the trim
    ``frequency``        G(j w) from the steer to every unit's acceleration, RA(f)
    ``exact``            exact response to steer inputs (augmented exponential)
    ``extrema``          extrema between samples (Hermite), the doubling scan
    ``time_response``    the Response protocol; TimeResponse (exact) and SampledResponse (integrated): signals, extrema, plot
    ``integrate``        one implicit integration of any model (Radau), restarted at the steer's breakpoints
    ``radau_batch``      scipy's Radau over many variants side by side, each with its own steps (a study's turns)
    ``respond``          the response of any model: a linear one's exact, any other's integrated
    ``response``         simulate, step_response: inputs held over intervals (exact)
    ``discretize``       exact zero-order-hold discretization, its cache
    ``modal``            modal superposition, exact and the thesis' method
    ``statespace``       named state space; to_statespace (python-control)
    ``closed_loop``      the vehicle with a driver: continuous, and sampled steering feedback
    ``batch``            variants of a vehicle in a batch: matrices and responses over the leading axis
``measures/``            **the field's measures**, one family per module:
    ``registry``         every measure once: key, label, unit, definition, limit kind, how it is batched
    ``stability``        least damping, critical speed, speed sweep
    ``crossings``        every speed an eigenvalue crosses the imaginary axis (the exact check of the critical speed)
    ``amplification``    single-sine RA, the RA peak
    ``yaw_damping``      yaw damping coefficient (ratio method)
    ``offtracking``      HSTO and RA of the lane change, HSSO
    ``low_speed``        the low-speed 90-degree turn: swept width, offtracking, tail and frontal swing
    ``friction_demand``  the turn with tire forces (nonlinear model, path-following law): STFD, drive-tyre demand
    ``rollover``         the static rollover threshold: quasi-static, lift-off axle by axle, exact events
    ``roll``             the roll measures: LTR, roll gains, the yaw-roll model's RA, HSTO, damping
    ``ra_points``        rearward amplification's numerator and denominator points (sprung CG, roll axis, steer axle)
    ``case``             one case: vehicle, model, speed, tire scale, conditions, load case, sources (Case)
    ``measure_set``      every measure of a vehicle at a speed (MeasureSet)
    ``criteria``         the user's limits and the verdicts
    ``scheme``           scheme files: levels, and per measure its conditions and limits per level
    ``assess``           every measure of a scheme at its conditions, verdicts per level, the level reached
    ``evidence``         what each measure of an assessment was read from, recomputed at its conditions
``tracking/``            **straight-line tracking** over a tire population:
    ``tires``            tire slots, per-axle residuals, sensitivities, the mounted-tires file
    ``statistics``       fleet statistics of the trimmed offtracking
    ``placement``        which measured tire goes where: the exact mounting plan (a mixed-integer program)
``thesis/``              **the reproduction of the dissertation**:
    ``tables``           its tables and gaps (data files in ``data/thesis``)
    ``tires``            cubic fits of the tire coefficients against load
    ``vehicles``         the presets built from the tables, as vehicle files
    ``configurations``   per-tire residual forces (Figures 3-6..3-8, 4-9..4-11)
    ``studies``          the chapter III-V runs, in both readings
    ``tracking_questions`` chapter VI's open questions on straight-line tracking, answered on AU-NCAT
    ``figures``          its own figures: free body, load configurations, tire curves and fits
    ``audit``            every published number against its recomputation
``fmu/``                 **the FMUs**:
    ``interface``        the one interface table of every FMU
    ``description_common`` what both modelDescription.xml versions share
    ``description_fmi2`` the FMI 2.0 modelDescription.xml
    ``description_fmi3`` the FMI 3.0 modelDescription.xml and buildDescription.xml
    ``driver``           the driver FMU (FMI 2.0 CS and ME, C99) of the preview driver
    ``engine``           the co-simulation engine (numpy only)
    ``nonlinear_engine`` the nonlinear model's co-simulation engine: each step integrated
    ``slave_core``       what the Python FMUs compute, FMI calls by value reference onto the engine
    ``slave_fmi2``       the FMI 2.0 slave class: the core behind pythonfmu
    ``slave_fmi3``       the FMI 3.0 slave class: the core behind pythonfmu3
    ``c_tree``           the C sources: the FMI API per version, the vehicle and driver models, the loaders
    ``c_sources``        generated C headers, the C files on this machine, the compiler call
    ``package``          documentation, licences, the package copy, the zip
    ``build``            builders of the pythonfmu and the C FMUs (sources in the
                         repository's ``fmu_src/``, installed as ``lcvreport.fmu_src``)
``study/``               **studies at scale** (pandas, pyarrow, dask on use):
    ``spec``             the study file: vehicle, factors, design, measures; the cases
    ``factors``          a study's factors: scales, payloads, load cases, residual sources, their checks
    ``compute``          the measures of a chunk of cases, batched over the cases
    ``folder``           the study folder's files and chunk names
    ``run``              ``lcv study``: chunks on Dask, Parquet written atomically, resume
    ``results``          ``read_study`` (one table) and ``study_case`` (a row as a measure_set call)
    ``summary``          spread of the measures, pass rates against criteria (the study report)
``report/``              **the reports** (notebooks in ``notebooks/``, installed as
                         ``lcvreport.notebooks``):
    ``tables``           captions, tables (HTML, LaTeX), CSV of every table and figure
    ``assessment``       what the assessment report of one vehicle shows
    ``notebooks``        notebook parameters and their checks, execution, merge, HTML and PDF export
    ``publish``          output folder checks, staging, manifest, atomic publish
    ``build``            the thesis report, the assessment report, the study report
``cli/``                 **the ``lcv`` command**, one module per command group (``__main__``: ``python -m lcvreport.cli``):
    ``start``            the start: Ctrl-C recorded, one BLAS thread, then ``main``
    ``main``             the parser, dispatch and exit statuses
    ``options``          the options the commands share (vehicle, speed, loads, residual sources)
    ``output``           the output stream and figures written aside
    ``model``            presets, eig, matrices, steady
    ``simulate``         simulate
    ``measures``         measures (text, CSV, JSON from the registry)
    ``tracking``         tracking place, tracking stats
    ``turn``             the low-speed turn
    ``roll``             the static rollover threshold, roll gains, LTR
    ``assess``           an assessment against a scheme file: the verdict table, text or JSON
    ``artifacts``        fmu, report, study
``_entry``               the console script (``cli.start``)

Units
-----
SI at every public interface: speeds ``speed_mps`` [m/s], lengths [m], forces [N],
moments [N*m], states ``v1`` [m/s], ``r`` [rad/s], ``theta`` [rad].  Names of
dimensional numbers carry their unit (``mass_kg``, ``x_m``, ``speed_mps``,
``offtracking_m``); the thesis reproduction asks for matrices in the thesis' units
explicitly (``units=lcvreport.units.THESIS``: in, lbf, s).  Joints are lettered A, B,
C ... as in thesis Table 3-2 (``thetaA``); the FMUs of a vehicle file number them (docs/fmu.md).

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

from . import _moved, ranges, units
from .version import __version__

#: public name -> module that defines it (loaded on first use: importing the package
#: loads numpy only, so the FMU engine's embedded interpreter stays light)
_API = {
    "Axle": "model.vehicle", "Unit": "model.vehicle", "Vehicle": "model.vehicle", "VehicleError": "model.vehicle",
    "load_vehicle": "model.vehicle_file", "loads_vehicle": "model.vehicle_file",
    "VehicleFileError": "model.vehicle_file", "dumps_vehicle": "model.vehicle_file",
    "PRESETS": "model.presets", "load_preset": "model.presets",
    "system_coefficients": "model.yaw_plane.equations", "system_matrices": "model.yaw_plane.equations",
    "ResidualLoads": "model.yaw_plane.loads", "one_percent_rule": "model.yaw_plane.loads", "load_vector": "model.yaw_plane.loads",
    "Modes": "analysis.modes", "modes": "analysis.modes", "eigenvalues": "analysis.modes",
    "steady_state": "analysis.steady",
    "TimeResponse": "analysis.time_response", "simulate": "analysis.response", "step_response": "analysis.response",
    "to_statespace": "analysis.statespace",
    "measure_set": "measures.measure_set", "rearward_amplification": "analysis.frequency",
    "critical_speed": "measures.stability", "least_damping": "measures.stability", "single_sine": "measures.amplification",
    "trim": "analysis.steady",
    "read_study": "study.results", "study_case": "study.results", "load_study": "study.spec",
    "run_study": "study.run",
    # 0.3.0: a function for every command (docs/index.md#what-is-public); "module:name" where the
    # public name is not the module's
    "assess": "measures.assess", "load_scheme": "measures.scheme", "loads_scheme": "measures.scheme",
    "roll": "measures.roll:roll_summary", "low_speed_turn": "measures.low_speed",
    "turn_with_tire_forces": "measures.friction_demand", "tracking_stats": "tracking.statistics",
    "place_tires": "tracking.placement", "build_fmus": "fmu.build:build_vehicle_fmus",
    "build_report": "report.build:build_assessment", "build_model": "model.base", "respond": "analysis.respond",
    "integrate": "analysis.integrate", "nonlinear_model": "model.nonlinear.model",
    "Case": "measures.case",
}
__all__ = sorted(_API) + ["ranges", "units"]

if __name__ == "lcvreport":      # not the copy an FMU bundles under a name of its own: a host is left as it was
    _moved.install()


def __getattr__(name: str):
    if name in _API:
        module, _, attr = _API[name].partition(":")
        value = getattr(importlib.import_module(f".{module}", __name__), attr or name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'lcvreport' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_API))
