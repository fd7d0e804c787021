"""Compiled fixed-step integrators, for the work-precision study (orders 1, 1, 2 and 4).

All run on the functions generated from the model (``pendverify.numerics.generate``:
same parameters, same force law τ = B (u0 − K x) − D q̇), compiled with numba so
that a million Euler steps cost milliseconds and the methods are compared on
equal terms.  The functions below are templates (``numerics.codegen.templates``),
copied into each model's generated module, where ``_run`` calls that model's
``_rhs`` and ``_hamilton`` inlined; ``fixedstep_runner.integrate_fixed`` runs the
module's copy.  This module holds the templates and their constants only.

=====================  =====  ===========================================================
method                 order  one step, h
=====================  =====  ===========================================================
``euler``              1      x ← x + h f(x), on x = (q, q̇) (tableau ``EULER``)
``symplectic_euler``   1      p ← p + h ṗ(q, p_new) (implicit in p),  q ← q + h M(q)⁻¹ p_new
``implicit_midpoint``  2      y ← y + h g((y + y_new)/2) on y = (q, p) (implicit)
``rk4``                4      the classical Runge–Kutta method on x = (q, q̇) (``RK4``)
=====================  =====  ===========================================================

The two explicit methods are their tableaux (``pendverify.numerics.integrators.tableaux``)
run by ``_explicit_rk``, the one stepper compiled.  The two implicit methods work in
canonical coordinates y = (q, p), p = M(q) q̇, where they are symplectic for the
conservative problems (so the energy error stays bounded instead of drifting); with
friction or feedback they remain
consistent methods of the same order.  The vector field in these coordinates is
the generated ``_hamilton`` (``pendverify.numerics.codegen.compiled``, which derives it):

    q̇ = M(q)⁻¹ p,     ṗ = Ṁ(q, q̇) q̇ − (C(q, q̇) q̇ + H(q)) + τ(q, q̇),

with Ṁ q̇ = Σ_k q̇_k (∂M/∂q_k) q̇, which is ½ q̇ᵀ (∂M/∂q) q̇ − ∂V/∂q + τ when the
model's C is Christoffel-consistent and H = ∂V/∂q.

Their implicit equations are solved by fixed-point iteration to rounding level
(|Δ| ≤ 4ε (1 + |y|)), at most ``MAX_ITERATIONS``; a step that does not converge
marks the run as failed.  ``nfev`` counts evaluations of f or g.
"""

from __future__ import annotations

import math

import numpy as np

from pendverify.numerics.codegen.templates import placeholder, template
from pendverify.numerics.integrators.tableaux import EULER, RK4

METHODS = {"euler": EULER.order, "symplectic_euler": 1, "implicit_midpoint": 2, "rk4": RK4.order}
MAX_ITERATIONS = 200
EPS = float(np.finfo(float).eps)
OK, NOT_CONVERGED, NOT_FINITE = 0, -3, -2

# the explicit methods' tableaux, as the arrays ``_explicit_rk`` reads (copied as exact literals)
_EULER_A, _EULER_W, _EULER_D = EULER.arrays()
_RK4_A, _RK4_W, _RK4_D = RK4.arrays()

# each generated module defines its model's
_rhs, _hamilton, _to_momentum = placeholder("_rhs"), placeholder("_hamilton"), placeholder("_to_momentum")


@template()
def _to_velocity(P, y, x, tmp):
    """x = (q, M(q)⁻¹ p) from y = (q, p)."""
    n = y.shape[0] // 2
    _hamilton(P, y, tmp)
    for i in range(n):
        x[i] = y[i]
        x[n + i] = tmp[i]


@template()
def _converged(delta, y):
    big = 0.0
    for i in range(y.shape[0]):
        big = max(big, abs(y[i]))
    return delta <= 4.0 * EPS * (1.0 + big)


# --- the methods --------------------------------------------------------------------------------
@template()
def _explicit_rk(P, x, h, A, W, d, K, tmp, f):
    """One step of the tableau (A, W / d) on x, in place: ``runge_kutta.explicit_rk_step`` compiled,
    the same sums in the same order.  K holds the stages; f goes to the scratch ``f`` and is
    copied (a row view K[s] would cost a reference count per stage)."""
    nx = x.shape[0]
    for s in range(W.shape[0]):
        for i in range(nx):
            acc = 0.0
            for j in range(s):
                if A[s, j] != 0.0:
                    acc += A[s, j] * K[j, i]
            tmp[i] = x[i] + h * acc
        _rhs(P, tmp, f)
        for i in range(nx):
            K[s, i] = f[i]
    for i in range(nx):
        acc = 0.0
        for j in range(W.shape[0]):
            if W[j] != 0.0:
                acc += W[j] * K[j, i]
        x[i] += h / d * acc


@template()
def _run(method, P, x0, h, steps, every):
    """Integrate ``steps`` steps of size h; states (q, q̇) every ``every`` steps, nfev, status."""
    nx = x0.shape[0]
    n = nx // 2
    out = np.empty((steps // every + 1, nx))
    x, y, tmp, z = x0.copy(), np.empty(nx), np.empty(nx), np.empty(nx)
    k1, k2 = np.empty(nx), np.empty(nx)
    K = np.empty((max(_EULER_W.shape[0], _RK4_W.shape[0]), nx))  # the explicit methods' stages
    out[0] = x0
    _to_momentum(P, x, y)
    nfev, status = 0, OK
    for s in range(1, steps + 1):
        if method == 0:  # explicit Euler
            _explicit_rk(P, x, h, _EULER_A, _EULER_W, _EULER_D, K, tmp, k1)
            nfev += _EULER_W.shape[0]
        elif method == 3:  # classical RK4
            _explicit_rk(P, x, h, _RK4_A, _RK4_W, _RK4_D, K, tmp, k1)
            nfev += _RK4_W.shape[0]
        else:
            # z: the unknown (p_new for symplectic Euler, y_new for implicit midpoint)
            _hamilton(P, y, k1)
            nfev += 1
            for i in range(nx):
                z[i] = y[i] + h * k1[i]
            done = False
            for _ in range(MAX_ITERATIONS):
                for i in range(nx):
                    if method == 2:
                        tmp[i] = 0.5 * (y[i] + z[i])
                    else:
                        tmp[i] = y[i] if i < n else z[i]
                _hamilton(P, tmp, k2)
                nfev += 1
                delta = 0.0
                for i in range(nx):
                    if method == 1 and i < n:
                        continue
                    new = y[i] + h * k2[i]
                    delta = max(delta, abs(new - z[i]))
                    z[i] = new
                if _converged(delta, z):
                    done = True
                    break
            if not done:
                status = NOT_CONVERGED
            if method == 1:  # q ← q + h M(q)⁻¹ p_new, with the last evaluation at (q_n, p_new)
                for i in range(n):
                    tmp[i] = y[i]
                    tmp[n + i] = z[n + i]
                _hamilton(P, tmp, k2)
                nfev += 1
                for i in range(n):
                    y[i] += h * k2[i]
                    y[n + i] = z[n + i]
            else:
                for i in range(nx):
                    y[i] = z[i]
            _to_velocity(P, y, x, tmp)
        if s % every == 0:
            out[s // every] = x
        if not math.isfinite(x[0]) or not math.isfinite(x[n]):
            status = NOT_FINITE
        if status != OK:
            break
    return out, nfev, status


#: the id ``_run`` takes for each method
METHOD_IDS = {"euler": 0, "symplectic_euler": 1, "implicit_midpoint": 2, "rk4": 3}
