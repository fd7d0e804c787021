"""The model boundary: a closed-form model's method, evaluated numerically, as a float array.

A hand-written method returns numbers in whatever container its code builds: a NumPy array of
floats, but also an object array (SymPy-derived code writes ``np.array([[...]], dtype=object)``),
a list, a tuple, nested lists, a NumPy scalar, a 0-d array where a scalar is meant, or SymPy's
``Float``/``Integer``/``Rational`` entries.  ``model_value(model, name, *args)`` calls method
``name`` and returns a float array of the method's shape in ``forms.INTERFACE``
(n × n for M, n for H, () for V …); whatever is not real numbers of that shape is refused
in one line (``UserCodeError`` naming the class, the method, the entry and the value): a complex
number, text, None, an expression with symbols left in it, a ragged or wrongly shaped array.

Everything that evaluates a model numerically — the interface's derived methods, the checks'
closed forms (``pendverify.checks.closed_forms``), the diagnosis's traps, the load-time check of
a plug-in (``pendverify.analytic.plugin.check_model_outputs``) — calls the model here, so all of
them see the same arrays.

Non-finite values are the caller's to judge: at a state the checks visit, a NaN or an infinity
where the robot's quantity is finite is a wrong model there (its check fails at that state, as
the stress catalogue's planted NaN shows).  At the zero state, where a model is first evaluated
(``check_model_outputs``), a NaN is refused, and an infinity or an OverflowError is refused as
the parameters leaving double's range (``parameters_overflow``).
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from pendverify.analytic.forms import INTERFACE
from pendverify.analytic.source_file import where
from pendverify.display import shortened
from pendverify.errors import ParameterError, PendverifyError, UserCodeError


def expected_shape(model, name: str) -> tuple[int, ...]:
    """The shape of method ``name``'s value for ``model`` (``forms.INTERFACE``: n, inputs, disturbances)."""
    sizes = {"n": model.nv, "u": len(model.inputs), "w": len(model.disturbances)}
    return tuple(sizes[d] for d in INTERFACE[name].shape or ())


def _place(model, name: str) -> str:
    cls = type(model)
    return f"{where(cls)}: {cls.__name__}.{name}"


def _entry(index: tuple[int, ...]) -> str:
    return "" if not index else "[" + ",".join(str(i + 1) for i in index) + "]"


def _refuse(model, name: str, problem: str) -> UserCodeError:
    return UserCodeError(_place(model, name), problem)


def _real(x) -> float | None:
    """x as a float when it is a real number (Python's, NumPy's, SymPy's numbers), else None."""
    if isinstance(x, (str, bytes, complex, np.complexfloating)) or x is None:
        return None
    real = isinstance(x, numbers.Real) or (getattr(x, "is_number", False) and getattr(x, "is_real", False))
    if not real:  # SymPy's Float, Integer, π are real numbers; a Symbol, I or zoo is not
        return None
    try:
        return float(x)
    except OverflowError:  # an integer beyond double's range
        return math.copysign(math.inf, x)


def as_floats(model, name: str, value) -> np.ndarray:
    """``value``, returned by ``model``'s method ``name``, as floats of its shape (module docstring)."""
    shape = expected_shape(model, name)
    try:
        array = np.asarray(value)
    except (ValueError, TypeError) as exc:  # ragged nested lists
        raise _refuse(model, name, f"must return numbers of shape {shape}; it returned {exc}") from None
    if array.shape != shape:
        got = shortened(repr(value), 80)
        if array.dtype.kind not in "biuf":
            raise _refuse(model, name, f"must return numbers of shape {shape}; it returned {got}")
        raise _refuse(model, name, f"returned an array of shape {array.shape}; expected {shape} ({got})")
    kind = array.dtype.kind
    if kind in "biuf":
        return array.astype(float)  # a copy: the caller may keep it
    if kind == "c":
        imaginary = np.argwhere(array.imag != 0) if shape else np.argwhere([array.imag != 0])
        index = tuple(int(i) for i in imaginary[0]) if shape and len(imaginary) else ()
        entry = _entry(index) or "its value"
        raise _refuse(model, name, f"{entry} is complex ({complex(array[index])!r}): must be a real number")
    if kind in "SU":  # NumPy made every entry text: find the entries that were
        array = np.asarray(value, dtype=object)
    out = np.empty(shape)
    for index in np.ndindex(*shape):
        x = array[index] if array.dtype.kind == "O" else array[index].item()
        real = _real(x)
        if real is None:
            what = "None" if x is None else f"{type(x).__name__} {shortened(repr(x), 60)}"
            entry = _entry(index) or "its value"
            raise _refuse(model, name, f"{entry} is {what}: must be a real number")
        out[index] = real
    return out


def model_value(model, name: str, *args) -> np.ndarray:
    """Method ``name`` of ``model`` at ``args``, as a float array of its interface shape."""
    return as_floats(model, name, getattr(model, name)(*args))


def first_non_finite(value: np.ndarray) -> tuple[str, float] | None:
    """(the entry, 1-based as ``[i,j]`` or "its value", and the number) of the first NaN or
    infinity in ``value``, or None when every entry is finite."""
    bad = np.argwhere(~np.isfinite(np.reshape(value, np.shape(value) or (1,))))
    if not len(bad):
        return None
    index = tuple(int(i) for i in bad[0]) if np.shape(value) else ()
    return _entry(index) or "its value", float(value[index])


#: a parameter beyond this (or below its inverse) in magnitude squares out of double's range
#: (√1.8e308 ≈ 1.3e154): a product of two such, as m·l² or I·m in any closed form, overflows
EXTREME = 1e150


def parameters_overflow(model, what: str) -> PendverifyError | None:
    """The refusal of a model whose value leaves double's range, or None when no parameter explains it.

    The parameters' size, not the code, is the cause when a parameter is beyond ``EXTREME``
    (or below 1/``EXTREME``): the one furthest from 1 in orders of magnitude is named, with
    ``what`` overflowed.
    """
    values = {k: v for k, v in model.params.as_dict().items() if v != 0 and math.isfinite(v)}
    extreme = {k: v for k, v in values.items() if not 1 / EXTREME <= abs(v) <= EXTREME}
    if not extreme:
        return None
    key = max(extreme, key=lambda k: abs(math.log10(abs(extreme[k]))))
    rule = f"too large or too small: the model's terms built from it overflow double precision ({what})"
    return ParameterError(f"<{model.name} parameters>", key, extreme[key], rule)
