"""The one interface every closed-form model offers.

A model describes

    M(q) q̈ + C(q, q̇) q̇ + D q̇ + H(q) = B u + W w

in *its own* coordinates q (whatever the hand derivation used: absolute or
relative angles, any zero).  Pinocchio's joint coordinates are reached through a
``CoordinateMap`` (``pendverify.coordinates``); nothing here knows about them.

``C`` is the Coriolis/centrifugal matrix without friction, ``D`` the viscous
friction matrix, ``H`` the gravity vector, ``B`` the input map and ``W`` the
disturbance map.  ``acceleration`` must be the model's *own* closed form (the
seed's f + g·u, or M⁻¹·f), not a re-assembly from the other methods, so that a
typo in any single place shows up in some check.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import ClassVar

import numpy as np

from pendverify.analytic.params import ParameterSet


class ClosedFormModel(ABC):
    """Hand-derived equations of motion of one system, for one parameter set."""

    name: ClassVar[str]
    params_type: ClassVar[type[ParameterSet]]
    #: Names of the model's coordinates, in order.
    coordinates: ClassVar[tuple[str, ...]]
    #: Which coordinates are angles (rad); the others are positions (m).
    angular: ClassVar[tuple[bool, ...]]
    #: Names of the inputs u and the disturbances w.
    inputs: ClassVar[tuple[str, ...]] = ()
    disturbances: ClassVar[tuple[str, ...]] = ()

    def __init__(self, params: ParameterSet):
        if not isinstance(params, self.params_type):
            raise TypeError(f"{self.name} needs {self.params_type.__name__}, got {type(params).__name__}")
        self.params = params

    @property
    def nv(self) -> int:
        return len(self.coordinates)

    # --- the equations -------------------------------------------------------------
    @abstractmethod
    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q), symmetric positive definite."""

    @abstractmethod
    def coriolis_matrix(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """C(q, q̇) without friction."""

    @abstractmethod
    def gravity(self, q: np.ndarray) -> np.ndarray:
        """H(q) = ∂V/∂q."""

    @abstractmethod
    def gravity_scale(self) -> np.ndarray:
        """Σ |coefficients| of each H_i: a bound of |H_i(q)| over all q (units of H)."""

    @abstractmethod
    def potential_energy(self, q: np.ndarray) -> float:
        """V(q), up to a constant."""

    @abstractmethod
    def damping_matrix(self) -> np.ndarray:
        """D: the generalized friction force is D·q̇."""

    @abstractmethod
    def input_matrix(self) -> np.ndarray:
        """B (nv × number of inputs)."""

    def disturbance_matrix(self) -> np.ndarray:
        """W (nv × number of disturbances); none by default."""
        return np.zeros((self.nv, len(self.disturbances)))

    @abstractmethod
    def det_mass_matrix(self, q: np.ndarray) -> float:
        """The closed form of det M(q)."""

    @abstractmethod
    def inverse_mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """The closed form of M(q)⁻¹."""

    @abstractmethod
    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray, w: np.ndarray) -> np.ndarray:
        """q̈ from the model's own closed form (f + g·u, or M⁻¹·f)."""

    # --- derived quantities, shared ------------------------------------------------
    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """C(q, q̇)·q̇ + H(q), friction excluded: what Pinocchio's rnea(q, q̇, 0) returns."""
        return self.coriolis_matrix(q, v) @ v + self.gravity(q)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float:
        return 0.5 * float(v @ self.mass_matrix(q) @ v)

    def diagonal_scale(self, q: np.ndarray) -> np.ndarray:
        """Per-coordinate inertia scale S_i ≥ |terms of M_ii| (units of M_ii).

        Tolerances compare quantities in the diagonally scaled coordinates
        z_i = √S_i·q_i, so that a cart in kg and a rod in kg·m² are judged alike.
        Models whose M_ii can cancel override this with the sum of |terms|.
        """
        return np.abs(np.diag(self.mass_matrix(q)))

    @abstractmethod
    def special_states(self) -> dict[str, np.ndarray]:
        """Named configurations every check visits (upright, folded, aligned...)."""
