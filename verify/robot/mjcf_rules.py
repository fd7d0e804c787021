"""The numbers of an MJCF (MuJoCo XML) file read strictly, before MuJoCo's compiler reads them.

MuJoCo's parser is lenient: it reads ``damping="0.1x"`` as 0.1 and a short vector's missing
numbers as defaults, without a word.  ``check_numbers`` reads every numeric attribute this
module knows (``VECTORS``, ``SCALARS``) wherever its element stands (bodies, default classes,
included files) and refuses with one line naming the file, the element, the attribute, the
value and the rule:

* One number: the whole attribute is a plain finite decimal literal, without surrounding
  whitespace (``pendverify.robot.urdf_numbers``, the URDF reader's rule).
* A vector: its numbers separated by XML whitespace, exactly as many as the attribute holds
  (``VECTORS``).
* Signs: masses, inertias, damping, armature, friction loss, joint margin, geom sizes,
  mass and density are ≥ 0 (``NON_NEGATIVE``).

What the numbers mean (default classes, frames, angle units, inertia from geoms) is MuJoCo's
compiler's to answer (``pendverify.robot.mjcf_compile``).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass
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


#: elements that name what a message is about
OWNERS = ("body", "joint", "geom", "site")


def check_numbers(root: ET.Element, numbers: Numbers) -> None:
    """Every numeric attribute below ``root`` (an MJCF with its includes expanded), checked."""

    def visit(element: ET.Element, owner: str) -> None:
        for child in element:
            if not isinstance(child.tag, str):
                continue
            name = child.get("name") if child.tag in OWNERS else None
            if child.tag == "default":
                place = f"default class {quoted(child.get('class', 'main'))}"
            elif name is not None:
                place = f"{child.tag} {quoted(name)}"
            else:
                place = f"{owner} <{child.tag}>".lstrip()
            numbers.element(child, place)
            visit(child, place)

    visit(root, "")
