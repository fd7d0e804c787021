"""Verdict levels, and the rules that move a check between them.

Every piece of evidence (``pendverify.checks.evidence``: a check result, an invariant, a
stress case, a battery item), and so every target and report, has one of these levels:

``pass``
    the error is within its tolerance on every state.
``warn``
    right where it matters, with something the user must know.  Three cases:
    a matrix C whose product C·q̇ is right (``rnea``, ``aba``, ``energy`` and
    every other check pass) but which is not the Christoffel C, so that
    ``coriolis`` and, when Ṁ − 2C is not skew-symmetric, ``skew`` differ from
    Pinocchio's; a URDF that carries what the hand model has no term for
    (Coulomb ``<dynamics friction>``); and closed forms that agree with Pinocchio
    only when evaluated in high precision (``pendverify.checks.precision``).
    ``--strict`` turns warnings into failures.
``fail``
    the error exceeds its tolerance: the hand model and the URDF disagree.
``refused``
    some state lies beyond the trust limit of ``pendverify.checks.trust``:
    rounding alone could exceed a relative 1e-6 there, so agreement would prove
    nothing and disagreement could be rounding.  Nothing is compared there.
``not run``
    the comparison does not apply (a stress case with no parameter to vary); never
    ranked among the others, as a check that does not apply has no result.

A target's level is its worst result's (fail > refused > warn > pass).  The
exit status of ``pendverify check`` is 0 for pass and warn (1 for warn with
``--strict``) and 1 for fail and refused: a refusal is not a verification.
"""

from __future__ import annotations

PASS, WARN, FAIL, REFUSED, NOT_RUN = "pass", "warn", "fail", "refused", "not run"
VERDICTS = (PASS, WARN, FAIL, REFUSED, NOT_RUN)
SEVERITY = {PASS: 0, WARN: 1, REFUSED: 2, FAIL: 3}
LABELS = {PASS: "pass", WARN: "pass (warn)", FAIL: "FAIL", REFUSED: "refused"}

#: The checks that compare the matrix C itself rather than its product C·q̇.
MATRIX_C_CHECKS = ("coriolis", "skew")
#: The checks that must pass for a differing C to be "a valid C·q̇".
BIAS_CHECKS = ("rnea", "aba", "energy")

#: One sentence for one finding, shared by ``check``, ``sympy`` and ``mutate``.
NON_CHRISTOFFEL = "a valid C·q̇, not the Christoffel C: Ṁ − 2C is not skew-symmetric"
CHRISTOFFEL_CONSISTENT = (
    "a valid C·q̇ with Ṁ − 2C skew-symmetric, but not the Christoffel C: a Christoffel-consistent "
    "factorisation"
)


def worst(levels) -> str:
    """The most severe of some levels (``pass`` for none)."""
    return max(levels, key=SEVERITY.__getitem__, default=PASS)


def non_christoffel_c(results) -> str:
    """Demote ``coriolis``/``skew`` failures to warnings when C·q̇ is right; return the sentence or "".

    C·q̇ is right when ``rnea``, ``aba`` and ``energy`` ran and every check other
    than the two that compare C itself passes.  A C·q̇ that is wrong fails
    ``rnea`` and keeps every failure.
    """
    by_name = {r.name: r for r in results}
    differing = [by_name[n] for n in MATRIX_C_CHECKS if n in by_name and by_name[n].status == FAIL]
    others = [r for r in results if r.name not in MATRIX_C_CHECKS]
    if (
        not differing
        or not all(n in by_name for n in BIAS_CHECKS)
        or not all(r.status in (PASS, WARN) for r in others)
    ):
        return ""
    skew = by_name.get("skew")
    finding = NON_CHRISTOFFEL if skew is not None and skew.status == FAIL else CHRISTOFFEL_CONSISTENT
    sizes = "; ".join(
        f"{r.name}: {r.error:.3g} relative ({r.ratio:.3g}× its tolerance, "
        f"{r.extras['max_abs_error']:.3g} absolute)"
        for r in differing
    )
    for r in differing:
        r.status = WARN
    return (
        f"{finding} — C differs from Pinocchio's Coriolis matrix by {sizes}; "
        "C·q̇ agrees (rnea, aba, energy pass)"
    )


def apply_strict(results) -> None:
    """``--strict``: every warning becomes a failure."""
    for r in results:
        if r.status == WARN:
            r.status = FAIL
