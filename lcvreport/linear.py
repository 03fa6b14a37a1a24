r"""Linear analysis: eigenvalues and modes, steady state, exact forced response.

* Free vibration (thesis 3.4): eigenvalues of ``M^-1 S``, damped frequency, damping
  ratio ``zeta = -Re(lambda)/|lambda|``, mode shapes.  Modes are ordered by real
  part, most negative first (the order of eq. 4.14), the member of a conjugate
  pair with positive imaginary part first, real eigenvalues after complex ones of
  equal real part.  Mode shapes are scaled so that their largest component is 1.
* Forced response: exact for inputs held constant over each interval (zero-order
  hold) through the exponential of the augmented matrix (:class:`Discretization`),
  for any step size and with the speed changing between intervals.  The state is
  augmented with the tractor heading psi1 and global lateral position Y1
  (``psi1' = r1``, ``Y1' = v1 + u psi1``).
* Steady state: ``x_ss = -S^-1 F``.
* Modal superposition: exact with left and right eigenvectors (``Y^T M X = I``);
  the thesis' method (``X^T M X = 1``, ``g = X^T F``, eq. 3.21/3.28) is kept as a
  labelled reproduction mode, exact only for symmetric M and S (SPEC erratum 3).

Units: thesis units throughout (in, lbf, s, rad).
"""
from __future__ import annotations

from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg

from .model import SystemCoefficients, check_speed, check_tire_scale, system_coefficients
from .vehicle import Train

#: names of the two states appended to the thesis state for global position
GLOBAL_STATES = ("psi1", "Y1")


# --------------------------------------------------------------------------- modes
@dataclass(frozen=True)
class Modes:
    """Eigen-analysis of one (train, speed, tire scale).

    Attributes
    ----------
    eigenvalues : numpy.ndarray, shape (2N,)
        Complex eigenvalues [1/s], in the documented order.
    shapes : numpy.ndarray, shape (2N, 2N)
        Right eigenvectors as columns, thesis state order, largest component 1.
    state_names : tuple of str
    """

    eigenvalues: np.ndarray
    shapes: np.ndarray
    state_names: tuple[str, ...]

    @property
    def natural_frequency(self) -> np.ndarray:
        """Undamped natural frequency |lambda| [rad/s]."""
        return np.abs(self.eigenvalues)

    @property
    def damped_frequency(self) -> np.ndarray:
        """Damped frequency |Im lambda| [rad/s]."""
        return np.abs(self.eigenvalues.imag)

    @property
    def damped_frequency_hz(self) -> np.ndarray:
        """Damped frequency |Im lambda| / 2 pi [Hz]."""
        return self.damped_frequency / (2 * np.pi)

    @property
    def damping_ratio(self) -> np.ndarray:
        """Damping ratio zeta = -Re lambda / |lambda| [-] (1 for a real negative root)."""
        return -self.eigenvalues.real / np.abs(self.eigenvalues)

    @property
    def time_constant(self) -> np.ndarray:
        """Time constant -1/Re lambda [s] (inf where Re lambda = 0)."""
        with np.errstate(divide="ignore"):
            return -1.0 / self.eigenvalues.real

    @property
    def stable(self) -> bool:
        """True when every eigenvalue has a negative real part."""
        return bool(np.all(self.eigenvalues.real < 0))

    @property
    def max_real(self) -> float:
        """Largest real part [1/s] (the stability margin, negative when stable)."""
        return float(self.eigenvalues.real.max())

    def dominant(self, state: str, among: tuple[str, ...] | None = None) -> int:
        """Index of the oscillatory mode (positive imaginary part) in which ``state``
        has the largest share of the magnitudes of the states ``among`` (all yaw
        rates by default): e.g. ``dominant("r5")`` is the mode of dolly 2 (Figure 2-2)."""
        names = list(self.state_names)
        among = among or tuple(n for n in names if n.startswith("r"))
        idx = [names.index(n) for n in among]
        k = names.index(state)
        best, best_share = -1, -1.0
        for j in range(self.eigenvalues.size):
            if self.eigenvalues[j].imag <= 0:
                continue
            mags = np.abs(self.shapes[idx, j])
            share = abs(self.shapes[k, j]) / mags.sum()
            if share > best_share:
                best, best_share = j, share
        if best < 0:
            raise ValueError("no oscillatory mode")
        return best

    def table(self) -> list[dict]:
        """One row per mode: eigenvalue [1/s], damped frequency [rad/s, Hz], zeta [-]."""
        return [dict(mode=i + 1, real_per_s=float(l.real), imag_per_s=float(l.imag),
                     damped_frequency_rad_per_s=float(w), damped_frequency_hz=float(f), damping_ratio=float(z))
                for i, (l, w, f, z) in enumerate(zip(self.eigenvalues, self.damped_frequency,
                                                     self.damped_frequency_hz, self.damping_ratio))]


def mode_order(eigenvalues: np.ndarray) -> np.ndarray:
    """Indices sorting eigenvalues by real part (ascending), then imaginary part (descending).

    Works along the last axis.  Real parts are compared after rounding to 1e-9
    relative to the spectral radius, so that the two members of a conjugate pair
    always tie and the one with positive imaginary part comes first.
    """
    lam = np.asarray(eigenvalues)
    scale = np.abs(lam).max(axis=-1, keepdims=True)
    scale = np.where(scale > 0, scale, 1.0)
    re = np.round(lam.real / scale, 9)
    first = np.argsort(-lam.imag, axis=-1, kind="stable")
    second = np.argsort(np.take_along_axis(re, first, axis=-1), axis=-1, kind="stable")
    return np.take_along_axis(first, second, axis=-1)


def sort_eigenvalues(eigenvalues: np.ndarray) -> np.ndarray:
    """Eigenvalues in the documented mode order (along the last axis, batches allowed)."""
    lam = np.asarray(eigenvalues)
    return np.take_along_axis(lam, mode_order(lam), axis=-1)


def modes(train: Train, speed: float, tire_scale: float = 1.0) -> Modes:
    """Eigenvalues and mode shapes of ``M^-1 S``.

    Parameters
    ----------
    train : Train
    speed : float
        Forward speed [in/s].
    tire_scale : float
        Tire coefficient factor [-].

    Returns
    -------
    Modes
    """
    check_speed(speed)
    check_tire_scale(tire_scale)
    co = system_coefficients(train)
    lam, X = scipy.linalg.eig(co.S(speed, tire_scale), co.M(speed))
    order = mode_order(lam)
    lam, X = lam[order], X[:, order]
    k = np.argmax(np.abs(X), axis=0)
    X = X / X[k, np.arange(X.shape[1])]
    return Modes(lam, X, train.state_names)


def eigenvalues(train: Train, speed: float | np.ndarray, tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
    """Eigenvalues [1/s] in mode order; broadcasts over arrays of speed [in/s] and tire scale."""
    check_speed(speed)
    check_tire_scale(tire_scale)
    co = system_coefficients(train)
    A = np.linalg.solve(co.M(speed), co.S(speed, tire_scale))
    return sort_eigenvalues(np.linalg.eigvals(A))


def eigen_steady_sweep(train: Train, speed: np.ndarray, F: np.ndarray,
                       tire_scale: float | np.ndarray = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """Eigenvalues and steady states of one train over many speeds and tire scales at once.

    Parameters
    ----------
    train : Train
    speed : numpy.ndarray, shape (K,)
        Forward speeds [in/s].
    F : numpy.ndarray, shape (2N,)
        Generalized force, thesis units.
    tire_scale : float or numpy.ndarray, shape (K,)

    Returns
    -------
    eigenvalues : numpy.ndarray, shape (K, 2N)
        [1/s], mode order.
    x_ss : numpy.ndarray, shape (K, 2N)
        Steady states ``-S^-1 F`` (v1 in/s, r rad/s, theta rad).
    """
    check_speed(speed)
    check_tire_scale(tire_scale)
    co = system_coefficients(train)
    S = co.S(speed, tire_scale)
    A = np.linalg.solve(co.M(speed), S)
    lam = sort_eigenvalues(np.linalg.eigvals(A))
    Fb = np.broadcast_to(np.asarray(F, dtype=float), S.shape[:-1])
    x = -np.linalg.solve(S, Fb[..., None])[..., 0]
    return lam, x


# --------------------------------------------------------------------- steady state
def steady_state(train: Train, speed: float | np.ndarray, F: np.ndarray,
                 tire_scale: float | np.ndarray = 1.0) -> np.ndarray:
    """Steady state ``x_ss = -S^-1 F`` under a constant generalized force.

    Parameters
    ----------
    train : Train
    speed : float or array
        Forward speed [in/s]; broadcasts.
    F : numpy.ndarray, shape (..., 2N)
        Generalized force in thesis units (see :mod:`lcvreport.loads`).
    tire_scale : float or array

    Returns
    -------
    numpy.ndarray, shape (..., 2N)
        v1 [in/s], r [rad/s], theta [rad].
    """
    check_speed(speed)
    check_tire_scale(tire_scale)
    S = system_coefficients(train).S(speed, tire_scale)
    F = np.asarray(F, dtype=float)
    Fb = np.broadcast_to(F, S.shape[:-1])
    return -np.linalg.solve(S, Fb[..., None])[..., 0]


# ------------------------------------------------------------ outputs and geometry
def unit_lengths(train: Train) -> np.ndarray:
    """Front joint to rear joint (rear end for the last unit) of units 2..N [in]."""
    return np.array([u.length_between_ends_in for u in train.units[1:]])


def rear_displacements(train: Train, theta: np.ndarray) -> np.ndarray:
    """Lateral displacement of the rear end of units 2..N relative to the tractor axis.

    Eq. 3.43 and 4.42-4.46: ``y_k = y_(k-1) + L_k sin(thetaA + ... + theta_(k-1))``.

    Parameters
    ----------
    train : Train
    theta : numpy.ndarray, shape (..., N-1)
        Articulation angles [rad].

    Returns
    -------
    numpy.ndarray, shape (..., N-1)
        y2 .. yN [in].
    """
    theta = np.asarray(theta, dtype=float)
    return np.cumsum(unit_lengths(train) * np.sin(np.cumsum(theta, axis=-1)), axis=-1)


def rear_end_global(train: Train, psi1: np.ndarray, Y1: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """Global lateral position of the last unit's rear end [in] (small angles).

    ``Y_rear = Y1 - x1A psi1 - sum_k L_k psi_k`` with ``psi_k = psi1 - sum_(j<k) theta_j``.
    """
    theta = np.asarray(theta, dtype=float)
    psi = np.asarray(psi1, dtype=float)[..., None] - np.cumsum(theta, axis=-1)
    return np.asarray(Y1) - train.units[0].rear_joint_in * np.asarray(psi1) - np.sum(unit_lengths(train) * psi, axis=-1)


# ------------------------------------------------------------- exact discretization
def augmented_state_matrix(co: SystemCoefficients, speed: float, tire_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """``A_aug`` and ``G`` of ``z' = A_aug z + G F`` with ``z = [x, psi1, Y1]``.

    Returns
    -------
    A_aug : numpy.ndarray, shape (2N+2, 2N+2)
    G : numpy.ndarray, shape (2N+2, 2N)
        ``[M^-1; 0; 0]`` mapping the generalized force to state rates.
    """
    n = co.n_states
    M = co.M(speed)
    Minv = np.linalg.inv(M)
    A = np.zeros((n + 2, n + 2))
    A[:n, :n] = Minv @ co.S(speed, tire_scale)
    A[n, 1] = 1.0            # psi1' = r1
    A[n + 1, 0] = 1.0        # Y1' = v1 + u psi1
    A[n + 1, n] = speed
    G = np.zeros((n + 2, n))
    G[:n] = Minv
    return A, G


def discretize(A: np.ndarray, G: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization over a step ``h`` [s].

    ``exp([[A, G], [0, 0]] h) = [[Ad, Gd], [0, I]]`` so that
    ``z(t+h) = Ad z(t) + Gd F`` for F held constant over the step.
    """
    n, m = G.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n] = A * h
    big[:n, n:] = G * h
    E = scipy.linalg.expm(big)
    return E[:n, :n], E[:n, n:]


class LRUCache:
    """A small least-recently-used cache: ``get(key, compute)`` returns the cached value
    or stores ``compute()``; at most ``maxsize`` entries are kept."""

    def __init__(self, maxsize: int = 64):
        self.maxsize = int(maxsize)
        self._data: OrderedDict = OrderedDict()

    def get(self, key, compute):
        """The value for ``key``, computed by ``compute()`` on a miss."""
        hit = self._data.get(key)
        if hit is not None:
            self._data.move_to_end(key)
            return hit
        value = compute()
        self._data[key] = value
        if len(self._data) > self.maxsize:
            self._data.popitem(last=False)
        return value

    def __len__(self) -> int:
        return len(self._data)


@dataclass
class Discretizer:
    """Cache of exact discretizations of one train keyed by (speed, tire scale, step).

    Repeated speeds and step sizes cost a dictionary look-up; the cache keeps the
    ``maxsize`` most recently used entries.
    """

    train: Train
    maxsize: int = 64
    _cache: LRUCache | None = field(default=None, repr=False)

    def __call__(self, speed: float, h: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(Ad, Gd) for forward speed [in/s], step h [s] and tire scale [-]."""
        if self._cache is None:
            self._cache = LRUCache(self.maxsize)

        def compute():
            A, G = augmented_state_matrix(system_coefficients(self.train), speed, tire_scale)
            out = discretize(A, G, h)
            for arr in out:
                arr.setflags(write=False)
            return out

        return self._cache.get((float(speed), float(h), float(tire_scale)), compute)

    @property
    def cache_size(self) -> int:
        """Number of cached discretizations."""
        return 0 if self._cache is None else len(self._cache)


# ------------------------------------------------------------------ time responses
@dataclass(frozen=True)
class TimeResponse:
    """Time histories of one simulation, read by name.

    Attributes
    ----------
    time : numpy.ndarray, shape (K,)
        [s]
    states : numpy.ndarray, shape (K, 2N+2)
        ``[v1 (in/s), r1..rN (rad/s), thetaA.. (rad), psi1 (rad), Y1 (in)]``.
    train : Train
    label : str
    """

    time: np.ndarray
    states: np.ndarray
    train: Train
    label: str = ""

    @property
    def names(self) -> tuple[str, ...]:
        """State names, thesis order then psi1, Y1."""
        return self.train.state_names + GLOBAL_STATES

    def __getitem__(self, name: str) -> np.ndarray:
        """Signal by name: a state, ``y2``..``yN`` [in], or ``Y_rear`` [in]."""
        if name in self.names:
            return self.states[:, self.names.index(name)]
        n = self.train.n_units
        if name.startswith("y") and name[1:].isdigit() and 2 <= int(name[1:]) <= n:
            return self.rear_displacements[:, int(name[1:]) - 2]
        if name == "Y_rear":
            return rear_end_global(self.train, self["psi1"], self["Y1"], self.theta)
        raise KeyError(f"unknown signal {name!r}; valid: {', '.join(self.names)}, y2..y{n}, Y_rear")

    @property
    def theta(self) -> np.ndarray:
        """Articulation angles [rad], shape (K, N-1)."""
        n = self.train.n_units
        return self.states[:, n + 1:2 * n]

    @property
    def rear_displacements(self) -> np.ndarray:
        """y2..yN [in] of eq. 4.42-4.46, shape (K, N-1)."""
        return rear_displacements(self.train, self.theta)


def simulate(train: Train, time: np.ndarray, speed: float | np.ndarray, forces: np.ndarray,
             tire_scale: float = 1.0, initial_state: np.ndarray | None = None,
             discretizer: Discretizer | None = None, label: str = "") -> TimeResponse:
    """Exact response to generalized forces held constant between time points.

    Parameters
    ----------
    train : Train
    time : numpy.ndarray, shape (K,)
        Increasing time points [s]; any spacing.
    speed : float or numpy.ndarray, shape (K-1,)
        Forward speed on each interval [in/s].
    forces : numpy.ndarray, shape (2N,) or (K-1, 2N)
        Generalized force on each interval (zero-order hold), thesis units.
    tire_scale : float
    initial_state : numpy.ndarray, shape (2N+2,), optional
        ``[x, psi1, Y1]`` at ``time[0]``; rest when omitted.
    discretizer : Discretizer, optional
        Reuse a cache across calls.
    label : str

    Returns
    -------
    TimeResponse
        States at every time point, exact for the held inputs.
    """
    t = np.asarray(time, dtype=float)
    if t.ndim != 1 or t.size < 1 or np.any(np.diff(t) <= 0) or not np.all(np.isfinite(t)):
        raise ValueError("time must be a 1-D, finite, strictly increasing array")
    k = t.size - 1
    u = np.broadcast_to(np.asarray(speed, dtype=float), (k,))
    check_speed(u)
    check_tire_scale(tire_scale)
    n = 2 * train.n_units
    f = np.broadcast_to(np.asarray(forces, dtype=float), (k, n))
    disc = discretizer or Discretizer(train)
    z = np.zeros((t.size, n + 2))
    if initial_state is not None:
        z[0] = initial_state
    h = np.diff(t)
    for i in range(k):
        Ad, Gd = disc(u[i], h[i], tire_scale)
        z[i + 1] = Ad @ z[i] + Gd @ f[i]
    return TimeResponse(t, z, train, label)


def step_response(train: Train, speed: float, F: np.ndarray, t_end: float, n_points: int = 1001,
                  tire_scale: float = 1.0, label: str = "") -> TimeResponse:
    """Exact response from rest to a constant generalized force F (the thesis' step input).

    Parameters
    ----------
    train : Train
    speed : float
        Forward speed [in/s].
    F : numpy.ndarray, shape (2N,)
        Generalized force, thesis units.
    t_end : float
        End time [s].
    n_points : int
        Number of evenly spaced output points including t = 0.
    tire_scale : float
    label : str
    """
    t = np.linspace(0.0, float(t_end), int(n_points))
    return simulate(train, t, speed, F, tire_scale=tire_scale, label=label)


# -------------------------------------------------------------- modal superposition
def modal_response(train: Train, speed: float, F: np.ndarray, time: np.ndarray, tire_scale: float = 1.0,
                   method: str = "exact") -> np.ndarray:
    """Response from rest to a constant force by modal superposition.

    Parameters
    ----------
    train, speed, F, tire_scale
        As :func:`step_response`.
    time : numpy.ndarray
        Output times [s].
    method : {"exact", "thesis"}
        ``exact``: left and right eigenvectors with ``Y^T M X = I`` and ``g = Y^T F``
        (exact for the non-symmetric M, S).  ``thesis``: the dissertation's eq.
        3.21, 3.26-3.32: ``X_i^T M X_i = 1``, ``g_i = X_i^T F``
        (a labelled reproduction mode, not exact).

    Returns
    -------
    numpy.ndarray, shape (K, 2N)
        Thesis states at ``time``.
    """
    check_speed(speed)
    check_tire_scale(tire_scale)
    co = system_coefficients(train)
    M, S = co.M(speed), co.S(speed, tire_scale)
    g, X, lam = modal_coefficients(M, S, F, method)
    t = np.asarray(time, dtype=float)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(lam == 0, g * t, g * np.expm1(lam * t) / lam)
    return (c @ X.T).real


def modal_coefficients(M: np.ndarray, S: np.ndarray, F: np.ndarray, method: str = "exact"
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Modal load coefficients g, normalized right eigenvectors X and eigenvalues.

    See :func:`modal_response` for ``method``.  Eigenvalues are in mode order.
    """
    if method not in ("exact", "thesis"):
        raise ValueError(f"method must be 'exact' or 'thesis', got {method!r}")
    lam, Yl, X = scipy.linalg.eig(S, M, left=True, right=True)
    order = mode_order(lam)
    lam, Yl, X = lam[order], Yl[:, order], X[:, order]
    if method == "exact":
        # left eigenvectors: Yl^H S = lam Yl^H M; use Y = conj(Yl) so that Y^T M X is diagonal
        Y = Yl.conj()
        scale = np.einsum("ij,ik,kj->j", Y, M, X)
        Y = Y / scale
        g = Y.T @ F
    else:
        norm = np.sqrt(np.einsum("ij,ik,kj->j", X, M, X))
        X = X / norm
        g = X.T @ F
    return g, X, lam
