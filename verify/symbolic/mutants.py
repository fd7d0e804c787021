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

import sympy as sp

from pendverify.analytic.forms import entry_position
from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.symbolic.edits import term_edits, trig_edits

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
    return f"{method}[{','.join(map(str, entry_position(method, value.shape, index)))}]"


def entry_mutants(expr, angles, rates) -> Iterator[tuple[str, str, sp.Expr]]:
    """(operator, what, mutated entry) for one non-zero entry (``pendverify.symbolic.edits``)."""
    for edit in term_edits(expr, rates, factors=(("scale", SCALE, "(1 + 1e-3)"),)):
        yield edit.operator, edit.what, edit.expr
    for edit in trig_edits(expr, angles):
        yield edit.operator, edit.what, edit.expr


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


def generate(sm: SymbolicModel, methods=None) -> list[Mutant]:
    """Every mutant of every declared closed form (of ``methods`` only, if given), deduplicated per
    method."""
    angles, rates = sm.angles, sm.symbols["v"]
    out: list[Mutant] = []
    for method, value in sm.closed_forms.items():
        if methods is not None and method not in methods:
            continue
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
