"""The matrix equation's text read into signed terms (assembled by ``matrix_equation``).

A term is a key times a vector (``M\\ddot{q}``, ``C(q,\\dot q)\\dot q``, ``B*u``), a vector key
alone (``G``, ``H``, ``h``) or the inputs (disturbances) alone (``\\tau``, ``u``, ``w``).  Names
are read to one spelling each: LaTeX fonts (``\\mathbf{}``, ``\\boldsymbol{}``, …) dropped,
``\\ddot{x}``/``x``+U+0308 → ``ddx``, ``\\dot{x}`` → ``dx``, Greek commands and letters → their
names (``\\tau``, ``τ`` → ``tau``), a subscript kept (``\\ddot{q}_1`` is ``ddq_1``, not q̈).
In LaTeX a name is one letter or command, products are written side by side, with ``\\cdot`` or
``*``, and spacing, ``&``, ``\\left``/``\\right``, ``\\label{…}`` and a closing ``.`` only
typeset; in SymPy syntax a name is an identifier and a product is ``*``.  Each error carries
its position in the text, for the caret.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

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
