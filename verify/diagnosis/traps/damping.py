"""Trap: friction missing from, or wrong in, the hand model's q̈ (``aba`` fails).

r = M_hand (q̈_hand − q̈_pin) is fitted by X q̇ with a constant matrix X over
the moving states.  X = D: the hand q̈ lacks the friction D q̇; X = 2D: the
friction has the wrong sign; X a part of D: those terms are missing; X not
in D: the q̈ carries friction that ``damping_matrix`` does not declare.  The fit
counts only when its relative residual is within ``FIT_RTOL``.  The model is evaluated through
the model boundary (``pendverify.analytic.numeric_values``), as the checks evaluate it.
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic.numeric_values import model_value
from pendverify.diagnosis.finding import Finding

FIT_RTOL = 1e-6  # relative residual of the damping fit that counts as exact


def missing_damping(model, system, failing, states) -> Finding | None:
    sentence = _damping_sentence(model, system, failing, states)
    return None if sentence is None else Finding(kind="pattern", message=sentence, quantity="qddot")


def _damping_sentence(model, system, failing, states) -> str | None:
    """The fit of M·(q̈_hand − q̈_pin) by X·q̇ in words (module docstring), or None."""
    if "aba" not in failing:
        return None
    moving = [s for s in states if np.any(s.v != 0)]
    if len(moving) < model.nv + 1:
        return None
    rows, target = [], []
    B, W = model_value(model, "input_matrix"), model_value(model, "disturbance_matrix")
    D = model_value(model, "damping_matrix")
    for s in moving:
        tau = B @ s.u + W @ s.w - D @ s.v
        diff = model_value(model, "acceleration", s.q, s.v, s.u, s.w) - system.acceleration(s.q, s.v, tau)
        target.append(model_value(model, "mass_matrix", s.q) @ diff)
        rows.append(s.v)
    V, R = np.array(rows, dtype=float), np.array(target)
    if not np.all(np.isfinite(R)):
        return None  # a q̈ not finite at a state is no damping trap (and LAPACK would refuse it)
    X, *_ = np.linalg.lstsq(V, R, rcond=None)  # R ≈ V Xᵀ: r = X q̇
    X = X.T
    if np.linalg.norm(V @ X.T - R) > FIT_RTOL * np.linalg.norm(R) or np.max(np.abs(X)) == 0:
        return None
    scale = max(float(np.max(np.abs(D))), float(np.max(np.abs(X))))
    X[np.abs(X) < FIT_RTOL * scale] = 0.0
    names = model.coordinates
    where = [(i, j) for i in range(model.nv) for j in range(model.nv) if X[i, j] != 0]
    terms = ", ".join(f"{X[i, j]:.6g}·d{names[j]}/dt on {names[i]}" for i, j in where)
    if np.allclose(X, D, rtol=FIT_RTOL, atol=0) and np.any(D):
        return (
            f"a missing damping term: M·(q̈_hand − q̈_pin) = D·q̇ exactly ({terms}): the hand model's q̈ "
            "leaves out the friction −D·q̇ that damping_matrix() declares"
        )
    if np.allclose(X, 2 * D, rtol=FIT_RTOL, atol=0) and np.any(D):
        return f"damping with the wrong sign: M·(q̈_hand − q̈_pin) = 2·D·q̇ exactly ({terms})"
    if all(abs(X[i, j] - D[i, j]) <= FIT_RTOL * abs(D[i, j]) for i, j in where):
        return (
            f"a missing damping term: M·(q̈_hand − q̈_pin) = {terms} exactly, part of D: the hand model's q̈ "
            "leaves out that friction"
        )
    return (
        f"a damping mismatch: M·(q̈_hand − q̈_pin) = {terms} exactly, which damping_matrix() does not "
        f"declare (D = {D.tolist()}): the q̈ carries friction the model's D lacks, or the reverse"
    )
