"""The limits on an expression read from a text or LaTeX model: exact numbers and nesting.

SymPy evaluates exact arithmetic without bound: ``10**10**10`` is an integer of
33 billion bits and ``theta1**(9**9**9)`` first computes 9**9**9 (369 million
digits).  Every exact number the readers build is therefore checked as it is
built, before the next operation:

* ``MAX_BITS`` = 1024: an exact integer, or a fraction's numerator or denominator,
  has at most 1024 bits.  Every value is finally evaluated in double precision,
  whose range ends at 2**1024 ≈ 1.8e308; an exact number beyond it is no
  coefficient a double can hold.
* ``MAX_EXPONENT`` = 1024: an exact integer exponent is at most 1024 in magnitude.
  x**1025 overflows a double for every |x| ≥ 2 and underflows for every
  |x| ≤ 1/2, so a larger exponent means nothing in double precision, while
  expanding a sum to it would take without bound.  ``x**2`` is untouched.
* A constant (``exp(1000)``, ``sqrt(2)**2000``) must be within a double's range
  once evaluated, as a literal float must.
* A number written as a literal is at most 309 digits (10**309 > 2**1024), and a
  float literal must be finite as a double (``1e300`` is read, ``1e400`` is not).
* ``MAX_NESTING`` = 100: brackets (and calls, and powers of powers) nest at most
  100 deep.  Python's own parser stops at 200 parentheses; SymPy's algorithms
  (simplification, printing, code generation) recurse several Python frames per
  level, and 100 levels keep them well inside Python's recursion limit of 1000.

Long sums and products are not nested: the readers build them flat, so a pasted
5000-term expansion is read.
"""

from __future__ import annotations

import math

import sympy as sp

MAX_BITS = 1024
MAX_EXPONENT = 1024
MAX_LITERAL_DIGITS = 309
MAX_NESTING = 100


class ExpressionTooLarge(ValueError):
    """An exact number or a nesting beyond the limits (module docstring); the message says which."""


def _bits(value: sp.Rational) -> int:
    return max(int(value.p).bit_length(), int(value.q).bit_length())


def checked(value):
    """``value`` itself if its exact number (itself, or a product's coefficient) is within ``MAX_BITS``."""
    number = value.as_coeff_Mul()[0] if isinstance(value, sp.Mul) else value
    if isinstance(number, sp.Rational) and _bits(number) > MAX_BITS:
        value = number
    if isinstance(value, sp.Rational) and _bits(value) > MAX_BITS:
        raise ExpressionTooLarge(
            f"an exact number of {_bits(value)} bits; the limit is {MAX_BITS} bits "
            f"(a double's range ends at 2**{MAX_BITS} ≈ 1.8e308)"
        )
    if isinstance(value, sp.Float) and not math.isfinite(float(value)):
        raise ExpressionTooLarge(f"a number beyond a double's range (≈ 1.8e308): {sp.sstr(value)[:30]}")
    if (
        isinstance(value, sp.Expr)
        and not isinstance(value, sp.Number)
        and value.is_number
        and not value.has(sp.zoo, sp.oo, sp.nan)  # refused as "not finite" by the readers
    ):
        number = complex(value.evalf(15))  # exp(1000): its arguments are already within range
        if not (math.isfinite(number.real) and math.isfinite(number.imag)):
            raise ExpressionTooLarge(
                f"a constant beyond a double's range (≈ 1.8e308): {sp.sstr(value)[:40]} ≈ "
                f"{sp.sstr(value.evalf(6))[:30]}"
            )
    return value


def power(base, exponent):
    """``base**exponent``, refused before it is computed if an exact exponent or result is too large."""
    if isinstance(exponent, sp.Integer) and abs(int(exponent)) > MAX_EXPONENT:
        raise ExpressionTooLarge(
            f"an exact exponent of {_digits(exponent)}; the limit is ±{MAX_EXPONENT} "
            f"(x**{MAX_EXPONENT + 1} leaves a double's range for every |x| ≥ 2 or ≤ 1/2)"
        )
    if isinstance(base, sp.Rational) and isinstance(exponent, sp.Rational) and base not in (0, 1, -1):
        estimate = _bits(base) * abs(exponent)
        if estimate > 2 * MAX_BITS:
            raise ExpressionTooLarge(
                f"a power of about {int(estimate)} bits; the limit is {MAX_BITS} bits "
                f"(a double's range ends at 2**{MAX_BITS} ≈ 1.8e308)"
            )
    if isinstance(base, sp.Float) and isinstance(exponent, sp.Number):
        try:
            float(base) ** float(exponent)
        except (OverflowError, ZeroDivisionError):
            raise ExpressionTooLarge("a power beyond a double's range (≈ 1.8e308)") from None
    return checked(base**exponent)


def literal(text: str):
    """A number as written (digits, a point, an exponent, ``_`` separators): SymPy Integer or Float."""
    plain = text.replace("_", "")
    mantissa = plain.lower().split("e")[0]
    if len(mantissa.replace(".", "").lstrip("0")) > MAX_LITERAL_DIGITS:
        raise ExpressionTooLarge(
            f"a number of more than {MAX_LITERAL_DIGITS} digits; the limit is {MAX_LITERAL_DIGITS} "
            f"(10**{MAX_LITERAL_DIGITS} exceeds a double's range)"
        )
    if "." not in plain and "e" not in plain.lower():
        return checked(sp.Integer(int(plain)))
    if not math.isfinite(float(plain)):
        raise ExpressionTooLarge(f"{text} is beyond a double's range (≈ 1.8e308)")
    return sp.Float(plain)


def nesting_depth(text: str, opening: str = "([{", closing: str = ")]}") -> int:
    """The deepest bracket nesting in ``text`` (unbalanced brackets are the parser's business)."""
    depth = deepest = 0
    for c in text:
        if c in opening:
            depth += 1
            deepest = max(deepest, depth)
        elif c in closing:
            depth -= 1
    return deepest


def check_nesting(text: str, opening: str = "([{", closing: str = ")]}") -> None:
    """Refuse brackets nested deeper than ``MAX_NESTING``."""
    depth = nesting_depth(text, opening, closing)
    if depth > MAX_NESTING:
        raise ExpressionTooLarge(f"brackets nested {depth} deep; the limit is {MAX_NESTING}")


def _digits(value: sp.Integer) -> str:
    n = abs(int(value))
    return f"{n}" if n < 10**12 else f"about 2**{n.bit_length() - 1}"
