"""Exact zero-order-hold discretization of the model augmented with global position.

The state is augmented with the tractor heading psi1 and the global lateral position
Y1 of its CG (``psi1' = r1``, ``Y1' = v1 + u psi1``): ``z = [x, psi1, Y1]`` (SI).
For a generalized force F held over a step h, ``z(t+h) = Ad z(t) + Gd F`` with
``exp([[A, G], [0, 0]] h) = [[Ad, Gd], [0, I]]`` -- exact for any step size.

Examples
--------
>>> from lcvreport import load_preset
>>> disc = Discretizer(load_preset("aucnat"))
>>> Ad, Gd = disc(22.352, 0.01)
>>> Ad.shape, Gd.shape
((14, 14), (14, 12))
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..model.linear import linear_model
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import SystemCoefficients
from ..util.cache import LRUCache

#: names of the two states appended to the model state for global position
GLOBAL_STATES = ("psi1", "Y1")


def augmented_state_matrix(co: SystemCoefficients, speed_mps: float, tire_scale: float = 1.0
                           ) -> tuple[np.ndarray, np.ndarray]:
    """``A_aug`` and ``G`` of ``z' = A_aug z + G F`` with ``z = [x, psi1, Y1]``.

    Parameters
    ----------
    co : SystemCoefficients
        In the unit system of F and z (SI normally).
    speed_mps : float
        Forward speed [m/s].
    tire_scale : float

    Returns
    -------
    A_aug : numpy.ndarray, shape (2N+2, 2N+2)
    G : numpy.ndarray, shape (2N+2, 2N)
        ``[M^-1; 0; 0]`` mapping the generalized force to state rates.
    """
    n = co.n_states
    A_x, Minv = co.state_derivative_maps(speed_mps, tire_scale)
    A = np.zeros((n + 2, n + 2))
    A[:n, :n] = A_x
    A[n, 1] = 1.0                               # psi1' = r1
    A[n + 1, 0] = 1.0                           # Y1' = v1 + u psi1
    A[n + 1, n] = float(co.units.speed(speed_mps))
    G = np.zeros((n + 2, n))
    G[:n] = Minv
    return A, G


def discretize(A: np.ndarray, G: np.ndarray, h: float, expm=None) -> tuple[np.ndarray, np.ndarray]:
    """Exact zero-order-hold discretization over a step ``h`` [s].

    Parameters
    ----------
    A, G : numpy.ndarray
        From :func:`augmented_state_matrix`.
    h : float
        Step [s].
    expm : callable, optional
        Matrix exponential (default ``scipy.linalg.expm``; the FMU engine passes
        :func:`lcvreport.util.numerics.expm`, which needs numpy only).

    Returns
    -------
    Ad, Gd : numpy.ndarray
    """
    if expm is None:
        from scipy.linalg import expm
    n, m = G.shape
    big = np.zeros((n + m, n + m))
    big[:n, :n] = A * h
    big[:n, n:] = G * h
    E = expm(big)
    return E[:n, :n], E[:n, n:]


@dataclass
class Discretizer:
    """Cache of exact discretizations of one vehicle keyed by (speed, tire scale, step).

    Repeated speeds and step sizes cost a dictionary look-up; the cache keeps the
    ``maxsize`` most recently used entries.
    """

    vehicle: Vehicle
    maxsize: int = 64
    model: str = "yaw_plane"
    _cache: LRUCache = field(default=None, repr=False)

    def __call__(self, speed_mps: float, h: float, tire_scale: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
        """(Ad, Gd) for forward speed [m/s], step h [s] and tire scale [-] (SI)."""
        if self._cache is None:
            self._cache = LRUCache(self.maxsize)

        def compute():
            A, G = augmented_state_matrix(linear_model(self.vehicle, self.model), speed_mps, tire_scale)
            out = discretize(A, G, h)
            for arr in out:
                arr.setflags(write=False)
            return out

        return self._cache.get((float(speed_mps), float(h), float(tire_scale)), compute)

    @property
    def cache_size(self) -> int:
        """Number of cached discretizations."""
        return 0 if self._cache is None else len(self._cache)
