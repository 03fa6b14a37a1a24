"""Modal superposition of the step response, exact and as the thesis did it.

``exact``: left and right eigenvectors with ``Y^T M X = I`` and ``g = Y^T F``, exact
for the non-symmetric M, S.  ``thesis``: the dissertation's eq. 3.21, 3.26-3.32,
``X_i^T M X_i = 1``, ``g_i = X_i^T F`` -- exact only for symmetric M and S (docs/thesis.md,
erratum 3), kept as a labelled reproduction mode.  The thesis' normalization is not
invariant under a change of units, so the reproduction runs it in the thesis' units
(``units=THESIS``) as the thesis did.

Examples
--------
>>> import numpy as np
>>> from lcvreport import load_preset, one_percent_rule, load_vector, step_response
>>> v = load_preset("tractor_semitrailer")
>>> F = load_vector(v, one_percent_rule(v, ["trailer1"]))
>>> x = modal_response(v, 22.352, F, np.array([0.0, 1.0, 5.0]))
>>> bool(np.allclose(x, step_response(v, 22.352, F, 5.0, 6).states[[0, 1, 5], :4], rtol=1e-9, atol=1e-15))
True
"""
from __future__ import annotations

import numpy as np

from ..model.linear import check_speed, check_tire_scale
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients
from ..units import SI, UnitSystem
from .modes import mode_order

#: modal methods
METHODS = ("exact", "thesis")


def modal_coefficients(M: np.ndarray, S: np.ndarray, F: np.ndarray, method: str = "exact"
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Modal load coefficients g, normalized right eigenvectors X and eigenvalues (mode order).

    See the module docstring for ``method``.
    """
    import scipy.linalg
    if method not in METHODS:
        raise ValueError(f"method must be 'exact' or 'thesis', got {method!r}")
    lam, Yl, X = scipy.linalg.eig(S, M, left=True, right=True)
    order = mode_order(lam)
    lam, Yl, X = lam[order], Yl[:, order], X[:, order]
    if method == "exact":
        # left eigenvectors: Yl^H S = lam Yl^H M; use Y = conj(Yl) so that Y^T M X is diagonal
        Y = Yl.conj()
        Y = Y / np.einsum("ij,ik,kj->j", Y, M, X)
        g = Y.T @ F
    else:
        X = X / np.sqrt(np.einsum("ij,ik,kj->j", X, M, X))
        g = X.T @ F
    return g, X, lam


def modal_response(vehicle: Vehicle, speed_mps: float, F: np.ndarray, time: np.ndarray, tire_scale: float = 1.0,
                   method: str = "exact", units: UnitSystem = SI) -> np.ndarray:
    """Response from rest to a constant force by modal superposition.

    Parameters
    ----------
    vehicle : Vehicle
    speed_mps : float
        Forward speed of every unit [m/s].
    F : numpy.ndarray, shape (2N,)
        Generalized force in ``units`` (SI or thesis), held from t = 0.
    time : numpy.ndarray
        Output times [s].
    tire_scale : float
    method : {"exact", "thesis"}
    units : UnitSystem
        The units of F, of M and S, and of the returned states (v1 in length/s).

    Returns
    -------
    numpy.ndarray, shape (K, 2N)
        States at ``time``.
    """
    check_speed(speed_mps)
    check_tire_scale(tire_scale)
    co = system_coefficients(vehicle, units)
    g, X, lam = modal_coefficients(co.M(speed_mps), co.S(speed_mps, tire_scale), F, method)
    t = np.asarray(time, dtype=float)[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(lam == 0, g * t, g * np.expm1(lam * t) / lam)
    return (c @ X.T).real
