"""Tires on a vehicle: the slots of every axle and the sign a tire's residuals take in each,
per-axle residuals of mounted tires, the sensitivity of the trimmed offtracking to each
axle's conicity, and the mounted-tires file (TOML or CSV).

Examples
--------
>>> from lcvreport import load_preset
>>> slots_of(2), len(tire_slots(load_preset("aucnat")))
(('left', 'right'), 20)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..analysis.steady import trim
from ..model.vehicle import Vehicle
from ..model.yaw_plane.equations import system_coefficients


@dataclass(frozen=True)
class AxleSensitivity:
    """Trimmed straight running per unit residual load on one axle.

    Attributes
    ----------
    axle, unit : str
    offtracking_per_P_m_per_kN, offtracking_per_T_m_per_kNm : float
        Trimmed offtracking [m] per kN of P (along +y) and per kN*m of T (about +z).
    delta_per_P_rad_per_kN, delta_per_T_rad_per_kNm : float
        Trim steer angle [rad] per kN of P and per kN*m of T.
    """

    axle: str
    unit: str
    offtracking_per_P_m_per_kN: float
    offtracking_per_T_m_per_kNm: float
    delta_per_P_rad_per_kN: float
    delta_per_T_rad_per_kNm: float

    @property
    def largest_m(self) -> float:
        """The larger |offtracking| of 1 kN of P and 1 kN*m of T [m] (the ranking key)."""
        return max(abs(self.offtracking_per_P_m_per_kN), abs(self.offtracking_per_T_m_per_kNm))


def conicity_sensitivity(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> list[AxleSensitivity]:
    """Trimmed offtracking and trim steer per unit P and T on each axle, ranked by |offtracking|, largest first."""
    co = system_coefficients(vehicle)
    out = []
    for col, (i, ax) in enumerate(zip(vehicle.axle_units, vehicle.axles)):
        tp = trim(vehicle, speed_mps, co.B_P[:, col] * 1e3, tire_scale)
        tt = trim(vehicle, speed_mps, co.B_T[:, col] * 1e3, tire_scale)
        out.append(AxleSensitivity(ax.name, vehicle.units[i].name, tp.offtracking_m, tt.offtracking_m,
                                   tp.delta_rad, tt.delta_rad))
    return sorted(out, key=lambda a: a.largest_m, reverse=True)


class TrackingError(ValueError):
    """A bad tire position, distribution or mounting; the message names it."""


def slots_of(tires: int) -> tuple[str, ...]:
    """The tire positions of an axle with ``tires`` tires."""
    if tires == 2:
        return ("left", "right")
    if tires == 4:
        return ("left_outer", "left_inner", "right_inner", "right_outer")
    return tuple(f"t{k + 1}" for k in range(tires))


def _side(slot: str, tires: int) -> float:
    """-1 for a tire on the left (-y) side, +1 on the right."""
    if slot.startswith("left"):
        return -1.0
    if slot.startswith("right"):
        return 1.0
    k = int(slot[1:])
    if tires % 2:
        raise TrackingError(f"slot {slot}: an axle with {tires} tires has no left and right half; give each tire's "
                            "serial side as +y or -y")
    return -1.0 if k <= tires // 2 else 1.0


def serial_sign(slot: str, mounting: str, tires: int = 2) -> float:
    """s = +1 when the serial side of the tire in ``slot`` mounted ``out`` or ``in`` faces +y."""
    if mounting not in ("out", "in"):
        raise TrackingError(f"mounting must be out or in, got {mounting!r}")
    side = _side(slot, tires if not slot.startswith(("left", "right")) else 2)
    return side if mounting == "out" else -side


def sensitivities(vehicle: Vehicle, speed_mps: float, tire_scale: float = 1.0) -> np.ndarray:
    """``g`` with ``[offtracking_m, trim_delta_rad] = g @ [P_axles (N), T_axles (N*m)]``, shape (2, 2 n_axles)."""
    co = system_coefficients(vehicle)
    cols = [co.B_P[:, j] for j in range(len(vehicle.axles))] + [co.B_T[:, j] for j in range(len(vehicle.axles))]
    g = np.zeros((2, len(cols)))
    for k, F in enumerate(cols):
        tr = trim(vehicle, speed_mps, F, tire_scale)
        g[:, k] = tr.offtracking_m, tr.delta_rad
    return g


@dataclass(frozen=True)
class TireSlot:
    """One tire position: its axle (index into :attr:`Vehicle.axles`), slot name, side."""

    axle: int
    axle_name: str
    slot: str
    side: float

    @property
    def position(self) -> str:
        return f"{self.axle_name}:{self.slot}"


def tire_slots(vehicle: Vehicle, axles: list[str] | None = None) -> list[TireSlot]:
    """Every tire position of the named axles (default: every axle of units 2..N)."""
    names = vehicle.axle_names
    if axles is None:
        chosen = [j for j, i in enumerate(vehicle.axle_units) if i >= 1]
    else:
        unknown = [a for a in axles if a not in names]
        if unknown:
            raise TrackingError(f"unknown axle {unknown[0]!r} of {vehicle.name}; valid: {', '.join(names)}")
        twice = next((a for k, a in enumerate(axles) if a in axles[:k]), None)
        if twice is not None:
            raise TrackingError(f"axle {twice!r} is named twice (its tires would count twice)")
        chosen = [names.index(a) for a in axles]
    out = []
    for j in chosen:
        a = vehicle.axles[j]
        for slot in slots_of(a.tires):
            out.append(TireSlot(j, a.name, slot, _side(slot, a.tires)))
    return out


def axle_residuals(vehicle: Vehicle, mounted: list[dict]):
    """The per-axle residual loads of mounted tires.

    Parameters
    ----------
    mounted : list of dict
        ``position`` (``axle:slot``), ``conicity_N``, ``ply_steer_N``, optional
        ``conicity_moment_Nm``, ``ply_steer_moment_Nm``, and ``serial_side`` (``out``, ``in``).

    Returns
    -------
    lcvreport.model.yaw_plane.loads.ResidualLoads
        P [N] and T [N*m] by axle (only the axles that carry a tire).

    Examples
    --------
    >>> from lcvreport import load_preset
    >>> v = load_preset("tractor_semitrailer")
    >>> r = axle_residuals(v, [dict(position="11:left", conicity_N=100.0, ply_steer_N=30.0, serial_side="out"),
    ...                        dict(position="11:right", conicity_N=100.0, ply_steer_N=30.0, serial_side="out")])
    >>> r.P_N                       # conicity cancels, ply steer doubles
    {'11': 60.0}
    """
    from ..model.yaw_plane.loads import ResidualLoads
    names = vehicle.axle_names
    P, T, seen = {}, {}, set()
    for tire in mounted:
        axle, _, slot = str(tire["position"]).partition(":")
        if axle not in names:
            raise TrackingError(f"position {tire['position']!r}: unknown axle {axle!r}; valid: {', '.join(names)}")
        n_tires = vehicle.axles[names.index(axle)].tires
        if slot not in slots_of(n_tires):
            raise TrackingError(f"position {tire['position']!r}: axle {axle} has the slots "
                                f"{', '.join(slots_of(n_tires))}")
        if tire["position"] in seen:
            raise TrackingError(f"position {tire['position']!r} is filled twice")
        seen.add(tire["position"])
        s = serial_sign(slot, tire["serial_side"], n_tires)
        P[axle] = P.get(axle, 0.0) + float(tire.get("ply_steer_N", 0.0)) + s * float(tire.get("conicity_N", 0.0))
        T[axle] = T.get(axle, 0.0) + float(tire.get("ply_steer_moment_Nm", 0.0)) + \
            s * float(tire.get("conicity_moment_Nm", 0.0))
    return ResidualLoads(P, T)


#: columns of a mounted-tires file
TIRE_COLUMNS = ("position", "conicity_N", "ply_steer_N", "serial_side")


TIRE_OPTIONAL = ("id", "conicity_moment_Nm", "ply_steer_moment_Nm")


#: the largest tire file [bytes] (a fleet's tires, one line each)
TIRE_FILE_MAX_BYTES = 4 << 20


def tire_number(raw, where: str) -> float:
    """A tire file's number: finite and within 1e6 (N or N*m), else a TrackingError naming ``where``."""
    try:
        val = float(raw)
    except (TypeError, ValueError):
        raise TrackingError(f"{where} must be a number, got {raw!r}") from None
    if not math.isfinite(val) or abs(val) > 1e6:
        raise TrackingError(f"{where} must be finite and within 1e6, got {raw!r}")
    return val


def read_mounted_tires(path) -> list[dict]:
    """Mounted tires from a CSV (header ``position,conicity_N,ply_steer_N,serial_side``
    and optionally ``id``, ``conicity_moment_Nm``, ``ply_steer_moment_Nm``) or a TOML file
    (``[[tires]]`` tables with the same keys).

    Raises
    ------
    TrackingError
        Unreadable file, unknown or missing columns, non-numbers, non-finite values,
        a serial side other than out or in.
    """
    import tomllib
    from pathlib import Path

    from ..util.files import FileInputError, TomlNumberError, loads_toml, read_csv, read_text_file
    path = Path(path)
    try:
        if path.suffix.lower() == ".toml":
            try:
                rows = loads_toml(read_text_file(path, "tire file", TIRE_FILE_MAX_BYTES)).get("tires")
            except (tomllib.TOMLDecodeError, TomlNumberError) as exc:
                raise TrackingError(f"{path}: {'not valid TOML: ' if isinstance(exc, tomllib.TOMLDecodeError) else ''}"
                                    f"{exc}") from None
            if not isinstance(rows, list) or not all(isinstance(r, dict) for r in rows):
                raise TrackingError(f"{path}: expected [[tires]] tables")
        else:
            rows = [row for _line, row in read_csv(path, "tire file", TIRE_COLUMNS, TIRE_OPTIONAL,
                                                   TIRE_FILE_MAX_BYTES)]
    except FileInputError as exc:
        raise TrackingError(str(exc)) from None
    out = []
    for k, row in enumerate(rows, start=1):
        unknown = set(row) - set(TIRE_COLUMNS) - set(TIRE_OPTIONAL)
        missing = [c for c in TIRE_COLUMNS if c not in row or row[c] in (None, "")]
        if unknown or missing:
            raise TrackingError(f"{path}: tire {k}: " + (f"unknown column {sorted(unknown)[0]!r}" if unknown else
                                                          f"missing {missing[0]!r}") +
                                f"; columns: {', '.join(TIRE_COLUMNS + TIRE_OPTIONAL)}")
        tire = {"position": str(row["position"]).strip(), "serial_side": str(row["serial_side"]).strip()}
        if row.get("id") not in (None, ""):
            tire["id"] = str(row["id"]).strip()
            if not tire["id"].isprintable() or any(t.get("id") == tire["id"] for t in out):
                raise TrackingError(f"{path}: tire {k}: id {tire['id']!r} is " +
                                    ("listed twice" if tire["id"].isprintable() else "not printable text"))
        if tire["serial_side"] not in ("out", "in"):
            raise TrackingError(f"{path}: tire {k}: serial_side must be out or in, got {tire['serial_side']!r}")
        for key in ("conicity_N", "ply_steer_N", "conicity_moment_Nm", "ply_steer_moment_Nm"):
            if key in row and row[key] not in (None, ""):
                tire[key] = tire_number(row[key], f"{path}: tire {k}: {key}")
        out.append(tire)
    if not out:
        raise TrackingError(f"{path}: no tires")
    return out
