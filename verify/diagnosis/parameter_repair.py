"""Repairs of a model whose code SymPy cannot read: edits of the parameter set the code is given.

Dynamics as code (``DYNAMICS``, ``pendverify.analytic.python_dynamics``), NumPy functions
(``pendverify.analytic.numpy_model``) and Python classes whose methods call NumPy or ``math``
cannot be read as expressions, so ``pendverify.diagnosis.repair`` cannot edit them.  Their
*parameters* can be edited: the code reads a parameter set, and many real errors are one
parameter used wrongly wherever the code uses it.  The search gives the code an edited set and
asks whether every check then passes.

What is tried (``pendverify.diagnosis.parameter_edits``), simplest first, at most its ``EDITS``:

1. p → k·p for k in 2, ½, −1: a quantity counted twice or halved (a mass doubled, a length
   where the half-length belongs, a diameter for a radius), a sign (gravity along +z);
2. p ↔ q, two parameters of the same dimension exchanged (``KIND_DIMENSIONS``; a damping
   coefficient only with another damping coefficient), then p → q: the code reads l1 where l2
   belongs;
3. p → k·p for k in 4, ¼, 3, ⅓, 12, 1/12: a factor 2 squared (a length l for l/2 in an
   inertia m·l²), a rod's inertia about its end m·l²/3 against a point mass's m·l², a rod's
   about its centre m·l²/12 against m·l²;
4. p → p ± P, P a product of parameters with p's dimension (``monomials``: the units check's
   dimensions), of at most ``ADDED_FACTORS`` distinct parameters: an inertia about the centre of
   mass where the one about the pivot belongs, I → I + m·l² (the parallel-axis term), or the
   other way; m1 → m1 + m2.

Only the parameters the code reads are edited (``code_parts.read_parameters``: those some part
of the code changes with at the screening states, each moved by a quarter); one it does not read
may be what another is given.  An exchange with such a parameter is that substitution (l ↔ lc where the
code reads l and never lc is l → lc) and is tried as it.  The factors of steps 1 and 3 are
the slips of a hand derivation named with each; a factor beyond them (5, 1/5) is no common slip
and would double the edits screened.

Screen, then checks.  Each edit is screened first (``differing``): the edited model's q̈, and,
for a model that writes them, its M, H and C·q̇ (and D where the description declares damping),
at the screening states against Pinocchio's, each entry within ``SCREEN_RTOL`` of its
quantity's size, as ``pendverify.diagnosis.slots`` screens an expression's edit (Pinocchio's
side is computed once).  Only an edit that passes the screen is run through every check on
every state (``confirmation.passes_checks``), and then at each perturbed parameter set
(``pendverify.diagnosis.perturbed``) with the same edit applied to the moved set: p → 2·p gives
the code twice the moved p.  At most ``CONFIRMATIONS`` edits are run so, within the time bound.

Confirmed, as for an expression's repair: it held at every perturbed set, every parameter the
edit involves (p, and q or those of P) was moved on its own there, and no other edit held;
otherwise the message says why not (``Perturbation.why_not_alone``: equal values moved together,
a parameter not moved and why), and names the other edits that held.  An edit that holds at
the file's values but not at a perturbed set is a coincidence of the values: not printed as a
repair, and named in the sentence that says none was found.

Given values outside a kind's rule.  p → −p gives a mass or g below zero, which a parameter
file would refuse; the edited set is what the code is given, not a robot, so it is made
without the rules when they refuse it (``ParameterEdit.applied``).
"""

from __future__ import annotations

import dataclasses

import numpy as np

from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.clock import now
from pendverify.diagnosis.code_parts import location, parts_using, read_parameters, uses
from pendverify.diagnosis.confirmation import PERTURBED_STATES, derives_scales, holds_at
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.parameter_edits import ParameterEdit, parameter_edits
from pendverify.diagnosis.perturbed import MovedSet, perturbations
from pendverify.diagnosis.slots import SCREEN_RTOL, SCREEN_STATES

#: edits run through every check at most (each a run of the checks, and of the perturbed sets)
CONFIRMATIONS = 12
#: edits that hold shown besides the first
ALTERNATIVES = 2


def differing(model, base) -> set[tuple]:
    """The entries of ``model``'s q̈ (and M, H, C·q̇, D where it writes them) that differ from
    Pinocchio's at the states of ``base`` (a ``CheckBatch`` on the same system, whose Pinocchio
    quantities are reused) by more than ``SCREEN_RTOL`` of their quantity's size; ``{("all",)}``
    when the model cannot be evaluated there."""
    batch = CheckBatch(model, base.system, base.states, base.pinocchio_angles)
    batch.__dict__["pin"] = base.pin  # the robot's side: the same states and system
    out: set[tuple] = set()
    with np.errstate(all="ignore"):
        try:
            t = batch.terms
            compared = [("qddot", t.a_hand, t.a_pin)]
            if model.has_mass_matrix and not model.mass_from_acceleration:
                bias = (t.bias_hand - t.H_hand, t.bias_pin - t.H_pin)
                compared += [("M", t.M_hand, t.M_pin), ("H", t.H_hand, t.H_pin), ("Cqdot", *bias)]
            if np.any(base.system.urdf_damping()):
                compared.append(("D", t.D, t.D_urdf))
            for quantity, hand, pin in compared:
                hand, pin = np.broadcast_arrays(np.asarray(hand, dtype=float), np.asarray(pin, dtype=float))
                size = float(np.max(np.abs(pin), initial=0.0)) + float(np.max(np.abs(hand), initial=0.0))
                close = np.abs(hand - pin) <= SCREEN_RTOL * (size if np.isfinite(size) and size else 1.0)
                entries = close if close.ndim < 2 or quantity == "D" else np.all(close, axis=0)
                out |= {(quantity, *map(int, i)) for i in np.argwhere(~np.atleast_1d(entries))}
        except Exception:  # the user's code, given values it never was: any failure fails
            return {("all",)}
    return out


def search_parameter_repair(batch, deadline_s: float, unread: str) -> tuple[list[Finding], str]:
    """The confirmed parameter edit of a failing model SymPy cannot read, as findings, and what
    the search did, in words; ``unread``: why SymPy cannot read it (module docstring)."""
    deadline = now() + deadline_s
    model = batch.model
    if not dataclasses.is_dataclass(model.params):
        return [], f"no repair searched: {unread}, and its parameters are not a parameter set"
    screening = batch.subset(range(min(SCREEN_STATES, len(batch))))
    differs = differing(model, screening)
    if not differs:
        return [], (
            f"no repair searched: {unread}, and its quantities agree with Pinocchio's at the "
            f"{len(screening)} screening states"
        )
    search = _Search(batch, screening, differs, deadline)
    search.read = read_parameters(model, screening.states)
    edits = parameter_edits(model.params, search.read)
    screened, screen_s = 0, 0.0
    for edit in edits:
        # a screen is started while the longest screen (and confirmation) so far still fits the bound
        if now() + max(search.longest, screen_s) > deadline or search.done:
            break
        screened += 1
        started = now()
        passed = not differing(type(model)(edit.applied(model.params)), screening)
        screen_s = max(screen_s, now() - started)
        if passed and now() + search.longest <= deadline:
            search.confirm(edit)
    if search.found:
        return search.findings(), ""
    if screened == len(edits):
        counted = f"none of {len(edits)} edits"
    else:
        why = f"after {CONFIRMATIONS} passed the screen" if search.done else "at its time bound"
        counted = f"none of the first {screened} of {len(edits)} edits (the search stopped {why})"
    return [], (
        f"no repair: {counted} of the parameters the code is given (p → k·p, another parameter of p's "
        f"units, two exchanged, p ± a product of parameters of its units) makes every check pass "
        f"({search.tried} passed the screen, each then run through every check); the code's own "
        f"expressions were not edited: {unread}{search.coincidence_note()}"
    )


class _Search:
    """The screened edits run through every check, in order: the first that holds, the others
    that hold as well, the coincidences (module docstring)."""

    def __init__(self, batch, screening, differs: set, deadline: float):
        self.batch, self.screening, self.differs, self.deadline = batch, screening, differs, deadline
        self.kinds = {f.name: f.metadata.get("kind") for f in dataclasses.fields(batch.model.params)}
        self.found: list[ParameterEdit] = []
        self.coincidences: list[ParameterEdit] = []
        self.tried, self.longest = 0, 0.0
        self._perturbation = None
        #: the parameters the code reads (``code_parts.read_parameters``)
        self.read: set = set()

    @property
    def done(self) -> bool:
        return self.tried >= CONFIRMATIONS or len(self.found) > ALTERNATIVES

    @property
    def perturbation(self):
        """The perturbed sets, made when first needed (``pendverify.diagnosis.perturbed``): a set
        is kept where no entry that agrees at the file's values disagrees."""
        if self._perturbation is None:
            states = self.batch.states[:PERTURBED_STATES]

            def consistent(model, system) -> bool:
                base = CheckBatch(model, system, states)
                return differing(model, base) <= self.differs

            self._perturbation = perturbations(self.batch.model, self.batch.system, consistent)
        return self._perturbation

    def confirm(self, edit: ParameterEdit) -> None:
        """Run ``edit`` through every check on every state, then at the perturbed sets."""
        started = now()
        self.tried += 1
        batch, model = self.batch, self.batch.model
        derived = derives_scales(model)

        def make(moved):
            return type(model)(edit.applied(moved.params))

        here = MovedSet(model.params, model, batch.system)
        if holds_at(make, [here], batch.states, derived=derived):
            sets = self.perturbation.sets
            if holds_at(make, sets, batch.states[:PERTURBED_STATES], derived=derived):
                self.found.append(edit)
            else:
                self.coincidences.append(edit)
        self.longest = max(self.longest, now() - started)

    def findings(self) -> list[Finding]:
        """The ``repair`` findings: the first edit that held, confirmed or not and why, then the
        others that held (module docstring)."""
        first, others = self.found[0], self.found[1 : ALTERNATIVES + 1]
        perturbation = self.perturbation
        sets = len(perturbation.sets)
        limits = perturbation.why_not_alone(first.parameters())
        limits += perturbation.unmoved_beside(first.parameters(), self.read)
        confirmed = not limits and not others and sets > 0
        if confirmed:
            verdict, why_not = f"at these parameter values and at {sets} others ({perturbation.how})", ""
        else:
            also = [f"every check passes as well when {o.given_words()}" for o in others]
            verdict, why_not = "at these parameter values", "; not confirmed: " + "; ".join(limits + also)
        out = [self._finding(first, verdict, why_not, confirmed)]
        for other in others:
            out.append(self._finding(other, "as well", "; not confirmed: like the first", False, True))
        return out

    def _finding(self, edit: ParameterEdit, verdict: str, why_not: str, confirmed: bool, alternative=False):
        """One ``repair`` finding: the edit, ``verdict`` (where it holds), what the code does then,
        where to look, ``why_not`` (why it is not confirmed, or ""), where the code is."""
        where, parts = location(type(self.batch.model))
        users = parts_using(self.batch.model, self.screening.states, edit.name, parts)
        message = (
            f"{'or, equally: ' if alternative else ''}{edit.written()}: every check passes on every "
            f"state when {edit.given_words()}, {verdict}: {edit.meaning(self.kinds)} (look where "
            f"{uses(users, edit.name, parts)}){why_not} ({where})"
        )
        details = {
            "written": edit.written(),
            "suggested": edit.suggested(),
            "suggested_source": edit.given_words(),
            "location": where,
            "checks_pass": True,
            "confirmed": confirmed,
        }
        return Finding("repair", message, details=details)

    def coincidence_note(self) -> str:
        """For the sentence that says no repair was found: the edits that held at the file's values
        only, or ""."""
        if not self.coincidences:
            return ""
        edits = "; ".join(e.given_words() for e in self.coincidences[:2])
        more = f" and {len(self.coincidences) - 2} more" if len(self.coincidences) > 2 else ""
        return (
            f"; every check passes when {edits}{more} at these parameter values, but not at other values "
            f"({self.perturbation.how}): a coincidence of the values, not a repair"
        )
