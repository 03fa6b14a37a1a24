"""``lcv study``: a study's chunks on a Dask scheduler, each written as a Parquet file when it
finishes (SPEC section 14).

The output folder holds ``study.json`` (the study as run: its vehicle as vehicle-file text,
factors, design, measures, chunk size), ``manifest.json`` (its digest, the number of cases and
chunks, the columns, the seed) and ``chunks/chunk-NNNNNN.parquet``.  A chunk file is written
under a temporary name in the same folder and renamed when complete (``os.replace``: atomic),
so a file under the final name is always whole; a rerun with the same folder computes only the
chunks that are missing; an interruption (SIGINT, SIGKILL, a lost worker) loses at most the
chunks being computed.  A folder holding anything else -- another study's results, a user's
files -- is refused, never changed.

Where the chunks run: in this process (neither option), a ``distributed.LocalCluster`` of
``workers`` processes with one thread each (``--workers N``), or an existing cluster
(``--scheduler ADDRESS``).  A chunk is a few hundred cases (``Study.chunk``): the scheduler's
~2 ms per task is below 1 % of it.  Each worker runs BLAS single-threaded.

Examples
--------
>>> import tempfile, pathlib
>>> from lcvreport.study.spec import study_from_dict
>>> s = study_from_dict({"vehicle": "tractor_semitrailer", "speed_kph": 88.0, "measures": ["hsso_m"],
...     "factors": {"trailer1.mass_scale": {"values": [0.8, 1.0, 1.2]}}})
>>> out = pathlib.Path(tempfile.mkdtemp()) / "s"
>>> run_study(s, out).n_computed
1
>>> run_study(s, out).n_computed            # a rerun: nothing left to compute
0
"""
from __future__ import annotations

import json
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from .spec import Study, StudyError

MANIFEST = "manifest.json"
STUDY = "study.json"
CHUNKS = "chunks"
FORMAT = "lcvreport-study/1"


def chunk_name(k: int) -> str:
    return f"chunk-{k:06d}.parquet"


@dataclass
class RunSummary:
    """What a run did: chunks computed now, chunks found done, cases, seconds."""

    out: Path
    n_chunks: int
    n_computed: int
    n_found: int
    n_cases: int
    seconds: float


def _chunk_job(study_doc: dict, k: int, start: int, stop: int, folder: str) -> int:
    """Compute chunk ``k`` (cases start..stop-1) and write it atomically; runs in a worker."""
    from .spec import study_from_stored
    study = study_from_stored(study_doc)
    write_chunk(study, k, start, stop, Path(folder))
    return k


def write_chunk(study: Study, k: int, start: int, stop: int, folder: Path) -> Path:
    """Compute and write ``chunks/chunk-k.parquet`` under a temporary name, then rename it."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq
    from .compute import compute_chunk
    cols = compute_chunk(study, np.arange(start, stop))
    table = pa.table(cols)
    final = folder / chunk_name(k)
    tmp = folder / f".{chunk_name(k)}.{os.getpid()}.tmp"
    try:
        pq.write_table(table, tmp)
        os.replace(tmp, final)
    finally:
        if tmp.exists():
            tmp.unlink()
    return final


def _prepare(study: Study, out: Path) -> Path:
    """Create or check the output folder; the chunks folder."""
    doc = study.to_dict()
    digest = study.digest()
    if out.exists() and not out.is_dir():
        raise StudyError(f"--out {out} is a file, not a folder")
    if out.exists() and any(out.iterdir()):
        manifest = out / MANIFEST
        if not manifest.is_file():
            raise StudyError(f"--out {out} holds files that are not a study's results; give a new or empty folder")
        try:
            old = json.loads(manifest.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            raise StudyError(f"--out {out}: its {MANIFEST} cannot be read; give a new or empty folder") from None
        if old.get("format") != FORMAT or old.get("study_sha256") != digest:
            raise StudyError(f"--out {out} holds the results of another study (or of another version of this one); "
                             "give a new folder to run this one")
    else:
        out.mkdir(parents=True, exist_ok=True)
        (out / CHUNKS).mkdir(exist_ok=True)
        columns = ["case_id"] + [f.name for f in study.factors] + list(study.measures)
        manifest = {"format": FORMAT, "study_sha256": digest, "n_cases": study.n_cases, "chunk_size": study.chunk,
                    "n_chunks": study.n_chunks, "columns": columns, "seed": study.seed, "kind": study.kind}
        for name, text in ((STUDY, json.dumps(doc, indent=1)), (MANIFEST, json.dumps(manifest, indent=1))):
            tmp = out / f".{name}.tmp"
            tmp.write_text(text, encoding="utf-8")
            os.replace(tmp, out / name)
    chunks = out / CHUNKS
    chunks.mkdir(exist_ok=True)
    for stale in chunks.glob(".chunk-*.tmp"):      # ours: a chunk an interrupted run left half-written
        stale.unlink()
    return chunks


def _progress(total: int, done: int, enabled: bool):
    if not enabled:
        return None
    from tqdm import tqdm
    return tqdm(total=total, initial=done, unit="case", unit_scale=True, smoothing=0.1, file=sys.stderr,
                desc="cases", dynamic_ncols=True)


def run_study(study: Study, out, workers: int | None = None, scheduler: str | None = None,
              progress: bool | None = None) -> RunSummary:
    """Run ``study`` into the folder ``out`` (new, empty, or this study's earlier results).

    Parameters
    ----------
    study : Study
    out : path
    workers : int, optional
        A local cluster of this many worker processes (one thread each).
    scheduler : str, optional
        The address of an existing Dask scheduler (``tcp://host:8786``).
    progress : bool, optional
        A progress bar on standard error (cases, cases/s, ETA); default: when it is a terminal.
    """
    out = Path(out)
    if workers is not None and scheduler is not None:
        raise StudyError("give --workers or --scheduler, not both")
    if workers is not None and not 1 <= workers <= 256:
        raise StudyError(f"--workers must be in [1, 256], got {workers}")
    chunks = _prepare(study, out)
    t0 = time.perf_counter()
    todo = [k for k in range(study.n_chunks) if not (chunks / chunk_name(k)).is_file()]
    n = study.n_cases
    size = study.chunk
    bounds = {k: (k * size, min(n, (k + 1) * size)) for k in todo}
    found = study.n_chunks - len(todo)
    done_cases = n - sum(b - a for a, b in bounds.values())
    bar = _progress(n, done_cases, sys.stderr.isatty() if progress is None else progress)
    try:
        if todo and workers is None and scheduler is None:
            for k in todo:
                a, b = bounds[k]
                write_chunk(study, k, a, b, chunks)
                if bar is not None:
                    bar.update(b - a)
        elif todo:
            _run_distributed(study, todo, bounds, chunks, workers, scheduler, bar)
    finally:
        if bar is not None:
            bar.close()
        for stale in chunks.glob(".chunk-*.tmp"):   # an interrupted chunk's partial file (ours), if any
            try:
                stale.unlink()
            except OSError:
                pass
    return RunSummary(out, study.n_chunks, len(todo), found, n, time.perf_counter() - t0)


#: the local cluster's workers: one BLAS thread; glibc's malloc told to keep freed memory
#: (Dask's default MALLOC_TRIM_THRESHOLD_=65536 and malloc's mmap of large arrays cost 40,000
#: page faults per chunk: a chunk took 0.40 s in a worker against 0.33 s in a plain process;
#: with these, 0.32 s); no statistical profiler sampling the compute thread every 10 ms
WORKER_CONFIG = {
    "distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": str(1 << 30),
    "distributed.nanny.pre-spawn-environ.MALLOC_MMAP_THRESHOLD_": str(1 << 28),
    "distributed.nanny.pre-spawn-environ.MALLOC_TOP_PAD_": str(1 << 27),
    "distributed.nanny.pre-spawn-environ.OPENBLAS_NUM_THREADS": "1",
    "distributed.nanny.pre-spawn-environ.OMP_NUM_THREADS": "1",
    "distributed.nanny.pre-spawn-environ.MKL_NUM_THREADS": "1",
    "distributed.worker.profile.enabled": False,
}


def _run_distributed(study, todo, bounds, chunks, workers, scheduler, bar) -> None:
    import logging
    from dask.distributed import Client, LocalCluster, as_completed
    logging.getLogger("distributed").setLevel(logging.ERROR)
    doc = study.to_dict()
    cluster = None
    try:
        if scheduler is not None:
            try:
                client = Client(scheduler, timeout="10s")
            except OSError as exc:
                raise StudyError(f"--scheduler {scheduler}: no Dask scheduler answers there ({exc})") from None
        else:
            import dask
            with dask.config.set(WORKER_CONFIG):
                cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
            client = Client(cluster)
        with client:
            futures = [client.submit(_chunk_job, doc, k, *bounds[k], str(chunks), key=f"lcv-study-{k}-{id(doc)}",
                                     pure=False) for k in todo]
            try:
                for fut in as_completed(futures):
                    k = fut.result()
                    if bar is not None:
                        a, b = bounds[k]
                        bar.update(b - a)
            except BaseException:
                client.cancel(futures)
                raise
    finally:
        if cluster is not None:
            cluster.close()
