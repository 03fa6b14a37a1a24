"""A study's folder: the names of its files (``study.json``, ``manifest.json``,
``chunks/``), chunk names, the format tag, and its JSON read through the guarded reader.
"""
from __future__ import annotations

import json
from pathlib import Path

from .spec import StudyError

MANIFEST = "manifest.json"


STUDY = "study.json"


CHUNKS = "chunks"


FORMAT = "lcvreport-study/1"


def chunk_name(k: int) -> str:
    return f"chunk-{k:06d}.parquet"


def read_folder_json(path: Path) -> dict:
    """A JSON document of a study folder (through the guarded reader: a FIFO never blocks)."""
    from ..util.files import read_text_file
    try:
        doc = json.loads(read_text_file(path, "study's JSON file", 64 << 20))
    except ValueError as exc:
        raise StudyError(f"{path} cannot be read: {exc}") from None
    if not isinstance(doc, dict):
        raise StudyError(f"{path} cannot be read: not a JSON object")
    return doc
