"""When an edited model counts as repaired: the checks' own verdict, against the model's baseline.

A repair is confirmed when the edited model passes every applicable check on every state
(``pendverify.diagnosis.repair``) — *passes* as ``pendverify check`` judges it, warnings
included.  One warning concerns the written closed forms themselves: a matrix C whose product
C·q̇ is right but which is not the Christoffel C (Tedrake's acrobot, many textbooks) fails
``coriolis`` and, when Ṁ − 2C is not skew-symmetric, ``skew`` — the two checks that compare C
itself — and ``pendverify.checks.verdict.non_christoffel_c`` demotes them to warnings when every
other check passes.  Such a model's untouched form is therefore a pass with that warning, and
an edit of it is repaired when the edited model is back there: those two checks warn, nothing
worse, and the C as written is such a C (``accepted``).  Requiring ``coriolis`` and ``skew`` to
pass outright would leave every error planted in such a model without a repair, as no edit of
one entry makes its C the Christoffel one.  Edits that make every check pass are preferred: the
repair search asks for the baseline only when none does (``pendverify.diagnosis.repair``).

``matrix_c_note`` says so next to a repair: whether the repaired model's C still differs from
Pinocchio's Coriolis matrix at the screening states.  The comparison is relative to the size
of the two matrices, with ``SCREEN_RTOL`` (``pendverify.diagnosis.slots``: far above rounding,
far below any edit).
"""

from __future__ import annotations

import numpy as np

from pendverify.analytic.symbolic_reading import entries
from pendverify.checks.verdict import MATRIX_C_CHECKS, non_christoffel_c
from pendverify.diagnosis.slots import SCREEN_RTOL, evaluator


def passes(results) -> bool:
    """Whether check results pass as ``pendverify check`` judges them: every check passes, the
    checks that compare C itself demoted to warnings first when C·q̇ is right.  ``results`` are
    judged in place, as ``pendverify check`` judges its rows."""
    non_christoffel_c(results)
    return all(r.passed for r in results)


def accepted(results, batch, sm, changes: dict, baseline: bool = False) -> bool:
    """Whether an edited model's check results make ``changes`` a repair (module docstring): every
    check passes; or, with ``baseline``, the model passes with the warning of a C that is not the
    Christoffel C and an entry of C the repair leaves alone differs from Pinocchio's.  (A valid C
    that is not the Christoffel one differs in two entries of a row at least: one entry alone
    cannot differ with the row's product with q̇ right, so one edit never hides that.)  The
    repair search asks for ``baseline`` only when no edit makes every check pass: a model whose
    C is the Christoffel one save for an error is repaired back to it where an edit does that."""
    if all(r.passed for r in results):
        return True
    return baseline and passes(results) and bool(_differing_c_entries(batch, sm, changes))


def written_c_differs(batch, sm) -> bool:
    """Whether an entry of the written C differs from Pinocchio's Coriolis matrix (``batch``'s states)."""
    return bool(_differing_c_entries(batch, sm, {}))


def _differing_c_entries(batch, sm, changes: dict, edited: bool = False) -> list[int]:
    """The entries of the written C (row-major) that differ from Pinocchio's Coriolis matrix at the
    states of ``batch``, relative to the size of the two: those ``changes`` leaves alone, or
    (``edited``) every entry of the C ``changes`` makes."""
    forms = type(batch.model).closed_forms
    if "coriolis_matrix" not in sm.closed_forms or forms["coriolis_matrix"].equals:
        return []
    params = [float(getattr(batch.model.params, p)) for p in sm.parameters]
    evaluate = evaluator(sm, {"q": batch.Q, "v": batch.V, "u": batch.U, "w": batch.W}, params)
    written = entries(sm.closed_forms["coriolis_matrix"])
    if edited:
        written = [changes.get(("coriolis_matrix", i), (None, e))[1] for i, e in enumerate(written)]
    pin = np.asarray(batch.terms.C_pin, dtype=float).reshape(len(batch), len(written))
    with np.errstate(all="ignore"):
        hand = np.stack([evaluate(e, forms["coriolis_matrix"].args) for e in written], axis=-1)
    size = float(np.max(np.abs(pin), initial=0.0) + np.max(np.abs(hand), initial=0.0)) or 1.0
    return [
        i
        for i in range(len(written))
        if (edited or ("coriolis_matrix", i) not in changes)
        and not np.max(np.abs(hand[:, i] - pin[:, i]), initial=0.0) <= SCREEN_RTOL * size  # nan differs
    ]


def matrix_c_note(screening, sm, changes: dict) -> str:
    """The note a repair carries when the repaired model's matrix C is not Pinocchio's at the
    ``screening`` states (``coriolis`` and ``skew`` warn, as they do for the model as written),
    else ""."""
    if not _differing_c_entries(screening, sm, changes, edited=True):
        return ""
    return (
        f"{' and '.join(MATRIX_C_CHECKS)} still warn, as for the model as written: its C is a valid C·q̇, "
        "not the Christoffel C"
    )
