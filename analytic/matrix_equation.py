"""The equation of motion in matrix form, its matrices given by the file's other keys.

A text or LaTeX model's ``equations`` may be one string such as

    M(q)\\ddot{q} + C(q,\\dot{q})\\dot{q} + D\\dot{q} + G(q) = B u       (LaTeX)
    M*ddq + C*dq + G = B*u                                            (SymPy syntax)

naming the vectors q̈ and q̇ (``\\ddot{q}``, ``\\ddot{\\mathbf{q}}``, ``q̈``, ``ddq``; ``\\dot{q}``,
``dq``), the inputs (``u``, ``\\tau``, ``\\boldsymbol{\\tau}``), the disturbances (``w``) and the
file's matrix keys: M, C, D, B, W (each times its vector: M q̈, C q̇, D q̇, B u, W w) and the
vectors G or H (gravity) and h (the bias C·q̇ + H), alone.  A key may carry an argument list,
``M(q)``, ``C(q, \\dot q)``, which is ignored but must name only q and q̇.  LaTeX products are
written side by side, with ``\\cdot`` or ``*``; SymPy ones with ``*``.  A coordinate named ``q``
makes ``ddq`` its acceleration: the string is then a scalar equation (``text_equations``).
The text is read into terms by ``pendverify.analytic.matrix_equation_parse``.

Every term moved to the left-hand side with its sign s (a right-hand side term changes sign; if
M q̈ comes out negative, all signs flip) gives the model's part, the standard form being
M q̈ + C q̇ + D q̇ + H = B u + W w:

    C = s·C_file,  D = s·D_file,  H = s·G_file (or s·H_file),  B = −s·B_file,  W = −s·W_file

and u alone is B = −s·I (as many inputs as coordinates).  So ``M q̈ + C q̇ = τ + G`` makes the
model's H the file's −G, and ``show`` says so.  With h the bias is split as any f is
(``pendverify.analytic.text_model._split_f``): f = B u + W w − s_h·h − C q̇ − D q̇ − H.  A term the
equation does not have is zero (C, H); a key the file gives that the equation does not use is
refused, as is, with a caret under it: an unknown name, a key the file does not give, no M q̈
term, a matrix times the wrong vector or none, a vector times something, a key or vector used
twice, an argument other than q and q̇.
"""

from __future__ import annotations

import sympy as sp

from pendverify.analytic.matrix_equation_parse import (
    KEYS,
    ROLES,
    WORDS,
    MatrixEquationError,
    Name,
    Term,
    read_terms,
)

#: the standard form the signs are read against
STANDARD = "M q̈ + C q̇ + D q̇ + H = B u + W w"


def assemble(
    terms: list[Term], given: dict, n: int, inputs: int, disturbances: int
) -> tuple[dict, dict, dict]:
    """The model's parts and how each was derived from the file's keys ``given`` (module docstring).

    Returns (parts, derived, written): ``written`` maps a part to the file's key that is it as it
    stands (H → G), the model's ``written_names``; a part ``"h"`` is the bias s_h·h, split by the
    caller.  Raises
    ``MatrixEquationError`` at the term at fault.
    """
    seen: dict[str, Name] = {}
    for t in terms:
        for part in (t.key, t.vector):
            if part is None or ROLES.get(part.name) in ("a", "v"):
                continue
            label = part.name if part.name in KEYS else ROLES[part.name]
            if label in seen:
                raise MatrixEquationError(f"{part.name} appears twice in the matrix equation", part.at)
            seen[label] = part
    if "H" in seen and "G" in seen:
        raise MatrixEquationError("give G or H (the gravity vector), not both", seen["H"].at)
    for t in terms:
        role = ROLES.get(t.vector.name) if t.vector is not None else None
        if role in ("u", "w") and not (inputs if role == "u" else disturbances):
            raise MatrixEquationError(f"the file declares no {WORDS[role][4:]}", t.vector.at)
        if t.key is not None and t.key.name not in given:
            raise MatrixEquationError(f"{t.key.name} is not given in the file", t.key.at)
        if t.key is None and ROLES[t.vector.name] == "u" and inputs != n:
            raise MatrixEquationError(
                f"{t.vector.name} alone needs as many inputs as coordinates ({n}); write B u", t.vector.at
            )
        if t.key is None and ROLES[t.vector.name] == "w" and disturbances != n:
            raise MatrixEquationError(
                f"w alone needs as many disturbances as coordinates ({n}); write W w", t.vector.at
            )
    mass = [t for t in terms if t.key is not None and t.key.name == "M"]
    if not mass:
        raise MatrixEquationError("no M q̈ term: a matrix equation is M q̈ + … = …", 0)
    flip = mass[0].sign
    parts, derived, written = {"M": given["M"]}, {}, {}
    for t in terms:
        s = t.sign * flip
        if t.key is not None and t.key.name == "M":
            continue
        if t.key is None:  # u or w alone: B (W) = −s·I
            key = "B" if ROLES[t.vector.name] == "u" else "W"
            parts[key] = -s * sp.eye(n)
            derived[key] = f"{'' if s < 0 else '−'}I: the matrix equation's {t.vector.name} alone"
            continue
        name = t.key.name
        target = {"G": "H"}.get(name, name)
        sign = -s if name in ("B", "W") else s
        parts[target] = sign * given[name]
        if sign < 0 or name != target:
            minus = "−" if sign < 0 else ""
            derived[target] = (
                f"{minus}{name}: the matrix equation puts {name} where {STANDARD} has {minus}{target}"
            )
        if sign > 0 and name != target:
            written[target] = name
    return parts, derived, written


def matrix_text(value) -> str | None:
    """The one string of an ``equations`` value that may be a matrix equation, else None."""
    if isinstance(value, list) and len(value) == 1:
        value = value[0]
    return value if isinstance(value, str) else None


def read_matrix_equation(reader, spec, key: str, text: str) -> None:
    """The matrix equation ``text`` over the file's parsed keys, made the model's parts in ``spec``.

    ``spec.equations`` holds the file's keys (M, C, G, …) as parsed; they are replaced by the
    model's (module docstring).  Every problem is one line, with a caret where it has a place.
    """
    eq, sym, n = spec.equations, spec.symbols, len(spec.coordinates)
    given = {k: eq[k] for k in KEYS if k in eq}
    try:
        terms = read_terms(text, spec.notation == "latex")
        parts, derived, written = assemble(terms, given, n, len(spec.inputs), len(spec.disturbances))
    except MatrixEquationError as exc:
        reader.fail_at(key, exc.why, text, exc.at)
    used = {t.key.name for t in terms if t.key is not None}
    unused = [k for k in given if k not in used]
    if unused:
        reader.fail(unused[0], f"given, but the matrix equation under '{key}' does not use it")
    if spec.inputs and "B" not in parts:
        reader.fail(
            key, f"the file declares inputs {', '.join(spec.inputs)}: the matrix equation needs B u (or τ)"
        )
    for k in given:
        del eq[k]
    eq.update(parts)
    spec.derived.update(derived)
    spec.written_names.update(written)
    if "h" in eq:  # the bias: f = B u + W w − h − C q̇ − D q̇, split as every f is
        v = sp.Matrix(sym["v"])
        f = -eq.pop("h") - sum((eq.pop(k) * v for k in ("C", "D") if k in eq), sp.zeros(n, 1))
        f -= eq.pop("H", sp.zeros(n, 1))
        for k, group in (("B", "u"), ("W", "w")):
            if k in eq:
                f += eq.pop(k) * sp.Matrix(sym[group])
        eq["f"] = f
        spec.derived = {k: how for k, how in spec.derived.items() if k not in ("H", "C", "D", "B", "W")}
        spec.derived["f"] = "the matrix equation's f"
        return
    if "C" not in eq:
        eq["C"] = sp.zeros(n, n)
        spec.derived["C"] = "zero: the matrix equation has no C q̇ term"
    if "H" not in eq:
        eq["H"] = sp.zeros(n, 1)
        spec.derived["H"] = "zero: the matrix equation has no gravity term"
