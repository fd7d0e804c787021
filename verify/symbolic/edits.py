"""Single edits of one closed-form entry, on its SymPy expression tree: what ``pendverify mutate``
plants and what a repair (``pendverify.diagnosis.repair``) undoes.

Each operator changes one place of an entry; the repair of an edit is its inverse:

===============  ==========================================  ===================================
operator         edit                                        its inverse
===============  ==========================================  ===================================
sign             one additive term t → −t                    sign (itself)
drop             one additive term removed                   add a term (fitted, below)
scale            one term t → k·t (k = 1.001, 2, ½, …)       a coefficient k' solved for
duplicate        one term t → 2t                             a coefficient (½)
sin↔cos          one sin call becomes cos, or the reverse    sin↔cos (itself)
swap θ           θi ↔ θj inside one sin/cos argument         swap θ (itself)
swap θ̇           θ̇i ↔ θ̇j inside one additive term            swap θ̇ (itself)
parameter        one parameter → another of its kind in      parameter (the reverse)
                 one term (l1 ↔ l2, m1 ↔ m2)
offset           one sin/cos argument shifted by π/2 or π    offset (the opposite shift)
pivot            a term ± m·r² added (an inertia about the   add a term (fitted)
                 pivot where the centre of mass is meant)
===============  ==========================================  ===================================

The coefficient and added-term inverses are not enumerated but solved for from the
numbers (``pendverify.diagnosis.repair``); the others are enumerated here (``structural_edits``).
Every edit is ``Edit(operator, old, new, expr, words)``: the sub-expression replaced, its
replacement, the whole new entry and the edit in words (``what``).  The words are a ``Phrase``
where they name SymPy expressions, formatted only when read: a repair search screens thousands
of edits and shows a few, and printing an expression costs more than evaluating it (the repair
search of gymnasium's acrobot spent 10 of its 23 s printing the words of edits it then dropped).
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from itertools import combinations

import sympy as sp

SHIFTS = (sp.pi / 2, -sp.pi / 2, sp.pi)


@dataclass(frozen=True)
class Phrase:
    """Words with SymPy expressions in them, ``template.format(*args)`` when read (module docstring)."""

    template: str
    args: tuple

    def __str__(self) -> str:
        return self.template.format(*self.args)


def phrase(template: str, *args) -> Phrase:
    """``template.format(*args)``, put off until it is read."""
    return Phrase(template, args)


@dataclass(frozen=True)
class Edit:
    """One edit of one entry: ``old`` (a sub-expression) became ``new``; ``expr`` is the new entry;
    ``words`` say it (``what``)."""

    operator: str
    old: sp.Expr
    new: sp.Expr
    expr: sp.Expr
    words: str | Phrase

    @property
    def what(self) -> str:
        """The edit in words."""
        return str(self.words)


def walk(node, path=()) -> Iterator[tuple[sp.Basic, tuple[int, ...]]]:
    """Every node of the tree with its path of argument positions."""
    yield node, path
    if node.is_Atom:
        return
    for i, arg in enumerate(node.args):
        yield from walk(arg, (*path, i))


def replace_at(node, path, new):
    """The tree with the node at ``path`` replaced by ``new``."""
    if not path:
        return new
    args = list(node.args)
    args[path[0]] = replace_at(args[path[0]], path[1:], new)
    return node.func(*args)


def sums(expr) -> Iterator[tuple[tuple[int, ...], list]]:
    """(path, terms) of every sum in the tree; a non-sum entry counts as a sum of one term."""
    if not expr.is_Add:
        yield (), [expr]
    for node, path in walk(expr):
        if node.is_Add:
            yield path, list(node.args)


def with_term(expr, path, terms, i, new):
    """The entry with term i of the sum at ``path`` replaced by ``new`` (None: removed)."""
    rest = [*terms[:i], *([] if new is None else [new]), *terms[i + 1 :]]
    return replace_at(expr, path, sp.Add(*rest) if rest else sp.S.Zero)


def term_edits(expr, rates, factors=()) -> Iterator[Edit]:
    """sign, drop, each (operator, factor, factor in words) of ``factors`` on one term, and swap θ̇
    inside one term."""
    for path, terms in sums(expr):
        for i, term in enumerate(terms):
            yield Edit(
                "sign", term, -term, with_term(expr, path, terms, i, -term), phrase("{} → {}", term, -term)
            )
            yield Edit(
                "drop", term, sp.S.Zero, with_term(expr, path, terms, i, None), phrase("drop {}", term)
            )
            for operator, factor, words in factors:
                new = factor * term
                yield Edit(
                    operator,
                    term,
                    new,
                    with_term(expr, path, terms, i, new),
                    phrase("{} → {}·{}", term, words, term),
                )
            for a, b in combinations(rates, 2):
                if term.has(a) or term.has(b):
                    swapped = term.xreplace({a: b, b: a})
                    new = with_term(expr, path, terms, i, swapped)
                    yield Edit("swap θ̇", term, swapped, new, phrase("{} ↔ {} in {}", a, b, term))


def trig_edits(expr, angles, offsets: bool = False) -> Iterator[Edit]:
    """sin↔cos of one call, swap θ inside one argument, and (``offsets``) one argument shifted."""
    for node, path in walk(expr):
        if not isinstance(node, (sp.sin, sp.cos)):
            continue
        other = (sp.cos if isinstance(node, sp.sin) else sp.sin)(*node.args)
        yield Edit("sin↔cos", node, other, replace_at(expr, path, other), phrase("{} → {}", node, other))
        arg = node.args[0]
        for a, b in combinations(angles, 2):
            if arg.has(a) or arg.has(b):
                swapped = node.func(arg.xreplace({a: b, b: a}))
                yield Edit(
                    "swap θ",
                    node,
                    swapped,
                    replace_at(expr, path, swapped),
                    phrase("{} ↔ {} in {}", a, b, node),
                )
        for shift in SHIFTS if offsets else ():
            shifted = node.func(arg + shift)
            yield Edit(
                "offset",
                node,
                shifted,
                replace_at(expr, path, shifted),
                phrase("{} → {} in {}", arg, arg + shift, node),
            )


def parameter_edits(expr, kinds: dict) -> Iterator[Edit]:
    """One occurrence of a parameter replaced by another of the same kind (in p² one factor: p·p')."""
    for node, path in walk(expr):
        if node in kinds:
            p, replaced = node, lambda other: other
        elif node.is_Pow and node.base in kinds and node.exp.is_Integer and node.exp > 1:
            p, replaced = node.base, lambda other, node=node: node.base ** (node.exp - 1) * other
        else:
            continue
        for other in sorted(kinds, key=str):
            if other != p and kinds[other] == kinds[p]:
                new = replaced(other)
                yield Edit("parameter", node, new, replace_at(expr, path, new), phrase("{} → {}", node, new))


def folded_parameter_edits(expr, kinds: dict) -> Iterator[Edit]:
    """The inverse of a parameter edit that SymPy folded: p' → p in p' + p' + … is written k·p', so
    one of the k becomes another parameter of its kind (k·p' → (k − 1)·p' + p)."""
    for node, path in walk(expr):
        if not (node.is_Mul and len(node.args) == 2 and node.args[0].is_Integer and node.args[1] in kinds):
            continue
        k, p = node.args
        if k < 2:
            continue
        for other in sorted(kinds, key=str):
            if other != p and kinds[other] == kinds[p]:
                new = (k - 1) * p + other
                yield Edit("parameter", node, new, replace_at(expr, path, new), phrase("{} → {}", node, new))


def structural_edits(expr, angles, rates, kinds: dict) -> Iterator[Edit]:
    """The enumerated edits a repair tries (module docstring): all but the solved-for ones."""
    for edit in term_edits(expr, rates):
        if edit.operator == "swap θ̇":  # sign and drop are coefficients, solved for
            yield edit
    yield from trig_edits(expr, angles, offsets=True)
    yield from parameter_edits(expr, kinds)
    yield from folded_parameter_edits(expr, kinds)
