"""A model's own closed forms run once over a whole batch of states, bit for bit as state by state.

A closed form is plain Python over ``self.math`` and ``np.array`` (``analytic.interface``).
Called with ``Lanes`` in place of the state's numbers — one object per coordinate holding
that coordinate at every state of the batch — the same code runs once for all states:
``Lanes`` does each scalar operation on a numpy array of lanes (elementwise IEEE
arithmetic, the same bits as on one number), ``np.array`` of them gives an object array
whose entries are ``Lanes``, and ``self.math`` maps Python's own ``math`` functions over
the lanes (not numpy's, whose SIMD versions may round differently).  What cannot be
done so raises and the method is evaluated state by state instead (``ClosedFormBatch``):

* a comparison, ``if``, ``float()``, a NumPy function on a ``Lanes`` (``np.cos``), an
  unsupported operator;
* code the scan ``pendverify.checks.elementwise`` rejects: reductions (``np.sum``, ``sum``, ``.dot``,
  ``np.linalg.norm`` …), whose results on float arrays come from BLAS or pairwise sums,
  not from the sequence of scalar operations an object array would do;
* a ``@`` NumPy would carry out entry by entry: ``@`` and ``np.linalg.solve``/``inv``/``det``
  on the arrays the batch hands out are done as one state's BLAS/LAPACK calls
  (``pendverify.checks.lane_arrays``), and an operation on lanes from inside any other
  ``@`` raises.

Two operations can round differently on one number and on an array element: ``x ** y``
(Python and numpy scalars call the C library's ``pow``; a float array squares for y = 2,
takes the root for 0.5, the reciprocal for −1) and a division by zero or a math
function out of its domain (a Python float raises, an array gives inf or nan).  Such
lanes are marked ``unsure`` and their states evaluated one by one.
"""

from __future__ import annotations

import dis
import functools
import math
import operator
import sys
import types

import numpy as np

_MATMUL_OPCODES = {
    dis.opmap[k] for k in ("BINARY_MATRIX_MULTIPLY", "INPLACE_MATRIX_MULTIPLY") if k in dis.opmap
}
_BINARY_OP = dis.opmap.get("BINARY_OP", -1)  # Python ≥ 3.11: its argument 4 is @, 17 is @=
_SCALARS = (float, int, np.integer)  # np.float64 is a float; other floating types are refused


class NotVectorisable(Exception):
    """The batch cannot run this code as written; the caller evaluates state by state."""


def merge(*masks):
    present = [m for m in masks if m is not None]
    if not present:
        return None
    out = present[0]
    for m in present[1:]:
        out = out | m
    return out


class Lanes:
    """One scalar of a closed form at every state of a batch: ``a`` the values, ``unsure`` (or None)."""

    __slots__ = ("a", "unsure")
    __array_ufunc__ = None  # numpy hands binary operations with a Lanes to its reflected methods
    __hash__ = None

    def __init__(self, a: np.ndarray, unsure=None):
        self.a, self.unsure = a, unsure

    def _operand(self, other):
        if isinstance(other, Lanes):
            return other.a, other.unsure
        if isinstance(other, _SCALARS) and not (isinstance(other, int) and abs(other) > 2**53):
            return other, None
        return None, None

    def _binary(self, other, op, reflected=False):
        if _in_matmul(sys._getframe(2)):  # the caller of the operator: NumPy adds the products one by one
            raise NotVectorisable("@ of arrays built from lanes: evaluated state by state")
        if isinstance(other, np.ndarray):
            f = (lambda e: op(e, self)) if reflected else (lambda e: op(self, e))
            return _each(other, f)
        b, unsure = self._operand(other)
        if b is None:
            return NotImplemented
        x, y = (b, self.a) if reflected else (self.a, b)
        out = op(x, y)
        mask = merge(self.unsure, unsure)
        if op is operator.truediv:  # a Python float raises where the array gives inf or nan
            zero = np.asarray(y == 0)
            if zero.any():
                mask = merge(mask, np.broadcast_to(zero, out.shape))
        return Lanes(out, mask)

    def __add__(self, o):
        return self._binary(o, operator.add)

    def __radd__(self, o):
        return self._binary(o, operator.add, True)

    def __sub__(self, o):
        return self._binary(o, operator.sub)

    def __rsub__(self, o):
        return self._binary(o, operator.sub, True)

    def __mul__(self, o):
        return self._binary(o, operator.mul)

    def __rmul__(self, o):
        return self._binary(o, operator.mul, True)

    def __truediv__(self, o):
        return self._binary(o, operator.truediv)

    def __rtruediv__(self, o):
        return self._binary(o, operator.truediv, True)

    def __pow__(self, o):
        return self._power(o, False)

    def __rpow__(self, o):
        return self._power(o, True)

    def _power(self, other, reflected):
        if isinstance(other, np.ndarray):
            return _each(other, lambda e: (e**self) if reflected else (self**e))
        b, unsure = self._operand(other)
        if b is None:
            return NotImplemented
        base, exponent = (b, self.a) if reflected else (self.a, b)
        # one number: the C library's pow (Python and numpy scalars alike); an array element:
        # numpy's array power (fast paths for 2, 0.5, -1); where they differ, the lane is unsure
        scalar, failed = _map(math.pow, [base, exponent], self.a.size)
        with np.errstate(all="ignore"):  # the exponent as given: numpy's fast paths depend on its type
            array = (b**self.a) if reflected else (self.a**b)
        differ = failed | ~((scalar == array) | (np.isnan(scalar) & np.isnan(array)))
        return Lanes(scalar, merge(self.unsure, unsure, differ if differ.any() else None))

    def __neg__(self):
        return Lanes(-self.a, self.unsure)

    def __pos__(self):
        return Lanes(+self.a, self.unsure)

    def __abs__(self):
        return Lanes(np.abs(self.a), self.unsure)

    def _refuse(self, *_):
        raise NotVectorisable("a closed form compares or converts a number: evaluated state by state")

    __eq__ = __ne__ = __lt__ = __le__ = __gt__ = __ge__ = _refuse
    __bool__ = __float__ = __int__ = __index__ = __complex__ = __round__ = _refuse


def _each(array: np.ndarray, f) -> np.ndarray:
    """``f`` of every entry of ``array``: an object array (what numpy does entry by entry anyway)."""
    from pendverify.checks.lane_arrays import lane_array

    out = np.empty(array.shape, dtype=object)
    for index in np.ndindex(array.shape):
        out[index] = f(array[index])
    return lane_array(out)


def _in_matmul(frame) -> bool:
    """Whether ``frame`` is executing ``@``: an operation on lanes from there is NumPy's object matmul."""
    code, i = frame.f_code.co_code, frame.f_lasti
    if not 0 <= i < len(code) - 1:
        return False
    return code[i] in _MATMUL_OPCODES or (code[i] == _BINARY_OP and code[i + 1] in (4, 17))


def _map(f, args, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(f over the lanes as Python floats, lanes where f raised); a scalar argument is repeated."""
    columns = [np.broadcast_to(np.asarray(a, dtype=float), (n,)).tolist() for a in args]
    failed = np.zeros(n, dtype=bool)
    try:
        return np.fromiter(map(f, *columns), dtype=float, count=n), failed
    except (ValueError, OverflowError, ZeroDivisionError, TypeError):
        out = np.empty(n)
        for i, xs in enumerate(zip(*columns, strict=True)):
            try:
                out[i] = f(*xs)
            except (ValueError, OverflowError, ZeroDivisionError, TypeError):
                out[i], failed[i] = np.nan, True
        return out, failed


def lane_function(f):
    """``f`` on numbers as it is; on ``Lanes``, ``f`` applied lane by lane (the same bits)."""

    @functools.wraps(f)
    def call(*args):
        lanes = [a for a in args if isinstance(a, Lanes)]
        if not lanes:
            return f(*args)
        if any(not isinstance(a, (Lanes, *_SCALARS)) for a in args):
            raise NotVectorisable(f"{getattr(f, '__name__', f)} of a non-number")
        values, failed = _map(f, [a.a if isinstance(a, Lanes) else a for a in args], lanes[0].a.size)
        return Lanes(values, merge(*(a.unsure for a in lanes), failed if failed.any() else None))

    return call


def lane_math(namespace: types.SimpleNamespace) -> types.SimpleNamespace:
    """A ``self.math`` whose functions take ``Lanes`` too (constants such as π unchanged)."""
    return types.SimpleNamespace(
        **{k: lane_function(v) if callable(v) else v for k, v in vars(namespace).items()}
    )


def to_lanes(X: np.ndarray) -> np.ndarray:
    """The batch (N, n) as one object vector of n ``Lanes``: what a closed form gets for q."""
    out = np.empty(X.shape[1], dtype=object)
    for i in range(X.shape[1]):
        out[i] = Lanes(np.ascontiguousarray(X[:, i]))
    return out


def stack(value, n: int) -> tuple[np.ndarray, np.ndarray | None]:
    """(values with the batch axis first, float (N, …), states marked unsure or None)."""
    if isinstance(value, Lanes):
        return np.broadcast_to(value.a, (n,)).astype(float), value.unsure
    if isinstance(value, list | tuple):
        value = np.array(value, dtype=object)
    if not isinstance(value, np.ndarray):
        if isinstance(value, _SCALARS):
            return np.full(n, float(value)), None
        raise NotVectorisable(f"a closed form returned a {type(value).__name__}")
    if value.dtype != object:
        if value.dtype.kind not in "fiub":
            raise NotVectorisable(f"a closed form returned an array of {value.dtype}")
        return np.broadcast_to(value.astype(float), (n, *value.shape)).copy(), None
    out, unsure = np.empty((n, *value.shape)), None
    for index in np.ndindex(value.shape):
        entry = value[index]
        if isinstance(entry, Lanes):
            out[(slice(None), *index)] = entry.a
            unsure = merge(unsure, entry.unsure)
        elif isinstance(entry, _SCALARS):
            out[(slice(None), *index)] = float(entry)
        else:
            raise NotVectorisable(f"a closed form returned an entry {type(entry).__name__}")
    return out, unsure
