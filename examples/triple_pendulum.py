"""A triple pendulum in absolute angles from the hanging position: a model file for ``--analytic``.

Verify it against its URDF::

    pendverify check --analytic examples/triple_pendulum.py --urdf examples/triple_pendulum.urdf \\
                     --params examples/triple_pendulum.toml
    pendverify sympy --analytic examples/triple_pendulum.py
    pendverify mutate --analytic examples/triple_pendulum.py --urdf examples/triple_pendulum.urdf \\
                      --params examples/triple_pendulum.toml

Regenerate the URDF with ``python examples/triple_pendulum.py``.

Conventions
-----------
Three rigid links hang from a fixed pivot and swing in the vertical (y, z)
plane, z up, about joint axes parallel to +x.  φ1, φ2, φ3 [rad] are the
*absolute* angles of the links from the downward vertical, positive
counter-clockwise seen along +x (from −z towards +y)::

          ● pivot (joint 1)
          |\\
          | \\ φ1      link i: mass m_i [kg], centre of mass at r_i [m] from
          |  o m1      its joint along the link, inertia I_i [kg·m²] about
          |   \\        that centre (axis x); l_i [m] joint-to-joint length
          |    ● joint 2       (l3 only draws link 3)
          |    |
          | φ2 o m2    (φ2 = 0: link 2 hangs straight down)
          |    |
          |    ● joint 3
          |   /
          |  o m3   φ3 < 0 here
       −z ↓  → +y

With u(φ) = (sin φ, −cos φ) the unit vector of a link in the (y, z) plane, the
centres of mass are c1 = r1 u(φ1), c2 = l1 u(φ1) + r2 u(φ2),
c3 = l1 u(φ1) + l2 u(φ2) + r3 u(φ3).  Joint k measures the *relative* angle
ψ_k = φ_k − φ_{k−1} (φ0 = 0); its viscous friction b_k [N·m·s/rad] acts on ψ̇_k
and its motor torque τ_k [N·m] does work τ_k ψ̇_k.  So, with ψ = A φ,
A the difference matrix [[1, 0, 0], [−1, 1, 0], [0, −1, 1]]:

    T = ½ Σ_i (m_i |ċ_i|² + I_i φ̇_i²),      V = −g (e1 cos φ1 + e2 cos φ2 + e3 cos φ3),
    R = ½ Σ_k b_k ψ̇_k² = ½ φ̇ᵀ Aᵀ diag(b) A φ̇,   P = Σ_k τ_k ψ̇_k = (Aᵀ τ)ᵀ φ̇,

    e1 = m1 r1 + (m2 + m3) l1,   e2 = m2 r2 + m3 l2,   e3 = m3 r3  [kg·m].

Lagrange's equations give M φ̈ + C φ̇ + D φ̇ + H = B τ with, writing
c_ij = cos(φi − φj), s_ij = sin(φi − φj),

    M = [ a1        k12 c12   k13 c13 ]    a1 = I1 + m1 r1² + (m2 + m3) l1²
        [ k12 c12   a2        k23 c23 ]    a2 = I2 + m2 r2² + m3 l2²
        [ k13 c13   k23 c23   a3      ]    a3 = I3 + m3 r3²
                                           k12 = l1 (m2 r2 + m3 l2),  k13 = l1 m3 r3,  k23 = l2 m3 r3

    C_ij = k_ij s_ij φ̇j  (i ≠ j, k_ji = k_ij),  C_ii = 0       (the Christoffel C:
        C = [ 0              k12 s12 φ̇2    k13 s13 φ̇3 ]      Ṁ − 2C is skew-symmetric)
            [ −k12 s12 φ̇1   0              k23 s23 φ̇3 ]
            [ −k13 s13 φ̇1   −k23 s23 φ̇2   0           ]

    H = g (e1 sin φ1, e2 sin φ2, e3 sin φ3),

    D = Aᵀ diag(b) A = [ b1 + b2   −b2       0   ]     B = Aᵀ = [ 1  −1   0 ]
                       [ −b2       b2 + b3   −b3 ]              [ 0   1  −1 ]
                       [ 0         −b3       b3  ]              [ 0   0   1 ]

    det M = a1 a2 a3 − a1 k23² c23² − a2 k13² c13² − a3 k12² c12² + 2 k12 k13 k23 c12 c13 c23

(the cofactor expansion along the first row), M⁻¹ = adj M / det M with the
cofactors

    adj11 = a2 a3 − k23² c23²,   adj12 = k13 k23 c13 c23 − a3 k12 c12,
    adj22 = a1 a3 − k13² c13²,   adj13 = k12 k23 c12 c23 − a2 k13 c13,
    adj33 = a1 a2 − k12² c12²,   adj23 = k12 k13 c12 c13 − a1 k23 c23,

and q̈ = M⁻¹ f with f = Bτ − Cφ̇ − Dφ̇ − H written out term by term
(``generalized_force``).  The diagonal of M is constant and a sum of positive
terms, so the inertia scale S = (a1, a2, a3) never cancels.

The URDF
--------
``triple_pendulum_urdf`` writes a chain base → joint1 → link1 → joint2 → link2
→ joint3 → link3 of revolute joints about +x, each link hanging along its
frame's −z at joint angle 0 (centre of mass at (0, 0, −r_i), joint k+1 at
(0, 0, −l_k)), with the inertia I_i about x and y (a slender rod: 0 about its
own axis z) and ``<dynamics damping="b_k">``.  Its joint angles are the relative
ψ = A φ, so the map q = T (θ − θ0) has T = A and θ0 = 0, and the friction
Pinocchio stores, diag(b) in joint coordinates, is Tᵀ·diag(b)·T = D here.
"""

from __future__ import annotations

import dataclasses
import math
import sys
from pathlib import Path
from typing import ClassVar

import numpy as np

from pendverify import ClosedFormModel, Energies, ParameterSet, quantity
from pendverify.analytic import STANDARD_CLOSED_FORMS, ClosedForm


@dataclasses.dataclass(frozen=True)
class TriplePendulumParams(ParameterSet):
    """Parameters of the triple pendulum, SI units."""

    model = "triple_pendulum"

    m1: float = quantity("mass", "mass of link 1 in [kg]")
    m2: float = quantity("mass", "mass of link 2 in [kg]")
    m3: float = quantity("mass", "mass of link 3 in [kg]")
    l1: float = quantity("length", "distance joint 1 to joint 2 in [m]")
    l2: float = quantity("length", "distance joint 2 to joint 3 in [m]")
    l3: float = quantity("length", "length of link 3, for drawing only, in [m]")
    r1: float = quantity("offset", "distance joint 1 to the centre of mass of link 1 in [m]")
    r2: float = quantity("offset", "distance joint 2 to the centre of mass of link 2 in [m]")
    r3: float = quantity("offset", "distance joint 3 to the centre of mass of link 3 in [m]")
    I1: float = quantity("inertia", "inertia of link 1 about its centre of mass in [kg·m²]")
    I2: float = quantity("inertia", "inertia of link 2 about its centre of mass in [kg·m²]")
    I3: float = quantity("inertia", "inertia of link 3 about its centre of mass in [kg·m²]")
    b1: float = quantity("damping", "viscous friction of joint 1 (on φ̇1) in [N·m·s/rad]")
    b2: float = quantity("damping", "viscous friction of joint 2 (on φ̇2 − φ̇1) in [N·m·s/rad]")
    b3: float = quantity("damping", "viscous friction of joint 3 (on φ̇3 − φ̇2) in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class TriplePendulum(ClosedFormModel):
    name = "triple_pendulum"
    params_type = TriplePendulumParams
    coordinates = ("phi1", "phi2", "phi3")
    angular = (True, True, True)
    inputs = ("tau1", "tau2", "tau3")
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **STANDARD_CLOSED_FORMS,
        "generalized_force": ClosedForm("qvuw", "-C*v - H - D*v + B*u + W*w"),
    }

    # the coordinate map to examples/triple_pendulum.urdf: relative joint angles ψ = T (φ − φ0)
    urdf_joints = ("joint1", "joint2", "joint3")
    joint_transform = ((1.0, 0.0, 0.0), (-1.0, 1.0, 0.0), (0.0, -1.0, 1.0))
    joint_offset = (0.0, 0.0, 0.0)

    # --- constants of M, H -------------------------------------------------------------------
    def _diagonal(self):
        p = self.params
        return (
            p.I1 + p.m1 * p.r1**2 + (p.m2 + p.m3) * p.l1**2,
            p.I2 + p.m2 * p.r2**2 + p.m3 * p.l2**2,
            p.I3 + p.m3 * p.r3**2,
        )

    def _couplings(self):
        p = self.params
        return p.l1 * (p.m2 * p.r2 + p.m3 * p.l2), p.l1 * p.m3 * p.r3, p.l2 * p.m3 * p.r3

    def _moments(self):
        """e_i: the first moments of mass that multiply g sin φi in H."""
        p = self.params
        return p.m1 * p.r1 + (p.m2 + p.m3) * p.l1, p.m2 * p.r2 + p.m3 * p.l2, p.m3 * p.r3

    def _cosines(self, q):
        cos = self.math.cos
        return cos(q[0] - q[1]), cos(q[0] - q[2]), cos(q[1] - q[2])

    def _sines(self, q):
        sin = self.math.sin
        return sin(q[0] - q[1]), sin(q[0] - q[2]), sin(q[1] - q[2])

    # --- the equations -------------------------------------------------------------------------
    def mass_matrix(self, q):
        a1, a2, a3 = self._diagonal()
        k12, k13, k23 = self._couplings()
        c12, c13, c23 = self._cosines(q)
        return np.array(
            [
                [a1, k12 * c12, k13 * c13],
                [k12 * c12, a2, k23 * c23],
                [k13 * c13, k23 * c23, a3],
            ]
        )

    def coriolis_matrix(self, q, v):
        k12, k13, k23 = self._couplings()
        s12, s13, s23 = self._sines(q)
        return np.array(
            [
                [0.0, k12 * s12 * v[1], k13 * s13 * v[2]],
                [-k12 * s12 * v[0], 0.0, k23 * s23 * v[2]],
                [-k13 * s13 * v[0], -k23 * s23 * v[1], 0.0],
            ]
        )

    def gravity(self, q):
        p = self.params
        e1, e2, e3 = self._moments()
        sin = self.math.sin
        return p.g * np.array([e1 * sin(q[0]), e2 * sin(q[1]), e3 * sin(q[2])])

    def gravity_scale(self):
        p = self.params
        return p.g * np.array(
            [p.m1 * p.r1 + p.m2 * p.l1 + p.m3 * p.l1, p.m2 * p.r2 + p.m3 * p.l2, p.m3 * p.r3]
        )

    def potential_energy(self, q):
        p = self.params
        e1, e2, e3 = self._moments()
        cos = self.math.cos
        return -p.g * (e1 * cos(q[0]) + e2 * cos(q[1]) + e3 * cos(q[2]))

    def damping_matrix(self):
        p = self.params
        return np.array(
            [
                [p.b1 + p.b2, -p.b2, 0.0],
                [-p.b2, p.b2 + p.b3, -p.b3],
                [0.0, -p.b3, p.b3],
            ]
        )

    def input_matrix(self):
        return np.array([[1.0, -1.0, 0.0], [0.0, 1.0, -1.0], [0.0, 0.0, 1.0]])

    def det_mass_matrix(self, q):
        a1, a2, a3 = self._diagonal()
        k12, k13, k23 = self._couplings()
        c12, c13, c23 = self._cosines(q)
        return (
            a1 * a2 * a3
            - a1 * (k23 * c23) ** 2
            - a2 * (k13 * c13) ** 2
            - a3 * (k12 * c12) ** 2
            + 2 * k12 * k13 * k23 * c12 * c13 * c23
        )

    def inverse_mass_matrix(self, q):
        a1, a2, a3 = self._diagonal()
        k12, k13, k23 = self._couplings()
        c12, c13, c23 = self._cosines(q)
        adj12 = k13 * k23 * c13 * c23 - a3 * k12 * c12
        adj13 = k12 * k23 * c12 * c23 - a2 * k13 * c13
        adj23 = k12 * k13 * c12 * c13 - a1 * k23 * c23
        adj = np.array(
            [
                [a2 * a3 - (k23 * c23) ** 2, adj12, adj13],
                [adj12, a1 * a3 - (k13 * c13) ** 2, adj23],
                [adj13, adj23, a1 * a2 - (k12 * c12) ** 2],
            ]
        )
        return adj / self.det_mass_matrix(q)

    def generalized_force(self, q, v, u, w):
        """The right-hand side of M φ̈ = f: Coriolis, gravity, joint friction and joint torques."""
        p = self.params
        k12, k13, k23 = self._couplings()
        s12, s13, s23 = self._sines(q)
        e1, e2, e3 = self._moments()
        sin = self.math.sin
        rel2, rel3 = v[1] - v[0], v[2] - v[1]  # the joint rates ψ̇2, ψ̇3
        return np.array(
            [
                -k12 * s12 * v[1] ** 2
                - k13 * s13 * v[2] ** 2
                - p.g * e1 * sin(q[0])
                - p.b1 * v[0]
                + p.b2 * rel2
                + u[0]
                - u[1],
                k12 * s12 * v[0] ** 2
                - k23 * s23 * v[2] ** 2
                - p.g * e2 * sin(q[1])
                - p.b2 * rel2
                + p.b3 * rel3
                + u[1]
                - u[2],
                k13 * s13 * v[0] ** 2 + k23 * s23 * v[1] ** 2 - p.g * e3 * sin(q[2]) - p.b3 * rel3 + u[2],
            ]
        )

    def acceleration(self, q, v, u, w):
        return self.inverse_mass_matrix(q) @ self.generalized_force(q, v, u, w)

    def diagonal_scale(self, q):
        return np.array(self._diagonal())

    def energies(self, q, v, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin

        def unit_rate(i):  # d/dt u(φi) = φ̇i (cos φi, sin φi)
            return (cos(q[i]) * v[i], sin(q[i]) * v[i])

        d1, d2, d3 = unit_rate(0), unit_rate(1), unit_rate(2)
        c1_dot = [p.r1 * d1[k] for k in range(2)]
        c2_dot = [p.l1 * d1[k] + p.r2 * d2[k] for k in range(2)]
        c3_dot = [p.l1 * d1[k] + p.l2 * d2[k] + p.r3 * d3[k] for k in range(2)]
        kinetic = (
            p.m1 * (c1_dot[0] ** 2 + c1_dot[1] ** 2)
            + p.m2 * (c2_dot[0] ** 2 + c2_dot[1] ** 2)
            + p.m3 * (c3_dot[0] ** 2 + c3_dot[1] ** 2)
            + p.I1 * v[0] ** 2
            + p.I2 * v[1] ** 2
            + p.I3 * v[2] ** 2
        ) / 2
        heights = (
            -p.r1 * cos(q[0]),
            -p.l1 * cos(q[0]) - p.r2 * cos(q[1]),
            -p.l1 * cos(q[0]) - p.l2 * cos(q[1]) - p.r3 * cos(q[2]),
        )
        joint_rates = (v[0], v[1] - v[0], v[2] - v[1])
        return Energies(
            kinetic=kinetic,
            potential=p.g * (p.m1 * heights[0] + p.m2 * heights[1] + p.m3 * heights[2]),
            dissipation=(p.b1 * joint_rates[0] ** 2 + p.b2 * joint_rates[1] ** 2 + p.b3 * joint_rates[2] ** 2)
            / 2,
            power=u[0] * joint_rates[0] + u[1] * joint_rates[1] + u[2] * joint_rates[2],
        )

    def special_states(self):
        pi = math.pi
        return {
            "hanging": np.array([0.0, 0.0, 0.0]),
            "inverted": np.array([pi, pi, pi]),
            "folded": np.array([0.0, pi, 0.0]),
            "horizontal": np.array([pi / 2, pi / 2, pi / 2]),
            "zigzag": np.array([pi / 2, -pi / 2, pi / 2]),
        }


# --- the URDF ---------------------------------------------------------------------------------
def triple_pendulum_urdf(p: TriplePendulumParams) -> str:
    """The URDF of a parameter set: three links hanging along −z at joint angle 0, joints about +x."""

    def num(x: float) -> str:
        return repr(float(x))

    lengths = (p.l1, p.l2, p.l3)
    masses, offsets, inertias = (p.m1, p.m2, p.m3), (p.r1, p.r2, p.r3), (p.I1, p.I2, p.I3)
    dampings = (p.b1, p.b2, p.b3)
    parts = [
        '<?xml version="1.0"?>',
        "<!-- Generated by examples/triple_pendulum.py from a triple_pendulum parameter set; "
        "do not edit by hand. -->",
        '<robot name="triple_pendulum">',
        '  <link name="base">',
        "    <visual>",
        '      <geometry><box size="0.06 0.06 0.06"/></geometry>',
        "    </visual>",
        "  </link>",
    ]
    for i in range(3):
        parent = "base" if i == 0 else f"link{i}"
        drop = 0.0 if i == 0 else -lengths[i - 1]
        parts += [
            f'  <joint name="joint{i + 1}" type="revolute">',
            f'    <parent link="{parent}"/>',
            f'    <child link="link{i + 1}"/>',
            f'    <origin xyz="0 0 {num(drop)}" rpy="0 0 0"/>',
            '    <axis xyz="1 0 0"/>',
            '    <limit lower="-1e9" upper="1e9" effort="1e9" velocity="1e9"/>',
            f'    <dynamics damping="{num(dampings[i])}"/>',
            "  </joint>",
            f'  <link name="link{i + 1}">',
            "    <inertial>",
            f'      <origin xyz="0 0 {num(-offsets[i])}" rpy="0 0 0"/>',
            f'      <mass value="{num(masses[i])}"/>',
            f'      <inertia ixx="{num(inertias[i])}" ixy="0" ixz="0" iyy="{num(inertias[i])}" iyz="0" '
            'izz="0"/>',
            "    </inertial>",
            "    <visual>",
            f'      <origin xyz="0 0 {num(-lengths[i] / 2)}" rpy="0 0 0"/>',
            f'      <geometry><cylinder radius="0.012" length="{num(lengths[i])}"/></geometry>',
            "    </visual>",
            "  </link>",
        ]
    parts.append("</robot>")
    return "\n".join(parts) + "\n"


if __name__ == "__main__":  # regenerate examples/triple_pendulum.urdf from examples/triple_pendulum.toml
    import pendverify

    here = Path(__file__).resolve().parent
    params = pendverify.load_params(TriplePendulum, here / "triple_pendulum.toml")
    (here / "triple_pendulum.urdf").write_text(triple_pendulum_urdf(params))
    sys.exit(0)
