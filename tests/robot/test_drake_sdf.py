"""SDFormat through Drake (issue 25, item 3): Drake's own example files verify against hand models.

Drake's wheel ships ``examples/acrobot/Acrobot.sdf`` and ``examples/multibody/cart_pole/cart_pole.sdf``
(found through ``pydrake.common.FindResourceOrThrow``).  Each verifies against a hand model
written here — the example cart-pole and the hanging double pendulum of ``examples/``, mapped to
Drake's joint names — with the parameters Drake's files state; a 1 % mass error in each hand model
fails.  Drake's log is captured, a conversion Drake disagrees with is refused, and joints
pendverify does not read are refused by name.  Skipped when pydrake is not installed.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

from pendverify import api
from pendverify.errors import UrdfShapeError
from pendverify.examples.cart_pole import CartPole
from pendverify.examples.hanging_double_pendulum import HangingDoublePendulum
from pendverify.robot import sdf_drake
from pendverify.robot.description import load_description

common = pytest.importorskip("pydrake.common")
CART_POLE = common.FindResourceOrThrow("drake/examples/multibody/cart_pole/cart_pole.sdf")
ACROBOT = common.FindResourceOrThrow("drake/examples/acrobot/Acrobot.sdf")


class DrakeCartPole(CartPole):
    """The example cart-pole (θ from upright) on Drake's cart_pole.sdf: its pole hangs at joint
    angle 0 and turns about −y, like examples/cart_pole.urdf; only the joints' names differ."""

    urdf_joints = ("CartSlider", "PolePin")


class DrakeAcrobot(HangingDoublePendulum):
    """Absolute angles from hanging on Drake's Acrobot.sdf: both joints turn about +y (a link
    hanging along −z swings towards −x), the elbow relative to the upper link, so q = T φ with
    T = [[1, 0], [−1, 1]] and no offset."""

    urdf_joints = ("shoulder", "elbow")
    joint_transform = ((1.0, 0.0), (-1.0, 1.0))
    joint_offset = (0.0, 0.0)


#: cart_pole.sdf's numbers (cart_pole_params.h): a point-mass pole 0.5 m below the pin
CART_POLE_PARAMS = {"mc": 10.0, "mp": 1.0, "r": 0.5, "I": 1e-20, "bx": 0.0, "bt": 0.0, "g": 9.81}
#: Acrobot.sdf's numbers: links of 1 kg, centres of mass 0.5 m and 1 m from their joints,
#: inertias about the centres of mass 0.083 and 0.33 kg·m² about the hinge axis, damping 0.1
ACROBOT_PARAMS = {
    "m1": 1.0,
    "m2": 1.0,
    "l1": 1.0,
    "l2": 2.1,
    "r1": 0.5,
    "r2": 1.0,
    "I1": 0.083,
    "I2": 0.33,
    "b1": 0.1,
    "b2": 0.1,
    "g": 9.81,
}
CASES = {
    "cart_pole": (DrakeCartPole, CART_POLE, CART_POLE_PARAMS, "mp"),
    "acrobot": (DrakeAcrobot, ACROBOT, ACROBOT_PARAMS, "m2"),
}


@pytest.mark.parametrize("case", CASES)
def test_drakes_example_verifies_against_its_hand_model(case):
    model, path, params, _ = CASES[case]
    report = api.check(model, path, params)
    assert report.passed, f"{case=}\n{report}"
    assert {"crba", "gravity"} <= set(report.checks), f"{case=}"


@pytest.mark.parametrize("case", CASES)
def test_a_one_percent_mass_error_in_the_hand_model_fails(case):
    model, path, params, mass = CASES[case]
    wrong = {**params, mass: params[mass] * 1.01}
    report = api.check(model, path, wrong)
    assert not report.passed, f"{case=}"
    assert not report["crba"].passed, f"{case=}"


def test_the_acrobots_damping_and_base_are_read():
    loaded = load_description(ACROBOT)
    assert loaded.format == "sdf" and list(loaded.model.names)[1:] == ["shoulder", "elbow"]
    assert loaded.model.damping.tolist() == [0.1, 0.1]
    assert loaded.facts.joint_dynamics["elbow"].damping == 0.1
    assert loaded.base_offset == pytest.approx(0.15)  # the shoulder stands 0.15 m along y


def test_drakes_log_is_captured_not_printed(capsys, caplog):
    """An element Drake ignores (a link's ``self_collide``): Drake's warning is the description's log."""
    text = Path(ACROBOT).read_text()
    text = text.replace(
        '<link name="lower_link">', '<link name="lower_link"><self_collide>true</self_collide>', 1
    )
    with caplog.at_level(logging.DEBUG):
        loaded = load_description(text)
    assert any("Ignoring unsupported SDFormat element in link: self_collide" in line for line in loaded.log)
    assert any("self_collide" in note for note in loaded.notes())
    assert "self_collide" not in capsys.readouterr().err
    assert not [r for r in caplog.records if "self_collide" in r.getMessage()]


def test_a_conversion_drake_disagrees_with_is_refused(monkeypatch):
    """A planted error in the conversion (the bodies' masses 1 % high) is caught by the cross-check."""
    inertia = sdf_drake._inertia

    def heavier(body, X_JB):
        found = inertia(body, X_JB)
        found.mass = found.mass * 1.01
        return found

    monkeypatch.setattr(sdf_drake, "_inertia", heavier)
    with pytest.raises(UrdfShapeError, match="disagrees with Drake on M by"):
        load_description(ACROBOT)


def test_a_ball_joint_is_refused_by_name():
    text = (
        Path(ACROBOT)
        .read_text()
        .replace('<joint name="elbow" type="revolute">', '<joint name="elbow" type="ball">')
    )
    with pytest.raises(
        UrdfShapeError, match="joint 'elbow' is ball_rpy: pendverify reads revolute, prismatic"
    ):
        load_description(text)


def test_a_free_body_is_refused():
    text = Path(ACROBOT).read_text()
    start, end = text.index('<joint name="base_weld"'), text.index("</joint>") + len("</joint>")
    with pytest.raises(UrdfShapeError, match="body 'base_link' has no joint to the world"):
        load_description(text[:start] + text[end:])


def test_a_links_gravity_switch_is_not_read_as_a_gravity_vector():
    """SDFormat's ``<link><gravity>`` is a boolean; a ``<world><gravity>`` holds three numbers."""
    text = Path(ACROBOT).read_text()
    text = text.replace('<link name="lower_link">', '<link name="lower_link"><gravity>true</gravity>', 1)
    assert load_description(text).model.nv == 2


def test_the_cross_check_tolerance_is_rounding_sized():
    """The cross-check's tolerance is ~1e-12 of the terms' scale: far below any modelling error."""
    n = 2
    assert sdf_drake.CROSS_CHECK_ULPS * n * np.finfo(float).eps < 1e-12


#: each case's hand model as a model file (certify embeds a model file's text)
MODEL_FILES = {
    "cart_pole": (
        "from pendverify.examples.cart_pole import CartPole\n\n\n"
        "class DrakeCartPole(CartPole):\n"
        '    urdf_joints = ("CartSlider", "PolePin")\n'
    ),
    "acrobot": (
        "from pendverify.examples.hanging_double_pendulum import HangingDoublePendulum\n\n\n"
        "class DrakeAcrobot(HangingDoublePendulum):\n"
        '    urdf_joints = ("shoulder", "elbow")\n'
        "    joint_transform = ((1.0, 0.0), (-1.0, 1.0))\n"
        "    joint_offset = (0.0, 0.0)\n"
    ),
}


@pytest.mark.parametrize("case", CASES)
def test_drakes_example_is_drawn_with_its_visual_geometry(case):
    from pendverify.viz.geometry import VisualSystem

    model, path, _, _ = CASES[case]
    visuals = VisualSystem.for_model(model, path)
    drawn = {o.parentJoint for o in visuals.objects}
    assert set(range(1, visuals.system.model.njoints)) <= drawn, f"{case}: joints drawn {drawn}"


@pytest.mark.parametrize("case", CASES)
def test_drakes_example_is_certified_and_rechecked(tmp_path, case):
    model, path, params, mass = CASES[case]
    model_file = tmp_path / f"drake_{case}.py"
    model_file.write_text(MODEL_FILES[case])

    def params_file(values: dict[str, float], name: str) -> Path:
        out = tmp_path / f"{name}.toml"
        lines = [f'model = "{model.name}"', f'name = "{model.name}"', "", "[parameters]"]
        out.write_text("\n".join(lines + [f"{k} = {float(v)!r}" for k, v in values.items()]) + "\n")
        return out

    issued = api.certify_set(
        tmp_path / "out", urdf=path, urdf_params=params_file(params, "right"), analytic=model_file, samples=20
    )
    assert issued.certified, f"{case}: {[(i.name, i.status) for i in issued.items]}"
    bundle = issued.path.name.removesuffix(".cert.json")  # the set's name: the model's, then the file's
    assert issued.path.with_name(bundle + Path(path).suffix).read_text() == Path(path).read_text()
    assert api.recheck(issued.path, run_embedded_code=True).passed
    wrong = {**params, mass: params[mass] * 1.01}
    refused = api.certify_set(
        tmp_path / "wrong",
        urdf=path,
        urdf_params=params_file(wrong, "wrong"),
        analytic=model_file,
        samples=20,
    )
    assert not refused.certified
