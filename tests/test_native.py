"""The nonlinear model's equations compiled (lcvreport/model/nonlinear/native.py, equations.c) are
the numpy equations: every preset and example, both tire laws, states that slide and states that
do not, per-variant parameters; a row's numbers are its own (a batch is its rows alone, bit for
bit); a driven axle out of friction is the same refusal; where no library can be had the numpy
equations run, and say why.  (The numpy equations and the compiled ones are each held to the
independent Newton-Euler derivation in tests/test_nonlinear.py.)"""
from __future__ import annotations

import dataclasses
import os
import subprocess
import sys

import numpy as np
import pytest

import lcvreport.model.nonlinear.model as nonlinear
from lcvreport.model.nonlinear import native
from lcvreport.model.nonlinear.model import TractionError, nonlinear_model
from lcvreport.model.presets import PRESETS, load_preset
from lcvreport.model.vehicle_file import load_vehicle

from conftest import EXAMPLE_NAMES, EXAMPLES

VEHICLES = [("preset", p) for p in PRESETS] + [("example", e) for e in EXAMPLE_NAMES]
#: compiled vs numpy: the two differ in the order of sums and in the mass matrix's factorization
#: (LAPACK's inverse vs an LU solve), so a state's accelerations agree to a few ulps times the
#: mass matrix's condition number (~300 at these articulations) times their size: measured at
#: most 1.23 eps cond |z| over these vehicles; the bound is 8 eps cond |z|, the velocities 8 eps
ULPS = 8.0
EPS = np.finfo(float).eps
#: outputs: the same bound for the largest condition number of the batch, relative to the output's size
RTOL = ULPS * EPS * 400.0


def _vehicle(kind, name):
    return load_preset(name) if kind == "preset" else load_vehicle(EXAMPLES / f"{name}.toml")


def _states(m, rng, B, slide):
    """B random states and inputs of ``m``: moderate, or (``slide``) slip angles past saturation."""
    N, na = m.vehicle.n_units, len(m.vehicle.axles)
    x = np.empty((B, m.n_states))
    x[:, :2] = rng.normal(size=(B, 2)) * 20.0
    x[:, 2:2 + N] = np.cumsum(rng.uniform(-0.5, 0.5, (B, N)), axis=1)
    x[:, 2 + N] = rng.normal(size=B) * (1.5 if slide else 0.05)
    x[:, 3 + N:] = rng.normal(size=(B, N)) * (0.5 if slide else 0.02)
    w = np.zeros((B, len(m.input_names)))
    w[:, 0] = rng.uniform(-0.3, 0.3, B) if slide else rng.normal(size=B) * 0.01
    w[:, 1:1 + na] = rng.normal(size=(B, na)) * 300.0
    w[:, 1 + na:1 + 2 * na] = rng.normal(size=(B, na)) * 50.0
    w[:, 1 + 2 * na:1 + 3 * na] = rng.normal(size=(B, na)) * 0.005
    w[:, -1] = rng.normal(size=B) * 0.2
    return x, w


def _variants(m, rng, B):
    """Per-row parameters: the model's masses, inertias and tire coefficients scaled per row (loads
    kept: the friction capacity is the vehicle's)."""
    p = m._p.take(np.zeros(B, dtype=int))
    f = lambda a: a * rng.uniform(0.8, 1.2, a.shape)          # noqa: E731
    return dataclasses.replace(p, m=f(p.m), I=f(p.I), CF=f(p.CF), CM=f(p.CM), tires_CSD2=f(p.tires_CSD2))


def _mass_condition(m, x, U, p):
    """The 2-norm condition number of each state's mass matrix of (v1, r) (the system solved)."""
    W, _bias = m._partials(m._kinematics(x, U), U, float)
    M = np.einsum("bi,bizc,biyc->bzy", p.m, W, W)[:, 1:, 1:]
    M[:, np.arange(1, m._N + 1), np.arange(1, m._N + 1)] += p.I
    return np.linalg.cond(M)


def _check(m, got, ref, x, U, p):
    N = m.vehicle.n_units
    vel = np.abs(got[:, :2 + N] - ref[:, :2 + N]).max(axis=0)
    assert np.all(vel <= ULPS * EPS * np.abs(ref[:, :2 + N]).max(axis=0)), vel
    z_ref = ref[:, 2 + N:]
    bound = ULPS * EPS * _mass_condition(m, x, U, p) * np.abs(z_ref).max(axis=1)
    err = np.abs(got[:, 2 + N:] - z_ref).max(axis=1)
    assert np.all(err <= bound), (err / bound).max()


def _numpy_only(monkeypatch):
    monkeypatch.setattr(nonlinear, "_compiled", lambda model: None)


def test_this_machine_has_the_compiled_equations():
    """The comparisons below are not vacuous: build.sh installs gcc, so the library is made."""
    ok, why = native.status()
    assert ok, why


@pytest.mark.parametrize("tire", ["saturating", "linear"])
@pytest.mark.parametrize("kind, name", VEHICLES)
def test_the_compiled_equations_are_the_numpy_equations(kind, name, tire):
    m = nonlinear_model(_vehicle(kind, name), tire=tire)
    assert nonlinear._compiled(m) is not None
    rng = np.random.default_rng(18)
    compared = 0
    for slide in (False, True):
        for U, s in ((1.4, 1.0), (25.0, 0.85)):
            x, w = _states(m, rng, 64, slide)
            p = _variants(m, rng, 64)
            ok = []                            # the states whose speed can be held (else: see below)
            for k in range(64):
                try:
                    m.derivatives_numpy(0.0, x[k], w[k], U, s, params=p.take([k]))
                    ok.append(k)
                except TractionError:
                    pass
            x, w, p = x[ok], w[ok], p.take(ok)
            ref = m.derivatives_numpy(0.0, x, w, U, s, params=p)
            got = m.derivatives(0.0, x, w, U, s, params=p)
            _check(m, got, ref, x, U, p)
            compared += len(ok)
    assert compared >= 128                     # sliding states compared, not only skipped


@pytest.mark.parametrize("name", EXAMPLE_NAMES)
def test_the_outputs_by_the_compiled_equations_are_the_numpy_outputs(name, monkeypatch):
    """outputs() reads the accelerations and the axles' forces of the compiled equations."""
    m = nonlinear_model(load_vehicle(EXAMPLES / f"{name}.toml"))
    x, w = _states(m, np.random.default_rng(3), 100, slide=False)
    got = m.outputs(0.0, x, w, 4.0, 1.1)
    _numpy_only(monkeypatch)
    ref = m.outputs(0.0, x, w, 4.0, 1.1)
    assert got.keys() == ref.keys()
    for k in ref:
        scale = max(float(np.abs(ref[k]).max()), 1e-300)
        assert np.abs(got[k] - ref[k]).max() <= RTOL * scale, k


def test_a_batch_is_its_rows_alone_bit_for_bit():
    m = nonlinear_model(load_preset("aucnat"))
    rng = np.random.default_rng(5)
    x, w = _states(m, rng, 40, slide=True)
    p = _variants(m, rng, 40)
    ok = []
    for k in range(40):
        try:
            m.derivatives(0.0, x[k], w[k], 20.0, 1.0, params=p.take([k]))
            ok.append(k)
        except TractionError:
            pass
    assert len(ok) >= 10
    x, w, p = x[ok], w[ok], p.take(ok)
    batch = m.derivatives(0.0, x, w, 20.0, 1.0, params=p)
    for k in range(len(ok)):
        alone = m.derivatives(0.0, x[k:k + 1], w[k:k + 1], 20.0, 1.0, params=p.take([k]))
        assert np.array_equal(alone[0], batch[k])


def test_a_driven_axle_out_of_friction_is_the_same_refusal(monkeypatch):
    v = load_vehicle(EXAMPLES / "b_double.toml")
    m = nonlinear_model(v, friction_coefficient=0.01)
    x = np.zeros((4, m.n_states))
    x[2] = [0.0, 0.0, 0.0, 0.5, 0.9, 0.0, 0.3, 0.3, 0.3]          # row 2 asks beyond the friction
    w = np.zeros((4, len(m.input_names)))
    w[2, 0] = 0.2
    with pytest.raises(TractionError) as compiled:
        m.derivatives(0.0, x, w, 25.0)
    _numpy_only(monkeypatch)
    with pytest.raises(TractionError) as reference:
        m.derivatives(0.0, x, w, 25.0)
    assert (compiled.value.axle, compiled.value.row) == (reference.value.axle, reference.value.row) == ("drive1", 2)
    assert compiled.value.needed_N == pytest.approx(reference.value.needed_N, rel=1e-12)
    assert str(compiled.value).startswith("driven axle drive1 needs")


def test_complex_states_take_the_numpy_equations():
    """The complex steps of the Jacobian (section 2's test) need the numpy equations."""
    m = nonlinear_model(load_vehicle(EXAMPLES / "b_double.toml"), tire="linear")
    x = np.zeros(m.n_states, dtype=complex)
    x[m.n_states - 1] += 1e-30j
    d = m.derivatives(0.0, x, m.zero_input().astype(complex), 20.0)
    assert np.iscomplexobj(d) and np.abs(d.imag).max() > 0.0


def _run(code: str, **env) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300,
                          env={**os.environ, **env})


PROBE = ("from lcvreport.model.nonlinear import native; from lcvreport.model.nonlinear.model import nonlinear_model; "
         "from lcvreport.model.presets import load_preset; import numpy as np; "
         "m = nonlinear_model(load_preset('aucnat')); d = m.derivatives(0.0, np.zeros(m.n_states), m.zero_input(), 20.0); "
         "print(native.status()); print(bool(np.all(d[2:] == 0.0)))")


def test_without_a_library_the_numpy_equations_run_and_say_why(tmp_path):
    off = _run(PROBE, LCV_NATIVE="0", LCV_CACHE_DIR=str(tmp_path / "off"))
    assert off.returncode == 0, off.stderr
    assert off.stdout.splitlines() == ["(False, 'LCV_NATIVE=0')", "True"]
    assert not (tmp_path / "off").exists()
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    nowhere = _run(PROBE, LCV_CACHE_DIR=str(blocked / "cache"))
    assert nowhere.returncode == 0, nowhere.stderr
    assert nowhere.stdout.startswith("(False, 'the cache ") and "is not writable" in nowhere.stdout
    assert blocked.read_text() == "not a directory"                # the user's file untouched


def test_the_library_is_compiled_into_the_cache_once_named_by_its_source(tmp_path):
    first = _run(PROBE, LCV_CACHE_DIR=str(tmp_path))
    assert first.returncode == 0, first.stderr
    libs = sorted(tmp_path.iterdir())
    assert len(libs) == 1 and libs[0].name.startswith("lcv_equations_") and libs[0].suffix == ".so", libs
    assert first.stdout.splitlines() == [f"(True, 'compiled: {libs[0]}')", "True"]
    stamp = libs[0].stat().st_mtime_ns
    again = _run(PROBE, LCV_CACHE_DIR=str(tmp_path))
    assert again.stdout == first.stdout and libs[0].stat().st_mtime_ns == stamp   # found, not rebuilt
    assert sorted(tmp_path.iterdir()) == libs                                     # no temporary left


def test_a_model_beyond_the_compiled_sizes_takes_the_numpy_equations(monkeypatch):
    monkeypatch.setattr(native, "NMAX", 2)
    m = nonlinear_model(load_preset("aucnat"))
    assert native.compiled(m, 60, 1e-13) is None
    assert np.all(m.derivatives(0.0, np.zeros(m.n_states), m.zero_input(), 20.0)[2:] == 0.0)


class _LibmNumpy:
    """numpy, but ``sin``, ``cos``, ``arctan2`` and ``hypot`` are the C library's (as the compiled
    code calls them).  Where numpy has SIMD versions of its own (AVX-512: ``arctan2`` differs from
    glibc's ``atan2`` in the last bit on 8 % of arguments, seen on this project's CI machines),
    numpy's law is still the compiled law's reference operation for operation, with libm's
    functions."""

    def __init__(self):
        import ctypes
        import ctypes.util
        libm = ctypes.CDLL(ctypes.util.find_library("m"))
        for name, numpy_name, nin in (("sin", "sin", 1), ("cos", "cos", 1), ("atan2", "arctan2", 2),
                                      ("hypot", "hypot", 2)):
            f = getattr(libm, name)
            f.restype, f.argtypes = ctypes.c_double, [ctypes.c_double] * nin
            ufunc = np.frompyfunc(f, nin, 1)
            setattr(self, numpy_name, lambda *a, _u=ufunc: np.asarray(_u(*a), dtype=float))

    def __getattr__(self, name):
        return getattr(np, name)


@pytest.mark.parametrize("angle_deg", [90.0, 180.0, 270.0, 360.0, 1440.0])
def test_the_compiled_path_following_law_is_the_numpy_law(angle_deg, monkeypatch):
    """The turn's steer law (friction_demand.PathFollowing; path_following.c): the outside wheel's
    arc length, path error and the steer of states all over the turn's ground -- the approach, the
    arc's laps, the exit, the corners -- are numpy's bit for bit (the same operations in the same
    order), with libm's sin/cos/atan2/hypot in numpy's law (:class:`_LibmNumpy`)."""
    import lcvreport.manoeuvres.paths as paths_module
    import lcvreport.measures.friction_demand as friction_demand_module
    from lcvreport.measures.friction_demand import turn_with_tire_forces
    follow = turn_with_tire_forces(load_vehicle(EXAMPLES / "b_double.toml"), angle_deg=90.0).follow
    follow = _with_angle(follow, angle_deg)
    assert follow._compiled is not None
    rng = np.random.default_rng(11)
    k = 4000
    X = np.zeros((len(follow.state_names), k))
    X[0], X[1] = rng.uniform(-30.0, 40.0, k), rng.uniform(-40.0, 15.0, k)
    X[2] = rng.uniform(-9.0, 1.0, k)
    X[-1] = rng.normal(size=k)
    t = rng.uniform(0.0, 1.2 * follow.path.s_end / follow.U, k)
    libm_np = _LibmNumpy()
    for module in (paths_module, friction_demand_module):
        monkeypatch.setattr(module, "np", libm_np)
    for got, ref in zip(follow._compiled(t, X), follow.law_numpy(t, X)):
        assert np.array_equal(got, ref)


def _with_angle(follow, angle_deg):
    """``follow`` on a path of ``angle_deg`` (its delta_kin table kept: the law's arithmetic is
    what is compared, not the turn)."""
    import copy
    import math

    from lcvreport.manoeuvres.paths import StraightArcPath
    from lcvreport.measures import friction_demand
    other = copy.copy(follow)
    p = follow.path
    other.path = StraightArcPath(p.radius_m, math.radians(angle_deg), p.exit_m)
    other._compiled = friction_demand._compiled_law(other)
    return other


@pytest.mark.parametrize("module", ["lcvreport.util.compiled", "lcvreport.model.nonlinear.native"])
def test_the_compile_commands_refuse_an_argument_in_one_line(module):
    bad = subprocess.run([sys.executable, "-m", module, "--bogus"], capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr == f"python -m {module}: takes no argument, got '--bogus'\n"
    good = subprocess.run([sys.executable, "-m", module, "--help"], capture_output=True, text=True, timeout=300)
    assert good.returncode == 0 and good.stdout.startswith(f"usage: python -m {module}\n")
