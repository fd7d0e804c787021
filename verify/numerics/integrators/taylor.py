"""Taylor-series integration in high precision of the model's equations.

The ODE ẋ = f(x) is the model's generated ``field`` (``pendverify.numerics.codegen.generic``:
same parameters, same force law τ = B (u0 − K x) − D q̇, written once from the
model's closed forms, generic over the number type): it runs on floats, numpy
arrays, mpmath numbers, Decimals and on ``Series``.  On ``Series`` it
records a tape of elementary operations on truncated power series (+, −, ×, ÷
and the sin/cos pair, each with its O(k) recurrence for the k-th coefficient),
replayed order by order: x_{k+1} = f_k / (k + 1).  Arithmetic is Python's
``decimal`` (libmpdec, C) at the requested digits plus ``GUARD_DIGITS``; the sin
and cos of each step's initial angles come from mpmath.

Order and step follow Jorba & Zou (2005): for a tolerance ε, order
p = ⌈−ln ε / 2⌉ + 1 and a step h with ‖x_k‖∞ h^k ≤ ε·max(1, ‖x_0‖∞) for
k = p − 1 and p, times SAFETY, so the neglected tail is ≈ ε per step.  Dense
points are the step's polynomial evaluated inside the step.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, getcontext, localcontext
from operator import mul

import mpmath
import numpy as np

from pendverify.errors import PendverifyError

GUARD_DIGITS = 8
SAFETY = 0.9


# --- truncated power series on a tape -----------------------------------------------------
def _add(n, k):
    return n.a.c[k] + n.b.c[k]


def _sub(n, k):
    return n.a.c[k] - n.b.c[k]


def _addc(n, k):
    return n.a.c[k] + n.value if k == 0 else n.a.c[k]


def _rsubc(n, k):
    return n.value - n.a.c[k] if k == 0 else -n.a.c[k]


def _mulc(n, k):
    return n.value * n.a.c[k]


def _mul(n, k):
    return sum(map(mul, n.a.c[: k + 1], n.b.c[k::-1]))


def _div(n, k):  # w = a / b:  w_k = (a_k − Σ_{j≥1} b_j w_{k−j}) / b_0
    b = n.b.c
    return (n.a.c[k] - sum(map(mul, b[1 : k + 1], n.c[k - 1 :: -1]))) / b[0] if k else n.a.c[0] / b[0]


def _rdiv(n, k):  # w = value / a
    a = n.a.c
    return -sum(map(mul, a[1 : k + 1], n.c[k - 1 :: -1])) / a[0] if k else n.value / a[0]


def _sin(n, k):  # s' = c u',  c' = −s u':  k s_k = Σ_j j u_j c_{k−j},  k c_k = −Σ_j j u_j s_{k−j}
    u, cos = n.a.c, n.partner.c
    if k == 0:
        s0, c0 = _sincos0(u[0])
        cos.append(c0)
        n.ju = [u[0]]  # slot 0 unused
        return s0
    n.ju.append(k * u[k])
    ju = n.ju[1 : k + 1]
    s_k = sum(map(mul, ju, cos[k - 1 :: -1])) / k
    cos.append(-sum(map(mul, ju, n.c[k - 1 :: -1])) / k)
    return s_k


def _sincos0(u: Decimal) -> tuple[Decimal, Decimal]:
    """sin and cos of a Decimal, through mpmath at the context's precision plus guard digits."""
    digits = getcontext().prec + 5
    with mpmath.workdps(digits):
        x = mpmath.mpf(str(u))
        return (
            +Decimal(mpmath.nstr(mpmath.sin(x), digits, strip_zeros=False)),
            +Decimal(mpmath.nstr(mpmath.cos(x), digits, strip_zeros=False)),
        )


_OPS = {
    "add": _add,
    "sub": _sub,
    "addc": _addc,
    "rsubc": _rsubc,
    "mulc": _mulc,
    "mul": _mul,
    "div": _div,
    "rdiv": _rdiv,
    "sin": _sin,
}


class Series:
    """One node of the tape: its Taylor coefficients c[0..k], computed order by order."""

    __slots__ = ("_tape", "a", "b", "c", "fn", "ju", "kind", "partner", "value")

    def __init__(self, tape: list, kind: str, a=None, b=None, value=None):
        self.c, self.kind, self.a, self.b, self.value = [], kind, a, b, value
        self.fn = _OPS.get(kind)  # None for "var" and "cos" (filled by others)
        self.partner = self.ju = None
        self._tape = tape
        tape.append(self)

    def _new(self, kind, a=None, b=None, value=None):
        return Series(self._tape, kind, a, b, value)

    def __add__(self, o):
        return self._new("add", self, o) if isinstance(o, Series) else self._new("addc", self, value=o)

    __radd__ = __add__

    def __sub__(self, o):
        return self._new("sub", self, o) if isinstance(o, Series) else self._new("addc", self, value=-o)

    def __rsub__(self, o):
        return self._new("rsubc", self, value=o)

    def __neg__(self):
        return self._new("mulc", self, value=-1)

    def __mul__(self, o):
        return self._new("mul", self, o) if isinstance(o, Series) else self._new("mulc", self, value=o)

    __rmul__ = __mul__

    def __truediv__(self, o):
        return self._new("div", self, o) if isinstance(o, Series) else self._new("mulc", self, value=1 / o)

    def __rtruediv__(self, o):
        return self._new("rdiv", self, value=o)


def series_sincos(u):
    """(sin u, cos u) for a Series, a float, a numpy array, a Decimal or an mpf."""
    if isinstance(u, Series):
        s = u._new("sin", u)
        c = u._new("cos", u)
        s.partner = c
        return s, c
    if isinstance(u, float):
        return math.sin(u), math.cos(u)
    if isinstance(u, np.ndarray):
        return np.sin(u), np.cos(u)
    if isinstance(u, Decimal):
        return _sincos0(u)
    return mpmath.sin(u), mpmath.cos(u)


# --- the model's generated functions, generic over float, numpy, mpf, Decimal and Series -------
def _numbers(fast, number) -> dict:
    """A ``GeneratedSystem``'s numbers as the generated generic functions take them (``number`` each)."""
    error = fast.module.FIELD_ERROR
    if error:
        raise PendverifyError(f"{fast.model}: no Taylor reference: {error}")
    if fast.forcing:
        why = "the forcing is time-varying, and the references integrate a time-invariant field"
        raise PendverifyError(f"{fast.model}: no Taylor reference: {why}")

    def conv(values):
        return [number(float(v)) for v in values]

    return {
        "system": fast,
        "module": fast.module,
        "N": number,
        "params": conv(fast.params),
        "D": [conv(row) for row in fast.D],
        "B": [conv(row) for row in fast.B],
        "K": [conv(row) for row in fast.K],
        "u0": conv(fast.u0),
    }


def exact_system(fast, number=mpmath.mpf) -> dict:
    """A ``GeneratedSystem`` in exact ``number`` values (Decimal or mpf: exact for doubles)."""
    return _numbers(fast, number)


def float_system(fast) -> dict:
    return _numbers(fast, float)


def field(system, x):
    """ẋ = f(x): the model's generated ``field`` in the system's number type (or on Series)."""
    return system["module"].field(system, x, system["N"], series_sincos)


def energy_above_minimum(system, x):
    """E(x) − V_min = ½ q̇ᵀ M q̇ + V(q) − min V, generated from the model (float, numpy or mpf).

    V_min is ``GeneratedSystem.potential_minimum`` (how it is found: there), as an
    exact ``number``: it only normalises relative energy errors."""
    fast, N = system["system"], system["N"]
    error = fast.module.ENERGY_ERROR
    if error:
        raise PendverifyError(f"{fast.model}: no energy for the Taylor path: {error}")
    return system["module"].energy(system, x, N, series_sincos) - N(fast.potential_minimum)


# --- the integrator ------------------------------------------------------------------------
@dataclass(frozen=True)
class TaylorRun:
    grid: list  # Decimal states at the dense points
    steps: int
    order: int


def _log10(x: Decimal) -> float:
    """log10 of a positive Decimal as a float (its exponent taken apart, so no overflow)."""
    e = x.adjusted()
    return e + math.log10(float(x.scaleb(-e)))


def _horner(coeffs: list, t: Decimal) -> Decimal:
    acc = coeffs[-1]
    for c in reversed(coeffs[:-1]):
        acc = acc * t + c
    return acc


def taylor_solve(fast, x0, duration: float, grid: np.ndarray, digits: int) -> TaylorRun:
    """States at ``grid`` (sorted, within [0, duration]) to about 10^-digits.

    Arithmetic is Python's ``decimal`` (C, libmpdec) at digits + GUARD_DIGITS
    significant digits; sin and cos of each step's initial angles come from mpmath.
    """
    with localcontext() as ctx:
        ctx.prec = digits + GUARD_DIGITS
        system = exact_system(fast, Decimal)
        eps = Decimal(10) ** (-digits)
        order = math.ceil(digits * math.log(10) / 2) + 1
        tape: list = []
        xs = [Series(tape, "var") for _ in x0]
        rhs = field(system, xs)
        work = [node for node in tape if node.fn is not None]
        x = [Decimal(float(v)) for v in x0]
        t, end = Decimal(0), Decimal(float(duration))
        times = [Decimal(float(v)) for v in grid]
        out, g, steps = [], 0, 0
        while g < len(times) and times[g] <= 0:
            out.append(list(x))
            g += 1
        while t < end:
            for node in tape:
                node.c.clear()
            for node, value in zip(xs, x, strict=True):
                node.c.append(value)
            for k in range(order):
                for node in work:
                    node.c.append(node.fn(node, k))
                new = [r.c[k] / (k + 1) for r in rhs]
                for node, value in zip(xs, new, strict=True):
                    node.c.append(value)
            coeffs = [node.c for node in xs]
            scale = _log10(eps * max(1, max(abs(v) for v in x)))
            h = end - t
            for k in (order - 1, order):
                size = max(abs(cs[k]) for cs in coeffs)
                if size > 0:  # ‖x_k‖ h^k = ε·max(1, ‖x‖), in floats: only a few digits of h matter
                    h = min(h, Decimal(SAFETY * 10.0 ** ((scale - _log10(size)) / k)))
            stop = end if h >= end - t else t + h  # the last step lands on ``end`` exactly
            while g < len(times) and times[g] <= stop:
                out.append([_horner(cs, times[g] - t) for cs in coeffs])
                g += 1
            x = [_horner(cs, h) for cs in coeffs]
            t = stop
            steps += 1
        return TaylorRun(out, steps, order)
