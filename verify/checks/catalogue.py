"""The checks: one Pinocchio quantity against its closed form, on many states.

``CHECKS`` names each check, what it compares and its constant K; what it measures at
one state (error and scale) is in ``pendverify.checks.quantities``, which checks apply
to a model in ``pendverify.checks.applicability``, and the scaled coordinates the
errors are measured in (z_i = √S_i·θ_i) in ``pendverify.checks.scaling``.

Tolerance
---------
For each state the check computes the error e, a *scale* s (the size of the
terms that produced the quantity, including cancellation and, for inverses and
accelerations, the conditioning ‖M̃⁻¹‖) and passes when

    e ≤ K·ε·((1 + |θ|max)·c_T + (A − 1))·s + a,

where ε is machine epsilon, K the check's named constant, (1 + |θ|max) the
growth of rounding in angles as large as |θ| (cos(θ + 2πk) is only as exact as
θ is), c_T = cond₂(T)² the amplification of rounding that Pinocchio commits in
its own joint coordinates by the map to the model's (1 for the double
pendulum, 6.85 for the cart's relative joint), A ≥ 1 the factor by which
Pinocchio's world-frame terms exceed the result (``pendverify.checks.trust.
term_amplification``: a cart far along its rail, a light link at the end of a
long one), whose rounding adds to the angles' rather than multiplying it, and a
the known model-form allowance (zero unless the URDF lies outside the
closed form's family, see ``pendverify.robot.geometry``).  This is the one
tolerance model: ``pendverify stress``, the certification battery and the
simulator's checks call these checks as they are.  Reported: e/s and the
tolerance (K·ε·((1 + |θ|max)·c_T + (A − 1)) + a/s) at the worst state, the state
with the largest e / tolerance.  A state whose rounding term alone exceeds the
trust limit (``pendverify.checks.trust.REFUSE_REL``) is refused, not judged.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from pendverify.analytic import ClosedFormModel
from pendverify.checks import precision, quantities
from pendverify.checks.applicability import hand_written, needs_matrix_c, needs_urdf_damping
from pendverify.checks.quantities import Sample
from pendverify.checks.sampling import State
from pendverify.checks.scaling import world_lever
from pendverify.checks.trust import EPS, REFUSE_REL
from pendverify.checks.verdict import FAIL, PASS, REFUSED, WARN
from pendverify.robot.system import PinocchioSystem

__all__ = [
    "CHECKS",
    "CHECK_NAMES",
    "Check",
    "CheckResult",
    "applicable_checks",
    "not_applicable",
    "run_check",
    "run_checks",
    "skipped_notes",
]


@dataclass(frozen=True)
class Check:
    name: str
    pinocchio: str
    closed_form: str
    K: float
    evaluate: Callable[[ClosedFormModel, PinocchioSystem, State], Sample]
    #: "" when the check applies to this model and system, else why it is not run
    requires: Callable[[ClosedFormModel, PinocchioSystem | None], str] = lambda model, system: ""
    #: whether the Pinocchio side is computed by its world-frame recursions (then A counts)
    world_frame: bool = True


@dataclass
class CheckResult:
    """The evidence of one check on one model: errors, tolerance, where it was worst."""

    model: str
    check: str
    description: str
    max_error: float
    tolerance: float
    max_abs_error: float
    samples: int
    seed: int
    worst_state: dict
    passed: bool
    #: the largest relative error over the judged states, and where (the worst *ratio* is above)
    largest_error: float = float("nan")
    largest_tolerance: float = float("nan")  # the tolerance at that state
    largest_state: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    #: pass, warn, fail or refused (``pendverify.checks.verdict``); ``passed`` is pass or warn
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = PASS if self.passed else FAIL

    def as_dict(self) -> dict:
        return dict(self.__dict__)


CHECKS: tuple[Check, ...] = (
    Check("crba", "crba (symmetrised)", "M(q)", 8, quantities.crba),
    Check("rnea", "rnea(q, q̇, 0)", "C(q,q̇)·q̇ + H(q), friction removed", 16, quantities.rnea),
    Check("gravity", "computeGeneralizedGravity", "H(q)", 16, quantities.gravity),
    Check(
        "coriolis",
        "computeCoriolisMatrix",
        "C(q,q̇) without friction",
        16,
        quantities.coriolis,
        needs_matrix_c,
    ),
    Check("skew", "Ṁ (RNEA derivatives) − 2C", "skew-symmetric", 16, quantities.skew, needs_matrix_c),
    Check(
        "det",
        "det(crba) by LU",
        "closed-form det M(q) > 0",
        16,
        quantities.det,
        hand_written("det_mass_matrix"),
    ),
    Check(
        "minverse",
        "computeMinverse",
        "M(q)⁻¹ (closed form)",
        16,
        quantities.minverse,
        hand_written("inverse_mass_matrix"),
    ),
    Check("aba", "aba(q, q̇, Bu + Ww − Dq̇)", "closed-form q̈ (f + g·u, M⁻¹f)", 16, quantities.aba),
    Check("energy", "kinetic + potential energy", "½q̇ᵀMq̇, V(q) − V(0)", 16, quantities.energy),
    # Tᵀ·diag(b)·T: each entry a sum of at most n products of exact decimals' roundings
    Check(
        "damping", "<dynamics damping> (Tᵀ·diag(b)·T)", "D", 8, quantities.damping, needs_urdf_damping, False
    ),
)
CHECK_NAMES = tuple(c.name for c in CHECKS)


@dataclass(frozen=True)
class _Judged:
    """One state judged: relative error and tolerance, the absolute error, a note."""

    rel_err: float
    rel_tol: float
    abs_err: float
    note: str = ""

    @property
    def ratio(self) -> float:
        return self.rel_err / self.rel_tol if np.isfinite(self.rel_err) else np.inf


#: what evaluating a state raises when its numbers leave double's range (parameters of 1e200)
OUT_OF_RANGE = (OverflowError, FloatingPointError, np.linalg.LinAlgError)


def _judge(check: Check, model, system, state: State, rounding: float) -> _Judged:
    sample = check.evaluate(model, system, state)
    if sample.scale > 0:
        rel_tol = rounding + sample.allowance / sample.scale
        rel_err = sample.error / sample.scale
    else:  # nothing acts (at rest with g = 0): any error at all is a failure
        rel_tol = rounding
        rel_err = 0.0 if sample.error == 0 else np.inf
    note = sample.note or ("NaN" if np.isnan(rel_err) else "")
    return _Judged(np.inf if np.isnan(rel_err) else float(rel_err), float(rel_tol), float(sample.error), note)


def _rejudge_precisely(check: Check, model, system, failing) -> tuple[dict[int, _Judged], str]:
    """Failing states judged again with the closed forms in high precision (``checks.precision``).

    Worst first; stops at the first state that still fails.  Returns {index: judged}
    for the states that pass so (all of them, or the check still fails) and why not.
    """
    try:
        precise = precision.precise_model(model)
    except precision.PrecisionUnavailable as exc:
        return {}, str(exc)
    passed = {}
    for i, state, rounding, _ in sorted(failing, key=lambda f: -f[3].ratio):
        try:
            judged = _judge(check, precise, system, state, rounding)
        except precision.PrecisionUnavailable as exc:
            return passed, str(exc)
        if not judged.ratio <= 1.0:
            return passed, ""
        passed[i] = judged
    return passed, ""


def run_check(check: Check, label: str, model, system, states, seed: int) -> CheckResult:
    """Evaluate one check on every state and keep the evidence of the worst one.

    A state whose own rounding tolerance K·ε·((1 + |θ|)·c_T + (A − 1)) exceeds the
    trust limit (``trust.REFUSE_REL``) is not judged: a tolerance that wide would
    pass a 1 ppm modelling error.  The check is then ``refused`` (unless another
    state fails), whatever the guard before it let through.  Failing states are
    judged again with the hand-written closed forms evaluated in high precision
    (``pendverify.checks.precision``): if all then pass, the check is a warning.
    """
    c_T = system.cmap.amplification
    notes: list[str] = []
    refused: list[tuple[State, float]] = []
    judged: list[tuple[int, State, float, _Judged]] = []
    for i, state in enumerate(states):
        angle = float(np.max(np.abs(state.q[np.array(model.angular)]), initial=0.0))
        lever = world_lever(model, system, state.q) if check.world_frame else 1.0
        rounding = check.K * EPS * ((1.0 + angle) * c_T + (lever - 1.0))
        if not rounding <= REFUSE_REL:
            refused.append((state, rounding))
            continue
        try:
            j = _judge(check, model, system, state, rounding)
        except OUT_OF_RANGE as exc:  # terms beyond double's range: nothing can be verified there
            refused.append((state, np.inf))
            notes.append(f"{state.label}: refused: its terms overflow double ({type(exc).__name__}: {exc})")
            continue
        if j.note and len(notes) < 3:
            notes.append(f"{state.label}: {j.note}")
        judged.append((i, state, rounding, j))
    max_abs = max((j.abs_err for *_, j in judged), default=0.0)
    status = ""
    failing = [f for f in judged if not f[3].ratio <= 1.0]
    if failing:
        precise, why = _rejudge_precisely(check, model, system, failing)
        if len(precise) == len(failing):
            i, state, _, double = max(failing, key=lambda f: f[3].ratio)
            notes.insert(0, _unstable_note(check, state, double, precise[i], len(failing), len(judged)))
            judged = [(k, s, r, precise.get(k, j)) for k, s, r, j in judged]
            status = WARN
        elif why:
            notes.append(f"not judged in high precision: {why}")
    worst_ratio, worst = -1.0, None
    for _, state, _, j in judged:
        if j.ratio > worst_ratio:
            worst_ratio, worst = j.ratio, (state, j.rel_err, j.rel_tol)
    largest = max(judged, key=lambda f: f[3].rel_err, default=None)
    if refused:
        state, rounding = refused[0]
        lever = world_lever(model, system, state.q)
        notes.insert(
            0,
            f"{len(refused)} of {len(states)} states refused: at {state.label} the rounding tolerance "
            f"{rounding:.2g} exceeds the trust limit {REFUSE_REL:g} (Pinocchio's terms {lever:.2g}× the "
            "result)",
        )
        if worst is None:
            worst = (state, float("nan"), rounding)
        if worst_ratio <= 1.0:
            status = REFUSED
    state, rel_err, rel_tol = worst
    return CheckResult(
        model=label,
        check=check.name,
        description=f"{check.pinocchio} vs {check.closed_form}",
        max_error=float(rel_err),
        tolerance=float(rel_tol),
        max_abs_error=max_abs,
        samples=len(states),
        seed=seed,
        worst_state=state.as_dict(),
        largest_error=float(largest[3].rel_err) if largest else float("nan"),
        largest_tolerance=float(largest[3].rel_tol) if largest else float("nan"),
        largest_state=largest[1].as_dict() if largest else {},
        passed=bool(worst_ratio <= 1.0) and not refused,
        notes=notes,
        status=status,
    )


def _unstable_note(check: Check, state: State, double: _Judged, precise: _Judged, n: int, of: int) -> str:
    return (
        f"{precision.UNSTABLE} at {n} of {of} states: at {state.label} {check.name} is off by "
        f"{double.rel_err:.2g} in double ({double.ratio:.3g}× its tolerance {double.rel_tol:.2g}) and by "
        f"{precise.rel_err:.2g} with the hand-written closed forms evaluated to {precision.DIGITS} digits"
    )


def not_applicable(model, system=None) -> dict[str, str]:
    """{check: why it is not run} for the checks this model (and URDF, if given) cannot take."""
    reasons = {c.name: c.requires(model, system) for c in CHECKS}
    return {name: why for name, why in reasons.items() if why}


def skipped_notes(model, system=None) -> list[str]:
    """One note per reason some checks are not run: "coriolis, skew not run: …"."""
    by_reason: dict[str, list[str]] = {}
    for name, why in not_applicable(model, system).items():
        by_reason.setdefault(why, []).append(name)
    return [f"{', '.join(names)} {why}" for why, names in by_reason.items()]


def applicable_checks(model, system=None) -> tuple[str, ...]:
    """The checks a model (and its URDF, if given) can take, in the table's order."""
    skipped = not_applicable(model, system)
    return tuple(name for name in CHECK_NAMES if name not in skipped)


def run_checks(label, model, system, states, seed, names=CHECK_NAMES) -> list[CheckResult]:
    """The named checks that apply to ``model`` and ``system``, each on every state."""
    names = set(names) & set(applicable_checks(model, system))
    return [run_check(c, label, model, system, states, seed) for c in CHECKS if c.name in names]
