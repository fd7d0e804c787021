"""URDFs of gymnasium's cart-pole and acrobot, built from the environments' constants (for the tests).

Shared by the tests that give their dynamics as q̈ alone (``test_acceleration_only.py``) and as
Python functions (``test_python_dynamics.py``); ``env`` is a ``CartPoleEnv`` or an ``AcrobotEnv``.
"""

from __future__ import annotations

import textwrap


def _inertial(mass: float, com_z: float, ixx: float, iyy: float, izz: float) -> str:
    return (
        f'<inertial><origin xyz="0 0 {com_z}"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" iyz="0" izz="{izz}"/></inertial>'
    )


def cart_pole_urdf(env) -> str:
    """The cart on a rail along x, the pole hinged about y, θ = 0 upright and tip at +x for θ > 0."""
    m, half = env.masspole, env.length
    rod = m * (2 * half) ** 2 / 12  # a uniform rod of length 2·length about its centre: gymnasium's 4/3
    return textwrap.dedent(f"""\
        <robot name="gym_cart_pole">
          <link name="world"/>
          <link name="cart">{_inertial(env.masscart, 0, 0.01, 0.01, 0.01)}</link>
          <link name="pole">{_inertial(m, half, rod, rod, 1e-6)}</link>
          <joint name="slider" type="prismatic"><parent link="world"/><child link="cart"/>
            <axis xyz="1 0 0"/><limit lower="-100" upper="100" effort="100" velocity="100"/></joint>
          <joint name="hinge" type="continuous"><parent link="cart"/><child link="pole"/>
            <axis xyz="0 1 0"/></joint>
        </robot>""")


def acrobot_urdf(env) -> str:
    """Two links hanging down at θ = 0 (gymnasium's zero), both joints about y, θ2 relative."""
    moi = env.LINK_MOI
    return textwrap.dedent(f"""\
        <robot name="gym_acrobot">
          <link name="world"/>
          <link name="link1">{_inertial(env.LINK_MASS_1, -env.LINK_COM_POS_1, moi, moi, moi)}</link>
          <link name="link2">{_inertial(env.LINK_MASS_2, -env.LINK_COM_POS_2, moi, moi, moi)}</link>
          <joint name="joint1" type="continuous"><parent link="world"/><child link="link1"/>
            <axis xyz="0 1 0"/></joint>
          <joint name="joint2" type="continuous"><parent link="link1"/><child link="link2"/>
            <origin xyz="0 0 {-env.LINK_LENGTH_1}"/><axis xyz="0 1 0"/></joint>
        </robot>""")
