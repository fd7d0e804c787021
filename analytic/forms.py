"""What a closed form is made of: its arguments, its Lagrangian data, the functions it may call.

* ``INTERFACE``: the model interface's methods, one ``InterfaceMethod`` each: its
  arguments, whether a model must write it, may (with an exact default, or derived
  from the others) or does not, how a derived one is derived, and its result's shape;
  every other description of the interface (``ClosedFormModel.hand_written``, the
  checks' applicability, the plug-in loader's checks) is read from it.
* ``ClosedForm``: one method holding a hand-written formula, its arguments from
  q, q̇, u, w, and (for methods beyond the interface) what it equals in terms of the
  Lagrangian quantities M, C, H, D, B, W, e.g. ``"-C*v - H - D*v + B*u + W*w"``;
  ``STANDARD_CLOSED_FORMS`` are the interface's own, in the order the tools report them.
* ``Energies``: T(q, q̇) = ½ q̇ᵀ M q̇, V(q), the Rayleigh function R(q̇) = ½ q̇ᵀ D q̇
  (friction −∂R/∂q̇) and the input power P = (B u + W w)ᵀ q̇, from which
  ``pendverify sympy`` derives M, C, H, D, B, W by Lagrange's equations.
* ``BatteryMotion``: the motion the certification battery simulates, for a model
  that states its own (``pendverify.certify.scenes`` derives one otherwise).
* ``NUMERIC_MATH``: what ``self.math`` is numerically (Python's ``math``); the SymPy
  tools swap in SymPy's functions to read the formulas as expressions, and the
  high-precision judge mpmath's (``math_namespace``).

The model interface that uses them is ``pendverify.analytic.interface.ClosedFormModel``.
"""

from __future__ import annotations

import math
import types
from dataclasses import dataclass
from typing import Any

#: The scalar functions closed forms call through ``self.math``: Python's own, numerically.
#: the functions (and π) a closed form may call through ``self.math``
MATH_NAMES = ("cos", "sin", "tan", "sqrt", "exp", "atan2", "pi")


def math_namespace(module) -> types.SimpleNamespace:
    """A ``self.math`` made of ``module``'s functions of those names (``math``, ``sympy``, ``mpmath``)."""
    return types.SimpleNamespace(**{name: getattr(module, name) for name in MATH_NAMES})


NUMERIC_MATH = math_namespace(math)


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


#: The kinds of interface method (``InterfaceMethod.kind``).
REQUIRED = "required"  # abstract: every model writes it (C or C·q̇: ``coriolis_force`` in a BiasOnlyModel)
DEFAULT = "default"  # optional; the interface's default is exact (no friction, no disturbances)
OPTIONAL = "optional"  # optional, with no default: without it the checks that compare it are not run
DERIVED = "derived"  # optional; derived from the other methods when not written, then not checked alone
TOLERANCE = "tolerance"  # a tolerance scale, derived from M or H when not written
STATES = "states"  # the named states every check visits
COMPOSED = "composed"  # always composed from the others by the interface: a model does not write it


@dataclass(frozen=True)
class InterfaceMethod:
    """One method of the model interface (``pendverify.analytic.interface.ClosedFormModel``).

    ``args`` names its arguments in order from "q", "v", "u", "w" (``""``: none).
    ``kind`` is one of REQUIRED, DEFAULT, OPTIONAL, DERIVED, TOLERANCE, STATES, COMPOSED (above).
    ``derived``: for a method the interface can derive, its name in reports and how it is
    derived, e.g. ``("det M", "from M (LU)")``; ``("", "")`` otherwise.
    ``shape``: its result's shape in the dimensions "n" (coordinates), "u" (inputs) and
    "w" (disturbances); None for the special states (a dict of states).
    ``closed_form``: one of the interface's own closed forms (``STANDARD_CLOSED_FORMS``),
    the methods ``pendverify mutate`` mutates unless a model says otherwise.
    """

    args: str
    kind: str
    derived: tuple[str, str] = ("", "")
    shape: tuple[str, ...] | None = ()
    closed_form: bool = False

    @property
    def equation(self) -> bool:
        """A part of the equations of motion (required, defaulted or derived), not a tolerance,
        the states or a composition of the others."""
        return self.kind in (REQUIRED, DEFAULT, OPTIONAL, DERIVED)


#: The model interface, in its order: each method's arguments, kind and result.
INTERFACE: dict[str, InterfaceMethod] = {
    "mass_matrix": InterfaceMethod("q", REQUIRED, shape=("n", "n"), closed_form=True),
    "coriolis_matrix": InterfaceMethod("qv", REQUIRED, shape=("n", "n"), closed_form=True),
    "coriolis_force": InterfaceMethod("qv", REQUIRED, shape=("n",)),
    "gravity": InterfaceMethod("q", REQUIRED, shape=("n",), closed_form=True),
    "potential_energy": InterfaceMethod("q", OPTIONAL, closed_form=True),
    "damping_matrix": InterfaceMethod("", DEFAULT, shape=("n", "n"), closed_form=True),
    "input_matrix": InterfaceMethod("", DEFAULT, shape=("n", "u"), closed_form=True),
    "disturbance_matrix": InterfaceMethod("", DEFAULT, shape=("n", "w"), closed_form=True),
    "det_mass_matrix": InterfaceMethod("q", DERIVED, ("det M", "from M (LU)"), closed_form=True),
    "inverse_mass_matrix": InterfaceMethod(
        "q", DERIVED, ("M⁻¹", "from M (solving with M)"), shape=("n", "n"), closed_form=True
    ),
    "acceleration": InterfaceMethod(
        "qvuw", DERIVED, ("q̈", "from M, C, H, D, B, W (M⁻¹(B u + W w − D q̇ − C q̇ − H))"), shape=("n",)
    ),
    "gravity_scale": InterfaceMethod("", TOLERANCE, ("the gravity scale", "from H (Σ|terms|)"), shape=("n",)),
    "diagonal_scale": InterfaceMethod(
        "q", TOLERANCE, ("the inertia scale", "from M (Σ|terms| of M_ii)"), shape=("n",)
    ),
    "special_states": InterfaceMethod(
        "", STATES, ("the special states", "(the zero state only)"), shape=None
    ),
    "bias": InterfaceMethod("qv", COMPOSED, ("the bias C·q̇ + H", "from C (or C·q̇) and H"), shape=("n",)),
    "kinetic_energy": InterfaceMethod("qv", COMPOSED, ("T", "from M (½ q̇ᵀ M q̇)")),
}


def entry_position(method: str, shape: tuple[int, int], index: int) -> tuple[int, ...]:
    """The zero-based position of flat entry ``index`` of ``method``'s value, a matrix of ``shape``.

    (row,) for a vector, (row, column) for a matrix.  Which it is, the interface says, not the
    value's shape: with one coordinate M is a 1×1 matrix and H a one-entry vector, both one column.
    A model's own closed form outside the interface is a vector when it has one column.
    """
    cols = shape[1]
    interface = INTERFACE.get(method)
    vector = len(interface.shape) == 1 if interface is not None and interface.shape else cols == 1
    r, c = divmod(index, cols)
    return (r,) if vector else (r, c)


#: The interface's own closed forms, in the order the tools report them.
STANDARD_CLOSED_FORMS: dict[str, ClosedForm] = {
    name: ClosedForm(method.args) for name, method in INTERFACE.items() if method.closed_form
}


@dataclass(frozen=True)
class BatteryMotion:
    """The motion the certification battery simulates, when a model states its own.

    ``q`` and ``v``: the initial state (model coordinates); ``input_amplitude`` and
    ``input_frequency`` (Hz): the sine on the inputs; ``disturbance_std`` and
    ``disturbance_bandwidth`` (Hz): the seeded noise on the disturbances;
    ``damping_floor``: when > 0, the damping run uses diag(max(D_ii, floor)) rather than D.
    A model that states none gets one derived from its scales (``pendverify.certify.scenes``).
    """

    q: tuple[float, ...]
    v: tuple[float, ...]
    input_amplitude: tuple[float, ...] = ()
    input_frequency: float = 0.5
    disturbance_std: tuple[float, ...] = ()
    disturbance_bandwidth: float = 4.0
    damping_floor: float = 0.0
