"""A robot given as a Pinocchio object: a ``pinocchio.Model`` (with its visual ``GeometryModel``) or a
``pinocchio.RobotWrapper``, as example-robot-data's and robot_descriptions' loaders return it.

``describe_model`` makes it a ``LoadedDescription`` like a file's, so every function that takes a
URDF takes it too:

* format ``"pinocchio"``; ``source`` ``<pinocchio.Model 'NAME'>`` (the model's ``name``);
* the model is a copy (the caller's is never changed: anchoring the base and setting gravity
  act on the copy), its fixed base anchored at the origin as a file's is;
* the joints' facts come from ``model.damping`` and ``model.friction`` (one entry per joint
  of one degree of freedom).  Pinocchio keeps an absent damping as 0, so a 0 here cannot be
  told from "not given": a joint's damping (friction) is *declared* when it is non-zero, and
  the notes say so.  A joint of several degrees of freedom, or a model with ``nq != nv``
  (a free-flyer, a continuous joint), is refused by the coordinate maps that follow, as a
  file's would be;
* ``text``: the URDF text the model was built from when the caller knows it (``urdf_text``);
  otherwise empty, and the notes say that no URDF text is known — a certificate needs one,
  ``pendverify.certify.issue`` refuses the model without it;
* the model's own gravity is not a fact of the description (a URDF sets none, and Pinocchio's
  default is 9.81 m/s²): the closed form's g is used, as for a URDF.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pendverify.display import shortened
from pendverify.errors import PendverifyError
from pendverify.robot.description import LoadedDescription, anchor_base, load_description
from pendverify.robot.strict import DescriptionFacts, JointDynamics

FORMAT = "pinocchio"


@dataclass(frozen=True)
class PinocchioRobot:
    """A Pinocchio model as the caller gave it, with what is known beside it.

    ``visual_model``: its visual geometry (drawn by ``render``), or None; ``urdf_text``: the
    URDF it was built from, or None (a certificate embeds it)."""

    model: pin.Model
    visual_model: pin.GeometryModel | None = None
    urdf_text: str | None = None


def is_pinocchio_object(value: object) -> bool:
    """Whether ``value`` is a ``pinocchio.Model``, a ``RobotWrapper`` or a ``PinocchioRobot``."""
    return isinstance(value, (pin.Model, pin.RobotWrapper, PinocchioRobot))


def as_robot(value: object) -> PinocchioRobot:
    """A ``pinocchio.Model``, ``RobotWrapper`` (its ``model`` and ``visual_model``) or ``PinocchioRobot``."""
    if isinstance(value, PinocchioRobot):
        return value
    if isinstance(value, pin.Model):
        return PinocchioRobot(value)
    if isinstance(value, pin.RobotWrapper):
        visual = getattr(value, "visual_model", None)
        return PinocchioRobot(value.model, visual if isinstance(visual, pin.GeometryModel) else None)
    raise PendverifyError(
        f"a Pinocchio robot is a pinocchio.Model or RobotWrapper; got a {type(value).__name__}"
    )


def source_of(model: pin.Model) -> str:
    """``<pinocchio.Model 'NAME'>``: how messages name a model given as an object."""
    return f"<pinocchio.Model {shortened(model.name or 'unnamed', 60)!r}>"


def describe_model(value: object) -> LoadedDescription:
    """A ``LoadedDescription`` of a Pinocchio object (see the module docstring)."""
    robot = as_robot(value)
    model = robot.model.copy()
    source = source_of(model)
    if robot.urdf_text is not None and not isinstance(robot.urdf_text, str):
        raise PendverifyError(
            f"{source}: urdf_text is the URDF's text; got a {type(robot.urdf_text).__name__}"
        )
    dynamics, types = {}, {}
    for j in range(1, model.njoints):
        joint = model.joints[j]
        name = model.names[j]
        types[name] = joint.shortname()
        if joint.nv != 1:
            continue
        damping, friction = float(model.damping[joint.idx_v]), float(model.friction[joint.idx_v])
        if damping or friction:
            dynamics[name] = JointDynamics(damping or None, friction or None)
    for name, values in (("damping", model.damping), ("friction", model.friction)):
        if not np.all(np.isfinite(values)) or np.any(np.asarray(values) < 0):
            raise PendverifyError(
                f"{source}: model.{name} = {np.asarray(values).tolist()}: must be finite and ≥ 0"
            )
    offset = anchor_base(model)
    notes = [
        "given as a Pinocchio model: a joint's damping or friction is declared where it is non-zero "
        "(Pinocchio keeps an absent value as 0, so a 0 cannot be told from one not given)"
    ]
    if robot.urdf_text is None:
        notes.append("no URDF text is known for this model (it was given as a Pinocchio object)")
    return LoadedDescription(
        model,
        source,
        robot.urdf_text or "",
        DescriptionFacts(dynamics, types),
        offset,
        [],
        FORMAT,
        notes,
        visual_model=None if robot.visual_model is None else robot.visual_model.copy(),
    )


def certified_text(loaded: LoadedDescription) -> str:
    """The URDF text a certificate of a model given as a Pinocchio object embeds.

    A certificate embeds the URDF it certifies so that ``recheck`` can re-run it; without the
    text that is refused, saying so.  With it, the text must build this very model: the model
    the text builds (anchored alike) has the same joints, parents, joint types, placements,
    inertias, damping and friction, number for number (the same reader gives the same doubles);
    the first difference is named otherwise.
    """
    if not loaded.text:
        raise PendverifyError(
            f"{loaded.source}: no URDF text is known for this model, and a certificate embeds the URDF "
            "it certifies so that recheck can re-run it: give it as "
            "pendverify.api.PinocchioRobot(model, urdf_text=TEXT)"
        )
    built = load_description(loaded.text, f"the URDF text given with {loaded.source}").model
    difference = first_difference(loaded.model, built)
    if difference:
        raise PendverifyError(
            f"{loaded.source}: the URDF text given with it builds another model: {difference}"
        )
    return loaded.text


def first_difference(a: pin.Model, b: pin.Model) -> str | None:
    """The first way two models differ (joints, parents, types, placements, inertias, damping,
    friction), or None when they are the same number for number."""
    if list(a.names) != list(b.names):
        return f"joints {list(a.names)[1:]} and {list(b.names)[1:]}"
    for j in range(1, a.njoints):
        name = a.names[j]
        if a.parents[j] != b.parents[j] or a.joints[j].shortname() != b.joints[j].shortname():
            return f"joint {name!r}: its parent or type"
        if not np.array_equal(a.jointPlacements[j].homogeneous, b.jointPlacements[j].homogeneous):
            return f"joint {name!r}: its placement"
        ia, ib = a.inertias[j], b.inertias[j]
        same = np.array_equal(ia.lever, ib.lever) and np.array_equal(ia.inertia, ib.inertia)
        if ia.mass != ib.mass or not same:
            return f"joint {name!r}: the inertia of its body (mass {ia.mass:.17g} and {ib.mass:.17g})"
    for field_name in ("damping", "friction", "armature"):
        if not np.array_equal(getattr(a, field_name), getattr(b, field_name)):
            return f"model.{field_name}"
    return None
