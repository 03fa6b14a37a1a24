"""Tire properties against vertical tire load (Appendix D, Figures D.1-D.3).

The thesis read per-tire cornering, aligning and circumferential stiffness off
curve fits of UMTRI data (Figures D.1-D.3, lost from the text).  The curves are
recovered here as least-squares cubic polynomials through the distinct points of
Tables D.1-D.5; a cubic reproduces every printed table value to better than 0.1 %
(a quadratic misses CM by 11 %), which is the resolution the tables are printed to.
The fits are valid over the loads the tables span, about 1,000 to 6,000 lbf per
tire; :func:`tire_properties` refuses loads outside ``FIT_RANGE_LBF``.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .tables import appendix_d_rows

#: degree of the polynomial fits
FIT_DEGREE = 3
#: tire loads over which the fits are trusted [lbf] (table span, rounded outward)
FIT_RANGE_LBF = (1000.0, 6000.0)


@dataclass(frozen=True)
class TireFit:
    """Cubic fits of per-tire coefficients against tire load.

    Attributes
    ----------
    CF, CM, CS : numpy.ndarray
        Polynomial coefficients (highest power first, ``numpy.polyval`` order)
        giving [lbf/rad], [lbf*in/rad] and [lbf] from a tire load in [lbf].
    points : dict
        The table points used: ``{"CF": (load_lbf, value), ...}`` arrays.
    """

    CF: np.ndarray
    CM: np.ndarray
    CS: np.ndarray
    points: dict

    def evaluate(self, tire_load_lbf: float | np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per-tire (CF [lbf/rad], CM [lbf*in/rad], CS [lbf]) at ``tire_load_lbf`` [lbf]."""
        w = np.asarray(tire_load_lbf, dtype=float)
        return np.polyval(self.CF, w), np.polyval(self.CM, w), np.polyval(self.CS, w)


@lru_cache(maxsize=1)
def tire_fit() -> TireFit:
    """Fit CF, CM and CS against tire load through the distinct Table D points.

    Returns
    -------
    TireFit
        The three cubic fits and the points they were fitted to.
    """
    pts: dict[str, dict[float, float]] = {"CF": {}, "CM": {}, "CS": {}}
    for row in appendix_d_rows():
        w = float(row["tire_load_lbf"])
        for key, col in (("CF", "CF_lbf_per_rad"), ("CM", "CM_lbf_in_per_rad"), ("CS", "CS_lbf_per_rad")):
            if col in row:
                pts[key][w] = float(row[col])
    arrays = {k: np.array(sorted(v.items())) for k, v in pts.items()}
    coef = {k: np.polyfit(a[:, 0], a[:, 1], FIT_DEGREE) for k, a in arrays.items()}
    return TireFit(CF=coef["CF"], CM=coef["CM"], CS=coef["CS"], points=arrays)


def tire_properties(tire_load_lbf: float) -> tuple[float, float, float]:
    """Per-tire coefficients at a vertical tire load.

    Parameters
    ----------
    tire_load_lbf : float
        Vertical load on one tire [lbf], within ``FIT_RANGE_LBF``.

    Returns
    -------
    tuple of float
        (CF [lbf/rad], CM [lbf*in/rad], CS [lbf]) for one tire.

    Raises
    ------
    ValueError
        If the load is not finite or lies outside the fitted range.
    """
    w = float(tire_load_lbf)
    lo, hi = FIT_RANGE_LBF
    if not np.isfinite(w) or not lo <= w <= hi:
        raise ValueError(f"tire_load_lbf must lie in [{lo:g}, {hi:g}] lbf (the Table D span), got {w!r}")
    cf, cm, cs = tire_fit().evaluate(w)
    return float(cf), float(cm), float(cs)
