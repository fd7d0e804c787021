"""A robot description as Pinocchio will use it, each number with where it came from.

``robot_summary`` walks a ``LoadedDescription``'s Pinocchio model (its fixed base already at
the origin) joint by joint and gives, for each, what the checks evaluate:

* the joint's type, its parent joint, its placement in the parent's frame (``xyz`` and
  roll-pitch-yaw, Pinocchio's ``jointPlacements``) and its axis: the joint's motion subspace
  S at the neutral configuration, expressed in the joint's own frame — the angular part for a
  revolute joint, the linear part for a prismatic one;
* the body the joint carries: mass, centre of mass (in the joint's frame) and the inertia
  tensor about the centre of mass in the joint's frame (Ixx Iyy Izz Ixy Ixz Iyz), bodies
  welded to it by fixed joints included (Pinocchio merges them);
* damping, armature and Coulomb friction (``model.damping``, ``armature``, ``friction``);

and the description's gravity vector.  Each quantity carries its origin: the description's
``origins`` map where its reader recorded one (an MJCF: written in the file, computed by
MuJoCo from geoms, resolved from a default class), else the format's own (written in the
file; for xacro, expanded by xacro; a damping a URDF leaves out is "absent: 0").
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pendverify.robot.description import READERS, LoadedDescription
from pendverify.robot.jacobian import joint_jacobian, joint_jacobians

#: format → where a number of its model came from, unless its reader recorded otherwise
DEFAULT_ORIGINS = {
    "urdf": "written in the file",
    "xacro": "expanded by xacro",
    "mjcf": "compiled by MuJoCo",
    "sdf": "read by the SDFormat reader",
    "pinocchio": "given as a Pinocchio model",
}
#: what each quantity's numbers are, for the reader of a summary
LEGEND = (
    "frame: the joint's placement in its parent joint's frame, xyz [m] then roll pitch yaw [rad]; "
    "axis: in the joint's frame; mass, com and inertia: the body the joint moves (bodies fixed to it "
    "included), com and inertia (Ixx Iyy Izz Ixy Ixz Iyz, about the centre of mass) in the joint's frame"
)
QUANTITIES = ("frame", "axis", "mass", "com", "inertia", "damping", "armature", "frictionloss")


@dataclass(frozen=True)
class Quantity:
    """One number (or vector) of the model, with its unit and where it came from."""

    name: str
    value: tuple[float, ...]
    unit: str
    origin: str


@dataclass(frozen=True)
class JointSummary:
    name: str
    kind: str
    parent: str
    quantities: tuple[Quantity, ...]


@dataclass(frozen=True)
class RobotSummary:
    source: str
    format: str
    joints: tuple[JointSummary, ...]
    gravity: Quantity | None
    notes: tuple[str, ...]
    legend: str = LEGEND

    @property
    def reader(self) -> str:
        """The format's name in messages (``URDF``, ``MJCF`` …)."""
        return READERS.get(self.format, self.format)


def robot_summary(loaded: LoadedDescription) -> RobotSummary:
    """What Pinocchio will use of ``loaded``, joint by joint (see the module docstring)."""
    model = loaded.model
    data = model.createData()
    joint_jacobians(model, data, pin.neutral(model))
    joints = tuple(_joint(loaded, data, j) for j in range(1, model.njoints))
    return RobotSummary(loaded.source, loaded.format, joints, _gravity(loaded), tuple(loaded.notes()))


def _origin(loaded: LoadedDescription, owner: str, quantity: str) -> str:
    recorded = getattr(loaded, "origins", None) or {}
    if f"{owner}.{quantity}" in recorded:
        return recorded[f"{owner}.{quantity}"]
    if quantity in ("damping", "frictionloss") and loaded.format in ("urdf", "xacro"):
        written = loaded.facts.joint_dynamics.get(owner)
        value = None if written is None else (written.damping if quantity == "damping" else written.friction)
        if value is None:
            return "absent from the file: 0"
    if quantity == "armature" and loaded.format in ("urdf", "xacro"):
        return "a URDF has none: 0"
    return DEFAULT_ORIGINS.get(loaded.format, "read from the file")


def _joint(loaded: LoadedDescription, data: pin.Data, j: int) -> JointSummary:
    model = loaded.model
    joint = model.joints[j]
    name = model.names[j]
    subspace = joint_jacobian(model, data, j, pin.LOCAL)[:, joint.idx_v : joint.idx_v + joint.nv]
    linear, angular = subspace[:3, 0], subspace[3:, 0]
    revolute = bool(np.linalg.norm(angular) > 0)
    kind = "revolute" if revolute else "prismatic"
    if joint.nq == 2 and joint.nv == 1:
        kind = "continuous"
    if joint.nv != 1:
        kind = joint.shortname()
    placement = model.jointPlacements[j]
    inertia = model.inertias[j]
    tensor = inertia.inertia
    v = joint.idx_v
    values = {
        "frame": (*placement.translation, *pin.rpy.matrixToRpy(placement.rotation)),
        "axis": tuple(angular if revolute else linear),
        "mass": (inertia.mass,),
        "com": tuple(inertia.lever),
        "inertia": (tensor[0, 0], tensor[1, 1], tensor[2, 2], tensor[0, 1], tensor[0, 2], tensor[1, 2]),
        "damping": (model.damping[v],),
        "armature": (model.armature[v],),
        "frictionloss": (model.friction[v],),
    }
    units = {
        "frame": "m, rad",
        "axis": "-",
        "mass": "kg",
        "com": "m",
        "inertia": "kg·m²",
        "damping": "N·m·s/rad" if revolute else "N·s/m",
        "armature": "kg·m²" if revolute else "kg",
        "frictionloss": "N·m" if revolute else "N",
    }
    body = model.frames[_body_frame(model, j)].name if _body_frame(model, j) is not None else name
    quantities = tuple(
        Quantity(
            q,
            tuple(float(x) for x in values[q]),
            units[q],
            _origin(loaded, body if q in ("mass", "com", "inertia") else name, q),
        )
        for q in QUANTITIES
    )
    parent = model.names[model.parents[j]] if model.parents[j] > 0 else "the fixed base"
    return JointSummary(name, kind, parent, quantities)


def _body_frame(model: pin.Model, j: int) -> int | None:
    """The first body frame attached to joint ``j`` (the link it moves), if the reader made one."""
    for index, frame in enumerate(model.frames):
        if frame.parentJoint == j and frame.type == pin.FrameType.BODY:
            return index
    return None


def _gravity(loaded: LoadedDescription) -> Quantity | None:
    facts = loaded.facts
    if facts.gravity_vector is not None:
        vector = np.asarray(facts.gravity_vector, dtype=float)
    elif facts.gravity is not None:  # a scalar g: the description's gravity along −z
        vector = np.array([0.0, 0.0, -float(facts.gravity)])
    else:
        return None
    recorded = getattr(loaded, "origins", None) or {}
    origin = recorded.get("gravity", DEFAULT_ORIGINS.get(loaded.format, "read from the file"))
    return Quantity("gravity", tuple(float(x) for x in vector), "m/s²", origin)
