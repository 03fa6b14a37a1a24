"""The thesis vehicles as presets: vehicle files shipped in ``lcvreport/data/vehicles``.

``aucnat``, ``legal_max``, ``loaded_loaded_empty``, ``empty_empty_loaded`` and
``empty`` are the five triple-trailer configurations of Appendices B-D;
``tractor_semitrailer`` is the AU-NCAT tractor with trailer 1 (chapter III).  The
files are SI conversions of the thesis tables (:mod:`lcvreport.thesis.vehicles`)
with the printed (rounded) masses; ``masses="unrounded"`` gives the masses the
published matrices imply (docs/thesis.md), for aucnat and tractor_semitrailer.

Examples
--------
>>> from lcvreport import load_preset
>>> v = load_preset("aucnat")
>>> v.n_units, v.unit_names[-1]
(6, 'trailer3')
"""
from __future__ import annotations

from functools import lru_cache
from importlib import resources

from ..units import THESIS
from .vehicle import Vehicle
from .vehicle_file import loads_vehicle

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
#: options of ``masses``
MASS_OPTIONS = ("table", "unrounded")


def check_preset(name: str) -> str:
    """Return ``name`` if it is a preset, else raise ``KeyError`` listing the valid ones."""
    if name not in PRESETS:
        raise KeyError(f"unknown preset {name!r}; valid presets: {', '.join(PRESETS)}")
    return name


def preset_path(name: str):
    """The shipped vehicle file of preset ``name`` (an importlib resource)."""
    # the top package by its own name: inside a Python FMU it is bundled under a name of its own
    return resources.files(__package__.partition(".")[0]).joinpath("data", "vehicles", f"{check_preset(name)}.toml")


@lru_cache(maxsize=None)
def load_preset(name: str, masses: str = "table") -> Vehicle:
    """Load a preset vehicle.

    Parameters
    ----------
    name : str
        One of :data:`PRESETS`.
    masses : {"table", "unrounded"}
        ``table`` keeps Table C's rounded masses; ``unrounded`` uses the masses implied
        by eq. 3.17/3.18 (tractor_semitrailer) or eq. 4.14 (aucnat).

    Returns
    -------
    Vehicle
        SI.

    Raises
    ------
    KeyError
        A name that is not a preset (the valid names in the message).
    ValueError
        ``masses`` not one of :data:`MASS_OPTIONS`, or unrounded masses of a preset that has none.

    Examples
    --------
    >>> v = load_preset("aucnat")
    >>> v.n_units, v.unit_names[0]
    (6, 'tractor')
    """
    check_preset(name)
    if masses not in MASS_OPTIONS:
        raise ValueError(f"masses must be one of {', '.join(MASS_OPTIONS)}, got {masses!r}")
    vehicle = loads_vehicle(preset_path(name).read_text(encoding="utf-8"), source=f"preset {name}")
    if masses == "unrounded":                   # the thesis' own correction of its Table C
        vehicle = vehicle.with_masses(unrounded_masses_kg(name))
    return vehicle


#: the gaps file's keys of the unrounded masses [lbf*s^2/in] of each preset that has them
UNROUNDED_KEYS = {"tractor_semitrailer": "four_dof_lbf_s2_per_in", "aucnat": "twelve_dof_lbf_s2_per_in"}


def unrounded_masses_kg(name: str) -> list[float]:
    """The unrounded masses the published matrices imply [kg], from the data file
    ``data/thesis/gaps.toml`` (``[unrounded_masses]``; see ``docs/thesis.md``).

    Raises
    ------
    ValueError
        For a preset other than ``aucnat`` and ``tractor_semitrailer``.
    """
    import tomllib
    key = UNROUNDED_KEYS.get(name)
    if key is None:
        raise ValueError(f"unrounded masses are known only for aucnat and tractor_semitrailer, not {name!r}")
    gaps = resources.files(__package__.partition(".")[0]).joinpath("data", "thesis", "gaps.toml")
    return [m * THESIS.mass_kg for m in tomllib.loads(gaps.read_text(encoding="utf-8"))["unrounded_masses"][key]]
