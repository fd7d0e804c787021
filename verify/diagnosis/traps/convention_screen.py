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
over the candidates (``numpy.linalg.pinv``), with c rounded to {−1, 0, 1} (``inertia.integer_coefficients``:
c = 0 where the coefficients are not all within ``inertia.COEFF_TOL`` of such integers).

A candidate's error is the one the ``crba`` and ``gravity`` checks measure
(``pendverify.checks.quantities``), the larger of the two over the states: the largest
entry of (M' − Σ_b c_b K'_b − M_hand)·(weights weightsᵀ), weights = S^{-½} the scaled
coordinates' weights, and max_i weights_i |H'_i − H_hand,i| over max_i weights_i·(gravity scale)_i.
Its residual is that error over the declared map's (the first candidate, without a fit).

Bounded work: H is compared first, for every candidate (K gravity evaluations each, no fit);
a candidate whose H alone leaves a residual beyond the caller's cutoff fails the screen whatever
its fit, so only the others are fitted, and of those only as many, in the candidates' order
(simplest first), as the fits' work counted before they start allows (``MAX_FIT_WORK``).  On a
model with gravity that is a handful; the decisions are those of fitting every candidate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.traps.inertia import integer_coefficients, parallel_axis_systems
from pendverify.robot.coordinates import CoordinateMap

#: candidates evaluated at once: their arrays, (CHUNK, K, n², nb) for the fit, stay within a few MB
CHUNK = 2048
#: the most numbers a chunk's arrays hold (8 bytes each: 256 MB), whatever the model's size: a
#: 40-link chain's 40 pivot systems at 24 states take 1.5 MB per candidate
MAX_CHUNK_FLOATS = 32_000_000
#: the most pivot-fit work one screen does, counted by ``fit_work`` before the fits start: the SVD
#: dominates, ~2.5 ns per unit (measured: one candidate of a 40-link chain, K = 4 states and 40
#: pivot systems, 1.1e7 units, in 25 ms on one core of an idle 2-core machine), so 2e8 units are
#: about half a second, ten times that on a loaded one.  A triple pendulum's whole budget of
#: candidates (``convention_maps.MAX_CANDIDATES``: 40 000 × 576 units) stays well inside it: up to
#: three coordinates every candidate is fitted
MAX_FIT_WORK = 200_000_000


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
    #: candidates whose H passed but that were not fitted: beyond ``MAX_FIT_WORK`` (residual inf)
    unfitted: int = 0


def _congruence(T, A):
    """Tᵀ A T for each candidate's T (C, n, n) and its states' A (C, K, n, n)."""
    Tc = T[:, None]
    return np.swapaxes(Tc, -1, -2) @ A @ Tc


@dataclass(frozen=True)
class _Hand:
    """The hand model at the screen's states: θ (K, n), M, H, the weights, their products, g scales."""

    theta: np.ndarray
    M: np.ndarray
    H: np.ndarray
    weights: np.ndarray
    pair_weights: np.ndarray
    g_scale: np.ndarray


def _configurations(hand: _Hand, T, theta0) -> np.ndarray:
    """q = T'(θ − θ0') of candidates (T, θ0') at the hand's states, (C·K, n)."""
    n = hand.theta.shape[1]
    return ((hand.theta[None] - theta0[:, None]) @ np.swapaxes(T, -1, -2)).reshape(-1, n)


def _gravity_errors(hand: _Hand, joint, T, theta0) -> np.ndarray:
    """The error of H of candidates (T, θ0') (C,)."""
    C, (K, n) = len(T), hand.theta.shape
    H = np.swapaxes(T, -1, -2)[:, None] @ joint.at(_configurations(hand, T, theta0)).gravity().reshape(
        C, K, n, 1
    )
    return np.max(np.max(hand.weights * np.abs(H[..., 0] - hand.H), axis=-1) / hand.g_scale, axis=-1)


def _mass_errors(hand: _Hand, joint, shifts, T, theta0):
    """(error of M without the fit, error of M with it, the fit's c) of candidates (T, θ0')."""
    C, (K, n) = len(T), hand.theta.shape
    q = _configurations(hand, T, theta0)
    M = _congruence(T, joint.at(q).mass_matrix().reshape(C, K, n, n))
    dM = ((M - hand.M) * hand.pair_weights).reshape(C, K * n * n)  # scaled
    bare = np.max(np.abs(dM), axis=-1)
    if not shifts:
        return bare, bare, np.zeros((C, 0))
    terms = [
        _congruence(T, only.at(q).mass_matrix().reshape(C, K, n, n)) * hand.pair_weights for _, only in shifts
    ]
    A = np.stack(terms, axis=-1).reshape(C, K * n * n, len(shifts))  # (C, K n², nb)
    coefficients = integer_coefficients((np.linalg.pinv(A) @ dM[..., None])[..., 0])
    left = dM - (A @ coefficients[..., None])[..., 0]
    return bare, np.max(np.abs(left), axis=-1), coefficients


def _chunks(count: int, size: int):
    return [slice(i, min(i + size, count)) for i in range(0, count, size)]


def screen(model, system, candidates, states, cutoff: float = np.inf) -> Screen | None:
    """Each candidate's residual and pivot fit at ``states`` (module docstring); None where the hand
    model's M or H is not finite there (nothing to compare).

    H first, for every candidate (K gravity evaluations each); a candidate whose H alone leaves a
    residual beyond ``cutoff`` fails whatever its fit, and is not fitted: its residual is H's alone.
    The others are fitted in the candidates' order (simplest first) while the fits' work, counted
    before they start (``fit_work``), stays within ``MAX_FIT_WORK``; the rest are ``unfitted``
    (residual infinite).  The candidates go through in chunks whose arrays hold at most
    ``MAX_CHUNK_FLOATS`` numbers, which bounds the memory the batched fit takes."""
    n = model.nv
    terms = CheckBatch(model, system, states).terms
    if not (np.all(np.isfinite(terms.M_hand)) and np.all(np.isfinite(terms.H_hand))):
        return None
    weights = terms.weights  # (K, n)
    g_scale = np.max(weights * terms.g_scale, axis=-1)  # (K,)
    # a model without gravity (scale 0): H compared in scaled units as they are
    g_scale = np.where(g_scale > 0, g_scale, 1.0)
    hand = _Hand(
        terms.q, terms.M_hand, terms.H_hand, weights, weights[:, :, None] * weights[:, None, :], g_scale
    )
    joint = system.with_map(CoordinateMap(np.eye(n), np.zeros(n), system.cmap.joint_nq))
    shifts = parallel_axis_systems(joint)
    T = np.array([c.T for c in candidates])  # (C, n, n)
    theta0 = np.array([c.theta0 for c in candidates])  # (C, n)
    K = len(hand.theta)
    # a chunk holds C·K·n² numbers per pivot system and a few more: at most MAX_CHUNK_FLOATS in all
    chunk = max(1, min(CHUNK, MAX_CHUNK_FLOATS // (K * n * n * (len(shifts) + 4))))
    eH = np.concatenate([_gravity_errors(hand, joint, T[s], theta0[s]) for s in _chunks(len(T), CHUNK)])
    bare0, _, _ = _mass_errors(hand, joint, shifts, T[:1], theta0[:1])
    before = float(max(bare0[0], eH[0]))
    with np.errstate(divide="ignore", invalid="ignore"):
        residual = eH / before
    todo = np.flatnonzero(~(residual > cutoff))
    todo = np.union1d([0], todo)  # the declared map is always fitted (its pivot fit is a finding)
    fits = max(1, min(len(todo), MAX_FIT_WORK // fit_work(K, n, len(shifts))))
    unfitted = len(todo) - fits
    residual[todo[fits:]] = np.inf
    todo = todo[:fits]
    coefficients = np.zeros((len(T), len(shifts)))
    for s in _chunks(len(todo), chunk):
        at = todo[s]
        _, fitted, c = _mass_errors(hand, joint, shifts, T[at], theta0[at])
        with np.errstate(divide="ignore", invalid="ignore"):
            residual[at] = np.maximum(fitted, eH[at]) / before
        coefficients[at] = c
    return Screen(residual, coefficients, [name for name, _ in shifts], before, unfitted)


def fit_work(states: int, n: int, pivots: int) -> int:
    """The work of one candidate's pivot fit, counted as K·n²·(nb + 1)² (the SVD of its K·n² × nb
    system and the M evaluations before it, in numbers)."""
    return states * n * n * (pivots + 1) ** 2
