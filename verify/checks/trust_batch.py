"""The trust rule's verdict at every state of a batch: ``trust.assess`` for all states at once.

``assess`` judges one state from three mass matrices' conditioning (the closed form's M
with the model's scale S, the same with Pinocchio's term amplification A, and Pinocchio's
M with its own diagonal); ``assess_batch`` forms the same numbers for a whole batch —
the matrices and A from ``pendverify.checks.batch.BatchContext``, κ matrix by matrix
as ``trust`` forms it (``checks.spectral``), the bounds elementwise, Python's ``max`` and tuple
comparisons written out — and returns the very ``Conditioning`` each state's ``assess``
returns.  A state whose numbers are not all finite is assessed by ``assess`` itself.
The rule and its argument are in ``pendverify.checks.trust``.
"""

from __future__ import annotations

import numpy as np

from pendverify.checks.spectral import conds2
from pendverify.checks.trust import EPS, KAPPA_K, REFUSE_REL, WARN_REL, Conditioning, assess


def _cond(M: np.ndarray) -> np.ndarray:
    """``trust._cond`` of each matrix: κ₂ (``checks.spectral``), inf for a matrix not finite or singular."""
    finite = np.all(np.isfinite(M), axis=(-2, -1))
    kappa = conds2(np.where(finite[:, None, None], M, np.eye(M.shape[-1])))
    return np.where(finite & np.isfinite(kappa), kappa, np.inf)


def _kappas(M, S):
    """κ raw, κ̃ (M scaled by S) and the scale spread of each state, as ``trust.conditioning``."""
    usable = np.all(S > 0, axis=-1) & np.all(np.isfinite(S), axis=-1)
    with np.errstate(all="ignore"):
        root = np.sqrt(S)
        kappa_scaled = np.where(usable, _cond(M / (root[:, :, None] * root[:, None, :])), np.inf)
        spread = np.where(usable, np.sqrt(np.max(S, axis=-1) / np.min(S, axis=-1)), np.inf)
    return _cond(M), kappa_scaled, spread


def _bound(kappa_scaled, spread, angle, amplification):
    """(the rounding bound, whether the spread decides it), as ``trust.conditioning``."""
    with np.errstate(all="ignore"):
        growth = 1.0 + np.abs(angle)
        rounding, visibility = kappa_scaled * (growth + (amplification - 1.0)), growth * spread
        return KAPPA_K * EPS * np.where(visibility > rounding, visibility, rounding), visibility > rounding


def _level(bound: float) -> str:
    return "ok" if bound <= WARN_REL else "warn" if bound <= REFUSE_REL else "refuse"


class BatchVerdicts:
    """``trust.assess`` at each state of a batch: ``verdicts[i]`` is the state's ``Conditioning``."""

    def __init__(self, ctx):
        M_hand, S = ctx.forms.value("mass_matrix"), ctx.forms.value("diagonal_scale")
        M_pin, A = ctx.pin.mass_matrix(), ctx.lever
        n = len(ctx.states)
        one = np.ones(n)
        hand, pin = _kappas(M_hand, S), _kappas(M_pin, np.abs(np.diagonal(M_pin, axis1=-2, axis2=-1)))
        # (κ raw, κ̃, bound, spread, by_spread, A) of the closed form's M alone, with A, and Pinocchio's M
        candidates = [
            (hand[0], hand[1], *_bound(hand[1], hand[2], ctx.angle, one), hand[2], one),
            (hand[0], hand[1], *_bound(hand[1], hand[2], ctx.angle, A), hand[2], A),
            (pin[0], pin[1], *_bound(pin[1], pin[2], ctx.angle, A), pin[2], A),
        ]
        self.fields = [np.stack([c[k] for c in candidates]) for k in range(6)]
        # max(verdicts, key=lambda c: (c.bound, c.kappa_raw)): the first of equals wins
        kappa, bound = self.fields[0], self.fields[2]
        best = np.zeros(n, dtype=int)
        for j in (1, 2):
            b0, k0 = np.choose(best, bound), np.choose(best, kappa)
            best = np.where(np.where(bound[j] == b0, kappa[j] > k0, bound[j] > b0), j, best)
        self.best = best
        finite = np.ones(n, dtype=bool)
        for x in self.fields:
            finite &= np.all(np.isfinite(x.astype(float)), axis=0)
        self.finite = finite
        self.bound = np.choose(best, bound)
        self.ctx = ctx

    def __len__(self) -> int:
        return len(self.best)

    def refuses(self, i: int) -> bool:
        """Whether state i's verdict is ``refuse`` (or not certain without ``assess`` itself)."""
        return not (self.finite[i] and self.bound[i] <= REFUSE_REL)

    def __getitem__(self, i: int) -> Conditioning:
        if not self.finite[i]:  # inf or nan somewhere: the state's own assessment decides
            return assess(self.ctx.model, self.ctx.states[i].q, self.ctx.system)
        kappa_raw, kappa_scaled, bound, by_spread, spread, amplification = (
            x[self.best[i], i] for x in self.fields
        )
        return Conditioning(
            float(kappa_raw),
            float(kappa_scaled),
            float(bound),
            _level(float(bound)),
            float(amplification),
            float(spread),
            bool(by_spread),
        )


def assess_batch(ctx) -> BatchVerdicts:
    """``trust.assess(model, state.q, system)`` for every state of the batch ``ctx``."""
    return BatchVerdicts(ctx)
