"""The fast path: a compiled DOP853 on the right-hand side generated from the model.

Why.  ``scipy.integrate.solve_ivp`` with a Pinocchio right-hand side spends most
of its time outside the dynamics: each evaluation costs a Python call, array
allocations and scipy's stage bookkeeping (≈ 15–30 µs), against ≈ 1–5 µs for
``pinocchio.aba`` itself.  Here the model's right-hand side *and* the stepper are
compiled together by numba, so one evaluation costs about 0.05–0.3 µs, stage
arithmetic included.  They take one packed float array
(``GeneratedSystem.packed``): a tuple of arrays costs reference counting on every
call, several times the dynamics.

What is compiled.

* the right-hand side generated from the model's closed forms
  (``pendverify.numerics.generate``: any ``ClosedFormModel``, seeds and plug-ins
  alike), under any time-invariant force law τ = B (u0 − K x) − D q̇;
* ``_dop853``: scipy's DOP853 reproduced step for step
  (``pendverify.numerics.integrators.dop853``, a template copied into each model's generated
  module, where it calls that model's ``_rhs`` (inlined where short) and is compiled and cached
  with it); ``integrate`` runs the generated module's copy.
* ``integrate_ensemble``: many initial states at once, one compiled DOP853 per
  state with its own step control; the kernel releases the GIL, so a pool of
  threads runs them in parallel (numba's ``parallel=True`` took ≈ 20 s more to
  compile, for no measurable gain on 2 cores).

Accuracy.  The compiled stepper takes the steps scipy's DOP853 takes at the same
rtol and atol: the same nfev and step count, each step equal to scipy's step from
the same state within the rounding of its stage sums (computed in another order),
step sizes within the jitter that rounding of the error estimate explains (up to
≈ 1e-7 relative; on a chaotic trajectory the final states of the two then differ
by a change of truncation error, ≈ 1e-10 at rtol 1e-5); ``tests/numerics/test_dop853_runner.py``
derives each bound.  So the fast path is as accurate as scipy's DOP853.
Against the high-precision references (``pendverify.numerics.reference``), the tests
check a final-state error ≤ 100 · rtol · (1 + ‖x‖∞) for rtol ≤ 1e-8 over
T ≤ 2 s on the benchmark problems, and ≤ 1e-10 at rtol = atol = 1e-11 on the
chaotic pendulum over 2 s.

The fast path is the model's closed form; that the closed form agrees with
Pinocchio is what ``pendverify check`` establishes (ε-level, every check).
``pendverify.simulation.compiled_scene.simulate_compiled`` runs a scene — a reference system's or a plug-in
model's — on the fast path and evaluates the *same* invariants as ``pendverify.simulation.simulate``
(``pendverify.simulation.invariants``), on the fast path's own steps, with the same
adaptive bound.

JIT.  The generated functions are compiled on first use and cached on disk (numba
``cache=True``, beside the generated module); ``warm_up(systems)`` triggers compilation
and returns the seconds it took, so that benchmarks report it separately from
per-run timings.
"""

from __future__ import annotations

import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from pendverify.numerics.codegen.cache import record_compiled
from pendverify.numerics.generate import GeneratedSystem, distinct_modules
from pendverify.numerics.integrators.dop853 import MAX_STEPS, OK, STEP_TOO_SMALL, TOO_MANY_STEPS

__all__ = ["FastResult", "integrate", "integrate_ensemble", "warm_up"]


# --- the Python side ---------------------------------------------------------------------
@dataclass
class FastResult:
    x: np.ndarray  # state at the final time
    dense: np.ndarray  # states at the requested output times
    steps_t: np.ndarray
    steps_x: np.ndarray
    nfev: int
    steps: int
    rejected: int


def integrate(system: GeneratedSystem, x0, t_end, rtol, atol, t_out=None, record=False) -> FastResult:
    """DOP853 from t = 0 to t_end on the model's generated right-hand side (its module's ``_dop853``).

    ``t_out``: sorted times in [0, t_end] for dense output; ``record``: keep
    every accepted step (for the invariant checks).
    """
    t_out = np.zeros(0) if t_out is None else np.ascontiguousarray(t_out, dtype=float)
    x0 = np.ascontiguousarray(x0, dtype=float)
    n = x0.shape[0]
    out = np.empty((t_out.shape[0], n))
    cap = 4096 if record else 0
    dop853 = system.kernel.module._dop853
    while True:
        y, st, sx = x0.copy(), np.empty(cap), np.empty((cap, n))
        nfev, steps, rejected, status, rows = dop853(
            system.packed(), y, float(t_end), float(rtol), float(atol), t_out, out, st, sx
        )
        if rows <= cap or not record:
            break
        cap = rows  # the run is deterministic: the second pass fits exactly
    record_compiled()  # numba's files of a first call go into the cache's signed record
    if status != OK:
        why = {
            STEP_TOO_SMALL: "step size fell below 10 ulp",
            TOO_MANY_STEPS: f"stopped at its bound of {MAX_STEPS} steps before t_end",
        }.get(status, "non-finite error estimate")
        raise RuntimeError(f"fast-path DOP853 failed: {why} (rtol {rtol:g}, atol {atol:g})")
    rows = rows if record else 1
    st, sx = (st[:rows], sx[:rows]) if record else (np.zeros(1), x0[None, :].copy())
    return FastResult(y, out, st, sx, int(nfev), int(steps), int(rejected))


def integrate_ensemble(system: GeneratedSystem, X0, t_end, rtol, atol, threads: int | None = None):
    """Final states and nfev of one DOP853 per row of X0, on ``threads`` threads (default: all cores).

    Each row is an independent run of the compiled kernel, with its own step
    control, so every trajectory meets the tolerance on its own.  The kernel
    releases the GIL: a pool of Python threads, each walking an interleaved
    slice of the rows, runs them in parallel.
    """
    X0 = np.ascontiguousarray(X0, dtype=float)
    m = X0.shape[0]
    threads = max(1, min(threads or os.cpu_count() or 1, m))
    X, nfev, status = np.empty_like(X0), np.zeros(m, dtype=np.int64), np.zeros(m, dtype=np.int64)
    P, t_end, rtol, atol = system.packed(), float(t_end), float(rtol), float(atol)
    none, no_rows, no_states = np.zeros(0), np.zeros((0, X0.shape[1])), np.zeros((0, X0.shape[1]))
    dop853 = system.kernel.module._dop853

    def work(k):
        for r in range(k, m, threads):
            y = X0[r].copy()
            res = dop853(P, y, t_end, rtol, atol, none, no_rows, none, no_states)
            X[r], nfev[r], status[r] = y, res[0], res[3]

    if threads == 1:
        work(0)
    else:
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(work, range(threads)))
    record_compiled()
    if np.any(status != OK):
        raise RuntimeError(f"fast-path ensemble: {int(np.sum(status != OK))} trajectories failed")
    return X, nfev


def warm_up(systems) -> float:
    """Compile (or load from numba's cache) the stepper of each distinct generated module among
    ``systems`` (``GeneratedSystem``s: a benchmark passes its problems'); the seconds it took."""
    start = time.perf_counter()
    for system in distinct_modules(systems):
        x0 = np.full(2 * system.nv, 0.1)
        integrate(system, x0, 0.01, 1e-6, 1e-6, t_out=np.array([0.005]), record=True)
        integrate(system, np.append(x0, [0.0, 0.0]), 0.01, 1e-6, 1e-6)
        integrate_ensemble(system, np.tile(x0, (2, 1)), 0.01, 1e-6, 1e-6)
    return time.perf_counter() - start
