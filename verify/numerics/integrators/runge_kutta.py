"""One explicit Runge–Kutta step of any tableau (``tableaux``), on numpy arrays.

The stage sums are formed as h·(Σ_j a_ij k_j) and (h / d)·(Σ_i w_i k_i), left to right,
with the zero entries of the tableau skipped (they are no evaluation of 0·k, so an
infinite k_j never becomes a NaN through them).  For RK4 this is, operation for operation,
the classical method as it is usually written, x + h/6 (k₁ + 2k₂ + 2k₃ + k₄), with
x + ½h k₁ as h·(½ k₁) (the same rounding: a product by ½ is exact).
"""

from __future__ import annotations

from pendverify.numerics.integrators.tableaux import Tableau


def _weighted(coefficients, ks):
    """Σ c_j k_j over the nonzero c_j, left to right (1·k_j as k_j, which is exact); None when
    every c_j is zero."""
    total = None
    for c, k in zip(coefficients, ks, strict=False):
        if c:
            term = k if c == 1 else c * k
            total = term if total is None else total + term
    return total


def explicit_rk_step(f, t: float, x, h: float, tableau: Tableau, k1=None):
    """x at t + h from x at t, one step of ``tableau`` on ẋ = f(t, x); ``k1`` = f(t, x) if known."""
    ks = [f(t, x) if k1 is None else k1]
    for row, c in zip(tableau.a[1:], tableau.c[1:], strict=True):
        increment = _weighted(row, ks)
        ks.append(f(t + c * h, x if increment is None else x + h * increment))
    return x + (h / tableau.denominator) * _weighted(tableau.weights, ks)
