"""The repair: a single edit of the model's own expressions after which every check passes.

1. **Where**: the entries of the written closed forms that disagree with Pinocchio, the
   *slots* (``pendverify.diagnosis.slots``).
2. **What**: per slot, the edits that make it agree at the screening states
   (``pendverify.diagnosis.candidates``: the inverses of ``pendverify mutate``'s operators,
   coefficients and added terms solved for), ordered simplest first.
3. **Confirmed**: a candidate becomes a repair only when the edited model
   (``pendverify.symbolic.edited``) passes every applicable check on every state of the
   report's batch; candidates are confirmed simplest first, at most ``CONFIRMATIONS`` of
   them, within the time bound.  Once one is confirmed, the next simple edits (of
   this entry or another, ``ALTERNATIVE_TRIES`` of them) are confirmed too and the ones that
   pass are shown as alternatives (up to ``ALTERNATIVES``): with the given parameter values two
   edits can give the same numbers (m = 2·m2 makes m2 → m the same as a factor 2), and an error
   in B shows as well in a hand-written q̈ that uses it; the checks cannot tell which one the
   derivation meant.  When no single edit
   passes, pairs of edits of one entry are tried for models of up to three degrees of freedom.
   When still none passes and the written C is not Pinocchio's, the screened edits are confirmed
   again against the model's own baseline: the warning of a C that is a valid C·q̇ but not the
   Christoffel C, nothing worse (``pendverify.diagnosis.acceptance``).  Then, for models of up
   to three degrees of freedom, one edit of each of two entries that each passed their own
   screen (``cross_pairs``): two errors in different keys, one in M and one in C.

The repair is printed in the model's own notation, where it sits
(``pendverify.diagnosis.notation``).  A key the model derives from another (H = ∂V/∂q of a text
model that writes V) is not repaired: an edit of its source is confirmed with it derived again
(``pendverify.diagnosis.derived``), and only the source's edit is printed.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.acceptance import accepted, matrix_c_note, written_c_differs
from pendverify.diagnosis.candidates import (
    RANK,
    candidates,
    cross_pairs,
    monomials_for,
    pairs_within,
    screen_slot,
    slot_pairs,
    sum_pool,
)
from pendverify.diagnosis.derived import derived_methods, with_derived
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.notation import TEXT_KEYS, Notation
from pendverify.diagnosis.slots import QUANTITY, SCREEN_STATES, Slot, entry_label, evaluator, find_slots
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.edits import Edit

CONFIRMATIONS = 12
#: pairs of edits of one entry are tried for models of up to this many degrees of freedom
PAIRS_UP_TO_DOF = 3
#: confirmed edits shown besides the first: parameter values can make two edits give the same
#: numbers (a parameter worth twice another, a 3·I = m·r²)
ALTERNATIVES = 2
#: candidates confirmed after the first repair, looking for alternatives (of this entry or
#: another: an error in B shows as well in a q̈ that uses B, and either edit passes)
ALTERNATIVE_TRIES = 4
#: how long the search for alternatives goes on after the first repair
ALTERNATIVE_SECONDS = 2.0


def _confirmed(batch, sm, changes: dict, baseline: bool = False) -> bool:
    """Whether the model with ``changes`` passes every applicable check on every state of ``batch``
    (``baseline``: or is back to the model's own warning, ``pendverify.diagnosis.acceptance``)."""
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
    return accepted(results, batch, sm, changes, baseline)


def _groups(slots: list[Slot], n: int) -> list[list[Slot]]:
    """The slots in the order they are screened, shortest first, each alone but for the entries of
    one row of a Coriolis-type matrix: those are screened together and their candidates confirmed
    simplest first, since only the row's product with q̇ is compared and an added term in one
    entry can make up for a swapped angle in the other."""
    groups: dict = {}
    for slot in sorted(slots, key=lambda s: sp.count_ops(s.expr)):
        row = slot.index // n if slot.row is not None else slot.index  # a Coriolis row form is n × n
        groups.setdefault((slot.method, slot.row is not None, row), []).append(slot)
    return list(groups.values())


def search_repair(batch, deadline_s: float) -> tuple[list[Finding], str]:
    """The confirmed repair of a failing model as findings, and what the search did, in words.

    The slots are screened shortest first, and each one's candidates are confirmed before the
    next is screened, so that a long entry (an M⁻¹ written with det M inside) does not use the
    time a short one needed.  Once a repair is found, the other slots are screened for
    alternatives for at most ``ALTERNATIVE_SECONDS``."""
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
    derived = derived_methods(type(batch.model))  # never repaired: derived again from their source
    if derived and all(s.method in derived for s in slots):
        sources = sorted({TEXT_KEYS.get(derived[s.method], derived[s.method]) for s in slots})
        return [], (
            f"no repair: the entries that disagree ({', '.join(s.label for s in slots)}) are derived "
            f"from {', '.join(sources)}, which agrees with Pinocchio"
        )
    slots = [s for s in slots if s.method not in derived]

    def run(confirmation, ordered) -> None:  # each candidate with its derived keys derived again
        confirmation.run((r, with_derived(c, sm, derived), e, s) for r, c, e, s in ordered)

    pool = sum_pool(sm)
    monomials: dict[str, tuple] = {}
    confirm = _Confirmation(batch, sm, deadline)
    screened = []
    for group in _groups(slots, batch.model.nv):
        for slot in group:
            if time.perf_counter() > min(deadline, confirm.alternatives_until):
                break
            quantity = QUANTITY.get(slot.method, "")
            if quantity not in monomials:
                monomials[quantity] = monomials_for(sm, params, quantity)
            screen_slot(slot, screening, sm, evaluate, monomials[quantity], pool, deadline)
            screened.append(slot)
        run(confirm, candidates(slots, [s for s in group if any(s is x for x in screened)]))
        if time.perf_counter() > min(deadline, confirm.alternatives_until):
            break
    if not confirm.found and len(slots) == 2 and len(screened) == 2:  # one edit of each entry
        run(confirm, slot_pairs(*slots))
    pairs = not confirm.found and batch.model.nv <= PAIRS_UP_TO_DOF and len(slots) <= 2
    if pairs:  # two edits of one entry
        run(
            confirm,
            (
                (RANK["pair"], {(slot.method, slot.index): (slot.expr, edit.expr)}, edit, slot)
                for slot in slots
                for edit in pairs_within(slot, sm, evaluate, pool, deadline)
            ),
        )
    tried = 0  # by the passes before
    if not confirm.found and time.perf_counter() < deadline and written_c_differs(batch, sm):
        # no edit makes every check pass; the written C is not Pinocchio's: the screened edits
        # again, a repair now one that is back to that C's warning (acceptance)
        tried, confirm = confirm.tried, _Confirmation(batch, sm, deadline, baseline=True)
        run(confirm, candidates(slots, screened))
        if not confirm.found and len(slots) == 2 and len(screened) == 2:
            run(confirm, slot_pairs(*slots))
    crossed = not confirm.found and batch.model.nv <= PAIRS_UP_TO_DOF and len(screened) > 2
    if crossed:  # two errors in two entries (of different keys: one in M, one in C)
        for baseline in (False, True) if written_c_differs(batch, sm) else (False,):
            if confirm.found or time.perf_counter() > deadline:
                break
            tried += confirm.tried
            confirm = _Confirmation(batch, sm, deadline, baseline=baseline)
            run(confirm, cross_pairs(screened))
    notation = Notation.of(type(batch.model))
    if confirm.found:
        findings = []
        for k, (changes, edit, slot) in enumerate(confirm.found):
            written = {key: change for key, change in changes.items() if key[0] not in derived}
            found = _findings(written, edit, slot, forms, notation, alternative=k > 0)
            if len(found) > 1:  # one repair in several entries: each finding names the others
                labels = [
                    f"{f.quantity}[{','.join(map(str, f.index))}]" if f.index else f.quantity for f in found
                ]
                found = [
                    dataclasses.replace(
                        f, message=f"{f.message}; together with the edit of {', '.join(others)}"
                    )
                    for f, others in ((f, labels[:i] + labels[i + 1 :]) for i, f in enumerate(found))
                ]
            note = matrix_c_note(screening, sm, changes)
            if note:  # coriolis and skew warn after the repair, as before the error
                found = [
                    dataclasses.replace(
                        f, message=f"{f.message}; {note}", details={**f.details, "warns": note}
                    )
                    for f in found
                ]
            findings += found
        return findings, ""
    where = ", ".join(s.label for s in slots[:6]) + (f" and {len(slots) - 6} more" if len(slots) > 6 else "")
    bound = (
        f" (the search stopped at its time bound: searched {len(screened)} of {len(slots)} entries)"
        if time.perf_counter() > deadline
        else ""
    )
    also = " nor two edits of one entry," if pairs else ""
    also += " nor one edit of each of two entries," if crossed else ""
    return [], (
        f"no repair: no single edit of {where} (nor one edit of each, for two entries,{also}) makes every "
        f"check pass; {tried + confirm.tried} candidate(s) tried against every check{bound}"
    )


class _Confirmation:
    """The candidates every check confirms, in the order they come: the first, then alternatives
    (module docstring); how many were tried; when the search for alternatives ends."""

    def __init__(self, batch, sm, deadline: float, baseline: bool = False):
        self.batch, self.sm, self.deadline, self.baseline = batch, sm, deadline, baseline
        self.found: list = []
        self.tried, self.tried_at_first, self.longest = 0, 0, 0.0
        self.seen: set = set()
        self.alternatives_until = float("inf")

    def run(self, ordered) -> None:
        for rank, changes, edit, slot in ordered:
            # a confirmation is not started unless the longest one so far still fits in the bound
            late = time.perf_counter() + self.longest > min(self.deadline, self.alternatives_until)
            if late or self.tried >= CONFIRMATIONS or len(self.found) > ALTERNATIVES:
                return
            if self.found and (rank > RANK["scale"] and rank != RANK["pair"]):
                return  # an alternative is a simple edit, not a shift or a fitted term that happens to fit
            key = tuple(sorted((m, i, str(new)) for (m, i), (_, new) in changes.items()))
            if key in self.seen:
                continue  # the same edit again
            if self.found and self.tried - self.tried_at_first >= ALTERNATIVE_TRIES:
                return
            self.seen.add(key)
            self.tried += 1
            started = time.perf_counter()
            if _confirmed(self.batch, self.sm, changes, self.baseline):
                self.found.append((changes, edit, slot))
                if len(self.found) == 1:
                    self.tried_at_first = self.tried
                    self.alternatives_until = time.perf_counter() + ALTERNATIVE_SECONDS
            self.longest = max(self.longest, time.perf_counter() - started)


def _findings(changes: dict, edit: Edit, slot: Slot, forms: dict, notation, alternative: bool = False):
    """The ``repair`` findings of one confirmed edit (one per entry it changes)."""
    out = []
    for (method, index), (old, new) in changes.items():
        label = entry_label(method, forms[method], index)
        written, suggested = notation.entry_edit(method, index, old, new)
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
            position = tuple(i + 1 for i in entry_position(method, value.shape, index))
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
