"""Read an MJCF (MuJoCo XML) file strictly, before Pinocchio's MJCF reader reads it leniently.

Pinocchio's reader (``pinocchio.buildModelFromMJCF``) silently misreads much of what MuJoCo
accepts.  Measured on Pinocchio 4.1: it reads a damping of ``nan`` or ``0.1x`` as 0, a short
vector's missing numbers from uninitialised memory, drops the pose of a fixed root body,
every ``<body>`` in ``<worldbody>`` after the first and every body inside a ``<frame>``,
takes a body's inertia from its geoms in its own way (visual geoms and meshes left out),
treats an upper-case (fixed-axis) ``eulerseq`` as the moving-axis one, does not normalise
an ``axisangle`` axis, drops a ball joint's damping and ignores joint springs.  This
module accepts the part of MJCF that Pinocchio reads as MuJoCo means it and refuses the
rest with one line naming the file, the element, the attribute, the value and the rule:

* numbers and default classes: ``pendverify.robot.mjcf_rules``; sections, ``<compiler>``
  (angles in degrees unless it says ``radian``: MuJoCo's default) and ``<option>``
  (gravity along −z): ``pendverify.robot.mjcf_header``;
* exactly one ``<body>`` in ``<worldbody>``; every body named, with at most one joint
  (``hinge`` or ``slide``; its name, if absent, Pinocchio's ``<body>Joint_0``), an
  ``<inertial>`` unless it has no geom, no ``frame``, ``freejoint``, ``mocap`` or
  ``gravcomp``; a fixed root body not rotated (the identity, e.g. ``quat="1 0 0 0"``, to a few
  ulps: ``pendverify.robot.mjcf_identity``; its position does not matter: the base is
  anchored at the origin anyway); at most one orientation per element, a unit
  ``axisangle`` axis;
* an inertial has ``pos``, ``mass`` and one of ``diaginertia``/``fullinertia`` (MuJoCo's order
  ixx iyy izz ixy ixz iyz), a valid tensor (``pendverify.robot.inertia_rounding``), and no
  compiler ``boundmass``/``boundinertia`` that would change it;
* a joint has no spring (``stiffness``, ``springdamper``); its damping and friction loss are
  its facts (as for a URDF's ``<dynamics>``), its armature is noted (Pinocchio adds it to M).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

from pendverify.errors import UrdfShapeError
from pendverify.robot.inertia_rounding import check_inertia_tensor
from pendverify.robot.mjcf_header import check_sections, read_compiler, read_gravity
from pendverify.robot.mjcf_identity import is_identity
from pendverify.robot.mjcf_rules import ORIENTATIONS, Numbers, read_defaults, resolve_joint
from pendverify.robot.strict import DescriptionFacts, JointDynamics
from pendverify.robot.urdf_numbers import quoted
from pendverify.robot.xml_reading import parse_xml

IGNORED_IN_BODY = {"geom", "site", "camera", "light"}
AXIS_UNIT_TOL = 1e-12
_INERTIA_KEYS = {
    "diaginertia": ("ixx", "iyy", "izz"),
    "fullinertia": ("ixx", "iyy", "izz", "ixy", "ixz", "iyz"),
}
_NO_INERTIA = dict.fromkeys(("ixx", "iyy", "izz", "ixy", "ixz", "iyz"), "0")


@dataclass
class MjcfReading:
    facts: DescriptionFacts
    #: joint names in Pinocchio's order (the bodies' document order)
    joints: list[str] = field(default_factory=list)
    #: joint name → resolved (damping, armature, frictionloss), as MuJoCo reads them
    dynamics: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    #: distance of a fixed root body from the origin (Pinocchio's reader drops it)
    root_offset: float = 0.0


def read_mjcf_strictly(text: str, source: str) -> MjcfReading:
    """Check an MJCF (see the module docstring); its facts, joints and notes for the loader."""
    root = parse_xml(text, source)
    if root.tag != "mujoco":
        raise UrdfShapeError(source, f"the root element is <{root.tag}>, an MJCF's must be <mujoco>")
    return _Reader(source, root).read()


class _Reader:
    def __init__(self, source: str, root: ET.Element):
        self.source, self.root, self.numbers = source, root, Numbers(source)
        self.reading = MjcfReading(DescriptionFacts({}, {}))
        self.bodies: set[str] = set()
        self.uses_angles = False

    def fail(self, place: str, problem: str):
        self.numbers.fail(place, problem)

    def read(self) -> MjcfReading:
        check_sections(self.root, self.numbers)
        self.compiler = read_compiler(self.root, self.numbers)
        gravity = read_gravity(self.root, self.numbers)
        self.classes = read_defaults(self.root, self.numbers)
        world = self.root.find("worldbody")
        bodies = [] if world is None else world.findall("body")
        if len(bodies) != 1:
            self.fail("<worldbody>", f": has {len(bodies)} <body>; Pinocchio's reader reads the first only")
        for child in world:
            if isinstance(child.tag, str) and child.tag != "body":
                self._ignored(child, "worldbody")
        self._body(bodies[0], None, root=True)
        if self.uses_angles and "angle" not in self.compiler:
            self.reading.notes.append(
                "no <compiler angle>: angles are in degrees, MuJoCo's default (Pinocchio's reader's too)"
            )
        facts = self.reading.facts
        self.reading.facts = DescriptionFacts(facts.joint_dynamics, facts.joint_types, gravity)
        return self.reading

    def _ignored(self, element: ET.Element, owner: str) -> None:
        place = f"{owner} <{element.tag}>"
        if element.tag not in IGNORED_IN_BODY:
            self.fail(place, ": not read (a body holds inertial, joint, geom, site, camera, light, body)")
        self.numbers.element(element, place)
        self._orientation(element, place)

    def _orientation(self, element: ET.Element, place: str) -> None:
        given = [a for a in ORIENTATIONS if a in element.attrib]
        if len(given) > 1:
            self.fail(place, f": has {' and '.join(given)}; an orientation is given once")
        if not given:
            return
        attr = given[0]
        values = self.numbers.element(element, place)[attr]
        self.uses_angles |= attr in ("euler", "axisangle")
        head = f" {attr} = {quoted(element.attrib[attr])}: "
        if attr == "quat" and not any(values):
            self.fail(place, head + "the zero quaternion is no rotation")
        if attr == "axisangle" and abs(math.hypot(*values[:3]) - 1) > AXIS_UNIT_TOL:
            self.fail(
                place, head + "the axis must be a unit vector (Pinocchio's reader does not normalise it)"
            )
        if attr == "xyaxes" and math.hypot(*_cross(values[:3], values[3:])) == 0:
            self.fail(place, head + "the two axes must be non-zero and not parallel")
        if attr == "zaxis" and (not any(values) or (values[0] == values[1] == 0 and values[2] < 0)):
            self.fail(place, head + "must be non-zero and not −z (the rotation is then ambiguous; give quat)")

    def _body(self, body: ET.Element, childclass: str | None, root: bool = False) -> None:
        name = body.get("name")
        if name is None:
            self.fail("a <body>", " has no name: Pinocchio's MJCF reader needs every body named")
        place = f"body {quoted(name)}"
        if name in self.bodies:
            self.fail(place, ": defined twice")
        self.bodies.add(name)
        values = self.numbers.element(body, place)
        self._orientation(body, place)
        if body.get("mocap") == "true":
            self.fail(place, " mocap = 'true': refused (a mocap body is driven, not simulated)")
        if values.get("gravcomp", (0.0,))[0] != 0:
            self.fail(place, f" gravcomp = {quoted(body.get('gravcomp'))}: gravity compensation is refused")
        childclass = body.get("childclass", childclass)
        if childclass is not None and childclass not in self.classes:
            self.fail(place, f": childclass {childclass!r} is not defined by any <default>")
        tags = [c.tag for c in body if isinstance(c.tag, str)]
        if "frame" in tags:
            self.fail(f"{place} <frame>", ": refused (Pinocchio's reader drops what is inside a frame)")
        if "freejoint" in tags:
            self.fail(f"{place} <freejoint>", ": refused (a free joint is not a chain's)")
        joints = body.findall("joint")
        if len(joints) > 1:
            self.fail(
                place, f": has {len(joints)} joints; Pinocchio's reader merges them into one, not compared"
            )
        if root and not joints:
            degrees = self.compiler.get("angle", "degree") == "degree"
            for attr in (a for a in ORIENTATIONS if a in body.attrib):
                if not is_identity(attr, values[attr], degrees):
                    self.fail(
                        place,
                        f" {attr} = {quoted(body.attrib[attr])}: a fixed root body may not be rotated "
                        "(Pinocchio's reader drops its pose; only the identity is read)",
                    )
            self.reading.root_offset = math.hypot(*values.get("pos", (0.0, 0.0, 0.0)))
        self._inertia(body, place, "geom" in tags)
        for joint in joints:
            self._joint(joint, name, childclass)
        for child in body:
            if not isinstance(child.tag, str) or child.tag in ("inertial", "joint"):
                continue
            if child.tag == "body":
                self._body(child, childclass)
            else:
                self._ignored(child, place)

    def _inertia(self, body: ET.Element, place: str, has_geoms: bool) -> None:
        inertials = body.findall("inertial")
        if len(inertials) > 1:
            self.fail(place, f": has {len(inertials)} <inertial> elements, one at most")
        if inertials:
            self._inertial(inertials[0], f"{place} <inertial>")
        elif has_geoms:
            self.fail(
                place,
                ": has geoms and no <inertial>; its inertia would come from its geoms, which Pinocchio's "
                "reader computes unlike MuJoCo (leaving out visual geoms and meshes): give it an <inertial>",
            )
        elif self.compiler.get("inertiafromgeom") == "false":
            self.fail(place, ": has no <inertial> (compiler inertiafromgeom = 'false' requires one)")

    def _inertial(self, inertial: ET.Element, place: str) -> None:
        values = self.numbers.element(inertial, place)
        self._orientation(inertial, place)
        for attr in ("pos", "mass"):
            if attr not in values:
                self.fail(place, f": the attribute {attr!r} is missing (MuJoCo requires it)")
        given = [a for a in _INERTIA_KEYS if a in values]
        if len(given) != 1:
            self.fail(
                place, ": needs one of diaginertia and fullinertia (Pinocchio's reader puts 1s otherwise)"
            )
        kind = given[0]
        written = dict(zip(_INERTIA_KEYS[kind], inertial.attrib[kind].split(), strict=True))
        check_inertia_tensor({**_NO_INERTIA, **written}, f"{place} {kind}", self.source)
        for attr, below in (("boundmass", values["mass"][0]), ("boundinertia", min(values[kind][:3]))):
            if float(self.compiler.get(attr, "0")) > below:
                bound = self.compiler[attr]
                self.fail(place, f": compiler {attr} = {quoted(bound)} would replace {below:g}; refused")

    def _joint(self, joint: ET.Element, body: str, childclass: str | None) -> None:
        name = joint.get("name", f"{body}Joint_0")  # Pinocchio's name for an unnamed joint
        place = f"joint {quoted(name)}"
        self.numbers.element(joint, place)
        if any(a in joint.attrib for a in ORIENTATIONS):
            self.fail(place, ": a joint has a pos and an axis, no orientation")
        attrs, _ = resolve_joint(joint, childclass, self.classes, place, self.numbers)
        resolved = self.numbers.element(ET.Element("joint", attrs), place)
        kind = attrs.get("type", "hinge")
        if kind not in ("hinge", "slide"):
            self.fail(
                place,
                f" type = {quoted(kind)}: hinge and slide joints only (Pinocchio drops a ball's damping)",
            )
        if not any(resolved.get("axis", (0.0, 0.0, 1.0))):
            self.fail(place, f" axis = {quoted(attrs['axis'])}: a joint axis must not be the zero vector")
        for attr in ("stiffness", "springdamper"):
            if any(resolved.get(attr, (0.0,))):
                self.fail(
                    place,
                    f" {attr} = {quoted(attrs[attr])}: a joint spring is refused (Pinocchio ignores it)",
                )
        self.uses_angles |= kind == "hinge" and bool({"range", "ref"} & attrs.keys())
        if name in self.reading.facts.joint_types:
            self.fail(place, ": defined twice")
        damping, armature, friction = (
            resolved.get(a, (None,))[0] for a in ("damping", "armature", "frictionloss")
        )
        self.reading.facts.joint_types[name] = kind
        if damping is not None or friction is not None:
            self.reading.facts.joint_dynamics[name] = JointDynamics(damping, friction)
        self.reading.joints.append(name)
        self.reading.dynamics[name] = (damping or 0.0, armature or 0.0, friction or 0.0)
        if armature:
            self.reading.notes.append(
                f"joint {quoted(name)} has armature {armature:g}: Pinocchio adds it to M"
            )


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
