"""MJCF as MuJoCo means it (issue 25, items 1, 2, 7): the files gymnasium and dm_control ship.

Each file is read unchanged from its installed package and verified against a hand model
(``tests/robot/mjcf_hand_models.py``) whose parameters are MuJoCo's compiled numbers, taken at
full precision from ``mujoco.MjModel`` here; a 1 % error in one mass fails; a Pinocchio model
that differs from MuJoCo's is refused by the cross-check; gravity tilted by 1e-5 is a
``pass (warn)``, by 10° a failure.
"""

from __future__ import annotations

import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

import pendverify.robot.mjcf as mjcf_module
from pendverify import api
from pendverify.analytic.plugin import load_model_class
from pendverify.errors import UrdfShapeError
from pendverify.robot.description import load_description
from pendverify.robot.mjcf_origins import DEFAULT, FROM_GEOMS, WRITTEN
from pendverify.robot.mujoco_warnings import caught
from tests.robot.mjcf_hand_models import GymCartDoublePole, GymCartPole, MjAcrobot, MjCartPole
from tests.robot.one_joint import write_one_joint

gymnasium = pytest.importorskip("gymnasium")
dm_control = pytest.importorskip("dm_control")
GYM = Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets"
SUITE = Path(dm_control.__file__).parent / "suite"
REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "double_pendulum.mjcf.xml"


def compiled(path: Path) -> mujoco.MjModel:
    with caught():  # MuJoCo's default handler would leave MUJOCO_LOG.TXT in the working folder
        return mujoco.MjModel.from_xml_path(str(path))


def body(mj: mujoco.MjModel, name: str) -> tuple[float, np.ndarray, float]:
    """(mass, centre of mass in the body frame, inertia about y through it) of a compiled body
    whose frame is its parent's turned by nothing and whose joint sits at its origin."""
    b = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, name)
    assert np.array_equal(mj.body_quat[b], [1, 0, 0, 0]), name
    if mj.body_jntnum[b]:
        assert not np.any(mj.jnt_pos[mj.body_jntadr[b]]), name
    w, x, y, z = mj.body_iquat[b]
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    inertia = R @ np.diag(mj.body_inertia[b]) @ R.T
    return float(mj.body_mass[b]), np.array(mj.body_ipos[b]), float(inertia[1, 1])


def damping(mj: mujoco.MjModel, joint: str) -> float:
    j = mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, joint)
    return float(mj.dof_damping[mj.jnt_dofadr[j]])


def cart_pole_params(path: Path, pole: str, hinge: str) -> dict[str, float]:
    mj = compiled(path)
    mc, _, _ = body(mj, "cart")
    mp, c, I = body(mj, pole)  # noqa: E741
    assert c[1] == 0
    return dict(
        mc=mc, mp=mp, r=math.hypot(c[0], c[2]), I=I, bx=damping(mj, "slider"), bt=damping(mj, hinge), g=9.81
    )


def cart_double_pole_params(path: Path) -> dict[str, float]:
    mj = compiled(path)
    mc, _, _ = body(mj, "cart")
    m1, c1, I1 = body(mj, "pole")
    m2, c2, I2 = body(mj, "pole2")
    assert c1[0] == c1[1] == c2[0] == c2[1] == 0  # both centres of mass on their poles' +z
    l1 = float(mj.body_pos[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, "pole2")][2])
    b = [damping(mj, j) for j in ("slider", "hinge", "hinge2")]
    return dict(
        mc=mc, m1=m1, m2=m2, l1=l1, r1=c1[2], r2=c2[2], I1=I1, I2=I2, bx=b[0], b1=b[1], b2=b[2], g=9.81
    )


def acrobot_params(path: Path) -> dict[str, float]:
    mj = compiled(path)
    m1, c1, I1 = body(mj, "upper_arm")
    m2, c2, I2 = body(mj, "lower_arm")
    assert c1[0] == c1[1] == c2[0] == c2[1] == 0
    l1 = float(mj.body_pos[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_BODY, "lower_arm")][2])
    return dict(
        m1=m1, m2=m2, l1=l1, r1=c1[2], r2=c2[2], I1=I1, I2=I2,
        b1=damping(mj, "shoulder"), b2=damping(mj, "elbow"), g=9.81,
    )  # fmt: skip


#: name → (file, hand model, its parameters from the compiled file, the mass to plant 1 % on)
CASES = {
    "gym-inverted-pendulum": (
        GYM / "inverted_pendulum.xml", GymCartPole,
        lambda: cart_pole_params(GYM / "inverted_pendulum.xml", "pole", "hinge"), "mp",
    ),
    "gym-inverted-double-pendulum": (
        GYM / "inverted_double_pendulum.xml", GymCartDoublePole,
        lambda: cart_double_pole_params(GYM / "inverted_double_pendulum.xml"), "m2",
    ),
    "dm-cartpole": (
        SUITE / "cartpole.xml", MjCartPole,
        lambda: cart_pole_params(SUITE / "cartpole.xml", "pole_1", "hinge_1"), "mp",
    ),
    "dm-acrobot": (SUITE / "acrobot.xml", MjAcrobot, lambda: acrobot_params(SUITE / "acrobot.xml"), "m1"),
}  # fmt: skip


def statuses(report) -> dict[str, str]:
    return {row.name: row.status for row in report.results}


def test_gymnasiums_pole_offset_is_the_hand_models():
    mj = compiled(GYM / "inverted_pendulum.xml")
    _, c, _ = body(mj, "pole")
    assert math.atan2(c[0], c[2]) == pytest.approx(GymCartPole.joint_offset[1], abs=4e-16)


@pytest.mark.parametrize("case", CASES)
def test_a_shipped_mujoco_file_verifies_against_its_hand_model(case):
    path, model, params, _ = CASES[case]
    report = api.check(model, str(path), params())
    found = statuses(report)
    assert report.passed, f"{case}: {report}"
    assert "fail" not in found.values() and "refused" not in found.values(), f"{case}: {found}"
    for check in ("crba", "gravity", "rnea"):
        assert found[check] == "pass", f"{case}: {found}"
    if case == "gym-inverted-double-pendulum":  # gravity 1e-5 0 −9.81: a tilt within the threshold
        assert found["model-form"] == "warn", found
        (row,) = [r for r in report.results if r.name == "model-form"]
        assert "tilted" in row.notes[0] and row.error == pytest.approx(1e-5 / 9.81)
    else:
        assert "model-form" not in found


@pytest.mark.parametrize("case", CASES)
def test_a_one_percent_mass_error_in_the_hand_model_fails(case):
    path, model, params, mass = CASES[case]
    values = params()
    values[mass] *= 1.01
    report = api.check(model, str(path), values, explain=False)
    failed = {check for check, status in statuses(report).items() if status == "fail"}
    assert {"crba", "gravity"} & failed, f"{case}: {statuses(report)}"


def test_a_pinocchio_model_unlike_mujocos_is_refused_with_the_difference(monkeypatch):
    original = mjcf_module.build_pinocchio

    def heavier(mj):
        model, joints = original(mj)
        inertia = model.inertias[2]
        inertia.mass = inertia.mass * (1 + 1e-6)
        model.inertias[2] = inertia
        return model, joints

    monkeypatch.setattr(mjcf_module, "build_pinocchio", heavier)
    with pytest.raises(UrdfShapeError, match=r"disagrees with MuJoCo's M at q = .*\(difference"):
        load_description(SUITE / "acrobot.xml")


def test_gravity_tilted_ten_degrees_fails_saying_the_files_gravity_is_not_the_models(tmp_path):
    text = (GYM / "inverted_double_pendulum.xml").read_text()
    tilt = 9.81 * math.tan(math.radians(10))
    path = tmp_path / "tilted.xml"
    path.write_text(text.replace('gravity="1e-5 0 -9.81"', f'gravity="{tilt!r} 0 -9.81"'))
    report = api.check(GymCartDoublePole, str(path), cart_double_pole_params(path), explain=False)
    (row,) = [r for r in report.results if r.name == "model-form"]
    assert row.status == "fail"
    assert "the file's gravity is not the model's" in row.notes[0]
    assert not report.passed


def test_the_shipped_example_is_accepted_by_mujoco_and_keeps_the_urdfs_dynamics():
    compiled(EXAMPLE)  # MuJoCo's compiler accepts it (it refused a zero principal moment)
    report = api.check("double_pendulum", str(EXAMPLE), REPO / "analytic" / "params" / "double_pendulum.toml")
    assert report.passed and "fail" not in statuses(report).values()


def test_origins_say_where_each_number_came_from():
    dm = load_description(SUITE / "cartpole.xml").origins
    assert dm["pole_1.mass"] == FROM_GEOMS and dm["cart.inertia"] == FROM_GEOMS
    assert dm["hinge_1.damping"] == "from default class 'pole'" and dm["slider.damping"] == WRITTEN
    assert dm["hinge_1.armature"] == DEFAULT and dm["gravity"] == DEFAULT
    mine = load_description(EXAMPLE).origins
    assert mine["link1.mass"] == WRITTEN and mine["joint1.damping"] == WRITTEN and mine["gravity"] == WRITTEN
    assert load_description(REPO / "urdf" / "double_pendulum.urdf").origins == {}


def test_strict_numbers_reach_included_files(tmp_path):
    (tmp_path / "part.xml").write_text('<mujoco><default><joint damping="0.1x"/></default></mujoco>')
    text = EXAMPLE.read_text().replace("<worldbody>", '<include file="part.xml"/>\n  <worldbody>', 1)
    (tmp_path / "main.xml").write_text(text)
    with pytest.raises(UrdfShapeError, match=r"default class 'main' <joint> damping = '0.1x'"):
        load_description(tmp_path / "main.xml")
    with pytest.raises(UrdfShapeError, match="no folder to resolve includes in"):
        load_description(text)


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        ('damping="0.05"', 'damping="0.05" stiffness="2"', "joint 'joint1' stiffness = 2: refused"),
        ('type="hinge" pos="0 0 0" axis="1 0 0" damping="0.05"', 'type="ball"', "type = 'ball': refused"),
        ('<body name="link2"', '<body name="link2" gravcomp="1"', "gravcomp = 1: refused"),
        ('<option gravity="0 0 -9.81"/>', '<option gravity="0 0 -9.81" density="1.2"/>', "fluid forces"),
        ("</mujoco>", '<equality><joint joint1="joint1" joint2="joint2"/></equality></mujoco>', "<equality>"),
        ('diaginertia="0.0208 7.2e-5 0.0208"', 'diaginertia="0.0208 0 0.0208"', "MuJoCo's compiler refuses"),
    ],
    ids=["spring", "ball", "gravcomp", "fluid", "equality", "compile-error"],
)
def test_what_changes_m_or_the_bias_and_cannot_be_carried_is_refused(old, new, expected):
    text = EXAMPLE.read_text()
    assert old in text
    with pytest.raises(UrdfShapeError, match=expected.replace("(", r"\(")):
        load_description(text.replace(old, new, 1))


INERTIAL = '<inertial pos="0 0.25 0" mass="1" diaginertia="0.02 0.01 0.02"/>'


def arm(body: str, head: str = "") -> str:
    return f'<mujoco model="arm">{head}<worldbody>{body}</worldbody></mujoco>'


def test_default_classes_childclass_and_degrees_are_mujocos():
    text = arm(
        f'<body name="b" childclass="c" euler="90 0 0"><joint name="j" axis="1 0 0"/>{INERTIAL}'
        f'<body name="e" pos="0 0.5 0"><joint name="k" class="d" axis="1 0 0"/>{INERTIAL}</body></body>',
        head='<default><joint damping="0.7" frictionloss="0.01"/>'
        '<default class="c"><joint damping="0.2"/></default>'
        '<default class="d"><joint armature="0.05"/></default></default>',
    )
    loaded = load_description(text)
    assert loaded.facts.joint_dynamics["j"].damping == 0.2 and loaded.facts.joint_dynamics["k"].damping == 0.7
    assert loaded.model.armature.tolist() == [0.0, 0.05] and loaded.model.friction.tolist() == [0.01, 0.01]
    assert np.allclose(
        loaded.model.jointPlacements[1].rotation, [[1, 0, 0], [0, 0, -1], [0, 1, 0]], atol=1e-15
    )
    assert loaded.origins["j.damping"] == "from default class 'c'"
    assert loaded.origins["k.armature"] == "from default class 'd'"


def test_an_unnamed_joint_gets_a_name_and_a_ref_is_the_pose_as_written():
    import pinocchio as pin

    loaded = load_description(
        arm(f'<body name="b"><joint axis="1 0 0" ref="30" damping="0.1"/>{INERTIAL}</body>')
    )
    assert loaded.model.names[1] == "bJoint_0"
    data = loaded.model.createData()
    pin.forwardKinematics(loaded.model, data, np.zeros(1))  # q = qpos − ref: the pose as written
    assert np.allclose(data.oMi[1].rotation, np.eye(3), atol=1e-15)


def _model_file(folder: Path, model: type) -> Path:
    """A model file holding the hand model (certify embeds a model file's text)."""
    path = folder / f"{model.name}.py"
    path.write_text(
        f"from tests.robot.mjcf_hand_models import {model.__name__} as HandModel\n\n\n"
        f"class {model.__name__}File(HandModel):\n    pass\n"
    )
    return path


def _params_file(folder: Path, model: type, values: dict[str, float]) -> Path:
    path = folder / f"{model.name}.toml"
    lines = [f'model = "{model.name}"', f'name = "{model.name}"', "", "[parameters]"]
    lines += [f"{key} = {float(value)!r}" for key, value in values.items()]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("case", CASES)
def test_a_shipped_mujoco_file_is_drawn_with_its_geoms_on_each_moving_body(case):
    from pendverify.viz.geometry import VisualSystem

    path, model, _, _ = CASES[case]
    visuals = VisualSystem.for_model(model, str(path))
    drawn = {o.parentJoint for o in visuals.objects}
    assert set(range(1, visuals.system.model.njoints)) <= drawn, f"{case}: joints drawn {drawn}"


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES)
def test_a_shipped_mujoco_file_is_certified_and_rechecked(tmp_path, case):
    """certify bundles the MJCF with its includes in place, and recheck reads that bundle back."""
    path, model, params, mass = CASES[case]
    model_file = _model_file(tmp_path, model)
    issued = api.certify_set(
        tmp_path / "out",
        urdf=path,
        urdf_params=_params_file(tmp_path, model, params()),
        analytic=model_file,
        samples=20,
    )
    assert issued.certified, f"{case}: {[(i.name, i.status) for i in issued.items]}"
    assert api.recheck(issued.path, run_embedded_code=True).passed
    wrong = params()
    wrong[mass] *= 1.01
    refused = api.certify_set(
        tmp_path / "wrong",
        urdf=path,
        urdf_params=_params_file(tmp_path, model, wrong),
        analytic=model_file,
        samples=20,
    )
    assert not refused.certified


def test_an_mjcf_geom_is_drawn_in_the_colour_mujoco_shows(tmp_path):
    """A geom with a material and no rgba of its own takes the material's colour (dm_control's
    files colour everything so); a geom's own rgba wins over its material; a bare geom stays grey."""
    from pendverify.viz.geometry import VisualSystem

    path = tmp_path / "coloured.xml"
    path.write_text(
        '<mujoco><asset><material name="red" rgba="0.9 0.1 0.1 1"/></asset><worldbody>'
        '<body name="bob"><joint name="hinge" type="hinge" axis="0 1 0"/>'
        '<geom name="by_material" size="0.05" pos="0 0 -0.5" mass="2" material="red"/>'
        '<geom name="own" size="0.02" pos="0 0 -0.25" mass="0" material="red" rgba="0.1 0.8 0.1 1"/>'
        '<geom name="bare" size="0.02" pos="0 0 -0.1" mass="0"/>'
        "</body></worldbody></mujoco>"
    )
    model_cls = load_model_class(write_one_joint("pendulum", tmp_path).model)
    colours = {o.name: tuple(o.meshColor) for o in VisualSystem.for_model(model_cls, str(path)).objects}
    assert colours["by_material"] == pytest.approx((0.9, 0.1, 0.1, 1.0))
    assert colours["own"] == pytest.approx((0.1, 0.8, 0.1, 1.0))
    assert colours["bare"] == pytest.approx((0.5, 0.5, 0.5, 1.0))
