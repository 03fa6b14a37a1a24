"""Unit conversions between the thesis system (in, lbf, s) and SI.

The thesis works in inch-pound-second units: lengths in inches [in], forces in
pound-force [lbf], masses in [lbf*s^2/in], yaw inertias in [lbf*in*s^2].  The FMU
and every JSON output speak SI.  All conversion factors live here and nowhere else.
"""
from __future__ import annotations

#: metres per inch [m/in] (exact)
M_PER_IN = 0.0254
#: newtons per pound-force [N/lbf] (exact, standard gravity)
N_PER_LBF = 4.4482216152605
#: inches per foot [in/ft]
IN_PER_FT = 12.0
#: inches per mile [in/mi]
IN_PER_MILE = 63360.0
#: seconds per hour [s/h]
S_PER_HOUR = 3600.0
#: metres per second in one mile per hour [(m/s)/(mi/h)]
MPS_PER_MPH = M_PER_IN * IN_PER_MILE / S_PER_HOUR
#: inches per second in one mile per hour [(in/s)/(mi/h)] (= 17.6)
IPS_PER_MPH = IN_PER_MILE / S_PER_HOUR
#: newton-metres per pound-force-inch [N*m/(lbf*in)]
NM_PER_LBF_IN = N_PER_LBF * M_PER_IN


def mph_to_in_per_s(v_mph: float) -> float:
    """Convert a speed from [mi/h] to [in/s]."""
    return v_mph * IPS_PER_MPH


def in_per_s_to_mph(v_ips: float) -> float:
    """Convert a speed from [in/s] to [mi/h]."""
    return v_ips / IPS_PER_MPH


def mps_to_in_per_s(v_mps: float) -> float:
    """Convert a speed from [m/s] to [in/s]."""
    return v_mps / M_PER_IN


def in_to_m(x_in: float) -> float:
    """Convert a length (or a speed in in/s to m/s) from [in] to [m]."""
    return x_in * M_PER_IN


def m_to_in(x_m: float) -> float:
    """Convert a length from [m] to [in]."""
    return x_m / M_PER_IN


def lbf_to_n(f_lbf: float) -> float:
    """Convert a force from [lbf] to [N]."""
    return f_lbf * N_PER_LBF


def n_to_lbf(f_n: float) -> float:
    """Convert a force from [N] to [lbf]."""
    return f_n / N_PER_LBF


def nm_to_lbf_in(m_nm: float) -> float:
    """Convert a moment from [N*m] to [lbf*in]."""
    return m_nm / NM_PER_LBF_IN


def lbf_in_to_nm(m_lbf_in: float) -> float:
    """Convert a moment from [lbf*in] to [N*m]."""
    return m_lbf_in * NM_PER_LBF_IN
