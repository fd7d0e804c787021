"""A ``pinocchio.Model`` built from a compiled ``mujoco.MjModel``, number for number.

MuJoCo's compiler has already resolved includes, default classes, ``childclass``, frames,
angle units, ``inertiafromgeom`` and ``fusestatic``: what is left is a tree of bodies, each
with a pose in its parent (``body_pos``, ``body_quat``), at most the joints it carries, and an
inertia (``body_mass`` at ``body_ipos``, principal moments ``body_inertia`` in the frame
``body_iquat``), all in double precision.  This module copies that tree into Pinocchio:

* **Frames.**  Body b's frame in its parent's is P_b = (R(body_quat), body_pos).  A hinge or
  slide joint sits at ``jnt_pos`` in b's frame, with axis ``jnt_axis`` (unit, in b's frame).
  MuJoCo moves b as  X_parent←b(q) = P_b · T(jnt_pos) · J(axis, q − qpos0) · T(−jnt_pos).
  The Pinocchio joint of b is placed at  P_b · T(jnt_pos)  in its parent joint's frame (after
  the parent body's own offset, below), and b's frame is  B_b = T(−jnt_pos)  in that joint's
  frame.  A body without a joint is welded to its parent: B_b = B_parent · P_b on the parent's
  joint, and its inertia is added there (a body welded to the world moves nothing).
* **Joints.**  A hinge is ``JointModelRX``/``RY``/``RZ`` when ``jnt_axis`` is exactly a unit
  vector of the frame, else ``JointModelRevoluteUnaligned``; a slide likewise ``PX``/``PY``/``PZ``
  or ``JointModelPrismaticUnaligned``.  Pinocchio's q is MuJoCo's ``qpos − qpos0`` (``qpos0`` is
  a joint's ``ref``; 0 unless the file sets it), so q = 0 is the pose the file draws.
* **Inertia.**  I_b = (m, c = ``body_ipos``, R(body_iquat) diag(``body_inertia``) Rᵀ) in b's frame,
  carried into the joint frame by B_b and summed onto the joint's body.
* **Joint dynamics.**  ``dof_damping``, ``dof_armature`` and ``dof_frictionloss`` go into
  ``model.damping``, ``model.armature`` (Pinocchio's CRBA adds it to M's diagonal, as MuJoCo's
  ``mj_fullM`` does) and ``model.friction``.
* **Gravity.**  ``opt.gravity``, the full vector.
* **Names.**  Joints keep their names (an unnamed one is ``<body>Joint_0``, the name Pinocchio's
  own MJCF reader gives it); each body becomes a ``BODY`` frame of its name (``body<b>`` if
  unnamed), which the visuals are attached to.

What this module cannot carry (free and ball joints, several joints in one body) is refused by
``pendverify.robot.mjcf_compile`` before this runs.
"""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin

#: MuJoCo's joint types as ``jnt_type`` holds them
HINGE, SLIDE = int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)
_ALIGNED = {
    HINGE: (pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ),
    SLIDE: (pin.JointModelPX, pin.JointModelPY, pin.JointModelPZ),
}


def body_name(mj: mujoco.MjModel, b: int) -> str:
    return mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}"


def joint_name(mj: mujoco.MjModel, j: int) -> str:
    name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_JOINT, j)
    return name or f"{body_name(mj, int(mj.jnt_bodyid[j]))}Joint_0"


def rotation(quat) -> np.ndarray:
    """The rotation matrix of a MuJoCo quaternion (w, x, y, z), normalised by MuJoCo's compiler."""
    w, x, y, z = (float(c) for c in quat)
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


def pose(quat, pos) -> pin.SE3:
    return pin.SE3(rotation(quat), np.array(pos, dtype=float))


def joint_model(kind: int, axis: np.ndarray):
    """Pinocchio's joint for a hinge or slide about/along the unit ``axis``."""
    for k in range(3):
        if np.array_equal(axis, np.eye(3)[k]):
            return _ALIGNED[kind][k]()
    if kind == HINGE:
        return pin.JointModelRevoluteUnaligned(axis)
    return pin.JointModelPrismaticUnaligned(axis)


def body_inertia(mj: mujoco.MjModel, b: int) -> pin.Inertia:
    """Body b's spatial inertia in its own frame."""
    R = rotation(mj.body_iquat[b])
    return pin.Inertia(
        float(mj.body_mass[b]), np.array(mj.body_ipos[b], dtype=float), R @ np.diag(mj.body_inertia[b]) @ R.T
    )


def build_pinocchio(mj: mujoco.MjModel) -> tuple[pin.Model, list[int]]:
    """(the Pinocchio model of ``mj``, the MuJoCo joint of each Pinocchio joint 1..n)."""
    model = pin.Model()
    model.name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_MODEL, 0) or "mjcf"
    #: MuJoCo body → (its Pinocchio joint, its frame in that joint's frame, the Pinocchio frame id)
    joint_of, frame_in = [0], [pin.SE3.Identity()]
    frame_ids = [0]
    joints: list[int] = []
    damping, armature, friction = [], [], []
    for b in range(1, mj.nbody):
        parent = int(mj.body_parentid[b])
        placed = frame_in[parent] * pose(mj.body_quat[b], mj.body_pos[b])
        if mj.body_jntnum[b] == 0:
            joint, in_joint = joint_of[parent], placed
        else:
            j = int(mj.body_jntadr[b])
            offset = np.array(mj.jnt_pos[j], dtype=float)
            axis = np.array(mj.jnt_axis[j], dtype=float)
            placement = placed * pin.SE3(np.eye(3), offset)
            joint = model.addJoint(
                joint_of[parent], joint_model(int(mj.jnt_type[j]), axis), placement, joint_name(mj, j)
            )
            in_joint = pin.SE3(np.eye(3), -offset)
            joint_frame = model.addJointFrame(joint, frame_ids[parent])
            joints.append(j)
            dof = int(mj.jnt_dofadr[j])
            damping.append(mj.dof_damping[dof])
            armature.append(mj.dof_armature[dof])
            friction.append(mj.dof_frictionloss[dof])
        parent_frame = frame_ids[parent] if mj.body_jntnum[b] == 0 else joint_frame
        if joint != 0:
            model.appendBodyToJoint(joint, in_joint.act(body_inertia(mj, b)), pin.SE3.Identity())
        frame = pin.Frame(body_name(mj, b), joint, parent_frame, in_joint, pin.FrameType.BODY)
        frame_ids.append(model.addFrame(frame, False))
        joint_of.append(joint)
        frame_in.append(in_joint)
    model.damping = np.array(damping, dtype=float)
    model.armature = np.array(armature, dtype=float)
    model.friction = np.array(friction, dtype=float)
    model.gravity.linear = np.array(mj.opt.gravity, dtype=float)
    return model, joints


def pinocchio_configuration(mj: mujoco.MjModel, joints: list[int], q) -> np.ndarray:
    """MuJoCo's ``qpos`` for Pinocchio's q (``qpos0 + q``, one entry per joint)."""
    qpos = np.array(mj.qpos0, dtype=float)
    for k, j in enumerate(joints):
        qpos[mj.jnt_qposadr[j]] += q[k]
    return qpos
