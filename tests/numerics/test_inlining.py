"""Which generated right-hand sides are inlined into the copied integrators (``codegen.compiled``).

A body of at most ``INLINE_LINES`` lines is marked ``inline="always"`` (``_rhs_t`` and ``_rhs``); a
longer one is called.  Both kinds run through every command in the conformance matrix (its 5-link
chain's body is 303 lines, the other systems' 45–109), where their results are checked.
"""

from __future__ import annotations

import sympy as sp

from pendverify.numerics.codegen.compiled import INLINE_LINES, render_rhs
from pendverify.numerics.codegen.expressions import Expressions


def _chain_like(n: int) -> Expressions:
    """n coordinates, a coupled M(q) and a bias with a term per pair: a body that grows as n²."""
    q, v = sp.symbols(f"q0:{n}"), sp.symbols(f"v0:{n}")
    p = sp.symbols(f"p0:{n}")
    mass = sp.Matrix(n, n, lambda i, j: p[max(i, j)] * sp.cos(q[i] - q[j]) + (1 if i == j else 0))
    bias = sp.Matrix([sum(p[j] * sp.sin(q[i] - q[j]) * v[j] ** 2 for j in range(n)) for i in range(n)])
    names = tuple(f"c{i}" for i in range(n))
    return Expressions(
        "chain", names, (True,) * n, tuple(f"m{i}" for i in range(n)), q, v, p, mass, bias, None
    )


def _decorators(lines: list[str]) -> dict[str, str]:
    return {
        lines[k + 1].split("(")[0].removeprefix("def "): lines[k]
        for k, line in enumerate(lines[:-1])
        if line.startswith("@njit")
    }


def _body_lines(lines: list[str]) -> int:
    start = lines.index("def _rhs_t(P, t, x, out):") + 1
    return next(k for k in range(start, len(lines)) if not lines[k].startswith("    ")) - start


def test_a_short_body_is_inlined_and_a_long_one_is_called():
    short, long = render_rhs(_chain_like(1)), render_rhs(_chain_like(8))
    assert _body_lines(short) <= INLINE_LINES < _body_lines(long)
    for name in ("_rhs_t", "_rhs"):
        assert 'inline="always"' in _decorators(short)[name]
        assert "inline" not in _decorators(long)[name]
