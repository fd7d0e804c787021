"""A single cart-pole with an inertial pole: a complete model file for ``--analytic``.

Verify it against its URDF::

    pendverify check --analytic examples/cart_pole.py --urdf examples/cart_pole.urdf \\
                     --params examples/cart_pole.toml
    pendverify sympy --analytic examples/cart_pole.py
    pendverify mutate --analytic examples/cart_pole.py --urdf examples/cart_pole.urdf \\
                      --params examples/cart_pole.toml

Regenerate the URDF with ``python examples/cart_pole.py``.

Conventions
-----------
::

            o  pole: mass mp [kg], centre of mass at distance r [m] from the
           /   pivot, inertia I [kg·m²] about its centre of mass; θ from the
          /    upright, positive when the pole leans towards +x
     [===o===]  → +x   cart: mass mc [kg] at position x [m], pushed by u [N]
    ===========  rail

Friction −bx ẋ on the cart [N·s/m] and −bt θ̇ at the pivot [N·m·s/rad]; a
disturbance torque w [N·m] acts on the pole.  The centre of mass of the pole is
at (x + r sin θ, r cos θ), so

    T = ½ mc ẋ² + ½ mp ((ẋ + r cos θ θ̇)² + (r sin θ θ̇)²) + ½ I θ̇²,   V = mp g r cos θ,

    M = [ mc + mp        mp r cos θ ]     C = [ 0   −mp r sin θ θ̇ ]
        [ mp r cos θ     I + mp r²  ]         [ 0    0            ]

    H = (0, −mp g r sin θ),  D = diag(bx, bt),  B = (1, 0),  W = (0, 1),
    det M = (mc + mp)(I + mp r²) − (mp r cos θ)²,
    q̈ = M⁻¹ f,  f = (u − bx ẋ + mp r sin θ θ̇²,  w − bt θ̇ + mp g r sin θ).

The URDF (written by ``cart_pole_urdf``) hangs the pole straight down at joint
angle 0 and turns it about −y, so its hinge angle is π − θ: the coordinate map
q = T (θ − θ0) has T = diag(1, −1) and θ0 = (0, π).  The hinge is a continuous
joint, which Pinocchio stores as (cos, sin).
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
class CartPoleParams(ParameterSet):
    """Parameters of the cart-pole, SI units."""

    model = "cart_pole"

    mc: float = quantity("mass", "mass of the cart in [kg]")
    mp: float = quantity("mass", "mass of the pole in [kg]")
    r: float = quantity("offset", "distance pivot to the pole's centre of mass in [m]")
    I: float = quantity("inertia", "inertia of the pole about its centre of mass in [kg·m²]")  # noqa: E741
    bx: float = quantity("damping", "viscous friction of the cart in [N·s/m]")
    bt: float = quantity("damping", "viscous friction at the pivot in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class CartPole(ClosedFormModel):
    name = "cart_pole"
    params_type = CartPoleParams
    coordinates = ("x", "theta")
    angular = (False, True)
    inputs = ("u",)
    disturbances = ("w",)
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **STANDARD_CLOSED_FORMS,
        "f": ClosedForm("qvuw", "-C*v - H - D*v + B*u + W*w"),
    }

    # the coordinate map to examples/cart_pole.urdf: q = T (θ − θ0)
    urdf_joints = ("cart_slider", "pole_hinge")
    joint_transform = ((1.0, 0.0), (0.0, -1.0))
    joint_offset = (0.0, math.pi)

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

    def gravity_scale(self):
        p = self.params
        return np.array([0.0, p.mp * p.g * p.r])

    def potential_energy(self, q):
        p = self.params
        return p.mp * p.g * p.r * self.math.cos(q[1])

    def damping_matrix(self):
        return np.diag([self.params.bx, self.params.bt])

    def input_matrix(self):
        return np.array([[1.0], [0.0]])

    def disturbance_matrix(self):
        return np.array([[0.0], [1.0]])

    def det_mass_matrix(self, q):
        p = self.params
        return (p.mc + p.mp) * (p.I + p.mp * p.r**2) - (p.mp * p.r * self.math.cos(q[1])) ** 2

    def inverse_mass_matrix(self, q):
        p = self.params
        k = p.mp * p.r * self.math.cos(q[1])
        adj = np.array([[p.I + p.mp * p.r**2, -k], [-k, p.mc + p.mp]])
        return adj / self.det_mass_matrix(q)

    def f(self, q, v, u, w):
        """The right-hand side of M q̈ = f."""
        p = self.params
        s = self.math.sin(q[1])
        return np.array(
            [
                u[0] - p.bx * v[0] + p.mp * p.r * s * v[1] ** 2,
                w[0] - p.bt * v[1] + p.mp * p.g * p.r * s,
            ]
        )

    def acceleration(self, q, v, u, w):
        return self.inverse_mass_matrix(q) @ self.f(q, v, u, w)

    def energies(self, q, v, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin
        com_velocity = (v[0] + p.r * cos(q[1]) * v[1], -p.r * sin(q[1]) * v[1])
        return Energies(
            kinetic=(
                p.mc * v[0] ** 2 + p.mp * (com_velocity[0] ** 2 + com_velocity[1] ** 2) + p.I * v[1] ** 2
            )
            / 2,
            potential=p.mp * p.g * p.r * cos(q[1]),
            dissipation=(p.bx * v[0] ** 2 + p.bt * v[1] ** 2) / 2,
            power=u[0] * v[0] + w[0] * v[1],
        )

    def special_states(self):
        return {
            "upright": np.array([0.0, 0.0]),
            "hanging": np.array([0.0, math.pi]),
            "horizontal": np.array([0.5, math.pi / 2]),
        }


# --- the URDF ---------------------------------------------------------------------------------
def cart_pole_urdf(p: CartPoleParams) -> str:
    """The URDF of a parameter set: pole hanging at joint angle 0, hinge about −y (continuous)."""

    def num(x: float) -> str:
        return repr(float(x))

    length = max(2 * p.r, 0.05)
    return f"""<?xml version="1.0"?>
<!-- Generated by examples/cart_pole.py from a cart_pole parameter set; do not edit by hand. -->
<robot name="cart_pole">
  <link name="rail"/>
  <joint name="cart_slider" type="prismatic">
    <parent link="rail"/>
    <child link="cart"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="-1e9" upper="1e9" effort="1e9" velocity="1e9"/>
  </joint>
  <link name="cart">
    <inertial>
      <origin xyz="0 0 0" rpy="0 0 0"/>
      <mass value="{num(p.mc)}"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>
    </inertial>
    <visual>
      <geometry><box size="0.3 0.15 0.1"/></geometry>
    </visual>
  </link>
  <joint name="pole_hinge" type="continuous">
    <parent link="cart"/>
    <child link="pole"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 -1 0"/>
  </joint>
  <link name="pole">
    <inertial>
      <origin xyz="0 0 {num(-p.r)}" rpy="0 0 0"/>
      <mass value="{num(p.mp)}"/>
      <inertia ixx="{num(p.I)}" ixy="0" ixz="0" iyy="{num(p.I)}" iyz="0" izz="0"/>
    </inertial>
    <visual>
      <origin xyz="0 0 {num(-length / 2)}" rpy="0 0 0"/>
      <geometry><cylinder radius="0.012" length="{num(length)}"/></geometry>
    </visual>
  </link>
</robot>
"""


if __name__ == "__main__":  # regenerate examples/cart_pole.urdf from examples/cart_pole.toml
    import pendverify

    here = Path(__file__).resolve().parent
    params = pendverify.load_params(CartPole, here / "cart_pole.toml")
    (here / "cart_pole.urdf").write_text(cart_pole_urdf(params))
    sys.exit(0)
