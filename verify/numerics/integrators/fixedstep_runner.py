"""Runs the fixed-step methods (``pendverify.numerics.integrators.fixedstep``) of a model's generated module.

The methods are templates copied into each generated module (``pendverify.numerics.generate``);
``integrate_fixed`` calls the copy of one ``GeneratedSystem``'s module with its packed
parameters, and ``warm_up`` compiles the copies before a benchmark times them.
"""

from __future__ import annotations

import time

import numpy as np

from pendverify.errors import PendverifyError
from pendverify.numerics.codegen.cache import record_compiled
from pendverify.numerics.generate import GeneratedSystem, distinct_modules
from pendverify.numerics.integrators.fixedstep import METHOD_IDS, OK


def integrate_fixed(method: str, system: GeneratedSystem, x0, duration: float, steps: int, every: int = 1):
    """States (q, q̇) at t = k·every·h, h = duration / steps; plus nfev and whether it succeeded.

    ``steps`` must be a multiple of ``every``.  A failed run (an implicit step
    that did not converge, or a non-finite state) returns ok = False.
    """
    if method not in METHOD_IDS:
        raise ValueError(f"unknown fixed-step method {method!r}; expected one of {', '.join(METHOD_IDS)}")
    if steps % every:
        raise ValueError(f"steps ({steps}) must be a multiple of every ({every})")
    if system.forcing:
        raise PendverifyError(f"{system.model}: the fixed-step methods integrate a time-invariant force law")
    x0 = np.ascontiguousarray(x0, dtype=float)
    run = system.kernel.module._run
    out, nfev, status = run(METHOD_IDS[method], system.packed(), x0, duration / steps, steps, every)
    record_compiled()  # numba's files of a first call go into the cache's signed record
    return out, int(nfev), status == OK


def warm_up(systems) -> float:
    """Compile (or load from numba's cache) the fixed-step methods of each distinct generated module
    among ``systems`` (``GeneratedSystem``s); the seconds it took."""
    start = time.perf_counter()
    for system in distinct_modules(systems):
        integrate_fixed("rk4", system, np.full(2 * system.nv, 0.1), 0.01, 2)
    return time.perf_counter() - start
