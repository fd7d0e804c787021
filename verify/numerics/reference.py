"""High-precision reference solutions: Taylor series at two precisions, bounded, cached.

Method.  ``pendverify.numerics.integrators.taylor`` integrates the ODE of the model's generated
``field`` (the model's own closed forms, same parameters, same force law as the
compiled back ends, initial state converted exactly) by a Taylor series method
with automatic differentiation, in decimal arithmetic, with the order and step
rule of Jorba & Zou.

How its error is bounded.  The same problem is solved twice: at ε = 10^-30
with 38 working digits (the reference) and at ε = 10^-40 with 48 digits (the
check); the quick benchmark and the tests use fewer digits, e.g. 24 and 32.
Both runs see the same double-precision constants and initial state, converted
exactly.  ``error_bound`` = max |x₁ − x₂| over every dense point and component;
since the check is eight to ten orders more accurate, this bounds the
reference's own error, chaos included (both runs amplify their errors alike).
The reference is stored as a double-double (hi + lo, ≈ 32 digits), and errors
of a double-precision run are formed as (x − hi) − lo, exact to ≈ 1e-32.

Cache.  Results go to the cache folder (``pendverify.cache_location``), one
``.npz`` per problem, named by the SHA-256 of a canonical description (the
digest of the model's generated generic code ``FIELD_DIGEST`` — the equations the
reference integrates —, the packed parameters and force law and the initial
state as exact float hex, horizon, dense grid, precisions, method version), so a
cached reference is reused only for the identical problem.  The files are arrays read
without pickles; one that is truncated or not a reference of its key is computed again
and rewritten, and a reference that cannot be written (a read-only or full cache) is
returned uncached with one line on stderr.
"""

from __future__ import annotations

import hashlib
import io
import json
import sys
import time
import zipfile
from dataclasses import dataclass
from decimal import Decimal, localcontext
from pathlib import Path

import mpmath
import numpy as np

from pendverify.atomic import write_atomic
from pendverify.cache_location import cache_root
from pendverify.errors import FileAccessError
from pendverify.numerics.codegen.folder import create_private
from pendverify.numerics.integrators.taylor import (
    GUARD_DIGITS,
    TaylorRun,
    energy_above_minimum,
    exact_system,
    float_system,
    taylor_solve,
)

VERSION = "taylor-jz-2"
DIGITS, CHECK_DIGITS = 30, 40


# --- cached references -----------------------------------------------------------------------
@dataclass(frozen=True)
class Reference:
    """States at the dense grid as hi + lo doubles, with the bound on their own error."""

    t: np.ndarray
    hi: np.ndarray
    lo: np.ndarray
    error_bound: float  # max |x₃₀ − x₄₀| over grid and components (absolute, SI)
    digits: int
    check_digits: int
    steps: int
    order: int
    seconds: float  # time to compute both runs (0 when read from the cache)
    key: str
    cached: bool = False

    def errors(self, states: np.ndarray) -> np.ndarray:
        """|x − x_ref| per grid point and component, with x given at every grid point."""
        return np.abs((np.asarray(states, float) - self.hi) - self.lo)

    def final_error(self, x: np.ndarray) -> float:
        return float(np.max(np.abs((np.asarray(x, float) - self.hi[-1]) - self.lo[-1])))

    def describe(self) -> str:
        origin = "cache" if self.cached else f"computed in {self.seconds:.1f} s"
        return (
            f"Taylor order {self.order}, {self.steps} steps, tolerance 1e-{self.digits}; "
            f"|x(1e-{self.digits}) − x(1e-{self.check_digits})| ≤ {self.error_bound:.1e} ({origin})"
        )


def problem_key(fast, x0, duration, grid, digits=DIGITS, check_digits=CHECK_DIGITS) -> str:
    def hexes(a):
        return [float(v).hex() for v in np.ravel(a)]

    description = {
        "version": VERSION,
        "model": fast.model,
        "equations": fast.module.FIELD_DIGEST,
        "packed": hexes(fast.packed()),
        "x0": hexes(x0),
        "duration": float(duration).hex(),
        "grid": hexes(grid),
        "digits": [digits, check_digits, GUARD_DIGITS],
    }
    return hashlib.sha256(json.dumps(description, sort_keys=True).encode()).hexdigest()


def _cache_path(key: str) -> Path:
    return cache_root() / f"reference-{key[:24]}.npz"


#: what reading a cached reference that is not one ``_assemble`` wrote raises (truncated, garbage)
UNREADABLE = (OSError, EOFError, ValueError, KeyError, TypeError, zipfile.BadZipFile)


def _load(key: str) -> Reference | None:
    """The cached reference of ``key``, or None when there is none or the file is not a complete
    one for that key (it is then computed again and rewritten).  Arrays only: no pickles."""
    path = _cache_path(key)
    if not path.is_file():
        return None
    try:
        with open(path, "rb") as fh, np.load(fh, allow_pickle=False) as data:  # closed if np.load raises
            meta = json.loads(str(data["meta"]))
            if not isinstance(meta, dict) or meta.get("key") != key or set(meta) != set(_META):
                return None
            t, hi, lo = (np.asarray(data[name], float) for name in ("t", "hi", "lo"))
    except UNREADABLE:
        return None
    if hi.shape != lo.shape or hi.shape[:1] != t.shape:
        return None
    return Reference(t, hi, lo, **meta, cached=True)


_META = ("error_bound", "digits", "check_digits", "steps", "order", "seconds", "key")


def _store(key: str, data: bytes) -> None:
    """Write a reference to the cache; one that cannot be written is only noted (it was computed)."""
    path = _cache_path(key)
    try:
        create_private(path.parent)
        write_atomic(path, data)
    except (FileAccessError, OSError) as exc:
        print(f"pendverify: note: the reference is not cached ({exc})", file=sys.stderr, flush=True)


def _assemble(run: TaylorRun, check: TaylorRun, grid, key, seconds, digits, check_digits, cache) -> Reference:
    with localcontext() as ctx:
        ctx.prec = check_digits + GUARD_DIGITS
        bound = max(
            abs(a - b)
            for xa, xb in zip(run.grid, check.grid, strict=True)
            for a, b in zip(xa, xb, strict=True)
        )
        hi = np.array([[float(v) for v in row] for row in run.grid])
        lo = np.array(
            [
                [float(v - Decimal(h)) for v, h in zip(row, hrow, strict=True)]
                for row, hrow in zip(run.grid, hi.tolist(), strict=True)
            ]
        )
    meta = {
        "error_bound": float(bound),
        "digits": digits,
        "check_digits": check_digits,
        "steps": run.steps,
        "order": run.order,
        "seconds": seconds,
        "key": key,
    }
    if cache:
        buf = io.BytesIO()
        np.savez(buf, t=grid, hi=hi, lo=lo, meta=np.array(json.dumps(meta)))
        _store(key, buf.getvalue())
    return Reference(np.asarray(grid, float), hi, lo, **meta)


def _timed_solve(args) -> tuple[TaylorRun, float]:
    start = time.perf_counter()
    run = taylor_solve(*args)
    return run, time.perf_counter() - start


def references(
    jobs, digits=DIGITS, check_digits=CHECK_DIGITS, workers: int = 1, cache=True
) -> list[Reference]:
    """References for ``jobs`` = [(fast, x0, duration, grid), ...]: cached ones are read, the others
    solved at both precisions, spread over ``workers`` processes."""
    jobs = [(fast, np.asarray(x0, float), float(T), np.asarray(grid, float)) for fast, x0, T, grid in jobs]
    keys = [problem_key(f, x0, T, g, digits, check_digits) for f, x0, T, g in jobs]
    found = [_load(k) if cache else None for k in keys]
    todo = [i for i, ref in enumerate(found) if ref is None]
    tasks = [(*jobs[i], d) for i in todo for d in (digits, check_digits)]
    if workers > 1 and len(tasks) > 1:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        methods = multiprocessing.get_all_start_methods()
        context = multiprocessing.get_context("fork" if "fork" in methods else None)
        with ProcessPoolExecutor(min(workers, len(tasks)), mp_context=context) as pool:
            solved = list(pool.map(_timed_solve, tasks))
    else:
        solved = [_timed_solve(task) for task in tasks]
    for n, i in enumerate(todo):
        (run, t1), (check, t2) = solved[2 * n], solved[2 * n + 1]
        found[i] = _assemble(run, check, jobs[i][3], keys[i], t1 + t2, digits, check_digits, cache)
    return found


def reference(fast, x0, duration, grid, digits=DIGITS, check_digits=CHECK_DIGITS, cache=True) -> Reference:
    """The reference solution of ẋ = f(x), x(0) = x0 at ``grid``: from the cache, or computed and stored."""
    return references([(fast, x0, duration, grid)], digits, check_digits, workers=1, cache=cache)[0]


def relative_energy_error(fast, x0, states, digits: int = DIGITS) -> np.ndarray:
    """|E(x) − E(x0)| / (E(x0) − V_min) for each row of ``states``, evaluated in mpmath.

    The exact flow of a conservative system keeps E(x0): this needs no reference
    run, and evaluating E at ``digits`` removes the rounding of a double evaluation.
    """
    with mpmath.workdps(digits + GUARD_DIGITS):
        system = exact_system(fast)
        e0 = energy_above_minimum(system, [mpmath.mpf(float(v)) for v in x0])
        rows = np.atleast_2d(states)
        return np.array(
            [
                float(abs(energy_above_minimum(system, [mpmath.mpf(float(v)) for v in row]) - e0) / e0)
                for row in rows
            ]
        )


def energy_errors(fast, x0, states, final, screen: int = 3) -> tuple[float, float]:
    """(relative energy error at ``final``, its max over ``states`` and ``final``), both in mpmath.

    The rows are screened in double precision and only the ``screen`` worst rows
    (and the final state) are evaluated in mpmath: the double screening can
    misorder rows only when their errors differ by rounding (≈ 1e-16).
    """
    states = np.atleast_2d(np.asarray(states, float))
    system = float_system(fast)
    e0 = energy_above_minimum(system, [float(v) for v in x0])
    rough = np.abs(energy_above_minimum(system, list(states.T)) - e0)
    rows = np.vstack([states[np.argsort(rough)[-screen:]], final])
    exact = relative_energy_error(fast, x0, rows)
    return float(exact[-1]), float(np.max(exact))
