"""A study's results as one table, and any row's case as a call of :func:`measure_set`.

Examples
--------
>>> import tempfile, pathlib
>>> from lcvreport.study.spec import study_from_dict
>>> from lcvreport.study.run import run_study
>>> s = study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m"],
...     "factors": {"trailer1.mass_scale": {"values": [0.8, 1.2]}}})
>>> out = pathlib.Path(tempfile.mkdtemp()) / "s"
>>> _ = run_study(s, out)
>>> table = read_study(out)
>>> list(table.columns)
['case_id', 'trailer1.mass_scale', 'hsso_m']
>>> vehicle, speed_mps, kwargs = study_case(out, 1)
>>> from lcvreport import load_preset
>>> round(vehicle.units[1].mass_kg / load_preset("tractor_semitrailer").units[1].mass_kg, 12)
1.2
"""
from __future__ import annotations

import json
from pathlib import Path

from .run import CHUNKS, MANIFEST, STUDY, chunk_name
from .spec import StudyError, study_from_stored


def _manifest(folder: Path) -> dict:
    try:
        return json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise StudyError(f"{folder} holds no study results ({MANIFEST} is missing)") from None
    except (OSError, ValueError) as exc:
        raise StudyError(f"{folder / MANIFEST} cannot be read: {exc}") from None


def read_study(folder, complete: bool = True):
    """The results of the study in ``folder`` as one ``pandas.DataFrame``, sorted by ``case_id``:
    ``case_id``, one column per factor (its name in the study file), one per measure (the
    ``lcv measures --json`` keys; NaN where undefined).

    Parameters
    ----------
    folder : path
        The ``--out`` folder of ``lcv study``.
    complete : bool
        Refuse a study with chunks still missing (default); False reads what is there.
    """
    import pandas as pd
    import pyarrow.parquet as pq
    folder = Path(folder)
    man = _manifest(folder)
    chunks = folder / CHUNKS
    present = [k for k in range(man["n_chunks"]) if (chunks / chunk_name(k)).is_file()]
    if complete and len(present) < man["n_chunks"]:
        raise StudyError(f"{folder}: {man['n_chunks'] - len(present)} of {man['n_chunks']} chunks are missing; "
                         "rerun lcv study with the same --out to complete it (or read_study(..., complete=False))")
    if not present:
        return pd.DataFrame({c: [] for c in man["columns"]})
    table = pd.concat([pq.read_table(chunks / chunk_name(k)).to_pandas() for k in present], ignore_index=True)
    return table[man["columns"]].sort_values("case_id", kind="stable").reset_index(drop=True)


def stored_study(folder):
    """The :class:`~lcvreport.study.spec.Study` whose results are in ``folder`` (as it was run)."""
    folder = Path(folder)
    _manifest(folder)
    try:
        doc = json.loads((folder / STUDY).read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise StudyError(f"{folder / STUDY} cannot be read: {exc}") from None
    return study_from_stored(doc)


def study_case(folder, case_id: int):
    """``(vehicle, speed_mps, kwargs)`` of row ``case_id``: ``measure_set(vehicle, speed_mps,
    **kwargs)`` recomputes that row alone."""
    return stored_study(folder).case(int(case_id))
