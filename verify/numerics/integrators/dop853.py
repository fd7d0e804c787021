"""scipy's DOP853, step for step, as numba templates for each model's generated module.

Same Butcher tableau (read from scipy), same initial step (Hairer's rule), same
error norm (the 5th- and 3rd-order estimates combined as in scipy), SAFETY 0.9,
step factors in [0.2, 10], with scipy's 7th-order dense output when output
times are asked for (3 extra evaluations per step that contains one, as scipy
counts them).  The functions are *templates* (``pendverify.numerics.codegen.
templates``): copied verbatim into each model's generated module, where they call
that model's ``_rhs_t`` (inlined where short: ``codegen.compiled``) and are compiled and
cached with it (``pendverify.numerics.integrators.dop853_runner.integrate`` runs the copy).
They take one packed float array P (``GeneratedSystem.packed``).  Every evaluation is at its stage's
time, t + c_s·h as scipy has it, so a system with time-varying forcing (a sine
input, band-limited noise: ``pendverify.numerics.generate``) takes the steps scipy
takes on the same right-hand side; without forcing, t is read by nothing.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate._ivp import dop853_coefficients as _coef

from pendverify.numerics.codegen.templates import placeholder, template

_rhs_t = placeholder("_rhs_t")  # each generated module defines its model's

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
OK, STEP_TOO_SMALL, NOT_FINITE, TOO_MANY_STEPS = 0, -1, -2, -3
#: accepted steps after which a run stops (TOO_MANY_STEPS): a work bound, not an accuracy one.  A
#: step is 12 evaluations of the right-hand side (about 1 µs each for these models), so this is
#: about a minute of work; a stiff run near t = 0, where 10 ulp of t is ~1e-323 and the step-size
#: floor never bites, would otherwise creep towards t_end for ever (the recheck of a forged
#: certificate in the fuzz tests ran for over 15 minutes in this loop).
MAX_STEPS = 5_000_000


# --- DOP853 ------------------------------------------------------------------------------
@template()
def _rms(x):
    s = 0.0
    for i in range(x.shape[0]):
        s += x[i] * x[i]
    return math.sqrt(s / x.shape[0])


@template()
def _initial_step(P, t0, y0, f0, t_end, rtol, atol, tmp, f1):
    """scipy's ``select_initial_step`` for an error estimator of order 7 (from t0, forward)."""
    n = y0.shape[0]
    length = abs(t_end - t0)
    scale = atol + np.abs(y0) * rtol
    d0, d1 = _rms(y0 / scale), _rms(f0 / scale)
    h0 = 1e-6 if (d0 < 1e-5 or d1 < 1e-5) else 0.01 * d0 / d1
    h0 = min(h0, length)
    for i in range(n):
        tmp[i] = y0[i] + h0 * f0[i]
    _rhs_t(P, t0 + h0, tmp, f1)
    d2 = _rms((f1 - f0) / scale) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, length)


@template()
def _stages(P, t, y, h, K, first, last, x, f):
    """K[s] = f(t + C[s] h, y + h Σ_j A[s, j] K[j]) for s in [first, last).

    f goes to the scratch ``f`` and is copied: a row view K[s] would cost a
    reference count per stage, more than the copy.  Callers pass ``first`` and ``last`` as
    ``np.int64``: numba types an integer constant argument by its value (``Literal[int](12)``),
    so the two call sites' constants made two compilations of this function, the right-hand
    side inlined in each (measured: DOP853's first compilation 7.2 → 6.5 s for the double
    pendulum, 8.5 → 6.9 s for the triple; its runs take the same time)."""
    n = y.shape[0]
    for s in range(first, last):
        for i in range(n):
            acc = 0.0
            for j in range(s):
                acc += _A[s, j] * K[j, i]
            x[i] = y[i] + acc * h
        _rhs_t(P, t + _C[s] * h, x, f)
        for i in range(n):
            K[s, i] = f[i]


@template()
def _dense(P, t_old, y_old, y_new, h, K, x, f, F):
    """scipy's DOP853 interpolant coefficients F (7 × n) for the step just taken."""
    n = y_old.shape[0]
    _stages(P, t_old, y_old, h, K, np.int64(_NS + 1), np.int64(16), x, f)
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
    _rhs_t(P, 0.0, y, f)
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
            _stages(P, t, y, h, K, np.int64(1), np.int64(_NS), tmp, fs)
            for i in range(n):
                acc = 0.0
                for j in range(_NS):
                    acc += _B[j] * K[j, i]
                y_new[i] = y[i] + h * acc
            _rhs_t(P, t + h, y_new, fs)
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
            _dense(P, t, y, y_new, h, K, tmp, fs, F)
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
        if steps >= MAX_STEPS and t < t_end:
            status = TOO_MANY_STEPS
            break
    return nfev, steps, rejected, status, nrec
