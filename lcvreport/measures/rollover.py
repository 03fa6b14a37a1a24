r"""The static rollover threshold: the quasi-static roll plane of each roll-coupled group,
piecewise linear, axle by axle lift-off, exact events (docs/roll.md#static-rollover-threshold).

Every unit of a group at the same steady lateral acceleration ``a_y``; axle lateral forces in
proportion to the static loads, ``F_y,j = F_z0,j a_y / g``; rigid tires, no lash.  Roll ``phi_i``,
the suspension moments ``M_j`` and the load transfers are measured toward the outside of the
turn.  Unit i's balance about its roll axis::

    m_s e (a_y + g phi_i) + sum_k +-W_k (h_c,k - h_r,i)(a_y/g + phi_i) - sum_j M_j - sum_k +-k_c,k (phi_k - phi_(k+1)) = 0

with ``M_j = K_j phi_i`` while axle j's inner wheels carry load, ``dF_j T_j = M_j + h_r,i F_y,j``;
when ``dF_j`` reaches ``F_z0,j / 2`` the wheels lift and ``M_j = F_z0,j T_j / 2 - h_r,i F_y,j`` from
then on.  Between lift-offs the path is linear, ``Kt phi = a_y q + c`` (``Kt`` the tangent roll
stiffness of the group, ``q`` and ``c`` the lateral and the lifted axles' terms), so each next
lift-off is the root of a linear function: the events are exact.  SRT is the ``a_y / g`` at which
``Kt`` stops being positive definite (the path turns back); a group not stable at rest has SRT 0.

Examples
--------
>>> from lcvreport import load_vehicle
>>> t = rollover_threshold(load_vehicle("examples/vehicles/western_double.toml"))
>>> [round(g.srt_g, 3) for g in t.groups], round(t.srt_min_g, 3)
([0.492, 0.468], 0.468)
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.vehicle import Vehicle
from ..model.yaw_roll.parameters import G_MPS2, RollParameters, roll_parameters

#: lift-offs within this fraction of a_y of each other are one event
SIMULTANEOUS = 1e-12


@dataclass(frozen=True)
class GroupThreshold:
    """The rollover threshold of one roll-coupled group.

    Attributes
    ----------
    units : tuple of str
        Its units, front to rear.
    srt_g : float
        The static rollover threshold [g].
    lift_off_g : dict
        Axle name -> a_y/g at its inner wheels' lift-off, or None if it does not lift at or
        before SRT.
    stable_at_rest : bool
        False when the group's roll stiffness cannot hold its sprung weight at rest (SRT 0).
    path_g : numpy.ndarray, shape (events + 1,)
        a_y/g at rest and at every lift-off up to SRT (the a_y - phi curve's corners).
    path_phi_rad : numpy.ndarray, shape (events + 1, units)
        The outward roll of every unit there [rad].
    """

    units: tuple
    srt_g: float
    lift_off_g: dict
    stable_at_rest: bool = True
    path_g: np.ndarray = field(default=None, repr=False)
    path_phi_rad: np.ndarray = field(default=None, repr=False)


@dataclass(frozen=True)
class RolloverThreshold:
    """Every group's threshold, front to rear (:func:`rollover_threshold`)."""

    vehicle: Vehicle
    groups: tuple

    @property
    def srt_min_g(self) -> float:
        """The weakest group's SRT [g]."""
        return min(g.srt_g for g in self.groups)

    @property
    def srt_rrcu_g(self) -> float:
        """The rearmost roll-coupled unit's (group's) SRT [g]."""
        return self.groups[-1].srt_g

    def to_dict(self) -> list:
        """The ``groups`` of ``lcv roll --json``."""
        return [{"units": list(g.units), "srt_g": g.srt_g, "lift_off_g": dict(g.lift_off_g)} for g in self.groups]

    def plot(self, ax=None):
        """The a_y - phi curve of every group, each lift-off marked (a tilt-table chart)."""
        from ..plotting.roll import plot_rollover
        return plot_rollover(self, ax)


def _positive_definite(K: np.ndarray) -> bool:
    if K.size == 0:
        return False
    try:
        np.linalg.cholesky(0.5 * (K + K.T))
    except np.linalg.LinAlgError:
        return False
    return True


def group_threshold(vehicle: Vehicle, rp: RollParameters, units: tuple) -> GroupThreshold:
    """The threshold of the group ``units`` (0-based unit indices, consecutive)."""
    g = G_MPS2
    first = units[0]
    nG = len(units)
    local = {u: k for k, u in enumerate(units)}
    axles = [j for j, i in enumerate(rp.axle_unit) if i in local]
    names = vehicle.axle_names
    # the lift-free balance: Kt phi = a q (a = a_y in m/s^2)
    Kt = np.zeros((nG, nG))
    q = np.zeros(nG)
    for i in units:
        k = local[i]
        Kt[k, k] -= rp.ms_kg[i] * g * rp.e_m[i]
        q[k] += rp.ms_kg[i] * rp.e_m[i]
        for c, sign in ((i, 1.0), (i - 1, -1.0)):          # rear coupling (carries W) and front coupling
            if 0 <= c < vehicle.n_units - 1:
                arm = rp.hc_m[c] - rp.hr_m[i]
                Kt[k, k] -= sign * rp.W_N[c] * arm
                q[k] += sign * rp.W_N[c] * arm / g
        if first <= i - 1:                                  # the coupling ahead, inside the group
            kc = rp.kc_Nm_per_rad[i - 1]
            a, b = local[i - 1], k
            Kt[a, a] += kc
            Kt[b, b] += kc
            Kt[a, b] -= kc
            Kt[b, a] -= kc
    for j in axles:
        Kt[local[rp.axle_unit[j]], local[rp.axle_unit[j]]] += rp.K_Nm_per_rad[j]
    lift = {names[j]: None for j in axles}
    active = set(axles)
    c = np.zeros(nG)
    a_now, phi_now = 0.0, np.zeros(nG)
    path_a, path_phi = [0.0], [phi_now]
    if not _positive_definite(Kt):
        return GroupThreshold(tuple(vehicle.unit_names[i] for i in units), 0.0, lift, False,
                              np.array(path_a), np.array(path_phi))
    while True:
        # phi(a) = phi0 + a dphi on this phase; each active axle's margin K phi_i + h_r F_z0 a/g - F_z0 T/2
        dphi = np.linalg.solve(Kt, q)
        phi0 = np.linalg.solve(Kt, c)
        best, hits = np.inf, []
        for j in active:
            k = local[rp.axle_unit[j]]
            hr = rp.hr_m[rp.axle_unit[j]]
            slope = rp.K_Nm_per_rad[j] * dphi[k] + hr * rp.Fz0_N[j] / g
            value0 = rp.K_Nm_per_rad[j] * phi0[k] - rp.Fz0_N[j] * rp.T_m[j] / 2
            if slope <= 0:
                continue
            a_j = max(-value0 / slope, a_now)
            if a_j < best * (1 - SIMULTANEOUS):
                best, hits = a_j, [j]
            elif a_j <= best * (1 + SIMULTANEOUS):
                hits.append(j)
                best = min(best, a_j)
        if not hits:                        # nothing lifts: the path never ends (no axle carries a moment)
            raise ValueError(f"{vehicle.name}: the group {[vehicle.unit_names[i] for i in units]} has no axle "
                             "whose wheels can lift: its roll threshold is unbounded")
        a_now = best
        phi_now = phi0 + a_now * dphi
        path_a.append(a_now)
        path_phi.append(phi_now)
        for j in hits:
            lift[names[j]] = float(a_now / g)
            active.discard(j)
            k = local[rp.axle_unit[j]]
            Kt[k, k] -= rp.K_Nm_per_rad[j]
            q[k] += rp.hr_m[rp.axle_unit[j]] * rp.Fz0_N[j] / g
            c[k] -= rp.Fz0_N[j] * rp.T_m[j] / 2
        if not active or not _positive_definite(Kt):
            break
    return GroupThreshold(tuple(vehicle.unit_names[i] for i in units), float(a_now / g), lift, True,
                          np.array(path_a) / g, np.array(path_phi))


def rollover_threshold(vehicle: Vehicle) -> RolloverThreshold:
    """The static rollover threshold of every roll-coupled group of ``vehicle``.

    Raises
    ------
    VehicleError
        Missing or invalid roll data, naming the unit, the axle and the key.
    """
    rp = roll_parameters(vehicle)
    return RolloverThreshold(vehicle, tuple(group_threshold(vehicle, rp, units) for units in rp.groups))
