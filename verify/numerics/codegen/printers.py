"""SymPy printers: NumPy code over arrays, scalar numba code (floats), and generic code whose
numbers go through ``N``.

NumPy (``numpy_printer``): SymPy's own NumPy printer, numbers written exactly (``ExactNumbers``).

Numba (``numba_printer``): floats as exact ``repr`` literals, rationals as the
correctly rounded p/q, small integer powers as products, ``math.sqrt`` for ½ powers.

Generic (``generic_printer``): code that runs on float, numpy arrays, ``mpmath.mpf``,
``Decimal`` and the Taylor ``Series``, so it may only add, subtract, multiply and
divide.  Every non-integer number is made exact in the caller's type through the
function ``N`` the code receives: a float as ``N(repr)`` (the double's exact value,
as the float model sees it), a rational as ``N(p)/N(q)``, π as ``N(repr(math.pi))``;
integers stay Python ints (every type above mixes with them exactly), and a
reciprocal is ``1/d``, never ``1.0/d`` (Decimal refuses floats).  Integer powers
become products (a ``Series`` has no power); sin and cos must have been replaced
by symbols beforehand (``generic.trig_symbols``); any other function raises
``Unsupported``.
"""

from __future__ import annotations


class Unsupported(ValueError):
    """An expression the generic printer cannot write with + − × ÷ alone."""


def _power(printer, expr, one: str, sqrt: bool):
    """Integer powers as products (1 ≤ |k| ≤ 4), else None; shared by both printers."""
    import sympy as sp
    from sympy.printing.precedence import PRECEDENCE

    base, exp = expr.base, expr.exp
    if exp.is_Integer and 2 <= int(exp) <= 4:
        b = printer.parenthesize(base, PRECEDENCE["Mul"])
        return "(" + "*".join([b] * int(exp)) + ")"
    if exp.is_Integer and -4 <= int(exp) <= -1:
        inner = base if exp == -1 else sp.Pow(base, -exp, evaluate=False)
        return f"({one}/{printer.parenthesize(inner, PRECEDENCE['Atom'])})"
    if sqrt and exp == sp.S.Half:
        return f"math.sqrt({printer._print(base)})"
    if sqrt and exp == -sp.S.Half:
        return f"({one}/math.sqrt({printer._print(base)}))"
    return None


class ExactNumbers:
    """Printer methods that write numbers exactly: a float as its repr, p/q correctly rounded."""

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return repr(int(expr.p) / int(expr.q))  # correctly rounded p/q


def numpy_printer():
    """SymPy's NumPy printer with exact numbers; it raises on a function NumPy has no ufunc for."""
    from sympy.printing.numpy import NumPyPrinter

    class ExactNumPyPrinter(ExactNumbers, NumPyPrinter):
        pass

    return ExactNumPyPrinter({"strict": True})


def numba_printer():
    """A PythonCodePrinter for numba: exact float literals, small powers as products."""
    from sympy.printing.precedence import PRECEDENCE, precedence
    from sympy.printing.pycode import PythonCodePrinter

    class NumbaPrinter(ExactNumbers, PythonCodePrinter):
        def _print_Pow(self, expr, rational=False):
            done = _power(self, expr, "1.0", sqrt=True)
            if done is not None:
                return done
            base, exp = expr.base, expr.exp
            return (
                f"{self.parenthesize(base, precedence(expr))}**{self.parenthesize(exp, PRECEDENCE['Atom'])}"
            )

    return NumbaPrinter({"fully_qualified_modules": True, "standard": "python3"})


def generic_printer():
    """A printer for code generic over the number type (module docstring)."""
    import sympy as sp
    from sympy.printing.precedence import PRECEDENCE
    from sympy.printing.pycode import PythonCodePrinter

    class GenericPrinter(PythonCodePrinter):
        def _print_Float(self, expr):
            return f"N({float(expr)!r})"

        def _print_Rational(self, expr):
            return f"(N({int(expr.p)})/N({int(expr.q)}))"

        def _print_Integer(self, expr):
            return str(int(expr))

        def _print_Pi(self, expr):
            return f"N({float(sp.pi)!r})"

        def _print_Exp1(self, expr):
            return f"N({float(sp.E)!r})"

        def _print_Mul(self, expr):
            # a product of factors, never a fraction "x/2" (int / int or Series / int is not exact)
            coeff, factors = expr.as_coeff_mul()
            sign = "-" if coeff < 0 else ""
            parts = [] if abs(coeff) == 1 else [self._print(abs(coeff))]
            parts += [self.parenthesize(f, PRECEDENCE["Mul"]) for f in factors]
            return sign + "*".join(parts or ["1"])

        def _print_Pow(self, expr, rational=False):
            base, exp = expr.base, expr.exp
            if exp.is_Integer and int(exp) != 0:
                done = _power(self, expr, "1", sqrt=False)
                if done is not None:
                    return done
                k = abs(int(exp))  # larger powers: a product all the same
                prod = "(" + "*".join([self.parenthesize(base, PRECEDENCE["Mul"])] * k) + ")"
                return prod if int(exp) > 0 else f"(1/{prod})"
            raise Unsupported(f"the power {expr}")

        def _print_Function(self, expr):
            raise Unsupported(f"the function {expr.func.__name__}")

        # the functions the base printer would print but the generic code cannot hold
        _print_Abs = _print_Max = _print_Min = _print_sign = _print_Piecewise = _print_Function
        _print_sqrt = _print_exp = _print_log = _print_Function
        _print_sin = _print_cos = _print_tan = _print_atan2 = _print_Function

        def emptyPrinter(self, expr):
            raise Unsupported(f"{type(expr).__name__} {expr}")

    return GenericPrinter({"standard": "python3"})
