"""The work of a SymPy derivation, bounded before it starts.

``pendverify sympy`` differentiates the kinetic energy T = ½ q̇ᵀ M q̇ twice and the
result once more per coordinate (the Christoffel symbols), then simplifies every
entry: the work grows with the number of coordinates n and the size of the
energies.  The estimate is n × (the operations in T and V, ``sympy.count_ops``);
measured on a 2-core VM: the reference systems 120–150 (under a second), the
triple pendulum 294 (8 s: its trigonometry of sums is the costly kind), a dense
10 × 10 M 6 680 (4 s), a dense 20 × 20 M 50 760 (22 s), a dense 50 × 50 M about
750 000 (minutes).  A model above ``DEFAULT_MAX_SYMBOLIC`` (20 000), or above
``PENDVERIFY_MAX_SYMBOLIC`` in the environment, is refused before any derivation
with one line naming the estimate and the limit.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import sympy as sp

from pendverify.analytic.source_file import where
from pendverify.errors import InputError
from pendverify.simulation.limits import environment_limit
from pendverify.symbolic.lagrange import energies_of

if TYPE_CHECKING:
    from pendverify.analytic.symbolic_reading import SymbolicModel

MAX_SYMBOLIC_VARIABLE = "PENDVERIFY_MAX_SYMBOLIC"
DEFAULT_MAX_SYMBOLIC = 20_000


def symbolic_work(sm: SymbolicModel) -> tuple[int, int]:
    """(n, operations in T and V): the estimate is their product (module docstring)."""
    energies = energies_of(sm)
    ops = sum(sp.count_ops(sp.sympify(e)) for e in (energies.kinetic, energies.potential))
    return len(sm.symbols["q"]), int(ops)


def check_symbolic_work(sm: SymbolicModel) -> None:
    """Refuse a model whose derivation is estimated beyond the limit (module docstring)."""
    limit = environment_limit(MAX_SYMBOLIC_VARIABLE, DEFAULT_MAX_SYMBOLIC)
    n, ops = symbolic_work(sm)
    if n * ops > limit:
        raise InputError(
            where(sm.cls),
            "energies",
            f"{n} coordinates, {ops} operations in T and V",
            f"the derivation's estimated work, {n} × {ops} = {n * ops}, exceeds the limit of {limit} "
            f"(about 20 s at 50 000 on a 2-core VM, growing faster than the estimate); "
            f"raise the limit with {MAX_SYMBOLIC_VARIABLE}, e.g. {MAX_SYMBOLIC_VARIABLE}={10 * n * ops:.0e}",
        )
