"""Wall-time measurement and the machine it ran on.

``measure``: one warm-up call, then the minimum and the median of ``repeats``
samples with the garbage collector off; calls shorter than ``SAMPLE_FLOOR`` are
repeated within a sample and the sample divided by the count (as ``timeit``
does), so that the timer's own cost stays negligible.  The CPU model comes from
/proc/cpuinfo; BLAS threads are limited by the caller (``pendverify bench``).
"""

from __future__ import annotations

import gc
import os
import platform
import statistics
import time

import numpy as np

SAMPLE_FLOOR = 0.005  # s: shorter calls are batched within one timing sample


def measure(fn, repeats: int, first: float | None = None):
    """(min, median, result) of the seconds one call of ``fn`` takes.

    One warm-up call (its result is returned), then ``repeats`` samples.  A call
    shorter than ``SAMPLE_FLOOR`` is repeated within each sample (as ``timeit``
    does) and the sample divided by the count, so timer overhead stays small.
    ``first``: the caller already made the warm-up call (an untimed run of the
    same integration, e.g. with dense output) and it took about this long; the
    result is then that of the last timed call.
    """
    result = None
    if first is None:
        start = time.perf_counter()
        result = fn()
        first = time.perf_counter() - start
    number = max(1, min(1000, int(SAMPLE_FLOOR / max(first, 1e-7))))
    times = []
    enabled = gc.isenabled()
    gc.disable()
    try:
        for _ in range(max(1, repeats)):
            start = time.perf_counter()
            for _ in range(number):
                last = fn()
            times.append((time.perf_counter() - start) / number)
    finally:
        if enabled:
            gc.enable()
    return min(times), statistics.median(times), last if result is None else result


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def machine_info(blas: str) -> dict:
    import numba
    import pinocchio
    import scipy

    return {
        "cpu": cpu_model(),
        "cores": os.cpu_count(),
        "blas_threads": blas,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pinocchio": pinocchio.__version__,
        "numba": numba.__version__,
    }
