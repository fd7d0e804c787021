"""A closed-form model read as SymPy expressions.

No formula is rewritten for SymPy: the model class is instantiated with one
SymPy symbol per parameter (real; masses and lengths positive, the other kinds
non-negative) and its ``math`` namespace swapped for SymPy's functions (see
``pendverify.analytic.interface``); its methods are then called with object
arrays of symbols

    q = (coordinates…),  v = (d<coordinate>…),  u = (inputs…),  w = (disturbances…)

and what they return becomes a SymPy matrix (vectors are columns) or scalar.
What is read is therefore exactly the code that runs numerically.  Python floats
with integer values (``np.eye``'s 1.0, a literal 0.0) become SymPy integers.
Whether an expression read here is zero is decided by ``pendverify.symbolic.zero_test``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np
import sympy as sp

from pendverify.analytic.forms import math_namespace
from pendverify.analytic.source_file import where
from pendverify.errors import PendverifyError

if TYPE_CHECKING:
    from pendverify.analytic.interface import ClosedFormModel

SYMBOLIC_MATH = math_namespace(sp)
_POSITIVE_KINDS = {"mass", "length"}


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
        if model_cls.numeric_only:
            raise PendverifyError(f"{where(model_cls)}: {model_cls.__name__}: {model_cls.numeric_only}")
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

    @cached_property
    def kinds(self) -> dict[sp.Symbol, str]:
        """{parameter symbol: its kind} (``mass``, ``length``, ...) as the parameter set declares it."""
        fields = dataclasses.fields(self.cls.params_type)
        return {self.parameters[f.name]: f.metadata.get("kind", "") for f in fields}

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
