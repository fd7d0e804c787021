"""Equations of motion given whole: ``lhs = rhs``, one per coordinate, split into M and f.

A text model's ``equations`` key is a list of strings ``lhs = rhs`` (SymPy syntax, with
the accelerations named ``dd<coordinate>``; with ``notation = "latex"`` LaTeX, one string
per equation or one ``align``-like block split at ``\\\\``), the i-th equation being the
one of the i-th coordinate (its Euler–Lagrange equation), in the coordinates, their rates
``d<coordinate>``, accelerations, inputs, disturbances and parameters.

Each equation is made a residual r_i = lhs − rhs, or rhs − lhs when the accelerations
appear on the right-hand side only (``tau1 = M11*ddq1 + …`` reads as ``M11*ddq1 + … =
tau1``): the side holding the accelerations is the M q̈ side.  Then

    M = ∂r/∂q̈      (required free of q̈: the equations are linear in the accelerations)
    f = −r(q, q̇, q̈ = 0, u, w)

so that r = M q̈ − f, and f goes the one way every right-hand side goes
(``pendverify.analytic.text_model._split_f``: H, C·q̇, D, B, W, each checked).  Refused,
with one line naming the equation: a string without exactly one ``=``, an equation in which
no acceleration appears, one nonlinear in the accelerations, and more or fewer equations
than coordinates.
"""

from __future__ import annotations

import re

import sympy as sp

from pendverify.analytic.latex_parse import LatexError
from pendverify.display import shortened

#: how M, and where f, came from (``spec.derived``, printed by ``pendverify show``)
DERIVED_M = "from the equations: the coefficients of the accelerations, ∂(lhs − rhs)/∂q̈"
DERIVED_F = "the equations' f"  # f = −(lhs − rhs) at q̈ = 0; the parts say "from the equations' f: …"

_ALIGN = re.compile(r"\\(begin|end)\{(align|aligned|eqnarray|equation|gather|gathered|split)\*?\}")
_ENV = re.compile(r"\\(begin|end)\{[^{}]*\}")
_ROW_BREAK = re.compile(r"\\\\(\s*\[[^\]]*\])?")


def _equals_at(text: str) -> list[int]:
    """Positions of the ``=`` signs at bracket depth 0 (``:=``, ``=:``, ``==``, ``<=``, ``>=`` are not)."""
    at, depth = [], 0
    for i, c in enumerate(text):
        if c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
        elif c == "=" and depth == 0:
            before, after = text[i - 1 : i], text[i + 1 : i + 2]
            if before not in (":", "<", ">", "!", "=") and after not in (":", "="):
                at.append(i)
    return at


def _sides(reader, key: str, text) -> tuple[str, str]:
    if not isinstance(text, str):
        reader.fail(key, f"must be an equation 'lhs = rhs', as a string, got {shortened(repr(text), 60)}")
    at = _equals_at(text)
    if len(at) != 1:
        what = "no '='" if not at else f"{len(at)} '=' signs"
        reader.fail(key, f"is not an equation lhs = rhs: {what} in {shortened(text.strip(), 80)!r}")
    lhs, rhs = text[: at[0]], text[at[0] + 1 :]
    for side, part in (("left", lhs), ("right", rhs)):
        if not part.strip():
            reader.fail(key, f"the {side}-hand side of '=' is empty in {shortened(text.strip(), 80)!r}")
    return lhs, rhs


def latex_rows(text: str) -> list[str]:
    """One LaTeX block (``align``, ``eqnarray``, …) split at its row breaks ``\\\\`` into equations.

    Row breaks inside another environment (a ``bmatrix``) do not split; ``&``, ``\\label{…}``,
    ``\\nonumber`` and ``\\notag`` only typeset and are dropped.
    """
    text = _ALIGN.sub(" ", text)
    text = re.sub(r"\\label\s*\{[^{}]*\}|\\nonumber\b|\\notag\b", " ", text)
    rows, depth, start = [], 0, 0
    for m in re.finditer(rf"{_ENV.pattern}|{_ROW_BREAK.pattern}", text):
        if m.group(0).startswith(r"\begin"):
            depth += 1
        elif m.group(0).startswith(r"\end"):
            depth -= 1
        elif depth == 0:
            rows.append(text[start : m.start()])
            start = m.end()
    rows.append(text[start:])
    cleaned = []
    for row in rows:
        row = re.sub(r"(?<!\\)&", " ", row).strip()
        row = re.sub(r"[\s,.;]+$", "", row)
        if row:
            cleaned.append(row)
    return cleaned


def read_equations(reader, spec, key: str, value, allowed: dict, parse_side) -> list[tuple]:
    """The (lhs, rhs) SymPy pairs of ``value``; ``parse_side(key, text)`` reads one side.

    ``value`` is a list of strings (or, in LaTeX, one string holding a block of rows).
    """
    if spec.notation == "latex" and isinstance(value, str):
        value = latex_rows(value)
    elif spec.notation == "latex" and isinstance(value, list):
        value = [r for x in value for r in (latex_rows(x) if isinstance(x, str) else [x])]
    if not isinstance(value, list) or not value:
        reader.fail(key, "must be a list of equations 'lhs = rhs', one per coordinate")
    pairs = []
    for i, text in enumerate(value):
        lhs, rhs = _sides(reader, f"{key}[{i}]", text)
        pairs.append((parse_side(f"{key}[{i}]", lhs, allowed), parse_side(f"{key}[{i}]", rhs, allowed)))
    return pairs


def latex_side(reader, latex):
    """A ``parse_side`` for LaTeX: one side read by the file's ``LatexReader``, a scalar."""

    def parse(key: str, text: str, allowed: dict):
        try:
            value = latex.read(text)[0]
        except LatexError as exc:
            reader.fail(key, str(exc))
        if isinstance(value, sp.MatrixBase):
            if value.shape != (1, 1):
                reader.fail(key, "a side of a scalar equation is a matrix; write one equation per coordinate")
            value = value[0, 0]
        stray = value.free_symbols - set(allowed.values())
        if stray:
            reader.fail(key, f"depends on {', '.join(sorted(s.name for s in stray))}, which is no model name")
        return value

    return parse


def split_equations(reader, spec, key: str, pairs: list[tuple]) -> None:
    """M and f of M q̈ = f from the equations (module docstring), into ``spec.equations``."""
    n = len(spec.coordinates)
    if len(pairs) != n:
        reader.fail(
            key,
            f"gives {len(pairs)} equation{'s' if len(pairs) != 1 else ''} for {n} coordinates "
            f"({', '.join(spec.coordinates)}): one equation of motion per coordinate",
        )
    a = list(spec.symbols["a"])
    residuals = []
    for i, (lhs, rhs) in enumerate(pairs):
        left, right = lhs.free_symbols & set(a), rhs.free_symbols & set(a)
        if not left and not right:
            reader.fail(
                f"{key}[{i}]",
                f"no acceleration ({', '.join(s.name for s in a)}) appears: not an equation of motion",
            )
        residuals.append(rhs - lhs if right and not left else lhs - rhs)
    r = sp.Matrix(residuals)
    M = r.jacobian(a)
    for i in range(n):
        if M[i, :].free_symbols & set(a):
            nonlinear = sorted(s.name for s in M[i, :].free_symbols & set(a))
            reader.fail(
                f"{key}[{i}]",
                f"is not linear in the accelerations (its coefficient of q̈ holds {', '.join(nonlinear)})",
            )
    spec.equations["M"] = M
    spec.equations["f"] = -r.xreplace({s: 0 for s in a})
    spec.derived["M"] = DERIVED_M
    spec.derived["f"] = DERIVED_F
