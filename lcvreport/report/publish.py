"""Where a report is written: the output folder's checks, the staging folder beside it,
its manifest, and the atomic publish (the folder appears whole or not at all; an
interrupted build leaves nothing and a user's file is never removed or rewritten).
"""
from __future__ import annotations

import shutil
from pathlib import Path

from .notebooks import ReportError, process_alive, stop_kernels, silence_client_loggers


def prepare_folder(out_dir: Path) -> tuple[Path, Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    for stale in (out_dir / "index.html", out_dir / "report.pdf", out_dir / "latex.log"):
        stale.unlink(missing_ok=True)
    data_dir = out_dir / "data"
    if data_dir.exists():
        shutil.rmtree(data_dir)
    data_dir.mkdir(parents=True)
    return out_dir, data_dir


#: the manifest an assessment report leaves in its folder: every file and folder it wrote
MANIFEST = ".lcv-report.json"
#: the entries of a report written before the manifest listed every path (lcvreport <= 0.2.x
#: listed only the top-level names): what those reports wrote inside their folders
LEGACY_NESTED = (("data", r"(?:table|figure)_[A-Za-z0-9_.-]+\.csv"), ("notebooks", r"[A-Za-z0-9_]+\.ipynb"),
                 ("mathjax", r".+"))


class OutputFolderError(ReportError):
    """``--out`` names a folder the report may not write into (a usage error)."""


def _digest(path: Path) -> str:
    import hashlib
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def report_paths(folder: Path) -> dict:
    """Every entry under ``folder`` (not following links) by its path relative to it (``/``
    separated): ``"dir"`` for a folder, ``"link"`` for a symbolic link, a file's SHA-256 -- what a
    report's manifest records of what it wrote."""
    import os
    out = {}
    for root, dirs, files in os.walk(folder):
        base = Path(root)
        for name in sorted(dirs + files):
            p = base / name
            rel = p.relative_to(folder).as_posix()
            out[rel] = "link" if p.is_symlink() else "dir" if p.is_dir() else _digest(p)
        dirs[:] = [d for d in dirs if not (base / d).is_symlink()]
    return out


def write_manifest(folder: Path, written_by: str) -> None:
    """The manifest of the report staged in ``folder``: who wrote it and every path it holds."""
    import json
    paths = report_paths(folder)
    files = sorted({rel.split("/", 1)[0] for rel in paths} | {MANIFEST})
    (folder / MANIFEST).write_text(json.dumps({"written_by": written_by, "files": files, "paths": paths}, indent=1),
                                   encoding="utf-8")


def _foreign(out: Path, manifest: dict) -> list[str]:
    """The entries of the earlier report ``out`` that its manifest does not account for: a file a
    person added anywhere in it (``data/mine.csv`` too), or changed since the report wrote it."""
    import re
    here = report_paths(out)
    here.pop(MANIFEST, None)
    paths = manifest.get("paths")
    if isinstance(paths, dict):                        # every path listed, with its digest
        return [rel if rel not in paths else f"{rel} (changed since the report wrote it)"
                for rel, what in here.items() if paths.get(rel) != what]
    owned = set(manifest["files"]) | {MANIFEST}        # an earlier manifest: the top-level names only
    legacy = dict(LEGACY_NESTED)
    bad = []
    for rel, what in here.items():
        top, _, rest = rel.partition("/")
        if top not in owned:
            bad.append(rel)
        elif rest and not (top in legacy and (what == "dir" or re.fullmatch(legacy[top], rest))):
            bad.append(rel)
        elif what == "link":
            bad.append(rel)
    return bad


def check_output_folder(out_dir: str | Path) -> Path:
    """The folder an assessment report may be written to, resolved.

    A report goes into a new folder, an empty one, or the folder of an earlier report (every
    entry in it, at any depth, listed in that report's manifest and unchanged, so replacing it
    removes nothing a person put there or edited).  Anything else is refused: a report never
    removes or rewrites a file it did not write.

    Raises
    ------
    OutputFolderError
        Naming the folder and what is in the way.
    """
    import json
    out = Path(out_dir).resolve()
    if out.exists() and not out.is_dir():
        raise OutputFolderError(f"--out {out_dir}: exists and is not a folder")
    if not out.exists():
        if not out.parent.is_dir():
            raise OutputFolderError(f"--out {out_dir}: its parent folder {out.parent} does not exist")
        return out
    entries = sorted(p.name for p in out.iterdir())
    if not entries:
        return out
    manifest = out / MANIFEST
    try:
        doc = json.loads(manifest.read_text(encoding="utf-8"))
        doc["files"]
    except (OSError, ValueError, KeyError, TypeError):
        raise OutputFolderError(f"--out {out_dir}: the folder is not empty ({', '.join(entries[:3])}"
                                f"{', ...' if len(entries) > 3 else ''}) and holds no report written by lcv report; "
                                "give a new or empty folder") from None
    foreign = _foreign(out, doc)
    if foreign:
        raise OutputFolderError(f"--out {out_dir}: besides an earlier report the folder holds "
                                f"{', '.join(foreign[:3])}{', ...' if len(foreign) > 3 else ''}, which lcv report did "
                                "not write; give a new or empty folder")
    return out


class WriterLock:
    """The one writer of a report folder: ``.<name>.lock`` beside ``out``, locked (``flock``)
    while a report is written into ``out`` and holding the writer's pid.  A second report into the
    same folder is refused at once, naming the first; the lock goes with its process (a killed
    writer leaves a file nobody holds, which the next writer takes)."""

    def __init__(self, out: Path):
        self.out = Path(out)
        self.path = self.out.with_name(f".{self.out.name}.lock")
        self.fd = None

    def __enter__(self) -> "WriterLock":
        import fcntl
        import os
        for _attempt in range(10):
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                try:
                    pid = os.read(fd, 32).decode("ascii", "replace").strip() or "?"
                finally:
                    os.close(fd)
                raise OutputFolderError(f"--out {self.out}: another report (process {pid}) is being written into "
                                        "this folder; wait for it or give another folder") from None
            try:
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if same:                                   # not a lock file its last holder just removed
                os.ftruncate(fd, 0)
                os.write(fd, str(os.getpid()).encode())
                self.fd = fd
                return self
            os.close(fd)
        raise OutputFolderError(f"--out {self.out}: cannot take the folder's lock {self.path}")

    def __exit__(self, *exc) -> None:
        import os
        if self.fd is not None:
            try:
                os.unlink(self.path)
            except OSError:
                pass
            os.close(self.fd)
            self.fd = None


def stage_folder(out: Path) -> Path:
    """A new hidden folder beside ``out`` to write the report into: ``.<name>.writing-<pid>-XXXX``.
    Folders of that form left by a process that no longer runs (SIGKILL, a power cut) are removed
    first: they are this command's, and nobody else writes them."""
    import os
    import re
    import tempfile
    pattern = re.compile(rf"\.{re.escape(out.name)}\.(?:writing|replaced)-(\d+)(?:-.*)?\Z")
    for p in out.parent.iterdir() if out.parent.is_dir() else ():
        m = pattern.match(p.name)
        if m and p.is_dir() and not p.is_symlink() and not process_alive(int(m.group(1))):
            shutil.rmtree(p, ignore_errors=True)
    return Path(tempfile.mkdtemp(prefix=f".{out.name}.writing-{os.getpid()}-", dir=out.parent))


def discard_staged(staged: Path, interrupted: bool = False) -> None:
    """Remove a report's staging folder after a failure or an interruption: its kernels first.
    After an interruption the notebook client's event loop still waits in its own thread for the
    cell the kernel was running; the loggers it reports through are silenced first, so that the
    kernel's end is not reported as an error (the interruption is the one line)."""
    if interrupted:
        silence_client_loggers()
    stop_kernels()
    shutil.rmtree(staged, ignore_errors=True)


def publish_staged(staged: Path, out: Path, existed_as: tuple) -> None:
    """Move the finished report ``staged`` into place as ``out`` (renames on one file
    system: a reader sees the old report or the new one, never a mix).  Ctrl-C and SIGTERM wait
    while it runs (the renames and the removal of the old report are one step: an interruption
    never leaves a half-removed copy beside the new report) and take effect after it."""
    import os

    from ..util.interrupts import raise_if_interrupted
    raise_if_interrupted()         # an interruption the interpreter swallowed: nothing is published
    with _deferred_interrupts():
        now = folder_state(out)
        if now != existed_as:
            raise ReportError(f"{out} changed while the report was being written (another report into the same "
                              "folder?); nothing was replaced")
        if now[0] == "report":
            aside = out.with_name(f".{out.name}.replaced-{os.getpid()}")
            os.rename(out, aside)
            try:
                os.rename(staged, out)
            except OSError:
                os.rename(aside, out)
                raise
            shutil.rmtree(aside, ignore_errors=True)
        else:
            os.rename(staged, out)     # replaces an empty folder atomically; fails if one appeared meanwhile


class _deferred_interrupts:
    """SIGINT and SIGTERM recorded, not acted on, inside the block; acted on (the handlers they
    had: KeyboardInterrupt, the CLI's SIGTERM) when it ends.  The Python handlers are swapped, not
    the thread's signal mask: a signal sent to the process may land on any thread, and Python runs
    its handler in the main thread whatever the mask.  Outside the main thread: nothing to defer
    (no handler runs there)."""

    SIGNALS = ("SIGINT", "SIGTERM")

    def __enter__(self):
        import signal
        import threading
        self.pending, self.saved = [], {}
        if threading.current_thread() is threading.main_thread():
            for name in self.SIGNALS:
                num = getattr(signal, name)
                self.saved[num] = signal.signal(num, lambda signum, _frame: self.pending.append(signum))
        return self

    def __exit__(self, *exc) -> None:
        import os
        import signal
        for num, handler in self.saved.items():
            signal.signal(num, handler)
        if self.pending and exc[0] is None:
            num = self.pending[0]
            handler = self.saved[num]
            if callable(handler):
                handler(num, None)                 # KeyboardInterrupt, or the CLI's SIGTERM handler
            elif handler == signal.SIG_DFL:
                os.kill(os.getpid(), num)          # the default action, now


def folder_state(out: Path) -> tuple:
    """What ``out`` is now -- absent, empty, a report (its manifest and the folder's inode: a
    report put in its place by another writer differs), or something else."""
    if not out.exists():
        return ("absent",)
    entries = sorted(p.name for p in out.iterdir())
    if not entries:
        return ("empty", out.stat().st_ino)
    try:
        return ("report", (out / MANIFEST).read_bytes(), out.stat().st_ino)
    except OSError:
        return ("other", tuple(entries))
