"""What a closed form is made of: its arguments, its Lagrangian data, the functions it may call.

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
