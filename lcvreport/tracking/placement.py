"""Tire placement: which measured tire goes where, serial side out or in (docs/tracking.md).

Given measured tires (conicity and ply steer forces, optionally moments) and the tire
positions to fill, find the plan -- a tire and a serial side for every position -- that
minimizes the trimmed offtracking's magnitude, ties broken by the trim steer's magnitude.

When the tires can cancel -- a plan with |offtracking| and |trim steer| both at zero (within
half of :data:`TIE_M` and :data:`TIE_GAP_RAD`) exists, the usual case with a dozen tires or more
-- that plan is optimal (no plan does better than 0) and is found directly: for a few seeded
placements of the tires, every combination of serial sides is searched by meeting two halves in
the middle (:func:`_near_zero_plan`; a tire's ply steer stays, its conicity flips).  Otherwise
it is solved exactly as a mixed-integer linear program (HiGHS through
:func:`scipy.optimize.milp`), where the optimum is away from zero and its bound proves it.  Positions on one axle are interchangeable (the tire's
force acts on its axle whatever the slot), so the program decides, per tire, an axle and
the direction its serial side faces (+y or -y): binaries ``y[i, a, s]`` with every tire
used once and every axle given its number of tires; ``|O| <= t`` minimized, where
``O = O_0 + sum y[i, a, s] g_a (p_i + s c_i) + ...`` is the trimmed offtracking (linear
in the tire forces, the sensitivities ``g`` of :func:`lcvreport.tracking.tires.sensitivities`).
A second program keeps ``|O|`` within :data:`TIE_M` of the optimum and minimizes the
trim steer's magnitude (to :data:`TIE_GAP_RAD`).  The slots of an axle are then filled in order, and each tire's
serial side (``out``/``in``) follows from its slot and the direction chosen.

The answer is checked, not trusted: the rounded plan is mounted with
:func:`lcvreport.tracking.tires.axle_residuals` and trimmed with
:func:`lcvreport.analysis.steady.trim`; its offtracking must agree with the program's
to :data:`CHECK_M` and lie within :data:`GAP_M` of HiGHS's proven lower bound.

Optimality is to :data:`GAP_M` = 1e-6 m of offtracking (HiGHS's absolute gap with the
objective in metres): a micrometre is far below anything a road or a tape measure sees,
and asking for less makes HiGHS's feasibility tolerances, not the tires, decide.

Examples
--------
>>> from lcvreport import load_preset
>>> v = load_preset("tractor_semitrailer")
>>> tires = [dict(id=f"T{k}", conicity_N=c, ply_steer_N=p)
...          for k, (c, p) in enumerate([(120, 40), (-60, 35), (80, -20), (10, 55)])]
>>> plan = place_tires(v, 24.4444, tires)
>>> [row["position"] for row in plan.plan]
['21:left_outer', '21:left_inner', '21:right_inner', '21:right_outer']
>>> abs(plan.offtracking_m) <= abs(plan.as_listed_offtracking_m)
True
"""
from __future__ import annotations

import contextlib
import os
import sys
from dataclasses import dataclass, field

import numpy as np

from ..analysis.steady import trim
from ..model.vehicle import Vehicle
from .tires import TireSlot, TrackingError, axle_residuals, sensitivities, tire_number, tire_slots

#: optimality of the plan's |offtracking| [m] (HiGHS's absolute MIP gap, objective in m)
GAP_M = 1e-6
#: plans within this much of the least |offtracking| [m] count as tied (then: least |trim steer|)
TIE_M = 1e-6
#: how much of the tie band is kept back for the solver's tolerances [m]
FEASIBILITY_M = 5e-7
#: the rounded plan's offtracking must equal the program's to this [m]
CHECK_M = 1e-6
#: random placements drawn for the comparison, and their seed
RANDOM_DRAWS = 10_000
SEED = 20110801
#: the solver's time limit per program [s]
TIME_LIMIT_S = 120.0
#: optimality of the tie-break's |trim steer| [rad] (HiGHS's absolute gap, objective in rad)
TIE_GAP_RAD = 1e-6
#: plans the search for a plan at zero looks at (:func:`_near_zero_plan`), and the fewest tires it is tried on
NEAR_ZERO_BUDGET = 1 << 33
#: "at zero": within 0.9 of the gaps (the rest for the plan's rounding when mounted anew)
ZERO_M = 0.9 * min(GAP_M, TIE_M)
ZERO_RAD = 0.9 * TIE_GAP_RAD
NEAR_ZERO_RESTARTS = 256
#: up to 16 tires: the plans looked at one by one, and the placements at most
NEAR_ZERO_FULL_BUDGET = 1 << 25
NEAR_ZERO_PLACEMENTS = 8192
NEAR_ZERO_MIN_TIRES = 10
#: measured-tire columns
COLUMNS = ("id", "conicity_N", "ply_steer_N")
OPTIONAL = ("conicity_moment_Nm", "ply_steer_moment_Nm")


@dataclass(frozen=True)
class Placement:
    """A mounting plan and how it compares (docs/tracking.md).

    Attributes
    ----------
    plan : list of dict
        ``position`` (``axle:slot``), ``tire`` (id), ``serial_side`` (``out``/``in``), in
        the order of the positions.
    offtracking_m, trim_delta_rad : float
        Trimmed offtracking [m] and trim steer [rad] of the plan (mounted and trimmed anew).
    lower_bound_m : float
        A lower bound on the least |offtracking| of any plan [m]: HiGHS's dual bound less
        :data:`GAP_M` (its bound is exact only to its tolerances), at least 0.
    as_listed_offtracking_m, as_listed_trim_delta_rad : float
        The tires in the order listed, into the positions in order, serial side out.
    random_offtracking_m : numpy.ndarray
        Offtracking [m] of :data:`RANDOM_DRAWS` random placements (random positions and
        serial sides, seed :data:`SEED`).
    """

    plan: list
    offtracking_m: float
    trim_delta_rad: float
    lower_bound_m: float
    as_listed_offtracking_m: float
    as_listed_trim_delta_rad: float
    random_offtracking_m: np.ndarray = field(repr=False)
    seed: int = SEED

    def to_dict(self) -> dict:
        """The JSON of ``lcv tracking place`` (docs/tracking.md)."""
        r = self.random_offtracking_m
        return {"plan": [dict(row) for row in self.plan], "offtracking_m": self.offtracking_m,
                "trim_delta_rad": self.trim_delta_rad, "lower_bound_m": self.lower_bound_m,
                "as_listed": {"offtracking_m": self.as_listed_offtracking_m,
                              "trim_delta_rad": self.as_listed_trim_delta_rad},
                "random_placements": {"mean": float(r.mean()), "sd": float(r.std(ddof=1)) if r.size > 1 else 0.0,
                                      "best_abs": float(np.abs(r).min()), "draws": int(r.size), "seed": self.seed}}

    def table(self):
        """The plan as a :class:`pandas.DataFrame` (position, tire, serial_side)."""
        import pandas as pd
        return pd.DataFrame(self.plan, columns=["position", "tire", "serial_side"])


def read_measured_tires(path) -> list[dict]:
    """Measured tires from a CSV with the header ``id,conicity_N,ply_steer_N`` and
    optionally ``conicity_moment_Nm,ply_steer_moment_Nm``.

    Raises
    ------
    TrackingError
        Unreadable file, unknown or missing columns, empty or duplicate ids, values that
        are not finite numbers within 1e6.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "t.csv"
    >>> _ = p.write_text("id,conicity_N,ply_steer_N\\nA1,120,40\\nA2,-60,35\\n")
    >>> [t["id"] for t in read_measured_tires(p)]
    ['A1', 'A2']
    """
    from ..util.files import FileInputError, read_csv
    try:
        rows = read_csv(path, "measured-tire file", COLUMNS, OPTIONAL)
    except FileInputError as exc:
        raise TrackingError(str(exc)) from None
    tires, seen = [], {}
    for k, row in rows:
        tid = (row["id"] or "").strip()
        if not tid or not tid.isprintable():
            raise TrackingError(f"{path}: line {k}: id must be a non-empty printable text, got {row['id']!r}")
        if tid in seen:
            raise TrackingError(f"{path}: line {k}: tire id {tid!r} is listed twice (first on line {seen[tid]})")
        seen[tid] = k
        tire = {"id": tid}
        for key in COLUMNS[1:] + OPTIONAL:
            raw = row.get(key)
            if raw in (None, ""):
                if key in COLUMNS:
                    raise TrackingError(f"{path}: line {k}: tire {tid}: {key} is empty")
                continue
            tire[key] = tire_number(raw, f"{path}: line {k}: tire {tid}: {key}")
        tires.append(tire)
    if not tires:
        raise TrackingError(f"{path}: no tires")
    return tires


def positions_of(vehicle: Vehicle, positions: list[str] | None) -> list[TireSlot]:
    """The named positions (``axle:slot``; default: every tire position of units 2..N)."""
    if positions is None:
        return tire_slots(vehicle)
    by_name = {s.position: s for s in tire_slots(vehicle, vehicle.axle_names)}
    out, seen = [], set()
    for pos in positions:
        if pos not in by_name:
            axle = pos.partition(":")[0]
            if axle not in vehicle.axle_names:
                raise TrackingError(f"position {pos!r}: unknown axle {axle!r}; valid: {', '.join(vehicle.axle_names)}")
            raise TrackingError(f"position {pos!r}: axle {axle} has the slots "
                                f"{', '.join(s.slot for s in by_name.values() if s.axle_name == axle)}")
        if pos in seen:
            raise TrackingError(f"position {pos!r} is named twice")
        seen.add(pos)
        out.append(by_name[pos])
    return out


@contextlib.contextmanager
def _quiet_stdout():
    """HiGHS writes some messages straight to file descriptor 1 (C++ ``std::cout``) even with
    ``disp=False``: send them to the null device while it runs.  Descriptor 1 itself, not
    ``sys.stdout.fileno()``: a Jupyter kernel's ``sys.stdout`` reports a copy of the original
    descriptor while descriptor 1 feeds the notebook."""
    fd = 1
    try:
        sys.stdout.flush()
    except (AttributeError, OSError, ValueError):
        pass
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
        yield
    finally:
        os.dup2(saved, fd)
        os.close(saved)


def _arrays(tires: list[dict]):
    get = lambda key: np.array([float(t.get(key, 0.0)) for t in tires])  # noqa: E731
    return get("conicity_N"), get("ply_steer_N"), get("conicity_moment_Nm"), get("ply_steer_moment_Nm")


def _mount(slots: list[TireSlot], tires: list[dict], order, facing) -> list[dict]:
    """Mounted tires: tire ``order[k]`` in ``slots[k]`` with its serial side facing ``facing[k]`` (+1: +y)."""
    rows = []
    for slot, i, f in zip(slots, order, facing):
        side = "out" if f == slot.side else "in"
        rows.append(dict(position=slot.position, serial_side=side, **tires[i]))
    return rows


def _evaluate(vehicle, speed_mps, mounted, F_const, tire_scale):
    from ..model.yaw_plane.loads import ResidualSources
    F = ResidualSources(axle_residuals(vehicle, mounted)).vector(vehicle, tire_scale)
    if F_const is not None:
        F = F + F_const
    tr = trim(vehicle, speed_mps, F, tire_scale)
    return tr.offtracking_m, tr.delta_rad


def _near_zero_plan(coef: np.ndarray, const: np.ndarray, slot_axle: np.ndarray, seed: int,
                    budget: int = NEAR_ZERO_BUDGET, half: int = 16) -> np.ndarray | None:
    """A plan with |offtracking| <= :data:`ZERO_M` and |trim steer| <= :data:`ZERO_RAD`, or None.

    Such a plan is optimal for both programs to their gaps (nothing does better than 0, and it lies
    in every tie band: ZERO_M is below GAP_M and TIE_M, ZERO_RAD below TIE_GAP_RAD), so when the measured
    set can cancel it is the answer and no program is solved.  For placements of the tires (the
    listed one, then seeded random ones) only the serial sides are searched: a tire's ply steer
    stays, its conicity flips with the side, so (O, delta) is a base point plus a signed sum of each
    tire's flip vector.  Up to 16 tires, every sign pattern of many placements at once; beyond, the
    sign patterns of two halves of up to ``half`` tires each met in the middle (sorted by O, every
    pair with |O| in the band looked at): about ``budget`` plans in all (:data:`NEAR_ZERO_FULL_BUDGET`
    up to 16 tires).
    Deterministic (seeded); ``coef`` is (2, tire, axle, facing)."""
    _two, n, _A, _two_f = coef.shape
    if n < NEAR_ZERO_MIN_TIRES:
        return None
    rng = np.random.default_rng(seed)

    exhaustive = _assignments(slot_axle) if n <= half else None             # every split over the axles, if few

    def placement(r):
        if exhaustive is not None:
            tire_of = exhaustive[r]
        else:
            tire_of = np.arange(n) if r == 0 else rng.permutation(n)      # tire_of[k] goes to slot k
        plus, minus = coef[:, tire_of, slot_axle, 0], coef[:, tire_of, slot_axle, 1]
        return tire_of, const + 0.5 * (plus + minus).sum(axis=1), 0.5 * (plus - minus)   # base point, flips

    def plan(tire_of, facing):
        y = np.zeros(coef.shape[1:])
        y[tire_of, slot_axle, np.where(facing > 0, 0, 1)] = 1.0
        return y

    if n <= half:                                                          # every sign pattern
        _S, signs = _signed_sums(np.zeros((2, n)))
        per = max(1, min(256, (1 << 22) >> n))                             # placements per batch
        count = len(exhaustive) if exhaustive is not None else min(NEAR_ZERO_PLACEMENTS,
                                                                     max(NEAR_ZERO_FULL_BUDGET >> n, 1))
        for start in range(0, count, per):
            batch = [placement(r) for r in range(start, min(start + per, count))]
            flips = np.stack([f for _t, _b, f in batch]).reshape(-1, n)      # (P * 2, n): one BLAS product
            pts = np.stack([b for _t, b, _f in batch])[:, :, None] + (flips @ signs.T).reshape(len(batch), 2, -1)
            ok = (np.abs(pts[:, 0]) <= ZERO_M) & (np.abs(pts[:, 1]) <= ZERO_RAD)
            if ok.any():
                p, k = np.argwhere(ok)[0]
                return plan(batch[p][0], signs[k])
        return None
    ka = min(half, n // 2)
    kb = min(half, n - ka)
    for r in range(min(NEAR_ZERO_RESTARTS, max(8, budget >> (ka + kb)))):
        tire_of, point, flip = placement(r)
        order = rng.permutation(n)
        A_idx, B_idx, rest = order[:ka], order[ka:ka + kb], order[ka + kb:]
        point = point + flip[:, rest].sum(axis=1)                          # the rest: serial side +y
        SA, FA = _signed_sums(flip[:, A_idx])
        SB, FB = _signed_sums(flip[:, B_idx])
        srt = np.argsort(SB[0], kind="stable")
        sb0 = SB[0][srt]
        target = -(point[0] + SA[0])
        lo = np.searchsorted(sb0, target - ZERO_M, side="left")
        counts = np.searchsorted(sb0, target + ZERO_M, side="right") - lo
        total = int(counts.sum())
        if not total:
            continue
        a = np.repeat(np.arange(counts.size), counts)
        b = srt[np.repeat(lo, counts) + (np.arange(total) - np.repeat(np.cumsum(counts) - counts, counts))]
        O = point[0] + SA[0][a] + SB[0][b]
        D = point[1] + SA[1][a] + SB[1][b]
        ok = np.flatnonzero((np.abs(O) <= ZERO_M) & (np.abs(D) <= ZERO_RAD))
        if ok.size:
            k = ok[0]
            facing = np.ones(n)
            facing[A_idx], facing[B_idx] = FA[a[k]], FB[b[k]]
            return plan(tire_of, facing)
    return None


def _assignments(slot_axle: np.ndarray) -> list | None:
    """Every distinct placement of the tires (which tires on which axle; the slots of an axle are
    interchangeable) as ``tire_of`` arrays, if they and their serial sides number at most
    :data:`NEAR_ZERO_FULL_BUDGET`; else None (then placements are drawn)."""
    import itertools
    import math
    n = slot_axle.size
    groups = [np.flatnonzero(slot_axle == a) for a in np.unique(slot_axle)]
    total = math.factorial(n)
    for g in groups:
        total //= math.factorial(g.size)
    if total << n > NEAR_ZERO_FULL_BUDGET:
        return None
    out = []

    def split(remaining, k, tire_of):
        if k == len(groups):
            out.append(tire_of.copy())
            return
        for chosen in itertools.combinations(remaining, groups[k].size):
            tire_of[groups[k]] = chosen
            split([t for t in remaining if t not in chosen], k + 1, tire_of)
    split(list(range(n)), 0, np.zeros(n, dtype=int))
    return out


def _signed_sums(vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every signed sum of the columns of ``vectors`` (2, k): the sums (2, 2^k) and the signs of
    column j in each (2^k, k)."""
    k = vectors.shape[1]
    bits = (np.arange(2 ** k)[:, None] >> np.arange(k)[None, :]) & 1
    signs = 1.0 - 2.0 * bits
    return vectors @ signs.T, signs


def place_tires(vehicle: Vehicle, speed_mps: float, tires: list[dict], positions: list[str] | None = None,
                F_const: np.ndarray | None = None, tire_scale: float = 1.0, draws: int = RANDOM_DRAWS,
                seed: int = SEED) -> Placement:
    """The mounting plan of ``tires`` on ``positions`` with the least |trimmed offtracking|.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed [m/s].
    tires : list of dict
        ``id``, ``conicity_N``, ``ply_steer_N`` and optionally ``conicity_moment_Nm``,
        ``ply_steer_moment_Nm`` (see :func:`read_measured_tires`); as many as positions.
    positions : list of str, optional
        ``axle:slot`` (default: every tire position of units 2..N).
    F_const : numpy.ndarray, optional
        A constant generalized force (crossfall, misalignment, other axles' residuals; SI).
    draws, seed : int
        Random placements drawn for comparison.

    Returns
    -------
    Placement

    Raises
    ------
    TrackingError
        Tires and positions differ in number (the message says how many are needed),
        duplicate ids or positions, a plan the solver could not prove optimal.

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> v = load_preset("tractor_semitrailer")
    >>> slots = positions_of(v, None)
    >>> tires = [{"id": f"t{k}", "conicity_N": 40.0 * (-1) ** k, "ply_steer_N": 10.0 * k} for k in range(len(slots))]
    >>> p = place_tires(v, 24.4, tires)
    >>> abs(p.offtracking_m) < 1e-3                    # [m]: the four tires nearly cancel
    True
    """
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import coo_array

    if not vehicle.steered_axles:
        raise TrackingError(f"{vehicle.name} has no steered axle: the trim needs one")
    slots = positions_of(vehicle, positions)
    n = len(slots)
    if len(tires) != n:
        raise TrackingError(f"{len(tires)} tires for {n} positions: "
                            + (f"{len(tires) - n} more tires than positions; name {len(tires)} positions with "
                               "--positions or list fewer tires" if len(tires) > n else
                               f"{n - len(tires)} tires missing: {n} are needed, or name fewer positions"))
    ids = [t["id"] for t in tires]
    dup = next((i for i in ids if ids.count(i) > 1), None)
    if dup is not None:
        raise TrackingError(f"tire id {dup!r} is listed twice")
    c, p, cm, pm = _arrays(tires)
    g = sensitivities(vehicle, speed_mps, tire_scale)
    na = len(vehicle.axles)
    const = np.zeros(2)
    if F_const is not None:
        tr = trim(vehicle, speed_mps, F_const, tire_scale)
        const = np.array([tr.offtracking_m, tr.delta_rad])
    axles = sorted({s.axle for s in slots})
    count = np.array([sum(s.axle == a for s in slots) for a in axles])
    A = len(axles)
    # y[i, a, k]: tire i on axle axles[a], serial side facing +y (k = 0) or -y (k = 1)
    facing = np.array([1.0, -1.0])
    gP = g[:, axles]                                              # (2, A)
    gT = g[:, [na + a for a in axles]]
    coef = (gP[:, None, :, None] * (p[None, :, None, None] + facing[None, None, None, :] * c[None, :, None, None]) +
            gT[:, None, :, None] * (pm[None, :, None, None] + facing[None, None, None, :] * cm[None, :, None, None]))
    coef = coef.reshape(2, n * A * 2)                             # [offtracking m, trim rad] per binary
    nb = n * A * 2
    idx = np.arange(nb).reshape(n, A, 2)
    rows, cols = [], []
    for i in range(n):                                            # every tire once
        rows += [i] * (A * 2)
        cols += list(idx[i].ravel())
    for a in range(A):                                            # every axle its number of tires
        rows += [n + a] * (n * 2)
        cols += list(idx[:, a, :].ravel())
    assign = coo_array((np.ones(len(rows)), (rows, cols)), shape=(n + A, nb + 1)).tocsr()
    assign_lo = np.concatenate([np.ones(n), count])

    def solve(row: int, scale: float, band: float | None):
        """min scale |const[row] + coef[row] y| subject to the assignment and, if given, |O| <= band [m]."""
        cons = [LinearConstraint(assign, assign_lo, assign_lo)]
        t = np.zeros(nb + 1)
        t[nb] = 1.0
        obj = np.concatenate([scale * coef[row], [0.0]])
        c0 = scale * const[row]
        cons += [LinearConstraint(np.vstack([obj - t, obj + t]), [-np.inf, -c0], [-c0, np.inf])]
        if band is not None:    # in micrometres: HiGHS meets a row in metres only to ~1e-6 m
            o = np.concatenate([coef[0], [0.0]]) * 1e6
            cons.append(LinearConstraint(o[None, :], [1e6 * (-band - const[0])], [1e6 * (band - const[0])]))
        integrality = np.ones(nb + 1)
        integrality[nb] = 0
        upper = np.ones(nb + 1)
        upper[nb] = np.inf
        with _quiet_stdout():
            res = milp(t, constraints=cons, integrality=integrality, bounds=Bounds(np.zeros(nb + 1), upper),
                       options=dict(disp=False, mip_rel_gap=0.0, time_limit=TIME_LIMIT_S))
        if res.status != 0 or res.x is None:
            raise TrackingError(f"the placement program was not solved to optimality: {res.message}")
        y = np.round(res.x[:nb]).reshape(n, A, 2)
        if not (np.all(y.sum(axis=(1, 2)) == 1) and np.all(y.sum(axis=(0, 2)) == count)):
            raise TrackingError("the placement program returned a plan that is not an assignment")
        return y, float(res.fun), float(getattr(res, "mip_dual_bound", res.fun))

    def relaxed() -> float:
        """The least |O| [m] of the linear relaxation (tires split over axles and sides): a lower bound."""
        t = np.zeros(nb + 1)
        t[nb] = 1.0
        obj = np.concatenate([coef[0], [0.0]])
        cons = [LinearConstraint(assign, assign_lo, assign_lo),
                LinearConstraint(np.vstack([obj - t, obj + t]), [-np.inf, -const[0]], [-const[0], np.inf])]
        upper = np.ones(nb + 1)
        upper[nb] = np.inf
        with _quiet_stdout():
            res = milp(t, constraints=cons, integrality=np.zeros(nb + 1), bounds=Bounds(np.zeros(nb + 1), upper))
        return float(res.fun) if res.status == 0 else 0.0

    slot_axle = np.array([axles.index(sl.axle) for sl in slots])
    # a plan at zero is searched for only where the relaxation allows one (a set whose ply steer
    # points one way cannot cancel: its optimum is away from zero and the program proves it fast)
    y = _near_zero_plan(coef.reshape(2, n, A, 2), const, slot_axle, seed) if relaxed() <= ZERO_M else None
    if y is not None:
        # |O| <= ZERO_M and |trim steer| <= ZERO_RAD: optimal for both programs, as no
        # plan does better than 0 (the plan lies in every tie band, whatever the least |O| is)
        bound, o_first = 0.0, abs(const[0] + coef[0] @ y.ravel())
    else:
        y, _t_off, bound = solve(0, 1.0, None)
        # ties: within TIE_M of the least |offtracking|, the least |trim steer| (to TIE_GAP_RAD).  The
        # band is set from the first plan's own offtracking (HiGHS meets rows in metres only to
        # about 1e-6 m, so its objective may undercut it), narrowed by FEASIBILITY_M, and written
        # in micrometres; the tie plan is kept only if it keeps the band.
        o_first = abs(const[0] + coef[0] @ y.ravel())
        try:
            y2 = solve(1, GAP_M / TIE_GAP_RAD, o_first + TIE_M - FEASIBILITY_M)[0]   # HiGHS's gap: TIE_GAP_RAD
            if abs(const[0] + coef[0] @ y2.ravel()) <= o_first + TIE_M:
                y = y2
        except TrackingError:
            pass                                                  # keep the first plan: it is optimal for O
    order, face = [None] * n, [0.0] * n
    for a_k, a in enumerate(axles):
        free = [k for k, s in enumerate(slots) if s.axle == a]
        for i, k_f in zip(*np.nonzero(y[:, a_k, :])):
            k = free.pop(0)
            order[k], face[k] = int(i), float(facing[k_f])
    mounted = _mount(slots, tires, order, face)
    off, dlt = _evaluate(vehicle, speed_mps, mounted, F_const, tire_scale)
    y_vec = y.ravel()
    if abs(off - (const[0] + coef[0] @ y_vec)) > CHECK_M or abs(off) > o_first + TIE_M + CHECK_M or \
            abs(off) - bound > GAP_M + TIE_M + CHECK_M:
        raise TrackingError(f"the placement program's plan does not check: offtracking {off:.9g} m mounted, "
                            f"{const[0] + coef[0] @ y_vec:.9g} m in the program, lower bound {bound:.9g} m")
    listed = _mount(slots, tires, range(n), [s.side for s in slots])
    off_l, dlt_l = _evaluate(vehicle, speed_mps, listed, F_const, tire_scale)
    # random placements: a random permutation of the tires and random serial sides, vectorised
    rng = np.random.default_rng(seed)
    g_slot = np.array([[g[0, s.axle], g[0, na + s.axle]] for s in slots])          # (n, 2)
    perm = rng.permuted(np.tile(np.arange(n), (draws, 1)), axis=1)
    sgn = rng.choice(facing, size=(draws, n))
    rand = const[0] + ((p[perm] + sgn * c[perm]) * g_slot[:, 0]).sum(1) + ((pm[perm] + sgn * cm[perm]) * g_slot[:, 1]).sum(1)
    plan = [{"position": m["position"], "tire": m["id"], "serial_side": m["serial_side"]} for m in mounted]
    return Placement(plan, float(off), float(dlt), max(0.0, bound - GAP_M), float(off_l), float(dlt_l), rand, seed)
