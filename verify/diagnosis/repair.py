"""The repair: a single edit of the model's own expressions after which every check passes.

1. **Where**: the entries of the written closed forms that disagree with Pinocchio, the
   *slots* (``pendverify.diagnosis.slots``).
2. **What**: per slot, the edits that make it agree at the screening states
   (``pendverify.diagnosis.candidates``: the inverses of ``pendverify mutate``'s operators,
   coefficients and added terms solved for), ordered simplest first.
3. **Confirmed**: a candidate becomes a repair only when the edited model
   (``pendverify.symbolic.edited``) passes every applicable check on every state of the
   report's batch; candidates are confirmed simplest first, at most ``CONFIRMATIONS`` of
   them, within the time bound.  Once one is confirmed, other simple edits of the same entries
   are confirmed too (up to ``ALTERNATIVES``) and shown as alternatives: with the given
   parameter values two edits can give the same numbers (m = 2·m2 makes m2 → m the same as a
   factor 2), and the checks cannot tell which one the derivation meant.  When no single edit
   passes, pairs of edits of one entry are tried for models of up to three degrees of freedom.

The repair is printed in the model's own notation, where it sits
(``pendverify.diagnosis.notation``).
"""

from __future__ import annotations

import time

import numpy as np
import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.candidates import (
    RANK,
    candidates,
    monomials_for,
    pairs_within,
    screen_slot,
    sum_pool,
)
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.notation import Notation
from pendverify.diagnosis.slots import QUANTITY, SCREEN_STATES, Slot, entry_label, evaluator, find_slots
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.edits import Edit

CONFIRMATIONS = 12
#: pairs of edits of one entry are tried for models of up to this many degrees of freedom
PAIRS_UP_TO_DOF = 3
#: confirmed edits of the same entries shown besides the first: parameter values can make two
#: edits give the same numbers (a parameter worth twice another, a 3·I = m·r²)
ALTERNATIVES = 2


def _confirmed(batch, sm, changes: dict) -> bool:
    edits: dict[str, list] = {}
    for (method, index), (old, new) in changes.items():
        edits.setdefault(method, []).append((index, old, new))
    repaired = edited_model(batch.model, sm, edits, "Repaired")
    names = applicable_checks(repaired, batch.system)
    with np.errstate(all="ignore"):
        try:
            results = run_checks("repair", repaired, batch.system, batch.states, 0, names)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError):
            return False
    return all(r.passed for r in results)


def search_repair(batch, deadline_s: float) -> tuple[list[Finding], str]:
    """The confirmed repair of a failing model as findings, and what the search did, in words."""
    start = time.perf_counter()
    deadline = start + deadline_s
    try:
        sm = SymbolicModel.of(type(batch.model))
        forms = sm.closed_forms
    except Exception as exc:
        return [], f"no repair searched: SymPy cannot read the model ({type(exc).__name__})"
    screening = batch.subset(range(min(SCREEN_STATES, len(batch))))
    params = {p: float(getattr(batch.model.params, p)) for p in sm.parameters}
    evaluate = evaluator(
        sm, {"q": screening.Q, "v": screening.V, "u": screening.U, "w": screening.W}, list(params.values())
    )
    slots = find_slots(screening, sm)
    if not slots:
        return [], "no single entry of the written closed forms disagrees with Pinocchio: no repair searched"
    pool = sum_pool(sm)
    monomials: dict[str, list] = {}
    for slot in slots:
        quantity = QUANTITY.get(slot.method, "")
        if quantity not in monomials:
            monomials[quantity] = monomials_for(sm, params, quantity)
        screen_slot(slot, screening, sm, evaluate, monomials[quantity], pool, deadline)
    notation = Notation.of(type(batch.model))
    found, tried = _confirm(batch, sm, candidates(slots), deadline)
    pairs = not found and batch.model.nv <= PAIRS_UP_TO_DOF and len(slots) <= 2
    if pairs:  # two edits of one entry
        within = [
            (RANK["pair"], {(slot.method, slot.index): (slot.expr, edit.expr)}, edit, slot)
            for slot in slots
            for edit in pairs_within(slot, sm, evaluate, pool, deadline)
        ]
        found, more = _confirm(batch, sm, within, deadline)
        tried += more
    if found:
        findings = _findings(*found[0], forms, notation)
        for changes, edit, slot in found[1:]:
            findings += _findings(changes, edit, slot, forms, notation, alternative=True)
        return findings, ""
    where = ", ".join(s.label for s in slots[:6]) + (f" and {len(slots) - 6} more" if len(slots) > 6 else "")
    bound = " (the search stopped at its time bound)" if time.perf_counter() > deadline else ""
    also = " nor two edits of one entry," if pairs else ""
    return [], (
        f"no repair: no single edit of {where} (nor one edit of each, for two entries,{also}) makes every "
        f"check pass; {tried} candidate(s) tried against every check{bound}"
    )


def _confirm(batch, sm, ordered, deadline: float) -> tuple[list, int]:
    """The candidates (in order) that every check confirms: the first, then alternatives of the
    same entries (module docstring); and how many were tried."""
    tried, found, seen = 0, [], set()
    for rank, changes, edit, slot in ordered:
        if time.perf_counter() > deadline or tried >= CONFIRMATIONS or len(found) > ALTERNATIVES:
            break
        if found and rank > RANK["scale"] and rank != RANK["pair"]:
            break  # an alternative is a simple edit, not a shift or a fitted term that happens to fit
        key = tuple(sorted((m, i, str(new)) for (m, i), (_, new) in changes.items()))
        if key in seen or (found and set(changes) != set(found[0][0])):
            continue  # the same edit again, or (once one is found) an edit of other entries
        seen.add(key)
        tried += 1
        if _confirmed(batch, sm, changes):
            found.append((changes, edit, slot))
    return found, tried


def _findings(changes: dict, edit: Edit, slot: Slot, forms: dict, notation, alternative: bool = False):
    """The ``repair`` findings of one confirmed edit (one per entry it changes)."""
    out = []
    for (method, index), (old, new) in changes.items():
        label = entry_label(method, forms[method], index)
        written, suggested = notation.render(old), notation.render(new)
        location = notation.location(method, label)
        shown = (
            f"{written} → {suggested}"
            if len(written) + len(suggested) <= 160
            else f"{notation.render(edit.old)} → {notation.render(edit.new)} in {label}"
        )
        if edit.operator == "pair":
            shown += f" (two edits: {edit.what})"
        message = f"{label}: {shown} makes every check pass on every state ({location})"
        if alternative:
            message = (
                f"or, equally: {message} (with these parameter values the checks cannot tell the two apart)"
            )
        quantity = QUANTITY.get(method)
        value = forms[method]
        if isinstance(value, sp.MatrixBase):
            r, c = divmod(index, value.shape[1])
            position = (r + 1,) if value.shape[1] == 1 else (r + 1, c + 1)
        else:
            position = ()
        out.append(
            Finding(
                "repair",
                message,
                quantity,
                position,
                {
                    "written": str(old),
                    "suggested": str(new),
                    "suggested_source": suggested,
                    "location": location,
                    "checks_pass": True,
                },
            )
        )
    return out
