"""SDFormat (``<sdf>``) descriptions: read strictly, then by Drake (``pendverify.robot.sdf_drake``).

Conventions:

* The file is read strictly first: every number held by an element pendverify knows
  (``NUMBERS``: poses, masses, inertias, axes, dynamics, limits, sizes, gravity) is a plain
  finite decimal, or as many such numbers as the element holds, separated by XML whitespace
  (surrounding whitespace in element text is allowed: SDF is pretty-printed); masses, damping,
  friction and sizes are ≥ 0; each inertia tensor is valid
  (``pendverify.robot.inertia_rounding``); a joint spring (``spring_stiffness``) is refused.
  Drake's parser is lenient where this reader is not.
* Then Drake's SDFormat parser (the optional extra ``pendverify[sdf]``; without it, one line
  naming the extra) builds a ``MultibodyPlant`` that is handed to Pinocchio and cross-checked
  against Drake's own M and bias (``pendverify.robot.sdf_drake``).  Pinocchio's own SDFormat
  reader is not used: the PyPI wheel has none.
* A joint's ``<axis><dynamics>`` damping and friction are its facts; an SDF sets no gravity
  pendverify reads (a model file has no ``<world>``): the closed form's g is used.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import pinocchio as pin

from pendverify.errors import UrdfShapeError
from pendverify.robot.inertia_rounding import check_inertia_tensor
from pendverify.robot.sdf_drake import build_from_drake, import_drake
from pendverify.robot.strict import DescriptionFacts, JointDynamics
from pendverify.robot.urdf_numbers import NOT_A_NUMBER, parse_number, quoted, why_not
from pendverify.robot.xml_reading import parse_xml

#: element tag → how many numbers its text holds
NUMBERS: dict[str, tuple[int, ...]] = {
    "pose": (6, 7),
    "xyz": (3,),
    "size": (3,),
    "scale": (3,),
    "gravity": (3,),
    **{tag: (1,) for tag in ("mass", "ixx", "ixy", "ixz", "iyy", "iyz", "izz", "damping", "friction")},
    **{tag: (1,) for tag in ("spring_reference", "spring_stiffness", "lower", "upper", "effort", "velocity")},
    **{tag: (1,) for tag in ("radius", "length")},
}
NON_NEGATIVE = (
    "mass",
    "damping",
    "friction",
    "effort",
    "velocity",
    "radius",
    "length",
    "size",
    "spring_stiffness",
)
#: SDFormat's booleans (a link's ``<gravity>`` is one)
BOOLEANS = ("true", "false", "1", "0")
INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def build_sdf_model(text: str, source: str) -> tuple[pin.Model, DescriptionFacts, list[str]]:
    """(model, facts, Drake's log) of an SDF document (see the module docstring)."""
    import_drake(source)  # without the extra: one line, before anything else is said
    facts = read_sdf_strictly(text, source)
    model, log = build_from_drake(text, source)
    return model, facts, log


def read_sdf_strictly(text: str, source: str) -> DescriptionFacts:
    """Check an SDF document's numbers (see the module docstring); the joints' facts."""
    root = parse_xml(text, source)
    if root.tag != "sdf":
        raise UrdfShapeError(source, f"the root element is <{root.tag}>, an SDF's must be <sdf>")
    for element, place in _walk(root, "sdf"):
        _check(element, place, source)
    dynamics, types = {}, {}
    for joint in root.iter("joint"):
        name = joint.get("name", "")
        if name in types:
            raise UrdfShapeError(source, f"joint {quoted(name)} is defined twice")
        types[name] = joint.get("type", "")
        found = joint.find("axis/dynamics")
        if found is not None:
            damping, friction = (found.findtext(t) for t in ("damping", "friction"))
            dynamics[name] = JointDynamics(
                None if damping is None else float(damping), None if friction is None else float(friction)
            )
    return DescriptionFacts(dynamics, types)


def _walk(element: ET.Element, owner: str):
    for child in element:
        if not isinstance(child.tag, str):
            continue
        name = child.get("name")
        here = (
            f"{child.tag} {quoted(name)}"
            if child.tag in ("model", "link", "joint") and name
            else f"{owner} <{child.tag}>"
        )
        yield child, here
        yield from _walk(child, here if child.tag in ("model", "link", "joint") else owner)


def _check(element: ET.Element, place: str, source: str) -> None:
    tag = element.tag
    if tag == "inertia":
        # SDFormat's defaults for a missing entry: 1 on the diagonal, 0 off it
        literals = {k: (element.findtext(k) or ("1" if k[1] == k[2] else "0")).strip() for k in INERTIA}
        check_inertia_tensor(literals, place, source)
    if tag not in NUMBERS or len(element):
        return
    raw = (element.text or "").strip()
    pieces = raw.split()
    if tag == "gravity" and len(pieces) == 1 and pieces[0] in BOOLEANS:
        return  # a link's <gravity> switch, not a world's gravity vector
    if len(pieces) not in NUMBERS[tag]:
        need = " or ".join(str(c) for c in NUMBERS[tag])
        found = len(pieces)
        raise UrdfShapeError(source, f"{place} = {quoted(raw)}: needs exactly {need} numbers, found {found}")
    values = []
    for piece in pieces:
        value = parse_number(piece)
        if value is None:
            rule = f"{quoted(piece)} is {NOT_A_NUMBER}{why_not(piece)}"
            raise UrdfShapeError(source, f"{place} = {quoted(raw)}: {rule}")
        values.append(value)
    if tag in NON_NEGATIVE and min(values) < 0:
        raise UrdfShapeError(source, f"{place} = {quoted(raw)}: must be ≥ 0")
    if tag == "spring_stiffness" and values[0] != 0:
        raise UrdfShapeError(
            source, f"{place} = {quoted(raw)}: a joint spring is refused (Pinocchio's model has none)"
        )
