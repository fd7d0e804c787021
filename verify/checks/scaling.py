"""Scaled coordinates and the sizes of the terms a check's tolerance is measured against.

Every comparison is made in diagonally scaled coordinates z_i = √S_i·θ_i, with
S_i the model's inertia scale of coordinate i (``diagonal_scale``), so that a
cart in kg and a rod in kg·m² are judged on one footing and raw κ(M), which
mostly reflects units, does not inflate tolerances.  In these coordinates
M̃ = S^{-½} M S^{-½} has entries of order one (``scaled_matrix(M, weights)``, with
weights w_i = 1/√S_i), forces scale by S^{-½} (w·f) and accelerations by S^{½} (a/w).

Rates are measured in 1/s (``rate_scale``): angular rates as they are, linear rates
over a radius of gyration.  A ≥ 1 (``world_lever``) is the factor by which
Pinocchio's world-frame terms exceed the result.  The checks
(``pendverify.checks.quantities``) build each state's *scale* from these.
"""

from __future__ import annotations

import numpy as np

from pendverify.checks.trust import term_amplification


def weights(model, q):
    return 1.0 / np.sqrt(model.diagonal_scale(q))


def scaled_matrix(A, w):
    return A * np.outer(w, w)


def rate_scale(model, q, v) -> float:
    """Largest rate in 1/s: angular rates as they are, linear rates over a natural length.

    Pinocchio's recursions carry body velocities that include linear ones (the
    cart's), so they set the size of the intermediate terms too.  The length for
    a linear coordinate i is ℓ_i = √(min S_angular / S_i), a radius of gyration.
    """
    angular = np.array(model.angular)
    S = model.diagonal_scale(q)
    rates = np.abs(v).astype(float)
    if np.any(~angular) and np.any(angular):
        rates[~angular] /= np.sqrt(np.min(S[angular]) / S[~angular])
    return float(np.max(rates, initial=0.0))


def norm2(A) -> float:
    return float(np.linalg.norm(A, 2))


def world_lever(model, system, q) -> float:
    """A ≥ 1: how much larger Pinocchio's world-frame terms are than M's diagonal (scaled).

    Pinocchio expresses spatial inertias about the world origin, so a joint whose
    subtree sits far from it (a cart 10 m along the rail, a small link 2 at the
    end of a long link 1) carries second moments m·|c|² ≫ M_ii into its
    recursions, which cancel in the result: its rounding is ε·A times the
    result's scale, added to the angles' (``pendverify.checks.catalogue.run_check``).
    (``pendverify.checks.trust.term_amplification``.)
    """
    return term_amplification(model, system, q)


def force_scale(model, state, w) -> float:
    """Size of the generalized forces acting, in scaled units (sum of |terms|)."""
    rate = rate_scale(model, state.q, state.v)
    zdot = state.v / w
    coriolis = rate * np.sum(np.abs(zdot))
    gravity = np.max(w * model.gravity_scale())
    applied = w * (
        np.abs(model.input_matrix()) @ np.abs(state.u)
        + np.abs(model.disturbance_matrix()) @ np.abs(state.w)
        + np.abs(model.damping_matrix()) @ np.abs(state.v)
    )
    return float(coriolis + gravity + np.max(applied, initial=0.0))


def damping_rate(model, w) -> float:
    """max |D̃| in 1/s: a hand C written with friction inside (C + D, as seed 000) rounds at this size."""
    return float(np.max(np.abs(scaled_matrix(model.damping_matrix(), w)), initial=0.0))
