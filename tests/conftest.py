"""Shared fixtures."""
from __future__ import annotations

import pytest

from lcvreport.presets import load_preset


@pytest.fixture(scope="session")
def aucnat():
    return load_preset("aucnat")


@pytest.fixture(scope="session")
def semi():
    return load_preset("tractor_semitrailer")
