"""A Furuta (rotary inverted) pendulum with full body inertias: a model file for ``--analytic``.

Verify it against its URDF::

    pendverify check --analytic examples/furuta_pendulum.py --urdf examples/furuta_pendulum.urdf \\
                     --params examples/furuta_pendulum.toml
    pendverify sympy --analytic examples/furuta_pendulum.py
    pendverify mutate --analytic examples/furuta_pendulum.py --urdf examples/furuta_pendulum.urdf \\
                      --params examples/furuta_pendulum.toml

Regenerate the URDF with ``python examples/furuta_pendulum.py``.

Conventions
-----------
World frame: z up, gravity −g z.  A horizontal arm turns about the vertical
axis z through its hub; the pendulum turns about the arm's own axis at the
arm's tip.  The system is not planar: the pendulum swings in the plane
perpendicular to the arm, and that plane turns with the arm::

                  z                          arm frame 1: x1 along the arm,
                  ↑      pendulum (α = 0:    z1 = z; θ [rad] about +z, θ = 0
                  |      upright)            with the arm along world x.
                  |        o  mp, CoM at lp
                  |        |                 pendulum frame 2: x2 = x1 (the
        θ ↺       |        |  ↶ α about x1   hinge axis), z2 along the
         ─────────●════════●  → x1           pendulum; α [rad] about +x1,
                 hub  arm (mr, CoM at cr)    α = 0 upright, α > 0 tips the
                      pivot at Lr            pendulum towards −y1.

Bodies (inertias about their centres of mass, principal axes along their frames):

* arm: mass mr [kg], centre of mass at cr [m] along x1, inertia
  diag(Jrxx, Jryy, Jrzz) [kg·m²] in frame 1; the pendulum's pivot at Lr [m] on x1.
* pendulum: mass mp [kg], centre of mass at lp [m] along z2 from the pivot,
  inertia diag(Jpxx, Jpyy, Jpzz) [kg·m²] in frame 2 (three different moments).

Frame 2 is frame 1 turned by R_x(α), so the pendulum's angular velocity in
frame 2 is ω2 = (α̇, θ̇ sin α, θ̇ cos α) and its centre of mass, at
(Lr, −lp sin α, lp cos α) in frame 1, moves with world velocity (in frame 1)

    ċ2 = (lp sin α θ̇,  Lr θ̇ − lp cos α α̇,  −lp sin α α̇).

Viscous friction br [N·m·s/rad] on θ̇ and bp [N·m·s/rad] on α̇; a motor torque
τ [N·m] on the arm and a disturbance torque w [N·m] on the pendulum.  Then

    T = ½ (Jrzz + mr cr²) θ̇² + ½ mp |ċ2|² + ½ (Jpxx α̇² + Jpyy sin²α θ̇² + Jpzz cos²α θ̇²),
    V = mp g lp cos α     (the arm's centre of mass stays at one height),
    R = ½ (br θ̇² + bp α̇²),      P = τ θ̇ + w α̇,

and Lagrange's equations M q̈ + C q̇ + D q̇ + H = B τ + W w, q = (θ, α), with

    M = [ a(α)            −mp Lr lp cos α ]    a(α) = Jrzz + mr cr² + mp Lr²
        [ −mp Lr lp cos α   d             ]           + (Jpyy + mp lp²) sin²α + Jpzz cos²α,
                                                d = Jpxx + mp lp²,

    C = [ K sin α cos α α̇    K sin α cos α θ̇ + mp Lr lp sin α α̇ ]    K = Jpyy + mp lp² − Jpzz
        [ −K sin α cos α θ̇   0                                  ]    (Christoffel: Ṁ − 2C skew)

    H = (0, −mp g lp sin α),   D = diag(br, bp),   B = (1, 0)ᵀ,   W = (0, 1)ᵀ,

    det M = a(α) d − (mp Lr lp cos α)²,   M⁻¹ = [ d  mp Lr lp cos α ; mp Lr lp cos α  a(α) ] / det M,

    q̈ = M⁻¹ f,   f = ( τ − br θ̇ − 2 K sin α cos α θ̇ α̇ − mp Lr lp sin α α̇²,
                       w − bp α̇ + K sin α cos α θ̇² + mp g lp sin α ).

Only the arm's Jrzz (with mr cr²) enters: Jrxx and Jryy are in the URDF but
belong to axes the arm never turns about.  The pendulum's three moments all
enter.  Its inertia about the pivot, diag(Jpxx + mp lp², Jpyy + mp lp², Jpzz)
in frame 2, turned into the arm's frame 1 (I = R_x(α) I₂ R_x(α)ᵀ), has the entries

    I_xx = Jpxx + mp lp²                              → M22
    I_zz = (Jpyy + mp lp²) sin²α + Jpzz cos²α         → M11 (with the arm's part)
    I_yz = (Jpyy + mp lp² − Jpzz) sin α cos α = K sin α cos α   → C (= ½ ∂I_zz/∂α)
    I_xy = I_xz = 0                                   (M12 comes from the pivot's offset Lr only)

Derivations that treat the pendulum as slender (Jpzz = 0) or symmetric
(Jpxx = Jpyy) lose the Jpzz cos²α of M11 and the Jpzz of the product of
inertia I_yz in C — the simplifications Cazzolato & Prime (2011, "On the
dynamics of the Furuta pendulum") point out in most published models; this example's
parameters give the pendulum three different moments so that both show.
Every M_ii is a sum of non-negative terms, so ``diagonal_scale`` (the sum of
their magnitudes, written out so that it does not move with M) never sees a
cancellation.

The URDF
--------
``furuta_pendulum_urdf`` writes base → ``arm_joint`` (revolute about +z at the
hub) → arm → ``pendulum_joint`` (continuous, at (Lr, 0, 0) in the arm frame,
about +x) → pendulum, with ``<dynamics damping>`` br and bp.  The pendulum
*hangs* at joint angle 0 (its centre of mass at (0, 0, −lp) in its link frame,
the frame turned by π about x from frame 2 above, which leaves the diagonal
inertia unchanged), so the joint angle is α − π: the map q = T (θ − θ0) has
T = identity and θ0 = (0, π).  The continuous joint is stored by Pinocchio as
(cos, sin).
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
class FurutaPendulumParams(ParameterSet):
    """Parameters of the Furuta pendulum, SI units."""

    model = "furuta_pendulum"

    mr: float = quantity("mass", "mass of the arm in [kg]")
    Lr: float = quantity("length", "distance from the arm's axis (hub) to the pendulum's pivot in [m]")
    cr: float = quantity("offset", "distance from the hub to the arm's centre of mass, along the arm, in [m]")
    Jrxx: float = quantity("inertia", "arm's moment about its own long axis x1, at its CoM, in [kg·m²]")
    Jryy: float = quantity("inertia", "arm's moment about the horizontal y1, at its CoM, in [kg·m²]")
    Jrzz: float = quantity("inertia", "arm's moment about the vertical z1, at its CoM, in [kg·m²]")
    mp: float = quantity("mass", "mass of the pendulum in [kg]")
    lp: float = quantity("offset", "distance from the pivot to the pendulum's centre of mass in [m]")
    Jpxx: float = quantity("inertia", "pendulum's moment about the hinge axis x2, at its CoM, in [kg·m²]")
    Jpyy: float = quantity("inertia", "pendulum's moment about y2, at its CoM, in [kg·m²]")
    Jpzz: float = quantity("inertia", "pendulum's moment about its own long axis z2, at its CoM, in [kg·m²]")
    br: float = quantity("damping", "viscous friction of the arm's joint in [N·m·s/rad]")
    bp: float = quantity("damping", "viscous friction of the pendulum's joint in [N·m·s/rad]")
    g: float = quantity("gravity", "gravitational acceleration in [m/s²]")


class FurutaPendulum(ClosedFormModel):
    name = "furuta_pendulum"
    params_type = FurutaPendulumParams
    coordinates = ("theta", "alpha")
    angular = (True, True)
    inputs = ("tau",)
    disturbances = ("w",)
    closed_forms: ClassVar[dict[str, ClosedForm]] = {
        **STANDARD_CLOSED_FORMS,
        "generalized_force": ClosedForm("qvuw", "-C*v - H - D*v + B*u + W*w"),
    }

    # the coordinate map to examples/furuta_pendulum.urdf: q = T (θ − θ0), the pendulum's joint hanging at 0
    urdf_joints = ("arm_joint", "pendulum_joint")
    joint_transform = ((1.0, 0.0), (0.0, 1.0))
    joint_offset = (0.0, math.pi)

    def _yaw_inertia(self, q):
        """a(α) = M11: the vertical moment of arm and pendulum about the hub, term by term."""
        p = self.params
        s, c = self.math.sin(q[1]), self.math.cos(q[1])
        return (
            p.Jrzz,
            p.mr * p.cr**2,
            p.mp * p.Lr**2,
            (p.Jpyy + p.mp * p.lp**2) * s**2,
            p.Jpzz * c**2,
        )

    def mass_matrix(self, q):
        p = self.params
        a = sum(self._yaw_inertia(q))
        b = -p.mp * p.Lr * p.lp * self.math.cos(q[1])
        return np.array([[a, b], [b, p.Jpxx + p.mp * p.lp**2]])

    def coriolis_matrix(self, q, v):
        p = self.params
        s, c = self.math.sin(q[1]), self.math.cos(q[1])
        ksc = (p.Jpyy + p.mp * p.lp**2 - p.Jpzz) * s * c
        return np.array(
            [
                [ksc * v[1], ksc * v[0] + p.mp * p.Lr * p.lp * s * v[1]],
                [-ksc * v[0], 0.0],
            ]
        )

    def gravity(self, q):
        p = self.params
        return np.array([0.0, -p.mp * p.g * p.lp * self.math.sin(q[1])])

    def gravity_scale(self):
        p = self.params
        return np.array([0.0, p.mp * p.g * p.lp])

    def potential_energy(self, q):
        p = self.params
        return p.mp * p.g * p.lp * self.math.cos(q[1])

    def damping_matrix(self):
        return np.diag([self.params.br, self.params.bp])

    def input_matrix(self):
        return np.array([[1.0], [0.0]])

    def disturbance_matrix(self):
        return np.array([[0.0], [1.0]])

    def det_mass_matrix(self, q):
        p = self.params
        return (
            sum(self._yaw_inertia(q)) * (p.Jpxx + p.mp * p.lp**2)
            - (p.mp * p.Lr * p.lp * self.math.cos(q[1])) ** 2
        )

    def inverse_mass_matrix(self, q):
        p = self.params
        off = p.mp * p.Lr * p.lp * self.math.cos(q[1])
        adj = np.array([[p.Jpxx + p.mp * p.lp**2, off], [off, sum(self._yaw_inertia(q))]])
        return adj / self.det_mass_matrix(q)

    def generalized_force(self, q, v, u, w):
        """The right-hand side of M q̈ = f: Coriolis and centrifugal, gravity, friction, torques."""
        p = self.params
        s, c = self.math.sin(q[1]), self.math.cos(q[1])
        ksc = (p.Jpyy + p.mp * p.lp**2 - p.Jpzz) * s * c
        return np.array(
            [
                u[0] - p.br * v[0] - 2 * ksc * v[0] * v[1] - p.mp * p.Lr * p.lp * s * v[1] ** 2,
                w[0] - p.bp * v[1] + ksc * v[0] ** 2 + p.mp * p.g * p.lp * s,
            ]
        )

    def acceleration(self, q, v, u, w):
        return self.inverse_mass_matrix(q) @ self.generalized_force(q, v, u, w)

    def diagonal_scale(self, q):
        p = self.params
        return np.array([sum(abs(t) for t in self._yaw_inertia(q)), p.Jpxx + p.mp * p.lp**2])

    def energies(self, q, v, u, w):
        p, cos, sin = self.params, self.math.cos, self.math.sin
        s, c = sin(q[1]), cos(q[1])
        # the pendulum: angular velocity in its own frame, centre-of-mass velocity in the arm's frame
        omega = (v[1], v[0] * s, v[0] * c)
        com = (p.lp * s * v[0], p.Lr * v[0] - p.lp * c * v[1], -p.lp * s * v[1])
        kinetic = (
            (p.Jrzz + p.mr * p.cr**2) * v[0] ** 2
            + p.mp * (com[0] ** 2 + com[1] ** 2 + com[2] ** 2)
            + p.Jpxx * omega[0] ** 2
            + p.Jpyy * omega[1] ** 2
            + p.Jpzz * omega[2] ** 2
        ) / 2
        return Energies(
            kinetic=kinetic,
            potential=p.mp * p.g * p.lp * c,
            dissipation=(p.br * v[0] ** 2 + p.bp * v[1] ** 2) / 2,
            power=u[0] * v[0] + w[0] * v[1],
        )

    def special_states(self):
        pi = math.pi
        return {
            "upright": np.array([0.0, 0.0]),
            "hanging": np.array([0.0, pi]),
            "horizontal": np.array([pi / 2, pi / 2]),
            "tipped back": np.array([-pi / 3, -pi / 2]),
            "arm turned, upright": np.array([pi, 0.0]),
        }


# --- the URDF ---------------------------------------------------------------------------------
def furuta_pendulum_urdf(p: FurutaPendulumParams) -> str:
    """The URDF of a parameter set: arm about +z, pendulum hanging at joint angle 0 about the arm's +x."""

    def num(x: float) -> str:
        return repr(float(x))

    length = max(2 * p.lp, 0.05)
    return f"""<?xml version="1.0"?>
<!-- Generated by examples/furuta_pendulum.py from a furuta_pendulum parameter set; do not edit by hand. -->
<robot name="furuta_pendulum">
  <link name="base">
    <visual>
      <origin xyz="0 0 -0.05" rpy="0 0 0"/>
      <geometry><cylinder radius="0.04" length="0.1"/></geometry>
    </visual>
  </link>
  <joint name="arm_joint" type="revolute">
    <parent link="base"/>
    <child link="arm"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-1e9" upper="1e9" effort="1e9" velocity="1e9"/>
    <dynamics damping="{num(p.br)}"/>
  </joint>
  <link name="arm">
    <inertial>
      <origin xyz="{num(p.cr)} 0 0" rpy="0 0 0"/>
      <mass value="{num(p.mr)}"/>
      <inertia ixx="{num(p.Jrxx)}" ixy="0" ixz="0" iyy="{num(p.Jryy)}" iyz="0" izz="{num(p.Jrzz)}"/>
    </inertial>
    <visual>
      <origin xyz="{num(p.Lr / 2)} 0 0" rpy="0 1.5707963267948966 0"/>
      <geometry><cylinder radius="0.01" length="{num(p.Lr)}"/></geometry>
    </visual>
  </link>
  <joint name="pendulum_joint" type="continuous">
    <parent link="arm"/>
    <child link="pendulum"/>
    <origin xyz="{num(p.Lr)} 0 0" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <dynamics damping="{num(p.bp)}"/>
  </joint>
  <link name="pendulum">
    <inertial>
      <origin xyz="0 0 {num(-p.lp)}" rpy="0 0 0"/>
      <mass value="{num(p.mp)}"/>
      <inertia ixx="{num(p.Jpxx)}" ixy="0" ixz="0" iyy="{num(p.Jpyy)}" iyz="0" izz="{num(p.Jpzz)}"/>
    </inertial>
    <visual>
      <origin xyz="0 0 {num(-length / 2)}" rpy="0 0 0"/>
      <geometry><box size="0.02 0.05 {num(length)}"/></geometry>
    </visual>
  </link>
</robot>
"""


if __name__ == "__main__":  # regenerate examples/furuta_pendulum.urdf from examples/furuta_pendulum.toml
    import pendverify

    here = Path(__file__).resolve().parent
    params = pendverify.load_params(FurutaPendulum, here / "furuta_pendulum.toml")
    (here / "furuta_pendulum.urdf").write_text(furuta_pendulum_urdf(params))
    sys.exit(0)
