"""An exact zero test for SymPy expressions of a model's closed forms.

``is_zero(e)`` decides ``simplify(e) == 0`` without calling ``simplify`` in the
common case, which is far too slow for rational trigonometric expressions (47 s
for the double pendulum's q̈ residual alone).  The canonical form used:

1. ``expand_trig`` turns sin/cos of sums of angles into products of sin θi, cos θi;
2. the numerator of the rational normal form (``together``) is expanded as a
   polynomial in s_i = sin θi, c_i = cos θi and every other symbol;
3. s_i² is replaced by 1 − c_i² (the remainder modulo the Gröbner basis
   {s_i² + c_i² − 1}), which leaves a canonical polynomial, linear in each s_i.

That polynomial is zero exactly when e is zero as a function.  When e holds
functions outside this class (sin of 1.001·θ, sqrt, ...), a numerical probe at
random rational points in 50-digit arithmetic proves non-zero results, and
``sympy.simplify`` decides the rest.  The expressions come from a model read by
``pendverify.analytic.symbolic_reading``.
"""

from __future__ import annotations

import random

import sympy as sp

PROBE_DIGITS = 50
PROBE_ZERO = sp.Float(10) ** -30  # |e| below this at 50 digits: numerically zero


def trig_normal_form(expr, angles, keep_trig: bool = False) -> sp.Expr | None:
    """The canonical polynomial of ``expr``'s numerator (module docstring); None if not a trig polynomial.

    With ``keep_trig`` the sin θi, cos θi are put back, so that the result is an
    expression equal to the numerator; otherwise they stay as dummy symbols.
    """
    expr = sp.sympify(expr)
    if expr == 0:
        return sp.S.Zero
    numerator, _ = sp.fraction(sp.together(sp.expand_trig(expr)))
    replace, pairs = {}, []
    for theta in angles:
        s, c = sp.Dummy(f"s_{theta}"), sp.Dummy(f"c_{theta}")
        replace[sp.sin(theta)], replace[sp.cos(theta)] = s, c
        pairs.append((s, c))
    poly = sp.expand(numerator.xreplace(replace))
    if _has_nonpolynomial(poly):
        return None
    if poly == 0 or not pairs:
        return poly
    reduced = sp.S.Zero
    for monomial, coefficient in sp.Poly(poly, *[s for s, _ in pairs]).terms():
        term = coefficient
        for (s, c), power in zip(pairs, monomial, strict=True):
            term *= s ** (power % 2) * (1 - c**2) ** (power // 2)
        reduced += term
    reduced = sp.expand(reduced)
    if keep_trig:
        back = {}
        for theta, (s, c) in zip(angles, pairs, strict=True):
            back[s], back[c] = sp.sin(theta), sp.cos(theta)
        reduced = reduced.xreplace(back)
    return reduced


def canonical(expr, angles):
    """``expr`` as its canonical trig polynomial if it is one (smaller, and equal); else unchanged."""
    expr = sp.sympify(expr)
    numerator, denominator = sp.fraction(sp.together(expr))
    form = trig_normal_form(numerator, angles, keep_trig=True)
    if denominator.has(*angles):
        denominator = trig_normal_form(denominator, angles, keep_trig=True)
    return expr if form is None or denominator is None else form / denominator


def _has_nonpolynomial(expr) -> bool:
    """True if a function call or a non-integer/negative power survives the rewriting."""
    for node in sp.preorder_traversal(expr):
        if isinstance(node, sp.Function) or (node.is_Pow and not (node.exp.is_Integer and node.exp > 0)):
            return True
    return False


def probe(expr, seed: int = 0, points: int = 2) -> bool:
    """True if ``expr`` is non-zero at some random rational point (50-digit arithmetic)."""
    expr = sp.sympify(expr)
    free = sorted(expr.free_symbols, key=lambda s: s.name)
    rng = random.Random(seed)
    for _ in range(points):
        values = {s: sp.Rational(rng.randint(300, 1700), 1000) for s in free}
        value = expr.xreplace(values).evalf(PROBE_DIGITS)
        if value.is_number and abs(value) > PROBE_ZERO:
            return True
    return False


def is_zero(expr, angles) -> bool:
    """``simplify(expr) == 0``, decided exactly and quickly (module docstring)."""
    expr = sp.sympify(expr)
    if expr == 0:
        return True
    form = trig_normal_form(expr, angles)
    if form is not None:
        return form == 0
    if probe(expr):
        return False
    return sp.simplify(expr) == 0


def show(expr, angles=(), limit: int = 160) -> str:
    """A short printable form: the canonical trig polynomial, factored when small and shorter."""
    expr = canonical(sp.sympify(expr), angles)
    if sp.count_ops(expr) <= 60:
        try:
            factored = sp.factor(expr)
            if len(str(factored)) < len(str(expr)):
                expr = factored
        except (sp.PolynomialError, TypeError, ValueError):  # pragma: no cover - factor gave up
            pass
    text = str(expr)
    return text if len(text) <= limit else text[: limit - 1] + "…"
