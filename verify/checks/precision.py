"""The hand-written closed forms evaluated in high precision: a wrong formula, or an unstable one?

A closed form can be right and still lose digits in double precision.  The triple
pendulum's M⁻¹ (``examples/triple_pendulum.py``) is written as adj(M)/det M with
every entry expanded in the diagonal terms a_i and couplings k_ij; with the third
bob 1e6 times heavier, a2·a3 and (k23 cos θ23)² are both O(m3²) while their
difference is O(m3), so six digits cancel: the double evaluation is off by a
relative 2e-11 where Pinocchio's M⁻¹ is good to 1e-13.  Judged as it is, the check
fails; yet the formula is right, and a user told "your M⁻¹ is wrong" would lose a day.

The remedy is to remove the closed form's own rounding and judge again.  Where a
check fails at a state, ``pendverify.checks.judge.rejudge_precisely`` judges it again: the
model's hand-written methods (``hand_written()``: M, C, H, det M, M⁻¹, q̈, …; not the
tolerance scales) are evaluated at that state in ``DIGITS`` significant digits —
the same code, on a second instance of the model class whose parameters are mpmath
numbers and whose ``self.math`` is mpmath's functions, with object arrays of mpmath
numbers as arguments (the parameters and the state convert exactly) — and rounded
to double; derived quantities are formed from those roundings as usual (a batch of
that one state whose closed forms are the model's own code, ``CheckBatch(...,
python_only=True)``).  The state is then judged by the same check, tolerance and scale.

* If every failing state passes so judged, the formulas agree with Pinocchio
  within the check's tolerance and the check is a *warning* (``pendverify.checks.verdict``): its
  double evaluation is not numerically stable at those states, which is worth
  knowing (a controller evaluates it in double) but is not a derivation error.
  ``--strict`` makes it a failure.
* A wrong formula is wrong in any precision: the state still fails, and so does
  the check (a planted error in the same M⁻¹ is caught, ``tests/stress/test_stress_generic.py``).
* A closed form that cannot run on mpmath numbers (it calls ``np.cos`` or
  ``np.linalg`` rather than ``self.math`` and plain arithmetic), or a model evaluated
  numerically only (``ClosedFormModel.numeric_only``: q̈ as Python code), is judged in
  double only; the note says why.

Cost: only failing states are evaluated again, worst first, and the first state
that still fails ends the search, so a real error costs one evaluation (about a
millisecond for three coordinates).
"""

from __future__ import annotations

import copy
import dataclasses

import mpmath
import numpy as np

from pendverify.analytic.forms import math_namespace

DIGITS = 40  # far beyond the 16 of double: the rounded result is the correctly rounded value
#: what ``self.math`` is on the high-precision twin (``mpmath.pi`` evaluates at the working precision)
MP_MATH = math_namespace(mpmath)
#: the finding, in one sentence shared by every report
UNSTABLE = (
    "the closed forms lose digits in double: evaluated in high precision they agree with Pinocchio "
    "within tolerance"
)
#: hand-written methods that are tolerance internals or state lists, not quantities the checks compare
NOT_QUANTITIES = ("gravity_scale", "diagonal_scale", "special_states")


class PrecisionUnavailable(Exception):
    """The model's closed forms cannot be evaluated on mpmath numbers (the message says why)."""


def _to_mp(value):
    if isinstance(value, np.ndarray):
        return np.array([mpmath.mpf(float(x)) for x in value.ravel()], dtype=object).reshape(value.shape)
    if isinstance(value, int | float | np.floating):
        return mpmath.mpf(float(value))
    return value


def _to_double(value):
    if isinstance(value, np.ndarray):
        return np.array([float(x) for x in value.ravel()], dtype=float).reshape(value.shape)
    if isinstance(value, list | tuple):
        return _to_double(np.array(value, dtype=object))
    return float(value)


def _mp_instance(model):
    """A second instance of the model's class, on mpmath parameters and mpmath's functions."""
    params = copy.copy(model.params)
    for f in dataclasses.fields(params):
        value = getattr(params, f.name)
        if isinstance(value, int | float):
            object.__setattr__(params, f.name, mpmath.mpf(float(value)))
    twin = type(model)(params)
    twin.math = MP_MATH
    return twin


def _precise(method, name: str):
    def call(*args):
        with mpmath.workdps(DIGITS):
            try:
                return _to_double(method(*(_to_mp(a) for a in args)))
            except Exception as exc:
                raise PrecisionUnavailable(
                    f"{name} does not run on mpmath numbers ({type(exc).__name__}: {exc}); "
                    "write it with self.math and plain arithmetic to have it judged in high precision"
                ) from None

    return call


def precise_model(model):
    """A copy of ``model`` whose hand-written methods run in ``DIGITS`` digits, rounded to double."""
    if model.numeric_only:  # its code is not ours to run on mpmath numbers: it would round to double
        raise PrecisionUnavailable(f"{model.numeric_only}: judged in double only")
    try:
        with mpmath.workdps(DIGITS):
            twin = _mp_instance(model)
    except Exception as exc:
        raise PrecisionUnavailable(
            f"{type(model).__name__}(params) fails on mpmath parameters ({type(exc).__name__}: {exc})"
        ) from None
    proxy = copy.copy(model)
    for name in type(model).hand_written():
        if name not in NOT_QUANTITIES:
            setattr(proxy, name, _precise(getattr(twin, name), name))
    return proxy
