"""The trust rule: how far a comparison with a (near-singular) mass matrix can be trusted.

The cart reference system's mass matrix loses rank as the middle bob vanishes::

    det M = l1² l2² m2 (m m1 + (m1² + m1 m2) sin² θ1 + m m2 sin²(θ1 − θ2)),

which at θ1 = 0 and θ1 = θ2 falls to l1² l2² m2 m m1 → 0 as m1 → 0 (rod 1 and
rod 2 can then counter-rotate about a massless joint).  At m1 = 0 Pinocchio's
ABA returns *finite* nonsense (about 1e10 m/s², 1e23 rad/s²) without a NaN or
an exception, so conditioning has to be checked before anything is compared.

Trust rule (``check_conditioning``)
-----------------------------------
Two sources of rounding add up.  A solve with M amplifies relative errors by
κ̃, the 2-norm condition number of M̃ = S^{-½} M S^{-½} (S the model's diagonal
inertia scale: raw κ(M) mostly measures units and overstates the difficulty).
The errors it amplifies are ε·(1 + |θ|max) from the angles themselves (cos θ is
only as exact as θ) plus ε·(A − 1) from the size of the terms Pinocchio works
with, A = ``term_amplification`` ≥ 1 (below).  The rounding bound is

    bound = K·ε·κ̃·((1 + |θ|max) + (A − 1)),        K = ``KAPPA_K``,

* bound ≤ ``WARN_REL`` (1e-10): ``ok``;
* ``WARN_REL`` < bound ≤ ``REFUSE_REL`` (1e-6): ``warn`` — fewer than ten digits
  are verified;
* bound > ``REFUSE_REL`` or κ̃ not finite: ``refuse`` (``IllConditionedError``).
  A comparison whose tolerance exceeds 1e-6 can no longer tell a 1 ppm
  modelling error (β off by 1e-6, one of the planted-error tests) from rounding.

A third source limits what a comparison can *see*.  In scaled coordinates an
error in the terms of a coordinate j with a small scale S_j that leaks into its
coupling with a coordinate i of large scale S_i — a wrong coordinate map does
exactly that (absolute vs relative angles moves M_jj into M_ij) — appears with
the size √(S_j/S_i) of the error.  Against a tolerance K·ε·(1 + |θ|max) such an
error is invisible below K·ε·(1 + |θ|max)·s, s = √(max S / min S) the *scale
spread*, so the bound is

    bound = K·ε·max(κ̃·((1 + |θ|max) + (A − 1)),  (1 + |θ|max)·s).

The spread term refuses only extreme sets: a link 1 of 1e30 kg on a link 2 of
0.8 kg (s ≈ 1e15; absolute and relative angles then give the same checks to
ε), never the mass and length ratios of up to 1e6 in ``pendverify stress``
(s ≤ 2e3 there).

So angles beyond about 2.8e8/κ̃ rad are refused however well-conditioned M is:
an angle that large is only known to ε·|θ|.  For the default cart (m = 1.5 kg,
m2 = 0.75 kg, l1 = 0.5 m, l2 = 0.75 m) at θ1 = θ2 = 0, κ̃ ≈ 3.7/m1 (m1 in kg) and
A ≈ 16: the rule warns below m1 ≈ 3e-3 kg and refuses below m1 ≈ 3e-7 kg.  The
study below measures every quantity within 1e-6 down to m1 = 1e-8 kg, so the
rule is conservative by a factor of about 30 there.

Term amplification A
--------------------
Pinocchio's RNEA, ABA, Coriolis and M⁻¹ work with spatial inertias expressed
in the world frame, whose entries grow like m·|c|² (c: a centre of mass seen
from the world origin), and the model's coordinates can be differences of
Pinocchio's (absolute angles from relative joints).  Their rounding is ε times
*those* terms, not ε times the result.  With W_j = Σ_{k in subtree(j)} m_k|c_k|² +
tr I_k for a revolute joint (M_q,jj for a prismatic one, never less than M_q,jj),
W̄_ij = √(W_i W_j) and T the coordinate map (M_θ = Tᵀ M_q T),

    A = max_i (|T|ᵀ W̄ |T|)_ii / S_i = max_i (Σ_k |T|_ki √W_k)² / S_i

(computed in ``pendverify.checks.amplification``).

Measured: a 1 mm double rod on a cart 8 m from the origin (A ≈ 6e7) gives
Pinocchio's M⁻¹ a relative error of 1.3e6·ε although κ̃ ≈ 12; a 1 km link carrying a
1 mm link (A ≈ 3e12) loses everything.  A ≈ 8 for the default double pendulum,
≈ 16 for the default cart near the origin (the relative-to-absolute map adds the
two rods' levers) and ≈ 1.5e3 for the default cart 10 m away.  A is an upper
estimate: measured errors stay about 10 to 1000 times below ε·κ̃·A.

The measured side of this rule — the m1 → 0 study against 50-digit mpmath —
lives in ``pendverify.stress.trust_study``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.checks.batch import CheckBatch, state_at
from pendverify.checks.spectral import conds2
from pendverify.errors import IllConditionedError

EPS = float(np.finfo(float).eps)
KAPPA_K = 16  # the K of the checks that solve with M (aba, minverse)
WARN_REL = 1e-10  # predicted relative error above which results carry a warning
REFUSE_REL = 1e-6  # predicted relative error above which results are refused


@dataclass(frozen=True)
class Conditioning:
    """κ(M) raw and after diagonal scaling, Pinocchio's term amplification, the bound, the verdict."""

    kappa_raw: float
    kappa_scaled: float
    bound: float
    level: str  # "ok", "warn" or "refuse"
    amplification: float = 1.0
    spread: float = 1.0
    by_spread: bool = False

    @property
    def note(self) -> str:
        if self.level == "ok":
            return ""
        return (
            f"{self.level}: κ̃(M) = {self.kappa_scaled:.3g}, term amplification {self.amplification:.3g}, "
            f"rounding bound {self.bound:.2g} (warn > {WARN_REL:g}, refuse > {REFUSE_REL:g})"
        )


def _cond(M: np.ndarray) -> np.ndarray:
    """κ₂ of each matrix of a stack (``checks.spectral``); inf for one not finite or singular."""
    finite = np.all(np.isfinite(M), axis=(-2, -1))
    kappa = conds2(np.where(finite[:, None, None], M, np.eye(M.shape[-1])))
    return np.where(finite & np.isfinite(kappa), kappa, np.inf)


def _level(bound: float) -> str:
    return "ok" if bound <= WARN_REL else "warn" if bound <= REFUSE_REL else "refuse"


def scaled_kappas(M, S) -> tuple[np.ndarray, np.ndarray]:
    """(κ̃, the scale spread) of each mass matrix of a stack (N, n, n) with scales S (N, n).

    A scale that is not positive and finite makes both infinite.
    """
    M, S = np.asarray(M, dtype=float), np.asarray(S, dtype=float)
    usable = np.all(S > 0, axis=-1) & np.all(np.isfinite(S), axis=-1)
    with np.errstate(all="ignore"):
        root = np.sqrt(np.where(usable[:, None], S, 1.0))
        kappa_scaled = np.where(usable, _cond(M / (root[:, :, None] * root[:, None, :])), np.inf)
        spread = np.where(usable, np.sqrt(np.max(S, axis=-1) / np.min(S, axis=-1)), np.inf)
    return kappa_scaled, spread


def bounds(kappa_scaled, spread, angle, amplification) -> tuple[np.ndarray, np.ndarray]:
    """(the rounding bound, whether the spread decides it) per state: K·ε·max(κ̃·((1 + |θ|) +
    (A − 1)), (1 + |θ|)·s), ``angle`` |θ|max and ``amplification`` A per state."""
    with np.errstate(all="ignore"):
        growth = 1.0 + np.abs(angle)
        rounding = kappa_scaled * (growth + (amplification - 1.0))
        visibility = growth * spread
        return KAPPA_K * EPS * np.where(visibility > rounding, visibility, rounding), visibility > rounding


def conditioning(
    M: np.ndarray, scale: np.ndarray | None = None, angle: float = 0.0, amplification: float = 1.0
) -> Conditioning:
    """Judge one mass matrix; ``scale`` is S (default |diag M|), ``angle`` the largest |θ|."""
    M = np.asarray(M, dtype=float)
    S = np.abs(np.diag(M)) if scale is None else np.asarray(scale, dtype=float)
    kappa_scaled, spread = scaled_kappas(M[None], S[None])
    bound, by_spread = bounds(kappa_scaled, spread, np.array([angle]), np.array([amplification]))
    return _verdict(_cond(M[None])[0], kappa_scaled[0], bound[0], spread[0], by_spread[0], amplification)


def _verdict(kappa_raw, kappa_scaled, bound, spread, by_spread, amplification) -> Conditioning:
    """The ``Conditioning`` of one matrix's figures (κ raw, ``scaled_kappas`` and ``bounds``)."""
    return Conditioning(
        float(kappa_raw),
        float(kappa_scaled),
        float(bound),
        _level(float(bound)),
        float(amplification),
        float(spread),
        bool(by_spread),
    )


class Verdicts:
    """The trust rule's verdict at each state of a batch (``pendverify.checks.batch.CheckBatch``).

    Three mass matrices are judged at each state — the closed form's M with the model's
    scale S, the same with Pinocchio's term amplification A, and Pinocchio's M with its own
    diagonal — and the verdict is the worst: the largest bound, then the largest κ raw, the
    first of equals.  Without a system only the first is judged.  ``verdicts[i]`` is state
    i's ``Conditioning``; ``worst(name)`` one of its figures at every state.  κ raw decides
    only between equal bounds, so it is computed only where it is asked for (``kappa_raw``).
    """

    def __init__(self, batch, with_system: bool = True):
        forms = batch.forms
        M_hand, S = forms.value("mass_matrix"), forms.value("diagonal_scale")
        n, angle = len(batch), batch.angle
        one = np.ones(n)
        hand = scaled_kappas(M_hand, S)
        candidates = [(M_hand, *hand, one)]
        if with_system:
            M_pin, A = batch.pin.mass_matrix(), batch.lever
            candidates.append((M_hand, *hand, A))
            candidates.append(
                (M_pin, *scaled_kappas(M_pin, np.abs(np.diagonal(M_pin, axis1=-2, axis2=-1))), A)
            )
        self._matrices = [c[0] for c in candidates]
        figures = [(kappa, *bounds(kappa, spread, angle, A), spread, A) for _, kappa, spread, A in candidates]
        names = ("kappa_scaled", "bound", "by_spread", "spread", "amplification")
        #: each figure of each candidate, (candidates, N)
        self.fields = {name: np.stack([f[k] for f in figures]) for k, name in enumerate(names)}
        bound = self.fields["bound"]
        best = np.zeros(n, dtype=int)
        for j in range(1, len(candidates)):
            b0 = np.choose(best, bound)
            with np.errstate(invalid="ignore"):
                later = (bound[j] > b0) | (np.isnan(bound[j]) & ~np.isnan(b0))
                tie = np.flatnonzero(bound[j] == b0)
            if tie.size:  # κ raw decides, computed at those states only
                later[tie] = self.kappa_raw(np.full(tie.size, j), tie) > self.kappa_raw(best[tie], tie)
            best = np.where(later, j, best)
        self.best = best
        self.bound = np.choose(best, bound)

    def kappa_raw(self, candidates: np.ndarray, states: np.ndarray) -> np.ndarray:
        """κ raw of candidate ``candidates[k]``'s matrix at state ``states[k]``, for each k."""
        out = np.empty(len(states))
        for j in np.unique(candidates):
            at = candidates == j
            out[at] = _cond(self._matrices[j][states[at]])
        return out

    def __len__(self) -> int:
        return len(self.best)

    def worst(self, name: str) -> np.ndarray:
        """Figure ``name`` (``kappa_raw``, ``kappa_scaled``, ``bound``, ``amplification``, …) of the
        verdict at each state."""
        if name == "kappa_raw":
            return self.kappa_raw(self.best, np.arange(len(self.best)))
        return np.choose(self.best, self.fields[name])

    def __getitem__(self, i: int) -> Conditioning:
        j = self.best[i]
        f = {name: field[j, i] for name, field in self.fields.items()}
        kappa_raw = self.kappa_raw(np.array([j]), np.array([i]))[0]
        return _verdict(
            kappa_raw, f["kappa_scaled"], f["bound"], f["spread"], f["by_spread"], f["amplification"]
        )


def assess(model, q, system=None) -> Conditioning:
    """The verdict on M(q) from the closed form and, if given, Pinocchio's CRBA and terms."""
    batch = CheckBatch(model, system, [state_at(model, q)])
    with np.errstate(all="ignore"):
        return Verdicts(batch, with_system=system is not None)[0]


def check_conditioning(
    model, q, system=None, what: str | None = None, verdict: Conditioning | None = None
) -> Conditioning:
    """``assess``, raising ``IllConditionedError`` when the verdict is ``refuse``.

    Returns the verdict when it is ``ok`` or ``warn`` (see ``Conditioning.note``).
    ``verdict``: ``assess(model, q, system)`` when already made (``Verdicts``).
    """
    verdict = assess(model, q, system) if verdict is None else verdict
    if verdict.level == "refuse":
        raise IllConditionedError(
            what or model.name,
            np.asarray(q, dtype=float).tolist(),
            verdict.kappa_scaled,
            verdict.bound,
            verdict.amplification,
            verdict.spread,
            verdict.by_spread,
            limit=REFUSE_REL,
        )
    return verdict
