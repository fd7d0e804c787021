"""A corpus of planted single-edit errors, and how well the diagnosis names and repairs them.

For every model file the worked examples ship (``pendverify.worked_examples``: the Python
class, and the same model as LaTeX or text where there is one) and every non-zero entry of
its written closed forms, one error per operator (``OPERATORS``) is planted where the
operator applies — the first place in the entry's tree where it changes the entry — with
``pendverify.symbolic.edited.edited_model``.  A planted model that passes every check is
*not detected* and left out (an equivalent edit, or a gap ``pendverify mutate`` reports); a
model passes as ``pendverify check`` judges it, a C that is a valid C·q̇ but not the Christoffel
C warning (``pendverify.diagnosis.acceptance``).
For each detected one the diagnosis (``pendverify.diagnosis.explain``) is run and scored:

named
    an ``entry`` finding names the planted entry (for a Coriolis-type matrix, which is not
    unique, its row of C·q̇; for a form beyond the interface, any entry of what it feeds);
repaired
    a confirmed ``repair`` finding (every check passes on every state);
restored
    the repair gives back the entries as they were, or ones proved equal to them
    (``pendverify.symbolic.zero_test``): the planted edit or an equivalent one;
confirmed
    a repair printed as confirmed (``details["confirmed"]``: it held at perturbed parameter sets
    too, ``pendverify.diagnosis.repair``) restores the planted entry;
wrong_confirmed
    a repair is printed as confirmed, and none that is restores the planted entry: advice that
    must never be given, whatever the parameter values;
ambiguity_stated
    no repair is printed as confirmed, and one printed as holding at these values only (the
    first or an alternative it names) restores the planted entry: the user is told the fix and
    that the checks cannot single it out;
seconds
    how long the diagnosis took (``explain``, after the checks, as ``check`` runs it).

The untouched models must pass every check (``ModelScores.clean``; warnings pass, as in
``pendverify check``), so get no diagnosis.  A corpus of pairs (``pair_plants``: two errors at
once, in different keys) is scored the same way, each of the two named and restored.
"""

from __future__ import annotations

import dataclasses
import itertools
import random
import time
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.analytic.text_expression import read_expression
from pendverify.analytic.text_parse import CONSTANTS, FUNCTIONS
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.acceptance import passes
from pendverify.diagnosis.derived import derived_methods
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.mechanics_source import entry_changes, planted_model, source_items
from pendverify.diagnosis.slots import QUANTITY
from pendverify.symbolic.edited import edited_model
from pendverify.symbolic.edits import parameter_edits, term_edits, trig_edits, walk
from pendverify.symbolic.zero_test import is_zero

OPERATORS = (
    "sign",
    "drop",
    "duplicate",
    "factor 2",
    "factor ½",
    "sin↔cos",
    "swap θ",
    "swap θ̇",
    "parameter",
    "offset",
    "pivot",
)
CORPUS_SEED = 24
CORPUS_SAMPLES = 12  # random states per planted model, besides the special ones


@dataclass(frozen=True)
class Plant:
    """One planted error: ``new`` for entry ``index`` (row-major) of ``method``."""

    method: str
    index: int
    operator: str
    original: sp.Expr
    new: sp.Expr
    what: str


def _pivot(expr, kinds: dict) -> sp.Expr | None:
    """The entry with one more m·r² (an inertia about the pivot where the centre of mass is meant)."""
    for node, _ in walk(expr):
        if node.is_Mul:
            mass = [s for s in node.free_symbols if kinds.get(s) == "mass"]
            length = [s for s in node.free_symbols if kinds.get(s) in ("length", "offset") and node.has(s**2)]
            if mass and length:
                return expr + mass[0] * length[0] ** 2
    return None


def entry_plants(method: str, index: int, expr, sm: SymbolicModel, kinds: dict) -> list[Plant]:
    """One planted error per operator that applies to this entry (module docstring)."""
    angles, rates = sm.angles, sm.symbols["v"]
    found: dict[str, tuple] = {}
    factors = (("duplicate", sp.Integer(2), "2"),)
    for edit in itertools.chain(term_edits(expr, rates, factors), trig_edits(expr, angles, offsets=True)):
        if edit.operator in ("scale",):
            continue
        if edit.operator == "offset" and edit.new.args and edit.new.args[0] - edit.old.args[0] != sp.pi / 2:
            continue
        if edit.operator not in found and edit.expr != expr:
            found[edit.operator] = (edit.expr, edit.what)
    for edit in parameter_edits(expr, kinds):
        if edit.expr != expr:
            found.setdefault("parameter", (edit.expr, edit.what))
            break
    found["factor 2"] = (2 * expr, f"{expr} → 2·({expr})")
    found["factor ½"] = (expr / 2, f"{expr} → ({expr})/2")
    if method == "mass_matrix":
        pivot = _pivot(expr, kinds)
        if pivot is not None:
            found["pivot"] = (pivot, f"{expr} → {pivot}")
    return [Plant(method, index, op, expr, *found[op]) for op in OPERATORS if op in found]


#: the ``method`` of a plant in an item of a ``sympy.physics.mechanics`` derivation (its ``index``:
#: the item's position, ``pendverify.diagnosis.mechanics_source.source_items``)
SOURCE = "source"


def plants(sm: SymbolicModel) -> list[Plant]:
    """Every planted error of the corpus for one model, in the keys it writes (not in one it derives
    from another, ``pendverify.diagnosis.derived``: a user cannot type an error there); for a model
    made from a ``sympy.physics.mechanics`` derivation, in what the derivation is written from
    (its bodies, particles, loads: ``SOURCE`` plants), with the same operators."""
    derivation = getattr(sm.cls, "derivation", None)
    items = source_items(derivation, sm) if derivation is not None else []
    if items:
        return [
            p
            for k, item in enumerate(items)
            if item.expr != 0
            for p in entry_plants(SOURCE, k, item.expr, sm, sm.kinds)
        ]
    kinds = sm.kinds
    derived = derived_methods(sm.cls)
    out = []
    for method, value in sm.closed_forms.items():
        if method in derived:
            continue
        for index, expr in enumerate(entries(value)):
            if expr != 0:
                out += entry_plants(method, index, expr, sm, kinds)
    return out


@dataclass
class Score:
    """What the diagnosis did with one planted error."""

    plant: Plant
    #: the other errors planted with it (a pair: ``pair_plants``)
    also: tuple = ()
    detected: bool = False
    named: bool = False
    repaired: bool = False
    restored: bool = False
    confirmed: bool = False
    wrong_confirmed: bool = False
    ambiguity_stated: bool = False
    seconds: float = 0.0
    message: str = ""


@dataclass
class ModelScores:
    """One model file's corpus: every planted error scored, and whether the untouched model is clean."""

    label: str
    scores: list[Score] = field(default_factory=list)
    clean: bool = True

    def count(self, what: str) -> int:
        return sum(getattr(s, what) for s in self.scores)


def _named(plant: Plant, findings, forms) -> bool:
    """Whether an ``entry`` finding names the planted entry (module docstring).  A form beyond the
    interface, B and W (no check compares them with Pinocchio) and D where no check compares it
    alone (a URDF without damping) show only in what they feed (q̈): named when any entry is."""
    value = forms[plant.method]
    quantity = QUANTITY.get(plant.method)
    named = [(f.quantity, f.index) for f in findings if f.kind == "entry"]
    if quantity in (None, "B", "W") or (quantity == "D" and all(q != "D" for q, _ in named)):
        return bool(named)
    if isinstance(value, sp.MatrixBase):
        index = tuple(i + 1 for i in entry_position(plant.method, value.shape, plant.index))
    else:
        index = ()
    if quantity == "C":  # C is not unique: its row of C·q̇ is what differs
        return (quantity, index) in named or ("Cqdot", (index[0],)) in named
    return (quantity, index) in named


def _restored(findings, plant: Plant, sm: SymbolicModel, confirmed: bool | None = None) -> bool:
    """Whether a repair of the planted entry that makes every check pass (and is ``confirmed``, or
    not, when that is given) gives back the original (or an equal) entry."""
    names = {s.name: s for group in sm.symbols.values() for s in group}
    names |= {p.name: p for p in sm.parameters.values()} | FUNCTIONS | CONSTANTS
    for f in findings:
        if f.kind != "repair" or not f.details.get("checks_pass"):
            continue
        if confirmed is not None and bool(f.details.get("confirmed")) is not confirmed:
            continue
        if f.details["written"] == str(plant.new):
            suggested = read_expression(f.details["suggested"], names)
            if is_zero(suggested - plant.original, sm.angles):
                return True
    return False


def _planted(model, sm: SymbolicModel, group) -> tuple:
    """(the planted model, the entry plants it amounts to): the entries edited for entry plants; for a
    ``SOURCE`` plant the derivation with the item edited (``mechanics_source.planted_model``),
    and each entry it changes in a key the model writes as a plant (None when the pair form
    refuses it)."""
    if group[0].method != SOURCE:
        edits: dict[str, list] = {}
        for p in group:
            edits.setdefault(p.method, []).append((p.index, p.original, p.new))
        return edited_model(model, sm, edits, "Planted"), group
    plant = group[0]
    cls = planted_model(model, sm, plant.index, plant.new)
    if cls is None:
        return None, ()
    params = cls.params_type(
        **{f.name: getattr(model.params, f.name) for f in dataclasses.fields(cls.params_type)}
    )
    item = source_items(type(model).derivation, sm)[plant.index]
    changes = entry_changes(type(model).derivation, sm, item, plant.new) or {}
    derived = derived_methods(type(model))  # V integrated from H: never repaired itself
    entry_group = tuple(
        Plant(method, index, plant.operator, old, new, plant.what)
        for (method, index), (old, new) in changes.items()
        if method not in derived
    )
    return cls(params), entry_group


def _source_restored(findings, plant: Plant, sm: SymbolicModel, confirmed: bool | None = None) -> bool:
    """Whether a repair of a source item (``details["source_item"]``) that makes every check pass
    (and is ``confirmed``, or not, when given) writes the planted item back as it was."""
    names = {s.name: s for group in sm.symbols.values() for s in group}
    names |= {p.name: p for p in sm.parameters.values()} | FUNCTIONS | CONSTANTS
    for f in findings:
        if f.kind != "repair" or "source_item" not in f.details or not f.details.get("checks_pass"):
            continue
        if confirmed is not None and bool(f.details.get("confirmed")) is not confirmed:
            continue
        if f.details["written"] == str(plant.new):
            if is_zero(read_expression(f.details["suggested"], names) - plant.original, sm.angles):
                return True
    return False


def _all_restored(findings, group, entry_group, sm: SymbolicModel, confirmed: bool | None = None) -> bool:
    """Whether every planted error of ``group`` is restored: an entry plant by a repair of its entry;
    a ``SOURCE`` plant by a repair of its item, or by repairs of every entry it changes."""
    if group[0].method == SOURCE:
        if _source_restored(findings, group[0], sm, confirmed):
            return True
        group = entry_group
    return all(_restored(findings, p, sm, confirmed) for p in group)


def score_model(
    label: str, model, system, chosen=None, deadline_s: float = 10.0, progress=None
) -> ModelScores:
    """The corpus of one model (``chosen``: a subset of its plants), each planted error scored."""
    cls = type(model)
    sm = SymbolicModel.of(cls)
    forms = sm.closed_forms
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    out = ModelScores(label)
    batch = CheckBatch(model, system, states)
    results = run_checks(label, model, system, states, CORPUS_SEED, applicable_checks(model, system), batch)
    out.clean = passes(results)
    for item in plants(sm) if chosen is None else chosen:
        group = item if isinstance(item, tuple) else (item,)  # a pair: two errors at once
        plant = group[0]
        score = Score(plant, also=group[1:])
        planted, entry_group = _planted(model, sm, group)
        if planted is None:  # a derivation the pair form refuses once edited: not a model to score
            continue
        with np.errstate(all="ignore"):
            batch = CheckBatch(planted, system, states)
            try:
                results = run_checks(
                    label, planted, system, states, CORPUS_SEED, applicable_checks(planted, system), batch
                )
            except (ArithmeticError, ValueError, np.linalg.LinAlgError):
                results = None
        if results is not None and not passes(results):
            score.detected = True
            start = time.perf_counter()  # the diagnosis alone, as check runs it after the checks
            findings = explain(batch, results, deadline_s)
            score.seconds = time.perf_counter() - start
            score.named = any(_named(p, findings, forms) for p in entry_group)
            if group[0].method != SOURCE:  # entry plants: every one named
                score.named = all(_named(p, findings, forms) for p in group)
            score.repaired = any(f.kind == "repair" and f.details.get("checks_pass") for f in findings)
            score.restored = _all_restored(findings, group, entry_group, sm)
            printed_confirmed = any(f.kind == "repair" and f.details.get("confirmed") for f in findings)
            score.confirmed = _all_restored(findings, group, entry_group, sm, confirmed=True)
            score.wrong_confirmed = printed_confirmed and not score.confirmed
            score.ambiguity_stated = not printed_confirmed and _all_restored(
                findings, group, entry_group, sm, confirmed=False
            )
            score.message = next((f.message for f in findings if f.kind == "repair"), "")
        out.scores.append(score)
        if progress is not None:
            progress.update(1)
    return out


def sample_plants(sm: SymbolicModel, per_operator: int, seed: int = CORPUS_SEED) -> list[Plant]:
    """Up to ``per_operator`` planted errors of each operator, drawn with ``seed``."""
    rng = random.Random(seed)
    by_operator: dict[str, list[Plant]] = {}
    for plant in plants(sm):
        by_operator.setdefault(plant.operator, []).append(plant)
    chosen = []
    for operator in OPERATORS:
        group = by_operator.get(operator, [])
        chosen += rng.sample(group, min(per_operator, len(group)))
    return chosen


#: the keys a pair of planted errors is drawn from, one error in each of two of them
PAIR_KEYS = ("mass_matrix", "coriolis_matrix", "coriolis_force", "gravity")


def pair_plants(sm: SymbolicModel, count: int, seed: int = CORPUS_SEED) -> list[tuple[Plant, Plant]]:
    """``count`` pairs of planted errors in two different keys of ``PAIR_KEYS`` (one in M and one
    in C, ...), drawn with ``seed`` from every such pair of the corpus's single plants."""
    by_key: dict[str, list[Plant]] = {}
    for plant in plants(sm):
        if plant.method in PAIR_KEYS:
            by_key.setdefault(plant.method, []).append(plant)
    pairs = [
        (a, b) for k1, k2 in itertools.combinations(sorted(by_key), 2) for a in by_key[k1] for b in by_key[k2]
    ]
    return random.Random(seed).sample(pairs, min(count, len(pairs)))
