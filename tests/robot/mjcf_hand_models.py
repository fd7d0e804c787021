"""Hand-derived models of the MuJoCo files gymnasium and dm_control ship (tests of issue 25).

Each is written out by hand: the parameters come from MuJoCo's compiled model at test time
(``tests/robot/test_mjcf_mujoco.py``), the equations do not.  Conventions common to the three:
every hinge turns about +y, so a rod whose centre of mass lies at distance r along the body's +z
leans towards +x by its angle θ (its centre of mass at (r sin θ, r cos θ) in x, z); angles are
measured from upright; gravity is g along −z.

Cart-pole (gymnasium ``inverted_pendulum.xml``, dm_control ``cartpole.xml``): coordinates x
(the slider), θ (the pole from upright; the hinge's q is θ − φ0 where φ0 is the angle of the
pole's centre of mass from the hinge's +z, ``joint_offset``)::

    M = [[mc + mp, mp r cos θ], [mp r cos θ, I + mp r²]],  C = [[0, −mp r sin θ θ̇], [0, 0]],
    H = (0, −mp g r sin θ),  V = mp g r cos θ,  D = diag(bx, bt),  B = (1, 0).

Cart with two poles (gymnasium ``inverted_double_pendulum.xml``): x, θ1, θ2 absolute angles from
upright; the hinges' q are θ1 and θ2 − θ1 (T below).  With a = m1 r1 + m2 l1, b = m2 r2,
c = m2 l1 r2, s12 = sin(θ1 − θ2)::

    M = [[mc + m1 + m2, a cos θ1, b cos θ2],
         [a cos θ1, I1 + m1 r1² + m2 l1², c cos(θ1 − θ2)],
         [b cos θ2, c cos(θ1 − θ2), I2 + m2 r2²]]
    C = [[0, −a sin θ1 θ̇1, −b sin θ2 θ̇2], [0, 0, c s12 θ̇2], [0, −c s12 θ̇1, 0]]
    V = g (a cos θ1 + b cos θ2),  H = (0, −g a sin θ1, −g b sin θ2),
    D = Tᵀ diag(bx, b1, b2) T  (MuJoCo's damping acts on the hinges' q = T θ).

Acrobot (dm_control ``acrobot.xml``): θ1 from upright, θ2 relative to link 1 (the hinges' own
angles); h = m2 l1 r2 sin θ2::

    M = [[I1 + I2 + m1 r1² + m2 (l1² + r2² + 2 l1 r2 cos θ2), I2 + m2 (r2² + l1 r2 cos θ2)],
         [I2 + m2 (r2² + l1 r2 cos θ2), I2 + m2 r2²]]
    C = [[−h θ̇2, −h (θ̇1 + θ̇2)], [h θ̇1, 0]]
    V = g (m1 r1 cos θ1 + m2 (l1 cos θ1 + r2 cos(θ1 + θ2))),
    H = −g ((m1 r1 + m2 l1) sin θ1 + m2 r2 sin(θ1 + θ2), m2 r2 sin(θ1 + θ2)),  D = diag(b1, b2).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pendverify.analytic import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity
from pendverify.examples.cart_pole import CartPoleParams


@dataclasses.dataclass(frozen=True)
class MjCartPoleParams(CartPoleParams):
    """A cart-pole's parameters (the example cart-pole's set), SI units."""

    model = "mjcf_cart_pole"


class MjCartPole(ClosedFormModel):
    """dm_control's cart-pole: the pole's centre of mass straight above the hinge (φ0 = 0)."""

    name = "mjcf_cart_pole"
    params_type = MjCartPoleParams
    coordinates = ("x", "theta")
    angular = (False, True)
    inputs = ("u",)
    urdf_joints = ("slider", "hinge_1")

    def mass_matrix(self, q):
        p = self.params
        k = p.mp * p.r * self.math.cos(q[1])
        return np.array([[p.mc + p.mp, k], [k, p.I + p.mp * p.r**2]])

    def coriolis_matrix(self, q, v):
        p = self.params
        return np.array([[0.0, -p.mp * p.r * self.math.sin(q[1]) * v[1]], [0.0, 0.0]])

    def gravity(self, q):
        p = self.params
        return np.array([0.0, -p.mp * p.g * p.r * self.math.sin(q[1])])

    def potential_energy(self, q):
        p = self.params
        return p.mp * p.g * p.r * self.math.cos(q[1])

    def damping_matrix(self):
        return np.diag([self.params.bx, self.params.bt])

    def input_matrix(self):
        return np.array([[1.0], [0.0]])


@dataclasses.dataclass(frozen=True)
class GymCartPoleParams(MjCartPoleParams):
    """gymnasium's cart-pole's parameters (those of ``MjCartPoleParams``)."""

    model = "gym_cart_pole"


class GymCartPole(MjCartPole):
    """gymnasium's cart-pole: its pole runs from the hinge to (0.001, 0, 0.6), so its centre of
    mass is at (0.0005, 0, 0.3), φ0 = atan2(0.0005, 0.3) from the hinge's +z."""

    name = "gym_cart_pole"
    params_type = GymCartPoleParams
    urdf_joints = ("slider", "hinge")
    joint_offset = (0.0, math.atan2(0.0005, 0.3))


@dataclasses.dataclass(frozen=True)
class MjCartDoublePoleParams(ParameterSet):
    """A cart with two poles' parameters, SI units."""

    model = "gym_cart_double_pole"

    mc: float = quantity("mass", "mass of the cart in [kg]")
    m1: float = quantity("mass", "mass of pole 1 in [kg]")
    m2: float = quantity("mass", "mass of pole 2 in [kg]")
    l1: float = quantity("length", "hinge 1 to hinge 2 in [m]")
    r1: float = quantity("offset", "hinge 1 to pole 1's centre of mass in [m]")
    r2: float = quantity("offset", "hinge 2 to pole 2's centre of mass in [m]")
    I1: float = quantity("inertia", "pole 1 about its centre of mass, about y, in [kg·m²]")
    I2: float = quantity("inertia", "pole 2 about its centre of mass, about y, in [kg·m²]")
    bx: float = quantity("damping", "slider damping in [N·s/m]")
    b1: float = quantity("damping", "hinge 1 damping in [N·m·s/rad]")
    b2: float = quantity("damping", "hinge 2 damping in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class GymCartDoublePole(ClosedFormModel):
    name = "gym_cart_double_pole"
    params_type = MjCartDoublePoleParams
    coordinates = ("x", "theta1", "theta2")
    angular = (False, True, True)
    inputs = ("u",)
    urdf_joints = ("slider", "hinge", "hinge2")
    # the hinges' q = T θ: q1 = θ1, q2 = θ2 − θ1
    joint_transform = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, -1.0, 1.0))

    def mass_matrix(self, q):
        p, cos = self.params, self.math.cos
        a, b, c = p.m1 * p.r1 + p.m2 * p.l1, p.m2 * p.r2, p.m2 * p.l1 * p.r2
        m01, m02, m12 = a * cos(q[1]), b * cos(q[2]), c * cos(q[1] - q[2])
        return np.array(
            [
                [p.mc + p.m1 + p.m2, m01, m02],
                [m01, p.I1 + p.m1 * p.r1**2 + p.m2 * p.l1**2, m12],
                [m02, m12, p.I2 + p.m2 * p.r2**2],
            ]
        )

    def coriolis_matrix(self, q, v):
        p, sin = self.params, self.math.sin
        a, b, c = p.m1 * p.r1 + p.m2 * p.l1, p.m2 * p.r2, p.m2 * p.l1 * p.r2
        s12 = sin(q[1] - q[2])
        return np.array(
            [
                [0.0, -a * sin(q[1]) * v[1], -b * sin(q[2]) * v[2]],
                [0.0, 0.0, c * s12 * v[2]],
                [0.0, -c * s12 * v[1], 0.0],
            ]
        )

    def gravity(self, q):
        p, sin = self.params, self.math.sin
        a, b = p.m1 * p.r1 + p.m2 * p.l1, p.m2 * p.r2
        return np.array([0.0, -p.g * a * sin(q[1]), -p.g * b * sin(q[2])])

    def potential_energy(self, q):
        p, cos = self.params, self.math.cos
        return p.g * ((p.m1 * p.r1 + p.m2 * p.l1) * cos(q[1]) + p.m2 * p.r2 * cos(q[2]))

    def damping_matrix(self):
        p = self.params
        T = np.array(self.joint_transform)
        return T.T @ np.diag([p.bx, p.b1, p.b2]) @ T

    def input_matrix(self):
        return np.array([[1.0], [0.0], [0.0]])


@dataclasses.dataclass(frozen=True)
class MjAcrobotParams(ParameterSet):
    """An acrobot's parameters, SI units."""

    model = "mjcf_acrobot"

    m1: float = quantity("mass", "mass of the upper arm in [kg]")
    m2: float = quantity("mass", "mass of the lower arm in [kg]")
    l1: float = quantity("length", "shoulder to elbow in [m]")
    r1: float = quantity("offset", "shoulder to the upper arm's centre of mass in [m]")
    r2: float = quantity("offset", "elbow to the lower arm's centre of mass in [m]")
    I1: float = quantity("inertia", "upper arm about its centre of mass, about y, in [kg·m²]")
    I2: float = quantity("inertia", "lower arm about its centre of mass, about y, in [kg·m²]")
    b1: float = quantity("damping", "shoulder damping in [N·m·s/rad]")
    b2: float = quantity("damping", "elbow damping in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class MjAcrobot(ClosedFormModel):
    name = "mjcf_acrobot"
    params_type = MjAcrobotParams
    coordinates = ("theta1", "theta2")
    angular = (True, True)
    inputs = ("tau",)
    urdf_joints = ("shoulder", "elbow")

    def mass_matrix(self, q):
        p = self.params
        c2 = self.math.cos(q[1])
        m12 = p.I2 + p.m2 * (p.r2**2 + p.l1 * p.r2 * c2)
        m11 = p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2 + 2 * p.l1 * p.r2 * c2)
        return np.array([[m11, m12], [m12, p.I2 + p.m2 * p.r2**2]])

    def coriolis_matrix(self, q, v):
        h = self.params.m2 * self.params.l1 * self.params.r2 * self.math.sin(q[1])
        return np.array([[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]])

    def gravity(self, q):
        p, sin = self.params, self.math.sin
        s12 = sin(q[0] + q[1])
        return -p.g * np.array(
            [(p.m1 * p.r1 + p.m2 * p.l1) * sin(q[0]) + p.m2 * p.r2 * s12, p.m2 * p.r2 * s12]
        )

    def potential_energy(self, q):
        p, cos = self.params, self.math.cos
        return p.g * (p.m1 * p.r1 * cos(q[0]) + p.m2 * (p.l1 * cos(q[0]) + p.r2 * cos(q[0] + q[1])))

    def damping_matrix(self):
        return np.diag([self.params.b1, self.params.b2])

    def input_matrix(self):
        return np.array([[0.0], [1.0]])
