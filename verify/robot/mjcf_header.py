"""The top of an MJCF file: which sections it may have, its ``<compiler>`` and its ``<option>``.

Used by ``pendverify.robot.mjcf_strict``.  Conventions (each violation one ``UrdfShapeError``):

* Sections: those in ``SECTIONS``; ``<include>``, ``<extension>`` and ``<deformable>`` are
  refused, as are a non-empty ``<equality>`` or ``<tendon>`` (they act on the chain, and
  Pinocchio's model of the file leaves them out); the sections in ``SINGLE_SECTIONS`` appear
  once at most (Pinocchio's reader reads the first one each time one appears).
* ``<compiler>``: ``angle`` is ``degree`` or ``radian`` (absent: degrees, MuJoCo's default,
  which Pinocchio's reader applies too); ``eulerseq`` is lower case (Pinocchio's reader
  treats upper-case, fixed axes as moving ones); ``inertiafromgeom`` is not ``true`` (then
  Pinocchio's reader ignores every ``<inertial>``); no ``settotalmass`` > 0 (MuJoCo would
  rescale every mass) and ``coordinate`` only ``local``.
* ``<option>``: ``gravity`` is 0 0 −g with g ≥ 0 (absent: MuJoCo's 0 0 −9.81); no fluid
  (``density``, ``viscosity`` 0), no ``<flag>`` disabling gravity, passive forces, dampers
  or springs.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

from pendverify.robot.mjcf_rules import Numbers
from pendverify.robot.urdf_numbers import quoted

#: MuJoCo's default gravity [m/s²] (``<option gravity="0 0 -9.81">``)
MUJOCO_G = 9.81
SECTIONS = {"compiler", "option", "size", "visual", "statistic", "default", "custom", "asset", "worldbody"}
SECTIONS |= {"contact", "equality", "tendon", "actuator", "sensor", "keyframe"}
SINGLE_SECTIONS = ("compiler", "option", "default", "worldbody", "equality", "tendon")
REFUSED_SECTIONS = {
    "include": "Pinocchio's MJCF reader does not follow <include>: give the file with its includes in place",
    "extension": "plugins may add forces Pinocchio's model leaves out",
    "deformable": "deformable bodies are not rigid links",
}
COMPILER_RULES = {
    "angle": (lambda v: v in ("degree", "radian"), "must be 'degree' or 'radian'"),
    "eulerseq": (
        lambda v: len(v) == 3 and set(v) <= set("xyz"),
        "must be three of x, y, z in lower case "
        "(Pinocchio's reader treats upper-case, fixed axes as moving ones)",
    ),
    "inertiafromgeom": (
        lambda v: v in ("false", "auto"),
        "must be 'false' or 'auto' (with 'true' Pinocchio's reader ignores every <inertial>)",
    ),
    "coordinate": (lambda v: v == "local", "only 'local' frames are read"),
    "settotalmass": (lambda v: float(v) <= 0, "MuJoCo would rescale every mass; Pinocchio's reader does not"),
}


def check_sections(root: ET.Element, numbers: Numbers) -> None:
    for child in root:
        if not isinstance(child.tag, str):
            continue
        if child.tag in REFUSED_SECTIONS:
            numbers.fail(f"<{child.tag}>", f": refused ({REFUSED_SECTIONS[child.tag]})")
        if child.tag not in SECTIONS:
            numbers.fail(f"<{child.tag}>", ": not an MJCF section pendverify reads")
        if child.tag in ("equality", "tendon") and len(child):
            numbers.fail(
                f"<{child.tag}>",
                ": refused (it acts on the chain; Pinocchio's model of the file leaves it out)",
            )
    for tag in SINGLE_SECTIONS:
        count = len(root.findall(tag))
        if count > 1:
            numbers.fail(
                f"<{tag}>", f": appears {count} times; Pinocchio's MJCF reader reads the first each time"
            )


def read_compiler(root: ET.Element, numbers: Numbers) -> dict[str, str]:
    """The ``<compiler>`` attributes as written ({} without one), checked."""
    element = root.find("compiler")
    if element is None:
        return {}
    numbers.element(element, "<compiler>")
    for attr, (ok, rule) in COMPILER_RULES.items():
        if attr in element.attrib and not ok(element.attrib[attr]):
            numbers.fail("<compiler>", f" {attr} = {quoted(element.attrib[attr])}: {rule}")
    return dict(element.attrib)


def read_gravity(root: ET.Element, numbers: Numbers) -> float:
    """g [m/s²] of ``<option gravity>`` (MuJoCo's 9.81 without it), its other rules checked."""
    option = root.find("option")
    if option is None:
        return MUJOCO_G
    values = numbers.element(option, "<option>")
    for attr in ("density", "viscosity"):
        if values.get(attr, (0.0,))[0] != 0:
            raw = option.attrib[attr]
            numbers.fail(
                "<option>", f" {attr} = {quoted(raw)}: fluid forces are refused (Pinocchio has none)"
            )
    for flag in option.findall("flag"):
        for attr in ("gravity", "passive", "damper", "spring"):
            if flag.get(attr) == "disable":
                numbers.fail("<option><flag>", f" {attr} = 'disable': refused (Pinocchio keeps {attr})")
    gx, gy, gz = values.get("gravity", (0.0, 0.0, -MUJOCO_G))
    if gx != 0 or gy != 0 or gz > 0:
        raw = option.attrib["gravity"]
        numbers.fail("<option>", f" gravity = {quoted(raw)}: must point along −z (0 0 −g, g ≥ 0)")
    return -gz + 0.0
