"""The thesis tables shipped as TOML data files in ``lcvreport/data/thesis``.

Units are part of every key name (``x1A_in``, ``axle_load_lbf``,
``mass_lbf_s2_per_in`` ...), see the comment at the top of each file.

Examples
--------
>>> dimensions("aucnat")["x1A_in"]
85.42
"""
from __future__ import annotations

import tomllib
from functools import lru_cache
from importlib import resources
from typing import Any

#: configuration keys of the five thesis data sets, in Appendix order
CONFIGURATIONS = ("aucnat", "legal_max", "loaded_loaded_empty", "empty_empty_loaded", "empty")
#: row keys of Tables C and D, front to back
TABLE_ROWS = ("tractor_steer", "tractor_tandem", "trailer1", "dolly1", "trailer2", "dolly2", "trailer3")


@lru_cache(maxsize=None)
def load_table_file(name: str) -> dict[str, Any]:
    """Parse ``lcvreport/data/thesis/<name>.toml`` and return its contents (cached)."""
    text = resources.files("lcvreport").joinpath("data", "thesis", f"{name}.toml").read_text(encoding="utf-8")
    return tomllib.loads(text)


def dimensions(config: str) -> dict[str, Any]:
    """Table B.x of ``config``: keys ``x1A_in`` ... ``x61_in`` [in], ``table``, ``title``."""
    return load_table_file("appendix_b_dimensions")[_check(config)]


def mass_table(config: str) -> dict[str, Any]:
    """Table C.x of ``config``: per row axle/tire load [lbf], mass [lbf*s^2/in], inertia [lbf*in*s^2]."""
    return load_table_file("appendix_c_mass")[_check(config)]


def tire_table(config: str) -> dict[str, Any]:
    """Table D.x of ``config``: per row per-tire CF [lbf/rad], CM [lbf*in/rad], CS [lbf]."""
    return load_table_file("appendix_d_tires")[_check(config)]


def appendix_d_rows() -> list[dict[str, Any]]:
    """Every row of Tables D.1-D.5 (with duplicates), in file order."""
    data = load_table_file("appendix_d_tires")
    return [data[c][r] for c in CONFIGURATIONS for r in TABLE_ROWS]


def gaps() -> dict[str, Any]:
    """Values the thesis text lacks, with their sources (``gaps.toml``)."""
    return load_table_file("gaps")


def published() -> dict[str, Any]:
    """Numbers printed in the thesis and their published tolerances (``published.toml``)."""
    return load_table_file("published")


def _check(config: str) -> str:
    if config not in CONFIGURATIONS:
        raise KeyError(f"unknown configuration {config!r}; valid: {', '.join(CONFIGURATIONS)}")
    return config
