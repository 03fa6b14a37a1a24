"""Build the FMUs: ``build/LCV.fmu`` (pythonfmu) and ``build/LCVNative.fmu`` (C).

``python -m lcvreport.fmu_build --out build`` is what ``./build.sh fmu`` runs.  The
pythonfmu FMU bundles ``fmu_src/fmi_xml.py`` and a copy of the ``lcvreport`` package
(without caches) into ``resources/``; numpy and scipy must be importable at run time.
"""
from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def build_python_fmu(out_dir: Path) -> Path:
    """Run ``pythonfmu build`` on ``fmu_src/LCV.py``; return the FMU path."""
    out_dir = out_dir.resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        pkg = Path(tmp) / "lcvreport"
        shutil.copytree(ROOT / "lcvreport", pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "native"))
        cmd = [sys.executable, "-m", "pythonfmu", "build", "-f", str(ROOT / "fmu_src" / "LCV.py"),
               "-d", str(out_dir), "--handle-state", "--serialize-state",
               str(ROOT / "fmu_src" / "fmi_xml.py"), str(pkg)]
        subprocess.run(cmd, check=True, cwd=tmp)
    fmu = out_dir / "LCV.fmu"
    if not fmu.exists():
        raise SystemExit(f"pythonfmu did not produce {fmu}")
    return fmu


def main(argv: list[str] | None = None) -> int:
    """Command-line entry: build every FMU into ``--out``."""
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("--out", default="build", type=Path, help="output folder (default build)")
    args = p.parse_args(argv)
    fmu = build_python_fmu(args.out)
    print(f"built {fmu}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
