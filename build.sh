#!/usr/bin/env bash
# One entry point for the project.
#
#   ./build.sh          set up, build the FMUs, build the report
#   ./build.sh setup    system packages (Debian) + .venv with pinned Python packages
#   ./build.sh fmu      build/LCV.fmu, build/LCV3.fmu (pythonfmu, pythonfmu3) and build/LCVNative.fmu, build/LCVNative3.fmu (C)
#   ./build.sh report   execute the notebooks, write build/report/{index.html,report.pdf,data/}
#   ./build.sh docs     the documentation site into build/docs/ (Sphinx, warnings as errors)
#   ./build.sh test     set up, build the FMUs, run the whole test suite
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
cd "$ROOT"
VENV="$ROOT/.venv"
PY="$VENV/bin/python"
export PYTHONHASHSEED=0
export SOURCE_DATE_EPOCH=1312156800   # 2011-08-01, the dissertation's date: reproducible PDFs

# Debian packages: LaTeX route of nbconvert (PDF), MathJax for the offline HTML,
# TBB for ecos, poppler for PDF checks, valgrind and gcc for the native FMU, cmake and make
# for `fmpy compile` (a test rebuilds the native FMU from its sources/), Chromium for the browser
# tests (tests/browser/: Playwright drives Debian's chromium; its own browser download is not used).
APT_PACKAGES=(texlive-xetex texlive-latex-recommended texlive-fonts-recommended texlive-plain-generic pandoc libjs-mathjax
              fonts-dejavu-core libtbb12 poppler-utils valgrind gcc cmake make chromium)

log() { printf '[build.sh] %s\n' "$*" >&2; }

system_packages() {
    local missing=() p
    for p in "${APT_PACKAGES[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    local sudo=""
    if [ "$(id -u)" != 0 ]; then
        command -v sudo >/dev/null || { log "need root to install Debian packages: ${missing[*]}"; exit 1; }
        sudo="sudo"
    fi
    log "installing Debian packages: ${missing[*]}"
    $sudo apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

python_env() {
    [ -x "$PY" ] || { log "creating .venv"; python3 -m venv "$VENV"; }
    local stamp
    stamp="$VENV/.installed-$(cat pyproject.toml constraints.txt | sha1sum | cut -c1-16)"
    if [ ! -f "$stamp" ]; then
        log "installing the package and pinned dependencies into .venv"
        "$PY" -m pip install -q -c constraints.txt -e ".[fmu,report,study,test,docs]"
        rm -f "$VENV"/.installed-*
        touch "$stamp"
    fi
}

# the package's C sources (the nonlinear model's equations, the turn's path-following law;
# lcvreport/util/compiled.py): compiled now, not at the first command that needs them
native() { "$PY" -m lcvreport.util.compiled >&2; }

setup() { system_packages; python_env; native; }

docs() {
    rm -rf build/docs
    "$PY" -m sphinx -W --keep-going -q -b html -d build/docs/.doctrees docs build/docs
    log "wrote build/docs/index.html"
}

fmu() {
    mkdir -p build
    "$PY" -m lcvreport.fmu.build --out build
}

report() {
    "$PY" -m lcvreport.report.build --build-dir build
}

run_tests() {
    # one BLAS thread per process: parallelism comes from the two pytest workers (issue 21)
    local n="${LCV_BLAS_THREADS:-1}"
    OPENBLAS_NUM_THREADS="${OPENBLAS_NUM_THREADS:-$n}" OMP_NUM_THREADS="${OMP_NUM_THREADS:-$n}" \
        MKL_NUM_THREADS="${MKL_NUM_THREADS:-$n}" "$PY" -m pytest -q -n 2 --dist loadgroup -p no:cacheprovider "$@"
}

cmd="${1:-all}"
[ $# -gt 0 ] && shift
case "$cmd" in
    all)    setup; fmu; report ;;
    setup)  setup ;;
    fmu)    setup; fmu ;;
    report) setup; report ;;
    docs)   setup; docs ;;
    test)   setup; fmu; run_tests "$@" ;;
    *)      echo "usage: ./build.sh [all|setup|fmu|report|docs|test]" >&2; exit 2 ;;
esac
