"""The machine a benchmark ran on, printed first by the benchmarks whose targets are times
(issue 43): the CPU, the SIMD extensions numpy dispatches to and the BLAS kernels.  The same code
took 19.9 s for 10^4 variants on an AVX-512 Xeon and 25-29 s on the machine before it, so a time
is read together with this line.

    python benchmarks/machine.py
"""
from __future__ import annotations

import os
import platform


def cpu_model() -> str:
    """The CPU's model name (/proc/cpuinfo; the platform's processor string elsewhere)."""
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_line() -> str:
    """One line: CPU model and count, numpy's SIMD extensions found, the BLAS library's kernels and
    threads (after the benchmark set its one BLAS thread)."""
    import numpy as np
    from threadpoolctl import threadpool_info
    from numpy._core._multiarray_umath import __cpu_features__
    simd = [k for k in ("AVX2", "FMA3", "AVX512F", "AVX512_SKX", "AVX512_SPR") if __cpu_features__.get(k)]
    blas = "; ".join(f"{i.get('internal_api')} {i.get('version')} {i.get('architecture')} x{i.get('num_threads')}"
                     for i in threadpool_info() if i.get("user_api") == "blas")
    return (f"machine: {cpu_model()}, {os.cpu_count()} CPUs; numpy {np.__version__} SIMD {'/'.join(simd) or 'baseline'}; "
            f"BLAS {blas or 'not loaded'}")


if __name__ == "__main__":
    print(machine_line())
