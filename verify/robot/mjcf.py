"""An MJCF read as MuJoCo means it: compiled by MuJoCo, copied into Pinocchio, cross-checked.

``build_mjcf_model`` runs, in order:

1. the strict reading of the file's numbers, includes expanded (``pendverify.robot.mjcf_rules``,
   ``pendverify.robot.mjcf_origins.expand_includes``): MuJoCo's own parser is lenient;
2. MuJoCo's compiler (``pendverify.robot.mjcf_compile``): includes, default classes,
   ``childclass``, frames, angle units, ``inertiafromgeom``, ``fusestatic``; a compile error is one
   line; what changes M or the bias and cannot be carried over is refused, the rest noted; MuJoCo's
   warnings (a deprecated attribute, an unstable state) are caught and become notes
   (``pendverify.robot.mujoco_warnings``), never a ``MUJOCO_LOG.TXT`` in the working folder;
3. the Pinocchio model built from the compiled ``MjModel`` at full double precision
   (``pendverify.robot.mjcf_pinocchio``);
4. the cross-check of M and the bias forces between MuJoCo and that model on seeded states
   (``pendverify.robot.mjcf_crosscheck``), refusing with the difference;
5. the facts (joint damping and friction loss as MuJoCo resolved them, the file's gravity
   vector) and where each number came from (``pendverify.robot.mjcf_origins``).

``mjcf_visuals`` draws MuJoCo's compiled geoms (boxes, spheres, capsules, cylinders,
ellipsoids; planes and meshes are left out) on the model's body frames, in the colour MuJoCo
shows: a geom's ``rgba`` where it differs from MuJoCo's default, else its material's.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin

from pendverify.robot.mjcf_compile import carried_over, compile_mjcf
from pendverify.robot.mjcf_crosscheck import cross_check
from pendverify.robot.mjcf_origins import DEFAULT, expand_includes, origins
from pendverify.robot.mjcf_pinocchio import body_name, build_pinocchio, joint_name, pose
from pendverify.robot.mjcf_rules import Numbers, check_numbers
from pendverify.robot.mujoco_warnings import caught
from pendverify.robot.strict import DescriptionFacts, JointDynamics
from pendverify.robot.xml_reading import parse_xml


@dataclass
class MjcfReading:
    """What reading an MJCF found besides the Pinocchio model."""

    facts: DescriptionFacts
    notes: list[str] = field(default_factory=list)
    #: "<body or joint>.<quantity>" (and "gravity") → where the number came from
    origins: dict[str, str] = field(default_factory=dict)
    #: the file's text with its includes in place (what a certificate bundles)
    text: str = ""


def build_mjcf_model(
    text: str, source: str, path: Path | None = None
) -> tuple[pin.Model, MjcfReading, list[str]]:
    """(model, reading, log) of an MJCF document (the file at ``path``, whose text is ``text``)."""
    root = parse_xml(text, source)
    has_includes = root.find(".//include") is not None
    expand_includes(root, None if path is None else path.parent, source)
    expanded = ET.tostring(root, encoding="unicode") if has_includes and path is not None else text
    check_numbers(root, Numbers(source))
    with caught() as warnings:
        mj = compile_mjcf(text, None if path is None else str(path), source, has_includes)
        note = carried_over(mj, source)
        model, joints = build_pinocchio(mj)
        cross_check(mj, model, joints, source)
    names = [joint_name(mj, j) for j in joints]
    bodies = [body_name(mj, b) for b in range(1, mj.nbody)]
    provenance = origins(root, bodies, [joint_name(mj, j) for j in range(mj.njnt)])

    def given(name: str, quantity: str, value) -> float | None:
        """``value``, or None where the file (and its classes) leave it at MuJoCo's default."""
        return None if provenance.get(f"{name}.{quantity}") == DEFAULT and value == 0 else float(value)

    dynamics, types = {}, {}
    for k, j in enumerate(joints):
        dof = int(mj.jnt_dofadr[j])
        damping = given(names[k], "damping", mj.dof_damping[dof])
        friction = given(names[k], "frictionloss", mj.dof_frictionloss[dof])
        if damping is not None or friction is not None:
            dynamics[names[k]] = JointDynamics(damping, friction)
        types[names[k]] = "hinge" if model.joints[k + 1].shortname().startswith("JointModelR") else "slide"
    gravity = tuple(float(x) for x in mj.opt.gravity)
    facts = DescriptionFacts(dynamics, types, -gravity[2] + 0.0, gravity)
    notes = [note] if note else []
    notes += [f"MuJoCo warns: {message}" for message in warnings]
    for k, j in enumerate(joints):
        armature = float(mj.dof_armature[int(mj.jnt_dofadr[j])])
        if armature:
            notes.append(
                f"joint {names[k]!r} has armature {armature:g}: it is on M's diagonal (MuJoCo's, Pinocchio's)"
            )
        if mj.qpos0[mj.jnt_qposadr[j]] != 0:
            notes.append(
                f"joint {names[k]!r} has ref = {mj.qpos0[mj.jnt_qposadr[j]]:g}: its q is MuJoCo's qpos − ref"
            )
    return model, MjcfReading(facts, notes, provenance, expanded), []


def mjcf_visuals(model: pin.Model, text: str, source: str) -> pin.GeometryModel:
    """MuJoCo's compiled geoms of an MJCF (read already by ``build_mjcf_model``: ``text`` is its
    text with includes in place, ``source`` its file if it is one) as Pinocchio visuals, each on
    its body's frame of ``model``."""
    import coal

    path = Path(source)
    with caught():  # compiled by build_mjcf_model before: its warnings are noted there
        mj = compile_mjcf(text, str(path) if path.is_file() else None, source, False)
    shapes = {
        int(mujoco.mjtGeom.mjGEOM_SPHERE): lambda s: coal.Sphere(s[0]),
        int(mujoco.mjtGeom.mjGEOM_CAPSULE): lambda s: coal.Capsule(s[0], 2 * s[1]),
        int(mujoco.mjtGeom.mjGEOM_CYLINDER): lambda s: coal.Cylinder(s[0], 2 * s[1]),
        int(mujoco.mjtGeom.mjGEOM_BOX): lambda s: coal.Box(*(2 * np.asarray(s))),
        int(mujoco.mjtGeom.mjGEOM_ELLIPSOID): lambda s: coal.Ellipsoid(*np.asarray(s)),
    }
    visuals = pin.GeometryModel()
    for g in range(mj.ngeom):
        make = shapes.get(int(mj.geom_type[g]))
        if make is None:
            continue
        b = int(mj.geom_bodyid[g])
        if b == 0:
            joint, placement = 0, pose(mj.geom_quat[g], mj.geom_pos[g])
        else:
            frame = model.frames[model.getFrameId(body_name(mj, b), pin.FrameType.BODY)]
            joint, placement = frame.parentJoint, frame.placement * pose(mj.geom_quat[g], mj.geom_pos[g])
        name = mujoco.mj_id2name(mj, mujoco.mjtObj.mjOBJ_GEOM, g) or f"geom{g}"
        obj = pin.GeometryObject(name, joint, placement, make(np.array(mj.geom_size[g], dtype=float)))
        obj.meshColor = _geom_colour(mj, g)
        visuals.addGeometryObject(obj)
    return visuals


#: MuJoCo's default geom rgba: a geom with this colour and a material is shown in the material's
GEOM_DEFAULT_RGBA = (0.5, 0.5, 0.5, 1.0)


def _geom_colour(mj, g: int) -> np.ndarray:
    """The RGBA MuJoCo shows geom ``g`` in: its own ``rgba``, unless that is the default and the
    geom has a material, whose ``rgba`` then applies."""
    own = np.array(mj.geom_rgba[g], dtype=float)
    material = int(mj.geom_matid[g])
    if material >= 0 and np.array_equal(own, np.array(GEOM_DEFAULT_RGBA, dtype=np.float32)):
        return np.array(mj.mat_rgba[material], dtype=float)
    return own
