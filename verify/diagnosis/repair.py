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
   perturbed set, every parameter of the edit was moved on its own there, and no other edit
   held: it is then the same function of the parameters as what the robot says, not only the
   same numbers.  Otherwise it holds at these values only, and the message says why: a
   parameter of the edit could not be moved in the description (its reason), or was moved
   only together with others that share its value (m1 = m2: an edit and the same edit with m1
   and m2 exchanged cannot be told apart), or another edit holds as well (an error in B shows
   as well in a hand-written q̈ that uses it).  Each alternative is named with the relation
   under which the two agree, solved for one parameter (``I → 4*I`` and ``I → I + mp*r**2``
   differ unless I = mp*r**2/3).

When no single edit passes, pairs of edits of one entry are tried for models of up to three
degrees of freedom.

The repair is printed in the model's own notation, where it sits
(``pendverify.diagnosis.notation``).
"""

from __future__ import annotations

import functools
import itertools
import time

import numpy as np
import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.candidates import (
    RANK,
    candidates,
    equal_valued,
    monomials_for,
    pairs_within,
    screen_slot,
    slot_pairs,
    sum_pool,
)
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.notation import Notation
from pendverify.diagnosis.perturbed import perturbations
from pendverify.diagnosis.slots import QUANTITY, SCREEN_STATES, Slot, entry_label, evaluator, find_slots
from pendverify.errors import PendverifyError
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.edits import Edit
from pendverify.symbolic.zero_test import trig_normal_form

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
#: states a candidate is checked on at each perturbed set: the screening states.  The candidate
#: already matched Pinocchio on every state at the file's values, so it is the right function of
#: the state there; what a perturbed set tests is the parameters, and a wrong edit's difference
#: (a trigonometric polynomial of a few terms in the state, not zero as a function at the moved
#: parameters) is non-zero at almost every state: 24 states, the special ones first, find it.
PERTURBED_STATES = SCREEN_STATES
#: edits tried in place of one that proved a coincidence, giving the same numbers with other
#: parameters (``_rematched``); each is a check run of a small model, a fraction of the bound
REMATCHES = 6


def _passes(model, system, states) -> bool:
    """Whether ``model`` passes every applicable check on every state of ``states`` against ``system``."""
    names = applicable_checks(model, system)
    with np.errstate(all="ignore"):
        try:
            results = run_checks("repair", model, system, states, 0, names)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError, PendverifyError):
            return False  # a scale that cannot be derived too: what is not shown to pass does not
    return all(r.passed for r in results)


def _confirmed(batch, sm, changes: dict, moved_sets=None) -> str:
    """Whether the model with ``changes`` passes every applicable check: "fails" (on some state of
    ``batch``), "coincidence" (on every state, but not at one of ``moved_sets``, a callable giving
    the perturbed sets, on the first ``PERTURBED_STATES``), or "holds" (module docstring)."""
    edits: dict[str, list] = {}
    for (method, index), (old, new) in changes.items():
        edits.setdefault(method, []).append((index, old, new))
    repaired = edited_model(batch.model, sm, edits, "Repaired")
    if not _passes(repaired, batch.system, batch.states):
        return "fails"
    states = batch.states[:PERTURBED_STATES]
    derived = bool({"gravity_scale", "diagonal_scale"} - set(type(batch.model).hand_written()))
    for moved in moved_sets() if moved_sets is not None else ():
        model = type(repaired)(moved.params)  # the same edited class: its generated code is reused
        if derived:  # the tolerance scales of the model as given, at these values (``edited_model``)
            model.use_derived_scales(moved.model.derived_scales())
        if _passes(model, moved.system, states):
            continue
        # the model as given can have degenerate scales (an H planted as 0 has a gravity scale 0,
        # which the rounding at the file's values may meet and other values not): the repaired
        # model's own, derived from its M and H, decide then
        if not derived or not _passes(type(repaired)(moved.params), moved.system, states):
            return "coincidence"
    return "holds"


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
    pool = sum_pool(sm)
    monomials: dict[str, tuple] = {}
    confirm = _Confirmation(batch, sm, deadline)
    screened = []
    for slot in sorted(slots, key=lambda s: sp.count_ops(s.expr)):
        if time.perf_counter() > min(deadline, confirm.alternatives_until):
            break
        quantity = QUANTITY.get(slot.method, "")
        if quantity not in monomials:
            monomials[quantity] = monomials_for(sm, params, quantity)
        screen_slot(slot, screening, sm, evaluate, monomials[quantity], pool, deadline)
        screened.append(slot)
        confirm.run(candidates(slots, [slot]))
    if not confirm.found and len(slots) == 2 and len(screened) == 2:  # one edit of each entry
        confirm.run(slot_pairs(*slots))
    pairs = not confirm.found and batch.model.nv <= PAIRS_UP_TO_DOF and len(slots) <= 2
    if pairs:  # two edits of one entry
        confirm.run(
            (RANK["pair"], {(slot.method, slot.index): (slot.expr, edit.expr)}, edit, slot)
            for slot in slots
            for edit in pairs_within(slot, sm, evaluate, pool, deadline)
        )
    notation = Notation.of(type(batch.model))
    if confirm.found:
        return confirm.findings(forms, notation), ""
    where = ", ".join(s.label for s in slots[:6]) + (f" and {len(slots) - 6} more" if len(slots) > 6 else "")
    bound = (
        f" (the search stopped at its time bound: searched {len(screened)} of {len(slots)} entries)"
        if time.perf_counter() > deadline
        else ""
    )
    also = " nor two edits of one entry," if pairs else ""
    return [], (
        f"no repair: no single edit of {where} (nor one edit of each, for two entries,{also}) makes every "
        f"check pass; {confirm.tried} candidate(s) tried against every check{bound}"
        f"{confirm.coincidence_note(forms, notation)}"
    )


class _Confirmation:
    """The candidates every check confirms, in the order they come: the first, then alternatives
    (module docstring); the coincidences (every check passes at the file's values, not at a
    perturbed set); how many were tried; when the search for alternatives ends."""

    def __init__(self, batch, sm, deadline: float):
        self.batch, self.sm, self.deadline = batch, sm, deadline
        self.found: list = []
        self.coincidences: list = []
        self.tried, self.tried_at_first, self.longest = 0, 0, 0.0
        self.seen: set = set()
        self.alternatives_until = float("inf")
        self._perturbation = None

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

    def _limits(self, changes) -> list[str]:
        """Why an edit is not confirmed even when it holds: its parameters not moved on their own."""
        return self.perturbation.why_not_alone(_edit_parameters(changes, self.sm))

    def run(self, ordered) -> None:
        for rank, changes, edit, slot in ordered:
            # a confirmation is not started unless the longest one so far still fits in the bound
            late = time.perf_counter() + self.longest > min(self.deadline, self.alternatives_until)
            if late or self.tried >= CONFIRMATIONS or len(self.found) > ALTERNATIVES:
                return
            simple = rank <= RANK["scale"] or rank == RANK["pair"]
            if self.found and not simple and not self._limits(self.found[0][0]):
                # after a confirmed edit an alternative is a simple edit, not a shift or a fitted term;
                # after one that holds at these values only, any edit that holds is worth naming
                return
            key = tuple(sorted((m, i, str(new)) for (m, i), (_, new) in changes.items()))
            if key in self.seen:
                continue  # the same edit again
            if self.found and self.tried - self.tried_at_first >= ALTERNATIVE_TRIES:
                return
            verdict = self._check(changes, edit, slot)
            first_limited = verdict == "holds" and len(self.found) == 1 and self._limits(changes)
            if (verdict == "coincidence" and not self.found) or first_limited:
                # the same numbers from other parameters, tried at once against every set: in place
                # of a coincidence, or as the alternatives of a repair that holds at these values only
                for variant, rematch in _rematched(changes, self.sm, self.batch.model.params, slot):
                    late = time.perf_counter() + self.longest > self.deadline
                    if late or len(self.found) > ALTERNATIVES:
                        break
                    if self._check(variant, rematch, slot) == "holds" and not first_limited:
                        break

    def _check(self, changes: dict, edit: Edit, slot: Slot) -> str:
        """``_confirmed``'s verdict on one candidate, recorded (found, a coincidence, tried)."""
        key = tuple(sorted((m, i, str(new)) for (m, i), (_, new) in changes.items()))
        if key in self.seen:
            return "seen"
        self.seen.add(key)
        self.tried += 1
        started = time.perf_counter()
        verdict = _confirmed(self.batch, self.sm, changes, lambda: self.perturbation.sets)
        if verdict == "holds":
            self.found.append((changes, edit, slot))
            if len(self.found) == 1:
                self.tried_at_first = self.tried
                self.alternatives_until = time.perf_counter() + ALTERNATIVE_SECONDS
        elif verdict == "coincidence":
            self.coincidences.append((changes, edit, slot))
        self.longest = max(self.longest, time.perf_counter() - started)
        return verdict

    def findings(self, forms: dict, notation) -> list[Finding]:
        """The ``repair`` findings of what was found: the first, confirmed or not and why, then the
        alternatives (the other edits that held, and the first with members of a group of equal
        parameters exchanged), each with the relation under which it agrees with the first."""
        (changes, edit, slot), found = self.found[0], self.found[1:]
        others = [(c, e, s, _unless(changes, c, self, notation)) for c, e, s in found]
        others += self._exchanges(changes, edit, slot)
        sets = len(self.perturbation.sets)
        limits = self._limits(changes)
        confirmed = not limits and not others and sets > 0
        if confirmed:
            verdict = "makes every check pass on every state, at these parameter values and at "
            verdict += f"{sets} others ({self.perturbation.how})"
        else:
            also = [f"{_shown(c, e, forms, notation)} holds as well{unless}" for c, e, _, unless in others]
            if limits:
                verdict = "makes every check pass on every state at these parameter values; not confirmed: "
            else:
                verdict = f"makes every check pass on every state, and at {sets} other parameter sets; "
                verdict += "not confirmed: "
            verdict += "; ".join(limits + also)
        out = _findings(changes, edit, slot, forms, notation, verdict, confirmed)
        for c, e, s, unless in others:
            verdict = f"makes every check pass on every state as well; not confirmed: like the first{unless}"
            out += _findings(c, e, s, forms, notation, verdict, False, alternative=True)
        return out

    def _exchanges(self, changes: dict, edit: Edit, slot: Slot) -> list:
        """The edit with the members of groups of equal parameters exchanged in what it changes
        (``add I2`` → ``add I1``), as [(changes, edit, slot, relation)]: at most one, every group
        the edit's difference holds exchanged at once.  The members' values are the same float
        here and at every perturbed set, so the exchanged edit gives the same numbers, bit for
        bit, and passes every check the first passed.  Listed only where the edit puts in or
        takes out whole terms (each term of its difference has the coefficient ±1: ``I2 → 2*I2``
        adds I2, so ``+ I1`` is an edit the user could have meant), not where it changes a term's
        sign or factor (``m2*l1*lc2*sin(theta2)`` flipped: the same flip with m1 would be a new
        term of two masses)."""
        params, symbols = self.batch.model.params, self.sm.parameters
        differences = [sp.expand(new - old) for old, new in changes.values()]
        whole = all(abs(term.as_coeff_Mul()[0]) == 1 for d in differences for term in sp.Add.make_args(d))
        swap = {}
        for group in self.perturbation.groups:
            if len({float(getattr(params, n)) for n in group}) != 1:
                continue  # equal to rounding only: the numbers would differ in the last bits
            inside = [n for n in group if any(d.has(symbols[n]) for d in differences)]
            if inside:
                a, b = symbols[inside[0]], symbols[next(n for n in group if n != inside[0])]
                swap.update({a: b, b: a})
        if not swap or not whole:
            return []
        exchanged = {}
        for key, (old, new) in changes.items():
            forms = (old + (new - old).xreplace(swap), sp.expand(old + (new - old).xreplace(swap)))
            exchanged[key] = (old, min(forms, key=lambda f: len(str(f))))
        if all(sp.expand(n - changes[k][1]) == 0 for k, (_, n) in exchanged.items()):
            return []
        pairs = sorted({tuple(sorted((str(a), str(b)))) for a, b in swap.items()})
        where = " and ".join(f"{a} = {b}" for a, b in pairs)
        (old, new) = next(iter(exchanged.values()))
        what = f"{edit.what}, with {where.replace(' = ', ' and ')} exchanged"
        return [(exchanged, Edit("exchange", old, new, new, what), slot, f": the two agree where {where}")]

    def coincidence_note(self, forms: dict, notation) -> str:
        """For the sentence that says no repair was found: the edits that passed at the file's values
        only (module docstring), or ""."""
        if not self.coincidences:
            return ""
        shown = ", ".join(_shown(c, e, forms, notation) for c, e, _ in self.coincidences[:2])
        more = f" and {len(self.coincidences) - 2} more" if len(self.coincidences) > 2 else ""
        return (
            f"; {shown}{more} make(s) every check pass at these parameter values, but not at other values "
            f"({self.perturbation.how}): a coincidence of the values, not a repair"
        )


def _rematched(changes: dict, sm, params, slot: Slot) -> list[tuple[dict, Edit]]:
    """Edits that give the same numbers as ``changes`` (an edit of one entry that proved a
    coincidence) at the file's values, with other parameters: each term of what the edit adds,
    then each term of the entry it writes, whose parameters times its number is matched by
    another product of parameters of the same value (``equal_valued``: ``3*I`` → ``mp*l**2``
    where I = mp·l²/3, ``l*m/2`` → ``l**2*m`` where l = 0.5, ``l1*lc2`` → ``l1*lc2*m2`` where
    m2 = 1).  At most ``REMATCHES``, products as they stand and the model's own first."""
    if len(changes) != 1:
        return []
    ((key, (old, new)),) = changes.items()
    values = {sm.parameters[p]: float(getattr(params, p)) for p in sm.parameters}
    own, generic = monomials_for(
        sm, {p: float(getattr(params, p)) for p in sm.parameters}, QUANTITY.get(slot.method, "")
    )
    parameters = set(values)
    out = []
    for base, source in ((old, sp.expand(new - old)), (sp.S.Zero, sp.expand(new))):
        terms = sp.Add.make_args(source)
        if len(terms) > 2:
            continue
        options = []
        for term in terms:
            part = sp.Mul(
                *[f for f in sp.Mul.make_args(term) if not f.free_symbols or f.free_symbols <= parameters]
            )
            value = float(part.xreplace(values))
            others = [m for m in equal_valued(value, own + generic) if m != part] if value else []
            options.append([(part, term / part)] + [(m, term / part) for m in others])
        for combo in itertools.product(*options):
            if all(choice is option[0] for choice, option in zip(combo, options, strict=True)):
                continue
            written = base + sp.Add(*[m * rest for m, rest in combo])
            if written != new:
                what = f"{new} → {written} (the same numbers here)"
                out.append(({key: (old, written)}, Edit("rematched", old, written, written, what)))
            if len(out) == REMATCHES:
                return out
    return out


def _edit_parameters(changes: dict, sm) -> set[str]:
    """The parameters an edit involves: those of the difference it makes to each entry."""
    names = {symbol: name for name, symbol in sm.parameters.items()}
    out = set()
    for old, new in changes.values():
        out |= {names[s] for s in sp.expand(new - old).free_symbols if s in names}
    return out


def _products(expr, parameters: set) -> set:
    """The product of ``parameters`` in each term of ``expr`` (numbers and state functions left out)."""
    return {
        sp.Mul(*[f for f in sp.Mul.make_args(term) if f.free_symbols and f.free_symbols <= parameters])
        for term in sp.Add.make_args(expr)
    }


def _shown(changes: dict, edit: Edit, forms: dict, notation) -> str:
    """An edit, short, in the model's notation: ``M[2,2]: I → 4*I``."""
    (method, index), (old, new) = next(iter(changes.items()))
    label = entry_label(method, forms[method], index)
    written, suggested = notation.render(old), notation.render(new)
    if len(written) + len(suggested) <= 80:
        return f"{label}: {written} → {suggested}"
    return f"{label}: {notation.render(edit.old)} → {notation.render(edit.new)}"


def _unless(changes: dict, other: dict, confirmation: _Confirmation, notation) -> str:
    """ ": they differ unless I = mp*r**2/3": the relation under which two edits of the same entries
    give the same numbers, solved for one parameter (one that was not moved on its own first);
    "" when the edits change different entries or the relation is not one equation."""
    if set(changes) != set(other):
        return ""
    key = next(iter(changes))
    relation = parameter_relation(changes[key][1] - other[key][1], confirmation.sm)
    if relation is None:
        return ""
    moved = confirmation.perturbation
    preferred = [p for p in relation.free_symbols if str(p) not in moved.independent]
    for symbol in sorted(preferred, key=str) + sorted(relation.free_symbols - set(preferred), key=str):
        solutions = sp.solve(relation, symbol)
        if len(solutions) == 1 and not sp.fraction(solutions[0])[1].free_symbols:
            return f": they differ unless {notation.render(symbol)} = {notation.render(solutions[0])}"
    terms = sp.Add.make_args(relation)
    if len(terms) == 2:  # no parameter solved for without dividing by another: both sides
        left, right = (
            (terms[0], -terms[1]) if terms[0].could_extract_minus_sign() is False else (-terms[0], terms[1])
        )
        return f": they differ unless {notation.render(left)} = {notation.render(right)}"
    return ""


def parameter_relation(difference, sm) -> sp.Expr | None:
    """The polynomial of the parameters that must vanish for two entries whose ``difference`` is
    given to agree at every state, or None when that is not one equation.  The difference is
    written as a polynomial in sin θ, cos θ, the rates and inputs (``trig_normal_form``); it
    vanishes at every state when each coefficient does, and that is one relation when all the
    coefficients share a factor (their GCD) and are otherwise numbers."""
    states = set(sm.flat_arguments("qvuw"))
    form = trig_normal_form(sp.expand(difference), sm.angles)
    if form is None or form == 0:
        return None
    parameters = set(sm.parameters.values())
    others = sorted(form.free_symbols - parameters, key=str)
    if states & form.free_symbols - set(others):  # pragma: no cover - every state symbol is in others
        return None
    coefficients = sp.Poly(form, *others).coeffs() if others else [form]
    common = functools.reduce(sp.gcd, coefficients)
    if not common.free_symbols or any(not sp.cancel(c / common).is_number for c in coefficients):
        return None
    # a factor that is one parameter vanishes only where that parameter is 0: not a relation
    factors = [f for f, _ in sp.factor_list(common)[1] if f.is_Add]
    return sp.Mul(*factors) if factors else None


def _findings(
    changes: dict, edit: Edit, slot: Slot, forms: dict, notation, verdict: str, confirmed: bool,
    alternative: bool = False,
):  # fmt: skip
    """The ``repair`` findings of one edit that makes every check pass (one per entry it changes);
    ``verdict`` says whether it is confirmed (``_Confirmation.findings``)."""
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
