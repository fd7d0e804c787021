"""Compiled fixed-step integrators, for the work-precision study (orders 1, 1, 2 and 4).

All run on the compiled closed forms of ``pendverify.numerics.kernels`` (same constants, same
force law τ = B (u0 − K x) − D q̇), compiled with numba so that a million
Euler steps cost milliseconds and the methods are compared on equal terms.

=====================  =====  ===========================================================
method                 order  one step, h
=====================  =====  ===========================================================
``euler``              1      x ← x + h f(x), on x = (q, q̇)
``symplectic_euler``   1      p ← p + h ṗ(q, p_new) (implicit in p),  q ← q + h M(q)⁻¹ p_new
``implicit_midpoint``  2      y ← y + h g((y + y_new)/2) on y = (q, p) (implicit)
``rk4``                4      the classical Runge–Kutta method on x = (q, q̇)
=====================  =====  ===========================================================

The two implicit methods work in canonical coordinates y = (q, p), p = M(q) q̇,
where they are symplectic for the conservative problems (so the energy error
stays bounded instead of drifting); with friction or feedback they remain
consistent methods of the same order.  The Hamiltonian vector field with forces
is

    q̇ = M(q)⁻¹ p,     ṗ = ½ q̇ᵀ (∂M/∂q) q̇ − ∂V/∂q + τ(q, q̇),

    double pendulum:  ½ q̇ᵀ ∂M/∂θ2 q̇ = −β sin θ2 (θ̇1² + θ̇1 θ̇2),  ∂M/∂θ1 = 0;
    cart:             ½ ẏᵀ ∂M/∂θ1 ẏ = −l1 (m1+m2) sin θ1 q̇ θ̇1 − l1 l2 m2 sin(θ1−θ2) θ̇1 θ̇2,
                      ½ ẏᵀ ∂M/∂θ2 ẏ = −m2 l2 sin θ2 q̇ θ̇2 + l1 l2 m2 sin(θ1−θ2) θ̇1 θ̇2.

Their implicit equations are solved by fixed-point iteration to rounding level
(|Δ| ≤ 4ε (1 + |y|)), at most ``MAX_ITERATIONS``; a step that does not converge
marks the run as failed.  ``nfev`` counts evaluations of f or g.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from pendverify.numerics.kernels import (
    C0,
    FastSystem,
    _cart_mass,
    _cart_solve,
    _cart_tau,
    _dp_tau,
    _rhs,
    cache_allowed,
)

#: pendverify.numerics.kernels.source_stamp() of the kernels inlined here (see cache_allowed).
KERNELS_STAMP = "03b2c66be689d7fd"
CACHE = cache_allowed(KERNELS_STAMP, __name__)

METHODS = {"euler": 1, "symplectic_euler": 1, "implicit_midpoint": 2, "rk4": 4}
MAX_ITERATIONS = 200
EPS = float(np.finfo(float).eps)
OK, NOT_CONVERGED, NOT_FINITE = 0, -3, -2


# --- canonical coordinates ------------------------------------------------------------------
@njit(cache=CACHE, error_model="numpy")
def _hamilton(P, y, out):
    """(q̇, ṗ) at y = (q, p); returns nothing, writes ``out``."""
    if P[0] == 0.0:
        a, b, d, g1, g2 = P[C0], P[C0 + 1], P[C0 + 2], P[C0 + 3], P[C0 + 4]
        s2, c2 = math.sin(y[1]), math.cos(y[1])
        c1, c12 = math.cos(y[0]), math.cos(y[0] + y[1])
        m00, m01 = a + 2.0 * b * c2, d + b * c2
        det = a * d - d * d - (b * c2) * (b * c2)
        v0 = (d * y[2] - m01 * y[3]) / det
        v1 = (-m01 * y[2] + m00 * y[3]) / det
        ti0, ti1, td0, td1 = _dp_tau(P, y[0], y[1], v0, v1)
        out[0], out[1] = v0, v1
        out[2] = -(g1 * c1 + g2 * c12) + ti0 + td0
        out[3] = -b * s2 * (v0 * v0 + v0 * v1) - g2 * c12 + ti1 + td1
    else:
        m1, m2, l1, l2, g = P[C0 + 1], P[C0 + 2], P[C0 + 3], P[C0 + 4], P[C0 + 5]
        m12, k = m1 + m2, l1 * l2 * m2
        s1, c1 = math.sin(y[1]), math.cos(y[1])
        s2, c2 = math.sin(y[2]), math.cos(y[2])
        s12, c12 = math.sin(y[1] - y[2]), math.cos(y[1] - y[2])
        v0, v1, v2 = _cart_solve(P, s1, c1, c2, s12, c12, y[3], y[4], y[5])
        ti0, ti1, ti2, td0, td1, td2 = _cart_tau(P, y[0], y[1], y[2], v0, v1, v2)
        out[0], out[1], out[2] = v0, v1, v2
        out[3] = ti0 + td0
        out[4] = -l1 * m12 * s1 * v0 * v1 - k * s12 * v1 * v2 + g * m12 * l1 * s1 + ti1 + td1
        out[5] = -m2 * l2 * s2 * v0 * v2 + k * s12 * v1 * v2 + g * m2 * l2 * s2 + ti2 + td2


@njit(cache=CACHE, error_model="numpy")
def _to_momentum(P, x, y):
    """y = (q, M(q) q̇) from x = (q, q̇)."""
    if P[0] == 0.0:
        a, b, d = P[C0], P[C0 + 1], P[C0 + 2]
        c2 = math.cos(x[1])
        y[0], y[1] = x[0], x[1]
        y[2] = (a + 2.0 * b * c2) * x[2] + (d + b * c2) * x[3]
        y[3] = (d + b * c2) * x[2] + d * x[3]
    else:
        p00, p01, p02, p11, p12, p22 = _cart_mass(P, math.cos(x[1]), math.cos(x[2]), math.cos(x[1] - x[2]))
        y[0], y[1], y[2] = x[0], x[1], x[2]
        y[3] = p00 * x[3] + p01 * x[4] + p02 * x[5]
        y[4] = p01 * x[3] + p11 * x[4] + p12 * x[5]
        y[5] = p02 * x[3] + p12 * x[4] + p22 * x[5]


@njit(cache=CACHE, error_model="numpy")
def _to_velocity(P, y, x, tmp):
    """x = (q, M(q)⁻¹ p) from y = (q, p)."""
    n = y.shape[0] // 2
    _hamilton(P, y, tmp)
    for i in range(n):
        x[i] = y[i]
        x[n + i] = tmp[i]


@njit(cache=CACHE, error_model="numpy")
def _converged(delta, y):
    big = 0.0
    for i in range(y.shape[0]):
        big = max(big, abs(y[i]))
    return delta <= 4.0 * EPS * (1.0 + big)


# --- the methods --------------------------------------------------------------------------------
@njit(cache=CACHE, error_model="numpy")
def _run(method, P, x0, h, steps, every):
    """Integrate ``steps`` steps of size h; states (q, q̇) every ``every`` steps, nfev, status."""
    nx = x0.shape[0]
    n = nx // 2
    out = np.empty((steps // every + 1, nx))
    x, y, tmp, z = x0.copy(), np.empty(nx), np.empty(nx), np.empty(nx)
    k1, k2, k3, k4 = np.empty(nx), np.empty(nx), np.empty(nx), np.empty(nx)
    out[0] = x0
    _to_momentum(P, x, y)
    nfev, status = 0, OK
    for s in range(1, steps + 1):
        if method == 0:  # explicit Euler
            _rhs(P, x, k1)
            for i in range(nx):
                x[i] += h * k1[i]
            nfev += 1
        elif method == 3:  # classical RK4
            _rhs(P, x, k1)
            for i in range(nx):
                tmp[i] = x[i] + 0.5 * h * k1[i]
            _rhs(P, tmp, k2)
            for i in range(nx):
                tmp[i] = x[i] + 0.5 * h * k2[i]
            _rhs(P, tmp, k3)
            for i in range(nx):
                tmp[i] = x[i] + h * k3[i]
            _rhs(P, tmp, k4)
            for i in range(nx):
                x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
            nfev += 4
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


_IDS = {"euler": 0, "symplectic_euler": 1, "implicit_midpoint": 2, "rk4": 3}


def integrate_fixed(method: str, system: FastSystem, x0, duration: float, steps: int, every: int = 1):
    """States (q, q̇) at t = k·every·h, h = duration / steps; plus nfev and whether it succeeded.

    ``steps`` must be a multiple of ``every``.  A failed run (an implicit step
    that did not converge, or a non-finite state) returns ok = False.
    """
    if method not in _IDS:
        raise ValueError(f"unknown fixed-step method {method!r}; expected one of {', '.join(_IDS)}")
    if steps % every:
        raise ValueError(f"steps ({steps}) must be a multiple of every ({every})")
    x0 = np.ascontiguousarray(x0, dtype=float)
    out, nfev, status = _run(_IDS[method], system.packed(), x0, duration / steps, steps, every)
    return out, int(nfev), status == OK


def warm_up() -> float:
    """Compile (or load from numba's cache) the fixed-step kernel; the seconds it took."""
    import time

    from pendverify.analytic import DoublePendulum
    from pendverify.analytic.params import default_parameter_file, load_parameter_file

    start = time.perf_counter()
    model = DoublePendulum(load_parameter_file(default_parameter_file(DoublePendulum.name))[2])
    integrate_fixed("rk4", FastSystem.from_model(model), np.array([0.1, 0.2, 0.0, 0.0]), 0.01, 2)
    return time.perf_counter() - start
