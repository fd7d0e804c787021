"""Single-term mutants of a closed-form model, made on its SymPy expression trees.

Each closed form the model declares (``closed_forms``) is read as SymPy
expressions (``pendverify.analytic.symbolic_reading``), one per matrix entry, and each mutant
changes one thing in one entry:

=========  ==========================================================================
operator   change
=========  ==========================================================================
sign       one additive term t → −t (any sum in the tree, including inside an
           argument or a factor such as m2·(l1² + r2²); a lone entry is a sum of one)
drop       one additive term removed
scale      one additive term multiplied by 1 + 1e-3 (exactly 1001/1000)
sin↔cos    one sin call becomes cos, or the reverse
swap θ     θi ↔ θj inside the argument of one sin/cos
swap θ̇     θ̇i ↔ θ̇j inside one additive term
move       (Coriolis-type forms only) one term t·θ̇k of C_ij moved to C_ik as t·θ̇j:
           C·q̇ is unchanged, so the mutant is a different factorisation of C
=========  ==========================================================================

Mutants whose expression comes out identical to the original (θ1 ↔ θ2 in
cos(θ1 + θ2)) are kept, and later reported as equivalent.  Within one method,
mutants giving the same expressions are generated once.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from itertools import combinations

import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel, entries

SCALE = sp.Rational(1001, 1000)
OPERATORS = ("sign", "drop", "scale", "sin↔cos", "swap θ", "swap θ̇", "move")


@dataclass(frozen=True)
class Mutant:
    """One change to one closed form: new expressions for one entry (two for a move)."""

    method: str
    operator: str
    description: str
    #: (row-major index into the method's value, original expression, mutated expression)
    changes: tuple[tuple[int, sp.Expr, sp.Expr], ...]

    @property
    def identical(self) -> bool:
        return all(old == new for _, old, new in self.changes)


def entry_label(method: str, value, index: int) -> str:
    if not isinstance(value, sp.MatrixBase):
        return method
    cols = value.shape[1]
    r, c = divmod(index, cols)
    return f"{method}[{r}]" if cols == 1 else f"{method}[{r},{c}]"


def _walk(node, path=()) -> Iterator[tuple[sp.Basic, tuple[int, ...]]]:
    yield node, path
    if node.is_Atom:
        return
    for i, arg in enumerate(node.args):
        yield from _walk(arg, (*path, i))


def _replace(node, path, new):
    if not path:
        return new
    args = list(node.args)
    args[path[0]] = _replace(args[path[0]], path[1:], new)
    return node.func(*args)


def _sums(expr) -> Iterator[tuple[tuple[int, ...], list]]:
    """(path, terms) of every sum in the tree; a non-sum entry counts as a sum of one term."""
    if not expr.is_Add:
        yield (), [expr]
    for node, path in _walk(expr):
        if node.is_Add:
            yield path, list(node.args)


def entry_mutants(expr, angles, rates) -> Iterator[tuple[str, str, sp.Expr]]:
    """(operator, what, mutated entry) for one non-zero entry."""
    for path, terms in _sums(expr):
        for i, term in enumerate(terms):

            def with_term(new, path=path, terms=terms, i=i):
                rest = [*terms[:i], *([] if new is None else [new]), *terms[i + 1 :]]
                return _replace(expr, path, sp.Add(*rest) if rest else sp.S.Zero)

            yield "sign", f"{term} → {-term}", with_term(-term)
            yield "drop", f"drop {term}", with_term(None)
            yield "scale", f"{term} → (1 + 1e-3)·{term}", with_term(SCALE * term)
            for a, b in combinations(rates, 2):
                if term.has(a) or term.has(b):
                    yield "swap θ̇", f"{a} ↔ {b} in {term}", with_term(term.xreplace({a: b, b: a}))
    for node, path in _walk(expr):
        if isinstance(node, (sp.sin, sp.cos)):
            other = sp.cos if isinstance(node, sp.sin) else sp.sin
            yield "sin↔cos", f"{node} → {other(*node.args)}", _replace(expr, path, other(*node.args))
            arg = node.args[0]
            for a, b in combinations(angles, 2):
                if arg.has(a) or arg.has(b):
                    swapped = node.func(arg.xreplace({a: b, b: a}))
                    yield "swap θ", f"{a} ↔ {b} in {node}", _replace(expr, path, swapped)


def _divides(rate, term) -> bool:
    return term.has(rate) and not sp.denom(sp.cancel(term / rate)).has(rate)


def move_mutants(method: str, C: sp.Matrix, rates) -> Iterator[Mutant]:
    """Re-factorisations of a Coriolis-type matrix that keep C·q̇ (module docstring)."""
    n = C.shape[0]
    for i in range(n):
        for j in range(n):
            for term in sp.Add.make_args(sp.expand(C[i, j])):
                for k in range(n):
                    if k == j or not _divides(rates[k], term):
                        continue
                    moved = sp.cancel(term * rates[j] / rates[k])
                    changes = (
                        (i * n + j, C[i, j], C[i, j] - term),
                        (i * n + k, C[i, k], C[i, k] + moved),
                    )
                    what = f"move {term} from {method}[{i},{j}] to [{i},{k}] as {moved}"
                    yield Mutant(method, "move", what, changes)


def is_coriolis_form(sm: SymbolicModel, method: str, value) -> bool:
    """A square nv × nv form of (q, q̇) that stands for C (possibly plus a constant, e.g. C + D)."""
    form = sm.cls.closed_forms[method]
    n = len(sm.symbols["q"])
    return (
        form.args == "qv"
        and isinstance(value, sp.MatrixBase)
        and value.shape == (n, n)
        and (method == "coriolis_matrix" or "C" in form.equals)
    )


def generate(sm: SymbolicModel) -> list[Mutant]:
    """Every mutant of every declared closed form, deduplicated per method."""
    angles, rates = sm.angles, sm.symbols["v"]
    out: list[Mutant] = []
    for method, value in sm.closed_forms.items():
        seen: set = set()
        candidates: list[Mutant] = []
        for index, expr in enumerate(entries(value)):
            if expr == 0:
                continue
            label = entry_label(method, value, index)
            for operator, what, new in entry_mutants(expr, angles, rates):
                candidates.append(Mutant(method, operator, f"{label}: {what}", ((index, expr, new),)))
        if is_coriolis_form(sm, method, value):
            candidates += list(move_mutants(method, value, rates))
        for mutant in candidates:
            key = tuple((i, new) for i, _, new in mutant.changes)
            if key not in seen:
                seen.add(key)
                out.append(mutant)
    return out
