"""Strict reading of a URDF's numbers: each planted fault is one line naming file, place, value and rule."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from pendverify.errors import UrdfShapeError
from pendverify.robot.erd import family_urdfs
from pendverify.robot.inertia_rounding import FLOAT_SLACK, check_inertia_tensor, inertia_tolerance, resolution
from pendverify.robot.strict import DescriptionFacts, JointDynamics, read_urdf_strictly
from pendverify.robot.urdfdom import build_pinocchio_model

REPO = Path(__file__).resolve().parents[2]
SOURCE = "robot.urdf"
NAN_RULE = "not a finite decimal number"

#: A two-link pendulum; every field can be replaced by a test.
PENDULUM = """<?xml version="1.0"?>
<robot name="pendulum">
  <link name="base"/>
  <joint name="j1" type="revolute">
    <parent link="base"/>
    <child link="link1"/>
    <origin xyz="{j1_xyz}" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="10" velocity="5"/>
    {j1_dynamics}
  </joint>
  <link name="link1">
    <inertial>
      <origin xyz="0 0 -0.25" rpy="0 0 0"/>
      <mass value="{m1}"/>
      <inertia ixx="{ixx1}" ixy="0" ixz="0" iyy="{iyy1}" iyz="0" izz="{izz1}"/>
    </inertial>
  </link>
  <joint name="j2" type="continuous">
    <parent link="link1"/>
    <child link="link2"/>
    <origin xyz="0 0 -0.5" rpy="0 0 0"/>
    <axis xyz="1 0 0"/>
    {j2_dynamics}
  </joint>
  <link name="link2">
    <inertial>
      <origin xyz="0 0 -0.2" rpy="0 0 0"/>
      <mass value="0.8"/>
      <inertia ixx="{ixx2}" ixy="{ixy2}" ixz="0" iyy="0.0135" iyz="0" izz="0.0001"/>
    </inertial>
  </link>
</robot>
"""
DEFAULTS = {
    "j1_xyz": "0 0 0",
    "j1_dynamics": '<dynamics damping="0.05"/>',
    "j2_dynamics": '<dynamics friction="0.01"/>',
    "m1": "1.0",
    "ixx1": "0.0208",
    "iyy1": "0.0208",
    "izz1": "0.0001",
    "ixx2": "0.0135",
    "ixy2": "0",
}


def pendulum(**changes: str) -> str:
    return PENDULUM.format(**{**DEFAULTS, **changes})


def refusal(text: str) -> str:
    with pytest.raises(UrdfShapeError) as info:
        read_urdf_strictly(text, SOURCE)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_the_plain_pendulum_is_accepted():
    model, facts, log = build_pinocchio_model(pendulum(), SOURCE)
    assert model.njoints == 3
    assert log == []
    assert facts == DescriptionFacts(
        joint_dynamics={"j1": JointDynamics(0.05, None), "j2": JointDynamics(None, 0.01)},
        joint_types={"j1": "revolute", "j2": "continuous"},
    )


# --------------------------------------------------------------------------- malformed numbers


@pytest.mark.parametrize("value", ["np.float64(0.0093)", "0,0093"])
def test_malformed_inertia_is_refused_where_pinocchio_would_zero_it(value, capfd):
    text = pendulum(ixx2=value)
    assert refusal(text) == (
        f"robot.urdf: link 'link2' <inertial><inertia> ixx = {value!r}: not a finite decimal number"
    )
    # Why the check is needed: Pinocchio accepts the file, logs to stderr, and link 2 loses
    # its whole inertia tensor while keeping its mass.
    model = pin.buildModelFromXML(text)
    assert "inertia element ixx is not a valid double" in capfd.readouterr().err
    link2 = model.inertias[model.getJointId("j2")]
    assert link2.mass == 0.8
    assert np.all(link2.inertia == 0.0)
    good = pin.buildModelFromXML(pendulum())
    assert good.inertias[good.getJointId("j2")].inertia[0, 0] == 0.0135


@pytest.mark.parametrize(
    ("field", "value", "place", "rule"),
    [
        ("m1", "1e400", "link 'link1' <inertial><mass> value", f"{NAN_RULE} (it overflows a double)"),
        ("ixx1", "nan", "link 'link1' <inertial><inertia> ixx", "not a finite decimal number"),
        ("ixx1", "inf", "link 'link1' <inertial><inertia> ixx", "not a finite decimal number"),
        ("iyy1", "", "link 'link1' <inertial><inertia> iyy", "not a finite decimal number"),
        ("izz1", "1.2.3", "link 'link1' <inertial><inertia> izz", "not a finite decimal number"),
        ("m1", "1.0 ", "link 'link1' <inertial><mass> value", "not a finite decimal number "
         "(surrounding whitespace is not allowed: urdfdom does not read a trailing blank)"),
        ("m1", "-1", "link 'link1' <inertial><mass> value", "must be ≥ 0"),
    ],
)  # fmt: skip
def test_bad_scalars_are_named(field, value, place, rule):
    assert refusal(pendulum(**{field: value})) == f"robot.urdf: {place} = {value!r}: {rule}"


def test_the_offending_joint_is_named():
    text = pendulum(j2_dynamics='<dynamics damping="-0.1"/>')
    assert refusal(text) == "robot.urdf: joint 'j2' <dynamics> damping = '-0.1': must be ≥ 0"


@pytest.mark.parametrize(
    ("value", "rule"),
    [
        ("0 0", "needs exactly 3 numbers separated by spaces, found 2"),
        ("0 0 0 1", "needs exactly 3 numbers separated by spaces, found 4"),
        ("0 nan 0", "number 2, 'nan', is not a finite decimal number"),
        ("0,0,0", "needs exactly 3 numbers separated by spaces, found 1"),
        ("0 0\t0", "separate the numbers with spaces only; urdfdom does not split on tabs or line breaks"),
    ],
)
def test_vectors_need_their_count_of_numbers(value, rule):
    assert refusal(pendulum(j1_xyz=value)) == f"robot.urdf: joint 'j1' <origin> xyz = {value!r}: {rule}"


def test_a_line_break_inside_an_inertial_origin_is_refused(capfd):
    """XML reports a literal line break in an attribute as a space; urdfdom then drops the inertial."""
    text = pendulum().replace('<origin xyz="0 0 -0.25"', '<origin xyz="0 0\n-0.25"')
    assert refusal(text) == (
        "robot.urdf: link 'link1' <inertial><origin> xyz = '0 0\\n-0.25': "
        "separate the numbers with spaces only; urdfdom does not split on tabs or line breaks"
    )
    model = pin.buildModelFromXML(text)  # what Pinocchio alone would have done
    assert "Could not parse inertial element for Link [link1]" in capfd.readouterr().err
    assert model.inertias[model.getJointId("j1")].mass == 0.0


def test_every_listed_element_is_checked_wherever_it_occurs():
    text = pendulum().replace(
        '<link name="base"/>',
        '<link name="base"><visual><geometry>'
        '<cylinder radius="0.01" length="-0.5"/></geometry></visual></link>',
    )
    assert refusal(text) == (
        "robot.urdf: link 'base' <visual><geometry><cylinder> length = '-0.5': must be ≥ 0"
    )
    text = pendulum().replace(
        '<robot name="pendulum">',
        '<robot name="pendulum"><material name="red"><color rgba="1 0 0"/></material>',
    )
    assert refusal(text) == (
        "robot.urdf: material 'red' <color> rgba = '1 0 0': "
        "needs exactly 4 numbers separated by spaces, found 3"
    )


def test_pinocchios_own_collision_checking_capsule_is_not_a_urdf_shape():
    """``<collision_checking><capsule name=.../>`` (a Pinocchio extension) has no radius and needs none."""
    text = pendulum().replace(
        '<link name="base"/>',
        '<link name="base"><collision_checking><capsule name="rod"/></collision_checking></link>',
    )
    read_urdf_strictly(text, SOURCE)
    shape = text.replace('<capsule name="rod"/>', '<capsule name="rod" radius="-1"/>')
    assert (
        refusal(shape) == "robot.urdf: link 'base' <collision_checking><capsule> radius = '-1': must be ≥ 0"
    )


def test_what_urdfdom_would_silently_drop_is_refused():
    missing = pendulum().replace(' ixy="{ixy2}"'.format(**DEFAULTS), "", 1)
    assert refusal(missing) == (
        "robot.urdf: link 'link1' <inertial><inertia>: the attribute 'ixy' is missing "
        "(urdfdom refuses the file or drops the element)"
    )
    twice = pendulum(j1_dynamics='<dynamics damping="0.05"/><dynamics damping="0.5"/>')
    assert refusal(twice) == (
        "robot.urdf: joint 'j1': has 2 <dynamics> elements; urdfdom silently uses the first, so one at most"
    )


# --------------------------------------------------------------------------- inertia tensors


def test_a_tensor_that_is_not_positive_semi_definite_is_refused():
    message = refusal(pendulum(ixx2="0.0135", ixy2="0.0200"))
    assert message == (
        "robot.urdf: link 'link2' <inertial><inertia>: principal moments (0.0335, 0.0001, -0.0065) "
        "include a negative one, -0.0065 (an inertia tensor must be positive semi-definite)"
    )


def test_a_triangle_inequality_violation_is_refused():
    message = refusal(pendulum(ixx1="0.1000", iyy1="0.0100", izz1="0.0100"))
    assert message == (
        "robot.urdf: link 'link1' <inertial><inertia>: principal moments (0.1, 0.01, 0.01) violate the "
        "triangle inequality 0.1 ≤ 0.01 + 0.01 (a rigid body's moments must satisfy it)"
    )


def test_a_thin_rod_rounded_to_four_digits_is_accepted():
    """1/6, 1/12, 1/12 written as 0.1667, 0.0833, 0.0833: 0.1667 > 0.0833 + 0.0833 only by rounding."""
    text = pendulum(ixx1="0.1667", iyy1="0.0833", izz1="0.0833")
    assert 0.1667 > 0.0833 + 0.0833
    read_urdf_strictly(text, SOURCE)
    # ... while the same body mistyped by a digit is still caught.
    assert "violate the triangle inequality" in refusal(pendulum(ixx1="0.1867", iyy1="0.0833", izz1="0.0833"))


def test_the_tolerance_is_only_as_sharp_as_the_written_digits():
    """'0.1' stands for anything in [0.05, 0.15]: the same tensor written coarsely is given the benefit."""
    read_urdf_strictly(pendulum(ixx1="0.1", iyy1="0.01", izz1="0.01"), SOURCE)


def test_resolution_is_half_a_unit_in_the_last_written_digit():
    assert resolution("0.1667") == pytest.approx(5e-5)
    assert resolution("1e-3") == pytest.approx(5e-4)
    assert resolution("2.5E-06") == pytest.approx(5e-8)
    assert resolution("12") == 0.5
    assert resolution("1.") == 0.5
    assert resolution(".25") == pytest.approx(5e-3)


def test_written_zeros_take_the_grid_of_their_tensor():
    rod = {"ixx": "0.0208", "ixy": "0", "ixz": "0", "iyy": "0.0", "iyz": "0", "izz": "0.0208"}
    # Nine entries on the 5e-5 grid: ‖R‖_F = 3·5e-5 (plus a float slack of order 1e-17).
    assert inertia_tolerance(rod) == pytest.approx(1.5e-4, rel=1e-9)
    zero = dict.fromkeys(rod, "0")
    assert inertia_tolerance(zero) == 0.0


def test_a_huge_tensor_keeps_a_finite_tolerance_and_a_negative_moment_is_still_refused():
    big = "1.00000e300"  # written to 6 digits: each entry within 5e294
    huge = {"ixx": big, "ixy": "0", "ixz": "0", "iyy": big, "iyz": "0", "izz": big}
    # ‖R‖_F = √3·5e294 (the written zeros: 0.5 each) and ‖I‖_F = √3·1e300, although the squares overflow
    expected = 3**0.5 * resolution(big) + FLOAT_SLACK * np.finfo(float).eps * 3**0.5 * 1e300
    assert inertia_tolerance(huge) == pytest.approx(expected, rel=1e-12)
    with pytest.raises(UrdfShapeError, match="include a negative one"):
        check_inertia_tensor({**huge, "izz": "-" + big}, "link1", SOURCE)


# --------------------------------------------------------------------------- XML


def test_a_doctype_with_an_entity_is_refused():
    text = (
        '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY m "1.0">]>\n' + pendulum(m1="&m;").split("\n", 1)[1]
    )
    message = refusal(text)
    assert message.startswith("robot.urdf: XML with a DOCTYPE or entities is refused (DTDForbidden(")


def test_malformed_xml_names_line_and_column():
    text = pendulum().replace("</inertial>\n  </link>\n  <joint", "</inertial>\n  <joint", 1)
    message = refusal(text)
    assert message.startswith("robot.urdf: malformed XML at line ")
    assert "column" in message and "mismatched tag" in message


def test_the_root_must_be_robot():
    assert refusal("<model/>") == "robot.urdf: the root element is <model>, a URDF's must be <robot>"


# --------------------------------------------------------------------------- Pinocchio's own refusals


def test_a_pinocchio_refusal_carries_urdfdoms_reason(capfd):
    text = pendulum().replace('<parent link="link1"/>', '<parent link="link9"/>')
    read_urdf_strictly(text, SOURCE)  # every number is fine
    with pytest.raises(UrdfShapeError) as info:
        build_pinocchio_model(text, SOURCE)
    message = str(info.value)
    assert message.startswith(
        "robot.urdf: Pinocchio cannot parse it as URDF: "
        "Failed to build tree: parent link [link9] of joint [j2] not found."
    )
    assert "does not contain a valid URDF model" not in message
    assert "\n" not in message
    assert "at line" not in message  # urdfdom's C++ source locations are dropped
    assert capfd.readouterr().err == ""  # nothing leaked to the terminal
    os.write(2, b"fd 2 restored\n")
    assert capfd.readouterr().err == "fd 2 restored\n"


def test_what_urdfdom_logs_on_success_is_returned_not_printed(capfd):
    """This urdfdom does not know <capsule>: it drops the collision with a log line and succeeds."""
    text = pendulum().replace(
        '<link name="base"/>',
        '<link name="base"><collision><geometry>'
        '<capsule radius="0.1" length="0.2"/></geometry></collision></link>',
    )
    model, _, log = build_pinocchio_model(text, SOURCE)
    assert model.njoints == 3
    assert capfd.readouterr().err == ""
    if log:  # a newer urdfdom may know capsules
        assert log == ["Error: Could not parse collision element for Link [base]"]


def test_a_world_link_and_fixed_joint_merge_into_the_universe():
    text = pendulum().replace(
        '<link name="base"/>',
        '<link name="world"/>\n  <joint name="anchor" type="fixed"><parent link="world"/><child link="base"/>'
        '<origin xyz="0 0 1" rpy="0 0 0"/></joint>\n  <link name="base"/>',
    )
    model, facts, log = build_pinocchio_model(text, SOURCE)
    assert log == []
    assert list(model.names) == ["universe", "j1", "j2"]
    assert {"world", "anchor", "base"} <= {frame.name for frame in model.frames}
    assert model.jointPlacements[1].translation.tolist() == [0.0, 0.0, 1.0]
    assert facts.joint_types == {"anchor": "fixed", "j1": "revolute", "j2": "continuous"}


# --------------------------------------------------------------------------- facts


def test_facts_tell_absent_damping_from_zero_damping():
    text = pendulum(j1_dynamics='<dynamics damping="0" friction="0.2"/>', j2_dynamics="")
    model, facts, _ = build_pinocchio_model(text, SOURCE)
    assert facts.joint_dynamics == {"j1": JointDynamics(damping=0.0, friction=0.2)}
    assert model.damping.tolist() == [0.0, 0.0]  # Pinocchio cannot tell the two apart
    assert refusal(pendulum(j2_dynamics="<dynamics/>")) == (
        "robot.urdf: joint 'j2' <dynamics>: has neither 'damping' nor 'friction' "
        "(urdfdom refuses an empty <dynamics>)"
    )


# --------------------------------------------------------------------------- shipped files


SHIPPED = {
    **{
        f"urdf/{name}": REPO / "urdf" / name for name in ("double_pendulum.urdf", "cart_double_pendulum.urdf")
    },
    **{f"examples/{p.name}": p for p in sorted((REPO / "examples").glob("*.urdf"))},
    **{f"example-robot-data/{stem}": path for stem, path in family_urdfs().items()},
}


@pytest.mark.parametrize("name", sorted(SHIPPED))
def test_shipped_urdfs_are_accepted(name, capfd):
    model, facts, log = build_pinocchio_model(SHIPPED[name].read_text(), name)
    assert log == []
    assert capfd.readouterr().err == ""
    assert model.njoints >= 2  # the universe and at least one joint (a single pendulum has one)
    assert set(facts.joint_dynamics) <= set(facts.joint_types)


def test_every_shipped_family_is_present():
    assert len([n for n in SHIPPED if n.startswith("examples/")]) >= 2
    assert {"double_pendulum", "double_pendulum_continuous", "double_pendulum_simple"} <= {
        n.split("/")[1] for n in SHIPPED if n.startswith("example-robot-data/")
    }


def test_a_zero_joint_axis_is_refused():
    # Pinocchio accepts it as a revolute joint about nothing
    text = pendulum().replace('<axis xyz="1 0 0"/>', '<axis xyz="0 0 0"/>', 1)
    assert "joint 'j1' <axis> xyz = '0 0 0': a joint axis must not be the zero vector" in refusal(text)
