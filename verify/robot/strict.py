"""Read a URDF's numbers strictly, before Pinocchio (urdfdom) reads them leniently.

Why: urdfdom, the parser inside Pinocchio, does not refuse every bad number.  For
``ixx="np.float64(0.0093)"``, ``ixx="0,0093"``, ``ixx="nan"``, ``mass value="1e400"``,
a trailing space (``ixx="0.5 "``) or a missing ``ixy`` it logs an error on the C-level
stderr and *drops the link's whole inertial* (the mass may survive, the inertia tensor
becomes zero), and Pinocchio returns a model as if nothing happened.  When urdfdom does
refuse a file, Pinocchio's exception says only "The XML stream does not contain a valid
URDF model" while the reason went to stderr.  This module closes both gaps.

``read_urdf_strictly`` checks, wherever the element occurs in the file:

* XML: no DOCTYPE or entities, bounded in size and depth (``pendverify.robot.xml_reading``),
  and read as urdfdom reads it: names as written, so ``<robot xmlns="http://drake.mit.edu">``
  is a ``<robot>``, and prefixed extension elements and attributes (Drake's ``<drake:joint>``,
  ``drake:declare_convex``), which urdfdom never looks at, are ignored.  The root must be
  ``<robot>``.
* Syntax of one number: the whole attribute is a plain decimal literal, finite as a
  double, without surrounding whitespace (``pendverify.robot.urdf_numbers``).
* Vectors (``origin@xyz``, ``origin@rpy``, ``axis@xyz``, ``mesh@scale``, ``box@size``: 3
  numbers; ``color@rgba``: 4) are split on spaces only, the one separator urdfdom
  knows (``pendverify.robot.urdf_numbers``).
* Scalars: ``mass@value``; ``inertia@ixx,ixy,ixz,iyy,iyz,izz``;
  ``limit@lower,upper,effort,velocity``; ``dynamics@damping,friction``;
  ``safety_controller@soft_lower_limit,soft_upper_limit,k_position,k_velocity``;
  ``calibration@rising,falling``; ``mimic@multiplier,offset``; ``cylinder@radius,length``;
  ``sphere@radius``; ``capsule@radius,length``.
* Required attributes (urdfdom's own list, where urdfdom reads the element):
  ``mass@value``, all six ``inertia`` attributes, ``limit@effort,velocity``, the shape
  sizes under ``<geometry>`` and ``color@rgba``; a joint's ``<dynamics>`` needs
  ``damping`` or ``friction``.  An ``<inertial>`` needs one ``<mass>`` and one
  ``<inertia>``.  Children urdfdom reads only once (a link's ``<inertial>``; an
  inertial's ``origin``/``mass``/``inertia``; a joint's ``origin``/``axis``/``limit``/
  ``dynamics``) must not be repeated: urdfdom silently keeps the first.
* Axes: a joint's ``<axis>`` is not the zero vector, except on a ``fixed`` or ``floating``
  joint, whose axis urdfdom does not read (exported URDFs give fixed joints ``0 0 0``).
* Signs: mass, damping, friction, ``limit`` effort and velocity, and every radius,
  length and box size are ≥ 0.
* Each inertia tensor I is positive semi-definite and its principal moments
  λ1 ≥ λ2 ≥ λ3 satisfy the triangle inequality λ1 ≤ λ2 + λ3 (for a rigid body
  λ_i = ∫(r² − x_i²) dm, so λ2 + λ3 − λ1 = 2∫x_1² dm ≥ 0), within the rounding of the
  digits as written (``pendverify.robot.inertia_rounding``:
  a correct body written to 4 digits passes; a file is refused only when no tensor
  within its rounding is valid).

Pinocchio is then run on the text by ``pendverify.robot.urdfdom.build_pinocchio_model``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Iterator
from dataclasses import dataclass
from typing import NoReturn

from pendverify.display import shortened
from pendverify.errors import UrdfShapeError
from pendverify.robot.inertia_rounding import check_inertia_tensor
from pendverify.robot.urdf_numbers import NOT_A_NUMBER, parse_number, parse_vector, quoted, why_not
from pendverify.robot.xml_reading import XmlDocument, as_urdfdom_reads, read_xml

__all__ = ["DescriptionFacts", "JointDynamics", "read_urdf_strictly"]

#: tag → (attribute → how many numbers it holds), following the URDF format.
VECTORS: dict[str, dict[str, int]] = {
    "origin": {"xyz": 3, "rpy": 3},
    "axis": {"xyz": 3},
    "mesh": {"scale": 3},
    "box": {"size": 3},
    "color": {"rgba": 4},
}
SCALARS: dict[str, tuple[str, ...]] = {
    "mass": ("value",),
    "inertia": ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
    "limit": ("lower", "upper", "effort", "velocity"),
    "dynamics": ("damping", "friction"),
    "safety_controller": ("soft_lower_limit", "soft_upper_limit", "k_position", "k_velocity"),
    "calibration": ("rising", "falling"),
    "mimic": ("multiplier", "offset"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "capsule": ("radius", "length"),
}
#: Attributes urdfdom requires, with the parent it reads the element under; without them it
#: refuses the file or drops the element.  (Elsewhere, e.g. Pinocchio's own
#: ``<collision_checking><capsule name=.../>``, the element means something else.)
REQUIRED: dict[str, tuple[str, tuple[str, ...]]] = {
    "mass": ("inertial", ("value",)),
    "inertia": ("inertial", SCALARS["inertia"]),
    "limit": ("joint", ("effort", "velocity")),
    "cylinder": ("geometry", ("radius", "length")),
    "sphere": ("geometry", ("radius",)),
    "capsule": ("geometry", ("radius", "length")),
    "box": ("geometry", ("size",)),
    "color": ("material", ("rgba",)),
}
#: Attributes that must be ≥ 0.
NON_NEGATIVE: dict[str, tuple[str, ...]] = {
    "mass": ("value",),
    "dynamics": ("damping", "friction"),
    "limit": ("effort", "velocity"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "capsule": ("radius", "length"),
    "box": ("size",),
}
#: parent tag → children urdfdom reads only the first of.
SINGLE_CHILDREN: dict[str, tuple[str, ...]] = {
    "link": ("inertial",),
    "inertial": ("origin", "mass", "inertia"),
    "joint": ("origin", "axis", "limit", "dynamics"),
}
#: joint types whose <axis> urdfdom does not read (a fixed joint's axis means nothing)
AXIS_IGNORED = ("fixed", "floating")
#: characters of an element's name or an attribute's value quoted in a message
TAG_WIDTH = 60
#: Elements that name what a message is about (the nearest one above a number).
OWNERS = ("link", "joint", "material", "transmission")


@dataclass(frozen=True)
class JointDynamics:
    """A joint's ``<dynamics>`` as written: ``None`` where the attribute is absent.

    Pinocchio stores an absent damping or friction as 0, indistinguishable from a
    written 0; this keeps the difference.
    """

    damping: float | None
    friction: float | None


@dataclass(frozen=True)
class DescriptionFacts:
    """What a robot description says that Pinocchio's model does not keep (any format).

    ``joint_dynamics``: joint name → its damping and Coulomb friction as written (a URDF's
    ``<dynamics>``, an MJCF joint's ``damping``/``frictionloss``), for every joint that has one.
    ``joint_types``: joint name → its type as written (``revolute``, ``hinge``, ...), for every joint.
    ``gravity``: g [m/s²] the description itself sets along −z (an MJCF's ``<option gravity>``:
    minus its z component; MuJoCo's default 9.81 when absent); None for a format that sets none
    (URDF).  ``gravity_vector``: the whole vector [m/s²] the description sets (its part not along
    −z is the tilt ``pendverify.robot.gravity_tilt`` measures); None for a format that sets none.
    """

    joint_dynamics: dict[str, JointDynamics]
    joint_types: dict[str, str]
    gravity: float | None = None
    gravity_vector: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class _Place:
    """Where an element sits, for messages: ``link 'link2' <inertial><inertia>``."""

    owner: str
    path: str

    def __str__(self) -> str:
        return f"{self.owner} {self.path}" if self.path else self.owner


def read_urdf_strictly(text: str, source: str, document: XmlDocument | None = None) -> DescriptionFacts:
    """Check every number of a URDF (see the module docstring) and return the facts Pinocchio hides.

    ``text`` is the URDF's XML, ``source`` names it in messages.  Any violation raises
    ``UrdfShapeError(source, problem)`` whose one-line problem names the link or joint,
    the element path, the attribute, the offending value and the rule.  ``document``: ``text``
    as the caller has parsed it already (``read_xml``); None: parsed here.
    """
    root = as_urdfdom_reads(document or read_xml(text, source))
    if root.tag != "robot":
        tag = shortened(root.tag, TAG_WIDTH)
        raise UrdfShapeError(source, f"the root element is <{tag}>, a URDF's must be <robot>")
    for element, parent, place in _walk(root):
        _check_element(element, parent, place, source)
    return _facts(root, source)


def _walk(root: ET.Element) -> Iterator[tuple[ET.Element, ET.Element, _Place]]:
    """Every element below the root with its parent and its place (owner, path from the owner down)."""
    robot_name = root.get("name")
    robot_owner = f"robot {robot_name!r}" if robot_name is not None else "robot"

    def visit(element: ET.Element, owner: str, path: str) -> Iterator[tuple[ET.Element, str, _Place]]:
        for child in element:
            if not isinstance(child.tag, str):
                continue  # comments and processing instructions
            if child.tag in OWNERS:
                name = child.get("name")
                child_owner = f"{child.tag} {quoted(name)}" if name is not None else f"{child.tag} (unnamed)"
                child_path = ""
            else:
                child_owner, child_path = owner, f"{path}<{child.tag}>"
            yield child, element, _Place(child_owner, child_path)
            yield from visit(child, child_owner, child_path)

    yield from visit(root, robot_owner, "")


# --------------------------------------------------------------------------- rules


def _check_element(element: ET.Element, parent_element: ET.Element, place: _Place, source: str) -> None:
    tag, parent = element.tag, parent_element.tag

    def fail(problem: str) -> NoReturn:
        raise UrdfShapeError(source, f"{place}{problem}")

    for child_tag in SINGLE_CHILDREN.get(tag, ()):
        count = len(element.findall(child_tag))
        if count > 1:
            fail(f": has {count} <{child_tag}> elements; urdfdom silently uses the first, so one at most")
    required_under, required = REQUIRED.get(tag, ("", ()))
    for attr in required if parent == required_under else ():
        if attr not in element.attrib:
            fail(f": the attribute {attr!r} is missing (urdfdom refuses the file or drops the element)")

    values: dict[str, tuple[float, ...]] = {}
    for attr, count in VECTORS.get(tag, {}).items():
        if attr in element.attrib:
            values[attr] = parse_vector(element.attrib[attr], count, lambda p, a=attr: fail(f" {a} = {p}"))
    for attr in SCALARS.get(tag, ()):
        if attr in element.attrib:
            raw = element.attrib[attr]
            number = parse_number(raw)
            if number is None:
                fail(f" {attr} = {quoted(raw)}: {NOT_A_NUMBER}{why_not(raw)}")
            values[attr] = (number,)

    for attr in NON_NEGATIVE.get(tag, ()):
        if attr in values and min(values[attr]) < 0:
            fail(f" {attr} = {quoted(element.attrib[attr])}: must be ≥ 0")
    moves = parent_element.get("type") not in AXIS_IGNORED
    if tag == "axis" and parent == "joint" and moves and "xyz" in values and not any(values["xyz"]):
        fail(f" xyz = {quoted(element.attrib['xyz'])}: a joint axis must not be the zero vector")
    if tag == "dynamics" and parent == "joint" and not {"damping", "friction"} & element.attrib.keys():
        fail(": has neither 'damping' nor 'friction' (urdfdom refuses an empty <dynamics>)")
    if tag == "inertial":
        for needed in ("mass", "inertia"):
            if element.find(needed) is None:
                fail(f": has no <{needed}> (urdfdom then silently drops the inertial)")
    if tag == "inertia" and set(SCALARS["inertia"]) <= element.attrib.keys():
        check_inertia_tensor({k: element.attrib[k] for k in SCALARS["inertia"]}, place, source)


# --------------------------------------------------------------------------- facts


def _facts(root: ET.Element, source: str) -> DescriptionFacts:
    dynamics: dict[str, JointDynamics] = {}
    types: dict[str, str] = {}
    for joint in root.findall("joint"):
        name = joint.get("name")
        if name is None:
            raise UrdfShapeError(source, "a <joint> has no name attribute")
        if name in types:
            raise UrdfShapeError(source, f"joint {quoted(name)} is defined twice")
        types[name] = joint.get("type", "")
        element = joint.find("dynamics")
        if element is not None:
            damping, friction = element.get("damping"), element.get("friction")
            dynamics[name] = JointDynamics(
                None if damping is None else float(damping),
                None if friction is None else float(friction),
            )
    return DescriptionFacts(dynamics, types)
