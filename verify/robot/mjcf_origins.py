"""Where each number of a compiled MJCF came from, for ``show --robot``.

``expand_includes`` gives the XML tree with every ``<include file>`` replaced by the included
file's ``<mujoco>`` children, as MuJoCo does (paths relative to the top file's folder), so the
strict reading of numbers and this provenance see what MuJoCo's compiler sees.

``origins`` maps ``"<body or joint name>.<quantity>"`` (bodies: ``mass``, ``com``, ``inertia``,
``frame``; joints: ``axis``, ``frame``, ``damping``, ``armature``, ``frictionloss``) and
``"gravity"`` to one of

* ``"written in the file"`` — on the element itself (a body's ``<inertial>``, a joint's attribute);
* ``"computed by MuJoCo from geoms"`` — a body's inertia when it has no ``<inertial>`` (or the
  compiler says ``inertiafromgeom="true"``) and has geoms;
* ``"from default class 'NAME'"`` — a joint attribute resolved as MuJoCo resolves it: the joint's
  ``class``, else its nearest body's ``childclass``, else ``main``, then that class's ancestors;
* ``"MuJoCo's default"`` — none of these.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

from pendverify.errors import UrdfShapeError
from pendverify.robot.xml_reading import parse_xml

WRITTEN = "written in the file"
FROM_GEOMS = "computed by MuJoCo from geoms"
DEFAULT = "MuJoCo's default"
#: nesting depth of includes followed (MuJoCo refuses a cycle; this bounds the reading here)
MAX_INCLUDE_DEPTH = 16
_JOINT_QUANTITIES = {"axis": ("axis",), "frame": ("pos",), "damping": ("damping",)}
_JOINT_QUANTITIES |= {"armature": ("armature",), "frictionloss": ("frictionloss",)}
_ORIENTATIONS = ("quat", "axisangle", "euler", "xyaxes", "zaxis")


def expand_includes(root: ET.Element, folder: Path | None, source: str, depth: int = 0) -> ET.Element:
    """``root`` with its includes in place (in place, and returned); no folder: left as it is."""
    if folder is None or depth > MAX_INCLUDE_DEPTH:
        return root
    for parent in list(root.iter()):
        for child in list(parent):
            if child.tag != "include":
                continue
            name = child.get("file")
            if name is None:
                raise UrdfShapeError(source, "<include> has no file attribute")
            path = folder / name
            try:
                text = path.read_text(encoding="utf-8-sig")
            except (OSError, UnicodeDecodeError) as exc:
                raise UrdfShapeError(source, f"<include file={name!r}>: cannot be read ({exc})") from None
            included = expand_includes(parse_xml(text, str(path)), folder, str(path), depth + 1)
            position = list(parent).index(child)
            parent.remove(child)
            for offset, grandchild in enumerate(included):
                parent.insert(position + offset, grandchild)
    return root


def origins(root: ET.Element, body_names: list[str], joint_names: list[str]) -> dict[str, str]:
    """{"name.quantity": where it came from} (see the module docstring) of an expanded MJCF tree.

    ``body_names``/``joint_names`` are MuJoCo's bodies (without the world) and joints in their
    compiled order, which is the document order of the tree's ``<body>`` and ``<joint>`` elements.
    """
    out: dict[str, str] = {}
    classes = _classes(root)
    compiler = root.find("compiler")
    from_geoms_always = compiler is not None and compiler.get("inertiafromgeom") == "true"
    world = root.find("worldbody")
    bodies: list[tuple[ET.Element, str | None]] = []
    joints: list[tuple[ET.Element, str | None]] = []

    def visit(element: ET.Element, childclass: str | None) -> None:
        for child in element:
            if child.tag == "body":
                inner = child.get("childclass", childclass)
                bodies.append((child, inner))
                for joint in child.findall("joint"):
                    joints.append((joint, inner))
                visit(child, inner)

    if world is not None:
        visit(world, None)
    if len(bodies) == len(body_names):
        for (body, _), name in zip(bodies, body_names, strict=True):
            has_inertial = body.find("inertial") is not None and not from_geoms_always
            source = WRITTEN if has_inertial else FROM_GEOMS if body.find("geom") is not None else DEFAULT
            for quantity in ("mass", "com", "inertia"):
                out[f"{name}.{quantity}"] = source
            written = "pos" in body.attrib or any(a in body.attrib for a in _ORIENTATIONS)
            out[f"{name}.frame"] = WRITTEN if written else DEFAULT
    if len(joints) == len(joint_names):
        for (joint, childclass), name in zip(joints, joint_names, strict=True):
            for quantity, attrs in _JOINT_QUANTITIES.items():
                out[f"{name}.{quantity}"] = _joint_origin(joint, childclass, attrs, classes)
    option = root.find("option")
    out["gravity"] = WRITTEN if option is not None and "gravity" in option.attrib else DEFAULT
    return out


def _classes(root: ET.Element) -> dict[str, tuple[ET.Element, str | None]]:
    """{class name: (its <default> element, its parent class)}; the top level is ``main``."""
    found: dict[str, tuple[ET.Element, str | None]] = {}

    def visit(element: ET.Element, parent: str | None) -> None:
        name = element.get("class", "main" if parent is None else None)
        if name is None:
            return
        found[name] = (element, parent)
        for child in element.findall("default"):
            visit(child, name)

    for top in root.findall("default"):
        visit(top, None)
    return found


def _joint_origin(joint: ET.Element, childclass: str | None, attrs: tuple[str, ...], classes) -> str:
    if any(a in joint.attrib for a in attrs):
        return WRITTEN
    name = joint.get("class") or childclass or ("main" if "main" in classes else None)
    while name is not None and name in classes:
        element, parent = classes[name]
        default = element.find("joint")
        if default is not None and any(a in default.attrib for a in attrs):
            return f"from default class {name!r}"
        name = parent
    return DEFAULT
