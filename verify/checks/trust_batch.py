"""The trust rule's verdict at every state of a batch: ``trust.assess`` for all states at once.

``assess`` judges one state from three mass matrices' conditioning (the closed form's M
with the model's scale S, the same with Pinocchio's term amplification A, and Pinocchio's
M with its own diagonal); ``assess_batch`` forms the same numbers for a whole batch —
the matrices and A from ``pendverify.checks.batch.BatchContext``, κ by one SVD per
matrix (as ``np.linalg.cond``), the bounds elementwise, Python's ``max`` and tuple
comparisons written out — and returns the very ``Conditioning`` each state's ``assess``
returns.  A state whose numbers are not all finite is assessed by ``assess`` itself.
The rule and its argument are in ``pendverify.checks.trust``.
"""

from __future__ import annotations

import numpy as np

from pendverify.checks.trust import EPS, KAPPA_K, REFUSE_REL, WARN_REL, Conditioning, assess


def _cond(M: np.ndarray) -> np.ndarray:
    """``trust._cond`` of each matrix: κ₂ by SVD, inf for a matrix not finite or singular."""
    finite = np.all(np.isfinite(M), axis=(-2, -1))
    safe = np.where(finite[:, None, None], M, np.eye(M.shape[-1]))
    s = np.linalg.svd(safe, compute_uv=False)
    with np.errstate(all="ignore"):
        kappa = s[:, 0] / s[:, -1]
    return np.where(finite & np.isfinite(kappa), kappa, np.inf)


def _verdict(M, S, angle, amplification):
    """``trust.conditioning`` of each state: (κ raw, κ̃, bound, spread, by_spread)."""
    usable = np.all(S > 0, axis=-1) & np.all(np.isfinite(S), axis=-1)
    with np.errstate(all="ignore"):
        root = np.sqrt(S)
        kappa_scaled = np.where(usable, _cond(M / (root[:, :, None] * root[:, None, :])), np.inf)
        spread = np.where(usable, np.sqrt(np.max(S, axis=-1) / np.min(S, axis=-1)), np.inf)
        growth = 1.0 + np.abs(angle)
        rounding, visibility = kappa_scaled * (growth + (amplification - 1.0)), growth * spread
        bound = KAPPA_K * EPS * np.where(visibility > rounding, visibility, rounding)
    return _cond(M), kappa_scaled, bound, spread, visibility > rounding


def _level(bound: float) -> str:
    return "ok" if bound <= WARN_REL else "warn" if bound <= REFUSE_REL else "refuse"


def assess_batch(ctx) -> list[Conditioning]:
    """``trust.assess(model, state.q, system)`` for every state of the batch ``ctx``."""
    M_hand, S = ctx.forms.value("mass_matrix"), ctx.forms.value("diagonal_scale")
    M_pin, A = ctx.pin.mass_matrix(), ctx.lever
    n = len(ctx.states)
    one = np.ones(n)
    candidates = [
        (*_verdict(M_hand, S, ctx.angle, one), one),
        (*_verdict(M_hand, S, ctx.angle, A), A),
        (*_verdict(M_pin, np.abs(np.diagonal(M_pin, axis1=-2, axis2=-1)), ctx.angle, A), A),
    ]
    # max(verdicts, key=lambda c: (c.bound, c.kappa_raw)): the first of equals wins
    best = np.zeros(n, dtype=int)
    for j in (1, 2):
        b, k = candidates[j][2], candidates[j][0]
        b0, k0 = np.choose(best, [c[2] for c in candidates]), np.choose(best, [c[0] for c in candidates])
        best = np.where(np.where(b == b0, k > k0, b > b0), j, best)
    finite = np.ones(n, dtype=bool)
    for c in candidates:
        for x in c:
            finite &= np.isfinite(np.asarray(x, dtype=float))
    out = []
    for i in range(n):
        if not finite[i]:  # inf or nan somewhere: the state's own assessment decides
            out.append(assess(ctx.model, ctx.states[i].q, ctx.system))
            continue
        kappa_raw, kappa_scaled, bound, spread, by_spread, amplification = (x[i] for x in candidates[best[i]])
        out.append(
            Conditioning(
                float(kappa_raw),
                float(kappa_scaled),
                float(bound),
                _level(float(bound)),
                float(amplification),
                float(spread),
                bool(by_spread),
            )
        )
    return out
