"""``lcv study``: a study's chunks on a Dask scheduler, each written as a Parquet file when it
finishes (docs/studies.md).

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

from .folder import CHUNKS, FORMAT, MANIFEST, STUDY, chunk_name
from .spec import Study, StudyError


@dataclass
class RunSummary:
    """What a run did: chunks computed now (``n_repaired`` of them replacing a damaged or
    foreign file), chunks found done, cases, seconds."""

    out: Path
    n_chunks: int
    n_computed: int
    n_found: int
    n_cases: int
    seconds: float
    n_repaired: int = 0
    seed: int | None = None

    def to_dict(self) -> dict:
        """The run as ``lcv study --json`` prints it (without ``--report``): the results folder,
        cases, chunks computed now and found done, the wall time [s], the design's seed.

        Returns
        -------
        dict
            ``out``, ``n_cases``, ``n_chunks``, ``chunks_computed``, ``chunks_found``, ``seconds``,
            ``seed``.

        Examples
        --------
        >>> RunSummary(Path("out"), 2, 2, 0, 100, 1.5).to_dict()["chunks_computed"]
        2
        """
        return {"out": str(self.out), "n_cases": self.n_cases, "n_chunks": self.n_chunks,
                "chunks_computed": self.n_computed, "chunks_found": self.n_found, "seconds": self.seconds,
                "seed": self.seed}


def _chunk_job(study_doc: dict, k: int, start: int, stop: int, folder: str) -> int:
    """Compute chunk ``k`` (cases start..stop-1) and write it atomically; runs in a worker."""
    from .spec import study_from_stored
    study = study_from_stored(study_doc)
    write_chunk(study, k, start, stop, Path(folder))
    return k


#: the chunk metadata keys (Parquet key-value metadata): what a chunk holds, checked on every read
CHUNK_META = ("lcv.study_sha256", "lcv.chunk", "lcv.cases")


def _chunk_metadata(digest: str, k: int, start: int, stop: int) -> dict:
    return {"lcv.study_sha256": digest, "lcv.chunk": str(k), "lcv.cases": f"{start}:{stop}"}


def write_chunk(study: Study, k: int, start: int, stop: int, folder: Path) -> Path:
    """Compute and write ``chunks/chunk-k.parquet`` under a temporary name, then rename it.

    The file carries what it holds -- the study's digest, its chunk number and case range --
    and page checksums, so that a chunk copied over another, cut short or damaged is found
    (:func:`chunk_problem`) instead of read as results."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .compute import compute_chunk
    cols = compute_chunk(study, np.arange(start, stop))
    table = pa.table(cols).replace_schema_metadata(_chunk_metadata(study.digest(), k, start, stop))
    final = folder / chunk_name(k)
    tmp = folder / f".{chunk_name(k)}.{os.getpid()}.tmp"
    try:
        pq.write_table(table, tmp, write_page_checksum=True)
        os.replace(tmp, final)
    finally:
        if tmp.exists():
            tmp.unlink()
    return final


def chunk_problem(path: Path, digest: str, k: int, start: int, stop: int) -> str | None:
    """Why the chunk file ``path`` is not chunk ``k`` (cases ``start..stop-1``) of the study
    with ``digest``, or None when its footer says it is (the metadata and the row count: no
    data is read)."""
    import pyarrow.parquet as pq
    try:
        md = pq.read_metadata(path)
    except Exception as exc:  # noqa: BLE001 - any failure to read the footer: a damaged file
        return f"cannot be read ({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"
    meta = {key.decode(errors="replace"): val.decode(errors="replace") for key, val in (md.metadata or {}).items()}
    want = _chunk_metadata(digest, k, start, stop)
    if meta.get("lcv.study_sha256") != want["lcv.study_sha256"]:
        return "belongs to another study (or was written by an older lcvreport)"
    if meta.get("lcv.chunk") != want["lcv.chunk"] or meta.get("lcv.cases") != want["lcv.cases"]:
        return (f"holds chunk {meta.get('lcv.chunk')} (cases {meta.get('lcv.cases')}), not chunk {k} "
                f"(cases {want['lcv.cases']})")
    if md.num_rows != stop - start:
        return f"holds {md.num_rows} rows, not {stop - start}"
    return None


#: what an interrupted set-up of a study folder can leave (ours: a rerun clears it)
SETUP_LEFTOVERS = (STUDY, f".{STUDY}.tmp", f".{MANIFEST}.tmp", CHUNKS)


def _write_json(out: Path, name: str, text: str) -> None:
    """Write ``out/name`` whole or not at all (a full disk leaves no partial file)."""
    tmp = out / f".{name}.tmp"
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, out / name)
    finally:
        if tmp.exists():
            tmp.unlink()


def _only_setup_leftovers(out: Path) -> bool:
    """True when ``out`` holds nothing but what an interrupted set-up of a study writes
    (``study.json`` before its manifest, their temporary files, an empty chunks folder)."""
    entries = list(out.iterdir())
    if any(e.name not in SETUP_LEFTOVERS for e in entries):
        return False
    chunks = out / CHUNKS
    if chunks.is_symlink() or (chunks.exists() and not chunks.is_dir()):
        return False
    return not chunks.exists() or all(c.name.startswith(".chunk-") and c.name.endswith(".tmp")
                                      for c in chunks.iterdir())


def _prepare(study: Study, out: Path) -> Path:
    """Create or check the output folder; the chunks folder.  ``study.json`` is written
    first and ``manifest.json`` last: a folder with a manifest is set up; one holding only
    what an interrupted set-up leaves (a full disk, Ctrl-C) is set up again."""
    import shutil
    doc = study.to_dict()
    digest = study.digest()
    if out.exists() and not out.is_dir():
        raise StudyError(f"--out {out} is a file, not a folder")
    if out.exists() and any(out.iterdir()) and not _only_setup_leftovers(out):
        manifest = out / MANIFEST
        if not manifest.is_file():
            raise StudyError(f"--out {out} holds files that are not a study's results; give a new or empty folder")
        from .folder import read_folder_json
        try:
            old = read_folder_json(manifest)
        except StudyError:
            raise StudyError(f"--out {out}: its {MANIFEST} cannot be read; give a new or empty folder") from None
        if old.get("format") != FORMAT or old.get("study_sha256") != digest:
            raise StudyError(f"--out {out} holds the results of another study (or of another version of this one); "
                             "give a new folder to run this one")
        if old.get("n_chunks") != study.n_chunks or old.get("n_cases") != study.n_cases or \
                old.get("chunk_size") != study.chunk:
            raise StudyError(f"--out {out}: its {MANIFEST} was changed (it says {old.get('n_chunks')} chunks of "
                             f"{old.get('chunk_size')} cases, {old.get('n_cases')} cases; the study has "
                             f"{study.n_chunks} of {study.chunk}, {study.n_cases}); give a new folder")
    else:
        if out.exists():                           # an interrupted set-up: ours to clear
            for e in out.iterdir():
                if e.is_dir() and not e.is_symlink():
                    shutil.rmtree(e)
                else:
                    e.unlink()
        out.mkdir(parents=True, exist_ok=True)
        (out / CHUNKS).mkdir(exist_ok=True)
        columns = study.columns
        manifest = {"format": FORMAT, "study_sha256": digest, "n_cases": study.n_cases, "chunk_size": study.chunk,
                    "n_chunks": study.n_chunks, "columns": columns, "seed": study.seed, "kind": study.kind}
        _write_json(out, STUDY, json.dumps(doc, indent=1))
        _write_json(out, MANIFEST, json.dumps(manifest, indent=1))
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

    Returns
    -------
    RunSummary
        How many chunks were computed and found, the folder, the time.

    Raises
    ------
    lcvreport.study.spec.StudyError
        Both ``workers`` and ``scheduler``, ``workers`` outside [1, 256], an output folder that holds
        other files than this study's, an unreachable scheduler (one line).

    Examples
    --------
    >>> import tempfile
    >>> from lcvreport import load_study
    >>> s = load_study("examples/studies/aucnat_loads.toml")
    >>> summary = run_study(s, tempfile.mkdtemp() + "/s", workers=2)  # doctest: +SKIP
    """
    out = Path(out)
    if workers is not None and scheduler is not None:
        raise StudyError("give --workers or --scheduler, not both")
    if workers is not None and not 1 <= workers <= 256:
        raise StudyError(f"--workers must be in [1, 256], got {workers}")
    if scheduler is not None:               # before the folder is touched: one line if it does not answer
        scheduler = check_scheduler_address(scheduler)
        probe_scheduler(scheduler)
    chunks = _prepare(study, out)
    t0 = time.perf_counter()
    n = study.n_cases
    size = study.chunk
    digest = study.digest()
    todo, repaired = [], []
    for k in range(study.n_chunks):
        path = chunks / chunk_name(k)
        if not (path.exists() or path.is_symlink()):
            todo.append(k)
            continue
        if path.is_dir() and not path.is_symlink():
            raise StudyError(f"--out {out}: {path} is a folder, not a chunk; give a new folder")
        why = "is not a regular file" if path.is_symlink() or not path.is_file() else \
            chunk_problem(path, digest, k, k * size, min(n, (k + 1) * size))
        if why is not None:                 # ours, and wrong: computed again (a warning names it)
            print(f"lcv study: warning: {path} {why}; it is computed again", file=sys.stderr)
            path.unlink()
            todo.append(k)
            repaired.append(k)
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
    return RunSummary(out, study.n_chunks, len(todo), found, n, time.perf_counter() - t0, len(repaired),
                      study.seed)


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
    # the workers log errors only: a chunk cancelled by Ctrl-C is not the user's concern
    "distributed.nanny.pre-spawn-environ.DASK_LOGGING__DISTRIBUTED": "error",
}


#: how long a scheduler has to answer, from the TCP connect to its reply to "identity" [s]
SCHEDULER_TIMEOUT_S = 10.0


def check_scheduler_address(address: str) -> str:
    """``address`` as Dask's comm layer reads it (``tcp://host:port``; a bare ``host:port`` is
    TCP), or :class:`StudyError` naming it and the form expected."""
    from distributed.comm.addressing import parse_address, parse_host_port
    form = "tcp://HOST:PORT (or tls://HOST:PORT) of a running Dask scheduler"
    if not isinstance(address, str) or not address.strip() or not address.isprintable():
        raise StudyError(f"--scheduler {address!r}: expected {form}")
    try:
        scheme, loc = parse_address(address)
        host, port = parse_host_port(loc)
    except (ValueError, TypeError) as exc:
        raise StudyError(f"--scheduler {address}: expected {form} ({exc})") from None
    if scheme not in ("tcp", "tls"):
        raise StudyError(f"--scheduler {address}: the scheme {scheme!r} is not one lcv study connects through; "
                         f"expected {form}")
    if not host or not 0 < int(port) < 65536:
        raise StudyError(f"--scheduler {address}: expected {form} (port in 1..65535)")
    return f"{scheme}://{loc}"


def probe_scheduler(address: str, timeout_s: float = SCHEDULER_TIMEOUT_S) -> dict:
    """Ask the peer at ``address`` who it is, with one deadline for the whole exchange (a port
    that accepts and never writes, or answers HTTP, is refused within ``timeout_s``).

    Raises
    ------
    StudyError
        Nothing listens there, the peer does not answer in time, or it is not a Dask scheduler.
    """
    import asyncio

    from distributed.comm import connect

    async def ask():
        comm = await connect(address, timeout=timeout_s)
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    async def bounded():
        return await asyncio.wait_for(ask(), timeout_s)
    try:
        reply = asyncio.run(bounded())
    except (asyncio.TimeoutError, TimeoutError):
        raise StudyError(f"--scheduler {address}: no Dask scheduler answers there (no answer within "
                         f"{timeout_s:g} s)") from None
    except (OSError, EOFError) as exc:
        raise StudyError(f"--scheduler {address}: no Dask scheduler answers there "
                         f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else 'closed'})") from None
    except Exception as exc:  # noqa: BLE001 - whatever a peer that is not a scheduler makes the comm raise
        raise StudyError(f"--scheduler {address}: the peer there is not a Dask scheduler "
                         f"({type(exc).__name__})") from None
    if not isinstance(reply, dict) or reply.get("type") != "Scheduler":
        raise StudyError(f"--scheduler {address}: the peer there is not a Dask scheduler")
    return reply


class _workers_quiet:
    """While the local cluster starts its worker processes: file descriptor 2 points at
    /dev/null, so that the workers inherit it as their standard error.  Ctrl-C reaches the whole
    foreground process group -- the workers too -- and a worker's traceback then goes nowhere;
    this process keeps its own standard error (restored before anything is printed) and acts on
    Ctrl-C alone: the chunks are cancelled and the cluster closed.  A worker's failure still
    reaches this process through its future."""

    def __enter__(self):
        sys.stderr.flush()
        self.saved = os.dup(2)
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 2)
        os.close(null)
        return self

    def __exit__(self, *exc):
        try:
            sys.stderr.flush()
        except (OSError, ValueError):
            pass
        os.dup2(self.saved, 2)
        os.close(self.saved)
        return False


#: the loggers of Dask's machinery (and every logger below them)
DASK_LOGGERS = ("distributed", "tornado", "asyncio")


def quiet_dask_logging() -> None:
    """Nothing from Dask's machinery reaches the terminal: failures reach the study through its
    futures, and an interrupt (Ctrl-C, a batch system's SIGTERM) that lands while the event loop
    runs a callback makes tornado log "Exception in callback" with a traceback -- the command's
    one line says it was interrupted.  Every logger below those names too: distributed's own
    configuration gives ``tornado.application`` a level of its own (ERROR), which a level set on
    ``tornado`` does not reach (that traceback got through, now and then)."""
    import importlib
    import logging

    importlib.import_module("distributed")          # its logging configuration first, then ours over it
    names = set(DASK_LOGGERS) | {n for n in logging.root.manager.loggerDict if n.split(".")[0] in DASK_LOGGERS}
    for name in names:
        logging.getLogger(name).setLevel(logging.CRITICAL)


def _run_distributed(study, todo, bounds, chunks, workers, scheduler, bar) -> None:
    from dask.distributed import Client, LocalCluster, as_completed
    quiet_dask_logging()
    doc = study.to_dict()
    cluster = None
    try:
        if scheduler is not None:
            try:
                client = Client(scheduler, timeout=f"{SCHEDULER_TIMEOUT_S:g}s")
            except (OSError, TimeoutError) as exc:
                raise StudyError(f"--scheduler {scheduler}: no Dask scheduler answers there ({exc})") from None
        else:
            import dask
            with dask.config.set(WORKER_CONFIG), _workers_quiet():
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
