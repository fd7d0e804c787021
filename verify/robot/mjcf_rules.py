"""The numbers of an MJCF (MuJoCo XML) file, and its default classes, read strictly.

Used by ``pendverify.robot.mjcf_strict``.  Conventions:

* One number: the whole attribute is a plain finite decimal literal, without surrounding
  whitespace (``pendverify.robot.urdf_numbers``, the URDF reader's rule).  Pinocchio's MJCF
  reader turns ``nan``, ``1.0x`` or ``1e400`` into a refusal only for a body's mass; elsewhere
  (damping, inertia, positions) it reads them as 0 or garbage without a word.
* A vector: its numbers separated by XML whitespace (MuJoCo's and Pinocchio's stream reading),
  exactly as many as the attribute holds (``VECTORS``; Pinocchio reads a short vector's
  missing numbers from uninitialised memory and ignores extra ones).
* Signs: masses, inertias, damping, armature, friction loss, joint margin, geom sizes,
  mass and density are ≥ 0 (``NON_NEGATIVE``).
* Default classes: the top-level ``<default>`` is MuJoCo's class ``main``; nested ones must
  be named.  A joint's attributes are resolved as MuJoCo does (its ``class``, else the
  nearest ``childclass`` of its bodies, else ``main``, each with its ancestors) and as
  Pinocchio's reader does (``main``, then the body's childclass, then the joint's class);
  where the two disagree the file is refused naming the joint and the attribute.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NoReturn

from pendverify.errors import UrdfShapeError
from pendverify.robot.urdf_numbers import NOT_A_NUMBER, parse_number, parse_pieces, quoted, why_not

ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")
_FRAME = {"pos": (3,), "quat": (4,), "axisangle": (4,), "euler": (3,), "xyaxes": (6,), "zaxis": (3,)}
_SHAPE = {**_FRAME, "size": (1, 2, 3), "fromto": (6,), "rgba": (4,)}
#: tag → attribute → the numbers of values it may hold
VECTORS: dict[str, dict[str, tuple[int, ...]]] = {
    "body": _FRAME,
    "inertial": {**_FRAME, "diaginertia": (3,), "fullinertia": (6,)},
    "joint": {"pos": (3,), "axis": (3,), "range": (2,), "actuatorfrcrange": (2,), "springdamper": (2,)},
    "geom": _SHAPE,
    "site": _SHAPE,
    "camera": _FRAME,
    "light": {"pos": (3,), "dir": (3,)},
    "option": {"gravity": (3,), "wind": (3,), "magnetic": (3,)},
}
SCALARS: dict[str, tuple[str, ...]] = {
    "body": ("gravcomp",),
    "inertial": ("mass",),
    "joint": ("damping", "armature", "frictionloss", "stiffness", "springref", "ref", "margin"),
    "geom": ("mass", "density"),
    "compiler": ("boundmass", "boundinertia", "settotalmass"),
    "option": ("timestep", "density", "viscosity"),
}
NON_NEGATIVE: dict[str, tuple[str, ...]] = {
    "inertial": ("mass", "diaginertia"),
    "joint": ("damping", "armature", "frictionloss", "stiffness", "margin"),
    "geom": ("mass", "density", "size"),
    "site": ("size",),
    "compiler": ("boundmass", "boundinertia"),
    "option": ("density", "viscosity"),
}
#: joint attributes whose resolved value must be the same for MuJoCo and for Pinocchio
JOINT_RESOLVED = (
    "type",
    "axis",
    "damping",
    "armature",
    "frictionloss",
    "stiffness",
    "springref",
    "springdamper",
    "range",
    "limited",
    "actuatorfrcrange",
    "margin",
)
#: joint attributes a default class may not set: Pinocchio's reader takes ``pos`` from the
#: joint element only, and converts a class's ``ref`` before it knows the joint's type
NOT_IN_DEFAULTS = {
    "pos": "Pinocchio's MJCF reader takes a joint's pos from the joint element only, MuJoCo from its class",
    "ref": "Pinocchio's MJCF reader converts a class's ref before it knows the joint's type",
}


@dataclass
class Numbers:
    """Reads the numbers of elements of one file; every failure is one ``UrdfShapeError``."""

    source: str

    def fail(self, place: str, problem: str) -> NoReturn:
        raise UrdfShapeError(self.source, f"{place}{problem}")

    def element(
        self, element: ET.Element, place: str, tag: str | None = None
    ) -> dict[str, tuple[float, ...]]:
        """Every numeric attribute of ``element`` (read as ``tag``'s), checked; {attribute: numbers}."""
        tag = tag or element.tag
        values: dict[str, tuple[float, ...]] = {}
        for attr, counts in VECTORS.get(tag, {}).items():
            if attr in element.attrib:
                values[attr] = self.vector(
                    element.attrib[attr], counts, lambda p, a=attr: self.fail(place, f" {a} = {p}")
                )
        for attr in SCALARS.get(tag, ()):
            if attr in element.attrib:
                raw = element.attrib[attr]
                number = parse_number(raw)
                if number is None:
                    self.fail(place, f" {attr} = {quoted(raw)}: {NOT_A_NUMBER}{why_not(raw)}")
                values[attr] = (number,)
        for attr in NON_NEGATIVE.get(tag, ()):
            if attr in values and min(values[attr]) < 0:
                self.fail(place, f" {attr} = {quoted(element.attrib[attr])}: must be ≥ 0")
        return values

    @staticmethod
    def vector(raw: str, counts: tuple[int, ...], fail: Callable[[str], NoReturn]) -> tuple[float, ...]:
        """Numbers separated by XML whitespace; their count one of ``counts``."""
        pieces = raw.split()
        if len(pieces) not in counts:
            need = " or ".join(str(c) for c in counts)
            fail(f"{quoted(raw)}: needs exactly {need} numbers, found {len(pieces)}")
        return parse_pieces(raw, pieces, fail)


@dataclass
class DefaultClass:
    name: str
    parent: str | None
    joint: dict[str, str] = field(default_factory=dict)


def read_defaults(root: ET.Element, numbers: Numbers) -> dict[str, DefaultClass]:
    """{class name: class} of the file's ``<default>`` tree (``main`` for the top level)."""
    classes: dict[str, DefaultClass] = {}
    tops = root.findall("default")
    if not tops:
        return classes

    def visit(element: ET.Element, parent: str | None) -> None:
        name = element.get("class")
        if parent is None and name not in (None, "main"):
            numbers.fail(
                "<default>", f" class = {quoted(name)}: the top-level default class is MuJoCo's 'main'"
            )
        if parent is not None and name is None:
            numbers.fail(f"default class {parent!r}", ": a nested <default> needs a class name")
        name = name or "main"
        if name in classes:
            numbers.fail(f"default class {quoted(name)}", ": defined twice")
        place = f"default class {quoted(name)}"
        cls = classes[name] = DefaultClass(name, parent)
        for tag in ("joint", "geom", "site"):
            found = element.findall(tag)
            if len(found) > 1:
                numbers.fail(place, f": has {len(found)} <{tag}> elements; Pinocchio's reader uses the first")
            for child in found:
                numbers.element(child, f"{place} <{tag}>")
        for child in element.findall("joint"):
            for attr, why in NOT_IN_DEFAULTS.items():
                if attr in child.attrib:
                    numbers.fail(
                        f"{place} <joint>",
                        f" {attr} = {quoted(child.attrib[attr])}: not in a default class ({why})",
                    )
            cls.joint = dict(child.attrib)
        for child in element.findall("default"):
            visit(child, name)

    visit(tops[0], None)
    return classes


def chain(classes: dict[str, DefaultClass], name: str | None) -> dict[str, str]:
    """A class's joint attributes with its ancestors' (nearer ones win); {} for None."""
    if name is None or name not in classes:
        return {}
    cls = classes[name]
    return {**chain(classes, cls.parent), **cls.joint}


def resolve_joint(
    joint: ET.Element, childclass: str | None, classes: dict[str, DefaultClass], place: str, numbers: Numbers
) -> tuple[dict[str, str], str | None]:
    """(the joint's attributes with its defaults, the class MuJoCo takes them from); refused where
    MuJoCo's and Pinocchio's readings differ."""
    own = joint.get("class")
    for name in (own, childclass):
        if name is not None and name not in classes:
            numbers.fail(place, f": class {quoted(name)} is not defined by any <default>")
    effective = own or childclass or ("main" if "main" in classes else None)
    mujoco = {**chain(classes, effective), **joint.attrib}
    pinocchio = {
        **chain(classes, "main"),
        **chain(classes, childclass),
        **chain(classes, own),
        **joint.attrib,
    }
    for attr in JOINT_RESOLVED:
        if mujoco.get(attr) != pinocchio.get(attr):
            numbers.fail(
                place,
                f": {attr} resolves to {quoted(mujoco.get(attr))} for MuJoCo (class {effective!r}) but to "
                f"{quoted(pinocchio.get(attr))} for Pinocchio's reader (which also applies childclass "
                f"{childclass!r}); give the joint its {attr} explicitly",
            )
    return mujoco, effective
