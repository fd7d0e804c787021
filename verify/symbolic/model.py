"""A closed-form model read as SymPy expressions, and an exact zero test.

Reading
-------
No formula is rewritten for SymPy: the model class is instantiated with one
SymPy symbol per parameter (real; masses and lengths positive, the other kinds
non-negative) and its ``math`` namespace swapped for SymPy's functions (see
``pendverify.analytic.interface``); its methods are then called with object
arrays of symbols

    q = (coordinates…),  v = (d<coordinate>…),  u = (inputs…),  w = (disturbances…)

and what they return becomes a SymPy matrix (vectors are columns) or scalar.
What is read is therefore exactly the code that runs numerically.  Python floats
with integer values (``np.eye``'s 1.0, a literal 0.0) become SymPy integers.

Zero test
---------
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
``sympy.simplify`` decides the rest.
"""

from __future__ import annotations

import dataclasses
import random
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import sympy as sp

from pendverify.analytic import ClosedFormModel
from pendverify.analytic.forms import math_namespace
from pendverify.analytic.plugin import where
from pendverify.errors import PendverifyError

SYMBOLIC_MATH = math_namespace(sp)
_POSITIVE_KINDS = {"mass", "length"}
PROBE_DIGITS = 50
PROBE_ZERO = sp.Float(10) ** -30  # |e| below this at 50 digits: numerically zero
ARGUMENT_KINDS = "qvuw"


def to_sympy(value):
    """A method's return value as a SymPy matrix (vectors as columns) or scalar."""
    if isinstance(value, sp.MatrixBase):
        return _integers(sp.Matrix(value))
    array = np.asarray(value, dtype=object)
    if array.ndim == 0:
        return _integers(sp.sympify(array.item()))
    if array.ndim == 1:
        array = array.reshape(-1, 1)
    rows, cols = array.shape
    return _integers(sp.Matrix(rows, cols, [sp.sympify(x) for x in array.ravel()]))


def _integers(expr):
    """Integer-valued floats (1.0, 0.0) as SymPy integers."""
    floats = {f: sp.Integer(int(f)) for f in expr.atoms(sp.Float) if float(f).is_integer()}
    return expr.xreplace(floats) if floats else expr


def entries(value) -> list:
    """The entries of a matrix in row-major order, or [value] for a scalar."""
    return list(value) if isinstance(value, sp.MatrixBase) else [value]


@dataclass
class SymbolicModel:
    """A model class instantiated with symbols: its closed forms as SymPy expressions."""

    cls: type[ClosedFormModel]
    model: ClosedFormModel
    symbols: dict[str, tuple[sp.Symbol, ...]]  # "q", "v", "u", "w"
    parameters: dict[str, sp.Symbol]

    @classmethod
    def of(cls, model_cls: type[ClosedFormModel]) -> SymbolicModel:
        params_type = model_cls.params_type
        params = object.__new__(params_type)  # symbols, not numbers: skip the validation
        parameters = {}
        for f in dataclasses.fields(params_type):
            kind = f.metadata.get("kind", "")
            assumption = {"positive": True} if kind in _POSITIVE_KINDS else {"nonnegative": True}
            parameters[f.name] = sp.Symbol(f.name, real=True, **assumption)
            object.__setattr__(params, f.name, parameters[f.name])
        symbols = {
            "q": tuple(sp.Symbol(c, real=True) for c in model_cls.coordinates),
            "v": tuple(sp.Symbol(f"d{c}", real=True) for c in model_cls.coordinates),
            "u": tuple(sp.Symbol(n, real=True) for n in model_cls.inputs),
            "w": tuple(sp.Symbol(n, real=True) for n in model_cls.disturbances),
        }
        names = [s.name for group in symbols.values() for s in group] + list(parameters)
        clashes = sorted({n for n in names if names.count(n) > 1})
        if clashes:
            raise PendverifyError(
                f"{where(model_cls)}: {model_cls.__name__} uses the name(s) {', '.join(clashes)} twice "
                "among coordinates, d<coordinate> rates, inputs, disturbances and parameters"
            )
        try:
            model = model_cls(params)
        except Exception as exc:
            raise PendverifyError(
                f"{where(model_cls)}: {model_cls.__name__}(params) fails with symbolic parameters "
                f"({type(exc).__name__}: {exc}); keep __init__ free of arithmetic on the parameters"
            ) from None
        model.math = SYMBOLIC_MATH
        return cls(model_cls, model, symbols, parameters)

    @property
    def angles(self) -> tuple[sp.Symbol, ...]:
        return tuple(s for s, a in zip(self.symbols["q"], self.cls.angular, strict=True) if a)

    def arguments(self, args: str) -> list[np.ndarray]:
        """The argument arrays for a signature such as "qv"."""
        return [np.array(self.symbols[a], dtype=object) for a in args]

    def flat_arguments(self, args: str) -> list[sp.Symbol]:
        return [s for a in args for s in self.symbols[a]]

    def evaluate(self, method: str, args: str):
        """Call ``method`` on symbols; a clear error if the code cannot take them."""
        try:
            # NumPy's floating-point flags say nothing about object arrays of SymPy expressions
            # (nan · [[m1 + m2, ...]] sets "invalid"): no RuntimeWarning from a symbolic reading
            with np.errstate(all="ignore"):
                return to_sympy(getattr(self.model, method)(*self.arguments(args)))
        except Exception as exc:
            raise PendverifyError(
                f"{where(self.cls)}: {self.cls.__name__}.{method} cannot be read by SymPy "
                f"({type(exc).__name__}: {exc}); call trigonometric functions through self.math "
                "(self.math.cos, self.math.sin, ...) and build arrays with np.array"
            ) from None

    @cached_property
    def closed_forms(self) -> dict:
        """Every declared closed form the model writes itself, evaluated (derived defaults are not)."""
        return {
            name: self.evaluate(name, form.args) for name, form in self.cls.written_closed_forms().items()
        }

    def column(self, kind: str) -> sp.Matrix:
        return sp.Matrix(len(self.symbols[kind]), 1, list(self.symbols[kind]))

    def values(self, params) -> dict[sp.Symbol, sp.Float]:
        """{parameter symbol: value} for a numeric parameter set."""
        return {s: sp.Float(getattr(params, name)) for name, s in self.parameters.items()}


# --- the zero test --------------------------------------------------------------------------
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
