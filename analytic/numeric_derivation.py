"""M, H and C·q̇ derived numerically from a q̈ given as code, where the inputs span the coordinates.

A mechanical system's q̈ is affine in its inputs,

    q̈(q, q̇, u) = M(q)⁻¹ (B u − C(q, q̇) q̇ − D q̇ − H(q)),

so with B square and invertible (as many inputs as coordinates), at one configuration q:

* A(q) = ∂q̈/∂u = M⁻¹B, column j = (q̈(q, 0, h_j e_j) − q̈(q, 0, 0))/h_j (any step is exact up
  to rounding, q̈ being affine in u).  h_j is 1, or where a unit input moves q̈ less than
  gravity does (|q̈̃(e_j) − q̈̃(0)| < |q̈̃(0)|, scaled as below, from a first pass with steps of
  1) the power of 2 that lifts it to |q̈̃(0)|: the difference then does not cancel the digits of
  q̈(0) (a unit torque on a 10⁶ kg pendulum would leave 10⁻⁶ of them), and dividing by h_j is exact;
* M(q) = B A(q)⁻¹;
* H(q) = −M(q) q̈(q, 0, 0);
* C(q, q̇)·q̇ = −M(q) (q̈(q, q̇, 0) − q̈(q, 0, 0)) − D q̇, so that C·q̇ + H = −M q̈(q, q̇, 0) − D q̇.

Affinity is checked at every configuration derived: for j ≤ k, with u_j = h_j e_j,
q̈(u_j + u_k) − q̈(u_j) − q̈(u_k) + q̈(0) (j = k: q̈(2u_j) − 2 q̈(u_j) + q̈(0)) must vanish within
four times the rounding of one q̈ (below); if not, the derivation is refused (``UserCodeError``
naming q).

Rounding bound
--------------
All in the checks' scaled coordinates (``pendverify.checks.scaling``): weights = 1/√S,
M̃ = diag(weights) M diag(weights), forces weights·f, accelerations q̈̃ = q̈/weights, B̃ = diag(weights) B
(steps of 1 in the inputs), n coordinates.

What differs between the derivation's calls.  Every call at a configuration has the same q (the
same bits), q̇ = 0 and w = 0; only u changes.  Whatever the code computes from q alone — cos θ,
M(q), H(q), a factorisation of M — is the same number in every call, so its rounding (ε·(1 + |θ|)
from the angles, ε-sized entries of M) enters the derived M as it enters a hand-written M: the
check's own tolerance K·ε·((1 + |θ|max)·c_T + (A − 1)) covers it, and it is not amplified by the
inversion below (M̂ = M + E common to all calls gives B (M̂⁻¹B)⁻¹ = M̂ exactly).  What differs is
the rounding of the operations that carry u: forming the forces B u − … and the solve with them.

1. One call's rounding, q̈ = M⁻¹f however the code solves: δq̈̃ ≤ K ε (‖M̃⁻¹‖ F + κ̃ ‖q̈̃‖), with F
   the 2-norm of the forces' terms and K = ``K_CODE`` (the aba check's K): the rounding of f (ε F)
   amplified by ‖M̃⁻¹‖, plus a backward-stable solve's κ̃ ε relative error.  ‖q̈̃‖ is Pinocchio's
   at the call's (q, u) (the URDF's q̈, never the code's own: a wrong code cannot widen its
   tolerance), where a worst case would take ‖M̃⁻¹‖ F: q̈ points along M's weakest direction only
   at special states, and the bound need not assume it does everywhere.
2. Column j of Ã = M̃⁻¹B̃ is (q̈̃(h_j e_j) − q̈̃(0))/h_j, whose calls have forces √n F₀ + h_j‖b̃_j‖
   and √n F₀ at most (F₀ = max_i w_i g_i, g the gravity scale) and Pinocchio's accelerations
   q̈̃₀ + h_j Ã e_j and q̈̃₀ (q̈̃₀ = −M̃⁻¹H̃ at rest): δÃ_j the sum of the two calls' bounds over h_j,
   ‖δÃ‖₂ ≤ ‖δÃ‖_F.
3. M̃ = B̃ Ã⁻¹, δ(Ã⁻¹) = −Ã⁻¹ δÃ Ã⁻¹ and Ã⁻¹ = B̃⁻¹M̃: ‖δM̃‖ ≤ ‖M̃‖² ‖B̃⁻¹‖ ‖δÃ‖, plus the
   inversion's own rounding K ε κ(Ã) κ(B̃) ‖M̃‖ ≤ K ε κ̃ κ(B̃)² ‖M̃‖.  This is ``crba``'s bound
   (its scale is 1: M̃'s entries are of order one).
4. H̃ = −M̃ q̈̃₀: δH̃ ≤ ‖δM̃‖ ‖q̈̃₀‖ + ‖M̃‖ δq̈̃₀, relative to F₀ (the gravity check's scale).
   C·q̇ + H = −M̃ q̈̃(q, q̇, 0) − D̃ q̇ is the same with Pinocchio's q̈̃(q, q̇, 0) and, for F, √n
   times the rnea check's scale (the size of the terms acting), relative to that scale.

The matrices and accelerations in the bound are Pinocchio's at the state (the URDF's M, scaled by
its own diagonal, its gravity bound, H and forces): the code's own numbers, which are what is
checked, never widen their tolerance.  Relative to a hand-written M (ε-sized rounding) the bound
grows like κ̃² for M and H (the code's solve and the inversion of Ã): rounding that the
hand-written forms do not have.  The checks add it to their own rounding tolerance
(``pendverify.checks.judge.collect``); where the sum exceeds the trust limit the state is
refused, not judged.

Measured (the conformance matrix's triple pendulum of point masses and 5-link chain, 60 states
each, κ̃ up to 400 and |θ| up to 100 rad): the derived M is within 3·10⁻¹⁴ of Pinocchio's and the
bound above is at most 1.5·10⁻⁸ (triple) and 1.6·10⁻⁷ (chain): pessimistic by 10⁵ to 10⁶, but below
the trust limit; a worst case of step 1 at every call, with γ = 1 + |θ| in it, would reach
1.3·10⁻³ and 0.19 and refuse these true models.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

EPS = float(np.finfo(float).eps)
#: the code's q̈ is trusted to the aba check's constant (``pendverify.checks.catalogue``)
K_CODE = 16
#: what the derivation is called in the report's notes
DERIVED = (
    "M = B (∂q̈/∂u)⁻¹, H = −M q̈(q, 0, 0) and C·q̇ + H = −M q̈(q, q̇, 0) − D q̇ are derived from the "
    "code's q̈ at each state (pendverify.analytic.numeric_derivation); crba, gravity and rnea add "
    "the derivation's rounding bound (∝ κ̃(M)², from Pinocchio's M and q̈) to their tolerance"
)


@dataclass(frozen=True)
class NumericDerivation:
    """M, q̈(q, 0, 0) and the inputs' steps h at one configuration (``derive``)."""

    M: np.ndarray
    rest: np.ndarray
    steps: np.ndarray


def _norms(A: np.ndarray) -> tuple[float, float]:
    s = np.linalg.svd(A, compute_uv=False)
    return float(s[0]), float(1.0 / s[-1]) if s[-1] > 0 else np.inf


def one_rounding(M: np.ndarray, angle: float) -> float:
    """A worst case of one call's rounding (step 1 with ‖q̈̃‖ ≤ ‖M̃⁻¹‖F and the angles' γ): δq̈̃ ≤ ρ·F.

    For the affinity test of ``derive``, which judges the code's own q̈ before any Pinocchio
    quantity is at hand: wide, so that only code that is not affine in u is refused."""
    weights = 1.0 / np.sqrt(np.abs(np.diag(M)))
    norm, inv = _norms(M * np.outer(weights, weights))
    return K_CODE * EPS * (1.0 + angle) * inv * (1.0 + norm * inv)


def _mass(A, B, q, fail) -> np.ndarray:
    n = len(q)
    try:
        M = B @ np.linalg.inv(A)
    except np.linalg.LinAlgError:
        M = np.full((n, n), np.nan)
    if not np.all(np.isfinite(M)):
        fail(f"∂q̈/∂u = {A.tolist()} at q = {q.tolist()} is not invertible: M = B (∂q̈/∂u)⁻¹ cannot be formed")
    if np.any(np.diag(M) <= 0):
        fail(f"M = B (∂q̈/∂u)⁻¹ = {M.tolist()} at q = {q.tolist()} has a diagonal entry ≤ 0")
    return M


def derive(acceleration, q, B: np.ndarray, n_disturbances: int, fail) -> NumericDerivation:
    """M(q) and q̈(q, 0, 0) from ``acceleration(q, v, u, w)`` and the declared B (module docstring).

    ``fail(message)`` raises: called when q̈ is not affine in u at q within its rounding, or
    ∂q̈/∂u is not invertible.
    """
    n = len(q)
    zero, w = np.zeros(n), np.zeros(n_disturbances)

    def at(u) -> np.ndarray:
        return np.asarray(acceleration(q, zero, np.asarray(u, dtype=float), w), dtype=float)

    eye = np.eye(n)
    rest = at(np.zeros(n))
    unit = np.stack([at(eye[j]) - rest for j in range(n)], axis=1)
    weights = 1.0 / np.sqrt(np.abs(np.diag(_mass(unit, B, q, fail))))
    steps = np.array([_step(rest / weights, unit[:, j] / weights) for j in range(n)])
    pushed = [at(steps[j] * eye[j]) for j in range(n)]
    A = np.stack([(p - rest) / h for p, h in zip(pushed, steps, strict=True)], axis=1)
    M = _mass(A, B, q, fail)
    weights = 1.0 / np.sqrt(np.abs(np.diag(M)))
    rho = one_rounding(M, float(np.max(np.abs(q), initial=0.0)))
    gravity = float(np.linalg.norm(weights * (M @ rest)))
    for j in range(n):
        for k in range(j, n):
            u = steps[j] * eye[j] + steps[k] * eye[k]
            residual = (at(u) - pushed[j] - pushed[k] + rest) / weights
            bound = 4.0 * rho * (gravity + float(np.linalg.norm(weights * (B @ u))))
            if not float(np.linalg.norm(residual)) <= bound:
                fail(
                    f"q̈ is not affine in the inputs at q = {q.tolist()}: q̈(u{j + 1} + u{k + 1}) − "
                    f"q̈(u{j + 1}) − q̈(u{k + 1}) + q̈(0) = {(residual * weights).tolist()} for steps "
                    f"{steps.tolist()}, beyond its rounding bound (scaled {bound:.2g}); "
                    "M = B (∂q̈/∂u)⁻¹ needs q̈ = M⁻¹(B u + …)"
                )
    return NumericDerivation(M, rest, steps)


def _step(rest: np.ndarray, column: np.ndarray) -> float:
    """h_j: 1, or the power of 2 (exact to divide by) that lifts a unit input's q̈ to the size of q̈ at rest."""
    size, unit = float(np.linalg.norm(rest)), float(np.linalg.norm(column))
    if not (unit > 0 and size > unit and np.isfinite(size / unit)):
        return 1.0
    return float(2.0 ** np.ceil(np.log2(size / unit)))


def rounding_bounds(M, S, B, gravity_scale, steps, H, force, scale) -> tuple[np.ndarray, ...]:
    """(crba's, gravity's, rnea's) relative rounding bounds per state (module docstring, "Rounding bound").

    ``M`` (N, n, n), ``S`` (N, n): Pinocchio's M and the scales at the states; ``B`` (n, n);
    ``gravity_scale`` (n,) the gravity bound; ``steps`` (N, n) the steps h the derivation took;
    ``H`` (N, n) Pinocchio's gravity and ``force`` (N, n) its M q̈(q, q̇, 0) = −(C q̇ + H + D q̇);
    ``scale`` (N,) the rnea check's scale.  Returns three arrays (N,).
    """
    M, S = np.asarray(M, dtype=float), np.asarray(S, dtype=float)
    n = M.shape[-1]
    weights = 1.0 / np.sqrt(S)
    Mt = M * (weights[:, :, None] * weights[:, None, :])
    s = np.linalg.svd(Mt, compute_uv=False)
    norm, inv = s[:, 0], 1.0 / s[:, -1]
    kappa = norm * inv
    Bt = weights[:, :, None] * np.asarray(B, dtype=float)[None]
    sb = np.linalg.svd(Bt, compute_uv=False)
    b_inv, kappa_b = 1.0 / sb[:, -1], sb[:, 0] / sb[:, -1]
    F0 = np.max(weights * np.asarray(gravity_scale, dtype=float), axis=-1)
    h = np.asarray(steps, dtype=float)

    def one(F, size, k=(slice(None),)):  # 1. one call's rounding: forces' terms F, ‖q̈̃‖ = size
        return K_CODE * EPS * (inv[k] * F + kappa[k] * size)

    rest = np.linalg.solve(Mt, (-weights * np.asarray(H, dtype=float))[..., None])[..., 0]
    rest_size = np.linalg.norm(rest, axis=-1)
    columns = np.swapaxes(np.linalg.solve(Mt, Bt), -1, -2)  # row j: column j of Ã = M̃⁻¹B̃
    gravity_terms = np.sqrt(n) * F0
    at_rest = one(gravity_terms, rest_size)
    each = (slice(None), None)
    pushed = one(
        gravity_terms[:, None] + h * np.linalg.norm(Bt, axis=-2),
        np.linalg.norm(rest[:, None, :] + h[:, :, None] * columns, axis=-1),
        each,
    )
    dA = np.sqrt(np.sum(((pushed + at_rest[:, None]) / h) ** 2, axis=-1))  # 2.
    dM = norm**2 * b_inv * dA + K_CODE * EPS * kappa * kappa_b**2 * norm  # 3.
    gravity = _relative(dM * rest_size + norm * at_rest, F0)  # 4.
    moving = np.linalg.solve(Mt, (weights * np.asarray(force, dtype=float))[..., None])[..., 0]
    moving_size, scale = np.linalg.norm(moving, axis=-1), np.asarray(scale, dtype=float)
    rnea = _relative(dM * moving_size + norm * one(np.sqrt(n) * scale, moving_size), scale)
    return dM, gravity, rnea


def _relative(bound: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """bound/scale; where nothing acts (scale 0: g = 0 at rest) a zero bound stays 0 (q̈ = M⁻¹·0 is
    exactly 0 in every call), any other is inf (refused)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(scale > 0, bound / scale, np.where(bound == 0, 0.0, np.inf))
