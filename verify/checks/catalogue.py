"""The checks: one Pinocchio quantity against its closed form, on many states.

``Check`` is what a check is; what it reports is an ``Evidence`` (``pendverify.checks.evidence``).
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

``run_check`` and ``run_checks`` evaluate a check over all states at once: one
``pendverify.checks.batch.CheckBatch`` holds the states and every quantity the checks
share, ``pendverify.checks.judge.collect`` forms the tolerance above as arrays and
``pendverify.checks.judge.conclude`` draws the verdict.  One state is the batch of one.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pendverify.checks import quantities
from pendverify.checks.applicability import (
    hand_written,
    needs_mass_matrix,
    needs_mass_matrix_and,
    needs_matrix_c,
    needs_potential_energy,
    needs_urdf_damping,
)
from pendverify.checks.batch import CheckBatch
from pendverify.checks.evidence import Evidence
from pendverify.checks.judge import collect, conclude

if TYPE_CHECKING:
    from pendverify.analytic import ClosedFormModel
    from pendverify.checks.quantities import Measure, Terms
    from pendverify.robot.system import PinocchioSystem

__all__ = [
    "CHECKS",
    "CHECK_NAMES",
    "Check",
    "applicable_checks",
    "not_applicable",
    "run_check",
    "run_checks",
    "skipped_notes",
]


@dataclass(frozen=True)
class Check:
    """One comparison: a Pinocchio quantity against its closed form, judged with the constant K."""

    name: str
    pinocchio: str
    closed_form: str
    K: float
    #: the check's measure at every state of a batch (``pendverify.checks.quantities``)
    measure: Callable[[Terms], Measure]
    #: "" when the check applies to this model and system, else why it is not run
    requires: Callable[[ClosedFormModel, PinocchioSystem | None], str] = lambda model, system: ""
    #: whether the Pinocchio side is computed by its world-frame recursions (then A counts)
    world_frame: bool = True


CHECKS: tuple[Check, ...] = (
    Check("crba", "crba (symmetrised)", "M(q)", 8, quantities.measure_crba, needs_mass_matrix),
    Check(
        "rnea",
        "rnea(q, q̇, 0)",
        "C(q,q̇)·q̇ + H(q), friction removed",
        16,
        quantities.measure_rnea,
        needs_mass_matrix,
    ),
    Check("gravity", "computeGeneralizedGravity", "H(q)", 16, quantities.measure_gravity, needs_mass_matrix),
    Check(
        "coriolis",
        "computeCoriolisMatrix",
        "C(q,q̇) without friction",
        16,
        quantities.measure_coriolis,
        needs_mass_matrix_and(needs_matrix_c),
    ),
    Check(
        "skew",
        "Ṁ (RNEA derivatives) − 2C",
        "skew-symmetric",
        16,
        quantities.measure_skew,
        needs_mass_matrix_and(needs_matrix_c),
    ),
    Check(
        "det",
        "det(crba) by LU",
        "closed-form det M(q) > 0",
        16,
        quantities.measure_det,
        needs_mass_matrix_and(hand_written("det_mass_matrix")),
    ),
    Check(
        "minverse",
        "computeMinverse",
        "M(q)⁻¹ (closed form)",
        16,
        quantities.measure_minverse,
        needs_mass_matrix_and(hand_written("inverse_mass_matrix")),
    ),
    Check("aba", "aba(q, q̇, Bu + Ww − Dq̇)", "closed-form q̈ (f + g·u, M⁻¹f)", 16, quantities.measure_aba),
    Check(
        "energy",
        "kinetic + potential energy",
        "½q̇ᵀMq̇, V(q) − V(0)",
        16,
        quantities.measure_energy,
        needs_mass_matrix_and(needs_potential_energy),
    ),
    # Tᵀ·diag(b)·T: each entry a sum of at most n products of exact decimals' roundings
    Check(
        "damping",
        "<dynamics damping> (Tᵀ·diag(b)·T)",
        "D",
        8,
        quantities.measure_damping,
        needs_urdf_damping,
        False,
    ),
)
CHECK_NAMES = tuple(c.name for c in CHECKS)


def run_check(check: Check, label: str, model, system, states, seed: int, batch=None) -> Evidence:
    """One check on every state, evaluated over all states at once.

    A state whose own rounding tolerance K·ε·((1 + |θ|)·c_T + (A − 1)) exceeds the trust
    limit (``trust.REFUSE_REL``) is not judged: a tolerance that wide would pass a 1 ppm
    modelling error.  The check is then ``refused`` (unless another state fails).  Failing
    states are judged again with the hand-written closed forms evaluated in high precision
    (``pendverify.checks.precision``): if all then pass, the check is a warning.
    ``batch``: a ``CheckBatch`` of these states to share with other checks (``run_checks``).
    """
    if batch is None:
        batch = CheckBatch(model, system, states)
    return conclude(check, label, batch, seed, collect(check, batch))


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


def run_checks(label, model, system, states, seed, names=CHECK_NAMES, batch=None) -> list[Evidence]:
    """The named checks that apply to ``model`` and ``system``, each on every state.

    The checks share one batch of the states (``batch``, if given, must hold these states).
    """
    names = set(names) & set(applicable_checks(model, system))
    if batch is None:
        batch = CheckBatch(model, system, states)
    return [run_check(c, label, model, system, states, seed, batch) for c in CHECKS if c.name in names]
