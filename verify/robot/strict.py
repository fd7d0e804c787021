"""Read a URDF's numbers strictly, before Pinocchio (urdfdom) reads them leniently.

Why: urdfdom, the parser inside Pinocchio, does not refuse every bad number.  For
``ixx="np.float64(0.0093)"``, ``ixx="0,0093"``, ``ixx="nan"``, ``mass value="1e400"``,
a trailing space (``ixx="0.5 "``) or a missing ``ixy`` it logs an error on the C-level
stderr and *drops the link's whole inertial* (the mass may survive, the inertia tensor
becomes zero), and Pinocchio returns a model as if nothing happened.  When urdfdom does
refuse a file, Pinocchio's exception says only "The XML stream does not contain a valid
URDF model" while the reason went to stderr.  This module closes both gaps.

``read_urdf_strictly`` checks, wherever the element occurs in the file:

* XML: parsed with ``defusedxml`` and ``forbid_dtd=True`` (a DOCTYPE or entity is
  refused, so nothing the file declares can change what a number says); the root must
  be ``<robot>``.
* Syntax of one number: the whole attribute is a plain decimal literal
  ``[+-]?(\\d+(\\.\\d*)?|\\.\\d+)([eE][+-]?\\d+)?`` (the forms urdfdom reads exactly as
  written) that is finite as a double.  Surrounding whitespace is refused too: urdfdom
  reads a trailing blank in ``mass``/``inertia`` as "not a float" and silently zeroes
  the inertial.
* Vectors (``origin@xyz``, ``origin@rpy``, ``axis@xyz``, ``mesh@scale``, ``box@size``: 3
  numbers; ``color@rgba``: 4) are split on spaces, the only separator urdfdom knows; a
  tab or line break inside the value (which an XML parser would otherwise report as a
  space) is refused, because urdfdom then fails to read the vector, and for an
  inertial ``<origin>`` that again drops the inertial without failing.
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
* Signs: mass, damping, friction, ``limit`` effort and velocity, and every radius,
  length and box size are ≥ 0.
* Each inertia tensor I is positive semi-definite and its principal moments
  λ1 ≥ λ2 ≥ λ3 satisfy the triangle inequality λ1 ≤ λ2 + λ3 (for a rigid body
  λ_i = ∫(r² − x_i²) dm, so λ2 + λ3 − λ1 = 2∫x_1² dm ≥ 0).

Tolerance of the tensor rules.  The file holds the tensor rounded to the digits
written, so a correct body rounded to 4 digits (a thin rod, 1/6, 1/12, 1/12, written
``0.1667 0.0833 0.0833``: 0.1667 > 0.1666) must pass.  A written decimal with ``f``
digits after the point and exponent ``E`` stands for some value within
r = ½·10^(E−f) of it ("0.1667" → 5e-5, "1e-3" → ½·10^-3 = 5e-4, "2.5E-06" → 5e-8).
A written zero is taken to lie on the grid of its tensor's other entries: its r is
the smaller of its own half unit and the largest r among the tensor's non-zero
entries, and 0 when all entries are zero ("0" and Python's "0.0" mark entries that
are zero by symmetry; their own half unit, 0.5 or 0.05, would swamp a tensor of size
0.02).  Let R be the symmetric 3×3 matrix of these r.  The true tensor is I + E with
|E_ij| ≤ R_ij, so ‖E‖₂ ≤ ‖E‖_F ≤ ‖R‖_F, and by Weyl's inequality every eigenvalue of
I + E lies within ‖E‖₂ of the matching eigenvalue of I.  Hence with
δ = ‖R‖_F + 16·ε·‖I‖_F (the second term covers the decimal → double conversion,
≤ ε/2 per entry, and the backward error of the symmetric eigensolver, a small multiple
of ε‖I‖₂; ε is the double's machine epsilon) a file is refused only when no tensor
within its rounding is valid:

* positive semi-definite: require λ3 ≥ −δ;
* triangle inequality: λ1 − λ2 − λ3 moves by at most 3δ, so require
  λ1 ≤ λ2 + λ3 + 3δ (checking the largest moment is enough: the other two
  inequalities then hold with room to spare).

The bound is loose for coarsely written numbers ("0.1" carries ±0.05), so a violation
shows only when the written digits resolve it; that is the price of never refusing a
correct but rounded file.

Pinocchio is then run on the text by ``pendverify.robot.urdfdom.build_pinocchio_model``.
"""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import NoReturn

import defusedxml
import defusedxml.ElementTree as DET
import numpy as np

from pendverify.errors import UrdfShapeError

__all__ = ["JointDynamics", "UrdfFacts", "read_urdf_strictly"]

#: A plain decimal literal; it must match the whole attribute (no surrounding whitespace).
DECIMAL = re.compile(r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")

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
#: Elements that name what a message is about (the nearest one above a number).
OWNERS = ("link", "joint", "material", "transmission")

NOT_A_NUMBER = "not a finite decimal number"
_EPS = float(np.finfo(float).eps)
#: Multiple of ε·‖I‖_F added to the rounding tolerance (conversion + eigensolver error).
FLOAT_SLACK = 16.0


@dataclass(frozen=True)
class JointDynamics:
    """A joint's ``<dynamics>`` as written: ``None`` where the attribute is absent.

    Pinocchio stores an absent damping or friction as 0, indistinguishable from a
    written 0; this keeps the difference.
    """

    damping: float | None
    friction: float | None


@dataclass(frozen=True)
class UrdfFacts:
    """What the URDF says that Pinocchio's model does not keep.

    ``joint_dynamics``: joint name → its ``<dynamics>``, for every joint that has one.
    ``joint_types``: joint name → its ``type`` attribute, for every joint.
    """

    joint_dynamics: dict[str, JointDynamics]
    joint_types: dict[str, str]


@dataclass(frozen=True)
class _Place:
    """Where an element sits, for messages: ``link 'link2' <inertial><inertia>``."""

    owner: str
    path: str

    def __str__(self) -> str:
        return f"{self.owner} {self.path}" if self.path else self.owner


def read_urdf_strictly(text: str, source: str) -> UrdfFacts:
    """Check every number of a URDF (see the module docstring) and return the facts Pinocchio hides.

    ``text`` is the URDF's XML, ``source`` names it in messages.  Any violation raises
    ``UrdfShapeError(source, problem)`` whose one-line problem names the link or joint,
    the element path, the attribute, the offending value and the rule.
    """
    root = _parse_xml(text, source)
    if root.tag != "robot":
        raise UrdfShapeError(source, f"the root element is <{root.tag}>, a URDF's must be <robot>")
    for element, parent, place in _walk(root):
        _check_element(element, parent, place, source)
    return _facts(root, source)


# --------------------------------------------------------------------------- XML


def _parse_xml(text: str, source: str) -> ET.Element:
    try:
        root = DET.fromstring(text, forbid_dtd=True)
    except defusedxml.DefusedXmlException as exc:
        raise UrdfShapeError(source, f"XML with a DOCTYPE or entities is refused ({exc})") from None
    except ET.ParseError as exc:
        line, column = exc.position
        reason = re.sub(r":\s*line \d+, column \d+$", "", str(exc))
        raise UrdfShapeError(source, f"malformed XML at line {line}, column {column + 1}: {reason}") from None
    exposed = _expose_attribute_whitespace(text)
    if exposed != text:
        # Same document, but literal tabs and line breaks inside attribute values are now
        # character references, which XML keeps instead of normalising them to spaces.
        try:
            root = DET.fromstring(exposed, forbid_dtd=True)
        except ET.ParseError:  # cannot happen for a well-formed file; keep the plain reading
            pass
    return root


_ATTRIBUTE = re.compile(r"""(?P<head>[\s][^\s=<>"'/]+\s*=\s*)(?P<quote>["'])(?P<value>[^<]*?)(?P=quote)""")
_RAW_WHITESPACE = {"\t": "&#9;", "\n": "&#10;", "\r": "&#13;"}


def _expose_attribute_whitespace(text: str) -> str:
    """Write literal tabs/CR/LF inside quoted attribute values as character references."""

    def escape(match: re.Match[str]) -> str:
        value = match["value"]
        if not any(c in value for c in _RAW_WHITESPACE):
            return match[0]
        for char, ref in _RAW_WHITESPACE.items():
            value = value.replace(char, ref)
        return f"{match['head']}{match['quote']}{value}{match['quote']}"

    return _ATTRIBUTE.sub(escape, text)


def _walk(root: ET.Element) -> Iterator[tuple[ET.Element, str, _Place]]:
    """Every element below the root with its parent's tag and its place (owner, path from the owner down)."""
    robot_name = root.get("name")
    robot_owner = f"robot {robot_name!r}" if robot_name is not None else "robot"

    def visit(element: ET.Element, owner: str, path: str) -> Iterator[tuple[ET.Element, str, _Place]]:
        for child in element:
            if not isinstance(child.tag, str):
                continue  # comments and processing instructions
            if child.tag in OWNERS:
                name = child.get("name")
                child_owner = f"{child.tag} {name!r}" if name is not None else f"{child.tag} (unnamed)"
                child_path = ""
            else:
                child_owner, child_path = owner, f"{path}<{child.tag}>"
            yield child, element.tag, _Place(child_owner, child_path)
            yield from visit(child, child_owner, child_path)

    yield from visit(root, robot_owner, "")


# --------------------------------------------------------------------------- rules


def _check_element(element: ET.Element, parent: str, place: _Place, source: str) -> None:
    tag = element.tag

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
            values[attr] = _vector(element.attrib[attr], count, lambda p, a=attr: fail(f" {a} = {p}"))
    for attr in SCALARS.get(tag, ()):
        if attr in element.attrib:
            raw = element.attrib[attr]
            number = _number(raw)
            if number is None:
                fail(f" {attr} = {raw!r}: {NOT_A_NUMBER}{_why_not(raw)}")
            values[attr] = (number,)

    for attr in NON_NEGATIVE.get(tag, ()):
        if attr in values and min(values[attr]) < 0:
            fail(f" {attr} = {element.attrib[attr]!r}: must be ≥ 0")
    if tag == "axis" and parent == "joint" and "xyz" in values and not any(values["xyz"]):
        fail(f" xyz = {element.attrib['xyz']!r}: a joint axis must not be the zero vector")
    if tag == "dynamics" and parent == "joint" and not {"damping", "friction"} & element.attrib.keys():
        fail(": has neither 'damping' nor 'friction' (urdfdom refuses an empty <dynamics>)")
    if tag == "inertial":
        for needed in ("mass", "inertia"):
            if element.find(needed) is None:
                fail(f": has no <{needed}> (urdfdom then silently drops the inertial)")
    if tag == "inertia" and set(SCALARS["inertia"]) <= element.attrib.keys():
        _check_tensor(element, place, source)


def _number(raw: str) -> float | None:
    """The value of a plain decimal literal, or None if ``raw`` is not one or is not finite."""
    if not DECIMAL.fullmatch(raw):
        return None
    value = float(raw)
    return value if math.isfinite(value) else None


def _why_not(raw: str) -> str:
    if raw != raw.strip() and DECIMAL.fullmatch(raw.strip()):
        return " (surrounding whitespace is not allowed: urdfdom does not read a trailing blank)"
    if DECIMAL.fullmatch(raw):
        return " (it overflows a double)"
    return ""


def _vector(raw: str, count: int, fail: Callable[[str], NoReturn]) -> tuple[float, ...]:
    """``count`` numbers separated by spaces (leading/trailing/repeated spaces allowed, as in urdfdom)."""
    if any(c in raw for c in _RAW_WHITESPACE):
        fail(f"{raw!r}: separate the numbers with spaces only; urdfdom does not split on tabs or line breaks")
    pieces = [p for p in raw.split(" ") if p]
    if len(pieces) != count:
        fail(f"{raw!r}: needs exactly {count} numbers separated by spaces, found {len(pieces)}")
    numbers = []
    for i, piece in enumerate(pieces, 1):
        number = _number(piece)
        if number is None:
            fail(f"{raw!r}: number {i}, {piece!r}, is {NOT_A_NUMBER}{_why_not(piece)}")
        numbers.append(number)
    return tuple(numbers)


def resolution(literal: str) -> float:
    """Half a unit in the last written digit of a decimal literal: "0.1667" → 5e-5, "2e-3" → 5e-4."""
    if not DECIMAL.fullmatch(literal):
        raise ValueError(f"not a decimal literal: {literal!r}")
    significand, _, exponent = literal.lower().partition("e")
    digits_after_point = len(significand.partition(".")[2])
    return float(f"5e{int(exponent or 0) - digits_after_point - 1}")


def inertia_tolerance(literals: dict[str, str]) -> float:
    """δ of the module docstring for the six written entries ``{ixx: "0.1667", ...}``."""
    values = {k: float(v) for k, v in literals.items()}
    own = {k: resolution(v) for k, v in literals.items()}
    nonzero = [own[k] for k in literals if values[k] != 0.0]
    grid = max(nonzero, default=0.0)
    r = {k: own[k] if values[k] != 0.0 else min(own[k], grid) for k in literals}
    R = _tensor(r)
    I = _tensor(values)  # noqa: E741 (the inertia tensor's usual name)
    return float(np.linalg.norm(R, "fro") + FLOAT_SLACK * _EPS * np.linalg.norm(I, "fro"))


def _tensor(v: dict[str, float]) -> np.ndarray:
    return np.array(
        [
            [v["ixx"], v["ixy"], v["ixz"]],
            [v["ixy"], v["iyy"], v["iyz"]],
            [v["ixz"], v["iyz"], v["izz"]],
        ]
    )


def _check_tensor(element: ET.Element, place: _Place, source: str) -> None:
    literals = {k: element.attrib[k] for k in SCALARS["inertia"]}
    tensor = _tensor({k: float(v) for k, v in literals.items()})
    delta = inertia_tolerance(literals)
    # Weyl: each eigenvalue of the true tensor is within δ of one of these (see module docstring).
    moments = sorted(np.linalg.eigvalsh(tensor).tolist(), reverse=True)
    shown = "(" + ", ".join(f"{m:.6g}" for m in moments) + ")"
    big, mid, small = moments
    if small < -delta:
        raise UrdfShapeError(
            source,
            f"{place}: principal moments {shown} include a negative one, {small:.6g} "
            f"(an inertia tensor must be positive semi-definite)",
        )
    if big > mid + small + 3 * delta:
        raise UrdfShapeError(
            source,
            f"{place}: principal moments {shown} violate the triangle inequality "
            f"{big:.6g} ≤ {mid:.6g} + {small:.6g} (a rigid body's moments must satisfy it)",
        )


# --------------------------------------------------------------------------- facts


def _facts(root: ET.Element, source: str) -> UrdfFacts:
    dynamics: dict[str, JointDynamics] = {}
    types: dict[str, str] = {}
    for joint in root.findall("joint"):
        name = joint.get("name")
        if name is None:
            raise UrdfShapeError(source, "a <joint> has no name attribute")
        if name in types:
            raise UrdfShapeError(source, f"joint {name!r} is defined twice")
        types[name] = joint.get("type", "")
        element = joint.find("dynamics")
        if element is not None:
            damping, friction = element.get("damping"), element.get("friction")
            dynamics[name] = JointDynamics(
                None if damping is None else float(damping),
                None if friction is None else float(friction),
            )
    return UrdfFacts(dynamics, types)
