"""The one interface every closed-form model offers.

A model describes

    M(q) q̈ + C(q, q̇) q̇ + D q̇ + H(q) = B u + W w

in *its own* coordinates q (whatever the hand derivation used: absolute or
relative angles, any zero).  Pinocchio's joint coordinates are reached through a
``CoordinateMap`` (``pendverify.robot.coordinates``); nothing here knows about them.

``C`` is the Coriolis/centrifugal matrix without friction, ``D`` the viscous
friction matrix, ``H`` the gravity vector, ``B`` the input map and ``W`` the
disturbance map.  ``acceleration`` must be the model's *own* closed form (the
seed's f + g·u, or M⁻¹·f), not a re-assembly from the other methods, so that a
typo in any single place shows up in some check.

Writing your own model (a plug-in)
----------------------------------
A model file for ``pendverify check --analytic FILE`` defines one subclass of
``ClosedFormModel`` and its parameter set (a frozen dataclass subclassing
``ParameterSet`` whose ``model`` equals the class's ``name``); ``examples/cart_pole.py``
is a complete one.  Beyond the abstract methods below it declares:

* ``urdf_joints``, ``joint_transform``, ``joint_offset``: the coordinate map
  q = T (θ − θ0) to the URDF's joints (``pendverify.robot.coordinates``), given
  explicitly — a plug-in's map is never guessed from the URDF's geometry.  Row k of
  T belongs to joint ``urdf_joints[k]``; T defaults to the identity, θ0 to zero.
  The built-in models name a registered reader in ``geometry_reader`` instead,
  which reads the map (and their parameters) off the URDF's geometry.
* optionally ``energies``: kinetic and potential energy, Rayleigh dissipation and
  input power, for ``pendverify sympy``, which derives M, C, H, D, B, W from them
  (Lagrange) and compares them with the closed forms term by term.
* optionally ``closed_forms``: which methods hold hand-written formulas (the ones
  ``pendverify mutate`` mutates); extra methods name what they equal in terms of
  the Lagrangian quantities, e.g. ``ClosedForm("qvuw", "-C*v - H - D*v + B*u + W*w")``.

A model that has no matrix C, only the force C(q, q̇)·q̇, subclasses ``BiasOnlyModel``
and writes ``coriolis_force`` instead; the checks that need a matrix C (``coriolis``,
``skew``) are then not run, and the report says so.

Closed forms must call trigonometric functions through ``self.math`` (``self.math.cos``,
``self.math.sin``, ...), not ``math`` or ``numpy``: numerically ``self.math`` *is*
Python's ``math``, and the SymPy tools swap in SymPy's functions and symbols to read
the formulas as expressions.  Build arrays with ``np.array`` (it holds SymPy objects
too) and keep ``__init__`` free of arithmetic on the parameters.
"""

from __future__ import annotations

import math
import types
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from pendverify.analytic.params import ParameterSet

#: The scalar functions closed forms call through ``self.math``: Python's own, numerically.
NUMERIC_MATH = types.SimpleNamespace(
    cos=math.cos, sin=math.sin, tan=math.tan, sqrt=math.sqrt, exp=math.exp, atan2=math.atan2, pi=math.pi
)


@dataclass(frozen=True)
class Energies:
    """The Lagrangian data of a model, as SymPy expressions in (q, q̇, u, w).

    ``kinetic`` T(q, q̇) = ½ q̇ᵀ M q̇; ``potential`` V(q); ``dissipation`` the Rayleigh
    function R(q̇) = ½ q̇ᵀ D q̇ (the friction force is −∂R/∂q̇); ``power`` the power of
    the inputs and disturbances, P = (B u + W w)ᵀ q̇.
    """

    kinetic: Any
    potential: Any
    dissipation: Any = 0
    power: Any = 0


@dataclass(frozen=True)
class ClosedForm:
    """One method that holds a hand-written formula.

    ``args`` names its arguments in order from "q", "v", "u", "w" (``""``: none).
    ``equals`` is empty for the methods of the interface; for any other method it
    says what the method equals in terms of the Lagrangian quantities M, C, H, D, B,
    W and the column vectors q, v, u, w, e.g. ``"-C*v - H - D*v + B*u + W*w"``.
    """

    args: str
    equals: str = ""


#: The interface's own closed forms, in the order the tools report them.
STANDARD_CLOSED_FORMS: dict[str, ClosedForm] = {
    "mass_matrix": ClosedForm("q"),
    "coriolis_matrix": ClosedForm("qv"),
    "gravity": ClosedForm("q"),
    "potential_energy": ClosedForm("q"),
    "damping_matrix": ClosedForm(""),
    "input_matrix": ClosedForm(""),
    "disturbance_matrix": ClosedForm(""),
    "det_mass_matrix": ClosedForm("q"),
    "inverse_mass_matrix": ClosedForm("q"),
}


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
    #: The scalar functions the closed forms call (see the module docstring).
    math: ClassVar[types.SimpleNamespace] = NUMERIC_MATH
    #: The methods holding hand-written formulas, mutated by ``pendverify mutate``.
    closed_forms: ClassVar[dict[str, ClosedForm]] = STANDARD_CLOSED_FORMS
    #: A plug-in's coordinate map q = T (θ − θ0): the URDF joint of each row of T,
    #: T itself (default identity) and θ0 (default zero), in the model's coordinates.
    urdf_joints: ClassVar[tuple[str, ...]] = ()
    joint_transform: ClassVar[Any] = None
    joint_offset: ClassVar[Any] = None
    #: The registered reader that reads the map (and parameters) off a URDF's geometry
    #: (``pendverify.robot.geometry``); "" for a model that declares its map instead.
    geometry_reader: ClassVar[str] = ""
    #: False for models that give only the force C·q̇ (``BiasOnlyModel``).
    has_coriolis_matrix: ClassVar[bool] = True

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

    # --- optional hooks ------------------------------------------------------------------
    def derived_constants(self) -> dict[str, float]:
        """Named constants the closed forms are built from (recorded in certificates); none by default."""
        return {}

    def energies(self, q, v, u, w) -> Energies | None:
        """T, V, R and the input power, for the SymPy derivation; None if not given.

        Called only with SymPy symbols (``self.math`` is SymPy's then).
        """
        return None


class BiasOnlyModel(ClosedFormModel):
    """A closed-form model that gives the Coriolis/centrifugal force C(q, q̇)·q̇, not a matrix C.

    It writes ``coriolis_force`` (friction excluded); ``bias`` uses it.  Only C·q̇
    is then verified: the ``coriolis`` and ``skew`` checks, which need the matrix,
    are not run.
    """

    has_coriolis_matrix: ClassVar[bool] = False
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **{k: f for k, f in STANDARD_CLOSED_FORMS.items() if k != "coriolis_matrix"},
        "coriolis_force": ClosedForm("qv", "C*v"),
    }

    @abstractmethod
    def coriolis_force(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """C(q, q̇)·q̇, friction excluded."""

    def coriolis_matrix(self, q, v):
        raise NotImplementedError(f"{self.name} gives only the force C·q̇ (coriolis_force), not a matrix C")

    def bias(self, q, v):
        return self.coriolis_force(q, v) + self.gravity(q)
