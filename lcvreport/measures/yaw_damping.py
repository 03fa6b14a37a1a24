"""The yaw damping coefficient (``docs/measures.md#yaw-damping-coefficient``): the ratio
method on the free decay of every articulation angle after a steer pulse of 0.01 rad for
0.5 s, over 40 s; the coefficient is the smallest over the joints.  Each joint's peak-to-peak
amplitudes are taken from its largest on, those of at least 5 % of it, the first six; a joint
with fewer than two decays faster than 20:1 per half cycle (zeta >= 0.6901), and when every
joint is so the coefficient is None with that lower bound.

Examples
--------
>>> from lcvreport import load_preset
>>> round(yaw_damping_coefficient(load_preset("aucnat"), 24.4444).value, 3)
0.217
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.batch import RESPONSE_GROUP, VariantBatch
from ..analysis.exact import ManoeuvreResponse
from ..manoeuvres.steer import pulse
from ..model.vehicle import Vehicle
from .registry import MeasureCase

#: the YDC pulse: amplitude [rad], duration [s]; the window after it [s]
YDC_PULSE = (0.01, 0.5)


YDC_WINDOW_S = 40.0


#: amplitudes kept: at least this fraction of the joint's largest, the first this many
YDC_MIN_FRACTION = 0.05


YDC_MAX_AMPLITUDES = 6


#: a joint with fewer than two kept amplitudes decays faster than 1/YDC_MIN_FRACTION per half
#: cycle: its zeta is at least this (ln 20 / sqrt(pi^2 + ln^2 20) = 0.6901), the YDC's lower bound
#: when every joint is so (docs/measures.md)
YDC_HEAVY_ZETA = math.log(1.0 / YDC_MIN_FRACTION) / math.sqrt(math.pi ** 2 + math.log(1.0 / YDC_MIN_FRACTION) ** 2)


YDC_DT_S = 0.005


@dataclass(frozen=True)
class YawDamping:
    """The ratio-method yaw damping of a pulse steer (docs/measures.md).

    Attributes
    ----------
    value : float or None
        The smallest per-joint value (None if no joint has two amplitudes).
    per_joint : list of (float or None)
        Each joint's mean ratio damping.
    amplitudes : list of numpy.ndarray
        The kept peak-to-peak amplitudes P_i of each joint [rad].
    extrema : list of (numpy.ndarray, numpy.ndarray)
        Times [s] and values [rad] of each joint's extrema after the pulse.
    modal_least_damping_ratio : float or None
        The modal zeta_min beside it (several modes of near frequency make the ratio
        method read low).
    response : ManoeuvreResponse
    why : str
        Why ``value`` is None.
    lower_bound : float or None
        When every joint is heavily damped (fewer than two kept amplitudes: a decay faster
        than x20 per half cycle), the bound ``YDC_HEAVY_ZETA`` = 0.6901 its value is at least;
        None otherwise.
    """

    value: float | None
    per_joint: list
    amplitudes: list
    extrema: list
    modal_least_damping_ratio: float | None
    response: ManoeuvreResponse
    why: str = ""
    lower_bound: float | None = None
    #: what a heavily damped joint's zeta is at least (:data:`YDC_HEAVY_ZETA`)
    heavy_zeta: float = YDC_HEAVY_ZETA


def ratio_damping(extrema_values) -> tuple[float | None, np.ndarray]:
    """The ratio method on a signal's successive extrema (time order): the peak-to-peak
    amplitudes P_i = |A_(i+1) - A_i|; the free decay starts at the largest (the amplitudes
    before it are the forced response); from it on, those >= 5 % of it (a smaller one is
    skipped, later ones still count), the first six; the mean over consecutive pairs of kept
    amplitudes of zeta = d / sqrt(pi^2 + d^2), d = ln(P_i/P_(i+1)); None when fewer than two are
    kept (docs/measures.md).  For one damped mode ``exp(sigma t) sin(omega t)`` it is
    exactly -sigma / |lambda|.

    Examples
    --------
    >>> import numpy as np
    >>> lam = -0.3 + 2.0j                     # extrema of exp(-0.3 t) sin(2 t + phi) are pi/2 apart
    >>> A = np.exp(lam.real * np.pi / 2 * np.arange(8)) * (-1.0) ** np.arange(8)
    >>> round(ratio_damping(A)[0], 12) == round(-lam.real / abs(lam), 12)
    True
    """
    v = np.asarray(extrema_values, dtype=float)
    P = np.abs(np.diff(v))
    if P.size:
        P = P[int(np.argmax(P)):]                  # the free decay starts at the largest amplitude
        P = P[P >= YDC_MIN_FRACTION * P[0]][:YDC_MAX_AMPLITUDES]
    if P.size < 2:
        return None, P
    d = np.log(P[:-1] / P[1:])
    return float(np.mean(d / np.sqrt(np.pi ** 2 + d ** 2))), P


def yaw_damping_coefficient(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0,
                            model: str = "yaw_plane", options: dict | None = None) -> YawDamping:
    """PBS-style yaw damping: the pulse ``pulse:0.01:0.5``; for each joint the extrema of
    its articulation angle from the end of the pulse to 40 s after (zeros of theta',
    located on the continuous response), their peak-to-peak amplitudes P_i = |A_(i+1) -
    A_i|, the first six of those >= 5 % of the joint's largest; each consecutive pair
    gives zeta = d / sqrt(pi^2 + d^2), d = ln(P_i / P_(i+1)); a joint's value is the mean
    of its pairs; the coefficient the smallest over joints with two amplitudes or more.
    On the model ``model`` (default the yaw plane; a model that is not linear integrated, its
    modal damping ratio its linearization's).
    """
    from ..model.base import LINEAR_MODELS
    from .stability import least_damping
    linear = model if model in LINEAR_MODELS else "yaw_plane"
    return _yaw_damping(vehicle, speed_mps, tire_scale, least_damping(vehicle, speed_mps, tire_scale, linear)[0],
                        model, options)


def _yaw_damping(vehicle: Vehicle, speed_mps: float, tire_scale: float, zeta_modal: float | None,
                 model: str = "yaw_plane", options: dict | None = None) -> YawDamping:
    """:func:`yaw_damping_coefficient` with the modal least damping ratio already known."""
    A, D = YDC_PULSE
    steer = pulse(A, D)
    t_end = round((D + YDC_WINDOW_S) / YDC_DT_S) * YDC_DT_S
    from ..analysis.respond import respond
    r = respond(vehicle, model, steer, speed_mps, t_end, YDC_DT_S, tire_scale, options=options)
    if vehicle.n_units < 2:
        return YawDamping(None, [], [], [], zeta_modal, r, "no joint: a single unit has no articulation angle")
    per_joint, amps, ext = [], [], []
    joints = [f"theta{c}" for c in vehicle.joint_letters]
    for t, v in r.extrema_many(joints, D, D + YDC_WINDOW_S):
        inner = (t > D + 1e-12) & (t < D + YDC_WINDOW_S - 1e-12)     # the window's ends are not extrema
        t, v = t[inner], v[inner]
        ext.append((t, v))
        zeta, P = ratio_damping(v)
        amps.append(P)
        per_joint.append(zeta)
    defined = [z for z in per_joint if z is not None]
    if not defined:
        return YawDamping(None, per_joint, amps, ext, zeta_modal, r,
                          f"heavily damped: no joint has two peak-to-peak amplitudes of at least 5 % of its "
                          f"largest after the pulse (a decay faster than x20 per half cycle), so YDC >= "
                          f"{YDC_HEAVY_ZETA:.4f}", YDC_HEAVY_ZETA)
    return YawDamping(min(defined), per_joint, amps, ext, zeta_modal, r)


def yaw_damping_batched(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
    """The yaw damping coefficient [-] of every variant
    (:func:`lcvreport.measures.yaw_damping.yaw_damping_coefficient`: the pulse, each joint's
    extrema from its end to 40 s after on the continuous response, the ratio method, the
    smallest over the joints); NaN where no joint has two amplitudes."""
    from ..manoeuvres.steer import pulse
    v = batch.vehicle
    B = batch.size
    out = np.full(B, np.nan)
    if v.n_units < 2:
        return out
    A, D = YDC_PULSE
    steer = pulse(A, D)
    t_end = round((D + YDC_WINDOW_S) / YDC_DT_S) * YDC_DT_S
    lo, hi = D + 1e-12, D + YDC_WINDOW_S - 1e-12
    joints = v.n_units - 1
    extrema = []
    for g in range(0, B, RESPONSE_GROUP):
        rows = np.arange(g, min(B, g + RESPONSE_GROUP))
        found = []
        for Mz, _z0, Z, _z_end, ka, _kb, _d, (_A, _b, m, n) in batch.pieces(speed_mps, steer, t_end, YDC_DT_S,
                                                                           tire_scale, rows, positions=False):
            if Z is None:
                continue
            C = np.zeros((rows.size, joints, Mz.shape[-1]))                 # theta rows over z
            C[:, np.arange(joints), v.n_units + 1 + np.arange(joints)] = 1.0
            b_i, s_i, t, val, _y = batch.between_samples(Z, C, Mz, YDC_DT_S, ka * YDC_DT_S)
            keep = (t > lo) & (t < hi)
            found.append((b_i[keep], s_i[keep], t[keep], val[keep]))
        b_i, s_i, t, val = (np.concatenate(a) for a in zip(*found))
        extrema.append((rows[b_i], s_i, t, val))
    b_i, s_i, t, val = (np.concatenate(a) for a in zip(*extrema))
    order = np.lexsort((t, s_i, b_i))                     # by variant, joint, time
    zeta, b_of, _s = ratio_damping_groups(b_i[order], s_i[order], val[order])
    np.fmin.at(out, b_of, zeta)                            # the smallest over a variant's joints
    return out


def ratio_damping_groups(group: np.ndarray, signal: np.ndarray, values: np.ndarray):
    """:func:`ratio_damping` of many signals at once: ``values``
    holds each signal's extrema in time order, the signals one after the other, labelled by
    ``(group, signal)``.  Returns (zeta, group, signal) of every signal with two kept amplitudes
    or more (the same arithmetic in the same order: equal to the one-signal function to a few ulp,
    numpy's vectorised logarithm and its scalar one differing by an ulp at most).

    Examples
    --------
    >>> import numpy as np
    >>> A = np.exp(-0.3 * np.pi / 2 * np.arange(8)) * (-1.0) ** np.arange(8)
    >>> z, g, s = ratio_damping_groups(np.zeros(8, int), np.zeros(8, int), A)
    >>> from lcvreport.measures.yaw_damping import ratio_damping
    >>> bool(abs(z[0] - ratio_damping(A)[0]) <= 1e-15)
    True
    """
    group, signal, values = np.asarray(group), np.asarray(signal), np.asarray(values, dtype=float)
    empty = (np.zeros(0), np.zeros(0, int), np.zeros(0, int))
    if values.size < 3:
        return empty
    new = np.r_[True, (group[1:] != group[:-1]) | (signal[1:] != signal[:-1])]
    label = np.cumsum(new) - 1                                  # one label per signal
    same = label[1:] == label[:-1]
    P = np.abs(np.diff(values))[same]                           # peak-to-peak amplitudes
    lab = label[1:][same]
    if not P.size:
        return empty
    starts = np.flatnonzero(np.r_[True, lab[1:] != lab[:-1]])
    pmax = np.maximum.reduceat(P, starts)
    which = np.cumsum(np.r_[True, lab[1:] != lab[:-1]]) - 1   # index into starts
    idx = np.arange(P.size)
    first_max = np.minimum.reduceat(np.where(P == pmax[which], idx, P.size), starts)
    # the free decay starts at each signal's largest amplitude; from it on, those >= 5 % of it
    keep = (idx >= first_max[which]) & (P >= YDC_MIN_FRACTION * pmax[which])
    rank = np.cumsum(keep)
    before = np.r_[0, rank][starts][which]                      # kept amplitudes before the signal's first
    keep &= (rank - before) <= YDC_MAX_AMPLITUDES
    P, lab = P[keep], lab[keep]
    pair = lab[1:] == lab[:-1]
    d = np.log(P[:-1][pair] / P[1:][pair])
    z = d / np.sqrt(np.pi ** 2 + d ** 2)
    zl = lab[:-1][pair]
    if not zl.size:
        return empty
    firsts = np.flatnonzero(np.r_[True, zl[1:] != zl[:-1]])
    counts = np.diff(np.r_[firsts, zl.size])
    sums = np.add.reduceat(z, firsts)
    idx = np.flatnonzero(new)[zl[firsts]]                        # each signal's first element
    return sums / counts, group[idx], signal[idx]


def yaw_damping_family_batched(batch: VariantBatch, speed_mps: float, tire_scale: float = 1.0) -> tuple:
    """(yaw damping coefficient [-], its lower bound [-]) of every variant: the registry's batched
    ``yaw_damping`` family (the bound 0.6901 where every joint is heavily damped, else NaN)."""
    zeta = yaw_damping_batched(batch, speed_mps, tire_scale)
    bound = np.where(np.isnan(zeta) & (batch.vehicle.n_units > 1), YDC_HEAVY_ZETA, np.nan)
    return zeta, bound


def yaw_damping_family(case: MeasureCase) -> tuple[dict, dict]:
    """The registry's ``yaw_damping`` family of one case: the coefficient and, when every joint
    is heavily damped, its lower bound."""
    zeta = case.shared.get("least_damping_ratio")
    if "least_damping_ratio" not in case.shared:
        from .stability import least_damping
        from ..model.base import LINEAR_MODELS
        zeta = least_damping(case.vehicle, case.speed_mps, case.tire_scale,
                             case.model if case.model in LINEAR_MODELS else "yaw_plane")[0]
    ydc = _yaw_damping(case.vehicle, case.speed_mps, case.tire_scale, zeta, case.model, case.model_options())
    why = {}
    if ydc.value is None:
        why["yaw_damping_coefficient"] = f"undefined: {ydc.why}"
    if ydc.lower_bound is None:
        why["yaw_damping_lower_bound"] = ("the yaw damping coefficient has a value (the bound is only given when "
                                          "every joint is heavily damped)") if ydc.value is not None else \
            why["yaw_damping_coefficient"]
    return {"yaw_damping_coefficient": ydc.value, "yaw_damping_lower_bound": ydc.lower_bound}, why
