"""The least a hand derivation has to give: M, C, H, V, D, B of a double pendulum.

Verify it against the reference double pendulum's URDF::

    pendverify check --analytic examples/minimal_double_pendulum.py \\
        --urdf urdf/double_pendulum.urdf --params examples/minimal_double_pendulum.toml
    pendverify sympy --analytic examples/minimal_double_pendulum.py
    pendverify mutate --analytic examples/minimal_double_pendulum.py \\
        --urdf urdf/double_pendulum.urdf --params examples/minimal_double_pendulum.toml

The formulas are the reference double pendulum's (``pendverify.analytic.double_pendulum``):
θ1 from the horizontal, θ2 relative to link 1, the URDF's own joint angles, so the
coordinate map is the identity.  Only M, C, H, V, D and B are written (and the
energies, for ``pendverify sympy``).  Everything else is derived by the interface:
det M (LU of M), M⁻¹ (solving with M), q̈ = M⁻¹(B u − D q̇ − C q̇ − H), the special
states (the zero state) and the tolerance scales (Σ|terms| of H_i and of M_ii).
The ``det`` and ``minverse`` checks are therefore not run (nothing hand-written to
check), ``aba`` checks the composition of the parts, and the report says so.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from pendverify import ClosedFormModel, Energies, ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class MinimalDoublePendulumParams(ParameterSet):
    """Parameters, SI units (those of the reference double pendulum)."""

    model = "minimal_double_pendulum"

    m1: float = quantity("mass", "mass of link 1 in [kg]")
    m2: float = quantity("mass", "mass of link 2 in [kg]")
    l1: float = quantity("length", "distance joint 1 to joint 2 in [m]")
    r1: float = quantity("offset", "distance joint 1 to the centre of mass of link 1 in [m]")
    r2: float = quantity("offset", "distance joint 2 to the centre of mass of link 2 in [m]")
    I1: float = quantity("inertia", "inertia of link 1 about its centre of mass in [kg·m²]")
    I2: float = quantity("inertia", "inertia of link 2 about its centre of mass in [kg·m²]")
    b1: float = quantity("damping", "viscous friction of joint 1 in [N·m·s/rad]")
    b2: float = quantity("damping", "viscous friction of joint 2 in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class MinimalDoublePendulum(ClosedFormModel):
    name = "minimal_double_pendulum"
    params_type = MinimalDoublePendulumParams
    coordinates = ("theta1", "theta2")
    angular = (True, True)
    inputs = ("tau1", "tau2")

    # θ are the URDF's joint angles: T = I, θ0 = 0 (the defaults)
    urdf_joints = ("joint1", "joint2")

    def mass_matrix(self, q):
        p = self.params
        alpha = p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
        beta, delta = p.m2 * p.l1 * p.r2, p.I2 + p.m2 * p.r2**2
        c2 = self.math.cos(q[1])
        return np.array([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])

    def coriolis_matrix(self, q, v):
        h = self.params.m2 * self.params.l1 * self.params.r2 * self.math.sin(q[1])
        return np.array([[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]])

    def gravity(self, q):
        p = self.params
        c1, c12 = self.math.cos(q[0]), self.math.cos(q[0] + q[1])
        return p.g * np.array([(p.m1 * p.r1 + p.m2 * p.l1) * c1 + p.m2 * p.r2 * c12, p.m2 * p.r2 * c12])

    def potential_energy(self, q):
        p = self.params
        s1, s12 = self.math.sin(q[0]), self.math.sin(q[0] + q[1])
        return p.g * ((p.m1 * p.r1 + p.m2 * p.l1) * s1 + p.m2 * p.r2 * s12)

    def damping_matrix(self):
        return np.diag([self.params.b1, self.params.b2])

    def input_matrix(self):
        return np.eye(2)

    def energies(self, q, v, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin
        omega1, omega12 = v[0], v[0] + v[1]  # absolute angular rates of the links
        c1_dot = (-p.r1 * sin(q[0]) * omega1, p.r1 * cos(q[0]) * omega1)
        c2_dot = (
            -p.l1 * sin(q[0]) * omega1 - p.r2 * sin(q[0] + q[1]) * omega12,
            p.l1 * cos(q[0]) * omega1 + p.r2 * cos(q[0] + q[1]) * omega12,
        )
        kinetic = (
            p.m1 * (c1_dot[0] ** 2 + c1_dot[1] ** 2)
            + p.I1 * omega1**2
            + p.m2 * (c2_dot[0] ** 2 + c2_dot[1] ** 2)
            + p.I2 * omega12**2
        ) / 2
        height1, height2 = p.r1 * sin(q[0]), p.l1 * sin(q[0]) + p.r2 * sin(q[0] + q[1])
        return Energies(
            kinetic=kinetic,
            potential=p.g * (p.m1 * height1 + p.m2 * height2),
            dissipation=(p.b1 * v[0] ** 2 + p.b2 * v[1] ** 2) / 2,
            power=u[0] * v[0] + u[1] * v[1],
        )
