"""A robot without visual geometry drawn as a skeleton: its joints, the links between them, its masses.

A dynamics-only description (a URDF without ``<visual>``, an MJCF body without geoms, an
SDFormat link without ``<visual>``) still moves; ``with_skeleton`` adds to its visual
``GeometryModel`` plain Pinocchio geometry objects, on the same joints, so that the animation
poses them by forward kinematics as it poses any visual:

* **joint markers**: at each joint's origin, a small dark box elongated along the joint's axis
  (its motion subspace at the neutral configuration, ``pendverify.robot.jacobian``; a cube for
  a joint of several degrees of freedom);
* **links**: a thin cylinder from each joint's origin to the origin of each child joint, and,
  for a body with no child joint (the end of a chain), to its centre of mass; a cylinder runs
  along its own z from the parent end to the child end, so the far end of the last body's
  cylinder is its centre of mass (the tip ``VisualSystem.tip_point`` traces);
* **centres of mass**: a small sphere at each body's centre of mass (bodies fixed to it
  included, as Pinocchio merges them), in the link's colour; a massless body has none;
* a grey cylinder from the world origin to a root joint that stands away from it.

Mixed descriptions: a joint whose body (bodies welded to it included) carries no visual of
its own gets its skeleton; a joint with visuals is drawn by them alone.  So every moving
body is seen, and a description with visuals everywhere is drawn as before.  The note says
which joints are drawn as a skeleton (or that the file has no visual geometry at all).

Sizes scale with the robot: L is the longest joint-to-joint or joint-to-centre-of-mass
offset (``DEFAULT_LENGTH`` when every offset is zero, a point mass on its joint), and the
link radius, marker and sphere sizes are the fractions of L below, chosen to be seen at the
camera distance that frames L (``pendverify.viz.animation.frame_camera``) and thin enough
not to hide each other.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from pendverify.robot.jacobian import joint_jacobian, joint_jacobians

#: L [m] of a robot whose every offset is zero (a point mass on its joint): a cart-sized box
DEFAULT_LENGTH = 0.5
LINK_RADIUS = 0.02  # × L: a rod's radius
MARKER_HALF = (0.05, 0.05, 0.12)  # × L: half sides of a joint marker, the long one along its axis
COM_RADIUS = 0.07  # × L: a centre-of-mass sphere
JOINT_RGBA = (0.2, 0.2, 0.2, 1.0)  # dark grey: the joints
BASE_RGBA = (0.5, 0.5, 0.5, 1.0)  # mid grey: the world to a root joint
PREFIX = "skeleton"


def with_skeleton(
    model: pin.Model, visuals: pin.GeometryModel, colours: tuple[tuple[float, ...], ...], source: str
) -> tuple[pin.GeometryModel, tuple[str, ...]]:
    """``visuals`` plus a skeleton for each moving joint that carries no visual, and the note.

    ``colours`` are the links' RGBA, one per joint in turn (cycled); ``source`` names the
    description in the note."""
    drawn = {obj.parentJoint for obj in visuals.geometryObjects}
    bare = [j for j in range(1, model.njoints) if j not in drawn]
    if not bare:
        return visuals, ()
    out = visuals.copy()
    data = model.createData()
    joint_jacobians(model, data, pin.neutral(model))  # the axes, at the neutral configuration
    length = _robot_length(model)
    children: dict[int, list[int]] = {j: [] for j in range(model.njoints)}
    for c in range(1, model.njoints):
        children[model.parents[c]].append(c)
    for j in bare:
        colour = colours[(j - 1) % len(colours)]
        frame = _joint_frame(model, j)
        _add(out, f"joint_{model.names[j]}", j, frame, *_marker(model, data, j, length), JOINT_RGBA)
        ends = [model.jointPlacements[c].translation for c in children[j]]
        inertia = model.inertias[j]
        if not children[j] and inertia.mass > 0:
            ends.append(inertia.lever)
        for k, end in enumerate(ends):
            rod = _rod(np.zeros(3), np.asarray(end, dtype=float), LINK_RADIUS * length)
            if rod is not None:
                _add(out, f"link_{model.names[j]}_{k}", j, frame, *rod, colour)
        if inertia.mass > 0:
            at = pin.SE3(np.eye(3), np.asarray(inertia.lever, dtype=float))
            _add(out, f"com_{model.names[j]}", j, frame, at, coal.Sphere(COM_RADIUS * length), colour)
    for c in children[0]:
        rod = _rod(np.zeros(3), model.jointPlacements[c].translation, LINK_RADIUS * length)
        if rod is not None and c in bare:
            _add(out, f"base_{model.names[c]}", 0, 0, *rod, BASE_RGBA)
    return out, (_note(model, bare, not visuals.geometryObjects, source),)


def _note(model: pin.Model, bare: list[int], none: bool, source: str) -> str:
    if none:
        return (
            f"{source} has no visual geometry: a skeleton is drawn (joints as dark boxes along their "
            "axes, links as rods, centres of mass as spheres)"
        )
    names = ", ".join(model.names[j] for j in bare)
    return (
        f"{source} has no visual geometry on the bodies of joint(s) {names}: they are drawn as a "
        "skeleton (joint boxes, rods, centres of mass)"
    )


def _robot_length(model: pin.Model) -> float:
    """L of the module docstring, in [m]."""
    offsets = [np.linalg.norm(model.jointPlacements[j].translation) for j in range(1, model.njoints)]
    offsets += [np.linalg.norm(model.inertias[j].lever) for j in range(1, model.njoints)]
    longest = max(offsets, default=0.0)
    return float(longest) if np.isfinite(longest) and longest > 0 else DEFAULT_LENGTH


def _joint_frame(model: pin.Model, j: int) -> int:
    """The index of joint ``j``'s own frame (every joint has one in a Pinocchio model)."""
    for index, frame in enumerate(model.frames):
        if frame.type == pin.FrameType.JOINT and frame.parentJoint == j:
            return index
    return 0


def _marker(model: pin.Model, data: pin.Data, j: int, length: float) -> tuple[pin.SE3, coal.Box]:
    """A box at joint ``j``'s origin, its long side along the joint's axis (a cube if it has none)."""
    joint = model.joints[j]
    half = np.array(MARKER_HALF) * length
    if joint.nv != 1:
        return pin.SE3.Identity(), coal.Box(*(2 * np.full(3, half[0])))
    motion = joint_jacobian(model, data, j, pin.LOCAL)[:, joint.idx_v]
    axis = motion[3:] if np.linalg.norm(motion[3:]) > 0 else motion[:3]
    return _along(axis), coal.Box(*(2 * half))


def _along(direction: np.ndarray) -> pin.SE3:
    """A rotation taking z onto ``direction`` (not zero), at the origin."""
    rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), direction / np.linalg.norm(direction))
    return pin.SE3(rotation.toRotationMatrix(), np.zeros(3))


def _rod(start: np.ndarray, end: np.ndarray, radius: float) -> tuple[pin.SE3, coal.Cylinder] | None:
    """A cylinder from ``start`` to ``end`` (its z from start to end), or None if they coincide."""
    span = np.asarray(end, dtype=float) - np.asarray(start, dtype=float)
    length = float(np.linalg.norm(span))
    if not np.isfinite(length) or length == 0.0:
        return None
    placement = _along(span)
    placement.translation = (np.asarray(start, dtype=float) + np.asarray(end, dtype=float)) / 2
    return placement, coal.Cylinder(radius, length)


def _add(out: pin.GeometryModel, name: str, joint: int, frame: int, placement, geometry, rgba) -> None:
    """Add one skeleton object of colour ``rgba``, named ``skeleton_NAME`` (numbered if taken)."""
    unique, k = f"{PREFIX}_{name}", 1
    while out.existGeometryName(unique):
        unique, k = f"{PREFIX}_{name}_{k}", k + 1
    obj = pin.GeometryObject(unique, joint, frame, placement, geometry)
    obj.meshColor = np.array(rgba, dtype=float)
    out.addGeometryObject(obj)
