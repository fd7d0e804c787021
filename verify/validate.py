"""Guards for numerical input: no NaN or infinity is ever passed on silently.

Pinocchio does not check its input: ``aba`` with a NaN angle returns NaN
accelerations, and with an infinite one it returns NaN or garbage, without an
exception.  Parameters are already guarded where they are built
(``pendverify.analytic.params``: masses and lengths finite and > 0, the rest
finite and ≥ 0); these functions guard the *states* (q, q̇, u, w) that reach
the closed forms and Pinocchio.

Every rejection is an ``InputError`` naming the source, the key, the value and
the rule, e.g. ``<state>: key 'q[1]' = nan: a state entry must be a finite number``.
"""

from __future__ import annotations

import numpy as np

from pendverify.errors import InputError

STATE_SOURCE = "<state>"


def finite_state(key: str, value, size: int | None = None, source: str = STATE_SOURCE) -> np.ndarray:
    """``value`` as a 1-D float array of finite numbers (of length ``size`` if given).

    Raises ``InputError`` naming the first offending entry as ``key[i]``.
    """
    if isinstance(value, (str, bytes)):
        raise InputError(source, key, value, f"must be a vector of numbers; got a {type(value).__name__}")
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(source, key, value, "must be a vector of numbers") from None
    if array.ndim == 0:
        array = array.reshape(1)
    if array.ndim != 1:
        raise InputError(source, key, value, f"must be a vector; got an array of shape {array.shape}")
    if size is not None and array.size != size:
        raise InputError(source, key, array.tolist(), f"must have {size} entries; got {array.size}")
    bad = np.flatnonzero(~np.isfinite(array))
    if bad.size:
        i = int(bad[0])
        raise InputError(source, f"{key}[{i}]", float(array[i]), "a state entry must be a finite number")
    return array


def model_state(model, q, v=None, u=None, w=None, source: str = STATE_SOURCE):
    """(q, q̇, u, w) checked against a closed-form model's sizes; missing parts are zeros."""
    q = finite_state("q", q, model.nv, source)
    v = np.zeros(model.nv) if v is None else finite_state("v", v, model.nv, source)
    nu, nw = len(model.inputs), len(model.disturbances)
    u = np.zeros(nu) if u is None else finite_state("u", u, nu, source)
    w = np.zeros(nw) if w is None else finite_state("w", w, nw, source)
    return q, v, u, w


def model_states(model, states, source_of) -> None:
    """``model_state`` for every state (objects with ``q``, ``v``, ``u``, ``w``); nothing returned.

    States that are already float vectors of the model's sizes are checked all at once;
    otherwise, or if any entry is not finite, each state is checked in turn, so the first
    bad one raises its own ``InputError`` (``source_of(state)`` names its source).
    """
    sizes = (model.nv, model.nv, len(model.inputs), len(model.disturbances))
    parts = [[getattr(s, key) for s in states] for key in "qvuw"]
    if all(
        all(type(x) is np.ndarray and x.dtype == np.float64 and x.shape == (n,) for x in column)
        for column, n in zip(parts, sizes, strict=True)
    ) and all(np.isfinite(np.array(column)).all() for column in parts if column):
        return
    for s in states:
        model_state(model, s.q, s.v, s.u, s.w, source=source_of(s))
