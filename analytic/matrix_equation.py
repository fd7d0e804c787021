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

Every term moved to the left-hand side with its sign s (a right-hand side term changes sign; if
M q̈ comes out negative, all signs flip) gives the model's part, the standard form being
M q̈ + C q̇ + D q̇ + H = B u + W w:

    C = s·C_file,  D = s·D_file,  H = s·G_file (or s·H_file),  B = −s·B_file,  W = −s·W_file

and u alone is B = −s·I (as many inputs as coordinates).  So ``M q̈ + C q̇ = τ + G`` makes the
model's H the file's −G, and ``show`` says so.  With h the bias is split as any f is
(``pendverify.analytic.text_model._split_f``): f = B u + W w − s_h·h − C q̇ − D q̇.  A term the
equation does not have is zero (C, H); a key the file gives that the equation does not use is
refused, as is, with a caret under it: an unknown name, a key the file does not give, no M q̈
term, a matrix times the wrong vector or none, a vector times something, a key or vector used
twice, an argument other than q and q̇.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from pendverify.analytic.latex_normalise import UNICODE

#: the matrix keys and the vector each multiplies (a: q̈, v: q̇, u: inputs, w: disturbances)
MATRICES = {"M": "a", "C": "v", "D": "v", "B": "u", "W": "w"}
#: the vector keys, which stand alone
VECTORS = ("G", "H", "h")
#: every key a matrix equation may name
KEYS = (*MATRICES, *VECTORS)
#: the spelled vectors (canonical name → role)
ROLES = {"ddq": "a", "dq": "v", "q": "q", "u": "u", "tau": "u", "w": "w"}
WORDS = {"a": "q̈", "v": "q̇", "u": "the inputs u", "w": "the disturbances w"}
#: the standard form the signs are read against
STANDARD = "M q̈ + C q̇ + D q̇ + H = B u + W w"
SPELLING = {"a": r"\ddot{q}", "v": r"\dot{q}", "u": "u", "w": "w"}
_FONTS = ("mathbf", "boldsymbol", "bm", "vec", "mathrm", "mathit", "mathsf", "pmb", "mathnormal")
_SKIP = re.compile(
    r"\s+|&|\$|\\[,;:! ]|\\q?quad\b|\\left\b|\\right\b|\\[bB]ig+[lr]?\b|\\displaystyle\b"
    r"|\\label\s*\{[^{}]*\}|\\nonumber\b|\\notag\b|\\(begin|end)\s*\{[^{}]*\}|[.,;]\s*$"
)
_IDENTIFIER = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


class MatrixEquationError(Exception):
    """``why`` at position ``at`` of the equation's text."""

    def __init__(self, why: str, at: int):
        super().__init__(why)
        self.why, self.at = why, at


@dataclass
class Name:
    name: str  # canonical: ddq, dq, tau, M, …
    at: int
    end: int


@dataclass
class Term:
    """One signed term of the left-hand side: ``key`` (or None) times ``vector`` (or None)."""

    sign: int
    key: Name | None
    vector: Name | None


def _name(text: str, i: int, latex: bool) -> tuple[str, int] | None:
    """The canonical name spelled at ``text[i:]`` and where it ends, or None."""
    if not latex:
        m = _IDENTIFIER.match(text, i)
        return (m.group(0), m.end()) if m else None
    if text.startswith("\\", i):
        m = re.compile(r"\\([A-Za-z]+)").match(text, i)
        if not m:
            return None
        command, j = m.group(1), m.end()
        if command in ("dot", "ddot") or command in _FONTS:
            inner = _argument(text, j, latex)
            if inner is None:
                return None
            name, j = inner
            if command in ("dot", "ddot"):
                name = "d" * len(command[:-2]) + name
        else:
            name, j = command, m.end()
    elif text[i].isalpha():
        name, j = UNICODE.get(text[i], text[i]), i + 1
        while j < len(text) and text[j] in "\u0307\u0308":
            name, j = ("dd" if text[j] == "\u0308" else "d") + name, j + 1
    else:
        return None
    sub, j = _subscript(text, j)
    return name + sub, j


def _argument(text: str, j: int, latex: bool) -> tuple[str, int] | None:
    """The name in ``{…}`` or the one name following a ``\\dot``/``\\mathbf`` at ``j``."""
    while j < len(text) and text[j].isspace():
        j += 1
    if text.startswith("{", j):
        inner = _name(text, _blank(text, j + 1), latex)
        if inner is None:
            return None
        k = _blank(text, inner[1])
        return (inner[0], k + 1) if text.startswith("}", k) else None
    return _name(text, j, latex)


def _blank(text: str, j: int) -> int:
    while j < len(text) and text[j].isspace():
        j += 1
    return j


def _subscript(text: str, j: int) -> tuple[str, int]:
    m = re.compile(r"_\s*(\{[^{}]*\}|\w)").match(text, j)
    return ("_" + m.group(1).strip("{}").strip(), m.end()) if m else ("", j)


def tokens(text: str, latex: bool, partial: bool = False) -> list[tuple[str, int, int]]:
    """(kind or canonical name, start, end): kinds ``+ - = * ( ) , 0``; names as ``_name`` spells them.

    ``partial``: the tokens before the first that cannot be read, instead of an error there.
    """
    out, i = [], 0
    while i < len(text):
        m = _SKIP.match(text, i) if latex else re.compile(r"\s+").match(text, i)
        if m and m.end() > i:
            i = m.end()
            continue
        if latex and text.startswith(r"\cdot", i):
            out.append(("*", i, i + 5))
            i += 5
            continue
        if re.match(r"0(?![\w.])", text[i:]):
            out.append(("0", i, i + 1))
            i += 1
            continue
        if text[i] in "+-=*(),":
            out.append((text[i], i, i + 1))
            i += 1
            continue
        if latex and text[i] in "[]":
            out.append(("([)]"["[]".index(text[i]) * 2], i, i + 1))
            i += 1
            continue
        found = _name(text, i, latex)
        if found is None and partial:
            return out
        if found is None:
            raise MatrixEquationError(f"unexpected {text[i]!r} in a matrix equation", i)
        out.append((found[0], i, found[1]))
        i = found[1]
    return out


def names_vectors(text: str, latex: bool, coordinates) -> bool:
    """Whether ``text`` is a matrix equation: it names the vector q̈ or q̇ (and no coordinate is q)."""
    return "q" not in coordinates and any(t[0] in ("ddq", "dq") for t in tokens(text, latex, partial=True))


def read_terms(text: str, latex: bool) -> list[Term]:
    """The equation's terms, moved to the left-hand side with their signs (module docstring)."""
    toks = tokens(text, latex)
    equals = [t for t in toks if t[0] == "="]
    if len(equals) != 1:
        raise MatrixEquationError(
            "a matrix equation has one '='", equals[1][1] if len(equals) > 1 else len(text)
        )
    terms, side, k = [], 1, 0
    while k < len(toks):
        sign = 1
        if toks[k][0] == "=":
            side, k = -1, k + 1
            if k == len(toks):
                raise MatrixEquationError("nothing after '='", len(text))
        if (
            toks[k][0] == "0"
            and (k == 0 or toks[k - 1][0] == "=")
            and (k + 1 == len(toks) or toks[k + 1][0] == "=")
        ):
            k += 1  # a side that is 0
            continue
        if toks[k][0] in "+-" and len(toks[k][0]) == 1:
            sign, k = (-1 if toks[k][0] == "-" else 1), k + 1
        factors = []
        while k < len(toks) and toks[k][0] not in ("+", "-", "="):
            if factors and toks[k][0] == "*":
                k += 1
            if k < len(toks) and toks[k][0] == "0":
                raise MatrixEquationError("0 stands only alone, as a whole side", toks[k][1])
            if k == len(toks) or not _is_name(toks[k][0]):
                at = toks[k][1] if k < len(toks) else len(text)
                raise MatrixEquationError("expected a key (M, C, G, …) or a vector (q̈, q̇, u)", at)
            factors.append(Name(toks[k][0], toks[k][1], toks[k][2]))
            k = _arguments(toks, k + 1, factors[-1], text)
        if not factors:
            at = toks[k][1] if k < len(toks) else len(text)
            raise MatrixEquationError("a term is missing here", at)
        terms.append(_term(side * sign, factors))
    return terms


def _is_name(kind: str) -> bool:
    return kind not in ("+", "-", "=", "*", "(", ")", ",", "0")


def _arguments(toks, k: int, owner: Name, text: str) -> int:
    """Past ``owner``'s argument list ``(q, q̇)`` at ``toks[k]``, if any; each must be q or q̇."""
    if k == len(toks) or toks[k][0] != "(":
        return k
    if owner.name not in KEYS:
        raise MatrixEquationError("only a key (M, C, G, …) takes an argument list", toks[k][1])
    k += 1
    while True:
        if k == len(toks) or ROLES.get(toks[k][0]) not in ("q", "v"):
            at = toks[k][1] if k < len(toks) else len(text)
            raise MatrixEquationError(f"an argument of {owner.name} must be q or q̇", at)
        k += 1
        if k < len(toks) and toks[k][0] == ")":
            return k + 1
        if k == len(toks) or toks[k][0] != ",":
            at = toks[k][1] if k < len(toks) else len(text)
            raise MatrixEquationError(f"expected ',' or ')' in {owner.name}'s argument list", at)
        k += 1


def _term(sign: int, factors: list[Name]) -> Term:
    first = factors[0]
    if len(factors) > 2:
        raise MatrixEquationError("a term is a key times a vector: one product at most", factors[2].at)
    second = factors[1] if len(factors) == 2 else None
    if first.name in MATRICES:
        want = MATRICES[first.name]
        if second is None:
            raise MatrixEquationError(
                f"{first.name} is a matrix: it multiplies {WORDS[want]} "
                f"(write {first.name}{SPELLING[want] if want in 'av' else ' ' + SPELLING[want]})",
                first.end,
            )
        if ROLES.get(second.name) != want:
            raise MatrixEquationError(f"{first.name} multiplies {WORDS[want]}, not this", second.at)
        return Term(sign, first, second)
    if first.name in VECTORS:
        if second is not None:
            raise MatrixEquationError(f"{first.name} is a vector: nothing multiplies it", second.at)
        return Term(sign, first, None)
    role = ROLES.get(first.name)
    if role in ("u", "w"):
        if second is not None:
            raise MatrixEquationError(f"{WORDS[role]} are a vector: write the matrix before it", second.at)
        return Term(sign, None, first)
    if role in ("a", "v"):
        raise MatrixEquationError(f"{WORDS[role]} without its matrix", first.at)
    if role == "q":
        raise MatrixEquationError("q is no term of the matrix equation (M q̈, C q̇, G, B u, …)", first.at)
    raise MatrixEquationError(
        f"unknown name {first.name!r}: a matrix equation names the keys {', '.join(KEYS)} "
        "and the vectors q̈, q̇, u (τ), w",
        first.at,
    )


def assemble(terms: list[Term], given: dict, n: int, inputs: int, disturbances: int) -> tuple[dict, dict]:
    """The model's parts and how each was derived from the file's keys ``given`` (module docstring).

    Returns (parts, derived); a part ``"h"`` is the bias s_h·h, split by the caller.  Raises
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
    parts, derived = {"M": given["M"]}, {}
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
    return parts, derived


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
        parts, derived = assemble(terms, given, n, len(spec.inputs), len(spec.disturbances))
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
    if "h" in eq:  # the bias: f = B u + W w − h − C q̇ − D q̇, split as every f is
        v = sp.Matrix(sym["v"])
        f = -eq.pop("h") - sum((eq.pop(k) * v for k in ("C", "D") if k in eq), sp.zeros(n, 1))
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
