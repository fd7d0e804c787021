"""Arrays of ``Lanes`` whose ``@`` and ``np.linalg`` run as one state's BLAS and LAPACK calls.

A closed form's ``A @ b`` on one state's float arrays is a BLAS call (it may fuse a
multiply and an add), ``np.linalg.solve`` a LAPACK one; on object arrays of ``Lanes``
NumPy would instead add the products one by one, and the bits would differ.  A
``LaneArray`` — the object arrays the batch hands a closed form (its q, q̇, u, w and what
the model's methods return) — catches both: it stacks its operands into float arrays
with the batch axis first, each state's matrix laid out in memory as that state's
would be (C or Fortran order), and calls NumPy's ``matmul`` or ``linalg`` on the stacks,
which make the same BLAS or LAPACK call once per state.  Elementwise operations stay
on the lanes (``pendverify.checks.lanes``); layout-changing functions (concatenate,
vstack, transpose …) keep the lanes; any other NumPy function on a ``LaneArray`` raises,
and the method is evaluated state by state.

A ``@`` between two arrays the closed form built itself (``np.array`` of lanes, which
this class cannot see) would run NumPy's object loop; ``Lanes`` refuses to be added or
multiplied from inside a ``@`` (``lanes.in_matmul``), so that case is evaluated state by
state too.
"""

from __future__ import annotations

import types

import numpy as np

from pendverify.checks.lanes import Lanes, NotVectorisable, merge, stack

#: NumPy functions that only move entries: on a LaneArray, done on the lanes as they are
STRUCTURAL = frozenset(
    {
        np.concatenate, np.vstack, np.hstack, np.stack, np.column_stack, np.atleast_1d, np.atleast_2d,
        np.transpose, np.reshape, np.ravel, np.squeeze, np.expand_dims, np.copy, np.diag, np.zeros_like,
    }
)  # fmt: skip


def lane_array(value):
    """``value`` as a LaneArray if it is an object array, else as it is."""
    if isinstance(value, np.ndarray) and value.dtype == object and not isinstance(value, LaneArray):
        return value.view(LaneArray)
    return value


def _plain(value):
    if isinstance(value, LaneArray):
        return value.view(np.ndarray)
    if isinstance(value, list | tuple):
        return type(value)(_plain(v) for v in value)
    return value


def _lanes_in(x: np.ndarray) -> int | None:
    for entry in x.flat:
        if isinstance(entry, Lanes):
            return entry.a.size
    return None


def _operand(x, n: int):
    """(values, unsure, batched): a float stack laid out per state as ``x`` is, or ``x`` itself."""
    if not (isinstance(x, np.ndarray) and x.dtype == object):
        return np.asarray(x), None, False
    if x.ndim not in (1, 2):
        raise NotVectorisable("@ or np.linalg of an array of more than two dimensions")
    values, unsure = stack(x.view(np.ndarray), n)
    if x.flags.c_contiguous:
        return values, unsure, True
    if x.ndim == 2 and x.flags.f_contiguous:  # each state's matrix in Fortran order, as x is
        return np.ascontiguousarray(values.transpose(0, 2, 1)).transpose(0, 2, 1), unsure, True
    raise NotVectorisable("@ or np.linalg of an array that is neither C- nor Fortran-contiguous")


def _batch_size(*xs) -> int:
    for x in xs:
        if isinstance(x, np.ndarray) and x.dtype == object:
            n = _lanes_in(x)
            if n is not None:
                return n
    raise NotVectorisable("no lanes")


def _result(values: np.ndarray, unsure):
    """Float values with the batch axis first as lanes: a Lanes for a number, else a LaneArray."""
    if values.ndim == 1:
        return Lanes(np.ascontiguousarray(values), unsure)
    out = np.empty(values.shape[1:], dtype=object)
    for index in np.ndindex(out.shape):
        out[index] = Lanes(np.ascontiguousarray(values[(slice(None), *index)]), unsure)
    return out.view(LaneArray)


def matmul(a, b):
    """``a @ b`` at every state, as NumPy multiplies one state's arrays (one BLAS call each)."""
    n = _batch_size(a, b)
    (A, ua, ba), (B, ub, bb) = _operand(a, n), _operand(b, n)
    nda, ndb = (A.ndim - ba), (B.ndim - bb)
    if nda == 0 or ndb == 0:
        raise NotVectorisable("@ of a scalar")
    left = A[..., None, :] if nda == 1 else A
    right = B[..., None] if ndb == 1 else B
    with np.errstate(all="ignore"):
        product = np.matmul(left, right)  # the batch axis first: one of them has it
    if ndb == 1:
        product = product[..., 0]
    if nda == 1:
        product = product[..., 0, :] if ndb == 2 else product[..., 0]
    return _result(product, merge(ua, ub))


def solve(a, b):
    """``np.linalg.solve(a, b)`` at every state (one LAPACK call each)."""
    n = _batch_size(a, b)
    (A, ua, _), (B, ub, bb) = _operand(a, n), _operand(b, n)
    A = np.broadcast_to(A, (n, *A.shape[-2:]))
    vector = B.ndim - bb == 1
    B = np.broadcast_to(B, (n, *B.shape[B.ndim - (1 if vector else 2) :]))
    x = np.linalg.solve(A, B[..., None])[..., 0] if vector else np.linalg.solve(A, B)
    return _result(x, merge(ua, ub))


def _unary(f):
    def call(a):
        n = _batch_size(a)
        A, unsure, _ = _operand(a, n)
        return _result(np.asarray(f(A)), unsure)

    return call


LINALG = {np.linalg.solve: solve, np.linalg.inv: _unary(np.linalg.inv), np.linalg.det: _unary(np.linalg.det)}


class LaneArray(np.ndarray):
    """An object array of a closed form at a batch of states (entries ``Lanes`` or numbers)."""

    def __array_ufunc__(self, ufunc, method, *inputs, **kwargs):
        if method != "__call__" or "out" in kwargs:
            raise NotVectorisable(f"np.{ufunc.__name__}.{method} on lanes")
        if ufunc is np.matmul:
            return matmul(*inputs)
        return lane_array(ufunc(*(_plain(x) for x in inputs), **kwargs))

    def __array_function__(self, func, types_, args, kwargs):
        if func in LINALG:
            return LINALG[func](*args, **kwargs)
        if func not in STRUCTURAL:
            raise NotVectorisable(f"np.{func.__name__} on lanes")
        return lane_array(func(*_plain(args), **_plain(kwargs)))

    def __matmul__(self, other):
        return matmul(self, other)

    def __rmatmul__(self, other):
        return matmul(other, self)

    def _refuse(self, *args, **kwargs):
        raise NotVectorisable("a reduction or product of lanes: evaluated state by state")

    dot = sum = prod = trace = mean = cumsum = cumprod = std = var = _refuse


def returning_lane_arrays(function: types.FunctionType):
    """``function`` with object arrays it returns made LaneArrays (so that ``@`` on them is caught)."""

    def call(*args, **kwargs):
        return lane_array(function(*args, **kwargs))

    call.__name__, call.__qualname__, call.__doc__ = (
        function.__name__,
        function.__qualname__,
        function.__doc__,
    )
    return call


def lane_twin_class(cls: type) -> type:
    """A subclass of the model class whose methods return LaneArrays (their code unchanged)."""
    namespace = {}
    for klass in reversed(cls.__mro__):
        for name, value in vars(klass).items():
            if isinstance(value, types.FunctionType) and not name.startswith("__"):
                namespace[name] = returning_lane_arrays(value)
    return type(cls)(f"{cls.__name__}OnLanes", (cls,), namespace)
