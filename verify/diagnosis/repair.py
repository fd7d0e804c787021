"""The repair: a single edit of the model's own expressions after which every check passes.

1. **Where**: the entries of the written closed forms that disagree with Pinocchio, the
   *slots* (``pendverify.diagnosis.slots``).
2. **What**: per slot, the edits that make it agree at the screening states
   (``pendverify.diagnosis.candidates``: the inverses of ``pendverify mutate``'s operators,
   coefficients and added terms solved for), ordered simplest first.
3. **Checked**: a candidate becomes a repair only when the edited model
   (``pendverify.symbolic.edited``) passes every applicable check on every state of the
   report's batch, and then again at each perturbed parameter set
   (``pendverify.diagnosis.perturbed``: the parameters moved, the robot description rewritten
   for each) on the first ``PERTURBED_STATES`` of those states.  One that fails at a perturbed
   set is a coincidence of the parameter values (``I → 4*I`` where I = m·l²/12 and lc = l/2):
   it is not a repair, and the search goes on; the sentence that says no repair was found names
   it.  Candidates are checked simplest first, at most ``CONFIRMATIONS`` of them, within the
   time bound.  Once one holds, the next simple edits (of this entry or another,
   ``ALTERNATIVE_TRIES`` of them; any edit, fitted terms too, when the first one involves a
   parameter that was not moved on its own) are checked too, and the ones that hold are shown
   as alternatives (up to ``ALTERNATIVES``).
4. **Confirmed**: the repair is *confirmed* (``details["confirmed"]``) when it held at every
   perturbed set, every parameter of the edit was moved on its own there, every other parameter
   the model's closed forms use was moved too, and no other edit held: it is then the same
   function of the parameters as what the robot says, not only the same numbers.  (A parameter
   left at its value is a number at every set, and an edit's number can stand for it: with lc =
   0.25 unmoved, ``g*m*sin(theta) → g*m*sin(theta)/4`` holds at every set where
   ``g*lc*m*sin(theta)`` is the repair.)  Otherwise the message says why not: a parameter of the
   edit, or of the model, could not be moved in the description (its reason), or was moved only
   together with others that share its value (m1 = m2: an edit and the same edit with m1 and m2
   exchanged cannot be told apart), or another edit holds as well (an error in B shows as well in
   a hand-written q̈ that uses it), or it edits what no check compares with the robot (B, W, and D
   where the URDF declares no damping: ``B[1,1]: 1 → 0`` passes every check when the q̈ that uses
   B lost its input, since both sides of aba take B from the model).  Each alternative is named
   with the relation under which the two agree, solved for one parameter (``I → 4*I`` and ``I → I
   + mp*r**2`` differ unless I = mp*r**2/3): ``pendverify.diagnosis.alternatives``, which also
   gives the edits tried in place of a coincidence (the same numbers from other parameters).

When no single edit passes, pairs of edits of one entry are tried for models of up to three
degrees of freedom.  When still none passes and the written C is not Pinocchio's, the screened
edits are checked again against the model's own baseline: the warning of a C that is a valid
C·q̇ but not the Christoffel C, nothing worse (``pendverify.diagnosis.acceptance``).  Then, for
models of up to three degrees of freedom, one edit of each of two entries that each passed their
own screen (``cross_pairs``): two errors in different keys, one in M and one in C.  Each pass
shares the perturbed sets and the coincidences found before it.

The repair is printed in the model's own notation, where it sits
(``pendverify.diagnosis.notation``).  A key the model derives from another (H = ∂V/∂q of a text
model that writes V) is not repaired: an edit of its source is confirmed with it derived again
(``pendverify.diagnosis.derived``), and only the source's edit is printed.
"""

from __future__ import annotations

import dataclasses
import functools

import numpy as np
import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.acceptance import accepted, matrix_c_note, passes, written_c_differs
from pendverify.diagnosis.alternatives import edit_parameters, exchanged, rematched, shown, unless
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
from pendverify.diagnosis.clock import now
from pendverify.diagnosis.confirmation import PERTURBED_STATES, derives_scales, holds_at, passes_checks
from pendverify.diagnosis.derived import derived_methods, with_derived
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.mechanics_source import SourceEdit, SourceSearch
from pendverify.diagnosis.notation import TEXT_KEYS, Notation
from pendverify.diagnosis.parameter_repair import search_parameter_repair
from pendverify.diagnosis.perturbed import perturbations
from pendverify.diagnosis.slots import QUANTITY, SCREEN_STATES, Slot, entry_label, evaluator, find_slots
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.edits import Edit
from pendverify.symbolic.zero_test import is_zero, probe

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
#: the share of the time left that the edits of a mechanics derivation's items may use: the entry
#: search after them (``search_repair``) is the fallback for an error no item edit undoes (one of
#: the kinematics) and needs its time too; the items' search took 1–2 s of the 10 s bound on the
#: corpus's Kane double pendulum
SOURCE_SHARE = 0.5
#: what no check compares with the robot (B and W enter both sides of aba; D too where the URDF
#: declares no damping): an edit of them is never confirmed
UNCOMPARED = ("input_matrix", "disturbance_matrix")


def _confirmed(batch, sm, changes: dict, moved_sets=None, baseline: bool = False) -> str:
    """Whether the model with ``changes`` passes every applicable check: "fails" (on some state of
    ``batch``), "coincidence" (on every state, but not at one of ``moved_sets``, a callable giving
    the perturbed sets, on the first ``PERTURBED_STATES``), or "holds" (module docstring).
    ``baseline``: or is back to the model's own warning (``pendverify.diagnosis.acceptance``)."""
    edits: dict[str, list] = {}
    for (method, index), (old, new) in changes.items():
        edits.setdefault(method, []).append((index, old, new))
    repaired = edited_model(batch.model, sm, edits, "Repaired")
    if not passes_checks(
        repaired, batch.system, batch.states, lambda r: accepted(r, batch, sm, changes, baseline)
    ):
        return "fails"
    # at the moved sets, the model's own warning is what the repair is back to when ``baseline``
    moved_accept = passes if baseline else None
    sets = moved_sets() if moved_sets is not None else ()
    states, derived = batch.states[:PERTURBED_STATES], derives_scales(batch.model)

    def make(moved):  # the same edited class: its generated code is reused
        return type(repaired)(moved.params)

    if not holds_at(make, sets, states, moved_accept, derived):
        return "coincidence"
    return "holds"


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
    start = now()
    deadline = start + deadline_s
    try:
        sm = SymbolicModel.of(type(batch.model))
        forms = sm.closed_forms
    except Exception as exc:  # code: the parameters it is given are searched instead
        unread = f"SymPy cannot read the model ({type(exc).__name__})"
        return search_parameter_repair(batch, deadline - now(), unread)
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

    notation = Notation.of(type(batch.model))
    confirm = _Confirmation(batch, sm, deadline, derived=derived, screening=screening)
    source, said = _source_search(batch, sm, slots, evaluate, confirm, deadline)
    if confirm.found:
        return confirm.findings(forms, notation), ""
    if source is not None:
        confirm = confirm.again(baseline=False)  # the entries next, sharing the perturbed sets
    pool = sum_pool(sm)
    monomials: dict[str, tuple] = {}
    screened = []
    for group in _groups(slots, batch.model.nv):
        for slot in group:
            if now() > min(deadline, confirm.alternatives_until):
                break
            quantity = QUANTITY.get(slot.method, "")
            if quantity not in monomials:
                monomials[quantity] = monomials_for(sm, params, quantity)
            screen_slot(slot, screening, sm, evaluate, monomials[quantity], pool, deadline)
            screened.append(slot)
        run(confirm, candidates(slots, [s for s in group if any(s is x for x in screened)]))
        if now() > min(deadline, confirm.alternatives_until):
            if confirm.found and len(screened) < len(slots):
                confirm.cut("the search for other edits that hold stopped at its time bound")
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
    if not confirm.found and now() < deadline and written_c_differs(batch, sm):
        # no edit makes every check pass; the written C is not Pinocchio's: the screened edits
        # again, a repair now one that is back to that C's warning (acceptance)
        confirm = confirm.again(baseline=True)
        run(confirm, candidates(slots, screened))
        if not confirm.found and len(slots) == 2 and len(screened) == 2:
            run(confirm, slot_pairs(*slots))
    crossed = not confirm.found and batch.model.nv <= PAIRS_UP_TO_DOF and len(screened) > 2
    if crossed:  # two errors in two entries (of different keys: one in M, one in C)
        for baseline in (False, True) if written_c_differs(batch, sm) else (False,):
            if confirm.found or now() > deadline:
                break
            confirm = confirm.again(baseline)
            run(confirm, cross_pairs(screened))
    if confirm.found:
        return confirm.findings(forms, notation), ""
    where = ", ".join(s.label for s in slots[:6]) + (f" and {len(slots) - 6} more" if len(slots) > 6 else "")
    bound = (
        f" (the search stopped at its time bound: searched {len(screened)} of {len(slots)} entries)"
        if now() > deadline
        else ""
    )
    also = " nor two edits of one entry," if pairs else ""
    also += " nor one edit of each of two entries," if crossed else ""
    return [], (
        f"no repair: no single edit of {where} (nor one edit of each, for two entries,{also}) makes every "
        f"check pass; {confirm.tried_before + confirm.tried} candidate(s) tried against every check{bound}"
        f"{said}{confirm.coincidence_note(forms, notation)}"
    )


def _source_search(batch, sm, slots, evaluate, confirm, deadline: float):
    """The edits of what a ``sympy.physics.mechanics`` derivation is written from (its bodies,
    particles, loads, Lagrangian: ``pendverify.diagnosis.mechanics_source``), confirmed as any
    candidate; (the search or None, the words for the sentence that says no repair was found)."""
    derivation = getattr(type(batch.model), "derivation", None)
    if derivation is None:
        return None, ""
    started = now()
    search = SourceSearch(derivation, sm, slots, evaluate, started + SOURCE_SHARE * (deadline - started))
    if not search.items:
        return None, ""
    confirm.run(search.candidates())
    bound = ", stopped at its share of the time bound" if search.stopped else ""
    if search.stopped:  # an edit of an item might hold where an edit of the entries does next
        confirm.cut("the edits of the derivation's items were not all screened (time bound)")
    return search, (
        f"; first, {search.tried} edit(s) of the {derivation.kind}'s bodies, particles and loads "
        f"({len(search.items)} items{bound}) were screened: {search.passed} passed, and {confirm.tried} "
        "of the candidates tried against every check were these"
    )


class _Confirmation:
    """The candidates every check confirms, in the order they come: the first, then alternatives
    (module docstring); the coincidences (every check passes at the file's values, not at a
    perturbed set); how many were tried; when the search for alternatives ends."""

    def __init__(self, batch, sm, deadline: float, baseline: bool = False, derived=None, screening=None):
        self.batch, self.sm, self.deadline, self.baseline = batch, sm, deadline, baseline
        #: the keys derived from others (never printed as edited) and the screening states
        self.derived, self.screening = derived or {}, screening
        self.found: list = []
        self.coincidences: list = []
        self.tried, self.tried_at_first, self.longest = 0, 0, 0.0
        self.tried_before = 0  # by the passes before this one (``again``)
        #: what a time bound left unsearched where an edit that holds as well might be: a repair is
        #: not confirmed then, so that what "confirmed" means does not depend on the machine's speed
        self.unsearched: list[str] = []
        self.seen: set = set()
        self.alternatives_until = float("inf")
        self._perturbation = None
        self._limits_of: dict = {}

    @functools.cached_property
    def _used(self) -> set[str]:
        """The parameters the model's closed forms use."""
        names = {symbol: name for name, symbol in self.sm.parameters.items()}
        forms = [v for v in self.sm.closed_forms.values() if isinstance(v, sp.Basic)]
        return {names[s] for form in forms for s in form.free_symbols if s in names}

    def again(self, baseline: bool) -> _Confirmation:
        """A new pass (module docstring) sharing this one's perturbed sets, coincidences and count."""
        nxt = _Confirmation(self.batch, self.sm, self.deadline, baseline, self.derived, self.screening)
        nxt._perturbation, nxt.coincidences = self._perturbation, self.coincidences
        nxt.unsearched = self.unsearched
        nxt.tried_before = self.tried_before + self.tried
        return nxt

    @property
    def perturbation(self):
        """The perturbed sets (``pendverify.diagnosis.perturbed``), made when first needed: at the
        first candidate that passes at the file's values."""
        if self._perturbation is None:
            states = self.batch.states[:PERTURBED_STATES]
            screening = self.batch.subset(range(len(states)))
            differing = {(s.method, s.index) for s in find_slots(screening, self.sm)}

            def consistent(model, system) -> bool:  # no entry that agrees here disagrees there
                with np.errstate(all="ignore"):
                    try:
                        slots = find_slots(CheckBatch(model, system, states), self.sm)
                    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
                        return False
                return {(s.method, s.index) for s in slots} <= differing

            self._perturbation = perturbations(self.batch.model, self.batch.system, consistent)
        return self._perturbation

    def _limits(self, changes, values: bool = False) -> list[str]:
        """Why an edit is not confirmed even when it holds: its parameters not moved on their own,
        then (unless ``values``: those alone) what it edits that no check compares with the robot.
        Kept per edit: the first repair's are asked for each candidate after it."""
        key = _edit_key(changes)
        if key not in self._limits_of:
            involved = edit_parameters(changes, self.sm)
            limits = self.perturbation.why_not_alone(involved)
            limits += self.perturbation.unmoved_beside(involved, self._used)
            free = self.batch.system.urdf_damping() is None
            unchecked = sorted(
                {QUANTITY[m] for m, _ in changes if m in UNCOMPARED or (m == "damping_matrix" and free)}
            )
            other = [
                f"no check compares {' or '.join(unchecked)} with the robot, so an edit of it and "
                "the same change where it is used cannot be told apart"
            ]
            other = other if unchecked else []
            if self.baseline:  # accepted against the model's own warning: C itself is not compared
                other.append(
                    "it is accepted with coriolis and skew warning, so only C·q̇ is compared with the "
                    "robot, not C itself (another C with the same C·q̇ passes as well)"
                )
            self._limits_of[key] = (limits, other)
        limits, other = self._limits_of[key]
        return limits if values else limits + other

    def cut(self, what: str) -> None:
        """Record that a time bound left ``what`` unsearched (``unsearched``)."""
        if what not in self.unsearched:
            self.unsearched.append(what)

    def run(self, ordered) -> None:
        for rank, changes, edit, slot in ordered:
            # a confirmation is not started unless the longest one so far still fits in the bound
            late = now() + self.longest > min(self.deadline, self.alternatives_until)
            if late and self.found:
                self.cut("the search for other edits that hold stopped at its time bound")
            if late or self.tried >= CONFIRMATIONS or len(self.found) > ALTERNATIVES:
                return
            simple = rank <= RANK["scale"] or rank == RANK["pair"]
            if self.found and not simple and not self._limits(self.found[0][0], values=True):
                # after an edit whose parameters all moved an alternative is a simple edit, not a fit;
                # after one that holds at these values only, any edit that holds is worth naming
                return
            key = _edit_key(changes)
            if key in self.seen:
                continue  # the same edit again
            if self.found and self.tried - self.tried_at_first >= ALTERNATIVE_TRIES:
                return
            verdict = self._check(changes, edit, slot)
            first_limited = verdict == "holds" and len(self.found) == 1 and self._limits(changes, values=True)
            if isinstance(edit, SourceEdit):
                continue  # its alternatives are other source edits, which come in their turn
            if (verdict == "coincidence" and not self.found) or first_limited:
                # the same numbers from other parameters, tried at once against every set: in place
                # of a coincidence, or as the alternatives of a repair that holds at these values only
                for variant, rematch in rematched(changes, self.sm, self.batch.model.params, slot):
                    late = now() + self.longest > self.deadline
                    if late or len(self.found) > ALTERNATIVES:
                        break
                    if self._check(variant, rematch, slot) == "holds" and not first_limited:
                        break

    def _check(self, changes: dict, edit: Edit, slot: Slot) -> str:
        """``_confirmed``'s verdict on one candidate, recorded (found, a coincidence, tried)."""
        key = _edit_key(changes)
        if key in self.seen:
            return "seen"
        self.seen.add(key)
        self.tried += 1
        started = now()
        verdict = _confirmed(self.batch, self.sm, changes, lambda: self.perturbation.sets, self.baseline)
        if verdict == "holds":
            self.found.append((changes, edit, slot))
            if len(self.found) == 1:
                self.tried_at_first = self.tried
                self.alternatives_until = now() + ALTERNATIVE_SECONDS
        elif verdict == "coincidence":
            self.coincidences.append((changes, edit, slot))
        self.longest = max(self.longest, now() - started)
        return verdict

    def findings(self, forms: dict, notation) -> list[Finding]:
        """The ``repair`` findings of what was found: the first, confirmed or not and why, then the
        alternatives (the other edits that held, and the first with members of a group of equal
        parameters exchanged), each with the relation under which it agrees with the first."""
        (changes, edit, slot), found = self.found[0], self.found[1:]
        found = [f for f in found if not _same_edit(f[0], changes, self.sm)]  # written otherwise
        independent = self.perturbation.independent
        others = [(c, e, s, unless(changes, c, self.sm, independent, notation)) for c, e, s in found]
        groups, params = self.perturbation.groups, self.batch.model.params
        others += exchanged(changes, edit, slot, groups, params, self.sm)
        sets = len(self.perturbation.sets)
        limits = self._limits(changes) + self.unsearched
        confirmed = not limits and not others and sets > 0
        values_only = bool(self._limits(changes, values=True))
        if confirmed:
            verdict = "makes every check pass on every state, at these parameter values and at "
            verdict += f"{sets} others ({self.perturbation.how})"
        else:
            also = [f"{_shown(c, e, forms, notation)} holds as well{why}" for c, e, _, why in others]
            if values_only:
                verdict = "makes every check pass on every state at these parameter values; not confirmed: "
            else:
                verdict = f"makes every check pass on every state, and at {sets} other parameter sets; "
                verdict += "not confirmed: "
            verdict += "; ".join(limits + also)
        out = self._dressed(changes, self._printed(changes, edit, slot, forms, notation, verdict, confirmed))
        for c, e, s, why in others:
            verdict = f"makes every check pass on every state as well; not confirmed: like the first{why}"
            out += self._dressed(c, self._printed(c, e, s, forms, notation, verdict, False, alternative=True))
        return out

    def _printed(self, changes, edit, slot, forms, notation, verdict, confirmed, alternative=False):
        """The findings of one repair: one naming the source item for a source edit, else one per
        written entry it changes."""
        written = self._written(changes)
        if isinstance(edit, SourceEdit):
            derivation = type(self.batch.model).derivation
            return [
                _source_finding(written, edit, derivation, forms, notation, verdict, confirmed, alternative)
            ]
        return _findings(written, edit, slot, forms, notation, verdict, confirmed, alternative)

    def _written(self, changes: dict) -> dict:
        """The changes of the keys the model writes (a derived key is derived again, not edited)."""
        return {key: change for key, change in changes.items() if key[0] not in self.derived}

    def _dressed(self, changes: dict, found: list[Finding]) -> list[Finding]:
        """The findings of one repair, each naming the others of a repair of several entries, and
        noting the warning of a C that is not the Christoffel one where the repaired model keeps it."""
        if len(found) > 1:
            labels = [
                f"{f.quantity}[{','.join(map(str, f.index))}]" if f.index else f.quantity for f in found
            ]
            found = [
                dataclasses.replace(f, message=f"{f.message}; together with the edit of {', '.join(others)}")
                for f, others in ((f, labels[:i] + labels[i + 1 :]) for i, f in enumerate(found))
            ]
        note = matrix_c_note(self.screening, self.sm, changes) if self.screening is not None else ""
        if note:  # coriolis and skew warn after the repair, as before the error
            found = [
                dataclasses.replace(f, message=f"{f.message}; {note}", details={**f.details, "warns": note})
                for f in found
            ]
        return found

    def coincidence_note(self, forms: dict, notation) -> str:
        """For the sentence that says no repair was found: the edits that passed at the file's values
        only (module docstring), or ""."""
        if not self.coincidences:
            return ""
        edits = ", ".join(_shown(c, e, forms, notation) for c, e, _ in self.coincidences[:2])
        more = f" and {len(self.coincidences) - 2} more" if len(self.coincidences) > 2 else ""
        return (
            f"; {edits}{more} make(s) every check pass at these parameter values, but not at other values "
            f"({self.perturbation.how}): a coincidence of the values, not a repair"
        )


def _shown(changes: dict, edit, forms: dict, notation) -> str:
    """An edit, short: the source item it edits for a source edit, else the entry (``shown``)."""
    return (
        edit.shown(notation.render) if isinstance(edit, SourceEdit) else shown(changes, edit, forms, notation)
    )


def _edit_key(changes: dict) -> tuple:
    """What identifies an edit among the candidates: each entry it changes and the text it writes."""
    return tuple(sorted((m, i, str(new)) for (m, i), (_, new) in changes.items()))


def _same_edit(changes: dict, other: dict, sm) -> bool:
    """Whether two edits write the same entries as the same functions (``l1**2*(m1 + m2)`` and
    ``l1**2*m1 + l1**2*m2``): one repair, not two."""
    differences = [changes[key][1] - other[key][1] for key in changes] if set(changes) == set(other) else None
    # a probe in 50 digits tells most different ones apart at once; the exact test decides the rest
    return differences is not None and all(not probe(d) and is_zero(d, sm.angles) for d in differences)


def _findings(
    changes: dict, edit: Edit, slot: Slot, forms: dict, notation, verdict: str, confirmed: bool,
    alternative: bool = False,
):  # fmt: skip
    """The ``repair`` findings of one edit that makes every check pass (one per entry it changes);
    ``verdict`` says whether it is confirmed (``_Confirmation.findings``)."""
    out = []
    line = notation.line_edit(changes)  # a .m model's repair as the one line of its file to change
    labels = [entry_label(method, forms[method], index) for method, index in changes]
    for ((method, index), (old, new)), label in zip(changes.items(), labels, strict=True):
        if line is not None:
            written, suggested = line.written, line.suggested
            location = f"{line.path}, line {line.line}, which computes {', '.join(labels)}"
        else:
            written, suggested = notation.entry_edit(method, index, old, new)
            location = notation.location(method, label, index)
        shown = (
            f"{written} → {suggested}"
            if len(written) + len(suggested) <= (320 if line is not None else 160)
            else f"{notation.render(edit.old)} → {notation.render(edit.new)} in {label}"
        )
        if edit.operator == "pair":
            shown += f" (two edits: {edit.what})"
        message = f"{'or, equally: ' if alternative else ''}{label}: {shown} {verdict} ({location})"
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
                    "confirmed": confirmed,
                },
            )
        )
    return out


def _source_finding(
    changes: dict, edit: SourceEdit, derivation, forms: dict, notation, verdict: str, confirmed: bool,
    alternative: bool = False,
):  # fmt: skip
    """The ``repair`` finding of a source edit that makes every check pass: the item it edits named
    (``body link2 (inertia): 2*I2 → I2``), then the entries of the closed forms it changes."""
    item = edit.item
    written, suggested = notation.render(item.expr), notation.render(edit.new)
    labels = [entry_label(method, forms[method], index) for method, index in changes]
    location = f"{derivation.source}, the {derivation.kind}'s {item.owner}"
    message = (
        f"{'or, equally: ' if alternative else ''}{item.label}: {written} → {suggested} {verdict} "
        f"({location}; it changes {', '.join(labels)})"
    )
    method, index = next(iter(changes))
    value = forms[method]
    position = (
        tuple(i + 1 for i in entry_position(method, value.shape, index))
        if isinstance(value, sp.MatrixBase)
        else ()
    )
    entries_changed = {
        label: [str(old), str(new)] for label, (old, new) in zip(labels, changes.values(), strict=True)
    }
    details = {
        "written": str(item.expr),
        "suggested": str(edit.new),
        "suggested_source": suggested,
        "location": location,
        "source_item": item.name(notation.render),
        "entries": entries_changed,
        "checks_pass": True,
        "confirmed": confirmed,
    }
    return Finding("repair", message, QUANTITY.get(method), position, details)
