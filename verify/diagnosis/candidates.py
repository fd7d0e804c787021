"""What could repair a slot: the edits tried on one entry, screened at the screening states.

Per slot (``pendverify.diagnosis.slots``), the edits of ``pendverify.symbolic.edits`` (the
inverses of ``pendverify mutate``'s operators) are evaluated at the screening states,
vectorised over them, and those that make the slot agree are kept (``screen_slot``).  Three kinds
are found from the numbers rather than enumerated blindly:

* a coefficient k on one term (t → k·t), fitted by least squares over the states where the
  entry is affine in it and kept when k is one of ``COEFFICIENTS`` — this undoes a sign
  (k = −1), a duplicated term or a factor 2 (k = ½), a factor ½ (k = 2), a term that should
  not be there (k = 0) and ``pendverify mutate``'s 1e-3 scale;
* an added term: the entry's difference fitted by the basis of
  ``pendverify.diagnosis.patterns``, each coefficient matched to a simple fraction times a
  product of at most ``DEGREE`` parameters of the kinds the quantity allows (the model's own
  products first) — this undoes a dropped term and an inertia about the pivot (± m·r²);
* a restored term: a sum completed by the one term it lacks, as the same sum stands elsewhere
  in the model (a term dropped inside det M or M⁻¹);
* a det M completed by what it lacks of the determinant of the written M;
* a number written in the entry put right (a decimal factor, a 3 for a 2): solved for where
  the entry is affine in it, kept when it is a simple fraction.

``candidates`` orders what passed the screen for confirmation, simplest first (``RANK``): each
edit alone, then the same edit wherever the same expression stands in other slots (a shared
sub-expression in code, a shorthand in a LaTeX file), then pairs of two slots' edits
(``slot_pairs``; ``cross_pairs`` for two errors in different keys or entries).
``pairs_within`` tries two edits of one entry, for models of up to three degrees of freedom.
"""

from __future__ import annotations

import collections
import dataclasses
import functools
import itertools
from collections.abc import Iterator
from fractions import Fraction

import numpy as np
import sympy as sp

from pendverify.analytic.parameter_set import KIND_DIMENSIONS
from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.diagnosis.clock import now
from pendverify.diagnosis.patterns import basis_for, fit
from pendverify.diagnosis.slots import QUANTITY, SCREEN_RTOL, Slot
from pendverify.symbolic.edits import Edit, phrase, replace_at, structural_edits, sums, walk, with_term

DEGREE = 3
MAX_PAIRS = 40

#: the coefficients a one-term edit may put right: a sign, a dropped term, a factor 2 or ½
#: (a duplicated term), and the inverse of ``pendverify mutate``'s 1e-3 scale
COEFFICIENTS = (Fraction(-1), Fraction(0), Fraction(2), Fraction(1, 2), Fraction(1000, 1001))


def _nice(k: float) -> Fraction | None:
    """k as one of ``COEFFICIENTS`` when it is one to rounding."""
    if not np.isfinite(k):
        return None
    return next((c for c in COEFFICIENTS if abs(float(c) - k) <= 1e-9 * max(1.0, abs(k))), None)


def _affine(expr, path) -> bool:
    """Whether the entry is affine in the coefficient of the term at ``path`` (only sums and
    products above it)."""
    node = expr
    for i in path:
        if not (node.is_Add or node.is_Mul):
            return False
        node = node.args[i]
    return True


def _coefficient_edits(slot: Slot, evaluate) -> list[Edit]:
    """t → k·t for one term: k solved for by least squares where the entry is affine in it,
    each of ``COEFFICIENTS`` tried where it is not (inside a power or a function)."""
    out = []
    if slot.row is None:
        goal = slot.target
    else:  # the entry value that zeroes the row's residual, where its rate is not zero
        with np.errstate(all="ignore"):
            goal = slot.values - slot.row[0] / np.where(slot.row[1] != 0, slot.row[1], np.nan)
    places = [((), [slot.expr], 0, True)]
    places += [(p, t, i, False) for p, t in sums(slot.expr) for i in range(len(t))]
    for path, terms, i, whole in places:
        term = terms[i]
        if whole or _affine(slot.expr, path):
            without = sp.S.Zero if whole else with_term(slot.expr, path, terms, i, None)
            base = evaluate(without, slot.symbols)
            part = slot.values - base
            target = goal - base
            if slot.centred:
                part, target = part - np.mean(part), target - np.mean(target)
            ok = np.isfinite(target) & np.isfinite(part)
            denominator = float(np.dot(part[ok], part[ok]))
            k = _nice(float(np.dot(part[ok], target[ok]) / denominator)) if denominator > 0 else None
            tried = [k] if k is not None else []
        else:
            tried = list(COEFFICIENTS)
        for k in tried:
            factor = sp.Rational(k.numerator, k.denominator)
            new = factor * term
            expr = new if whole else with_term(slot.expr, path, terms, i, new)
            operator = {0: "drop", -1: "sign"}.get(k, "scale")
            out.append(Edit(operator, term, new, expr, phrase("{} → {}", term, new)))
    return out


#: the largest denominator of a simple fraction, the numbers of hand derivations (½, ⅓, ¼, 1/12 of a
#: rod's inertia): a written number put right, a constant entry, a coefficient matched to parameters
NUMBER_DENOMINATOR = 12


def _number_edits(slot: Slot, evaluate) -> list[Edit]:
    """A number written in the entry (``1.1`` in ``1.1*(I + m*lc**2)``, which SymPy spreads over
    the sum's terms) put right: every occurrence of it replaced by the value that makes the entry
    agree, solved for where the entry is affine in it (its values at 0, 1 and 2 on a line), and
    kept when that value is a fraction of denominator at most ``NUMBER_DENOMINATOR``.  What no
    coefficient of ``COEFFICIENTS`` undoes: a decimal factor, a 3 for a 2."""
    if slot.row is not None or slot.target is None:
        return []
    numbers = {n for n, _ in walk(slot.expr) if n.is_Number and abs(n) != 1 and n != 0}
    out = []
    for number in sorted(numbers, key=str):
        at = [evaluate(slot.expr.xreplace({number: sp.Integer(v)}), slot.symbols) for v in (0, 1, 2)]
        slope = at[1] - at[0]
        ok = np.isfinite(slope) & np.isfinite(slot.target) & np.isfinite(at[2])
        scale = np.max(np.abs(at[0][ok]), initial=0.0) + np.max(np.abs(slope[ok]), initial=0.0)
        if not ok.any() or np.max(np.abs(at[2][ok] - 2 * at[1][ok] + at[0][ok])) > 1e-9 * max(scale, 1e-300):
            continue  # not affine in the number (inside a power or a function)
        denominator = float(np.dot(slope[ok], slope[ok]))
        if not denominator > 0:
            continue
        value = float(np.dot(slope[ok], slot.target[ok] - at[0][ok]) / denominator)
        fraction = Fraction(value).limit_denominator(NUMBER_DENOMINATOR) if np.isfinite(value) else None
        if fraction is None or abs(float(fraction) - value) > 1e-9 * max(1.0, abs(value)):
            continue
        new = sp.Rational(fraction.numerator, fraction.denominator)
        if new != number:
            expr = slot.expr.xreplace({number: new})
            out.append(Edit("number", number, new, expr, phrase("{} → {}", number, new)))
    return out


#: the kinds of parameter an added term of each quantity may hold (its units): friction only in
#: D, gravity only in H and V
KINDS_OF = {
    "D": {"damping"},
    "H": {"mass", "length", "offset", "gravity", "inertia", ""},
    "V": {"mass", "length", "offset", "gravity", "inertia", ""},
}
OTHER_KINDS = {"mass", "length", "offset", "inertia", ""}


def monomials_for(sm: SymbolicModel, params: dict, quantity: str) -> tuple[list, list]:
    """(value, expression) of the parameter products an added term may hold: first those the
    model's own terms hold (the parameter part of each term of its written forms), then every
    product of at most ``DEGREE`` parameters of the kinds the quantity allows (``KINDS_OF``)."""
    kinds = sm.kinds
    allowed = KINDS_OF.get(quantity, OTHER_KINDS)
    symbols = [s for s in sm.parameters.values() if kinds[s] in allowed]
    own: dict = {}
    for value in sm.closed_forms.values():
        for expr in entries(value):
            for _, terms in sums(expr):
                for term in terms:
                    factor = sp.Mul(*[f for f in sp.Mul.make_args(term) if f.free_symbols <= set(symbols)])
                    factor = factor.as_coeff_Mul()[1]
                    if factor.free_symbols:
                        own[factor] = None
    values = {sm.parameters[p]: v for p, v in params.items()}
    mine = []
    for expr in own:
        value = float(expr.xreplace(values))
        if value != 0 and np.isfinite(value):
            mine.append((value, expr))
    return mine, _products(tuple(symbols), tuple(values[s] for s in symbols))


@functools.lru_cache(maxsize=256)
def parameter_products(symbols: tuple, values: tuple, most: int) -> tuple[tuple[float, sp.Expr, tuple], ...]:
    """(value, expression, factors) of every nonzero finite product of at most ``most`` of ``symbols``
    (with repetition; ``factors`` the indices multiplied), kept for the process: the same parameter
    set meets every planted error of a model."""
    out = []
    for degree in range(1, most + 1):
        for combo in itertools.combinations_with_replacement(range(len(symbols)), degree):
            value = float(np.prod([values[i] for i in combo]))
            if value != 0 and np.isfinite(value):
                out.append((value, sp.Mul(*[symbols[i] for i in combo]), combo))
    return tuple(out)


def _products(symbols: tuple, values: tuple) -> list:
    """(value, expression) of every product of at most ``DEGREE`` of ``symbols`` (``parameter_products``)."""
    return [(value, expr) for value, expr, _ in parameter_products(symbols, values, DEGREE)]


FRACTIONS = tuple(
    Fraction(a, b) for b in (1, 2, 3, 4, 6, 12) for a in range(1, 5) if Fraction(a, b).denominator == b
)


PAIR_FACTORS = (1, -1, 2, -2, sp.Rational(1, 2), -sp.Rational(1, 2))


def _matched(coefficient: float, monomials) -> sp.Expr | None:
    """coefficient as ± a simple fraction times a product of parameters, or as a sum of two such
    (factors ±1, ±2, ±½), the simplest such; None when none equals it to 1e-9."""
    close = 1e-9 * abs(coefficient)
    for whole in (True, False):  # a product as it stands before one with a fraction
        for value, expr in monomials:
            ratio = Fraction(abs(coefficient) / value).limit_denominator(NUMBER_DENOMINATOR)
            if (
                (ratio == 1) is whole
                and ratio in FRACTIONS
                and abs(float(ratio) * value - abs(coefficient)) <= close
            ):
                return sp.sign(coefficient) * sp.Rational(ratio.numerator, ratio.denominator) * expr
    values = np.array([v for v, _ in monomials])
    order = np.argsort(values)
    ordered = values[order]
    for f1, f2 in itertools.product(PAIR_FACTORS, repeat=2):
        rest = (coefficient - float(f1) * values) / float(f2)  # what the second monomial must be
        at = np.clip(np.searchsorted(ordered, rest), 1, len(ordered) - 1)
        for k in np.flatnonzero(np.minimum(abs(ordered[at] - rest), abs(ordered[at - 1] - rest)) <= close):
            j = order[at[k]] if abs(ordered[at[k]] - rest[k]) <= close else order[at[k] - 1]
            if j != k:
                return f1 * monomials[k][1] + f2 * monomials[j][1]
    return None


#: the physical dimension (kg, m, s) of each kind of parameter whose unit is fixed
DIMENSIONS = {kind: d for kind, d in KIND_DIMENSIONS.items() if d is not None}


def _dimension(expr, kinds: dict) -> tuple | None:
    """The dimension of a product of parameters, or None when a factor's kind has no fixed unit."""
    total = np.zeros(3)
    for factor in sp.Mul.make_args(expr):
        if factor.is_Number:
            continue
        base, exponent = factor.as_base_exp()
        if kinds.get(base) not in DIMENSIONS or not exponent.is_Number:
            return None
        total += float(exponent) * np.array(DIMENSIONS[kinds[base]])
    return tuple(total)


def _entry_dimensions(expr, kinds: dict) -> set:
    """The dimensions of the parameter parts of an entry's terms (an added term must have one)."""
    out = set()
    for term in sp.Add.make_args(sp.expand(expr)):
        factor = sp.Mul(
            *[f for f in sp.Mul.make_args(term) if f.free_symbols and f.free_symbols <= set(kinds)]
        )
        dimension = _dimension(factor, kinds)
        if dimension is not None and factor != 1:
            out.add(dimension)
    return out


def _added_term_edits(slot: Slot, batch, monomials, kinds: dict) -> list[Edit]:
    """The entry's difference fitted and written as parameters times basis functions (module
    docstring).  For a Coriolis row the entry's share q̇j·Δ of the row's residual is fitted, with
    Δ in the basis of C."""
    quantity = QUANTITY.get(slot.method, "C" if slot.row is not None else None)
    if quantity not in ("M", "H", "V", "D", "detM", "Cqdot", "C"):
        return []
    model = batch.model
    basis = basis_for(quantity, batch.Q, batch.V, model.angular, model.coordinates)
    if slot.row is None:
        diff = slot.target - slot.values
    else:
        residual, rate = slot.row
        basis = [(name, values * rate, expr) for name, values, expr in basis]
        diff = -residual
    pattern = fit(diff, basis)
    if pattern is None:
        return []
    dimensions = _entry_dimensions(slot.expr, kinds)
    if dimensions:  # an added term has the dimension of the entry's own terms
        monomials = tuple(
            [(v, e) for v, e in group if _dimension(e, kinds) in dimensions] for group in monomials
        )
    added = []
    for (c, name), function in zip(pattern.terms, pattern.functions, strict=True):
        if slot.centred and name == "1":  # V is compared up to a constant
            continue
        own, generic = monomials  # the model's own products alone first, then with every other
        monomial = _matched(c, own) or _matched(c, own + generic)
        if monomial is None:
            return []
        added.append(monomial * function)
    term = sp.Add(*added)
    return [Edit("add", sp.S.Zero, term, slot.expr + term, f"add {term}")]


def sum_pool(sm: SymbolicModel) -> list[frozenset]:
    """The sums written anywhere in the model's closed forms, each as the set of its terms."""
    pool = set()
    for value in sm.closed_forms.values():
        for expr in entries(value):
            pool |= {frozenset(node.args) for node, _ in walk(expr) if node.is_Add}
    return sorted(pool, key=len)


def _restored_term_edits(slot: Slot, pool) -> list[Edit]:
    """A sum (or a lone term) completed by the one term it lacks, as the same sum stands elsewhere
    in the model: the inverse of a term dropped inside a factor (det M, M⁻¹).  A sum written inside
    another sum is one sum to SymPy (q̈'s −(d2·θ̈2 + φ1)/d1, where φ1 stands alone in θ̈2): a sum
    that holds all but one term of a sum written elsewhere, two at least, gets that one too."""
    out = []
    for node, path in walk(slot.expr):
        terms = frozenset(node.args) if node.is_Add else frozenset([node])
        if node.is_Number:
            continue
        for other in pool:
            missing = other - terms
            if len(missing) != 1:
                continue
            if len(other) == len(terms) + 1 and terms < other:
                new = sp.Add(*other)
            elif node.is_Add and len(other) > 2 and other - missing < terms:
                new = sp.Add(node, *missing)
            else:
                continue
            added = next(iter(missing))
            out.append(
                Edit("drop", node, new, replace_at(slot.expr, path, new), phrase("add {} to {}", added, node))
            )
    return out


#: det M is expanded symbolically from the written M for models of up to this many coordinates
DETERMINANT_UP_TO_DOF = 3


def _determinant_edits(slot: Slot, sm) -> list[Edit]:
    """A written det M completed by what it lacks of the determinant of the written M: the
    difference of the two, expanded and factored, added as one term when it is a part of the
    determinant (fewer terms, expanded), or all of it where the entry is 0 (a product of sums
    dropped from the expansion: (I2 + m2·r2²)(I1 + l1²·m2 + m1·r1²)).
    Where the written M is right, as its own checks say, its determinant is Pinocchio's."""
    M = sm.closed_forms.get("mass_matrix")
    if slot.method != "det_mass_matrix" or M is None or M.shape[0] > DETERMINANT_UP_TO_DOF:
        return []
    determinant = sp.expand(M.det(method="berkowitz"))
    difference = determinant - sp.expand(slot.expr)
    whole = len(sp.Add.make_args(difference)) >= len(sp.Add.make_args(determinant))
    if difference == 0 or (whole and slot.expr != 0):
        return []  # not a part of det M missing (a factor on all of it is a coefficient edit)
    term = sp.factor(sp.trigsimp(difference))
    # the whole entry is what is edited: where M⁻¹'s entries are written over the same det M,
    # the edit is made there too (``candidates``)
    new = slot.expr + term
    return [Edit("drop", slot.expr, new, new, f"add {term} (a term of det M from the written M)")]


def _evaluated(slot: Slot, edits, sm, evaluate, deadline: float):
    """(edit, its values at the screening states, the slot's mismatch with them) of each new edit."""
    seen = set()
    allowed = set(sm.flat_arguments(slot.symbols)) | set(sm.parameters.values())
    for edit in edits:
        if now() > deadline:
            return
        if edit.expr in seen or edit.expr == slot.expr or not edit.expr.free_symbols <= allowed:
            continue
        seen.add(edit.expr)
        values = _edited_values(slot, edit.expr, evaluate)
        if np.all(np.isfinite(values)):
            yield edit, values, slot.mismatch(values)


#: an edit that changes at most this many of a sum's terms is evaluated through those terms
CHANGED_TERMS = 4


def _edited_values(slot: Slot, expr, evaluate) -> np.ndarray:
    """The edited entry at the screening states.  When it differs from the entry in a few of its
    top-level terms, as most edits do, the entry's values less the terms taken out plus the terms
    put in: a long entry (the triple pendulum's det M) is not compiled again for each edit, and
    its terms are met again by other edits.  Otherwise the whole edited entry."""
    before = collections.Counter(sp.Add.make_args(slot.expr))
    after = collections.Counter(sp.Add.make_args(expr))
    removed, added = before - after, after - before
    if slot.expr.is_Add and sum(removed.values()) + sum(added.values()) <= CHANGED_TERMS:
        values = np.array(slot.values, dtype=float)
        for term, count in removed.items():
            values = values - count * evaluate(term, slot.symbols)
        for term, count in added.items():
            values = values + count * evaluate(term, slot.symbols)
        return values
    return evaluate(expr, slot.symbols)


def _constant_edits(slot: Slot, monomials) -> list[Edit]:
    """A constant entry (of B, W, D) written as the value its slot must take, when that value is a
    simple fraction or a fraction times a product of parameters of the quantity's kinds."""
    if slot.symbols or slot.target is None:
        return []
    value = float(np.mean(slot.target))
    fraction = Fraction(value).limit_denominator(NUMBER_DENOMINATOR)
    if abs(float(fraction) - value) <= 1e-9 * max(1.0, abs(value)):
        new = sp.Rational(fraction.numerator, fraction.denominator)
    else:
        own, generic = monomials
        new = _matched(value, own) or _matched(value, own + generic)
    if new is None or new == slot.expr:
        return []
    return [Edit("constant", slot.expr, new, new, f"{slot.expr} → {new}")]


def screen_slot(slot: Slot, batch, sm, evaluate, monomials, pool, deadline: float) -> None:
    """The edits of one slot that make it agree at the screening states, in ``slot.matches``."""
    edits = _coefficient_edits(slot, evaluate) + _added_term_edits(slot, batch, monomials, sm.kinds)
    edits += _restored_term_edits(slot, pool) + _constant_edits(slot, monomials)
    edits += _determinant_edits(slot, sm) + _number_edits(slot, evaluate)
    edits += list(structural_edits(slot.expr, sm.angles, sm.symbols["v"], sm.kinds))
    # simplest first: an added term that SymPy folds into a swapped angle is kept as the swap
    edits.sort(key=lambda e: RANK.get(e.operator, 9))
    slot.matches += [
        e for e, _, mismatch in _evaluated(slot, edits, sm, evaluate, deadline) if mismatch <= SCREEN_RTOL
    ]


#: first edits of an entry a pair starts from: those that bring it closest to agreeing
FIRST_EDITS = 15


def expression_edits(expr, sm) -> Iterator[Edit]:
    """The edits of one expression that need no fit: a sign, a drop, a factor 2 or ½ on each term,
    and the structural edits (``pendverify.symbolic.edits``), one at a time."""
    for path, terms in sums(expr):
        for i, term in enumerate(terms):
            for k in COEFFICIENTS[:4]:
                new = sp.Rational(k.numerator, k.denominator) * term
                yield Edit(
                    "scale", term, new, with_term(expr, path, terms, i, new), phrase("{} → {}", term, new)
                )
    yield from structural_edits(expr, sm.angles, sm.symbols["v"], sm.kinds)


def _enumerated(slot: Slot, sm, pool) -> Iterator[Edit]:
    """The edits of an entry that need no fit (``expression_edits``) and the restored terms (a
    pair's two edits are each of these, or the second a solved coefficient: never an added term,
    which would fit anything).  One at a time, as they are evaluated: the time bound stops a long
    entry's (a q̈ written out) early."""
    yield from expression_edits(slot.expr, sm)
    yield from _restored_term_edits(slot, pool)


def pairs_within(slot: Slot, sm, evaluate, pool, deadline: float) -> list[Edit]:
    """Two edits of one entry that together make it agree: each of the ``FIRST_EDITS`` first
    edits that bring it closest, followed by every second edit (module docstring)."""
    before = slot.mismatch(slot.values)
    evaluated = _evaluated(slot, _enumerated(slot, sm, pool), sm, evaluate, deadline)
    closer = [(m, i, e, v) for i, (e, v, m) in enumerate(evaluated) if m < before]
    firsts = sorted(closer, key=lambda x: (x[0], x[1]))[:FIRST_EDITS]
    out = []
    for _, _, first, values in firsts:
        if now() > deadline:
            break
        inner = dataclasses.replace(slot, expr=first.expr, values=values, matches=[])
        seconds = itertools.chain(
            _coefficient_edits(inner, evaluate), _number_edits(inner, evaluate), _enumerated(inner, sm, pool)
        )
        for second, _, mismatch in _evaluated(inner, seconds, sm, evaluate, deadline):
            if mismatch <= SCREEN_RTOL and second.expr != slot.expr:
                out.append(
                    Edit(
                        "pair",
                        slot.expr,
                        second.expr,
                        second.expr,
                        phrase("{}, then {}", first.words, second.words),
                    )
                )
    return out


#: the order candidates are confirmed in, simplest first: a factor 2 or ½ comes after the edits
#: that change a symbol, so that a parameter swapped for one worth twice as much (mc = 2·mp) is
#: put back as the swap, not as a factor
RANK = {
    "sign": 0,
    "drop": 1,
    "swap θ": 2,
    "swap θ̇": 2,
    "parameter": 2,
    "constant": 2,
    "number": 2,
    "sin↔cos": 3,
    "scale": 4,
    "offset": 5,
    "add": 6,
    "pair": 30,
}


def candidates(slots: list[Slot], among: list[Slot]) -> list[tuple[int, dict, Edit, Slot]]:
    """(rank, {(method, index): (old, new)}, the edit shown, its slot) of the edits that passed the
    screen in the slots ``among``, simplest first: each alone, then the same edit wherever the
    same expression stands in the other ``slots``."""
    out = []
    for slot in among:
        for edit in slot.matches:
            local = {(slot.method, slot.index): (slot.expr, edit.expr)}
            out.append((RANK.get(edit.operator, 9), local, edit, slot))
            shared = dict(local)
            for other in (s for s in slots if s is not slot):
                if other.expr == slot.expr:
                    shared[(other.method, other.index)] = (other.expr, edit.expr)
                elif not edit.old.is_Atom and other.expr.has(edit.old):
                    shared[(other.method, other.index)] = (other.expr, other.expr.subs(edit.old, edit.new))
            if len(shared) > 1:
                out.append((10 + RANK.get(edit.operator, 9), shared, edit, slot))
    return sorted(out, key=lambda c: c[0])


#: pairs of edits of two entries (in different keys, or different rows of one) confirmed at most
MAX_CROSS_PAIRS = 60


def cross_pairs(slots: list[Slot]) -> list[tuple[int, dict, Edit, Slot]]:
    """One edit of each of two slots, each of which passed its own screen, for every two slots
    that are not one Coriolis row (whose entries share one comparison): two errors in different
    keys (one in M, one in C) or entries; simplest first, at most ``MAX_CROSS_PAIRS``."""
    screened = [s for s in slots if s.matches]
    out = []
    for a, b in itertools.combinations(screened, 2):
        same_row = a.row is not None and b.row is not None and np.array_equal(a.row[0], b.row[0])
        if a.method == b.method and same_row:
            continue  # one row of C·q̇ (the same residual): not two separate comparisons
        out += slot_pairs(a, b)
    return sorted(out, key=lambda c: c[0])[:MAX_CROSS_PAIRS]


def slot_pairs(a: Slot, b: Slot) -> list[tuple[int, dict, Edit, Slot]]:
    """One edit of each of two slots, each of which passed its own screen (at most ``MAX_PAIRS``)."""
    out = []
    for ea, eb in itertools.islice(itertools.product(a.matches, b.matches), MAX_PAIRS):
        changes = {(a.method, a.index): (a.expr, ea.expr), (b.method, b.index): (b.expr, eb.expr)}
        out.append((20 + RANK.get(ea.operator, 9) + RANK.get(eb.operator, 9), changes, ea, a))
    return sorted(out, key=lambda c: c[0])


def equal_valued(value: float, monomials, limit: int = 4) -> list[sp.Expr]:
    """Up to ``limit`` expressions ± a simple fraction times a product of parameters (of
    ``monomials``, (value, expression) pairs) equal to ``value`` to 1e-9, products as they stand
    first, in ``monomials``' order (``_matched``'s, which gives only the first): at parameter
    values that satisfy relations several are, and a repair that proves a coincidence
    (``pendverify.diagnosis.repair``) is tried again with the others."""
    close = 1e-9 * abs(value)
    out = []
    for whole in (True, False):
        for v, expr in monomials:
            ratio = Fraction(abs(value) / v).limit_denominator(NUMBER_DENOMINATOR)
            if (ratio == 1) is whole and ratio in FRACTIONS and abs(float(ratio) * v - abs(value)) <= close:
                found = sp.sign(value) * sp.Rational(ratio.numerator, ratio.denominator) * expr
                if found not in out:
                    out.append(found)
                if len(out) == limit:
                    return out
    return out
