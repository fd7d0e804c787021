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
* ``_dop853``: scipy's DOP853 reproduced step for step — same Butcher tableau
  (read from scipy), same initial step (Hairer's rule), same error norm (the 5th-
  and 3rd-order estimates combined as in scipy), SAFETY 0.9, factors in
  [0.2, 10] — with scipy's 7th-order dense output when output times are asked
  for (3 extra evaluations per step that contains one, as scipy counts them).
  The functions below are *templates* (``pendverify.numerics.codegen.templates``):
  they are copied into each model's generated module, where they call that
  model's ``_rhs`` inlined and are compiled and cached with it; ``integrate``
  runs the generated module's copy.
* ``integrate_ensemble``: many initial states at once, one compiled DOP853 per
  state with its own step control; the kernel releases the GIL, so a pool of
  threads runs them in parallel (numba's ``parallel=True`` took ≈ 20 s more to
  compile, for no measurable gain on 2 cores).

Accuracy.  The compiled stepper takes the steps scipy's DOP853 takes at the same
rtol and atol: the same nfev and step count, each step equal to scipy's step from
the same state within the rounding of its stage sums (computed in another order),
step sizes within the jitter that rounding of the error estimate explains (up to
≈ 1e-7 relative; on a chaotic trajectory the final states of the two then differ
by a change of truncation error, ≈ 1e-10 at rtol 1e-5); ``tests/test_fastpath.py``
derives each bound.  So the fast path is as accurate as scipy's DOP853.
Against the high-precision references (``pendverify.numerics.reference``), the tests
check a final-state error ≤ 100 · rtol · (1 + ‖x‖∞) for rtol ≤ 1e-8 over
T ≤ 2 s on the benchmark problems, and ≤ 1e-10 at rtol = atol = 1e-11 on the
chaotic pendulum over 2 s.

The fast path is the model's closed form; that the closed form agrees with
Pinocchio is what ``pendverify check`` establishes (ε-level, every check).
``simulate`` runs a scene — a seed's or a plug-in model's — on the fast path and
evaluates the *same* invariants as ``pendverify.simulation.simulate``
(``pendverify.simulation.invariants``), on the fast path's own steps, with the same
adaptive bound.

JIT.  The generated functions are compiled on first use and cached on disk (numba
``cache=True``, beside the generated module); ``warm_up(systems)`` triggers compilation
and returns the seconds it took, so that benchmarks report it separately from
per-run timings.
"""

from __future__ import annotations

import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _coef

from pendverify.errors import FastPathError
from pendverify.numerics.codegen.templates import placeholder, template
from pendverify.numerics.generate import GeneratedSystem

__all__ = ["FastPathError", "FastResult", "FastRun", "integrate", "integrate_ensemble", "simulate", "warm_up"]

_rhs = placeholder("_rhs")  # each generated module defines its model's

# --- DOP853 tableau, as scipy has it ----------------------------------------------------
_NS = _coef.N_STAGES  # 12 stages, then f(t + h, y_new) as the 13th row of K
_A = np.ascontiguousarray(_coef.A)
_B = np.ascontiguousarray(_coef.B)
_C = np.ascontiguousarray(_coef.C)
_E3 = np.ascontiguousarray(_coef.E3)
_E5 = np.ascontiguousarray(_coef.E5)
_DD = np.ascontiguousarray(_coef.D)
SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
ERROR_EXPONENT = -1.0 / 8.0  # error estimator of order 7

# status codes of the stepper
OK, STEP_TOO_SMALL, NOT_FINITE = 0, -1, -2


# --- DOP853 ------------------------------------------------------------------------------
@template()
def _rms(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i] * x[i]
    return math.sqrt(s / x.shape[0])


@template()
def _initial_step(P, t0, y0, f0, t_end, rtol, atol, tmp, f1):
    """scipy's ``select_initial_step`` for an error estimator of order 7."""
    n = y0.shape[0]
    length = abs(t_end - t0)
    scale = atol + np.abs(y0) * rtol
    d0, d1 = _rms(y0 / scale), _rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, length)
    for i in range(n):
        tmp[i] = y0[i] + h0 * f0[i]
    _rhs(P, tmp, f1)
    d2 = _rms((f1 - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, length)


@template()
def _stages(P, y, h, K, first, last, x, f):
    """K[s] = f(y + h Σ_j A[s, j] K[j]) for s in [first, last).

    f goes to the scratch ``f`` and is copied: a row view K[s] would cost a
    reference count per stage, more than the copy."""
    n = y.shape[0]
    for s in range(first, last):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += _A[s, j] * K[j, i]
            x[i] = y[i] + acc * h
        _rhs(P, x, f)
        for i in range(n):
            K[s, i] = f[i]


@template()
def _dense(P, y_old, y_new, h, K, x, f, F):
    """scipy's DOP853 interpolant coefficients F (7 × n) for the step just taken."""
    n = y_old.shape[0]
    _stages(P, y_old, h, K, _NS + 1, 16, x, f)
    for i in range(n):
        dy = y_new[i] - y_old[i]
        F[0, i] = dy
        F[1, i] = h * K[0, i] - dy
        F[2, i] = 2.0 * dy - h * (K[_NS, i] + K[0, i])
        for r in range(4):
            acc = 0.0
            for j in range(16):
                acc += _DD[r, j] * K[j, i]
            F[3 + r, i] = h * acc


@template()
def _interpolate(F, y_old, xi, out):
    for i in range(y_old.shape[0]):
        y = 0.0
        for k in range(7):
            y += F[6 - k, i]
            y *= xi if k % 2 == 0 else 1.0 - xi
        out[i] = y + y_old[i]


@template()
def _error_norm(y, y_new, K, h_abs, rtol, atol):
    """scipy's DOP853 error norm: the 5th-order estimate, damped by the 3rd-order one."""
    n = y.shape[0]
    e5 = e3 = 0.0
    for i in range(n):
        sc = atol + max(abs(y[i]), abs(y_new[i])) * rtol
        a5 = a3 = 0.0
        for j in range(_NS + 1):
            a5 += _E5[j] * K[j, i]
            a3 += _E3[j] * K[j, i]
        e5 += (a5 / sc) ** 2
        e3 += (a3 / sc) ** 2
    if e5 == 0.0 and e3 == 0.0:
        return 0.0
    return h_abs * e5 / math.sqrt((e5 + 0.01 * e3) * n)


@template(nogil=True)
def _dop853(P, y, t_end, rtol, atol, t_out, out, st, sx):
    """Integrate y (in place) from t = 0 to t_end.

    Writes the states at ``t_out`` into ``out`` and, while there is room, every
    accepted step (t = 0 first) into ``st``, ``sx``.  Returns (nfev, steps,
    rejected, status, rows of st/sx that were needed).
    """
    n = y.shape[0]
    K = np.empty((16, n))
    F = np.empty((7, n))
    tmp, y_new, f, fs = np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    cap = st.shape[0]
    if cap > 0:
        st[0] = 0.0
        sx[0] = y
    nrec = 1
    _rhs(P, y, f)
    h_abs = _initial_step(P, 0.0, y, f, t_end, rtol, atol, tmp, fs)
    nfev = 2
    k_out = 0
    while k_out < t_out.shape[0] and t_out[k_out] <= 0.0:
        out[k_out] = y
        k_out += 1
    t, steps, rejected, status = 0.0, 0, 0, OK
    while t < t_end:
        min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
        if h_abs < min_step:
            h_abs = min_step
        accepted, was_rejected = False, False
        while not accepted:
            if h_abs < min_step:
                status = STEP_TOO_SMALL
                break
            t_new = t + h_abs
            if t_new > t_end:
                t_new = t_end
            h = t_new - t
            h_abs = abs(h)
            for i in range(n):
                K[0, i] = f[i]
            _stages(P, y, h, K, 1, _NS, tmp, fs)
            for i in range(n):
                acc = 0.0
                for j in range(_NS):
                    acc += _B[j] * K[j, i]
                y_new[i] = y[i] + h * acc
            _rhs(P, y_new, fs)
            for i in range(n):
                K[_NS, i] = fs[i]
            nfev += _NS
            err = _error_norm(y, y_new, K, h_abs, rtol, atol)
            if not math.isfinite(err):
                status = NOT_FINITE
                break
            if err < 1.0:
                factor = MAX_FACTOR if err == 0.0 else min(MAX_FACTOR, SAFETY * err**ERROR_EXPONENT)
                if was_rejected:
                    factor = min(1.0, factor)
                h_abs *= factor
                accepted = True
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * err**ERROR_EXPONENT)
                was_rejected = True
                rejected += 1
        if status != OK:
            break
        if k_out < t_out.shape[0] and t_out[k_out] <= t_new:
            _dense(P, y, y_new, h, K, tmp, fs, F)
            nfev += 3
            while k_out < t_out.shape[0] and t_out[k_out] <= t_new:
                _interpolate(F, y, (t_out[k_out] - t) / h, out[k_out])
                k_out += 1
        t = t_new
        for i in range(n):
            y[i] = y_new[i]
            f[i] = K[_NS, i]
        steps += 1
        if nrec < cap:
            st[nrec] = t
            sx[nrec] = y
        nrec += 1
    return nfev, steps, rejected, status, nrec


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
    if status != OK:
        why = "step size fell below 10 ulp" if status == STEP_TOO_SMALL else "non-finite error estimate"
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


def distinct_modules(systems) -> list[GeneratedSystem]:
    """The first of ``systems`` for each generated module (compilation is per module)."""
    seen = {}
    for system in systems:
        seen.setdefault(id(system.module), system)
    return list(seen.values())


# --- scenes on the fast path ----------------------------------------------------------------
@dataclass
class FastRun:
    """A scene run on the fast path: samples, the integrator's own steps and the invariant results."""

    scene: object
    dynamics: object
    system: GeneratedSystem
    result: FastResult
    t: np.ndarray
    x: np.ndarray  # samples (q, q̇, W_in, W_diss)
    invariants: list

    @property
    def passed(self) -> bool:
        return all(i.passed for i in self.invariants)


def simulate(scene) -> FastRun:
    """Run a scene with the compiled DOP853 (at the scene's rtol, atol) and check its invariants.

    Any model a scene names, seed or plug-in file: its module is generated on first use.

    The invariants are ``pendverify.simulation.invariants``' — the energy drift, dissipation
    or work–energy balance with the bound an adaptive method's tolerance implies —
    evaluated on the fast path's accepted steps, with the scene's closed-form
    ``Dynamics`` for E, ∇E and the energy scale.
    """
    from pendverify.simulation.dynamics import build_dynamics
    from pendverify.simulation.invariants import adaptive_bound, energy_scale, evaluate

    if not scene.integrator.adaptive:
        raise FastPathError(
            scene.source, "integrator.method", scene.integrator.method, "an adaptive method (rtol, atol)"
        )
    dyn = build_dynamics(scene, "closed_form")
    system = GeneratedSystem.from_dynamics(dyn, scene.source)
    x0 = np.concatenate([scene.q0, scene.v0, [0.0, 0.0]])
    n_samples = int(np.floor(scene.duration * scene.sample_rate + 1e-9)) + 1
    t = np.arange(n_samples) / scene.sample_rate
    res = integrate(system, x0, scene.duration, scene.integrator.rtol, scene.integrator.atol, t, record=True)
    scale = energy_scale(dyn, res.steps_x)
    bound = adaptive_bound(dyn, res.steps_x, scene.integrator, scale)
    invariants = evaluate(dyn, scene, res.steps_t, res.steps_x, bound, scale)
    return FastRun(scene, dyn, system, res, t, res.dense, invariants)
