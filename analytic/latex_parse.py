"""Read equations written in LaTeX, as they stand in a derivation, into SymPy.

A text model with ``notation = "latex"`` gives its equations as LaTeX copied from
the paper.  The names the file declares are read by convention (``m_1`` is m1,
``\\theta_1`` theta1, ``\\dot{\\theta}_1`` dtheta1: ``pendverify.analytic.latex_names``);
a ``[symbols]`` table maps the document's other symbols to the model's names
(``'x_3' = "dtheta1"``) or defines them by an expression in SymPy syntax over those
names (``'\\alpha' = "I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2)"``), and wins over the
convention.

What is read
------------
* ``\\begin{bmatrix} … \\end{bmatrix}`` (and ``pmatrix``, ``Bmatrix``, ``matrix``,
  ``array`` with its column specification), cells split by ``&`` (by ``&&`` in a matrix whose
  every separator is ``&&``, as notebooks write them; amsmath would read an empty column
  there, the same in every row: ``latex_normalise``), rows by ``\\\\``
  (``\\\\[2pt]`` too); matrix sums and products; a row ``[a, b]`` (``(a, b)``);
  transposes ``^T``, ``^{T}``, ``^\\top``, ``^{\\mathsf{T}}`` (``^T`` is a power when the
  table declares ``T``).
* ``+ − \\cdot \\times * /``, ``\\frac{a}{b}``, ``\\sqrt{x}``, powers ``x^2``, ``x^{n}``;
  **implicit products** of declared symbols: ``m_1gr_1\\cos(\\theta_1)`` is
  m1·g·r1·cos θ1 — the lexer matches the longest declared symbol first.
* ``\\sin \\cos \\tan \\exp`` (also ``\\operatorname{sin}``, ``\\mathrm{sin}``) and powers
  of them (``\\sin^2(\\theta_1 - \\theta_2)`` is sin²(θ1 − θ2)).  **The argument of a
  function** is what follows it in parentheses or braces; written without them it is
  one symbol, a number times one symbol, or a ``\\frac``: ``\\sin 2\\theta_2`` is
  sin(2θ2) (as the Furuta literature prints it), ``\\sin\\frac{\\theta}{2}`` is sin(θ/2),
  and every factor after that argument multiplies the function: ``\\sin\\theta_1\\cos\\theta_2``
  is sin θ1 · cos θ2 and ``\\cos\\theta\\,\\dot\\theta^2`` is cos θ · θ̇² (a product of two
  symbols as an argument, sin(θ1θ2), must be written ``\\sin(\\theta_1\\theta_2)``).
* ``( ) [ ] \\{ \\}`` and their ``\\left``/``\\right``/``\\bigl`` forms as grouping;
  ``\\mathbf{}``, ``\\boldsymbol{}``, ``\\bm{}``, ``\\mathrm{}`` are dropped around
  their content; ``\\underbrace{X}_{…}`` and ``\\overbrace{X}^{…}`` read as X;
  ``\\dot\\theta``, ``\\dot{\\theta_1}`` and ``\\dot{\\theta}_1`` are one symbol, as are
  ``x_1`` and ``x_{1}``, and ``θ₁`` is ``\\theta_1``; spacing (``\\, \\; \\! \\quad`` …),
  ``\\label{…}``, ``\\nonumber``, ``\\notag``, a display's environment (``align``,
  ``equation``, ``eqnarray`` …) or delimiters (``$$``, ``\\[ \\]``) and a closing ``,``/``.``
  are ignored.
* A chain ``LABEL = A = B``: a leading label — a name (a letter or command, with a
  subscript, ⁻¹ or ᵀ) with or without its arguments, such as ``M``,
  ``\\mathbf{M}(\\mathbf{q})``, ``\\det M`` or ``f(y,\\dot{y},u,w)`` — is dropped, a
  leading ``=`` too; ``:=`` is ``=``; ``align``'s ``&=`` and ``eqnarray``'s ``&=&`` are ``=``
  and a ``\\\\`` outside every matrix ends a line of the display.  Every right-hand side
  must be read and be *equal* (the double-pendulum reference system prints each matrix in
  θ and in x = (θ, θ̇) notation: both are read and compared).

Anything else is an error that shows the LaTeX around the place where reading stopped,
with a caret under it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import sympy as sp
from lark import Lark, Token, Transformer, v_args
from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedInput, UnexpectedToken, VisitError

from pendverify.analytic import expression_limits as limits
from pendverify.analytic.latex_normalise import Stop, Text, normalise
from pendverify.errors import ExcerptError, PendverifyError, excerpt

#: commands that only typeset their argument: dropped around it
FUNCTIONS = {"sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "exp": sp.exp}
_MATRICES = ("bmatrix", "pmatrix", "Bmatrix", "matrix", "smallmatrix")


class LatexError(PendverifyError):
    """LaTeX that cannot be read: why, and (when known) the text and the position where."""

    def __init__(self, why: str, text: str | None = None, at: int | None = None):
        self.why, self.text, self.at = why, text, at
        pointer = ""
        if text is not None and at is not None:
            pointer = "\n" + ExcerptError("", *excerpt(text, at)).pointer()
        super().__init__(why + pointer)


_GRAMMAR = r"""
?start: sum
?sum: SIGN? term (SIGN term)*
?term: power (MULOP? power)*
?power: primary
    | primary "^" "{" sum "}"  -> pow
    | primary TRANSPOSE        -> transpose
?primary: NUMBER          -> number
    | SYMBOL              -> symbol
    | "(" sum ")"
    | "(" sum ("," sum)+ ")" -> listed_row
    | "{" sum "}"
    | FUNC arg            -> func
    | FUNC "^" "{" sum "}" arg -> funcpow
    | "\\frac" "{" sum "}" "{" sum "}" -> div
    | "\\sqrt" "{" sum "}" -> sqrt
    | BEGIN rows END      -> matrix
?arg: "(" sum ")" | "{" sum "}" | SYMBOL -> symbol
    | NUMBER SYMBOL -> scaled
    | "\\frac" "{" sum "}" "{" sum "}" -> div
rows: row (ROWSEP row)* ROWSEP?
row: sum ("&" sum)*
FUNC: /\\(sin|cos|tan|exp)(?![A-Za-z])/
BEGIN: /\\begin\{[A-Za-z]+\}/
END: /\\end\{[A-Za-z]+\}/
ROWSEP: /\\\\/
TRANSPOSE.3: "^{\\top}"
SIGN: "+" | "-"
MULOP: "*" | "/"
NUMBER: /\d+(\.\d*)?|\.\d+/
%ignore " "
"""


@dataclass
class SymbolTable:
    """The document's symbols (canonical LaTeX) → SymPy expressions over the model's names."""

    entries: dict[str, sp.Expr]
    source: dict[str, str]  # canonical → the key as the file wrote it
    #: the entries read by convention (``latex_names``), not written in the file's table
    conventional: dict[str, object] = field(default_factory=dict)

    def grammar(self) -> str:
        # longest first, so that m_1 is read before m; a bare command (\\alpha) must end there
        keys = sorted(self.entries, key=len, reverse=True)
        alternation = "|".join(
            re.escape(k).replace("/", "\\/") + ("(?![A-Za-z])" if re.fullmatch(r"\\[A-Za-z]+", k) else "")
            for k in keys
        )
        return _GRAMMAR + f"SYMBOL.2: /({alternation or '(?!)x'})/\n"


@v_args(inline=True)
class _ToSympy(Transformer):
    def __init__(self, table: SymbolTable, used: dict):
        super().__init__()
        self.table, self.used = table, used

    def number(self, tok):
        return limits.literal(str(tok))

    def symbol(self, tok):
        key = str(tok).replace(" ", "")
        self.used.setdefault(key, None)
        return self.table.entries[key]

    def sum(self, *items):
        """Terms with their signs (a leading sign optional), added in one flat ``Add``."""
        terms, sign = [], 1
        for item in items:
            if isinstance(item, Token) and item.type == "SIGN":
                sign = -1 if item == "-" else 1
            else:
                terms.append(item if sign == 1 else -item)
                sign = 1
        if any(isinstance(t, sp.MatrixBase) for t in terms):
            total = terms[0]
            for t in terms[1:]:
                total = total + t
            return total
        return limits.checked(sp.Add(*terms))

    def term(self, *items):
        """Factors, implicit or with ``*`` and ``/``, multiplied left to right (one flat ``Mul``)."""
        factors, divide = [], False
        for item in items:
            if isinstance(item, Token) and item.type == "MULOP":
                divide = item == "/"
                continue
            if divide:
                if isinstance(item, sp.MatrixBase):
                    raise ValueError("division by a matrix")
                item = limits.power(item, sp.Integer(-1))
            factors.append(item)
            divide = False
        if any(isinstance(f, sp.MatrixBase) for f in factors):
            product = factors[0]
            for f in factors[1:]:
                product = product * f
            return product
        return limits.checked(sp.Mul(*factors))

    def div(self, a, b):
        if isinstance(b, sp.MatrixBase):
            raise ValueError("division by a matrix")
        return limits.checked(a * limits.power(b, sp.Integer(-1)))

    def pow(self, a, b):
        if isinstance(a, sp.MatrixBase):
            raise ValueError("a power of a matrix (write the product, or give M_inv as its own key)")
        return limits.power(a, b)

    def func(self, name, a):
        if isinstance(a, sp.MatrixBase):
            raise ValueError(f"{name} of a matrix")
        return limits.checked(FUNCTIONS[str(name)[1:]](a))

    def funcpow(self, name, power, a):
        return limits.power(self.func(name, a), power)

    def transpose(self, a, _):
        return a.T if isinstance(a, sp.MatrixBase) else a

    def listed_row(self, *cells):
        """``[a, b]``: a row vector, as papers write one before its transpose."""
        if any(isinstance(c, sp.MatrixBase) for c in cells):
            raise ValueError("a matrix inside a row (a, b, …)")
        return sp.Matrix([list(cells)])

    def scaled(self, number, symbol):
        return limits.checked(self.number(number) * self.symbol(symbol))

    def sqrt(self, a):
        return limits.checked(sp.sqrt(a))

    def rows(self, *rows):
        return [r for r in rows if not (hasattr(r, "type") and r.type == "ROWSEP")]

    def row(self, *cells):
        return list(cells)

    def matrix(self, begin, rows, end):
        kind, close = str(begin)[7:-1], str(end)[5:-1]
        if kind != close:
            raise ValueError(f"\\begin{{{kind}}} closed by \\end{{{close}}}")
        if kind not in _MATRICES:
            raise ValueError(f"\\begin{{{kind}}} is not a matrix ({', '.join(_MATRICES)})")
        widths = {len(r) for r in rows}
        if len(widths) != 1:
            raise ValueError(f"a matrix whose rows have {sorted(widths)} cells")
        if any(isinstance(c, sp.MatrixBase) for r in rows for c in r):
            raise ValueError("a matrix inside a matrix cell")
        return sp.Matrix(rows)


#: a display's label: a name (a letter or a command, with a subscript, ⁻¹ or ᵀ) and its arguments
_LABEL = re.compile(
    r"^\s*(\\det\s*)?(\\[A-Za-z]+|[A-Za-z])\s*(_\w|_\{[^{}]*\})?\s*(\^\{(-1|\\top)\})?\s*(\([^()=]*\))?\s*$"
)


def _split_chain(t: Text) -> list[tuple[int, int]]:
    """Spans of the sides of ``A = B = C`` (or ``A := B``) at brace depth 0 (``=:`` is not a split)."""
    spans, depth, start = [], 0, 0
    s = t.text
    for i, c in enumerate(s):
        if c in "{(":
            depth += 1
        elif c in "})":
            depth -= 1
        elif c == "=" and depth == 0 and s[i + 1 : i + 2] != ":":
            spans.append((start, i - 1 if s[i - 1 : i] == ":" else i))
            start = i + 1
    spans.append((start, len(s)))
    return spans


class LatexReader:
    """Parses LaTeX for one model file with its symbol table."""

    def __init__(self, table: SymbolTable):
        self.table = table
        #: the symbols read so far, canonical LaTeX, in the order first read
        self.used: dict[str, None] = {}
        self.parser = Lark(table.grammar(), parser="lalr", maybe_placeholders=False)

    def read(self, text: str) -> tuple[object, str]:
        """The expression (or matrix) ``text`` holds, and the label it dropped ("" if none).

        Raises ``LatexError`` with the LaTeX and where reading stopped.
        """
        try:
            t = normalise(text, transpose_letter="T" not in self.table.entries)
        except Stop as stop:
            raise _stopped(text, stop.at, stop.why) from None
        t.sub(r"[\s,.;]+$", "")  # a sentence's punctuation after a display
        deep = _too_deep(t.text)
        if deep is not None:
            why = (
                f"brackets nested {limits.nesting_depth(t.text, '({', ')}')} deep; "
                f"the limit is {limits.MAX_NESTING} (a bracket opened here is one too many)"
            )
            raise LatexError(why, text, t.where(deep))
        sides = _split_chain(t)
        label = ""
        if len(sides) > 1 and not t.text[slice(*sides[0])].strip():
            sides = sides[1:]  # a continuation line "= …"
        elif len(sides) > 1 and _LABEL.match(t.text[slice(*sides[0])]):
            label = t.text[slice(*sides[0])].strip()
            sides = sides[1:]
        values = [self._side(t, a, b, text) for a, b in sides]
        first = values[0]
        for k, other in enumerate(values[1:], start=2):
            if not _equal(first, other):
                raise LatexError(
                    f"the chain's right-hand sides 1 and {k} differ: {_brief(first)} vs {_brief(other)} "
                    f"in {_excerpt(text)}"
                )
        return first, label

    def conventions_used(self) -> list:
        """The conventions (``latex_names.Convention``) the text read so far used, in order."""
        return [self.table.conventional[k] for k in self.used if k in self.table.conventional]

    def _side(self, t: Text, a: int, b: int, original: str):
        piece = t.text[a:b]
        if not piece.strip():
            raise _stopped(original, t.where(a), "an empty side of '='")
        try:
            return _ToSympy(self.table, self.used).transform(self.parser.parse(piece))
        except UnexpectedInput as exc:
            at = t.where(a + _position(exc, piece))
            raise _stopped(original, at, _why(exc, piece, original[at : at + 1])) from None
        except VisitError as exc:
            raise LatexError(f"{exc.orig_exc} in {_excerpt(original)}") from None


def _position(exc: UnexpectedInput, piece: str) -> int:
    if isinstance(exc, UnexpectedEOF):
        return len(piece)
    if isinstance(exc, UnexpectedToken) and exc.token.type != "$END":
        return exc.token.start_pos if exc.token.start_pos is not None else len(piece)
    if isinstance(exc, UnexpectedCharacters):
        return exc.pos_in_stream
    return len(piece)


def _why(exc: UnexpectedInput, piece: str, written: str) -> str:
    """What stopped the reading, and the fix when one is known; ``written``: the original character."""
    if isinstance(exc, UnexpectedCharacters):
        rest = piece[exc.pos_in_stream :]
        m = re.match(r"\\[A-Za-z]+|[A-Za-z](_\w|_\{[^}]*\})?", rest)
        if m and written and not written.isascii():
            return (
                f"unknown symbol '{written}' (read as {m.group(0)}): declare it (a coordinate or "
                f"parameter {m.group(0).lstrip(chr(92))}) or write it in [symbols] as '{m.group(0)}'"
            )
        if re.match(r"\\ddot\b", rest):
            return (
                "an acceleration (\\ddot) of no declared coordinate: this is an equation of motion; "
                "give it under `equations`"
            )
        if m:
            return (
                f"unknown symbol or command '{m.group(0)}': declare it (a coordinate, input or "
                "parameter) or give it in [symbols]"
            )
        if not written.isascii():
            return f"unexpected '{written}': write it in LaTeX (a Greek letter as \\theta, …)"
        return f"unexpected '{piece[exc.pos_in_stream]}'"
    if isinstance(exc, UnexpectedEOF) or (isinstance(exc, UnexpectedToken) and exc.token.type == "$END"):
        return "the text ends too early (an unclosed bracket or a missing operand?)"
    before = piece[: _position(exc, piece)]
    unclosed = before.count("(") - before.count(")")
    closing = str(exc.token) in ("&", ")", "\\\\") or str(exc.token).startswith("\\end")
    hint = " (a '(' opened before it is not closed)" if unclosed > 0 and closing else ""
    return f"unexpected '{exc.token}'{hint}"


def _stopped(text: str, at: int, why: str) -> LatexError:
    return LatexError(f"cannot read the LaTeX at character {at + 1}: {why}", text, at)


def _too_deep(text: str) -> int | None:
    """The position of the first bracket that opens beyond ``MAX_NESTING`` levels, or None."""
    depth = 0
    for i, c in enumerate(text):
        if c in "({":
            depth += 1
            if depth > limits.MAX_NESTING:
                return i
        elif c in ")}":
            depth -= 1
    return None


def _excerpt(text: str) -> str:
    one = " ".join(text.split())
    return repr(one if len(one) <= 80 else one[:77] + "...")


def _brief(value) -> str:
    s = str(value.tolist() if isinstance(value, sp.MatrixBase) else value)
    return s if len(s) <= 60 else s[:57] + "..."


def _equal(a, b) -> bool:
    if isinstance(a, sp.MatrixBase) != isinstance(b, sp.MatrixBase):
        return False
    if isinstance(a, sp.MatrixBase):
        return a.shape == b.shape and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    diff = sp.expand(sp.expand_trig(a - b))
    return diff == 0 or sp.simplify(diff) == 0


__all__ = ["LatexError", "LatexReader", "SymbolTable"]
