"""Robots of one degree of freedom, with their hand models, for the tests of every command on them.

* ``pendulum``: the single pendulum of a dynamics-only URDF (no ``<visual>``): a continuous hinge
  about +y, a point mass m = 2 kg at r = 0.5 m below it, damping 0.1 N·m·s/rad.  θ is the hinge
  angle (θ = 0 hanging): M = m r², H = m g r sin θ, V = −m g r cos θ.
* ``cart``: a cart on a rail along x (prismatic, no ``<visual>``), m = 1.5 kg, damping
  0.3 N·s/m: M = m, H = 0.
* ``dm_pendulum``: dm_control's ``suite/pendulum.xml`` (MJCF, with geoms): a hinge about +y, a
  1 kg sphere of radius 0.05 m (I = 2/5·m·0.05² = 0.001 kg·m²) at 0.5 m *above* the hinge at
  q = 0, damping 0.1; the same model as the pendulum's with θ = q + π (``joint_offset``).

Each is written into a folder as a model file, a parameter file and its robot file
(``OneJoint.files``), with a short scene (``OneJoint.scene``).  ``PLANTED_M`` is the mass
matrix 1 % too heavy, the error ``check`` must catch on each.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

PENDULUM_URDF = """<robot name="pend"><link name="base"/>
  <joint name="hinge" type="continuous"><parent link="base"/><child link="bob"/><axis xyz="0 1 0"/>
    <dynamics damping="0.1"/></joint>
  <link name="bob"><inertial><origin xyz="0 0 -0.5"/><mass value="2.0"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link></robot>
"""

CART_URDF = """<robot name="cart"><link name="rail"/>
  <joint name="slider" type="prismatic"><parent link="rail"/><child link="cart"/><axis xyz="1 0 0"/>
    <limit lower="-10" upper="10" effort="100" velocity="100"/><dynamics damping="0.3"/></joint>
  <link name="cart"><inertial><origin xyz="0 0 0"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link></robot>
"""

PENDULUM_MODEL = '''"""A single pendulum: θ the hinge angle, θ = 0 hanging."""

import dataclasses
import math

import numpy as np

from pendverify.analytic import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class SinglePendulumParams(ParameterSet):
    model = "single_pendulum"

    m: float = quantity("mass", "mass of the bob in [kg]")
    r: float = quantity("offset", "pivot to the centre of mass in [m]")
    I: float = quantity("inertia", "inertia about the centre of mass in [kg·m²]")  # noqa: E741
    b: float = quantity("damping", "pivot friction in [N·m·s/rad]")
    g: float = quantity("gravity", "in [m/s²]")


class SinglePendulum(ClosedFormModel):
    name = "single_pendulum"
    params_type = SinglePendulumParams
    coordinates = ("theta",)
    angular = (True,)
    inputs = ("tau",)
    urdf_joints = ("hinge",)
    joint_offset = ({offset},)

    def mass_matrix(self, q):
        p = self.params
        return np.array([[{scale}(p.I + p.m * p.r**2)]])

    def coriolis_matrix(self, q, v):
        return np.zeros((1, 1))

    def gravity(self, q):
        p = self.params
        return np.array([p.m * p.g * p.r * self.math.sin(q[0])])

    def potential_energy(self, q):
        p = self.params
        return -p.m * p.g * p.r * self.math.cos(q[0])

    def damping_matrix(self):
        return np.array([[self.params.b]])

    def input_matrix(self):
        return np.array([[1.0]])

    def special_states(self):
        return {{"hanging": np.array([0.0]), "upright": np.array([math.pi])}}
'''

CART_MODEL = '''"""A cart on a horizontal rail: x along it."""

import dataclasses

import numpy as np

from pendverify.analytic import ClosedFormModel
from pendverify.analytic.parameter_set import ParameterSet, quantity


@dataclasses.dataclass(frozen=True)
class CartParams(ParameterSet):
    model = "cart"

    m: float = quantity("mass", "mass of the cart in [kg]")
    b: float = quantity("damping", "rail friction in [N·s/m]")
    g: float = quantity("gravity", "in [m/s²]")


class Cart(ClosedFormModel):
    name = "cart"
    params_type = CartParams
    coordinates = ("x",)
    angular = (False,)
    inputs = ("u",)
    urdf_joints = ("slider",)

    def mass_matrix(self, q):
        return np.array([[{scale}self.params.m]])

    def coriolis_matrix(self, q, v):
        return np.zeros((1, 1))

    def gravity(self, q):
        return np.zeros(1)

    def potential_energy(self, q):
        return 0.0

    def damping_matrix(self):
        return np.array([[self.params.b]])

    def input_matrix(self):
        return np.array([[1.0]])
'''

PLANTED_M = "1.01 * "  # the mass matrix 1 % too heavy


@dataclass(frozen=True)
class OneJoint:
    """A one-joint robot and its model, written into ``folder``."""

    name: str
    folder: Path
    robot: Path  # the URDF or MJCF
    initial: float  # θ or x at the start of the scene

    @property
    def model(self) -> Path:
        return self.folder / "model.py"

    @property
    def params(self) -> Path:
        return self.folder / "params.toml"

    def files(self) -> list[str]:
        return ["--analytic", str(self.model), "--urdf", str(self.robot), "--params", str(self.params)]

    def scene(self, duration: float = 0.5) -> Path:
        path = self.folder / "scenes" / f"{self.name}.toml"
        path.parent.mkdir(exist_ok=True)
        path.write_text(
            f'name = "{self.name} swing"\nmodel = "{self.model}"\nparams = "{self.params}"\n'
            f'urdf = "{self.robot}"\nengine = "both"\n[initial]\nq = [{self.initial}]\nv = [0.5]\n'
            f"[time]\nduration = {duration}\nsample_rate = 50.0\n"
            '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
            "[effects]\ngravity = true\ndamping = true\n"
        )
        return path


def dm_control_pendulum() -> Path | None:
    """dm_control's pendulum MJCF, if dm_control is installed (it is in the test extra)."""
    try:
        import dm_control
    except ImportError:
        return None
    return Path(dm_control.__file__).parent / "suite" / "pendulum.xml"


def write_one_joint(name: str, folder: Path, planted: bool = False) -> OneJoint:
    """``pendulum``, ``cart`` or ``dm_pendulum`` (see the module docstring) in ``folder``;
    ``planted``: its model's M is ``PLANTED_M``."""
    folder.mkdir(parents=True, exist_ok=True)
    scale = PLANTED_M if planted else ""
    if name == "cart":
        robot = folder / "cart.urdf"
        robot.write_text(CART_URDF)
        model, params, initial = CART_MODEL.format(scale=scale), "m = 1.5\nb = 0.3\ng = 9.81\n", 0.0
    elif name == "pendulum":
        robot = folder / "pend.urdf"
        robot.write_text(PENDULUM_URDF)
        model = PENDULUM_MODEL.format(offset=0.0, scale=scale)
        params, initial = "m = 2.0\nr = 0.5\nI = 0.0\nb = 0.1\ng = 9.81\n", 1.0
    else:
        robot = dm_control_pendulum()
        model = PENDULUM_MODEL.format(offset="math.pi", scale=scale)
        params, initial = "m = 1.0\nr = 0.5\nI = 0.001\nb = 0.1\ng = 9.81\n", 1.0
    (folder / "model.py").write_text(model)
    model_name = "cart" if name == "cart" else "single_pendulum"
    (folder / "params.toml").write_text(f'model = "{model_name}"\n[parameters]\n{params}')
    return OneJoint(name, folder, robot, initial)
