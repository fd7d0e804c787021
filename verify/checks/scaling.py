"""Scaled coordinates and the sizes of the terms a check's tolerance is measured against.

Every comparison is made in diagonally scaled coordinates z_i = √S_i·θ_i, with
S_i the model's inertia scale of coordinate i (``diagonal_scale``), so that a
cart in kg and a rod in kg·m² are judged on one footing and raw κ(M), which
mostly reflects units, does not inflate tolerances.  In these coordinates
M̃ = S^{-½} M S^{-½} has entries of order one (``scaled_matrix(M, weights)``, with
weights_i = 1/√S_i), forces scale by S^{-½} (weights·f) and accelerations by S^{½} (a/weights).

Rates are measured in 1/s (``rate_scale``): angular rates as they are, linear rates
over a radius of gyration.  The checks (``pendverify.checks.quantities``) build each
state's *scale* from these.

The functions ending in ``_of`` (and ``scaled_matrix``, ``mv``, ``total``, ``norms2``)
take a batch's arrays (leading batch axes): elementwise arithmetic, reductions over the
last axes and one BLAS/LAPACK call per state, so no state's figure depends on the others.
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic.numeric_values import model_value
from pendverify.checks.spectral import norms2


def weights_of(S):
    """1/√S, the scaled coordinates' weights (S with optional leading batch axes)."""
    return 1.0 / np.sqrt(S)


def weights_at(model, q):
    return weights_of(model_value(model, "diagonal_scale", q))


def scaled_matrix(A, weights):
    """A·(weights weightsᵀ) (= A * np.outer(weights, weights) for one state; leading batch axes allowed)."""
    return A * (weights[..., :, None] * weights[..., None, :])


def mv(A, x):
    """A·x as NumPy multiplies one state's matrix and vector (one BLAS call per state in a batch)."""
    return (A @ x[..., None])[..., 0]


def total(x):
    """Σ x_i over the last axis (one state's sum, or each state's of a batch, the same bits)."""
    return np.sum(x, axis=-1)


def rates_of(S, v, angular):
    """Largest rate in 1/s per state: angular rates as they are, linear rates over a natural length."""
    angular = np.asarray(angular, dtype=bool)
    rates = np.abs(v).astype(float)
    if np.any(~angular) and np.any(angular):
        rates[..., ~angular] /= np.sqrt(np.min(S[..., angular], axis=-1, keepdims=True) / S[..., ~angular])
    return np.max(rates, axis=-1, initial=0.0)


def rate_scale(model, q, v) -> float:
    """Largest rate in 1/s: angular rates as they are, linear rates over a natural length.

    Pinocchio's recursions carry body velocities that include linear ones (the
    cart's), so they set the size of the intermediate terms too.  The length for
    a linear coordinate i is ℓ_i = √(min S_angular / S_i), a radius of gyration.
    """
    return float(rates_of(model_value(model, "diagonal_scale", q), v, model.angular))


def norm2(A) -> float:
    """‖A‖₂ of one matrix (``checks.spectral``)."""
    return float(norms2(A))


def force_scale_of(rate, v, weights, g_scale, B, W, D, u, w_in):
    """Size of the generalized forces acting, in scaled units (sum of |terms|), per state."""
    coriolis = rate * total(np.abs(v / weights))
    gravity = np.max(weights * g_scale, axis=-1)
    applied = weights * (mv(np.abs(B), np.abs(u)) + mv(np.abs(W), np.abs(w_in)) + mv(np.abs(D), np.abs(v)))
    return coriolis + gravity + np.max(applied, axis=-1, initial=0.0)


def damping_rate_of(D, weights):
    """max |D̃| in 1/s per state: a hand C with friction inside (C + D) rounds at this size."""
    return np.max(np.abs(scaled_matrix(D, weights)), axis=(-2, -1), initial=0.0)
