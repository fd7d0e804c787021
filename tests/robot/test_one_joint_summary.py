"""``show --robot`` on robots of one degree of freedom, and the joint Jacobians under it.

Pinocchio hands a 6 × 1 Jacobian back as a 1-D array of 6; the summary sliced it as 6 × nv
and crashed (exit 3) on every one-joint robot.  Planted here: the brief's dynamics-only
pendulum URDF, a prismatic cart and dm_control's pendulum MJCF; the summary must give each
joint's kind, axis, mass and centre of mass as the file has them, and a changed axis or mass
in the file must show (the summary reads the file, it does not fill in a default).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pendverify import api
from pendverify.cli import main
from pendverify.robot.jacobian import joint_jacobian, joint_jacobians
from pendverify.robot.writer import urdf_for

from ..commands.test_show_robot import rows
from ..conftest import default_params
from .one_joint import PENDULUM_URDF, dm_control_pendulum, write_one_joint


def test_joint_jacobians_are_6_by_nv_for_one_and_two_joints(tmp_path):
    one = pin.buildModelFromXML(PENDULUM_URDF)
    two = pin.buildModelFromXML(urdf_for(default_params("double_pendulum")))
    for model in (one, two):
        data = model.createData()
        q = pin.neutral(model)
        world = joint_jacobians(model, data, q)
        assert world.shape == (6, model.nv), f"{model.name}: {world.shape}"
        np.testing.assert_array_equal(world.ravel(), np.reshape(data.J, (6, model.nv)).ravel())
        for j in range(1, model.njoints):
            local = joint_jacobian(model, data, j, pin.LOCAL)
            assert local.shape == (6, model.nv)
            raw = np.reshape(pin.getJointJacobian(model, data, j, pin.LOCAL), (6, model.nv))
            np.testing.assert_array_equal(local, raw)
    # the pendulum's hinge turns about +y: its motion is the angular unit vector y
    np.testing.assert_array_equal(
        joint_jacobians(one, one.createData(), pin.neutral(one))[:, 0], [0, 0, 0, 0, 1, 0]
    )


@pytest.mark.parametrize(
    ("name", "joint", "kind", "axis", "mass", "com", "damping"),
    [
        ("pendulum", "hinge", "continuous", "0 1 0", "2", "0 0 -0.5", "0.1 N·m·s/rad"),
        ("cart", "slider", "prismatic", "1 0 0", "1.5", "0 0 0", "0.3 N·s/m"),
        ("dm_pendulum", "hinge", "revolute", "0 1 0", "1", "0 0 0.5", "0.1 N·m·s/rad"),
    ],
)
def test_show_robot_on_a_one_joint_robot(name, joint, kind, axis, mass, com, damping, tmp_path, capsys):
    if name == "dm_pendulum" and dm_control_pendulum() is None:
        pytest.skip("dm_control is not installed")
    robot = write_one_joint(name, tmp_path).robot
    assert main(["show", "--robot", str(robot)]) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert out.splitlines()[0].endswith("as Pinocchio will use it: 1 joint"), out
    assert f"joint {joint}: {kind}, on the fixed base" in out
    table = rows(out)
    assert " ".join(table[(joint, "axis")].split()[1:4]) == axis, f"{name=}"
    assert table[(joint, "mass")].split()[1] == mass, f"{name=}"
    assert " ".join(table[(joint, "com")].split()[1:4]) == com, f"{name=}"
    assert " ".join(table[(joint, "damping")].split()[1:3]) == damping, f"{name=}"


def test_a_changed_axis_or_mass_of_a_one_joint_urdf_shows(tmp_path):
    robot = write_one_joint("pendulum", tmp_path).robot
    text = robot.read_text()
    robot.write_text(text.replace('axis xyz="0 1 0"', 'axis xyz="1 0 0"').replace('"2.0"', '"2.2"'))
    (hinge,) = api.read_robot(robot).joints
    values = {q.name: q.value for q in hinge.quantities}
    assert values["axis"] == (1.0, 0.0, 0.0)
    assert values["mass"] == (2.2,)


def test_a_bad_one_joint_urdf_is_still_one_line(tmp_path, capsys):
    robot = write_one_joint("pendulum", tmp_path).robot
    robot.write_text(robot.read_text().replace('"2.0"', '"-2.0"'))
    assert main(["show", "--robot", str(robot)]) == 2
    err = capsys.readouterr().err
    assert "pend.urdf" in err and "'-2.0': must be ≥ 0" in err and "Traceback" not in err
