"""One expression in SymPy syntax read into SymPy without running Python.

The grammar is Python's, cut down to what an equation of motion needs::

    sum     := ["+" | "-"] product (("+" | "-") product)*
    product := unary (("*" | "/") unary)*
    unary   := ("+" | "-")* power
    power   := atom ["**" unary]
    atom    := NUMBER | NAME | FUNCTION "(" sum ")" | "(" sum ")"

NAME is one of the declared names (or ``pi``), FUNCTION one of sin, cos, tan,
sqrt, exp.  Nothing is evaluated by Python: the tokens are read by a regular
expression and the expression is built from SymPy objects directly.  Sums and
products are built flat (``sympy.Add(*terms)``), so a pasted 5000-term expansion
is no deeper than one term; brackets nest at most ``MAX_NESTING`` deep, and every
exact number is bounded as it is built (``pendverify.analytic.expression_limits``).
A problem raises ``ExpressionError`` with its position in the text.
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass

import sympy as sp

from pendverify.analytic import expression_limits as limits

FUNCTIONS = {"sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "sqrt": sp.sqrt, "exp": sp.exp}
_NUMBER = r"(?:\d[\d_]*(?:\.[\d_]*)?|\.\d[\d_]*)(?:[eE][+-]?\d[\d_]*)?"
_TOKEN = re.compile(rf"\s*(?:(?P<number>{_NUMBER})|(?P<name>[^\W\d]\w*)|(?P<op>\*\*|[-+*/(),^.\[\]]))")


class ExpressionError(ValueError):
    """An expression that cannot be read: why, and the character position (0-based) where."""

    def __init__(self, why: str, at: int):
        super().__init__(why)
        self.why, self.at = why, at


@dataclass
class _Token:
    kind: str  # "number", "name", "op", "end", or "error" (text: why)
    text: str
    at: int


def _tokens(text: str) -> list[_Token]:
    out, at = [], 0
    while True:
        while at < len(text) and text[at].isspace():
            at += 1
        if at == len(text):
            out.append(_Token("end", "", at))
            return out
        m = _TOKEN.match(text, at)
        if m is None or m.end() == at:
            c = text[at]
            why = (
                "a string is not a number"
                if c in "'\""
                else f"'{c}' is not allowed (numbers, names, + - * / ** and calls of {', '.join(FUNCTIONS)})"
            )
            out.append(_Token("error", why, at))  # raised when the parser reaches it
            out.append(_Token("end", "", len(text)))
            return out
        kind = m.lastgroup
        start = m.start(kind)
        token = _Token(kind, m.group(kind), start)
        if kind == "number" and m.end() < len(text) and (text[m.end()].isalnum() or text[m.end()] == "_"):
            token = _Token("error", f"'{text[start : m.end() + 1]}' is not a number", start)
        out.append(token)
        at = m.end()


class _Parser:
    def __init__(self, text: str, names: dict):
        self.text, self.names = text, names
        self.tokens = _tokens(text)
        self.i = 0
        self.depth = 0

    @property
    def token(self) -> _Token:
        return self.tokens[self.i]

    def take(self) -> _Token:
        token = self.tokens[self.i]
        self.i += 1
        return token

    def is_op(self, *ops: str) -> bool:
        return self.token.kind == "op" and self.token.text in ops

    def expect(self, op: str, why: str) -> None:
        if not self.is_op(op):
            raise self.unexpected(why)
        self.take()

    def unexpected(self, why: str = "") -> ExpressionError:
        t = self.token
        if t.kind == "error":
            return ExpressionError(t.text, t.at)
        if t.kind == "end":
            return ExpressionError("the expression ends too early" + (f" ({why})" if why else ""), t.at)
        if t.text == "^":
            return ExpressionError("'^' is not a power: write powers as **", t.at)
        if t.text == ".":
            return ExpressionError("Attribute access ('.') is not allowed", t.at)
        if t.text == ",":
            return ExpressionError("',' is not allowed: each function takes one argument", t.at)
        return ExpressionError(f"unexpected '{t.text}'" + (f" ({why})" if why else ""), t.at)

    def deeper(self, at: int) -> None:
        self.depth += 1
        if self.depth > limits.MAX_NESTING:
            depth = max(limits.nesting_depth(self.text, "(", ")"), self.depth)
            raise ExpressionError(
                f"brackets, calls and powers nested {depth} deep; the limit is {limits.MAX_NESTING}", at
            )

    def read(self):
        value = self.sum()
        if self.token.kind != "end":
            raise self.unexpected("an operator missing before it?" if self.token.kind != "op" else "")
        return value

    def sum(self):
        terms, start = [], self.token.at
        sign = 1
        if self.is_op("+", "-"):
            sign = -1 if self.take().text == "-" else 1
        while True:
            at = self.token.at
            term = self.product()
            terms.append(self.exact(at, lambda t=term, s=sign: t if s == 1 else -t))
            if not self.is_op("+", "-"):
                break
            sign = -1 if self.take().text == "-" else 1
        return self.exact(start, lambda: sp.Add(*terms)) if len(terms) > 1 else terms[0]

    def product(self):
        factors, divisors = [self.unary()], []
        while self.is_op("*", "/"):
            into = factors if self.take().text == "*" else divisors
            at = self.token.at
            into.append(self.unary())
            if into is divisors and divisors[-1] == 0:
                raise ExpressionError("division by zero", at)
        if len(factors) == 1 and not divisors:
            return factors[0]
        at = self.token.at
        value = self.exact(at, lambda: sp.Mul(*factors))
        for d in divisors:
            value = self.exact(at, lambda v=value, d=d: v / d)
        return value

    def unary(self):
        sign, at = 1, self.token.at
        while self.is_op("+", "-"):
            if self.take().text == "-":
                sign = -sign
        value = self.power()
        return value if sign == 1 else self.exact(at, lambda: -value)

    def power(self):
        at = self.token.at
        base = self.atom()
        if not self.is_op("**"):
            return base
        self.take()
        self.deeper(at)
        exponent = self.unary()
        self.depth -= 1
        return self.exact(at, lambda: limits.power(base, exponent))

    def atom(self):
        t = self.take()
        if t.kind == "number":
            return self.exact(t.at, lambda: limits.literal(t.text))
        if t.kind == "name":
            if self.is_op("("):
                if t.text not in FUNCTIONS:
                    raise ExpressionError(f"only {', '.join(FUNCTIONS)} may be called, not '{t.text}'", t.at)
                self.take()
                self.deeper(t.at)
                argument = self.sum()
                self.expect(")", f"the '(' of {t.text} at character {t.at + len(t.text) + 1} is not closed")
                self.depth -= 1
                return self.exact(t.at, lambda: FUNCTIONS[t.text](argument))
            if t.text in FUNCTIONS:
                raise ExpressionError(f"{t.text} must be called: {t.text}(…)", t.at)
            if t.text not in self.names:
                close = difflib.get_close_matches(t.text, list(self.names), n=3)
                hint = f"; did you mean {', '.join(close)}?" if close else ""
                raise ExpressionError(f"unknown name '{t.text}'{hint}", t.at)
            return self.names[t.text]
        if t.kind == "op" and t.text == "(":
            self.deeper(t.at)
            value = self.sum()
            self.expect(")", f"the '(' at character {t.at + 1} is not closed")
            self.depth -= 1
            return value
        self.i -= 1
        raise self.unexpected("a number, a name or '(' expected")

    def exact(self, at: int, build):
        """``build()``, its exact numbers bounded; a problem is reported at ``at``."""
        try:
            return limits.checked(build())
        except limits.ExpressionTooLarge as exc:
            raise ExpressionError(str(exc), at) from None


def read_expression(text: str, names: dict):
    """The SymPy expression ``text`` holds over ``names`` (name → SymPy symbol or constant)."""
    return _Parser(text, names).read()


def fragment(text: str, at: int, width: int = 50) -> str:
    """A short piece of ``text`` around position ``at``, for a message: ``…m2*rr2**2 + …``."""
    one = re.sub(r"\s", " ", text)
    if len(one) <= width:
        return repr(one)
    start = max(0, min(at - width // 2, len(one) - width))
    piece = one[start : start + width]
    return repr(("…" if start > 0 else "") + piece + ("…" if start + width < len(one) else ""))
