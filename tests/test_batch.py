"""Variants in a batch (issue 21, first part): the batched matrices and damping measures equal
the one-variant calls on random batches to 1e-12 relative."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lcvreport import load_preset, load_vehicle
from lcvreport.analysis.batch import AXLE_PARAMETERS, UNIT_PARAMETERS, BatchError, VariantBatch, _nominal, _with
from lcvreport.measures.amplification import ra_peak_batched, single_sine_batched
from lcvreport.measures.measure_set import batch_measures
from lcvreport.measures.offtracking import lane_change_batched, steady_turn_batched
from lcvreport.measures.stability import critical_speed_batched, least_damping_batched
from lcvreport.measures.yaw_damping import yaw_damping_batched
from lcvreport.measures.stability import least_damping
from lcvreport.analysis.modes import eigenvalues, state_matrix

from conftest import EXAMPLES


def _variant(v, values: dict, i: int):
    """Variant ``i`` of ``v`` built one parameter at a time (the one-variant reference)."""
    for name, arr in values.items():
        v = _with(v, name, float(arr[i]))
    return v


@pytest.mark.parametrize("source", ["aucnat", "b_double"])
def test_batched_measures_equal_one_variant_calls(source):
    v = load_preset(source) if source == "aucnat" else load_vehicle(EXAMPLES / f"{source}.toml")
    names = [f"{u.name}.{k}" for u in v.units for k in UNIT_PARAMETERS] + \
        [f"{a.name}.{k}" for a in v.axles for k in AXLE_PARAMETERS]
    names = [n for n in names if _nominal(v, n) > 0]          # C_S of a steer axle is 0
    rng = np.random.default_rng(21)
    B = 12
    values = {n: _nominal(v, n) * rng.uniform(0.8, 1.2, B) for n in names}
    batch = VariantBatch(v, values)
    u = 24.0
    A = batch.state_matrix(u)
    zeta, f_hz = least_damping_batched(batch, u)
    top = batch.max_real(u)
    for i in range(B):
        vi = _variant(v, values, i)
        Ai = state_matrix(vi, u)
        assert np.abs(A[i] - Ai).max() <= 1e-12 * np.abs(Ai).max()
        z1, f1 = least_damping(vi, u)
        assert zeta[i] == pytest.approx(z1, rel=1e-12) and f_hz[i] == pytest.approx(f1, rel=1e-12)
        assert top[i] == pytest.approx(eigenvalues(vi, u).real.max(), rel=1e-12, abs=1e-14)
    assert np.ptp(zeta) > 0                                    # the variants do differ


def test_bad_batches_are_refused():
    v = load_preset("tractor_semitrailer")
    with pytest.raises(BatchError, match="unknown parameter 'trailer9.mass_kg'"):
        VariantBatch(v, {"trailer9.mass_kg": np.ones(2)})
    with pytest.raises(BatchError, match="one length"):
        VariantBatch(v, {"tractor.mass_kg": np.ones(2) * 1e4, "trailer1.mass_kg": np.ones(3) * 1e4})
    with pytest.raises(BatchError, match="finite and > 0"):
        VariantBatch(v, {"tractor.mass_kg": np.array([1e4, np.nan])})


@pytest.mark.parametrize("tire_scale", [0.2, 1.0])
def test_batched_critical_speed_equals_the_one_variant_algorithm(tire_scale):
    """Masses and C_F varied ±40 % on the empty triple: unstable and stable variants alike,
    the same critical speed (to its 0.1 km/h) as measures.critical_speed of each variant."""
    from lcvreport.measures.stability import critical_speed
    v = load_preset("empty")
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(14)
    B = 16
    values = {n: _nominal(v, n) * rng.uniform(0.6, 1.4, B) for n in names}
    got = critical_speed_batched(VariantBatch(v, values), tire_scale=tire_scale)
    ref = []
    for i in range(B):
        vi = _variant(v, values, i)
        r = critical_speed(vi, tire_scale=tire_scale)
        ref.append(np.nan if r is None else r)
    assert np.array_equal(np.nan_to_num(got, nan=-1.0), np.nan_to_num(np.array(ref), nan=-1.0)), (got, ref)
    assert np.isfinite(got).any()


def test_batched_gains_and_rearward_amplification():
    from lcvreport.analysis.frequency import rearward_amplification, steer_to_acceleration
    v = load_preset("aucnat")
    names = [f"{u.name}.yaw_inertia_kg_m2" for u in v.units] + [f"{a.name}.aligning_stiffness_Nm_per_rad"
                                                                 for a in v.axles]
    rng = np.random.default_rng(5)
    values = {n: _nominal(v, n) * rng.uniform(0.8, 1.2, 8) for n in names}
    batch = VariantBatch(v, values)
    G = batch.steer_to_acceleration(24.0, 0.4, tire_scale=0.9)
    ra = batch.rearward_amplification(24.0, 0.4, tire_scale=0.9)
    for i in range(8):
        vi = _variant(v, values, i)
        Gi = steer_to_acceleration(vi, 24.0, 0.4, tire_scale=0.9)
        assert np.abs(G[i] - Gi).max() <= 1e-12 * np.abs(Gi).max()
        assert ra[i] == pytest.approx(rearward_amplification(vi, 24.0, 0.4, tire_scale=0.9), rel=1e-12)


def test_batched_trim_equals_the_one_variant_trim():
    """Residual forces and moments on the last two trailers (1 % rule), C_F and masses varied."""
    from lcvreport.analysis.steady import trim
    from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule
    v = load_preset("aucnat")
    F = load_vector(v, one_percent_rule(v, ["trailer2", "trailer3"]))
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(9)
    values = {n: _nominal(v, n) * rng.uniform(0.8, 1.2, 10) for n in names}
    delta, off = VariantBatch(v, values).trim(24.0, F, tire_scale=0.8)
    for i in range(10):
        vi = _variant(v, values, i)
        t = trim(vi, 24.0, F, tire_scale=0.8)
        assert delta[i] == pytest.approx(t.delta_rad, rel=1e-12)
        assert off[i] == pytest.approx(t.offtracking_m, rel=1e-12)
    assert np.ptp(off) > 0


def test_batched_steady_turn_equals_hsso():
    from lcvreport.measures.offtracking import steady_turn
    v = load_vehicle(EXAMPLES / "western_double.toml")
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(11)
    values = {n: _nominal(v, n) * rng.uniform(0.8, 1.2, 6) for n in names}
    hsso, delta = steady_turn_batched(VariantBatch(v, values), 24.0)
    for i in range(6):
        vi = _variant(v, values, i)
        t = steady_turn(vi, 24.0)
        # hsso is the difference of two ~393 m radii: rounding of 1e-16 of a radius is 1.3e-12 of a 30 mm hsso
        assert hsso[i] == pytest.approx(t.hsso_m, rel=1e-11) and delta[i] == pytest.approx(t.delta_rad, rel=1e-12)


def test_batched_ra_peak_equals_the_one_variant_peak():
    """The value to 1e-12; where it is to 1e-10: both locate the zero of the exact slope (a
    search on RA's values alone would find a smooth maximum to about sqrt(eps) only)."""
    from lcvreport.measures.amplification import ra_peak
    v = load_preset("aucnat")
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(2)
    values = {n: _nominal(v, n) * rng.uniform(0.8, 1.2, 6) for n in names}
    peak, where = ra_peak_batched(VariantBatch(v, values), 24.0)
    for i in range(6):
        vi = _variant(v, values, i)
        p = ra_peak(vi, 24.0)
        assert peak[i] == pytest.approx(p.value, rel=1e-12) and where[i] == pytest.approx(p.frequency_hz, rel=1e-10)


def test_the_measures_table_has_the_measure_set_numbers():
    from lcvreport import measure_set
    v = load_preset("tractor_semitrailer")
    values = {"trailer1.mass_kg": _nominal(v, "trailer1.mass_kg") * np.array([0.9, 1.0, 1.1])}
    table = batch_measures(VariantBatch(v, values), 24.0)
    assert list(table["case_id"]) == [0, 1, 2] and "trailer1.mass_kg" in table
    m = measure_set(v, 24.0).to_dict()                              # the middle case is the vehicle itself
    for key in ("least_damping_ratio", "least_damped_frequency_hz", "ra_frequency", "ra_peak", "hsso_m",
                "steady_turn_delta_rad"):
        assert table[key][1] == pytest.approx(m[key], rel=1e-11), key
    assert (np.isnan(table["critical_speed_kph"][1]) and m["critical_speed_kph"] is None) or \
        table["critical_speed_kph"][1] == m["critical_speed_kph"]


def test_ra_peak_does_not_depend_on_the_batch_or_the_scan(monkeypatch):
    """Each variant's search stops on its own: a variant's peak is the same bit for bit in any
    batch; and the modal scan (which only picks the bracket) gives what the exact scan gives."""
    import lcvreport.analysis.batch as batch_module
    v = load_preset("aucnat")
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(5)
    values = {n: _nominal(v, n) * rng.uniform(0.7, 1.3, 9) for n in names}
    whole = ra_peak_batched(VariantBatch(v, values), 22.0)
    for part in (slice(0, 1), slice(2, 7), slice(8, 9)):
        sub = ra_peak_batched(VariantBatch(v, {n: a[part] for n, a in values.items()}), 22.0)
        assert np.array_equal(sub[0], whole[0][part]) and np.array_equal(sub[1], whole[1][part])
    monkeypatch.setattr(batch_module, "SCAN_COND_MAX", 0.0)             # every variant: the exact scan
    exact = ra_peak_batched(VariantBatch(v, values), 22.0)
    assert np.array_equal(exact[0], whole[0]) and np.array_equal(exact[1], whole[1])


@pytest.mark.parametrize("preset,speed", [("aucnat", 24.0), ("tractor_semitrailer", 30.0), ("legal_max", 14.0)])
def test_batched_single_sine_is_the_one_variant_single_sine(preset, speed):
    """RA of the single sine on the continuous exact response, every variant at once (in groups
    of RESPONSE_GROUP), against measures.single_sine of each variant built on its own: 1e-12 relative (what
    differs is the scaling the matrix exponential chooses for the smaller augmented matrices)."""
    from lcvreport.measures.amplification import single_sine
    v = load_preset(preset)
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(9)
    B = 70                                     # groups of 16: 63 and 64 on either side of a boundary
    values = {n: _nominal(v, n) * rng.uniform(0.75, 1.25, B) for n in names}
    ra, ra_r = single_sine_batched(VariantBatch(v, values), speed)
    for i in (0, 1, 63, 64, 69):
        s = single_sine(_variant(v, values, i), speed)
        assert ra[i] == pytest.approx(s.rearward_amplification, rel=1e-12), i
        r = s.response.peaks_abs(["r1", f"r{v.n_units}"])          # the yaw rates' peaks, one variant
        assert ra_r[i] == pytest.approx(r[1] / r[0], rel=1e-12), i


@pytest.mark.parametrize("preset,speed", [("aucnat", 24.0), ("tractor_semitrailer", 30.0), ("legal_max", 20.0)])
def test_batched_yaw_damping_is_the_one_variant_coefficient(preset, speed):
    """The pulse, each joint's extrema after it on the continuous response, the ratio method:
    every variant at once against field_measures.yaw_damping_coefficient of each.  1e-11
    relative: d = ln(P_i / P_(i+1)) of peak-to-peak amplitudes takes the extrema's rounding
    (1e-14 of the peaks, located by different exponentials' scalings) to about 1e-12."""
    from lcvreport.measures.yaw_damping import yaw_damping_coefficient
    v = load_preset(preset)
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(10)
    B = 66
    values = {n: _nominal(v, n) * rng.uniform(0.75, 1.25, B) for n in names}
    ydc = yaw_damping_batched(VariantBatch(v, values), speed)
    for i in (0, 7, 63, 64, 65):
        ref = yaw_damping_coefficient(_variant(v, values, i), speed).value
        if ref is None:
            assert np.isnan(ydc[i])
        else:
            assert ydc[i] == pytest.approx(ref, rel=1e-11), i


@pytest.mark.parametrize("preset,speed", [("aucnat", 24.0), ("tractor_semitrailer", 30.0), ("empty", 22.0)])
def test_batched_lane_change_is_the_one_variant_lane_change(preset, speed):
    """HSTO and the lane change's RA through every variant's inverse system at once, against
    field_measures.lane_change_measures of each: 1e-12 relative (HSTO absolute 1e-12 m where 0)."""
    from lcvreport.measures.offtracking import lane_change_measures
    v = load_preset(preset)
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(11)
    B = 66
    values = {n: _nominal(v, n) * rng.uniform(0.75, 1.25, B) for n in names}
    lc = lane_change_batched(VariantBatch(v, values), speed)
    hsto, ra = lc["hsto_m"], lc["ra_lane_change"]
    for i in (0, 5, 63, 64, 65):
        ref = lane_change_measures(_variant(v, values, i), speed)
        assert hsto[i] == pytest.approx(ref.hsto_m, rel=1e-12, abs=1e-12), i
        assert ra[i] == pytest.approx(ref.ra_lane_change, rel=1e-12), i


def test_a_variants_time_responses_do_not_depend_on_the_variants_beside_it(monkeypatch):
    """The single sine, the yaw damping pulse and the lane change of a variant, bit for bit the same
    in groups of 16 (the default), 5 and 1: each root between samples stops on its own
    (:func:`lcvreport.analysis.extrema.hermite_roots`), so neither the group nor a study's chunks
    change a number."""
    import lcvreport.analysis.batch as batch_module
    import lcvreport.measures.offtracking as offtracking_module
    import lcvreport.measures.yaw_damping as yaw_damping_module
    v = load_preset("tractor_semitrailer")
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(12)
    values = {n: _nominal(v, n) * rng.uniform(0.75, 1.25, 17) for n in names}
    b = VariantBatch(v, values)
    results = []
    for group in (16, 5, 1):
        for module in (batch_module, offtracking_module, yaw_damping_module):
            monkeypatch.setattr(module, "RESPONSE_GROUP", group)
        lc = lane_change_batched(b, 24.0)
        results.append(np.column_stack([*single_sine_batched(b, 24.0), yaw_damping_batched(b, 24.0), lc["hsto_m"],
                                        lc["ra_lane_change"]]))
    assert np.isfinite(results[0]).sum(axis=0).min() >= 12, results[0]   # (a heavily damped variant: no YDC)
    for other in results[1:]:
        assert np.array_equal(other, results[0], equal_nan=True)


@pytest.mark.parametrize("name, model", [("aucnat", "yaw_plane"), ("tractor_semitrailer", "yaw_plane"),
                                         ("b_double", "yaw_roll")])
def test_a_variants_batched_measures_do_not_depend_on_the_variants_beside_it(name, model):
    """Every batched measure (the trim's included) of a variant, bit for bit the same computed with
    16 others, with 4, and alone: a study's chunks never change a number.  (On a machine with
    AVX-512, BLAS rounds a row of a (B, n) @ (n, k) product by B, and a dot product differently from
    a matrix-vector one: the lane change's ``b @ [1, x_s, 0, ...]`` and RA's ``x @ map.T`` did.)"""
    from lcvreport.model.yaw_plane.loads import load_vector, one_percent_rule
    v = load_vehicle(EXAMPLES / f"{name}.toml") if name == "b_double" else load_preset(name)
    names = [f"{u.name}.mass_kg" for u in v.units] + [f"{a.name}.cornering_stiffness_N_per_rad" for a in v.axles]
    rng = np.random.default_rng(12)
    values = {n: _nominal(v, n) * rng.uniform(0.75, 1.25, 17) for n in names}
    batch = VariantBatch(v, values).on_model(model)
    F = np.tile(load_vector(v, one_percent_rule(v, [v.units[-1].name])), (17, 1)) if model == "yaw_plane" else None
    full = batch_measures(batch, 24.0, F=F)
    assert np.isfinite(full["hsto_m"]).all() and np.isfinite(full["ra_frequency"]).all()
    for rows in ([3], [0, 1, 2, 3, 4], [16]):
        rows = np.array(rows)
        part = batch_measures(batch.subset(rows), 24.0, F=None if F is None else F[rows])
        for key, column in full.items():
            if key != "case_id":
                assert np.array_equal(part[key], np.asarray(column)[rows], equal_nan=True), (key, rows)


def _cpu_flags() -> set:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            return {w for line in f if line.startswith("flags") for w in line.split(":", 1)[1].split()}
    except OSError:
        return set()


@pytest.mark.parametrize("core, flag", [("Nehalem", "sse4_2"), ("SandyBridge", "avx"), ("Haswell", "avx2")])
def test_no_variant_depends_on_its_neighbours_with_other_blas_kernels(core, flag):
    """The two tests above, bit for bit, with OpenBLAS's kernels of older processors
    (``OPENBLAS_CORETYPE``): the machines CI may run on.  (Sandy Bridge's kernels rounded the
    steady turn's sideslips by the batch's size until every batched product was taken row by row,
    ``lcvreport.util.numerics.rowwise``.)"""
    import os
    import re
    import subprocess
    import sys
    if flag not in _cpu_flags():
        pytest.skip(f"this processor has no {flag}: OpenBLAS's {core} kernels cannot run here")
    env = dict(os.environ, OPENBLAS_CORETYPE=core, OPENBLAS_NUM_THREADS="1")
    p = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                        str(Path(__file__)), "-k", "do_not_depend_on_the_variants_beside_it"],
                       capture_output=True, text=True, env=env, cwd=Path(__file__).parents[1], timeout=600)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-2000:]
    assert re.search(r"\b4 passed\b", p.stdout), p.stdout[-1000:]


def test_a_variant_with_an_unstable_inverse_system_has_no_lane_change():
    """legal_max at 60 m/s has a right-half-plane zero (exact.response refuses the lane change,
    measure_set reports null): its variants get NaN, the others their numbers."""
    from lcvreport.analysis.exact import ManoeuvreError
    from lcvreport.measures.offtracking import lane_change_measures
    v = load_preset("legal_max")
    name = f"{v.units[0].name}.yaw_inertia_kg_m2"
    values = {name: _nominal(v, name) * np.array([1.0, 1.0])}
    lc = lane_change_batched(VariantBatch(v, values), 60.0)
    hsto, ra = lc["hsto_m"], lc["ra_lane_change"]
    with pytest.raises(ManoeuvreError, match="unstable"):
        lane_change_measures(v, 60.0)
    assert np.isnan(hsto).all() and np.isnan(ra).all()
    hsto = lane_change_batched(VariantBatch(v, values), 20.0)["hsto_m"]
    assert np.isfinite(hsto).all()


def test_the_grouped_ratio_method_equals_the_one_signal_method():
    from lcvreport.measures.yaw_damping import ratio_damping_groups
    from lcvreport.measures.yaw_damping import ratio_damping
    rng = np.random.default_rng(7)
    groups, signals, values, expected = [], [], [], {}
    for g in range(40):
        for s in range(3):
            n = int(rng.integers(0, 12))                 # 0, 1, 2 extrema: no amplitudes or one
            lam = complex(-rng.uniform(0.01, 1.5), rng.uniform(0.5, 8.0))
            t = np.sort(rng.uniform(0, 20, n))
            v = np.exp(lam.real * t) * np.cos(lam.imag * t) + rng.normal(0, 0.02, n)   # some below 5 %
            groups += [g] * n
            signals += [s] * n
            values += v.tolist()
            zeta, _P = ratio_damping(v)
            if zeta is not None:
                expected[(g, s)] = zeta
    z, g, s = ratio_damping_groups(np.array(groups), np.array(signals), np.array(values))
    got = {(int(a), int(b)): float(c) for a, b, c in zip(g, s, z)}
    # the same arithmetic in the same order; numpy's vectorised log may differ from its scalar
    # path by an ulp, which the log-ratio d (not small) passes on at a few ulp
    assert got.keys() == expected.keys() and len(expected) > 60
    for k, zeta in expected.items():
        assert got[k] == pytest.approx(zeta, rel=1e-14, abs=1e-16)


def test_the_batched_ra_peak_falls_back_to_a_golden_section_where_the_slope_brackets_no_zero(monkeypatch):
    v = load_preset("aucnat")
    names = [f"{u.name}.mass_kg" for u in v.units]
    rng = np.random.default_rng(3)
    values = {n: _nominal(v, n) * rng.uniform(0.8, 1.2, 5) for n in names}
    peak, where = ra_peak_batched(VariantBatch(v, values), 24.0)
    import lcvreport.measures.amplification as amplification
    monkeypatch.setattr(amplification, "_ra_slope", lambda batch, s, x, t, rows: np.full(len(rows), np.nan))
    peak2, where2 = ra_peak_batched(VariantBatch(v, values), 24.0)
    np.testing.assert_allclose(peak2, peak, rtol=1e-13)
    assert np.max(np.abs(where2 - where)) <= 1e-7


def test_hermite_roots_of_an_array_are_the_one_root_function_bit_for_bit():
    """The vectorised safeguarded Newton iteration against the scalar one (Python floats) on
    20,000 random intervals (zeros at either end, slopes over six decades), and on a subset: every
    root the same whatever the others of the call."""
    from lcvreport.analysis.extrema import _hermite_root, hermite_roots
    rng = np.random.default_rng(5)
    n = 20_000
    f0 = rng.standard_normal(n)
    f1 = -np.sign(f0) * rng.uniform(1e-6, 3.0, n)
    d0, d1 = (rng.standard_normal(n) * 10.0 ** rng.uniform(-3, 3, n) for _ in range(2))
    f0[:50], f1[50:100] = 0.0, 0.0
    h = 0.005
    roots = hermite_roots(f0, d0, f1, d1, h)
    one = [_hermite_root(*a, h) for a in zip(f0.tolist(), d0.tolist(), f1.tolist(), d1.tolist())]
    assert np.array_equal(roots, np.array(one))
    assert ((roots >= 0.0) & (roots <= 1.0)).all()
    assert np.array_equal(hermite_roots(f0[::7], d0[::7], f1[::7], d1[::7], h), roots[::7])
