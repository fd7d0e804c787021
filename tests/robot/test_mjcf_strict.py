"""The strict MJCF reader: what Pinocchio's MJCF reader misreads is refused, what it reads is kept.

Each refusal below is a file Pinocchio 4.1 reads without a word into a model MuJoCo would
not build from it (measured: see ``pendverify.robot.mjcf_strict``); each is one line naming
the file, the element, the attribute and the rule.  The accepted cases check that the
strict reading and Pinocchio's model agree (joints, damping, angles in degrees).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pendverify.analytic import MODELS
from pendverify.errors import UrdfShapeError
from pendverify.robot.description import load_description
from pendverify.robot.mjcf import _same_as_read, build_mjcf_model
from pendverify.robot.mjcf_strict import read_mjcf_strictly
from pendverify.robot.strict import JointDynamics
from pendverify.robot.system import PinocchioSystem

SOURCE = "arm.xml"
INERTIAL = '<inertial pos="0 0.25 0" mass="1" diaginertia="0.02 0.01 0.02"/>'
NO_TENSOR = INERTIAL.replace(' diaginertia="0.02 0.01 0.02"', "")
NO_POS = INERTIAL.replace(' pos="0 0.25 0"', "")
BAD_MASS = INERTIAL.replace('mass="1"', 'mass="1.0x"')
NEGATIVE_MASS = INERTIAL.replace('mass="1"', 'mass="-1"')
LOPSIDED = INERTIAL.replace("0.02 0.01 0.02", "0.500 0.100 0.100")
SEED_MJCF = Path(__file__).resolve().parents[2] / "examples" / "double_pendulum.mjcf.xml"


def mjcf(body: str = "", head: str = "", world: str = "") -> str:
    """A one-link arm (or ``body`` instead), with ``head`` before the worldbody."""
    body = body or f'<body name="b"><joint name="j" axis="1 0 0" damping="0.1"/>{INERTIAL}</body>'
    return f'<mujoco model="arm">{head}<worldbody>{world}{body}</worldbody></mujoco>'


def refusal(text: str) -> str:
    with pytest.raises(UrdfShapeError) as info:
        read_mjcf_strictly(text, SOURCE)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{SOURCE}: ")
    return message.removeprefix(f"{SOURCE}: ")


def test_the_plain_arm_is_accepted_and_agrees_with_pinocchio():
    model, reading, log = build_mjcf_model(mjcf(), SOURCE)
    assert reading.joints == ["j"] and model.names[1] == "j"
    assert reading.facts.joint_dynamics == {"j": JointDynamics(0.1, None)}
    assert reading.facts.joint_types == {"j": "hinge"}
    assert reading.facts.gravity == 9.81  # MuJoCo's default, no <option>
    assert model.damping.tolist() == [0.1]
    assert log == []


REFUSED = {
    # numbers
    "mass suffix": (
        mjcf(f'<body name="b"><joint/>{BAD_MASS}</body>'),
        "body 'b' <inertial> mass = '1.0x': not a",
    ),
    "damping nan": (
        mjcf().replace('damping="0.1"', 'damping="nan"'),
        "joint 'j' damping = 'nan': not a finite",
    ),
    "damping overflow": (mjcf().replace('damping="0.1"', 'damping="1e400"'), "joint 'j' damping = '1e400'"),
    "damping blank": (mjcf().replace('damping="0.1"', 'damping=" 0.1"'), "joint 'j' damping = ' 0.1'"),
    "negative damping": (
        mjcf().replace('damping="0.1"', 'damping="-0.1"'),
        "joint 'j' damping = '-0.1': must be ≥ 0",
    ),
    "short vector": (
        mjcf().replace('axis="1 0 0"', 'axis="1 0"'),
        "joint 'j' axis = '1 0': needs exactly 3 numbers",
    ),
    "long vector": (
        mjcf(head='<option gravity="0 0 -9.81 1"/>'),
        "<option> gravity = '0 0 -9.81 1': needs exactly 3",
    ),
    "comma": (
        mjcf().replace('axis="1 0 0"', 'axis="1,0,0"'),
        "joint 'j' axis = '1,0,0': needs exactly 3 numbers",
    ),
    "zero axis": (
        mjcf().replace('axis="1 0 0"', 'axis="0 0 0"'),
        "joint 'j' axis = '0 0 0': a joint axis must not",
    ),
    "negative mass": (
        mjcf(f'<body name="b"><joint/>{NEGATIVE_MASS}</body>'),
        "body 'b' <inertial> mass = '-1': must be ≥ 0",
    ),
    # structure Pinocchio drops silently
    "second body": (
        mjcf(world=f'<body name="a"><joint/>{INERTIAL}</body>'),
        "<worldbody>: has 2 <body>; Pinocchio's reader reads the first only",
    ),
    "no name": (mjcf(f'<body pos="0 0 0"><joint/>{INERTIAL}</body>'), "a <body> has no name"),
    "frame": (
        mjcf(f'<body name="b"><joint/>{INERTIAL}<frame><body name="c"/></frame></body>'),
        "body 'b' <frame>: refused",
    ),
    "free joint": (mjcf(f'<body name="b"><freejoint/>{INERTIAL}</body>'), "body 'b' <freejoint>: refused"),
    "ball joint": (
        mjcf(f'<body name="b"><joint type="ball"/>{INERTIAL}</body>'),
        "joint 'bJoint_0' type = 'ball'",
    ),
    "two joints": (mjcf(f'<body name="b"><joint/><joint/>{INERTIAL}</body>'), "body 'b': has 2 joints"),
    "geom inertia": (
        mjcf('<body name="b"><joint/><geom type="sphere" size="0.1"/></body>'),
        "body 'b': has geoms and no <inertial>",
    ),
    "inertiafromgeom": (
        mjcf(head='<compiler inertiafromgeom="true"/>'),
        "<compiler> inertiafromgeom = 'true'",
    ),
    "fixed-axis euler": (
        mjcf(head='<compiler eulerseq="XYZ"/>'),
        "<compiler> eulerseq = 'XYZ': must be three",
    ),
    "angle unit": (
        mjcf(head='<compiler angle="grad"/>'),
        "<compiler> angle = 'grad': must be 'degree' or 'radian'",
    ),
    "non-unit axisangle": (
        mjcf(f'<body name="b" axisangle="2 0 0 90"><joint/>{INERTIAL}</body>'),
        "body 'b' axisangle = '2 0 0 90': the axis must be a unit vector",
    ),
    "two orientations": (
        mjcf(f'<body name="b" quat="1 0 0 0" euler="0 0 0"><joint/>{INERTIAL}</body>'),
        "body 'b': has quat and euler",
    ),
    "rotated fixed root": (
        mjcf(
            f'<body name="r" quat="0.5 0.5 0.5 0.5">{INERTIAL}<body name="b"><joint/>{INERTIAL}</body></body>'
        ),
        "body 'r' quat = '0.5 0.5 0.5 0.5': a fixed root body may not be rotated",
    ),
    "spring": (mjcf().replace('damping="0.1"', 'stiffness="2"'), "joint 'j' stiffness = '2': a joint spring"),
    "equality": (
        mjcf(head="<equality><connect body1='b' anchor='0 0 0'/></equality>"),
        "<equality>: refused",
    ),
    "include": (mjcf(head='<include file="other.xml"/>'), "<include>: refused"),
    "settotalmass": (
        mjcf(head='<compiler settotalmass="5"/>'),
        "<compiler> settotalmass = '5': MuJoCo would rescale",
    ),
    "boundmass": (
        mjcf(head='<compiler boundmass="5"/>'),
        "body 'b' <inertial>: compiler boundmass = '5' would",
    ),
    "fluid": (mjcf(head='<option density="1.2"/>'), "<option> density = '1.2': fluid forces are refused"),
    "sideways gravity": (
        mjcf(head='<option gravity="0 -9.81 0"/>'),
        "<option> gravity = '0 -9.81 0': must point",
    ),
    "no gravity flag": (
        mjcf(head='<option><flag gravity="disable"/></option>'),
        "<option><flag> gravity = 'disable': refused",
    ),
    "gravcomp": (mjcf(f'<body name="b" gravcomp="1"><joint/>{INERTIAL}</body>'), "body 'b' gravcomp = '1'"),
    "no inertia tensor": (
        mjcf(f'<body name="b"><joint/>{NO_TENSOR}</body>'),
        "body 'b' <inertial>: needs one of diaginertia and fullinertia",
    ),
    "no inertial pos": (
        mjcf(f'<body name="b"><joint/>{NO_POS}</body>'),
        "body 'b' <inertial>: the attribute 'pos' is missing",
    ),
    "triangle inequality": (
        mjcf(f'<body name="b"><joint/>{LOPSIDED}</body>'),
        "body 'b' <inertial> diaginertia: principal moments (0.5, 0.1, 0.1) violate the triangle inequality",
    ),
    "zero quaternion": (
        mjcf(f'<body name="b" quat="0 0 0 0"><joint/>{INERTIAL}</body>'),
        "body 'b' quat = '0 0 0 0'",
    ),
    "unknown class": (mjcf().replace("<joint ", '<joint class="x" '), "joint 'j': class 'x' is not defined"),
    "default pos": (
        mjcf(head='<default><joint pos="0 0 1"/></default>'),
        "default class 'main' <joint> pos = '0 0 1': not in a default class",
    ),
    "classes disagree": (
        mjcf(
            f'<body name="b" childclass="c"><joint name="j" class="d"/>{INERTIAL}</body>',
            head='<default><default class="c"><joint damping="0.2"/></default>'
            '<default class="d"><joint armature="0.01"/></default></default>',
        ),
        "joint 'j': damping resolves to None for MuJoCo (class 'd') but to '0.2' for Pinocchio's reader",
    ),
    "not a section": (mjcf(head="<robot/>"), "<robot>: not an MJCF section pendverify reads"),
    "not mujoco": ("<robot/>", "the root element is <robot>, an MJCF's must be <mujoco>"),
}


@pytest.mark.parametrize("case", REFUSED)
def test_refused(case):
    text, expected = REFUSED[case]
    message = refusal(text)
    assert message.startswith(expected), message


def test_without_compiler_angle_mujocos_degrees_apply_as_in_pinocchio():
    degrees = mjcf(f'<body name="b" euler="90 0 0"><joint name="j" axis="1 0 0"/>{INERTIAL}</body>')
    radians = mjcf(
        f'<body name="b" euler="1.5707963267948966 0 0"><joint name="j" axis="1 0 0"/>{INERTIAL}</body>',
        head='<compiler angle="radian"/>',
    )
    a, b = load_description(degrees), load_description(radians)
    assert np.allclose(a.model.jointPlacements[1].rotation, b.model.jointPlacements[1].rotation, atol=1e-15)
    assert np.allclose(a.model.jointPlacements[1].rotation, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-15)
    assert any("angles are in degrees, MuJoCo's default" in n for n in a.notes())
    assert not any("degrees" in n for n in b.notes())


def test_default_classes_reach_the_facts_as_mujoco_resolves_them():
    text = mjcf(
        f'<body name="b" childclass="c"><joint name="j" axis="1 0 0"/>{INERTIAL}'
        f'<body name="e" pos="0 0.5 0"><joint name="k" class="d" axis="1 0 0"/>{INERTIAL}</body></body>',
        head='<default><joint damping="0.7" frictionloss="0.01"/>'
        '<default class="c"><joint damping="0.2"/></default>'
        '<default class="d"><joint armature="0.05"/></default></default>',
    )
    model, reading, _ = build_mjcf_model(text, SOURCE)
    assert reading.facts.joint_dynamics == {"j": JointDynamics(0.2, 0.01), "k": JointDynamics(0.7, 0.01)}
    assert model.damping.tolist() == [0.2, 0.7]
    assert model.armature.tolist() == [0.0, 0.05]
    assert model.friction.tolist() == [0.01, 0.01]
    assert reading.notes == ["joint 'k' has armature 0.05: Pinocchio adds it to M"]


def test_an_unnamed_joint_gets_pinocchios_name_and_a_ref_is_mujocos_qpos():
    text = mjcf(f'<body name="b"><joint axis="1 0 0" ref="30" damping="0.1"/>{INERTIAL}</body>')
    model, reading, _ = build_mjcf_model(text, SOURCE)
    assert reading.joints == ["bJoint_0"]
    data = model.createData()
    pin.forwardKinematics(model, data, np.array([np.pi / 6]))  # qpos = ref: the pose as written
    assert np.allclose(data.oMi[1].rotation, np.eye(3), atol=1e-15)


def test_the_model_guard_refuses_a_model_unlike_the_reading():
    """``build_mjcf_model`` compares Pinocchio's damping with the strict reading; the guard can fail."""
    model, reading, _ = build_mjcf_model(mjcf(), SOURCE)
    reading.dynamics["j"] = (0.2, 0.0, 0.0)
    with pytest.raises(UrdfShapeError, match=r"joint 'j': Pinocchio's MJCF reader gives .* refused"):
        _same_as_read(model, reading, SOURCE)
    reading.joints = ["other"]
    with pytest.raises(UrdfShapeError, match=r"Pinocchio's MJCF reader built the joints \['j'\]"):
        _same_as_read(model, reading, SOURCE)


def test_the_mjcf_gravity_is_used_when_the_closed_form_gives_none():
    text = SEED_MJCF.read_text().replace('gravity="0 0 -9.81"', 'gravity="0 0 -9.80665"')
    system = PinocchioSystem.for_model(MODELS["double_pendulum"], text)
    assert system.geometry.params.g == 9.80665
    assert system.model.gravity.linear.tolist() == [0.0, 0.0, -9.80665]
    given = PinocchioSystem.for_model(MODELS["double_pendulum"], text, g=9.81)
    assert given.model.gravity.linear.tolist() == [0.0, 0.0, -9.81]
    assert "the description's own gravity is g = 9.80665 m/s²" in " ".join(given.notes)
