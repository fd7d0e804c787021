"""Fixed-base actuated double pendulum: the double-pendulum reference system.

Conventions
-----------
* Vertical plane, gravity g pointing down.  θ1 is the angle of link 1 measured
  from the horizontal, positive towards "up" (θ1 = π/2: link 1 points straight
  up); θ2 is the angle of link 2 *relative to link 1* (θ2 = 0: links aligned).
* Link i has mass m_i [kg]; its centre of mass lies on the line from joint i to
  joint i+1 at distance r_i [m] from joint i; I_i [kg·m²] is its rotational
  inertia about that centre of mass.  l1 [m] is the joint-1-to-joint-2 distance;
  l2 [m] is the length of link 2 (it only shapes the drawing).
* b1, b2 [N·m·s/rad] are viscous joint frictions; u = (τ1, τ2) [N·m] are joint
  torques.  State x = (θ1, θ2, θ̇1, θ̇2).

Equations (the derivation's, verbatim)::

    M(q) = [ α + 2β cos θ2    δ + β cos θ2 ]
           [ δ + β cos θ2     δ            ]

    C(q, q̇) = [ −β sin θ2 θ̇2 + b1    −β sin θ2 (θ̇1 + θ̇2) ]
              [  β sin θ2 θ̇1          b2                 ]

    H(q) = [ m1 g r1 cos θ1 + m2 g (l1 cos θ1 + r2 cos(θ1 + θ2)) ]
           [ m2 g r2 cos(θ1 + θ2)                              ]

    M q̈ + C q̇ + H = u,       ẋ = f(x) + g(x) u,
    f(x) = [ θ̇ ;  −M⁻¹ (C q̇ + H) ],   g(x) = [ 0 ; M⁻¹ ].

The derivation takes its constants from an appendix not at hand.  They are taken as
α = I1 + I2 + m1 r1² + m2 (l1² + r2²),  β = m2 l1 r2,  δ = I2 + m2 r2²
(inertias about the centres of mass, parallel-axis terms written out).  The
derivation's C carries the friction on its diagonal; ``coriolis_matrix`` returns it
without, ``seed_coriolis_matrix`` with.  V(q) = g (m1 r1 + m2 l1) sin θ1 +
g m2 r2 sin(θ1 + θ2), so H = ∂V/∂q.

Lagrangian (for ``pendverify sympy``): the centres of mass sit at
c1 = r1 (cos θ1, sin θ1) and c2 = l1 (cos θ1, sin θ1) + r2 (cos(θ1+θ2), sin(θ1+θ2)), so

    T = ½ m1 |ċ1|² + ½ I1 θ̇1² + ½ m2 |ċ2|² + ½ I2 (θ̇1 + θ̇2)²,
    V = g (m1 c1,y + m2 c2,y),   R = ½ (b1 θ̇1² + b2 θ̇2²),   P = τ1 θ̇1 + τ2 θ̇2.
"""

from __future__ import annotations

import dataclasses
import math
from typing import ClassVar

import numpy as np

from pendverify.analytic.forms import STANDARD_CLOSED_FORMS, BatteryMotion, ClosedForm, Energies
from pendverify.analytic.interface import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity
from pendverify.errors import ParameterError


@dataclasses.dataclass(frozen=True)
class DoublePendulumParams(ParameterSet):
    """Parameters of the fixed-base double pendulum, SI units."""

    model = "double_pendulum"

    m1: float = quantity("mass", "mass of link 1 in [kg]")
    m2: float = quantity("mass", "mass of link 2 in [kg]")
    l1: float = quantity("length", "distance joint 1 to joint 2 in [m]")
    l2: float = quantity("length", "length of link 2, for drawing only, in [m]")
    r1: float = quantity("offset", "distance joint 1 to the centre of mass of link 1 in [m]")
    r2: float = quantity("offset", "distance joint 2 to the centre of mass of link 2 in [m]")
    I1: float = quantity("inertia", "inertia of link 1 about its centre of mass in [kg·m²]")
    I2: float = quantity("inertia", "inertia of link 2 about its centre of mass in [kg·m²]")
    b1: float = quantity("damping", "viscous friction of joint 1 in [N·m·s/rad]")
    b2: float = quantity("damping", "viscous friction of joint 2 in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")

    def __post_init__(self) -> None:
        super().__post_init__()
        # det M = I2 (I1 + m1 r1² + m2 l1²) + m2 r2² (I1 + m1 r1²) ≥ det M(θ) for all θ
        if (
            self.I2 * (self.I1 + self.m1 * self.r1**2 + self.m2 * self.l1**2)
            + self.m2 * self.r2**2 * (self.I1 + self.m1 * self.r1**2)
            <= 0
        ):
            raise ParameterError(
                f"<{self.model} parameters>",
                "I2" if self.I2 == 0 and self.r2 == 0 else "I1",
                0.0,
                "M(θ) is singular: link 2 needs inertia about joint 2 (I2 > 0 or r2 > 0), "
                "and with I2 = 0 link 1 needs some too (I1 > 0 or r1 > 0)",
            )


class DoublePendulum(ClosedFormModel):
    name = "double_pendulum"
    params_type = DoublePendulumParams
    coordinates = ("theta1", "theta2")
    angular = (True, True)
    inputs = ("tau1", "tau2")
    battery_motion = BatteryMotion(
        q=(0.4, 1.1), v=(0.5, -0.5), input_amplitude=(1.0, 0.4), input_frequency=0.7, damping_floor=0.05
    )
    # The derivation writes C with the friction on its diagonal: that is the formula to mutate.
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **{k: f for k, f in STANDARD_CLOSED_FORMS.items() if k != "coriolis_matrix"},
        "seed_coriolis_matrix": ClosedForm("qv", "C + D"),
    }

    #: the map, the offsets and the parameters are read off the URDF
    #: (``pendverify.analytic.reference_geometry``)
    geometry_reader = "double_pendulum"
    erd_urdf_folder = "double_pendulum_description/urdf"

    def derived_constants(self) -> dict[str, float]:
        """α, β, δ of the derivation."""
        return {"alpha": self.alpha, "beta": self.beta, "delta": self.delta}

    # --- the appendix constants ------------------------------------------------------
    @property
    def alpha(self) -> float:
        p = self.params
        return p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)

    @property
    def beta(self) -> float:
        p = self.params
        return p.m2 * p.l1 * p.r2

    @property
    def delta(self) -> float:
        p = self.params
        return p.I2 + p.m2 * p.r2**2

    # --- the derivation's matrices -----------------------------------------------------------
    def mass_matrix(self, q):
        a, b, d = self.alpha, self.beta, self.delta
        c2 = self.math.cos(q[1])
        return np.array([[a + 2 * b * c2, d + b * c2], [d + b * c2, d]])

    def seed_coriolis_matrix(self, q, v):
        """C exactly as the derivation prints it: friction b1, b2 on the diagonal."""
        b, p = self.beta, self.params
        s2 = self.math.sin(q[1])
        return np.array(
            [
                [-b * s2 * v[1] + p.b1, -b * s2 * (v[0] + v[1])],
                [b * s2 * v[0], p.b2],
            ]
        )

    def coriolis_matrix(self, q, v):
        # the derivation's own C, less its friction; the checks' scales include |D| for this subtraction
        return self.seed_coriolis_matrix(q, v) - self.damping_matrix()

    def gravity(self, q):
        p = self.params
        c1, c12 = self.math.cos(q[0]), self.math.cos(q[0] + q[1])
        return np.array(
            [
                p.m1 * p.g * p.r1 * c1 + p.m2 * p.g * (p.l1 * c1 + p.r2 * c12),
                p.m2 * p.g * p.r2 * c12,
            ]
        )

    def gravity_scale(self):
        p = self.params
        return p.g * np.array([p.m1 * p.r1 + p.m2 * (p.l1 + p.r2), p.m2 * p.r2])

    def potential_energy(self, q):
        p = self.params
        return p.g * (
            (p.m1 * p.r1 + p.m2 * p.l1) * self.math.sin(q[0]) + p.m2 * p.r2 * self.math.sin(q[0] + q[1])
        )

    def damping_matrix(self):
        return np.diag([self.params.b1, self.params.b2])

    def input_matrix(self):
        return np.eye(2)

    def det_mass_matrix(self, q):
        a, b, d = self.alpha, self.beta, self.delta
        return a * d - d * d - (b * self.math.cos(q[1])) ** 2

    def inverse_mass_matrix(self, q):
        a, b, d = self.alpha, self.beta, self.delta
        c2 = self.math.cos(q[1])
        adj = np.array([[d, -(d + b * c2)], [-(d + b * c2), a + 2 * b * c2]])
        return adj / self.det_mass_matrix(q)

    # --- the control-affine form -----------------------------------------------------
    def drift(self, x):
        """f(x) of ẋ = f(x) + g(x)·u, with x = (θ1, θ2, θ̇1, θ̇2)."""
        q, v = x[:2], x[2:]
        rhs = self.seed_coriolis_matrix(q, v) @ v + self.gravity(q)
        return np.concatenate([v, -self.inverse_mass_matrix(q) @ rhs])

    def input_gain(self, x):
        """g(x) of ẋ = f(x) + g(x)·u: zeros over M⁻¹."""
        return np.vstack([np.zeros((2, 2)), self.inverse_mass_matrix(x[:2])])

    def acceleration(self, q, v, u, w):
        x = np.concatenate([q, v])
        return (self.drift(x) + self.input_gain(x) @ u)[2:]

    def diagonal_scale(self, q):
        # M11 = α + 2β cos θ2 can cancel; scale by its terms' magnitudes.
        return np.array([self.alpha + 2 * abs(self.beta), self.delta])

    def energies(self, q, v, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin
        omega1, omega12 = v[0], v[0] + v[1]  # absolute angular rates of the links
        c1_dot = (-p.r1 * sin(q[0]) * omega1, p.r1 * cos(q[0]) * omega1)
        c2_dot = (
            -p.l1 * sin(q[0]) * omega1 - p.r2 * sin(q[0] + q[1]) * omega12,
            p.l1 * cos(q[0]) * omega1 + p.r2 * cos(q[0] + q[1]) * omega12,
        )
        kinetic = (
            p.m1 * (c1_dot[0] ** 2 + c1_dot[1] ** 2) / 2
            + p.I1 * omega1**2 / 2
            + p.m2 * (c2_dot[0] ** 2 + c2_dot[1] ** 2) / 2
            + p.I2 * omega12**2 / 2
        )
        height1, height2 = p.r1 * sin(q[0]), p.l1 * sin(q[0]) + p.r2 * sin(q[0] + q[1])
        return Energies(
            kinetic=kinetic,
            potential=p.g * (p.m1 * height1 + p.m2 * height2),
            dissipation=(p.b1 * v[0] ** 2 + p.b2 * v[1] ** 2) / 2,
            power=u[0] * v[0] + u[1] * v[1],
        )

    def special_states(self):
        half_pi = math.pi / 2
        return {
            "zero": np.array([0.0, 0.0]),
            "upright": np.array([half_pi, 0.0]),
            "hanging": np.array([-half_pi, 0.0]),
            "folded": np.array([half_pi, math.pi]),
            "theta1=theta2": np.array([0.7, 0.7]),
        }
