"""Free vibration: eigenvalues and mode shapes of ``M^-1 S`` (thesis section 3.4).

Damped frequency, damping ratio ``zeta = -Re(lambda)/|lambda|``, mode shapes,
stability.  Modes are ordered by real part, most negative first (the order of
eq. 4.14), the member of a conjugate pair with positive imaginary part first, real
eigenvalues after complex ones of equal real part.  Mode shapes are scaled so that
their largest component is 1.  Eigenvalues are in 1/s whatever the unit system.

Examples
--------
>>> from lcvreport import load_preset, modes
>>> from lcvreport.units import mph_to_mps
>>> m = modes(load_preset("tractor_semitrailer", masses="unrounded"), mph_to_mps(50.0))
>>> complex(m.eigenvalues[0]).real.__round__(3), m.stable       # eq. 3.20: -3.0109 +- 4.4006i
(-3.011, True)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.linear import check_speed, check_tire_scale, linear_model
from ..model.vehicle import Vehicle
from ..util.numerics import solve_scaled


@dataclass(frozen=True)
class Modes:
    """Eigen-analysis of one (vehicle, speed, tire scale).

    Attributes
    ----------
    eigenvalues : numpy.ndarray, shape (2N,)
        Complex eigenvalues [1/s], in the documented order.
    shapes : numpy.ndarray, shape (2N, 2N)
        Right eigenvectors as columns, state order, largest component 1 (SI states:
        v1 in m/s, r in rad/s, theta in rad).
    state_names : tuple of str
    speed_mps : float
        Forward speed [m/s].
    tire_scale : float

    Examples
    --------
    >>> from lcvreport import load_preset, modes
    >>> m = modes(load_preset("aucnat"), 24.4)
    >>> m.stable, m.eigenvalues.shape
    (True, (12,))
    """

    eigenvalues: np.ndarray
    shapes: np.ndarray
    state_names: tuple[str, ...]
    speed_mps: float = float("nan")
    tire_scale: float = 1.0

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
        mag = np.abs(self.eigenvalues)
        return np.where(mag > 0, -self.eigenvalues.real / np.where(mag > 0, mag, 1.0), 1.0)

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

    @property
    def least_damped(self) -> int | None:
        """Index of the oscillatory mode (Im > 0) with the smallest damping ratio; None if none oscillates."""
        idx = np.flatnonzero(self.eigenvalues.imag > 0)
        if idx.size == 0:
            return None
        return int(idx[np.argmin(self.damping_ratio[idx])])

    def to_dict(self) -> dict:
        """The modes as ``lcv eig --json`` prints them: eigenvalues as [real, imaginary] [1/s],
        damping ratios [-], damped frequencies [Hz], the least damped mode (1-based; None if none
        oscillates).

        Returns
        -------
        dict
            ``eigenvalues``, ``damping_ratio``, ``damped_frequency_hz``, ``least_damped_mode``.

        Examples
        --------
        >>> from lcvreport import load_preset, modes
        >>> d = modes(load_preset("aucnat"), 24.4).to_dict()
        >>> len(d["eigenvalues"]), d["least_damped_mode"] is not None
        (12, True)
        """
        k = self.least_damped
        return {"eigenvalues": [[float(lam.real), float(lam.imag)] for lam in self.eigenvalues],
                "damping_ratio": [float(z) for z in self.damping_ratio],
                "damped_frequency_hz": [float(f) for f in self.damped_frequency_hz],
                "least_damped_mode": None if k is None else k + 1}

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
        return [dict(mode=i + 1, real_per_s=float(lam.real), imag_per_s=float(lam.imag),
                     damped_frequency_rad_per_s=float(w), damped_frequency_hz=float(f), damping_ratio=float(z))
                for i, (lam, w, f, z) in enumerate(zip(self.eigenvalues, self.damped_frequency,
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


def state_matrix(vehicle: Vehicle, speed_mps: float | np.ndarray, tire_scale: float | np.ndarray = 1.0,
                 model: str = "yaw_plane") -> np.ndarray:
    """``A = M^-1 S`` (SI) of the linear model ``model`` (:data:`lcvreport.model.linear.MODELS`)
    at forward speed [m/s]; broadcasts over speed and tire scale."""
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = linear_model(vehicle, model)
    S = co.S(speed_mps, tire_scale)
    M = np.broadcast_to(co.M(speed_mps), S.shape)
    return solve_scaled(M, S)


def eigenvalues(vehicle: Vehicle, speed_mps: float | np.ndarray, tire_scale: float | np.ndarray = 1.0,
                model: str = "yaw_plane") -> np.ndarray:
    """Eigenvalues [1/s] of the model ``model`` in mode order; broadcasts over arrays of speed
    [m/s] and tire scale.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float or array_like
        Forward speed [m/s]; broadcasts.
    tire_scale : float or array_like
        Factor on every tire coefficient [-]; broadcasts.
    model : str
        A linear model (:data:`lcvreport.model.base.LINEAR_MODELS`).

    Returns
    -------
    numpy.ndarray, shape (..., n)
        Complex eigenvalues [1/s], mode order (:func:`modes`).

    Examples
    --------
    >>> from lcvreport import load_preset, eigenvalues
    >>> eigenvalues(load_preset("aucnat"), [10.0, 20.0, 30.0]).shape
    (3, 12)
    """
    return sort_eigenvalues(np.linalg.eigvals(state_matrix(vehicle, speed_mps, tire_scale, model)))


def _modes_one(vehicle: Vehicle, speed: float, tire_scale: float, model: str = "yaw_plane") -> Modes:
    # the same routine as eigenvalues(): the balanced, scaled state matrix (QZ on the
    # unscaled pencil (S, M) lost up to two digits on long chains)
    lam, X = np.linalg.eig(state_matrix(vehicle, speed, tire_scale, model))
    order = mode_order(lam)
    lam, X = lam[order], X[:, order]
    k = np.argmax(np.abs(X), axis=0)
    X = X / X[k, np.arange(X.shape[1])]
    return Modes(lam, X, linear_model(vehicle, model).state_names, float(speed), float(tire_scale))


def modes(vehicle: Vehicle, speed_mps: float | np.ndarray, tire_scale: float | np.ndarray = 1.0,
          model: str = "yaw_plane") -> Modes | list[Modes]:
    """Eigenvalues and mode shapes of ``M^-1 S`` at forward speed [m/s].

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float or array
        Forward speed [m/s]; an array gives one :class:`Modes` per element.
    tire_scale : float or array
        Tire coefficient factor [-]; broadcasts with ``speed_mps``.
    model : str
        The linear model (:data:`lcvreport.model.linear.MODELS`; default the yaw plane).

    Returns
    -------
    Modes or list of Modes

    Examples
    --------
    >>> from lcvreport import load_preset, modes
    >>> [round(m.max_real, 3) for m in modes(load_preset("aucnat"), [10.0, 30.0])]
    [-2.463, -0.981]
    """
    u = check_speed(speed_mps)
    s = check_tire_scale(tire_scale)
    if u.ndim == 0 and s.ndim == 0:
        return _modes_one(vehicle, float(u), float(s), model)
    ub, sb = np.broadcast_arrays(u, s)
    return [_modes_one(vehicle, float(a), float(b), model) for a, b in zip(ub.ravel(), sb.ravel())]
