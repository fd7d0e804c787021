"""An MJCF compiled by MuJoCo's own compiler, and what of it Pinocchio's model can carry.

``compile_mjcf`` loads the file with ``mujoco.MjModel.from_xml_path`` (includes resolve relative
to the file) or, for XML text with no file, ``from_xml_string`` (then an ``<include>`` is refused:
there is no folder to resolve it in).  A compile error is one ``UrdfShapeError`` line naming the
file and MuJoCo's message.

``carried_over`` then sorts the compiled model's features:

* **refused**, because they change M or the bias forces and Pinocchio's model of the chain has
  no place for them: free and ball joints (not a chain's one-degree-of-freedom joints), more
  than one joint in a body, joint springs (``stiffness``), tendons with inertia (``armature``)
  or stiffness, gravity compensation (``gravcomp``), fluid forces (``<option density>`` or
  ``viscosity`` non-zero), equality constraints, mocap bodies, flexes and plugins, and a
  ``<flag gravity="disable">`` (MuJoCo's bias would then hold no gravity);
* **noted, in one sentence**, because they change neither M nor the bias: joint limits,
  contacts and geoms, actuators (their own dynamics; the hand model's B is its own), sensors
  and tendons without inertia or stiffness.
"""

from __future__ import annotations

import mujoco
import numpy as np

from pendverify.errors import UrdfShapeError
from pendverify.robot.mjcf_pinocchio import HINGE, SLIDE, body_name, joint_name

_TYPES = {int(mujoco.mjtJoint.mjJNT_FREE): "free", int(mujoco.mjtJoint.mjJNT_BALL): "ball"}


def compile_mjcf(text: str, path: str | None, source: str, has_includes: bool) -> mujoco.MjModel:
    """MuJoCo's compiled model of the file at ``path`` (or of ``text`` when there is no file)."""
    if path is None and has_includes:
        raise UrdfShapeError(
            source, "<include>: MJCF text given without its file has no folder to resolve includes in"
        )
    try:
        if path is not None:
            return mujoco.MjModel.from_xml_path(path)
        return mujoco.MjModel.from_xml_string(text)
    except ValueError as exc:
        message = " ".join(str(exc).split())
        raise UrdfShapeError(source, f"MuJoCo's compiler refuses it: {message}") from None


def carried_over(mj: mujoco.MjModel, source: str) -> str:
    """Refuse what changes M or the bias and cannot be carried over; the one note on the rest."""

    def refuse(place: str, why: str):
        raise UrdfShapeError(source, f"{place}: refused ({why})")

    for j in range(mj.njnt):
        kind = int(mj.jnt_type[j])
        name = joint_name(mj, j)
        if kind not in (HINGE, SLIDE):
            refuse(f"joint {name!r} type = '{_TYPES[kind]}'", "hinge and slide joints only: a chain's joints")
        if mj.jnt_stiffness[j] != 0:
            refuse(
                f"joint {name!r} stiffness = {mj.jnt_stiffness[j]:g}",
                "a joint spring changes the forces on the chain and the closed form's M, C, H have no place "
                "for it",
            )
    for b in range(1, mj.nbody):
        if mj.body_jntnum[b] > 1:
            refuse(f"body {body_name(mj, b)!r}", f"it has {mj.body_jntnum[b]} joints; one joint per body")
        if mj.body_gravcomp[b] != 0:
            refuse(f"body {body_name(mj, b)!r} gravcomp = {mj.body_gravcomp[b]:g}", "gravity compensation")
        if mj.body_mocapid[b] >= 0:
            refuse(f"body {body_name(mj, b)!r} mocap", "a mocap body is driven, not simulated")
    for t in range(mj.ntendon):
        for what, values in (("armature", mj.tendon_armature), ("stiffness", mj.tendon_stiffness)):
            if np.any(values[t] != 0):
                name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_TENDON, t) or f"tendon {t}"
                refuse(f"tendon {name!r} {what}", f"a tendon's {what} changes M or the bias forces")
    for what in ("density", "viscosity"):
        if getattr(mj.opt, what) != 0:
            refuse(f"<option> {what} = {getattr(mj.opt, what):g}", "fluid forces: Pinocchio has none")
    if mj.neq:
        refuse("<equality>", "an equality constraint ties the joints; the chain's model leaves it out")
    if mj.nflex:
        refuse("<flex>/<deformable>", "deformable bodies are not rigid links")
    if mj.nplugin:
        refuse("<extension>/<plugin>", "a plugin may add forces Pinocchio's model leaves out")
    if mj.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_GRAVITY):
        refuse("<option><flag> gravity = 'disable'", "MuJoCo's bias would hold no gravity, the file's does")
    return _not_carried_note(mj)


def _count(n: int, noun: str) -> str:
    """ "1 geom", "5 geoms": a count with its noun."""
    return f"{n} {noun}{'s' if n != 1 else ''}"


def _not_carried_note(mj: mujoco.MjModel) -> str:
    parts = []
    limited = [joint_name(mj, j) for j in range(mj.njnt) if mj.jnt_limited[j]]
    if limited:
        parts.append(f"the limits of {', '.join(limited)}")
    if mj.ngeom:
        parts.append(f"the contacts of {_count(mj.ngeom, 'geom')} (their shapes are drawn by render)")
    if mj.nu:
        parts.append(f"the own dynamics of {_count(mj.nu, 'actuator')} (the hand model's B is its own)")
    if mj.nsensor:
        parts.append(_count(mj.nsensor, "sensor"))
    if mj.ntendon:
        parts.append(f"{mj.ntendon} tendons without inertia or stiffness")
    if not parts:
        return ""
    return "not verified, as they change neither M nor the bias forces: " + "; ".join(parts)
