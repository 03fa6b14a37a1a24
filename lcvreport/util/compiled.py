"""C sources of the package compiled on this machine and loaded with ctypes (the nonlinear model's
equations, :mod:`lcvreport.model.nonlinear.native`; the turn's path-following law,
:mod:`lcvreport.measures.friction_demand`): hot inner loops that numpy would pay the
interpreter's cost for at every call.

A source is compiled with the machine's C compiler (``$CC``, ``cc``, else ``gcc``) the first
time it is needed and kept in the user's cache (``$LCV_CACHE_DIR``, else
``$XDG_CACHE_HOME/lcvreport``, else ``~/.cache/lcvreport``), named by the hash of its source and
flags: a changed source is a new library, never a stale one; written atomically, so concurrent
processes find a whole library or none.  ``./build.sh`` compiles them at set-up.  Where no
compiler or no writable cache is found, or ``LCV_NATIVE=0``, :func:`load` says why and the caller
runs its numpy twin (the same equations, numbers that differ in rounding only).

Examples
--------
>>> from pathlib import Path
>>> import lcvreport.model.nonlinear as nl
>>> lib, why = load(Path(nl.__file__).with_name("equations.c"))
>>> (lib is None) == (not why.startswith("compiled: "))
True
"""
from __future__ import annotations

import ctypes
import hashlib
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

#: the compiler's flags: optimized, no fused multiply-add (the source's rounding), position-independent
FLAGS = ("-O2", "-ffp-contract=off", "-fno-fast-math", "-shared", "-fPIC")

_loaded: dict = {}


def cache_dir() -> Path:
    """Where compiled libraries are kept (see the module docstring)."""
    if os.environ.get("LCV_CACHE_DIR"):
        return Path(os.environ["LCV_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "lcvreport"


def _compiler() -> str | None:
    for name in (os.environ.get("CC"), "cc", "gcc"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def library_path(source: Path) -> Path:
    """The cache's file of ``source`` compiled: ``lcv_<stem>_<hash of source and flags>.so``."""
    digest = hashlib.sha256(source.read_bytes() + " ".join(FLAGS).encode()).hexdigest()[:16]
    return cache_dir() / f"lcv_{source.stem}_{digest}.so"


def _build(source: Path, target: Path) -> str | None:
    """Compile ``source`` to ``target``; the reason it could not, or None."""
    cc = _compiler()
    if cc is None:
        return "no C compiler (cc, gcc) on PATH"
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(suffix=".so", dir=target.parent)
        os.close(fd)
    except OSError as exc:
        return f"the cache {target.parent} is not writable ({exc.strerror})"
    try:
        done = subprocess.run([cc, *FLAGS, "-o", tmp, str(source), "-lm"], capture_output=True, text=True,
                              timeout=120)
        if done.returncode != 0:
            return f"{cc} failed: {done.stderr.strip().splitlines()[-1] if done.stderr.strip() else done.returncode}"
        os.replace(tmp, target)
        return None
    except (OSError, subprocess.SubprocessError) as exc:
        return f"{cc} could not run ({exc})"
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)


def load(source: Path, signatures: dict | None = None) -> tuple:
    """(library, why) of the C ``source``: the ctypes library (compiled if needed; each function of
    ``signatures``, name -> (restype, argtypes), declared) and ``"compiled: <path>"``, or (None,
    the reason it could not be had).  Once per process and source."""
    source = Path(source)
    if source in _loaded:
        return _loaded[source]
    lib, why = None, None
    if os.environ.get("LCV_NATIVE", "1") == "0":
        why = "LCV_NATIVE=0"
    else:
        path = library_path(source)
        if not path.exists():
            why = _build(source, path)
        if why is None:
            try:
                lib = ctypes.CDLL(str(path))
                for name, (restype, argtypes) in (signatures or {}).items():
                    f = getattr(lib, name)
                    f.restype, f.argtypes = restype, argtypes
                why = f"compiled: {path}"
            except (OSError, AttributeError) as exc:
                lib, why = None, f"{path} could not be loaded ({exc})"
    _loaded[source] = (lib, why)
    return lib, why


def command_line(prog: str, doc: str, argv=None) -> int | None:
    """The argument check of a command that takes none (``python -m <prog>``): the exit status
    (0 after ``--help``, 2 after one line naming an argument), or None to go on."""
    import sys
    argv = sys.argv[1:] if argv is None else argv
    if argv in (["-h"], ["--help"]):
        print(f"usage: python -m {prog}\n" + " ".join(line.strip() for line in doc.split("\n\n")[0].split("\n")))
        return 0
    if argv:
        print(f"python -m {prog}: takes no argument, got {argv[0]!r}", file=sys.stderr)
        return 2
    return None


def main(argv=None) -> int:
    """``python -m lcvreport.util.compiled``: compile (if needed) every C source of the package and
    say where each is, or why not (``./build.sh`` set-up).  Takes no argument (``--help``: this)."""
    status = command_line("lcvreport.util.compiled", main.__doc__ or "", argv)
    if status is not None:
        return status
    for source in sorted(Path(__file__).resolve().parents[1].rglob("*.c")):
        print(f"{source.name}: {load(source)[1]}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
