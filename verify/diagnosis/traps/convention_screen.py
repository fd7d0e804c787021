"""Screen every candidate map at once: Pinocchio's M and H through it against the hand model's.

At a handful of states θ_s, each candidate map (T', θ0')
(``pendverify.diagnosis.traps.convention_maps``) puts Pinocchio at q = T'(θ_s − θ0').  One
batch in joint coordinates (``PinocchioSystem.at`` under the identity map) evaluates M_q, H_q
and the bodies' parallel-axis terms K_q (``pendverify.diagnosis.traps.inertia``) at every
such q, and the congruences of ``pendverify.robot.coordinates`` bring them to the hand's
coordinates:

    M' = T'ᵀ M_q T',   H' = T'ᵀ H_q,   K'_b = T'ᵀ K_q,b T'.

The hand model's M and H are evaluated once, at the same states.

The pivot-inertia trap is fitted after the map change, as ``inertia.pivot_inertia`` fits it
without one: M' − M_hand ≈ Σ_b c_b K'_b by least squares over the scaled entries, batched
over the candidates (``numpy.linalg.pinv``), with c rounded to {−1, 0, 1}; a candidate whose
coefficients are not all within ``inertia.COEFF_TOL`` of such integers gets c = 0.

A candidate's error is the one the ``crba`` and ``gravity`` checks measure
(``pendverify.checks.quantities``), the larger of the two over the states: the largest
entry of (M' − Σ_b c_b K'_b − M_hand)·(w wᵀ), w = S^{-½} the scaled coordinates' weights,
and max_i w_i |H'_i − H_hand,i| over max_i w_i·(gravity scale)_i.  Its residual is that
error over the declared map's (the first candidate, without a fit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.traps.inertia import COEFF_TOL, parallel_axis_terms
from pendverify.robot.coordinates import CoordinateMap


@dataclass(frozen=True)
class Screen:
    """The screen's verdict on each candidate, in the candidates' order."""

    #: error over the declared map's (C,)
    residual: np.ndarray
    #: the fitted pivot coefficients c_b in {−1, 0, 1} (C, nb)
    coefficients: np.ndarray
    #: the links whose bodies carry a parallel-axis term, in the coefficients' order
    links: list[str]
    #: the declared map's error (the denominator of ``residual``)
    before: float


def _congruence(T, A):
    """Tᵀ A T for each candidate's T (C, n, n) and its states' A (C, K, n, n)."""
    Tc = T[:, None]
    return np.swapaxes(Tc, -1, -2) @ A @ Tc


def _integers(coefficients: np.ndarray) -> np.ndarray:
    """Each row rounded to integers in {−1, 0, 1}, or zero where one entry is not within COEFF_TOL."""
    rounded = np.round(coefficients)
    ok = np.all((np.abs(coefficients - rounded) <= COEFF_TOL) & (np.abs(rounded) <= 1), axis=-1)
    return np.where(ok[:, None], rounded, 0.0)


def screen(model, system, candidates, states) -> Screen | None:
    """Each candidate's residual and pivot fit at ``states`` (module docstring); None where the hand
    model's M or H is not finite there (nothing to compare)."""
    n = model.nv
    hand = CheckBatch(model, system, states).terms
    if not (np.all(np.isfinite(hand.M_hand)) and np.all(np.isfinite(hand.H_hand))):
        return None
    theta, w = hand.q, hand.w  # (K, n)
    ww = w[:, :, None] * w[:, None, :]
    g_scale = np.max(w * hand.g_scale, axis=-1)  # (K,)
    # a model without gravity (scale 0): H compared in scaled units as they are
    g_scale = np.where(g_scale > 0, g_scale, 1.0)

    T = np.array([c.T for c in candidates])  # (C, n, n)
    theta0 = np.array([c.theta0 for c in candidates])  # (C, n)
    q = ((theta[None] - theta0[:, None]) @ np.swapaxes(T, -1, -2)).reshape(-1, n)  # q = T'(θ − θ0')
    joint = system.with_map(CoordinateMap(np.eye(n), np.zeros(n), system.cmap.joint_nq))
    pin = joint.at(q)
    C, K = len(candidates), len(states)
    M = _congruence(T, pin.mass_matrix().reshape(C, K, n, n))
    H = (np.swapaxes(T, -1, -2)[:, None] @ pin.gravity().reshape(C, K, n, 1))[..., 0]

    dM = (M - hand.M_hand) * ww  # (C, K, n, n), scaled
    eH = np.max(np.max(w * np.abs(H - hand.H_hand), axis=-1) / g_scale, axis=-1)  # (C,)
    links, Kq = parallel_axis_terms(joint, q)
    if links:
        Kc = np.stack([_congruence(T, k.reshape(C, K, n, n)) * ww for k in Kq], axis=-1)
        A = Kc.reshape(C, K * n * n, len(links))  # (C, K n², nb)
        b = dM.reshape(C, K * n * n, 1)
        coefficients = _integers((np.linalg.pinv(A) @ b)[..., 0])
        left = b[..., 0] - (A @ coefficients[..., None])[..., 0]
    else:
        coefficients = np.zeros((C, 0))
        left = dM.reshape(C, -1)
    eM = np.max(np.abs(left), axis=-1)
    error = np.maximum(eM, eH)
    before = float(max(np.max(np.abs(dM[0])), eH[0]))
    with np.errstate(divide="ignore", invalid="ignore"):
        residual = error / before
    return Screen(residual, coefficients, links, before)
