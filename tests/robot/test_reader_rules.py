"""Every rule of the strict readers, shown on a file it must read next to one it must refuse.

Rules (``pendverify.robot.xml_reading``, ``strict``, ``urdf_numbers``): each row of
``URDF_RULES`` is (rule, a published-style file the rule accepts, the same file breaking the
rule, the start of the refusal).  (An MJCF's rules are MuJoCo's compiler's; its numbers'
strict reading is tested in ``test_mjcf_mujoco.py``.)  The accepted file is read the whole
way (strict reader, then Pinocchio); the refused one gives one line naming the file, the
place and the value.  Published files from installed packages (example-robot-data) that the
format's tools read are read as well, and an error message quotes at most a short fragment
of a long value.
"""

from __future__ import annotations

import importlib.metadata
import subprocess
import sys
from pathlib import Path

import pytest

from pendverify.errors import UrdfShapeError
from pendverify.robot import description
from pendverify.robot.description import load_description
from pendverify.robot.xml_reading import MAX_XML_DEPTH

SOURCE = "<urdf text>"
CLI_TIMEOUT_S = 120

# --------------------------------------------------------------------------- URDF

INERTIA = 'ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.001"'
URDF = """<?xml version="1.0"?>
<!-- an exported arm -->
<robot name="arm"{robot_attrs}>
  <link name="base"/>
  <joint name="j" type="revolute">
    <parent link="base"/>
    <child link="l"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
    <axis xyz="{axis}"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/>
    {dynamics}
  </joint>
  <link name="l">
    {inertial}
    {link}
  </link>
  <joint name="{tool_joint}" type="fixed">
    <parent link="l"/>
    <child link="tool"/>
    <origin xyz="0 0 -0.5"/>
    {tool_axis}
  </joint>
  <link name="tool"/>
  {extra}
</robot>
"""
URDF_PARTS = {
    "robot_attrs": "",
    "axis": "1 0 0",
    "dynamics": '<dynamics damping="0.05"/>',
    "inertial": f'<inertial><origin xyz="0 0 -0.25"/><mass value="1"/><inertia {INERTIA}/></inertial>',
    "link": "",
    "tool_joint": "tool_joint",
    "tool_axis": "",
    "extra": "",
}


def urdf(**parts: str) -> str:
    return URDF.format(**{**URDF_PARTS, **parts})


def inertial(mass: str = "1", inertia: str = INERTIA, origin: str = '<origin xyz="0 0 -0.25"/>') -> str:
    return f'<inertial>{origin}<mass value="{mass}"/><inertia {inertia}/></inertial>'


DRAKE = ' xmlns="http://drake.mit.edu" xmlns:drake="http://drake.mit.edu"'
DRAKE_EXTENSIONS = (
    '<visual><geometry><mesh filename="arm.obj" drake:declare_convex=""/></geometry></visual>'
    "<collision><geometry><box size='0.1 0.1 0.1'/></geometry>"
    '<drake:proximity_properties><drake:mu_static value="0.8"/></drake:proximity_properties></collision>'
)
NESTED_OK = "<visual><geometry><box size='0.1 0.1 0.1'/></geometry></visual>"


def nested(depth: int) -> str:
    return "<visual>" * depth + "</visual>" * depth


URDF_RULES = [
    # (rule, accepted, refused, start of the refusal after "<urdf text>: ")
    (
        "no DOCTYPE or entity",
        urdf(),
        "<!DOCTYPE robot [<!ENTITY m '1'>]>" + urdf().split("?>", 1)[1],
        "XML with a DOCTYPE",
    ),
    (
        "well-formed XML",
        urdf(dynamics="<dynamics damping='0.05'/>"),
        urdf(dynamics="<dynamics>"),
        "malformed XML at line",
    ),
    (
        "root <robot>, a default namespace read",
        urdf(robot_attrs=DRAKE, link=DRAKE_EXTENSIONS),
        urdf()
        .replace("<robot", "<drake:robot xmlns:drake='http://drake.mit.edu'")
        .replace("</robot>", "</drake:robot>"),
        "the root element is <drake:robot>",
    ),
    (
        "prefixed extension elements ignored, as urdfdom does",
        urdf(
            robot_attrs=' xmlns:drake="http://drake.mit.edu"',
            dynamics='<drake:rotor_inertia value="x"/><drake:joint><origin xyz="bad"/></drake:joint>',
        ),
        urdf(dynamics='<origin xyz="bad"/>'),
        "joint 'j': has 2 <origin> elements",
    ),
    (
        "nesting depth",
        urdf(link=NESTED_OK),
        urdf(link=nested(MAX_XML_DEPTH)),
        f"elements nested more than {MAX_XML_DEPTH} deep",
    ),
    (
        "a number is a plain decimal",
        urdf(inertial=inertial(mass="+1.")),
        urdf(inertial=inertial(mass="1,0")),
        "link 'l' <inertial><mass> value = '1,0': not a finite decimal number",
    ),
    (
        "a number is finite",
        urdf(inertial=inertial(mass="1e300")),
        urdf(inertial=inertial(mass="1e400")),
        "link 'l' <inertial><mass> value = '1e400': not a finite decimal number (it overflows a double)",
    ),
    (
        "no blank around a number",
        urdf(inertial=inertial(mass="1")),
        urdf(inertial=inertial(mass="1 ")),
        "link 'l' <inertial><mass> value = '1 ': not a finite decimal number (surrounding whitespace",
    ),
    (
        "a vector's numbers split on spaces (repeated ones too)",
        urdf(axis="  1  0 0 "),
        urdf(axis="1\t0 0"),
        "joint 'j' <axis> xyz = '1\\t0 0': separate the numbers with spaces only",
    ),
    (
        "a vector has its count of numbers",
        urdf(axis="1 0 0"),
        urdf(axis="1 0"),
        "joint 'j' <axis> xyz = '1 0': needs exactly 3 numbers",
    ),
    (
        "required attributes (urdfdom's)",
        urdf().replace('lower="-3" upper="3" ', ""),
        urdf().replace('effort="10" ', ""),
        "joint 'j' <limit>: the attribute 'effort' is missing",
    ),
    (
        "a <dynamics> has damping or friction",
        urdf(dynamics='<dynamics friction="0.1"/>'),
        urdf(dynamics="<dynamics/>"),
        "joint 'j' <dynamics>: has neither 'damping' nor 'friction'",
    ),
    (
        "an <inertial> has <mass> and <inertia>",
        urdf(inertial=inertial(origin="")),
        urdf(inertial='<inertial><mass value="1"/></inertial>'),
        "link 'l' <inertial>: has no <inertia>",
    ),
    ("children urdfdom reads once", urdf(), urdf(link=inertial()), "link 'l': has 2 <inertial> elements"),
    (
        "signs",
        urdf(dynamics='<dynamics damping="0"/>'),
        urdf(dynamics='<dynamics damping="-0.05"/>'),
        "joint 'j' <dynamics> damping = '-0.05': must be ≥ 0",
    ),
    (
        "a fixed joint's zero axis is not read; a moving joint's is refused",
        urdf(tool_axis='<axis xyz="0 0 0"/>'),
        urdf(axis="0 0 0"),
        "joint 'j' <axis> xyz = '0 0 0': a joint axis must not be the zero vector",
    ),
    (
        "an inertia tensor is positive semi-definite (within its rounding)",
        urdf(inertial=inertial(inertia='ixx="0.0208" ixy="0" ixz="0" iyy="0.0208" iyz="0" izz="0"')),
        urdf(inertial=inertial(inertia='ixx="0.0200" ixy="0" ixz="0" iyy="0.0200" iyz="0" izz="-0.0010"')),
        "link 'l' <inertial><inertia>: principal moments",
    ),
    (
        "principal moments obey the triangle inequality",
        urdf(inertial=inertial(inertia='ixx="0.2" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"')),
        urdf(inertial=inertial(inertia='ixx="0.500" ixy="0" ixz="0" iyy="0.100" iyz="0" izz="0.100"')),
        "link 'l' <inertial><inertia>: principal moments",
    ),
    ("joint names are unique", urdf(), urdf(tool_joint="j"), "joint 'j' is defined twice"),
    (
        "every joint named",
        urdf(),
        urdf().replace('<joint name="tool_joint"', "<joint"),
        "a <joint> has no name",
    ),
    (
        "a shape has its sizes",
        urdf(link="<visual><geometry><cylinder radius='0.02' length='0.5'/></geometry></visual>"),
        urdf(link="<visual><geometry><cylinder radius='0.02'/></geometry></visual>"),
        "link 'l' <visual><geometry><cylinder>: the attribute 'length' is missing",
    ),
    (
        "a material's colour has rgba",
        urdf(
            link="<visual><geometry><sphere radius='0.1'/></geometry><material name='m'>"
            "<color rgba='1 0 0 1'/></material></visual>"
        ),
        urdf(
            link="<visual><geometry><sphere radius='0.1'/></geometry><material name='m'><color/>"
            "</material></visual>"
        ),
        "material 'm' <color>: the attribute 'rgba' is missing",
    ),
    (
        "a mesh scale has 3 numbers",
        urdf(link="<visual><geometry><mesh filename='a.stl' scale='0.001 0.001 0.001'/></geometry></visual>"),
        urdf(link="<visual><geometry><mesh filename='a.stl' scale='0.001'/></geometry></visual>"),
        "link 'l' <visual><geometry><mesh> scale = '0.001': needs exactly 3 numbers",
    ),
    (
        "a shape's sizes are ≥ 0",
        urdf(link="<collision><geometry><box size='0.1 0.1 0.1'/></geometry></collision>"),
        urdf(link="<collision><geometry><box size='0.1 -0.1 0.1'/></geometry></collision>"),
        "link 'l' <collision><geometry><box> size = '0.1 -0.1 0.1': must be ≥ 0",
    ),
]


def refusal(text: str) -> str:
    with pytest.raises(UrdfShapeError) as info:
        load_description(text)
    message = str(info.value)
    assert "\n" not in message and message.startswith(f"{SOURCE}: "), message
    return message.removeprefix(f"{SOURCE}: ")


@pytest.mark.parametrize(
    ("rule", "accepted", "refused", "expected"), URDF_RULES, ids=[r[0] for r in URDF_RULES]
)
def test_urdf_rule(rule, accepted, refused, expected, capfd):
    loaded = load_description(accepted)
    assert loaded.format == "urdf" and loaded.model.nq == 1
    message = refusal(refused)
    assert message.startswith(expected), message


def test_a_drake_urdf_reads_as_urdfdom_reads_it():
    """Drake's default namespace and its extensions change nothing Pinocchio builds."""
    plain = load_description(urdf())
    drake = load_description(urdf(robot_attrs=DRAKE, link=DRAKE_EXTENSIONS))
    assert list(drake.model.names) == list(plain.model.names)
    assert drake.model.inertias[1] == plain.model.inertias[1]
    assert not plain.notes()
    (note,) = drake.notes()
    assert note.endswith("so the model leaves them out: <drake:proximity_properties>"), note


# --------------------------------------------------------------------------- MJCF

MJCF_INERTIAL = '<inertial pos="0 0 -0.25" mass="1" diaginertia="0.02 0.02 0.001"/>'
ARM = f'<body name="b"><joint name="j" axis="1 0 0" damping="0.1"/>{MJCF_INERTIAL}</body>'


def mjcf(body: str = ARM, head: str = "", world: str = "", root: str = "") -> str:
    """A one-link arm hanging from a fixed root body (``root`` its attributes)."""
    return (
        f'<mujoco model="arm">{head}<worldbody>{world}<body name="base"{root}>{MJCF_INERTIAL}{body}</body>'
        "</worldbody></mujoco>"
    )


def arm(joint: str = 'axis="1 0 0"', body: str = "", inside: str = MJCF_INERTIAL) -> str:
    return f'<body name="b"{body}><joint name="j" {joint}/>{inside}</body>'


#: two default classes: a body's childclass c, its joint's class d (with ``d``'s joint attributes)
# The MJCF rule set that mirrored Pinocchio's MJCF reader is gone: MuJoCo's compiler reads the
# file (tests/robot/test_mjcf_mujoco.py); its numbers are still read strictly (tests/robot/test_formats.py).

# --------------------------------------------------------------------------- published files, bounds, quoting


def erd_urdfs(*names: str) -> list[Path]:
    """Installed example-robot-data URDFs by file name (skipped where it is not installed)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed (pip install pendverify[erd])")
    found = {
        Path(str(r)).name: Path(str(dist.locate_file(r)))
        for r in dist.files or ()
        if str(r).endswith(".urdf")
    }
    return [found[name] for name in names]


def test_published_urdfs_with_fixed_joints_on_a_zero_axis_are_read():
    """urdfdom and Pinocchio ignore a fixed joint's axis; these files give theirs as 0 0 0."""
    for path in erd_urdfs("TwoDofs.urdf", "so101.urdf", "go2.urdf"):
        text = path.read_text()
        assert 'xyz="0 0 0"' in text
        assert load_description(path).model.nq >= 2, path


def test_a_published_urdf_keeps_refusing_a_moving_joint_on_a_zero_axis():
    (path,) = erd_urdfs("TwoDofs.urdf")
    text = path.read_text()
    head, tail = text.split('<joint name="J1" type="revolute">')
    broken = (
        head
        + '<joint name="J1" type="revolute">'
        + tail.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1)
    )
    assert refusal(broken).startswith(
        "joint 'J1' <axis> xyz = '0 0 0': a joint axis must not be the zero vector"
    )


def test_a_urdf_nested_100000_deep_is_one_line_exit_2(tmp_path):
    path = tmp_path / "deep.urdf"
    path.write_text(urdf(link=nested(100_000)))
    done = subprocess.run(
        [sys.executable, "-m", "pendverify", "check", "--model", "double_pendulum", "--urdf", str(path)],
        capture_output=True,
        text=True,
        timeout=CLI_TIMEOUT_S,
    )
    assert done.returncode == 2, done.stderr
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in done.stderr
    assert f"elements nested more than {MAX_XML_DEPTH} deep" in lines[0] and "deep.urdf" in lines[0]


def test_an_mjcf_chain_as_deep_as_the_limit_allows_is_read():
    depth = MAX_XML_DEPTH - 4  # mujoco, worldbody, the bodies, their inertial
    bodies = "".join(
        f'<body name="b{i}" pos="0 0 -0.1"><joint name="j{i}" axis="0 1 0"/>{MJCF_INERTIAL}'
        for i in range(depth)
    )
    text = f"<mujoco><worldbody>{bodies}{'</body>' * depth}</worldbody></mujoco>"
    assert load_description(text).model.nq == depth


def test_a_long_value_is_quoted_as_a_short_fragment():
    value = "1" * 4000 + "x"
    message = refusal(urdf(inertial=inertial(mass=value)))
    assert (
        len(message) < 300 and "…" in message and message.startswith("link 'l' <inertial><mass> value = '111")
    )
    long_name = "n" * 4000
    message = refusal(urdf(axis="0 0 0").replace('name="j"', f'name="{long_name}"'))
    assert len(message) < 300 and "…" in message


def test_a_xacro_error_quotes_a_long_expression_short():
    expression = "1 + " * 1000 + "__import__('os')"
    text = (
        '<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="p" value="1"/>'
        '<link name="base"><visual><geometry>'
        f'<box size="${{{expression}}} 1 1"/></geometry></visual></link></robot>'
    )
    message = refusal(text)
    assert message.startswith("xacro cannot expand it: ") and len(message) < 300 and "…" in message


def test_a_description_file_beyond_the_size_limit_is_refused_unread(tmp_path, monkeypatch):
    monkeypatch.setattr(description, "MAX_XML_CHARACTERS", 1000)
    path = tmp_path / "big.urdf"
    path.write_text(urdf(link=NESTED_OK * 40))
    with pytest.raises(UrdfShapeError, match="larger than the limit of 1000 bytes"):
        load_description(path)
