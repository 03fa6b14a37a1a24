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

from pathlib import Path

from .folder import CHUNKS, MANIFEST, STUDY, read_folder_json, chunk_name
from .spec import StudyError, study_from_stored


def _manifest(folder: Path) -> dict:
    if not (folder / MANIFEST).exists():
        raise StudyError(f"{folder} holds no study results ({MANIFEST} is missing)")
    return read_folder_json(folder / MANIFEST)


def _checked(folder: Path) -> tuple[dict, object]:
    """The manifest and the stored study of ``folder``, checked against each other: the
    manifest must describe the study that ``study.json`` holds (its digest, its cases and
    chunks), so an edited manifest cannot make part of a study read as all of it."""
    from .folder import FORMAT
    man = _manifest(folder)
    study = stored_study(folder)
    if man.get("format") != FORMAT or man.get("study_sha256") != study.digest():
        raise StudyError(f"{folder / MANIFEST} does not describe the study in {folder / STUDY} (another study's, "
                         "or changed); the results cannot be trusted: run the study again into a new folder")
    for key, want in (("n_cases", study.n_cases), ("chunk_size", study.chunk), ("n_chunks", study.n_chunks),
                      ("columns", study.columns)):
        if man.get(key) != want:
            raise StudyError(f"{folder / MANIFEST}: {key} is {man.get(key)!r} but the study has {want!r} (the "
                             "manifest was changed); run the study again into a new folder")
    return man, study


def read_study(folder, complete: bool = True):
    """The results of the study in ``folder`` as one ``pandas.DataFrame``, sorted by ``case_id``:
    ``case_id``, one column per factor (its name in the study file), one per measure (the
    ``lcv measures --json`` keys; NaN where undefined).

    Every chunk is checked before its rows are used: its metadata (the study's digest, its
    chunk number and case range), its row count, its page checksums and its ``case_id``
    column; a chunk that fails is named (a rerun of ``lcv study`` with the same ``--out``
    computes it again).

    Parameters
    ----------
    folder : path
        The ``--out`` folder of ``lcv study``.
    complete : bool
        Refuse a study with chunks still missing (default); False reads what is there.

    Returns
    -------
    pandas.DataFrame
        One row per case, sorted by ``case_id``.

    Raises
    ------
    StudyError
        A folder without results, a manifest that does not describe its study, missing
        chunks (when ``complete``), a damaged or foreign chunk.

    Examples
    --------
    >>> import tempfile
    >>> from lcvreport import load_study, run_study
    >>> out = tempfile.mkdtemp() + "/s"
    >>> s = load_study("examples/studies/aucnat_loads.toml").with_count(8)  # doctest: +SKIP
    >>> _ = run_study(s, out, progress=False)  # doctest: +SKIP
    >>> len(read_study(out))  # doctest: +SKIP
    8
    """
    import numpy as np
    import pandas as pd
    import pyarrow.parquet as pq

    from .run import chunk_problem
    folder = Path(folder)
    man, study = _checked(folder)
    chunks = folder / CHUNKS
    n, size, digest = study.n_cases, study.chunk, study.digest()
    present = [k for k in range(study.n_chunks) if (chunks / chunk_name(k)).exists()]
    if complete and len(present) < study.n_chunks:
        raise StudyError(f"{folder}: {study.n_chunks - len(present)} of {study.n_chunks} chunks are missing; "
                         "rerun lcv study with the same --out to complete it (or read_study(..., complete=False))")
    if not present:
        return pd.DataFrame({c: [] for c in man["columns"]})
    parts = []
    for k in present:
        path = chunks / chunk_name(k)
        start, stop = k * size, min(n, (k + 1) * size)
        why = chunk_problem(path, digest, k, start, stop) if path.is_file() else "is not a regular file"
        if why is None:
            try:
                part = pq.read_table(path, page_checksum_verification=True).to_pandas()
            except Exception as exc:  # noqa: BLE001 - a damaged file, whatever pyarrow calls it
                why = f"is damaged ({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"
            else:
                if list(part.columns) != man["columns"] or \
                        not np.array_equal(part["case_id"].to_numpy(), np.arange(start, stop)):
                    why = f"does not hold the cases {start}..{stop - 1} it says it holds"
        if why is not None:
            raise StudyError(f"{path} {why}; rerun lcv study with the same --out to compute it again")
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    return table[man["columns"]].sort_values("case_id", kind="stable").reset_index(drop=True)


def stored_study(folder):
    """The :class:`~lcvreport.study.spec.Study` whose results are in ``folder`` (as it was run)."""
    folder = Path(folder)
    _manifest(folder)
    return study_from_stored(read_folder_json(folder / STUDY))


def study_case(folder, case_id: int):
    """``(vehicle, speed_mps, kwargs)`` of row ``case_id``: ``measure_set(vehicle, speed_mps,
    **kwargs)`` recomputes that row alone.

    Parameters
    ----------
    folder : path
        The ``--out`` folder of ``lcv study``.
    case_id : int
        The row's ``case_id``.

    Returns
    -------
    tuple
        ``(vehicle, speed_mps, kwargs)``: the case's Vehicle, its speed [m/s] and the keyword
        arguments of :func:`~lcvreport.measures.measure_set.measure_set` (tire scale, loads, sources).

    Examples
    --------
    >>> from lcvreport import measure_set
    >>> vehicle, u, kw = study_case("aucnat_loads", 17)  # doctest: +SKIP
    >>> measure_set(vehicle, u, **kw).hsso_m  # doctest: +SKIP
    """
    return stored_study(folder).case(int(case_id))
