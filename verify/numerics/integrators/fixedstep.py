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

The two explicit methods are their tableaux (``pendverify.numerics.integrators.tableaux``):
``render_explicit_steps`` writes one step of each from its tableau into the generated
module, the one stepper's sums with the coefficients as literals.  The two implicit methods work in
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
from pendverify.numerics.integrators.tableaux import EULER, RK4, TABLEAUX

METHODS = {"euler": EULER.order, "symplectic_euler": 1, "implicit_midpoint": 2, "rk4": RK4.order}
MAX_ITERATIONS = 200
EPS = float(np.finfo(float).eps)
OK, NOT_CONVERGED, NOT_FINITE = 0, -3, -2

#: the explicit methods' stages; ``_run`` holds ``STAGE_ARRAYS`` stage arrays, K0 to K3
_EULER_STAGES, _RK4_STAGES = EULER.stages, RK4.stages
STAGE_ARRAYS = 4

# each generated module defines its model's
_rhs, _hamilton, _to_momentum = placeholder("_rhs"), placeholder("_hamilton"), placeholder("_to_momentum")
# and one step of each explicit tableau, written from it by ``render_explicit_steps``
_step_euler, _step_rk4 = placeholder("_step_euler"), placeholder("_step_rk4")


def render_explicit_steps() -> str:
    """numba source of ``_step_<name>(P, x, h, tmp, K0, …)`` for every tableau in ``TABLEAUX``: one
    step on x in place, its coefficients written in as literals (so the compiled step is
    straight-line code, as fast as the method written out), the sums those of
    ``runge_kutta.explicit_rk_step`` in the same order, zero entries left out.  Stage s goes
    into the array K<s>; ``_run`` holds ``STAGE_ARRAYS`` of them."""
    stage_arrays = ", ".join(f"K{s}" for s in range(STAGE_ARRAYS))
    chunks = []
    for name, tableau in TABLEAUX.items():
        if tableau.stages > STAGE_ARRAYS:
            raise ValueError(f"tableau {name}: {tableau.stages} stages, _run holds {STAGE_ARRAYS}")
        lines = [
            '@njit(cache=True, error_model="numpy")',
            f"def _step_{name}(P, x, h, tmp, {stage_arrays}):",
            f'    """One step of the {name} tableau (pendverify.numerics.integrators.tableaux)."""',
            "    nx = x.shape[0]",
        ]
        for stage, row in enumerate(tableau.a):
            terms = [f"{a!r} * K{j}[i]" for j, a in enumerate(row) if a]
            if terms:
                lines += ["    for i in range(nx):", f"        tmp[i] = x[i] + h * ({' + '.join(terms)})"]
            lines += [f"    _rhs(P, {'tmp' if terms else 'x'}, K{stage})"]
        terms = [f"{w!r} * K{j}[i]" for j, w in enumerate(tableau.weights) if w]
        lines += [
            "    for i in range(nx):",
            f"        x[i] += h / {tableau.denominator!r} * ({' + '.join(terms)})",
        ]
        chunks.append("\n".join(lines) + "\n")
    return "\n\n".join(chunks)


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
def _run(method, P, x0, h, steps, every):
    """Integrate ``steps`` steps of size h; states (q, q̇) every ``every`` steps, nfev, status."""
    nx = x0.shape[0]
    n = nx // 2
    out = np.empty((steps // every + 1, nx))
    x, y, tmp, z = x0.copy(), np.empty(nx), np.empty(nx), np.empty(nx)
    k1, k2 = np.empty(nx), np.empty(nx)
    K0, K1, K2, K3 = np.empty(nx), np.empty(nx), np.empty(nx), np.empty(nx)  # STAGE_ARRAYS stages
    out[0] = x0
    _to_momentum(P, x, y)
    nfev, status = 0, OK
    for s in range(1, steps + 1):
        if method == 0:  # explicit Euler
            _step_euler(P, x, h, tmp, K0, K1, K2, K3)
            nfev += _EULER_STAGES
        elif method == 3:  # classical RK4
            _step_rk4(P, x, h, tmp, K0, K1, K2, K3)
            nfev += _RK4_STAGES
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
