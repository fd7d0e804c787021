"""Symbolic proofs that a mutant does not change the dynamics.

A mutant (``pendverify.symbolic.mutants``) replaces some entries e of a closed form
by e'.  It is equivalent when every difference e' − e is zero
(``pendverify.symbolic.zero_test.is_zero``), with two refinements:

* V matters up to a constant: for ``potential_energy`` the differences compared are
  the gradients ∂(V' − V)/∂q_k.
* A Coriolis-type form C may be re-factorised: with ΔC the matrix of the changes,
  the mutant keeps the dynamics when ΔC·q̇ = 0; it is then Christoffel-consistent
  when Ṁ − 2(C + ΔC) stays skew-symmetric (N + Nᵀ = 0), and "a valid C·q̇, not the
  Christoffel C" otherwise (a warning, not a failure).

A difference that vanishes only once the parameter values are substituted (exactly,
as rationals of their decimal repr) is reported as equivalent *for these parameters*.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import sympy as sp

from pendverify.checks.verdict import CHRISTOFFEL_CONSISTENT, NON_CHRISTOFFEL
from pendverify.symbolic.lagrange import mass_matrix_rate
from pendverify.symbolic.zero_test import is_zero, probe

if TYPE_CHECKING:
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.symbolic.mutants import Mutant


def coriolis_equivalence(sm: SymbolicModel, mutant: Mutant) -> str | None:
    """The reason text if the mutant keeps C·q̇ (a different factorisation of C), else None."""
    n = len(sm.symbols["q"])
    delta = sp.zeros(n, n)
    for index, old, new in mutant.changes:
        delta[index // n, index % n] = new - old
    bias = delta * sm.column("v")
    if any(probe(e) for e in bias) or not all(is_zero(e, sm.angles) for e in bias):
        return None
    C = sm.evaluate("coriolis_matrix", "qv") + delta
    N = mass_matrix_rate(sm.evaluate("mass_matrix", "q"), sm.symbols["q"], sm.symbols["v"]) - 2 * C
    if all(is_zero(e, sm.angles) for e in N + N.T):
        return CHRISTOFFEL_CONSISTENT
    return NON_CHRISTOFFEL


def differences(sm: SymbolicModel, mutant: Mutant) -> list:
    diffs = [new - old for _, old, new in mutant.changes]
    if mutant.method == "potential_energy":  # V matters up to a constant
        return [d.diff(x) for d in diffs for x in sm.symbols["q"]]
    return diffs


def equivalence(sm: SymbolicModel, mutant: Mutant, params) -> str | None:
    """Why the mutant is equivalent, if it is (symbolic proof); None otherwise."""
    diffs = differences(sm, mutant)
    if all(is_zero(d, sm.angles) for d in diffs):
        if mutant.method == "potential_energy":
            return "V changes by a constant only, which no equation of motion sees"
        return "simplifies to the original expression"
    values = {s: sp.Rational(repr(getattr(params, n))) for n, s in sm.parameters.items()}
    if all(is_zero(d.xreplace(values), sm.angles) for d in diffs):
        used = sorted({s.name for d in diffs for s in d.free_symbols if s in values.keys()})
        return f"equivalent for this parameter set only (the change vanishes at {', '.join(used)} as given)"
    return None
