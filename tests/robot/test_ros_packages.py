"""ROS packages without ROS (issue 25, item 4): ``$(find PKG)`` and ``package://`` through --package-path.

A package made in the test (``my_robot/package.xml``, ``urdf/robot.urdf.xacro`` including
``$(find my_robot)/urdf/body.xacro``, a ``package://my_robot/meshes/marker.stl`` visual) is the
reference double pendulum: it verifies with ``--package-path``, and through ``ROS_PACKAGE_PATH``
and ``AMENT_PREFIX_PATH``; a planted 1 % mass error in the included file still fails; ``render``
draws the mesh; an unknown package is one line naming it and the folders searched.
"""

from __future__ import annotations

import base64
import re
import shutil
from pathlib import Path

import pytest

import pendverify
from pendverify.cli import main
from pendverify.errors import PendverifyError, UrdfShapeError
from pendverify.robot.description import load_description
from pendverify.robot.packages import MAX_DEPTH, find_package, package_path
from pendverify.viz.geometry import VisualSystem

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"
SCENE = REPO / "scenes" / "minimal_double_pendulum_release.toml"
XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'

#: a tetrahedron, the smallest closed STL
STL = """solid marker
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0.02 0 0
  vertex 0 0.02 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 0 0 0.02
  vertex 0.02 0 0
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0.02 0
  vertex 0 0 0.02
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 0.02 0 0
  vertex 0 0 0.02
  vertex 0 0.02 0
 endloop
endfacet
endsolid marker
"""

MESH_VISUAL = (
    '<visual name="marker"><origin xyz="0 0.5 0" rpy="0 0 0"/>'
    '<geometry><mesh filename="package://my_robot/meshes/marker.stl"/></geometry></visual>'
)


@pytest.fixture(autouse=True)
def no_ros_environment(monkeypatch):
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)


def make_package(root: Path, mass1: str = "1.0", folder: str = "my_robot") -> Path:
    """``root/<folder>``: package my_robot, the reference double pendulum split over two xacro files."""
    package = root / folder
    (package / "urdf").mkdir(parents=True)
    (package / "meshes").mkdir()
    (package / "meshes" / "marker.stl").write_text(STL)
    (package / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>my_robot</name><version>0.1.0</version>'
        "<description>test</description><maintainer email='a@b.c'>a</maintainer>"
        "<license>BSD</license></package>\n"
    )
    body = URDF.read_text().split('<robot name="double_pendulum">', 1)[1].rsplit("</robot>", 1)[0]
    body = body.replace('<mass value="1.0"/>', f'<mass value="{mass1}"/>', 1)
    body = body.replace('<visual name="com1">', MESH_VISUAL + '<visual name="com1">', 1)
    (package / "urdf" / "body.xacro").write_text(
        f'<?xml version="1.0"?>\n<robot {XACRO_NS}><xacro:macro name="body" params="">{body}'
        "</xacro:macro></robot>\n"
    )
    main_file = package / "urdf" / "robot.urdf.xacro"
    main_file.write_text(
        f'<?xml version="1.0"?>\n<robot name="double_pendulum" {XACRO_NS}>'
        '<xacro:include filename="$(find my_robot)/urdf/body.xacro"/><xacro:body/></robot>\n'
    )
    return main_file


def check_argv(robot: Path, *extra: str) -> list[str]:
    return ["check", "--model", "double_pendulum", "--urdf", str(robot), "--params", str(PARAMS), *extra]


def one_error(err: str) -> str:
    assert "Traceback" not in err, err
    lines = [line for line in err.splitlines() if line.startswith("pendverify:")]
    assert len(lines) == 1, err
    return lines[0]


def test_a_xacro_package_verifies_with_package_path(tmp_path, capsys):
    robot = make_package(tmp_path / "ws" / "src")
    assert main(check_argv(robot, "--package-path", str(tmp_path / "ws"))) == 0, capsys.readouterr()
    assert "pass" in capsys.readouterr().out


def test_a_planted_mass_error_in_the_included_file_still_fails(tmp_path, capsys):
    robot = make_package(tmp_path, mass1="1.01")
    assert main(check_argv(robot, "--package-path", str(tmp_path))) == 1
    assert "FAIL" in capsys.readouterr().out


def test_the_package_is_named_by_its_package_xml_not_its_folder(tmp_path):
    robot = make_package(tmp_path, folder="checkout-of-my-robot")
    with pendverify.ros_packages(tmp_path):
        loaded = load_description(robot)
    assert f"{tmp_path}/checkout-of-my-robot/urdf/body.xacro" not in loaded.text  # expanded, not named
    assert loaded.model.nv == 2 and loaded.model.inertias[1].mass == 1.0


def test_ros_package_path_and_ament_prefix_path_are_searched(tmp_path, monkeypatch):
    robot = make_package(tmp_path / "a" / "b")
    monkeypatch.setenv("ROS_PACKAGE_PATH", f"/nonexistent:{tmp_path / 'a'}")
    assert load_description(robot).model.nv == 2
    monkeypatch.delenv("ROS_PACKAGE_PATH")
    prefix = tmp_path / "install"
    shutil.copytree(tmp_path / "a" / "b" / "my_robot", prefix / "share" / "my_robot")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(prefix))
    assert find_package("my_robot", "<t>") == prefix / "share" / "my_robot"


def test_the_search_is_bounded_in_depth(tmp_path):
    deep = tmp_path.joinpath(*[f"d{i}" for i in range(MAX_DEPTH)])
    make_package(deep)
    with package_path([tmp_path]), pytest.raises(UrdfShapeError, match="ROS package 'my_robot' not found"):
        find_package("my_robot", "<t>")
    with package_path([tmp_path / "d0"]):
        assert find_package("my_robot", "<t>") == deep / "my_robot"


def test_an_unknown_package_is_one_line_naming_it_and_the_folders_searched(tmp_path, capsys, monkeypatch):
    robot = make_package(tmp_path / "pkgs")
    robot.write_text(robot.read_text().replace("$(find my_robot)", "$(find other_robot)"))
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(tmp_path / "ros"))
    assert main(check_argv(robot, "--package-path", str(tmp_path / "pkgs"))) == 2
    line = one_error(capsys.readouterr().err)
    assert line.startswith(f"pendverify: error: {robot}: xacro cannot expand it: ROS package 'other_robot'")
    assert f"searched {tmp_path / 'pkgs'} (--package-path), {tmp_path / 'ros'} (ROS_PACKAGE_PATH)" in line
    assert "--package-path DIR" in line


def test_without_any_package_folder_the_line_says_so(tmp_path):
    robot = make_package(tmp_path)
    with pytest.raises(UrdfShapeError) as info:
        load_description(robot)
    assert "ROS package 'my_robot' not found: no package folders were given" in str(info.value)


def test_a_package_path_that_is_no_folder_is_refused(tmp_path, capsys):
    robot = make_package(tmp_path)
    assert main(check_argv(robot, "--package-path", str(tmp_path / "missing"))) == 2
    assert "missing: a package folder (--package-path, ros_packages) that is not a folder" in one_error(
        capsys.readouterr().err
    )
    with pytest.raises(PendverifyError, match="a package folder is a path; got a int"):
        pendverify.ros_packages(3)


def test_the_setting_ends_with_its_block(tmp_path):
    robot = make_package(tmp_path)
    with pendverify.ros_packages(tmp_path):
        load_description(robot)
    with pytest.raises(UrdfShapeError, match="not found"):
        load_description(robot)


def test_api_check_reads_the_package_inside_the_block(tmp_path):
    robot = make_package(tmp_path)
    with pendverify.ros_packages(tmp_path):
        report = pendverify.check("double_pendulum", robot, PARAMS)
    assert report.passed, report


def test_render_draws_the_package_mesh(tmp_path, capsys):
    robot = make_package(tmp_path)
    with pendverify.ros_packages(tmp_path):
        visual = VisualSystem.for_model(pendverify.load_model("double_pendulum"), robot)
    meshes = [o for o in visual.objects if o.meshPath.endswith("marker.stl")]
    assert len(meshes) == 1 and Path(meshes[0].meshPath) == tmp_path / "my_robot" / "meshes" / "marker.stl"
    out = tmp_path / "out.html"
    argv = ["render", str(SCENE), "--urdf", str(robot), "--package-path", str(tmp_path), "-o", str(out)]
    assert main(argv) == 0, capsys.readouterr()
    commands = [base64.b64decode(c) for c in re.findall(r'^"([A-Za-z0-9+/=]{40,})"', out.read_text(), re.M)]
    assert any(b"solid marker" in c for c in commands)  # the STL file itself is in the page
