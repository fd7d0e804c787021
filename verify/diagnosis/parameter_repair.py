"""Repairs of a model whose code SymPy cannot read: edits of the parameter set the code is given.

Dynamics as code (``DYNAMICS``, ``pendverify.analytic.python_dynamics``), NumPy functions
(``pendverify.analytic.numpy_model``) and Python classes whose methods call NumPy or ``math``
cannot be read as expressions, so ``pendverify.diagnosis.repair`` cannot edit them.  Their
*parameters* can be edited: the code reads a parameter set, and many real errors are one
parameter used wrongly wherever the code uses it.  The search gives the code an edited set and
asks whether every check then passes.

What is tried (``parameter_edits``), simplest first, at most ``EDITS``:

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

Only the parameters the code reads are edited (``read_parameters``: those some part of the code
changes with at the screening states, each moved by a quarter); one it does not read may be
what another is given.  An exchange with such a parameter is that substitution (l ↔ lc where the
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

import copy
import dataclasses
import time
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp

from pendverify.analytic.numpy_model import FUNCTIONS, NumpyFunctionModel
from pendverify.analytic.parameter_set import KIND_DIMENSIONS
from pendverify.analytic.python_dynamics import PythonDynamicsModel
from pendverify.analytic.source_file import where
from pendverify.checks.batch import CheckBatch
from pendverify.diagnosis.confirmation import PERTURBED_STATES, derives_scales, holds_at
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.monomials import fixed_parameters, products_of
from pendverify.diagnosis.perturbed import MovedSet, perturbations
from pendverify.diagnosis.slots import SCREEN_RTOL, SCREEN_STATES
from pendverify.errors import ParameterError

#: the factors of step 1 and of step 3 (module docstring)
FIRST_SCALES = (Fraction(2), Fraction(1, 2), Fraction(-1))
LATER_SCALES = (Fraction(4), Fraction(1, 4), Fraction(3), Fraction(1, 3), Fraction(12), Fraction(1, 12))
#: distinct parameters in a product added to or taken from a parameter (m·l² has two)
ADDED_FACTORS = 2
#: edits screened at most
EDITS = 400
#: edits run through every check at most (each a run of the checks, and of the perturbed sets)
CONFIRMATIONS = 12
#: edits that hold shown besides the first
ALTERNATIVES = 2


@dataclass(frozen=True)
class ParameterEdit:
    """One edit of the parameter set the code is given (module docstring)."""

    kind: str  # "scale", "exchange", "other" or "add"
    name: str  # the parameter whose value the code is given otherwise
    other: str = ""  # exchange, other: the parameter whose value it gets
    factor: Fraction = Fraction(1)  # scale
    term: sp.Expr = sp.S.Zero  # add: the product added (with its sign)

    def given(self, values: dict[str, float]) -> dict[str, float]:
        """The values the code is given in place of ``values``' (only those that change)."""
        if self.kind == "scale":
            return {self.name: float(self.factor) * values[self.name]}
        if self.kind == "exchange":
            return {self.name: values[self.other], self.other: values[self.name]}
        if self.kind == "other":
            return {self.name: values[self.other]}
        symbols = {sp.Symbol(n): v for n, v in values.items()}
        return {self.name: values[self.name] + float(self.term.xreplace(symbols))}

    def applied(self, params):
        """``params`` with the edit, of the same type: validated as a set is where the values keep
        the kinds' rules, else the same set with the values replaced (module docstring)."""
        changes = self.given(params.as_dict())
        try:
            return params.replace(**changes)
        except (ParameterError, ValueError, ArithmeticError, TypeError):
            edited = copy.copy(params)
            for name, value in changes.items():
                object.__setattr__(edited, name, value)
            return edited

    def parameters(self) -> set[str]:
        """The parameters the edit involves (``Perturbation.why_not_alone``)."""
        extra = {self.other} if self.other else {str(s) for s in self.term.free_symbols}
        return {self.name} | extra

    def written(self) -> str:
        """What the code is given now (SymPy syntax): ``m2``; ``l1, l2`` for an exchange."""
        return f"{self.name}, {self.other}" if self.kind == "exchange" else self.name

    def suggested(self) -> str:
        """What the code is to be given instead: ``m2/2``; ``l2, l1`` for an exchange."""
        p = sp.Symbol(self.name)
        if self.kind == "scale":
            return str(sp.Rational(self.factor.numerator, self.factor.denominator) * p)
        if self.kind == "exchange":
            return f"{self.other}, {self.name}"
        return self.other if self.kind == "other" else str(p + self.term)

    def given_words(self) -> str:
        """ "the code is given m2/2 for m2" (the edit, in words)."""
        if self.kind == "exchange":
            return f"the code is given {self.other} for {self.name} and {self.name} for {self.other}"
        return f"the code is given {self.suggested()} for {self.name}"

    def meaning(self, kinds: dict[str, str]) -> str:
        """What the code does, if the edit is the repair, in the user's terms."""
        p = sp.Symbol(self.name)
        if self.kind == "scale":
            used = sp.Rational(self.factor.denominator, self.factor.numerator) * p
            return f"the code uses {_pretty(used)} where the robot has {self.name}"
        if self.kind == "exchange":
            return (
                f"the code uses {self.name} where {self.other} belongs, "
                f"and {self.other} where {self.name} belongs"
            )
        if self.kind == "other":
            return f"the code uses {self.name} where {self.other} belongs"
        out = f"the code uses {self.name} where {_pretty(p + self.term)} belongs"
        masses = [s for s in self.term.free_symbols if kinds.get(str(s)) == "mass"]
        if kinds.get(self.name) == "inertia" and masses:  # m·l²: an inertia about another point
            if self.term.could_extract_minus_sign():
                axis = f"the parallel-axis term {_pretty(-self.term)} counted twice"
                return f"{out} ({axis}: an inertia about the pivot where the centre of mass's belongs?)"
            axis = f"the parallel-axis term {_pretty(self.term)}"
            return f"{out} ({axis}: an inertia about the centre of mass where the pivot's belongs?)"
        return out


def _pretty(expr) -> str:
    """``2·m2``, ``m2·r2²``, ``−g``: an expression as the messages write it."""
    text = str(expr)
    for exponent, superscript in (("**2", "²"), ("**3", "³")):
        text = text.replace(exponent, superscript)
    return text.replace("*", "·").replace("-", "−")


def alike(a: str, b: str, kinds: dict, values: dict) -> bool:
    """Whether parameters ``a`` and ``b`` have one dimension (a damping coefficient only with another)
    and different values: one can stand for the other."""
    da, db = KIND_DIMENSIONS.get(kinds[a]), KIND_DIMENSIONS.get(kinds[b])
    same = da == db if da is not None else kinds[a] == kinds[b] is not None
    return a != b and same and values[a] != values[b]


def parameter_edits(params, read=None) -> list[ParameterEdit]:
    """The edits tried, in order (module docstring), at most ``EDITS``; ``read``: the parameters the
    code reads (``read_parameters``; None: all).  An edit changes what the code is given for a
    parameter it reads; an exchange with one it does not read is the other given for it (l → lc,
    where the code reads l and not lc), and is tried as that."""
    kinds = {f.name: f.metadata.get("kind") for f in dataclasses.fields(params)}
    values = params.as_dict()
    every = [n for n in kinds if np.isfinite(values[n]) and values[n] != 0]
    names = [n for n in every if read is None or n in read]

    out = [ParameterEdit("scale", n, factor=k) for k in FIRST_SCALES for n in names]
    out += [
        ParameterEdit("exchange", a, b)
        for i, a in enumerate(names)
        for b in names[i + 1 :]
        if alike(a, b, kinds, values)
    ]
    out += [ParameterEdit("other", a, b) for a in names for b in every if alike(a, b, kinds, values)]
    out += [ParameterEdit("scale", n, factor=k) for k in LATER_SCALES for n in names]
    fixed = fixed_parameters(params)
    for name in names:
        dimension = KIND_DIMENSIONS.get(kinds[name])
        if dimension is None:
            continue
        products = [
            expr
            for _, expr in products_of(fixed, dimension)
            if len(expr.free_symbols) <= ADDED_FACTORS and expr != sp.Symbol(name)
        ]
        for expr in sorted(products, key=lambda e: (sp.Poly(e).total_degree(), str(e))):
            out += [ParameterEdit("add", name, term=expr), ParameterEdit("add", name, term=-expr)]
    return out[:EDITS]


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
    deadline = time.perf_counter() + deadline_s
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
    edits = parameter_edits(model.params, read_parameters(model, screening.states))
    screened, screen_s = 0, 0.0
    for edit in edits:
        # a screen is started while the longest screen (and confirmation) so far still fits the bound
        if time.perf_counter() + max(search.longest, screen_s) > deadline or search.done:
            break
        screened += 1
        started = time.perf_counter()
        passed = not differing(type(model)(edit.applied(model.params)), screening)
        screen_s = max(screen_s, time.perf_counter() - started)
        if passed and time.perf_counter() + search.longest <= deadline:
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
        started = time.perf_counter()
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
        self.longest = max(self.longest, time.perf_counter() - started)

    def findings(self) -> list[Finding]:
        """The ``repair`` findings: the first edit that held, confirmed or not and why, then the
        others that held (module docstring)."""
        first, others = self.found[0], self.found[1 : ALTERNATIVES + 1]
        perturbation = self.perturbation
        sets = len(perturbation.sets)
        limits = perturbation.why_not_alone(first.parameters())
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
        location, parts = _location(type(self.batch.model))
        users = parts_using(self.batch.model, self.screening.states, edit.name, parts)
        message = (
            f"{'or, equally: ' if alternative else ''}{edit.written()}: every check passes on every "
            f"state when {edit.given_words()}, {verdict}: {edit.meaning(self.kinds)} (look where "
            f"{_uses(users, edit.name, parts)}){why_not} ({location})"
        )
        details = {
            "written": edit.written(),
            "suggested": edit.suggested(),
            "suggested_source": edit.given_words(),
            "location": location,
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


#: each interface method's arguments (``pendverify.analytic.forms.INTERFACE``'s ``args``)
_ARGUMENTS = {
    "mass_matrix": "q",
    "coriolis_matrix": "qv",
    "coriolis_force": "qv",
    "bias": "qv",
    "gravity": "q",
    "potential_energy": "q",
    "acceleration": "qvuw",
}


#: the matrices a dynamics-as-code declaration writes, by their methods
_DECLARED = {"damping_matrix": "D", "input_matrix": "B", "disturbance_matrix": "W"}


def _location(model_cls) -> tuple[str, dict[str, str]]:
    """(where the code is: its file and what it defines, its parts: method → the name the code
    gives it)."""
    if issubclass(model_cls, PythonDynamicsModel):
        name = f"DYNAMICS {getattr(model_cls.dynamics, '__name__', 'function')}"
        declared = {m: f'DECLARATION["{k}"]' for m, k in _DECLARED.items() if m in model_cls.hand_written()}
        return f"{model_cls.source}, {name}", {"acceleration": "DYNAMICS", **declared}
    if issubclass(model_cls, NumpyFunctionModel):
        parts = {FUNCTIONS[key][2]: key for key in model_cls.functions}
        if "h" in model_cls.functions:
            parts |= {"coriolis_force": "h", "gravity": parts.get("gravity", "h")}
        return f"{model_cls.source}, functions {', '.join(model_cls.functions)}", parts
    parts = {m: f"{model_cls.__name__}.{m}" for m in model_cls.hand_written() if m in _ARGUMENTS or m in (
        "damping_matrix", "input_matrix", "disturbance_matrix")}  # fmt: skip
    return f"{where(model_cls)}, class {model_cls.__name__}", parts


def parts_using(model, states, name: str, parts: dict[str, str]) -> list[str]:
    """The parts of ``model``'s code (``parts``: method → the name the code gives it) whose values
    change with parameter ``name`` (moved by a quarter) at some state of ``states``."""
    other = type(model)(ParameterEdit("scale", name, factor=Fraction(5, 4)).applied(model.params))
    rows = [{"q": s.q, "v": s.v, "u": s.u, "w": s.w} for s in states]
    out = []
    with np.errstate(all="ignore"):
        for method, part in parts.items():
            for row in rows:
                args = [row[a] for a in _ARGUMENTS.get(method, "")]
                try:
                    a = np.asarray(getattr(model, method)(*args), dtype=float)
                    b = np.asarray(getattr(other, method)(*args), dtype=float)
                except Exception:  # the user's code at moved values: not seen to use it
                    break
                if a.shape != b.shape or not np.array_equal(a, b):
                    out.append(part)
                    break
    return list(dict.fromkeys(out))


def read_parameters(model, states) -> set[str]:
    """The parameters ``model``'s code reads: those some part of it changes with at ``states``."""
    _, parts = _location(type(model))
    return {n for n in model.params.as_dict() if parts_using(model, states, n, parts)}


def _uses(found: list[str], name: str, parts: dict[str, str]) -> str:
    """ "M, G use m2": the parts that use a parameter, or all of them when none was seen to."""
    names = found or list(dict.fromkeys(parts.values()))
    return f"{', '.join(names)} use{'s' if len(names) == 1 else ''} {name}"
