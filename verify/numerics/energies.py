"""The invariants' energies on the fast path: the model's generated functions on all steps at once.

``pendverify.simulation.invariants`` reads E, M q̇ and T at every accepted step (and at
2n displaced copies of each for ∇E).  Evaluated state by state in Python that costs
≈ 0.1 ms a step, more than the compiled run itself; here

* E = ½ q̇ᵀ M q̇ + V: the generated ``energy``, generic over the number type, run once on
  NumPy arrays holding every row (``pendverify.numerics.codegen.generic``);
* M q̇: the generated ``_to_momentum`` (compiled), row by row;
* T = ½ q̇ᵀ (M q̇).

They are the model's own closed forms (M from ``mass_matrix``, V from ``potential_energy``,
read by SymPy), as the fast path's right-hand side is: the invariants then judge the
closed form's own consistency (C with M, H with ∇V).  A model whose energy the generic
functions cannot take (``ENERGY_ERROR``: V unreadable, a function beyond sin and cos)
falls back to the per-state view of its ``Dynamics``.
"""

from __future__ import annotations

import numpy as np

from pendverify.simulation.invariants import TrajectoryEnergies


def _float_sincos(u):
    return np.sin(u), np.cos(u)


class GeneratedEnergies(TrajectoryEnergies):
    """E, M q̇ and T of a ``GeneratedSystem``'s model, vectorised over the rows."""

    def __init__(self, dyn, system):
        super().__init__(dyn)
        self.system = system
        self._numbers = system.float_numbers()
        self._P = system.packed()

    @classmethod
    def of(cls, dyn, system) -> TrajectoryEnergies:
        """The vectorised view, or the per-state one when the generated energy is not there."""
        return TrajectoryEnergies(dyn) if system.module.ENERGY_ERROR else cls(dyn, system)

    def energy(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        columns = [*np.asarray(Q, float).T, *np.asarray(V, float).T]
        value = self.system.module.energy(self._numbers, columns, float, _float_sincos)
        return np.broadcast_to(np.asarray(value, float), Q.shape[:1]).copy()

    def momentum(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        X = np.ascontiguousarray(np.concatenate([Q, V], axis=1), dtype=float)
        out = np.empty_like(X)
        to_momentum = self.system.module._to_momentum
        for x, y in zip(X, out, strict=True):
            to_momentum(self._P, x, y)
        return out[:, self.nv :]

    def kinetic(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        return 0.5 * np.sum(np.asarray(V, float) * self.momentum(Q, V), axis=1)
