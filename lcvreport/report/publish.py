"""Where a report is written: the output folder's checks, the staging folder beside it,
its manifest, and the atomic publish (the folder appears whole or not at all; an
interrupted build leaves nothing and a user's file is never removed or rewritten).
"""
from __future__ import annotations

import shutil
from pathlib import Path

from .notebooks import ReportError, _alive, _stop_kernels, silence_client_loggers


def _prepare(out_dir: Path) -> tuple[Path, Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    for stale in (out_dir / "index.html", out_dir / "report.pdf", out_dir / "latex.log"):
        stale.unlink(missing_ok=True)
    data_dir = out_dir / "data"
    if data_dir.exists():
        shutil.rmtree(data_dir)
    data_dir.mkdir(parents=True)
    return out_dir, data_dir


#: the manifest an assessment report leaves in its folder: the names it wrote
MANIFEST = ".lcv-report.json"


class OutputFolderError(ReportError):
    """``--out`` names a folder the report may not write into (a usage error)."""


def check_output_folder(out_dir: str | Path) -> Path:
    """The folder an assessment report may be written to, resolved.

    A report goes into a new folder, an empty one, or the folder of an earlier report
    (every entry in it listed in that report's manifest, so replacing it removes nothing
    a person put there).  Anything else is refused: a report never removes or rewrites a
    file it did not write.

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
        owned = set(json.loads(manifest.read_text(encoding="utf-8"))["files"]) | {MANIFEST}
    except (OSError, ValueError, KeyError, TypeError):
        raise OutputFolderError(f"--out {out_dir}: the folder is not empty ({', '.join(entries[:3])}"
                                f"{', ...' if len(entries) > 3 else ''}) and holds no report written by lcv report; "
                                "give a new or empty folder") from None
    foreign = [e for e in entries if e not in owned]
    if foreign:
        raise OutputFolderError(f"--out {out_dir}: besides an earlier report the folder holds "
                                f"{', '.join(foreign[:3])}{', ...' if len(foreign) > 3 else ''}, which lcv report did "
                                "not write; give a new or empty folder")
    return out


def _stage(out: Path) -> Path:
    """A new hidden folder beside ``out`` to write the report into: ``.<name>.writing-<pid>-XXXX``.
    Folders of that form left by a process that no longer runs (SIGKILL, a power cut) are removed
    first: they are this command's, and nobody else writes them."""
    import os
    import re
    import tempfile
    pattern = re.compile(rf"\.{re.escape(out.name)}\.(?:writing|replaced)-(\d+)(?:-.*)?\Z")
    for p in out.parent.iterdir() if out.parent.is_dir() else ():
        m = pattern.match(p.name)
        if m and p.is_dir() and not p.is_symlink() and not _alive(int(m.group(1))):
            shutil.rmtree(p, ignore_errors=True)
    return Path(tempfile.mkdtemp(prefix=f".{out.name}.writing-{os.getpid()}-", dir=out.parent))


def _discard(staged: Path, interrupted: bool = False) -> None:
    """Remove a report's staging folder after a failure or an interruption: its kernels first.
    After an interruption the notebook client's event loop still waits in its own thread for the
    cell the kernel was running; the loggers it reports through are silenced first, so that the
    kernel's end is not reported as an error (the interruption is the one line)."""
    if interrupted:
        silence_client_loggers()
    _stop_kernels()
    shutil.rmtree(staged, ignore_errors=True)


def _publish(staged: Path, out: Path, existed_as: tuple) -> None:
    """Move the finished report ``staged`` into place as ``out`` (renames on one file
    system: a reader sees the old report or the new one, never a mix)."""
    import os
    now = _folder_state(out)
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


def _folder_state(out: Path) -> tuple:
    if not out.exists():
        return ("absent",)
    entries = sorted(p.name for p in out.iterdir())
    if not entries:
        return ("empty",)
    try:
        return ("report", (out / MANIFEST).read_bytes())
    except OSError:
        return ("other", tuple(entries))
