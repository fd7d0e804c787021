"""Which of a model's methods may run on ``Lanes``: a scan of their code for reductions.

``np.sum``, ``sum``, ``.dot``, ``np.linalg.norm`` … on one state's float arrays are BLAS
calls or pairwise sums; on object arrays of lanes NumPy would add entry by entry and round
differently, and neither ``Lanes`` nor ``LaneArray`` sees it happen.  A method whose code,
or the code of the methods, properties and module functions it reaches, names one of
``NOT_ELEMENTWISE`` is evaluated state by state (``pendverify.checks.forms_batch``).
"""

from __future__ import annotations

import dis
import inspect
import types

#: names whose use makes a method unfit for object arrays (see the module docstring)
NOT_ELEMENTWISE = frozenset(
    {
        "accumulate", "average", "convolve", "correlate", "cumprod", "cumsum", "dot", "einsum", "fsum",
        "inner", "matmul", "matrix_power", "mean", "multi_dot", "nanprod", "nansum", "norm",
        "polyval", "prod", "reduce", "reduceat", "std", "sum", "tensordot", "trace", "var", "vdot",
    }
)  # fmt: skip
_LOADS = ("LOAD_ATTR", "LOAD_METHOD", "LOAD_GLOBAL", "LOAD_NAME", "LOAD_DEREF", "IMPORT_FROM")
_SCANS: dict = {}  # (class, method) -> (elementwise?, the lookups the answer depends on)


def elementwise(cls: type, name: str) -> bool:
    """Whether method ``name`` of ``cls`` (and what it calls on self or module level) is elementwise.

    False when its code, or that of the methods, properties and module functions it
    reaches, uses a name of ``NOT_ELEMENTWISE``.  Answers are kept while every
    name they looked up still resolves to the same object (a patched method is scanned
    again).
    """
    entry = _SCANS.get((cls, name))
    if entry is not None and all(_unchanged(*lookup) for lookup in entry[1]):
        return entry[0]
    lookups: list = []
    func = _class_function(cls, name, lookups)
    answer = func is not None and _scan(func.__code__, func.__globals__, cls, set(), lookups)
    if len(_SCANS) >= 1024:
        _SCANS.clear()
    unique = {(id(holder), key): (holder, key, value) for holder, key, value in lookups}
    _SCANS[(cls, name)] = (answer, list(unique.values()))
    return answer


_MISSING = object()


def _unchanged(holder, name, value) -> bool:
    if isinstance(holder, dict):
        return holder.get(name, _MISSING) is value
    return getattr(holder, name, _MISSING) is value


def _class_function(cls: type, name: str, lookups: list):
    attribute = inspect.getattr_static(cls, name, None)
    lookups.append((cls, name, getattr(cls, name, _MISSING)))
    if isinstance(attribute, property):
        attribute = attribute.fget
    attribute = getattr(attribute, "__func__", attribute)
    return attribute if isinstance(attribute, types.FunctionType) else None


def _scan(code: types.CodeType, globals_: dict, cls: type, seen: set, lookups: list) -> bool:
    if code in seen:
        return True
    seen.add(code)
    for ins in dis.get_instructions(code):
        if ins.opname in _LOADS and isinstance(ins.argval, str):
            if ins.argval in NOT_ELEMENTWISE:
                return False
            target = None
            if ins.opname in ("LOAD_ATTR", "LOAD_METHOD"):  # a method or property of the class
                target = _class_function(cls, ins.argval, lookups)
            elif ins.opname in ("LOAD_GLOBAL", "LOAD_NAME"):  # a function of the module
                value = globals_.get(ins.argval, _MISSING)
                lookups.append((globals_, ins.argval, value))
                target = value if isinstance(value, types.FunctionType) else None
            if target is not None and not _scan(target.__code__, target.__globals__, cls, seen, lookups):
                return False
    return all(
        _scan(const, globals_, cls, seen, lookups)
        for const in code.co_consts
        if isinstance(const, types.CodeType)
    )
