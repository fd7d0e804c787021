"""The one interface every closed-form model offers.

A model describes

    M(q) q̈ + C(q, q̇) q̇ + D q̇ + H(q) = B u + W w

in *its own* coordinates q (whatever the hand derivation used: absolute or
relative angles, any zero).  Pinocchio's joint coordinates are reached through a
``CoordinateMap`` (``pendverify.robot.coordinates``); nothing here knows about them.

``C`` is the Coriolis/centrifugal matrix without friction, ``D`` the viscous
friction matrix, ``H`` the gravity vector, ``B`` the input map and ``W`` the
disturbance map.

What a model must and may write
-------------------------------
Required (abstract): ``mass_matrix`` M(q), ``coriolis_matrix`` C(q, q̇) (or
``coriolis_force`` C·q̇ in a ``BiasOnlyModel``) and ``gravity`` H(q).  Optional without a
default: ``potential_energy`` V(q); a model that does not write it is checked without it
(the ``energy`` check is not run, and says why; ``sympy`` leaves V out; a simulation's energy
is Pinocchio's, or not recorded).  Optional, with a default: ``damping_matrix`` D (zero),
``input_matrix`` B (required when ``inputs`` are declared), ``disturbance_matrix``
W (zero).  Optional and *derived* when not written: ``det_mass_matrix`` (LU of M),
``inverse_mass_matrix`` (solving with M), ``acceleration`` (M⁻¹(B u + W w − D q̇ −
C q̇ − H)), ``special_states`` (the zero state only), and the tolerance scales
``gravity_scale`` and ``diagonal_scale`` (Σ |terms| of H_i and of M_ii, read by
SymPy from the model's own H and M); ``pendverify.analytic.forms.INTERFACE`` is the
table of these methods.  ``hand_written()`` names the methods a model
writes itself; a derived det M or M⁻¹ is not checked (nothing to check), and a
derived q̈ is checked by ``aba`` as the composition of the parts, with a note.
A hand-written ``acceleration`` must be the model's *own* closed form (as the
reference systems' f + g·u, or M⁻¹·f), not a re-assembly from the other methods, so that a typo in
any single place shows up in some check.

Writing your own model (a plug-in)
----------------------------------
A model file for ``pendverify check --analytic FILE`` defines one subclass of
``ClosedFormModel`` and its parameter set (a frozen dataclass subclassing
``ParameterSet`` whose ``model`` equals the class's ``name``), importing them as
``from pendverify import ClosedFormModel, ParameterSet, quantity``; ``examples/cart_pole.py``
is a complete one, ``examples/minimal_double_pendulum.py`` a minimal one.  Beyond
the abstract methods below it declares:

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
  (``Energies``, ``ClosedForm`` and ``STANDARD_CLOSED_FORMS`` are in ``pendverify.analytic.forms``,
  with ``INTERFACE``, the table of the interface's methods.)

A model that has no matrix C, only the force C(q, q̇)·q̇, subclasses ``BiasOnlyModel``
and writes ``coriolis_force`` instead; the checks that need a matrix C (``coriolis``,
``skew``) are then not run, and the report says so.

Closed forms must call trigonometric functions through ``self.math`` (``self.math.cos``,
``self.math.sin``, ...), not ``math`` or ``numpy``: numerically ``self.math`` *is*
Python's ``math``, and the SymPy tools swap in SymPy's functions and symbols to read
the formulas as expressions.  Build arrays with ``np.array`` (it holds SymPy objects
too) and keep ``__init__`` free of arithmetic on the parameters.  A method may return any
container of real numbers (an object array, nested lists, SymPy's numbers): whatever evaluates
the model numerically reads it through ``pendverify.analytic.numeric_values``, as a float array
of the method's shape, or refuses it in one line.
"""

from __future__ import annotations

import types
from abc import ABCMeta, abstractmethod
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from pendverify.analytic.forms import (
    COMPOSED,
    INTERFACE,
    NUMERIC_MATH,
    STANDARD_CLOSED_FORMS,
    BatteryMotion,
    ClosedForm,
    Energies,
)
from pendverify.analytic.numeric_values import model_value
from pendverify.analytic.parameter_set import ParameterSet
from pendverify.display import REPR_LIMIT, listed, shortened

if TYPE_CHECKING:
    from pendverify.analytic.derived_scales import DerivedScales


def _shape(cls) -> str:
    """ "2 dof (theta1, theta2), 1 input": a model class's coordinates, inputs and disturbances."""
    coordinates = tuple(str(c) for c in getattr(cls, "coordinates", ()) or ())
    parts = [f"{len(coordinates)} dof ({listed(coordinates, 60)})"]
    for what, declared in (
        ("input", getattr(cls, "inputs", ())),
        ("disturbance", getattr(cls, "disturbances", ())),
    ):
        names = tuple(declared or ())
        if names:
            parts.append(f"{len(names)} {what}{'s' if len(names) > 1 else ''}")
    return ", ".join(parts)


class ModelClass(ABCMeta):
    """The type of every closed-form model class: an ABC whose classes show their model's name,
    module and coordinates (``<model class DoublePendulum 'double_pendulum' in ...: 2 dof ...>``)."""

    def __repr__(cls) -> str:
        name = getattr(cls, "name", None)
        if not isinstance(name, str):  # the interface itself, or a class that names no model
            return f"<model interface {cls.__qualname__} in {cls.__module__}>"
        title = f"{shortened(cls.__qualname__, 60)} {shortened(name, 60)!r}"
        return f"<model class {title} in {shortened(cls.__module__, 80)}: {_shape(cls)}>"


class ClosedFormModel(metaclass=ModelClass):
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
    #: The folder of example-robot-data (``pendverify.robot.erd``) whose URDFs belong to this
    #: model's family, checked by default with ``--model`` naming it; "" for none.
    erd_urdf_folder: ClassVar[str] = ""
    #: False for models that give only the force C·q̇ (``BiasOnlyModel``).
    has_coriolis_matrix: ClassVar[bool] = True
    #: False for models that give q̈ alone (``AccelerationOnlyModel``).
    has_mass_matrix: ClassVar[bool] = True
    #: How a model that gives q̈ alone derives M, H and C·q̇ from it at each state ("" when it does
    #: not): then crba, gravity and rnea run on the derived forms, with the derivation's rounding
    #: in their tolerance (``pendverify.analytic.numeric_derivation``); such a model gives
    #: ``derivation_steps(q)``, the input steps its derivation took at q.
    mass_from_acceleration: ClassVar[str] = ""
    #: Why the model's code is evaluated numerically only ("" when SymPy reads it): then no SymPy
    #: reading (``show``, ``sympy``, ``mutate``, generated NumPy) and no high-precision re-judge.
    numeric_only: ClassVar[str] = ""
    #: The parameter set a model file gives with the model (``PARAMS``), used when none is named;
    #: None: the parameters must be named (``--params``, a scene's ``params``).
    default_params: ClassVar[ParameterSet | None] = None
    #: The motion ``pendverify certify`` simulates; None: derived from the model's scales.
    battery_motion: ClassVar[BatteryMotion | None] = None
    #: The model's own names of the quantities where its source names them otherwise than the
    #: interface (quantity as a diagnosis names it → the model's name): ``{"H": "G"}`` for a model
    #: file whose gravity vector is ``G(q, p)``.  A diagnosis names entries by them.
    written_names: ClassVar[dict[str, str]] = {}

    def __init__(self, params: ParameterSet):
        if not isinstance(params, self.params_type):
            raise TypeError(f"{self.name} needs {self.params_type.__name__}, got {type(params).__name__}")
        self.params = params

    @property
    def nv(self) -> int:
        """The number of coordinates (degrees of freedom)."""
        return len(self.coordinates)

    def __repr__(self) -> str:
        head = f"<{shortened(type(self).__qualname__, 60)} {shortened(self.name, 60)!r}: {_shape(type(self))}"
        values = self.params.as_dict() if isinstance(self.params, ParameterSet) else {}
        text = ", ".join(f"{k}={v:.6g}" if isinstance(v, float) else f"{k}={v}" for k, v in values.items())
        return f"{head}; {shortened(text, REPR_LIMIT - len(head) - 3)}>"

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

    def potential_energy(self, q: np.ndarray) -> float:
        """V(q), up to a constant; optional: a model that does not write it gives no V."""
        raise NotImplementedError(f"{self.name} gives no potential energy V(q) (potential_energy)")

    @classmethod
    def has_potential_energy(cls) -> bool:
        """Whether the model writes V(q) (``potential_energy``): the ``energy`` check needs it."""
        return "potential_energy" in cls.hand_written()

    def damping_matrix(self) -> np.ndarray:
        """D: the generalized friction force is D·q̇; none (frictionless) by default."""
        return np.zeros((self.nv, self.nv))

    def input_matrix(self) -> np.ndarray:
        """B (nv × number of inputs); a model that declares ``inputs`` must write it."""
        if self.inputs:
            raise NotImplementedError(f"{self.name} declares inputs {self.inputs} but writes no input_matrix")
        return np.zeros((self.nv, 0))

    def disturbance_matrix(self) -> np.ndarray:
        """W (nv × number of disturbances); none by default."""
        return np.zeros((self.nv, len(self.disturbances)))

    # --- derived by default: a model may write them as closed forms -------------------
    def det_mass_matrix(self, q: np.ndarray) -> float:
        """det M(q).  Derived by default (LU of M); a hand-written closed form is checked (``det``)."""
        return float(np.linalg.det(model_value(self, "mass_matrix", q)))

    def inverse_mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """M(q)⁻¹.  Derived by default (solving with M); a hand-written one is checked (``minverse``)."""
        return np.linalg.solve(model_value(self, "mass_matrix", q), np.eye(self.nv))

    def acceleration(self, q: np.ndarray, v: np.ndarray, u: np.ndarray, w: np.ndarray) -> np.ndarray:
        """q̈.  Derived by default: M⁻¹ (B u + W w − D q̇ − C q̇ − H) from the model's own parts.

        A model with its own closed form (as the reference systems' f + g·u, or M⁻¹·f) writes it
        here, *not* as a re-assembly of the other methods, so that a typo in any
        single place shows up in some check.
        """
        force = (
            model_value(self, "input_matrix") @ np.asarray(u, dtype=float)
            + model_value(self, "disturbance_matrix") @ np.asarray(w, dtype=float)
            - model_value(self, "damping_matrix") @ np.asarray(v, dtype=float)
            - model_value(self, "bias", q, v)
        )
        return np.linalg.solve(model_value(self, "mass_matrix", q), force)

    def gravity_scale(self) -> np.ndarray:
        """Σ |coefficients| of each H_i: a bound of |H_i(q)| over all q (units of H).

        Derived by default from the model's own H, read by SymPy: every H_i expanded
        into terms, each sin/cos bounded by 1 (``pendverify.analytic.derived_scales``).
        """
        return self.derived_scales().gravity()

    # --- derived quantities, shared ------------------------------------------------
    def bias(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """C(q, q̇)·q̇ + H(q), friction excluded: what Pinocchio's rnea(q, q̇, 0) returns."""
        return self.coriolis_matrix(q, v) @ v + self.gravity(q)

    def kinetic_energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """T(q, q̇) = ½ q̇ᵀ M(q) q̇."""
        v = np.asarray(v, dtype=float)
        return 0.5 * float(v @ model_value(self, "mass_matrix", q) @ v)

    def diagonal_scale(self, q: np.ndarray) -> np.ndarray:
        """Per-coordinate inertia scale S_i ≥ |terms of M_ii| (units of M_ii).

        Tolerances compare quantities in the diagonally scaled coordinates
        z_i = √S_i·q_i, so that a cart in kg and a rod in kg·m² are judged alike.
        Derived by default as Σ |terms| of the model's own M_ii, each sin/cos
        bounded by 1 (so an M_ii whose terms cancel, α + 2β cos θ2, is scaled by
        α + 2|β|); |M_ii(q)| if SymPy cannot read M.
        """
        return self.derived_scales().diagonal(q)

    def special_states(self) -> dict[str, np.ndarray]:
        """Named configurations every check visits (upright, folded...); the zero state by default."""
        return {"zero": np.zeros(self.nv)}

    @classmethod
    def how_to_name_joints(cls) -> str:
        """How this model's own file names the URDF joint of each coordinate, for a message to the
        person who wrote it (a class sets ``urdf_joints``; a text model overrides this with its
        ``[urdf]`` table)."""
        return (
            f"set urdf_joints = (...) in class {cls.__name__}, the URDF joint of each coordinate "
            f"({', '.join(cls.coordinates)}) in order, with joint_transform T and joint_offset θ0 when "
            "q = T (θ − θ0) is not the identity"
        )

    @classmethod
    def written_name(cls, quantity: str) -> str:
        """The model's own name of ``quantity`` (``written_names``), else the quantity's."""
        return cls.written_names.get(quantity, quantity)

    # --- which quantities are hand-written --------------------------------------------------
    @classmethod
    def hand_written(cls) -> tuple[str, ...]:
        """The interface methods this model writes itself, in the order of ``forms.INTERFACE``.

        A method counts as hand-written when the class, or a base that is a real
        model, defines it; the interface's own defaults (``ClosedFormModel``,
        ``BiasOnlyModel``) are derived, and the checks do not count them as evidence.
        The compositions (the bias and T) are not listed: a model that writes its own is
        evaluated as written (``own_methods``), but it is no closed form of its own.
        """
        return tuple(name for name in cls.own_methods() if INTERFACE[name].kind != COMPOSED)

    @classmethod
    def own_methods(cls) -> tuple[str, ...]:
        """Every interface method the class, or a base that is a real model, defines, in order."""
        own = []
        for name in INTERFACE:
            owner = next((k for k in cls.__mro__ if name in vars(k)), None)
            if owner is not None and owner not in _INTERFACE_CLASSES:
                own.append(name)
        return tuple(own)

    @classmethod
    def written_closed_forms(cls) -> dict[str, ClosedForm]:
        """``closed_forms`` less the interface's methods this model leaves to their defaults."""
        written = set(cls.hand_written())
        return {k: f for k, f in cls.closed_forms.items() if k not in STANDARD_CLOSED_FORMS or k in written}

    def derived_scales(self) -> DerivedScales:
        """The tolerance scales derived from this model's M and H (``pendverify.analytic.derived_scales``).

        Derived once per instance, or the scales handed over by ``use_derived_scales``.
        """
        scales = self.__dict__.get("_derived_scales_cache")
        if scales is None:
            # deferred on purpose: SymPy (analytic.derived_scales) loads only for a model that leaves
            # a scale to be derived, so `pendverify check` on the built-in models does not import it
            from pendverify.analytic.derived_scales import DerivedScales

            scales = self.__dict__["_derived_scales_cache"] = DerivedScales.of(self)
        return scales

    def use_derived_scales(self, scales: DerivedScales) -> None:
        """Take ``scales`` (another instance's ``derived_scales()``) instead of deriving this model's own.

        A model made from another one, as ``pendverify mutate`` makes each mutant, keeps the
        original's tolerance scales, as it keeps hand-written ones.
        """
        self.__dict__["_derived_scales_cache"] = scales

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
        "coriolis_force": ClosedForm(INTERFACE["coriolis_force"].args, "C*v"),
    }

    @abstractmethod
    def coriolis_force(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """C(q, q̇)·q̇, friction excluded."""

    def coriolis_matrix(self, q, v):
        raise NotImplementedError(f"{self.name} gives only the force C·q̇ (coriolis_force), not a matrix C")

    def bias(self, q, v):
        return self.coriolis_force(q, v) + self.gravity(q)


class AccelerationOnlyModel(ClosedFormModel):
    """A model given only by its accelerations q̈ = f(q, q̇, u, w), with B (and D, W) declared.

    It writes ``acceleration`` and, with inputs, ``input_matrix`` B: the generalised force of
    each input, which Pinocchio's ABA needs (τ = B u + W w − D q̇).  Its inputs do not determine
    M (fewer inputs than coordinates: ∂q̈/∂u = M⁻¹B is not square), so it has no M, C, H or V:
    only ``aba`` (and ``damping``) run, and the report says why the others do not.  The sizes
    of the terms that its tolerance is judged against (the inertia scale, ‖M‖, ‖M⁻¹‖ and the
    gravity scale) are then the URDF's (``pendverify.checks.batch``): the robot the model is
    compared with, whose M the model's q̈ implies if it is right.
    """

    has_mass_matrix: ClassVar[bool] = False
    has_coriolis_matrix: ClassVar[bool] = False
    #: why M, C·q̇, H and V are not there (the checks that need them say it)
    without_mass_matrix: ClassVar[str] = (
        "its inputs do not span the coordinates (∂q̈/∂u = M⁻¹B is not square), "
        "so M, C·q̇, H and V are not determined"
    )
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        "acceleration": ClosedForm(INTERFACE["acceleration"].args, "M**-1*(B*u + W*w - D*v - C*v - H)")
    }

    @abstractmethod
    def acceleration(self, q, v, u, w):
        """q̈(q, q̇, u, w), the model's own closed form."""

    def _none(self, what: str):
        raise NotImplementedError(f"{self.name} gives q̈ alone, no {what}")

    def mass_matrix(self, q):
        self._none("M")

    def coriolis_matrix(self, q, v):
        self._none("C")

    def coriolis_force(self, q, v):
        self._none("C·q̇")

    def gravity(self, q):
        self._none("H")

    def potential_energy(self, q):
        self._none("V")

    def bias(self, q, v):
        self._none("C·q̇ + H")


#: the classes whose methods are the interface's own defaults, not a model's
_INTERFACE_CLASSES = (ClosedFormModel, BiasOnlyModel, AccelerationOnlyModel)
