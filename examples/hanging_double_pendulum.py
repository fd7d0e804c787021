"""A double pendulum in absolute angles from the hanging position: a model file for ``--analytic``.

Verify it against its URDF::

    pendverify check --analytic examples/hanging_double_pendulum.py \\
        --urdf examples/hanging_double_pendulum.urdf --params examples/hanging_double_pendulum.toml
    pendverify sympy --analytic examples/hanging_double_pendulum.py
    pendverify mutate --analytic examples/hanging_double_pendulum.py \\
        --urdf examples/hanging_double_pendulum.urdf --params examples/hanging_double_pendulum.toml

Regenerate the URDF with ``python examples/hanging_double_pendulum.py``.

Conventions
-----------
φ1, φ2 are the *absolute* angles of the two links from the downward vertical,
positive counter-clockwise (seen along +x: from −z towards +y).  Link i has
mass m_i, centre of mass at r_i from its joint, inertia I_i about that centre;
l1 is the joint-to-joint length (l2 only draws link 2).  Joint frictions b1,
b2 act on the *joint* rates φ̇1 and φ̇2 − φ̇1, and the joint torques τ1, τ2 do
work τ1 φ̇1 + τ2 (φ̇2 − φ̇1); in absolute angles both become non-diagonal::

    M = [ a          k cos(φ1−φ2) ]    a = I1 + m1 r1² + m2 l1²,  d = I2 + m2 r2²,
        [ k cos(φ1−φ2)  d         ]    k = m2 l1 r2

    C = [ 0                   k sin(φ1−φ2) φ̇2 ]     H = g (e sin φ1, m2 r2 sin φ2),
        [ −k sin(φ1−φ2) φ̇1   0               ]     e = m1 r1 + m2 l1

    D = [ b1 + b2   −b2 ]     B = [ 1   −1 ]     V = −g (e cos φ1 + m2 r2 cos φ2)
        [ −b2        b2 ]         [ 0    1 ]

The URDF is the project's own double-pendulum URDF (``pendverify.robot.writer``),
whose joint angles are θ1 from the horizontal (+y) and θ2 relative to link 1.
So q1 = φ1 − π/2 and q2 = φ2 − φ1: the map q = T (φ − φ0) is linear *and*
offset, T = [[1, 0], [−1, 1]], φ0 = (π/2, π/2).
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import ClassVar

import numpy as np

from pendverify import ClosedFormModel, Energies, ParameterSet, quantity
from pendverify.analytic import STANDARD_CLOSED_FORMS, ClosedForm, DoublePendulumParams


@dataclasses.dataclass(frozen=True)
class HangingDoublePendulumParams(ParameterSet):
    """Parameters, SI units (the same physical quantities as the reference double pendulum)."""

    model = "hanging_double_pendulum"

    m1: float = quantity("mass", "mass of link 1 in [kg]")
    m2: float = quantity("mass", "mass of link 2 in [kg]")
    l1: float = quantity("length", "distance joint 1 to joint 2 in [m]")
    l2: float = quantity("length", "length of link 2, for drawing only, in [m]")
    r1: float = quantity("offset", "distance joint 1 to the centre of mass of link 1 in [m]")
    r2: float = quantity("offset", "distance joint 2 to the centre of mass of link 2 in [m]")
    I1: float = quantity("inertia", "inertia of link 1 about its centre of mass in [kg·m²]")
    I2: float = quantity("inertia", "inertia of link 2 about its centre of mass in [kg·m²]")
    b1: float = quantity("damping", "viscous friction of joint 1 in [N·m·s/rad]")
    b2: float = quantity("damping", "viscous friction of joint 2 (on φ̇2 − φ̇1) in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class HangingDoublePendulum(ClosedFormModel):
    name = "hanging_double_pendulum"
    params_type = HangingDoublePendulumParams
    coordinates = ("phi1", "phi2")
    angular = (True, True)
    inputs = ("tau1", "tau2")
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **STANDARD_CLOSED_FORMS,
        "generalized_force": ClosedForm("qvuw", "-C*v - H - D*v + B*u + W*w"),
    }

    # the coordinate map to the project's double-pendulum URDF: q = T (φ − φ0)
    urdf_joints = ("joint1", "joint2")
    joint_transform = ((1.0, 0.0), (-1.0, 1.0))
    joint_offset = (math.pi / 2, math.pi / 2)

    def _constants(self):
        p = self.params
        return p.I1 + p.m1 * p.r1**2 + p.m2 * p.l1**2, p.I2 + p.m2 * p.r2**2, p.m2 * p.l1 * p.r2

    def mass_matrix(self, q):
        a, d, k = self._constants()
        c = k * self.math.cos(q[0] - q[1])
        return np.array([[a, c], [c, d]])

    def coriolis_matrix(self, q, v):
        _, _, k = self._constants()
        s = k * self.math.sin(q[0] - q[1])
        return np.array([[0.0, s * v[1]], [-s * v[0], 0.0]])

    def gravity(self, q):
        p = self.params
        return p.g * np.array(
            [(p.m1 * p.r1 + p.m2 * p.l1) * self.math.sin(q[0]), p.m2 * p.r2 * self.math.sin(q[1])]
        )

    def gravity_scale(self):
        p = self.params
        return p.g * np.array([p.m1 * p.r1 + p.m2 * p.l1, p.m2 * p.r2])

    def potential_energy(self, q):
        p = self.params
        return -p.g * ((p.m1 * p.r1 + p.m2 * p.l1) * self.math.cos(q[0]) + p.m2 * p.r2 * self.math.cos(q[1]))

    def damping_matrix(self):
        p = self.params
        return np.array([[p.b1 + p.b2, -p.b2], [-p.b2, p.b2]])

    def input_matrix(self):
        return np.array([[1.0, -1.0], [0.0, 1.0]])

    def det_mass_matrix(self, q):
        a, d, k = self._constants()
        return a * d - (k * self.math.cos(q[0] - q[1])) ** 2

    def inverse_mass_matrix(self, q):
        a, d, k = self._constants()
        c = k * self.math.cos(q[0] - q[1])
        return np.array([[d, -c], [-c, a]]) / self.det_mass_matrix(q)

    def generalized_force(self, q, v, u, w):
        """The right-hand side of M φ̈ = f: Coriolis, gravity, friction and joint torques."""
        p = self.params
        _, _, k = self._constants()
        s = k * self.math.sin(q[0] - q[1])
        e = p.m1 * p.r1 + p.m2 * p.l1
        return np.array(
            [
                -s * v[1] ** 2
                - p.g * e * self.math.sin(q[0])
                - p.b1 * v[0]
                + p.b2 * (v[1] - v[0])
                + u[0]
                - u[1],
                s * v[0] ** 2 - p.g * p.m2 * p.r2 * self.math.sin(q[1]) - p.b2 * (v[1] - v[0]) + u[1],
            ]
        )

    def acceleration(self, q, v, u, w):
        return self.inverse_mass_matrix(q) @ self.generalized_force(q, v, u, w)

    def diagonal_scale(self, q):
        a, d, _ = self._constants()
        return np.array([a, d])

    def energies(self, q, v, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin
        # centres of mass: c1 = r1 (sin φ1, −cos φ1), c2 = l1 (sin φ1, −cos φ1) + r2 (sin φ2, −cos φ2)
        c1_dot = (p.r1 * cos(q[0]) * v[0], p.r1 * sin(q[0]) * v[0])
        c2_dot = (
            p.l1 * cos(q[0]) * v[0] + p.r2 * cos(q[1]) * v[1],
            p.l1 * sin(q[0]) * v[0] + p.r2 * sin(q[1]) * v[1],
        )
        kinetic = (
            p.m1 * (c1_dot[0] ** 2 + c1_dot[1] ** 2)
            + p.I1 * v[0] ** 2
            + p.m2 * (c2_dot[0] ** 2 + c2_dot[1] ** 2)
            + p.I2 * v[1] ** 2
        ) / 2
        heights = (-p.r1 * cos(q[0]), -p.l1 * cos(q[0]) - p.r2 * cos(q[1]))
        return Energies(
            kinetic=kinetic,
            potential=p.g * (p.m1 * heights[0] + p.m2 * heights[1]),
            dissipation=(p.b1 * v[0] ** 2 + p.b2 * (v[1] - v[0]) ** 2) / 2,
            power=u[0] * v[0] + u[1] * (v[1] - v[0]),
        )

    def special_states(self):
        pi = math.pi
        return {
            "hanging": np.array([0.0, 0.0]),
            "inverted": np.array([pi, pi]),
            "folded": np.array([0.0, pi]),
            "horizontal": np.array([pi / 2, pi / 2]),
        }


def hanging_double_pendulum_urdf(p: HangingDoublePendulumParams) -> str:
    """The project's double-pendulum URDF of the same physical parameters."""
    from pendverify.robot.writer import urdf_for

    return urdf_for(DoublePendulumParams(**p.as_dict()), "hanging_double_pendulum")


if __name__ == "__main__":  # regenerate the URDF from the TOML next to this file
    import pendverify

    here = Path(__file__).resolve().parent
    params = pendverify.load_params(HangingDoublePendulum, here / "hanging_double_pendulum.toml")
    (here / "hanging_double_pendulum.urdf").write_text(hanging_double_pendulum_urdf(params))
    sys.exit(0)
