"""Robots given as Pinocchio objects (issue 25, item 5): a ``pinocchio.Model`` or ``RobotWrapper``.

example-robot-data 6 ships its URDFs but no Python loader (``example_robot_data.load``), so
the RobotWrapper is built as that loader builds it, ``RobotWrapper.BuildFromURDF`` on the
installed double-pendulum URDF.  ``check`` gives the same verdicts on the wrapper, its model
and the URDF path; a 1 % mass change in the wrapper's model fails; the caller's model is never
changed; a certificate embeds the URDF text given with the model only when it builds that very
model, and refuses a model without one, saying so.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pendverify
from pendverify import api
from pendverify.certify.issue import certification_input
from pendverify.errors import PendverifyError
from pendverify.robot import erd
from pendverify.robot.pinocchio_model import describe_model
from pendverify.viz.geometry import VisualSystem

pytestmark = pytest.mark.skipif(erd.installed() is None, reason="example-robot-data is not installed")
STEM = "double_pendulum_simple"
SCENE = Path(__file__).resolve().parents[2] / "scenes" / "minimal_double_pendulum_release.toml"


@pytest.fixture
def urdf_path():
    return erd.family_urdfs()[STEM]


@pytest.fixture
def robot(urdf_path):
    return pin.RobotWrapper.BuildFromURDF(str(urdf_path))


def verdicts(report) -> dict[str, list[str]]:
    return {check: [r.status for r in report[check]] for check in report.checks}


def params_of(urdf_path) -> dict[str, float]:
    return api.load_urdf("double_pendulum", urdf_path).geometry.params.as_dict()


def test_a_robot_wrapper_and_its_model_verify_as_the_urdf_does(robot, urdf_path):
    params = params_of(urdf_path)
    by_path = api.check("double_pendulum", urdf_path, params)
    assert by_path.passed
    for given in (robot, robot.model):
        report = api.check("double_pendulum", given, params)
        assert verdicts(report) == verdicts(by_path), f"{type(given).__name__}"
    target = report.models[0]
    assert target == f"double_pendulum:{robot.model.name}"


def test_parameters_are_read_off_the_model_as_off_the_urdf(robot, urdf_path):
    system = api.load_urdf("double_pendulum", robot)
    assert system.geometry.params == api.load_urdf("double_pendulum", urdf_path).geometry.params
    assert system.source == f"<pinocchio.Model {robot.model.name!r}>"
    assert system.urdf.format == "pinocchio"
    assert any("a 0 cannot be told from one not given" in n for n in system.notes)
    assert any("no URDF text is known" in n for n in system.notes)


def test_a_one_percent_mass_error_in_the_wrapper_fails(robot, urdf_path):
    params = params_of(urdf_path)
    inertia = robot.model.inertias[2]
    robot.model.inertias[2] = pin.Inertia(inertia.mass * 1.01, inertia.lever, inertia.inertia)
    report = api.check("double_pendulum", robot, params)
    assert not report.passed
    assert not report["crba"].passed and not report["gravity"].passed


def test_the_callers_model_is_left_as_it_was(robot, urdf_path):
    base = robot.model.jointPlacements[1].copy()
    base.translation = np.array([0.0, 0.0, 2.0])
    robot.model.jointPlacements[1] = base
    gravity = robot.model.gravity.linear.copy()
    system = api.load_urdf("double_pendulum", robot, g=3.0)
    assert robot.model.jointPlacements[1].translation.tolist() == [0.0, 0.0, 2.0]  # anchored: the copy
    assert robot.model.gravity.linear.tolist() == gravity.tolist()
    assert system.model.jointPlacements[1].translation.tolist() == [0.0, 0.0, 0.0]


def test_damping_is_declared_where_non_zero(robot):
    robot.model.damping[:] = [0.0, 0.2]
    facts = describe_model(robot).facts
    assert set(facts.joint_dynamics) == {robot.model.names[2]}
    assert facts.joint_dynamics[robot.model.names[2]].damping == 0.2
    robot.model.damping[0] = np.nan
    with pytest.raises(PendverifyError, match=r"model.damping = \[nan, 0.2\]: must be finite and ≥ 0"):
        describe_model(robot)


def test_anything_else_is_refused_by_name():
    with pytest.raises(PendverifyError, match=r"a pinocchio\.Model or a RobotWrapper; got a int"):
        api.check("double_pendulum", 3)


def test_simulate_and_render_take_the_wrapper_and_draw_its_visual_model(robot):
    visual = VisualSystem.for_model(api.load_model("double_pendulum"), describe_model(robot))
    assert [o.name for o in visual.objects] == [o.name for o in robot.visual_model.geometryObjects]
    run = api.simulate(SCENE, urdf=robot)
    assert run.metadata()["urdf"] == f"<pinocchio.Model {robot.model.name!r}>"
    page = api.animation_html(api.trajectory(run))
    assert page.startswith("<!DOCTYPE html>")


def test_a_certificate_embeds_the_urdf_text_only_when_it_builds_the_model(robot, urdf_path):
    text = urdf_path.read_text()
    with pytest.raises(PendverifyError, match="no URDF text is known for this model, and a certificate"):
        certification_input(urdf=describe_model(robot), model="double_pendulum")
    target = certification_input(
        urdf=describe_model(api.PinocchioRobot(robot.model, urdf_text=text)), model="double_pendulum"
    )
    assert target.urdf == text and target.name == f"double_pendulum-{robot.model.name}"  # model, then URDF
    inertia = robot.model.inertias[1]
    robot.model.inertias[1] = pin.Inertia(inertia.mass * 1.01, inertia.lever, inertia.inertia)
    with pytest.raises(PendverifyError, match=r"builds another model: joint .*: the inertia of its body"):
        certification_input(
            urdf=describe_model(api.PinocchioRobot(robot.model, urdf_text=text)), model="double_pendulum"
        )


def test_the_lazy_package_names_the_api():
    assert pendverify.ros_packages is api.ros_packages


@pytest.mark.parametrize("command", ["stress", "mutate"])
def test_commands_that_reread_the_file_refuse_a_model_saying_so(robot, command):
    model = Path(__file__).resolve().parents[2] / "examples" / "minimal_double_pendulum.py"
    with pytest.raises(PendverifyError, match=f"{command} takes the URDF as a file path"):
        getattr(api, command)(model=model, urdf=robot.model, params=model.with_suffix(".toml"))
