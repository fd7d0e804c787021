"""A robot without visual geometry is drawn as a skeleton, and the animation moves it.

Planted: the brief's dynamics-only pendulum URDF (``render`` and ``simulate --html`` crashed
on it, exit 3), the same pendulum as an MJCF body without geoms and as an SDFormat link
without ``<visual>``, a bare ``pinocchio.Model``, and a double pendulum whose second link
lost its visuals.  The page must hold the skeleton's objects (joint marker, rod, centre of
mass), their keyframes must be the pendulum's closed-form positions (the bob at
r·(−sin θ, 0, −cos θ) at each frame's θ), and the note must be printed; a description with
visuals must be drawn by them alone, with no skeleton and no note.
"""

from __future__ import annotations

import colorsys
import re
import time

import numpy as np
import pinocchio as pin
import pytest
import umsgpack
from PIL import Image

from pendverify.analytic import MODELS
from pendverify.cli import main
from pendverify.robot.pinocchio_model import describe_model
from pendverify.robot.writer import urdf_for
from pendverify.simulation.scene import load_scene
from pendverify.simulation.simulate import run_scene
from pendverify.viz.animation import DEFAULT_FPS, Trajectory, animation_page, build_scene, resample
from pendverify.viz.geometry import LINK_COLOURS, VisualSystem

from ..conftest import default_params
from ..robot.one_joint import PENDULUM_URDF, dm_control_pendulum, write_one_joint
from .test_viz import SHOT_SIZE, _hsv, browser, needs_chromium, wait_for_clock  # noqa: F401

NOTE = "has no visual geometry: a skeleton is drawn"
SKELETON = ("skeleton_joint_hinge", "skeleton_link_hinge_0", "skeleton_com_hinge")
R = 0.5  # m, the pendulum's pivot to its bob
ATOL = 1e-6  # m: keyframes are float32 (7 digits) of positions of at most 1 m
MJCF_NO_GEOMS = """<mujoco model="pend">
  <worldbody>
    <body name="bob">
      <joint name="hinge" type="hinge" axis="0 1 0" damping="0.1"/>
      <inertial pos="0 0 -0.5" mass="2" diaginertia="1e-9 1e-9 1e-9"/>
    </body>
  </worldbody>
</mujoco>
"""
SDF_NO_VISUAL = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="pend">
    <link name="base"/>
    <joint name="weld" type="fixed"><parent>world</parent><child>base</child></joint>
    <link name="bob">
      <inertial><pose>0 0 -0.5 0 0 0</pose><mass>2.0</mass>
        <inertia><ixx>0</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0</iyy><iyz>0</iyz><izz>0</izz></inertia>
      </inertial>
    </link>
    <joint name="hinge" type="revolute"><parent>base</parent><child>bob</child>
      <axis><xyz>0 1 0</xyz><limit><lower>-1e9</lower><upper>1e9</upper></limit></axis></joint>
  </model>
</sdf>
"""
#: pixels of the rod's colour (LINK_COLOURS[0]) and of the dark joint marker in an 800×600 shot
MIN_ROD_PIXELS, MIN_MARKER_PIXELS, MIN_MOVED_PIXELS = 150, 20, 100


def _commands(recorder) -> list[dict]:
    return [umsgpack.unpackb(c) for c in recorder.commands]


def _keyed_positions(commands: list[dict], node: str) -> np.ndarray:
    (anim,) = [c for c in commands if c["type"] == "set_animation"]
    clip = next(a["clip"] for a in anim["animations"] if a["path"] == f"/meshcat/pendverify/visuals/{node}")
    track = next(t for t in clip["tracks"] if t["name"] == ".position")
    return np.array([k["value"] for k in track["keys"]], dtype=float)


def _pendulum_trajectory(tmp_path, robot_text: str | None = None, suffix: str = ".urdf") -> Trajectory:
    robot = write_one_joint("pendulum", tmp_path)
    if robot_text is not None:
        path = tmp_path / f"pend{suffix}"
        path.write_text(robot_text)
        robot = type(robot)(robot.name, robot.folder, path, robot.initial)
    return Trajectory.from_run(run_scene(load_scene(robot.scene())))


@pytest.mark.parametrize("fmt", ["urdf", "mjcf", "sdf"])
def test_a_pendulum_without_visuals_is_drawn_as_a_moving_skeleton(fmt, tmp_path):
    if fmt == "sdf":
        pytest.importorskip("pydrake")
    text = {"urdf": None, "mjcf": MJCF_NO_GEOMS, "sdf": SDF_NO_VISUAL}[fmt]
    traj = _pendulum_trajectory(tmp_path, text, {"urdf": ".urdf", "mjcf": ".xml", "sdf": ".sdf"}[fmt])
    page = animation_page(traj)
    (note,) = page.notes
    assert note.startswith(f"{traj.urdf} {NOTE}"), f"{fmt=}: {page.notes}"
    commands = _commands(build_scene(traj))
    drawn = {c["path"].rsplit("/", 1)[-1] for c in commands if c["type"] == "set_object"}
    assert set(SKELETON) <= drawn, f"{fmt=}: {sorted(drawn)}"
    # the centre of mass is keyed where the closed form puts the bob, frame by frame
    _, frames = resample(traj.t, traj.q, DEFAULT_FPS)
    theta = frames[:, 0]
    bob = R * np.column_stack([-np.sin(theta), np.zeros_like(theta), -np.cos(theta)])
    keyed = _keyed_positions(commands, "skeleton_com_hinge")
    np.testing.assert_allclose(keyed, bob, atol=ATOL, err_msg=f"{fmt=}")
    span = float(np.max(np.linalg.norm(keyed[:, None] - keyed[None, :], axis=-1)))  # farthest two frames
    swing = 2 * R * np.sin((theta.max() - theta.min()) / 2)  # the chord of the arc swept
    assert swing > 0.05 and span == pytest.approx(swing, abs=ATOL), f"{fmt=}: the bob does not move"
    # the rod's far end, the trace's tip, is the bob
    visual = VisualSystem.for_model(traj.model_cls, traj.urdf, traj.params.g)
    i, local = visual.tip_point()
    pose = visual.placements(np.array([theta[-1]]))[i]
    np.testing.assert_allclose(pose[:3, :3] @ local + pose[:3, 3], bob[-1], atol=1e-12)


def test_render_and_simulate_print_the_note_and_write_the_page(tmp_path, capsys):
    scene = write_one_joint("pendulum", tmp_path).scene()
    for argv in (
        ["render", str(scene), "-o", str(tmp_path / "r.html"), "--trace"],
        ["simulate", str(scene), "--html", str(tmp_path / "s.html")],
    ):
        assert main(argv) == 0, capsys.readouterr().err
        out = capsys.readouterr().out
        assert out.count(f"note: {scene.parent.parent / 'pend.urdf'} {NOTE}") == 1, out
    for name in ("r", "s"):
        page = (tmp_path / f"{name}.html").read_text()
        assert page.startswith("<!DOCTYPE html>") or "<html" in page[:500]


def test_a_description_with_visuals_gets_no_skeleton_and_no_note(tmp_path, capsys):
    visual = VisualSystem.from_params(default_params("double_pendulum"))
    assert visual.notes == ()
    assert "<visual" not in PENDULUM_URDF  # the planted file of the other tests has none
    assert not [o.name for o in visual.objects if o.name.startswith("skeleton")]
    mjcf = dm_control_pendulum()
    if mjcf is None:
        pytest.skip("dm_control is not installed")
    scene = write_one_joint("dm_pendulum", tmp_path).scene()
    assert main(["render", str(scene), "-o", str(tmp_path / "dm.html")]) == 0
    assert "skeleton" not in capsys.readouterr().out


def test_only_the_bodies_without_visuals_get_a_skeleton():
    params = default_params("double_pendulum")
    link2 = re.compile(r'(<link name="link2">.*?</link>)', re.S)
    text = link2.sub(lambda m: re.sub(r"<visual.*?</visual>", "", m.group(1), flags=re.S), urdf_for(params))
    visual = VisualSystem.for_model(MODELS["double_pendulum"], text, params.g)
    skeleton = [o for o in visual.objects if o.name.startswith("skeleton")]
    assert {o.parentJoint for o in skeleton} == {2}, [o.name for o in skeleton]
    assert {o.name for o in skeleton} == {
        "skeleton_joint_joint2",
        "skeleton_link_joint2_0",
        "skeleton_com_joint2",
    }
    assert any(o.parentJoint == 1 and not o.name.startswith("skeleton") for o in visual.objects)
    (note,) = visual.notes
    assert "joint2" in note and "joint1" not in note


def test_a_bare_pinocchio_model_is_drawn_as_a_skeleton():
    model = pin.buildModelFromXML(urdf_for(default_params("double_pendulum")))
    visual = VisualSystem.for_model(MODELS["double_pendulum"], describe_model(model))
    assert {o.parentJoint for o in visual.objects if o.name.startswith("skeleton_com")} == {1, 2}
    assert visual.notes == (
        f"<pinocchio.Model {model.name!r}> {NOTE} (joints as dark boxes along their axes, "
        "links as rods, centres of mass as spheres)",
    )


def test_a_one_joint_skeleton_cart_slides_along_its_rail(tmp_path):
    cart = write_one_joint("cart", tmp_path)
    traj = Trajectory.from_run(run_scene(load_scene(cart.scene())))
    commands = _commands(build_scene(traj))
    keyed = _keyed_positions(commands, "skeleton_com_slider")
    _, frames = resample(traj.t, traj.q, DEFAULT_FPS)
    expected = np.column_stack([frames[:, 0], np.zeros((len(frames), 2))])
    np.testing.assert_allclose(keyed, expected, atol=ATOL)
    assert np.ptp(keyed[:, 0]) > 0.05, "the cart does not move"


def _rod_and_marker(png) -> tuple[np.ndarray, np.ndarray]:
    """Pixels of the rod's colour (hue of LINK_COLOURS[0], any shading) and of the dark marker."""
    hue, sat, val = _hsv(png)
    rod_hue = colorsys.rgb_to_hsv(*LINK_COLOURS[0][:3])[0] * 360.0
    rod = (np.abs((hue - rod_hue + 180.0) % 360.0 - 180.0) < 14.0) & (sat > 0.35) & (val > 0.2)
    marker = (sat < 0.15) & (val < 0.35)  # the dark grey joint marker
    return rod, marker


@needs_chromium
def test_the_skeleton_is_seen_and_swings_in_chromium(tmp_path, browser):  # noqa: F811
    scene = write_one_joint("pendulum", tmp_path).scene(duration=3.0)
    page = tmp_path / "pendulum.html"
    assert main(["render", str(scene), "-o", str(page)]) == 0
    tab = browser.open(page, SHOT_SIZE)
    try:
        tab.evaluate("viewer.animator.reset(), viewer.animator.play(), 0")
        wait_for_clock(tab, 0.3)
        first = tab.screenshot(tmp_path / "first.png")
        time.sleep(0.8)
        second = tab.screenshot(tmp_path / "second.png")
    finally:
        tab.close()
    (rod1, marker1), (rod2, _) = _rod_and_marker(first), _rod_and_marker(second)
    assert rod1.sum() >= MIN_ROD_PIXELS, f"the rod is hardly visible: {int(rod1.sum())} pixels"
    assert marker1.sum() >= MIN_MARKER_PIXELS, f"the joint marker is hardly visible: {int(marker1.sum())}"
    moved = int((rod1 ^ rod2).sum())
    assert moved >= MIN_MOVED_PIXELS, f"the skeleton did not move ({moved} pixels changed)"
    assert np.asarray(Image.open(first)).shape[:2] == (SHOT_SIZE[1], SHOT_SIZE[0])


def test_a_broken_description_without_visuals_is_still_refused_in_one_line(tmp_path, capsys):
    robot = write_one_joint("pendulum", tmp_path)
    robot.robot.write_text(robot.robot.read_text().replace('"2.0"', '"-2.0"'))
    out = tmp_path / "r.html"
    assert main(["render", str(robot.scene()), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert "pend.urdf" in err and "must be ≥ 0" in err and "Traceback" not in err
    assert not out.exists()
