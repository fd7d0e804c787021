"""Tolerance scales derived from a model's own M and H: Σ |terms|, every sin/cos bounded by 1.

``gravity_scale`` bounds |H_i(q)| over all q and ``diagonal_scale`` is the size of
the terms of M_ii (``pendverify.checks.catalogue``).  A model that does not write
them gets them from its closed forms, read as SymPy expressions
(``pendverify.analytic.symbolic_reading.SymbolicModel``): each entry is expanded with the
parameters as symbols (so that terms that cancel stay separate, m1 r1 cos θ1 −
m2 l1 cos θ1 counts |m1 r1| + |m2 l1|), every sin and cos is replaced by its
bound 1, and the |terms| are summed and evaluated at the parameter values.

The reading is done once per model class; the values once per model instance.
A model SymPy cannot read (a subclass with its own ``__init__``, code that is
not a closed form) falls back to |M_ii(q)| for the diagonal; its gravity scale
must then be written by hand.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.errors import PendverifyError


def term_bound(expr) -> sp.Expr:
    """Σ |terms| of ``expr`` expanded, with every sin and cos replaced by its bound 1."""
    total = sp.S.Zero
    for term in sp.Add.make_args(sp.expand(sp.sympify(expr))):
        bounded = term.replace(lambda e: isinstance(e, sp.sin | sp.cos), lambda e: sp.S.One)
        total += sp.Abs(bounded)
    return total


@dataclass(frozen=True)
class _ClassBounds:
    """The bounds of one model class as functions of (q, parameters); None where SymPy cannot read."""

    parameters: tuple[str, ...]
    diagonal: object  # callable (q, params) -> list, or None
    diagonal_uses_q: bool
    gravity: object  # callable (params) -> list, or None
    gravity_problem: str


@functools.cache
def _class_bounds(cls) -> _ClassBounds:
    try:
        sm = SymbolicModel.of(cls)
    except PendverifyError as exc:
        return _ClassBounds((), None, False, None, str(exc))
    q = list(sm.symbols["q"])
    params = list(sm.parameters.values())
    diagonal, uses_q = None, False
    try:
        M = sm.evaluate("mass_matrix", "q")
        bounds = [term_bound(M[i, i]) for i in range(len(q))]
        uses_q = any(b.has(*q) for b in bounds)
        diagonal = sp.lambdify([q, params], bounds, modules="numpy")
    except PendverifyError:
        pass
    gravity, problem = None, ""
    try:
        H = sm.evaluate("gravity", "q")
        bounds = [term_bound(h) for h in H]
        free = sorted({s.name for b in bounds for s in b.free_symbols if s in set(q)})
        if free:
            problem = (
                f"H depends on {', '.join(free)} beyond sin/cos, so Σ|coefficients| bounds nothing; "
                "write gravity_scale"
            )
        else:
            gravity = sp.lambdify([params], bounds, modules="numpy")
    except PendverifyError as exc:
        problem = str(exc)
    return _ClassBounds(tuple(sm.parameters), diagonal, uses_q, gravity, problem)


@dataclass
class DerivedScales:
    """The derived scales of one model instance (``ClosedFormModel.derived_scales``)."""

    model: object
    bounds: _ClassBounds
    values: list
    _gravity: np.ndarray | None = None
    _diagonal: np.ndarray | None = None

    @classmethod
    def of(cls, model) -> DerivedScales:
        bounds = _class_bounds(type(model))
        values = [float(getattr(model.params, name)) for name in bounds.parameters]
        return cls(model, bounds, values)

    def gravity(self) -> np.ndarray:
        if self._gravity is None:
            if self.bounds.gravity is None:
                name = type(self.model).__name__
                raise PendverifyError(
                    f"{name}: gravity_scale cannot be derived: {self.bounds.gravity_problem}"
                )
            self._gravity = np.asarray(self.bounds.gravity(self.values), dtype=float).reshape(-1)
        return self._gravity

    def diagonal(self, q) -> np.ndarray:
        """S at configuration q (n,)."""
        return self.diagonal_at(np.asarray(q, dtype=float)[None])[0]

    def diagonal_at(self, Q) -> np.ndarray:
        """S at each configuration of Q (N, n), as (N, n): the bounds evaluated on arrays at once."""
        Q = np.asarray(Q, dtype=float)
        if self.bounds.diagonal is None:
            return np.array([np.abs(np.diag(np.asarray(self.model.mass_matrix(q), dtype=float))) for q in Q])
        if self._diagonal is None or self.bounds.diagonal_uses_q:
            at = list(Q.T) if self.bounds.diagonal_uses_q else [0.0] * self.model.nv
            entries = self.bounds.diagonal(at, self.values)
            S = np.stack([np.broadcast_to(np.asarray(e, dtype=float), (len(Q),)) for e in entries], axis=-1)
            if self.bounds.diagonal_uses_q:
                return S
            self._diagonal = S[0]
        return np.broadcast_to(self._diagonal, Q.shape).copy()
