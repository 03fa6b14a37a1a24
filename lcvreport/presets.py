"""Presets: the thesis vehicles built from the Appendix B-D tables.

``aucnat``, ``legal_max``, ``loaded_loaded_empty``, ``empty_empty_loaded`` and
``empty`` are the five triple-trailer configurations of Appendices B-D;
``tractor_semitrailer`` is the AU-NCAT tractor with trailer 1 (chapter III).
Presets keep the printed (rounded) table masses; ``masses="unrounded"`` gives the
masses the published matrices imply (SPEC section 3, ``gaps.toml``), defined for the
AU-NCAT data only.
"""
from __future__ import annotations

from typing import Iterable

from . import data
from .tires import tire_properties
from .vehicle import UNIT_NAMES, Axle, Train, Unit

#: preset names, in the order the thesis introduces them
PRESETS = ("aucnat", "legal_max", "loaded_loaded_empty", "empty_empty_loaded", "empty", "tractor_semitrailer")
#: a readable label per preset
PRESET_LABELS = {
    "aucnat": "AU-NCAT (as tested)",
    "legal_max": "Legal Max",
    "loaded_loaded_empty": "Loaded, Loaded, Empty",
    "empty_empty_loaded": "Empty, Empty, Loaded",
    "empty": "Empty",
    "tractor_semitrailer": "AU-NCAT tractor + trailer 1",
}
MASS_OPTIONS = ("table", "unrounded")

_KIND = {"tractor": "tractor", "trailer1": "trailer", "dolly1": "dolly", "trailer2": "trailer",
         "dolly2": "dolly", "trailer3": "trailer"}
_TIRE_ROWS = {"tractor": ("tractor_steer", "tractor_tandem"), "trailer1": ("trailer1",), "dolly1": ("dolly1",),
              "trailer2": ("trailer2",), "dolly2": ("dolly2",), "trailer3": ("trailer3",)}


def check_preset(name: str) -> str:
    """Return ``name`` if it is a preset, else raise ``KeyError`` listing the valid ones."""
    if name not in PRESETS:
        raise KeyError(f"unknown preset {name!r}; valid presets: {', '.join(PRESETS)}")
    return name


def load_preset(name: str, masses: str = "table") -> Train:
    """Build a preset train from the thesis tables.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS`.
    masses : {"table", "unrounded"}
        ``table`` keeps Table C's rounded masses [lbf*s^2/in]; ``unrounded`` uses the
        masses implied by eq. 3.17/3.18 (tractor_semitrailer) or eq. 4.14 (aucnat).

    Returns
    -------
    Train
    """
    check_preset(name)
    if masses not in MASS_OPTIONS:
        raise ValueError(f"masses must be one of {MASS_OPTIONS}, got {masses!r}")
    config = "aucnat" if name == "tractor_semitrailer" else name
    n_units = 2 if name == "tractor_semitrailer" else 6
    train = _build_from_tables(config, n_units, name)
    if masses == "unrounded":
        g = data.gaps()["unrounded_masses"]
        if name == "tractor_semitrailer":
            train = train.with_masses(g["four_dof_lbf_s2_per_in"])
        elif name == "aucnat":
            train = train.with_masses(g["twelve_dof_lbf_s2_per_in"])
        else:
            raise ValueError(f"unrounded masses are known only for aucnat and tractor_semitrailer, not {name!r}")
    return train


def _build_from_tables(config: str, n_units: int, name: str) -> Train:
    dims = data.dimensions(config)
    mass = data.mass_table(config)
    tires = data.tire_table(config)
    per_tire = {row: (tires[row]["CF_lbf_per_rad"], tires[row]["CM_lbf_in_per_rad"],
                      tires[row].get("CS_lbf_per_rad", 0.0)) for row in data.TABLE_ROWS}
    loads = {row: mass[row]["axle_load_lbf"] for row in data.TABLE_ROWS}
    return _assemble(dims, loads, mass, per_tire, n_units, name,
                     f"Tables {dims['table']}, {mass['table']}, {tires['table']} of Patterson (2011)")


def _assemble(dims: dict, loads: dict, mass: dict, per_tire: dict, n_units: int, name: str,
              description: str) -> Train:
    g = data.gaps()
    n_steer = g["tires_per_axle"]["steer"]
    n_other = g["tires_per_axle"]["other"]
    n_tandem = g["tandem"]["axles"]
    x6F = g["rear_end"]["x6F_in"]
    units = []
    for k, uname in enumerate(UNIT_NAMES[:n_units]):
        i = k + 1
        letters = "ABCDE"
        front = 0.0 if k == 0 else dims[f"x{i}{letters[k - 1]}_in"]
        if k == n_units - 1:
            # rear end of the last unit: x2B for the tractor-semitrailer (eq. 3.43), x6F for the triple
            rear = dims[f"x{i}B_in"] if n_units == 2 else x6F
        else:
            rear = dims[f"x{i}{letters[k]}_in"]
        axles = []
        if uname == "tractor":
            cf, cm, cs = per_tire["tractor_steer"]
            axles.append(Axle("11", 1, dims["x11_in"], loads["tractor_steer"], n_steer,
                              n_steer * cf, n_steer * cm, 0.0, dual=False, steer=True))
            cf, cm, cs = per_tire["tractor_tandem"]
            for j in range(n_tandem):
                axles.append(Axle(f"1{j + 2}", 1, -dims[f"x1{j + 2}_in"], loads["tractor_tandem"] / n_tandem,
                                  n_other, n_other * cf, n_other * cm, n_other * cs, dual=True))
        else:
            cf, cm, cs = per_tire[uname]
            axles.append(Axle(f"{i}1", i, -dims[f"x{i}1_in"], loads[uname], n_other,
                              n_other * cf, n_other * cm, n_other * cs, dual=True))
        row = "tractor_steer" if uname == "tractor" else uname
        units.append(Unit(i, uname, _KIND[uname], float(mass[row]["mass_lbf_s2_per_in"]),
                          float(mass[row]["inertia_lbf_in_s2"]), float(front), float(rear), tuple(axles)))
    return Train(name=name, units=tuple(units), dual_spacing_in=float(g["dual_spacing"]["D_in"]),
                 description=description, drawing=dict(g["drawing"]))


def train_from_axle_loads(config: str, axle_loads_lbf: dict[str, float], name: str | None = None,
                          n_units: int = 6) -> Train:
    """A train with the dimensions, masses and inertias of ``config`` and tire
    coefficients read off the Appendix D fits at the given axle loads.

    Parameters
    ----------
    config : str
        Thesis configuration giving dimensions, masses and inertias (Appendix B, C).
    axle_loads_lbf : dict
        Axle load per Table C row (``tractor_steer``, ``tractor_tandem`` (both drive
        axles together), ``trailer1``, ...) [lbf]; rows left out keep the table load.
    name : str, optional
    n_units : int
        2 for a tractor-semitrailer, 6 for the triple.

    Returns
    -------
    Train
    """
    dims = data.dimensions(config)
    mass = data.mass_table(config)
    g = data.gaps()
    unknown = set(axle_loads_lbf) - set(data.TABLE_ROWS)
    if unknown:
        raise KeyError(f"unknown axle rows {sorted(unknown)}; valid: {', '.join(data.TABLE_ROWS)}")
    loads = {row: float(axle_loads_lbf.get(row, mass[row]["axle_load_lbf"])) for row in data.TABLE_ROWS}
    per_tire = {}
    for row in data.TABLE_ROWS:
        n = g["tires_per_axle"]["steer"] if row == "tractor_steer" else g["tires_per_axle"]["other"]
        if row == "tractor_tandem":
            n *= g["tandem"]["axles"]
        per_tire[row] = tire_properties(loads[row] / n)
    return _assemble(dims, loads, mass, per_tire, n_units, name or f"{config}_fitted",
                     f"dimensions/masses of {config}; tires from the Appendix D fits at the given axle loads")


def preset_trains(names: Iterable[str] = PRESETS) -> dict[str, Train]:
    """Dictionary of preset trains with table masses."""
    return {n: load_preset(n) for n in names}
