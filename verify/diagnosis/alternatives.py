"""The other edits a repair cannot be told from, and the relation under which they agree.

At parameter values that satisfy relations (``pendverify.diagnosis.perturbed``) several edits
of an entry give the same numbers.  Three things about them, for the repair search
(``pendverify.diagnosis.repair``):

* ``rematched``: the edits that give the same numbers as a given one with other parameters.
  Each term of what the edit adds (then each term of the entry it writes) is c·P·f, a number c
  times a product P of parameters times a function f of the state; c·P's value is matched by
  other products of parameters of the same value (``equal_valued``), products as they stand
  and the model's own first.  ``3*I`` → ``mp*l**2`` where I = mp·l²/3; ``l*m/2`` → ``l**2*m``
  where l = 0.5; ``l1*lc2`` → ``l1*lc2*m2`` where m2 = 1.  An edit that proves a coincidence
  is followed by these, and one that holds at these values only is named with them.
* ``exchanged``: the edit with the members of groups of equal parameters (m1 = m2, moved
  together by the perturbed sets) exchanged where it puts in or takes out whole terms.
* ``relation``: the polynomial of the parameters under which two edits of an entry agree at
  every state, and ``unless``, that relation in words, solved for one parameter.

``edit_parameters`` are the parameters an edit involves (those of the difference it makes),
``shown`` an edit in a few words of the model's notation.
"""

from __future__ import annotations

import functools
import itertools

import sympy as sp

from pendverify.diagnosis.candidates import equal_valued, monomials_for
from pendverify.diagnosis.slots import QUANTITY, Slot, entry_label
from pendverify.symbolic.edits import Edit
from pendverify.symbolic.zero_test import trig_normal_form

#: edits ``rematched`` gives at most; each costs a check run of a small model when tried
REMATCHES = 6
#: terms of what an edit adds (or of the entry it writes) ``rematched`` matches again, at most
REMATCHED_TERMS = 2


def rematched(changes: dict, sm, params, slot: Slot) -> list[tuple[dict, Edit]]:
    """(changes, edit) of the edits that give the same numbers as ``changes`` (an edit of one
    entry) at the file's values ``params`` with other parameters (module docstring)."""
    if len(changes) != 1:
        return []
    ((key, (old, new)),) = changes.items()
    numbers = {p: float(getattr(params, p)) for p in sm.parameters}
    values = {sm.parameters[p]: v for p, v in numbers.items()}
    own, generic = monomials_for(sm, numbers, QUANTITY.get(slot.method, ""))
    out = []
    for base, source in ((old, sp.expand(new - old)), (sp.S.Zero, sp.expand(new))):
        terms = sp.Add.make_args(source)
        if len(terms) > REMATCHED_TERMS:
            continue
        options = []
        for term in terms:
            factors = sp.Mul.make_args(term)
            part = sp.Mul(*[f for f in factors if not f.free_symbols or f.free_symbols <= set(values)])
            value = float(part.xreplace(values))
            others = [m for m in equal_valued(value, own + generic) if m != part] if value else []
            options.append([(part, term / part)] + [(m, term / part) for m in others])
        for combo in itertools.product(*options):
            if all(choice is option[0] for choice, option in zip(combo, options, strict=True)):
                continue  # the edit itself
            written = base + sp.Add(*[m * rest for m, rest in combo])
            if written != new:
                what = f"{new} → {written} (the same numbers here)"
                out.append(({key: (old, written)}, Edit("rematched", old, written, written, what)))
            if len(out) == REMATCHES:
                return out
    return out


def exchanged(changes: dict, edit: Edit, slot: Slot, groups, params, sm) -> list:
    """The edit with the members of ``groups`` of equal parameters exchanged in what it changes
    (``add I2`` → ``add I1``), as [(changes, edit, slot, relation in words)]: at most one, every
    group the edit's difference holds exchanged at once.  The members' values are the same float
    here and at every perturbed set, so the exchanged edit gives the same numbers, bit for bit,
    and passes every check the first passed.  Listed only where the edit puts in or takes out
    whole terms (each term of its difference has the coefficient ±1: ``I2 → 2*I2`` adds I2, so
    ``+ I1`` is an edit the user could have meant), not where it changes a term's sign or factor
    (``m2*l1*lc2*sin(theta2)`` flipped: the same flip with m1 would be a new term of two masses)."""
    symbols = sm.parameters
    differences = [sp.expand(new - old) for old, new in changes.values()]
    whole = all(abs(term.as_coeff_Mul()[0]) == 1 for d in differences for term in sp.Add.make_args(d))
    swap = {}
    for group in groups:
        if len({float(getattr(params, n)) for n in group}) != 1:
            continue  # equal to rounding only: the numbers would differ in the last bits
        inside = [n for n in group if any(d.has(symbols[n]) for d in differences)]
        if inside:
            a, b = symbols[inside[0]], symbols[next(n for n in group if n != inside[0])]
            swap.update({a: b, b: a})
    if not swap or not whole:
        return []
    out = {}
    for key, (old, new) in changes.items():
        forms = (old + (new - old).xreplace(swap), sp.expand(old + (new - old).xreplace(swap)))
        out[key] = (old, min(forms, key=lambda f: len(str(f))))
    if all(sp.expand(n - changes[k][1]) == 0 for k, (_, n) in out.items()):
        return []
    pairs = sorted({tuple(sorted((str(a), str(b)))) for a, b in swap.items()})
    where = " and ".join(f"{a} = {b}" for a, b in pairs)
    old, new = next(iter(out.values()))
    what = f"{edit.what}, with {where.replace(' = ', ' and ')} exchanged"
    return [(out, Edit("exchange", old, new, new, what), slot, f": the two agree where {where}")]


def edit_parameters(changes: dict, sm) -> set[str]:
    """The parameters an edit involves: those of the difference it makes to each entry."""
    names = {symbol: name for name, symbol in sm.parameters.items()}
    out = set()
    for old, new in changes.values():
        out |= {names[s] for s in sp.expand(new - old).free_symbols if s in names}
    return out


def shown(changes: dict, edit: Edit, forms: dict, notation) -> str:
    """An edit, short, in the model's notation: ``M[2,2]: I → 4*I``."""
    (method, index), (old, new) = next(iter(changes.items()))
    label = entry_label(method, forms[method], index)
    written, suggested = notation.render(old), notation.render(new)
    if len(written) + len(suggested) <= 80:
        return f"{label}: {written} → {suggested}"
    return f"{label}: {notation.render(edit.old)} → {notation.render(edit.new)}"


def unless(changes: dict, other: dict, sm, independent, notation) -> str:
    """ ": they differ unless I = mp*r**2/3": the relation under which two edits of the same entries
    give the same numbers, solved for one parameter (one that was not moved on its own, when one
    is in it; one the solution does not divide by), or as its two sides
    (": they differ unless lc1**2*m1 = lc2**2*m2"); "" when the edits change different entries
    or the relation is not one equation."""
    if set(changes) != set(other):
        return ""
    key = next(iter(changes))
    found = relation(changes[key][1] - other[key][1], sm)
    if found is None:
        return ""
    preferred = [p for p in found.free_symbols if str(p) not in independent]
    for symbol in sorted(preferred, key=str) + sorted(found.free_symbols - set(preferred), key=str):
        solutions = sp.solve(found, symbol)
        if len(solutions) == 1 and not sp.fraction(solutions[0])[1].free_symbols:
            return f": they differ unless {notation.render(symbol)} = {notation.render(solutions[0])}"
    terms = sp.Add.make_args(found)
    if len(terms) == 2:
        left, right = (-terms[0], terms[1]) if terms[0].could_extract_minus_sign() else (terms[0], -terms[1])
        return f": they differ unless {notation.render(left)} = {notation.render(right)}"
    return ""


def relation(difference, sm) -> sp.Expr | None:
    """The polynomial of the parameters that must vanish for two entries whose ``difference`` is
    given to agree at every state, or None when that is not one equation.  The difference is
    written as a polynomial in sin θ, cos θ, the rates and inputs (``trig_normal_form``); it
    vanishes at every state when each coefficient does, and that is one relation when all the
    coefficients share a factor (their GCD) and are otherwise numbers.  A factor that is one
    parameter vanishes only where that parameter is 0 and is left out."""
    form = trig_normal_form(sp.expand(difference), sm.angles)
    if form is None or form == 0:
        return None
    others = sorted(form.free_symbols - set(sm.parameters.values()), key=str)
    coefficients = sp.Poly(form, *others).coeffs() if others else [form]
    common = functools.reduce(sp.gcd, coefficients)
    if not common.free_symbols or any(not sp.cancel(c / common).is_number for c in coefficients):
        return None
    factors = [f for f, _ in sp.factor_list(common)[1] if f.is_Add]
    return sp.Mul(*factors) if factors else None
