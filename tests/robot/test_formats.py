"""Robot descriptions beyond plain URDF (issue 14, item 4): xacro, MJCF, SDFormat.

The shipped xacro and MJCF descriptions of the reference double pendulum build the very
model the URDF builds; ``check`` gives the same table on each; a planted error in each
format fails ``crba`` and ``gravity``; malformed numbers in each format are one line and
exit status 2; an SDF is read by Drake, and refused without it naming the extra.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.cli import main
from pendverify.errors import UrdfShapeError
from pendverify.robot.description import description_stem, load_description, urdf_text
from pendverify.robot.sdf import read_sdf_strictly
from pendverify.robot.strict import JointDynamics
from pendverify.robot.system import PinocchioSystem

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "urdf" / "double_pendulum.urdf"
XACRO = REPO / "examples" / "double_pendulum.xacro"
MJCF = REPO / "examples" / "double_pendulum.mjcf.xml"
PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"
FORMATS = {"xacro": XACRO, "mjcf": MJCF}
REFERENCE_MODEL = MODELS["double_pendulum"]


def one_error(err: str) -> str:
    assert "Traceback" not in err, err
    lines = [line for line in err.splitlines() if line.startswith("pendverify:")]
    assert len(lines) == 1, err
    return lines[0]


def planted(tmp_path: Path, original: Path, old: str, new: str, name: str | None = None) -> Path:
    text = original.read_text()
    assert old in text, old
    path = tmp_path / (name or original.name)
    path.write_text(text.replace(old, new, 1))
    return path


# --------------------------------------------------------------------------- the same model


@pytest.mark.parametrize("fmt", FORMATS)
def test_each_format_builds_the_urdfs_model(fmt):
    urdf, other = load_description(URDF), load_description(FORMATS[fmt])
    assert other.format == fmt
    a, b = urdf.model, other.model
    assert [a.names[j] for j in range(a.njoints)][1:] == [b.names[j] for j in range(b.njoints)][1:]
    assert list(a.parents) == list(b.parents)
    for j in range(1, a.njoints):
        assert a.joints[j].shortname() == b.joints[j].shortname()
        assert np.array_equal(a.jointPlacements[j].homogeneous, b.jointPlacements[j].homogeneous)
        assert a.inertias[j].mass == b.inertias[j].mass
        assert np.array_equal(a.inertias[j].lever, b.inertias[j].lever)
        # the MJCF's rods have their axial (y) moment, which MuJoCo requires and which a rod
        # turning about x never feels (examples/double_pendulum.mjcf.xml); the rest is the URDF's
        keep = [0, 2] if fmt == "mjcf" else [0, 1, 2]
        assert np.array_equal(
            a.inertias[j].inertia[np.ix_(keep, keep)], b.inertias[j].inertia[np.ix_(keep, keep)]
        )
    for field in ("damping", "friction", "armature"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    assert urdf.facts.joint_dynamics == other.facts.joint_dynamics
    assert other.facts.joint_dynamics["joint1"] == JointDynamics(0.05, None)


@pytest.mark.parametrize("fmt", FORMATS)
def test_the_reference_reader_reads_each_format_off_pinocchios_model(fmt):
    """``geometry_reader`` works on the Pinocchio model, so the format does not matter."""
    expected = PinocchioSystem.for_model(REFERENCE_MODEL, URDF).geometry.params
    read = PinocchioSystem.for_model(REFERENCE_MODEL, FORMATS[fmt]).geometry.params
    assert read == expected


def check_json(tmp_path: Path, argv: list[str]) -> tuple[int, dict]:
    out = tmp_path / "report.json"
    status = main(["check", *argv, "--json", str(out), "--quiet"])
    return status, json.loads(out.read_text())


@pytest.mark.parametrize("fmt", FORMATS)
def test_check_gives_the_urdfs_table(tmp_path, fmt):
    status_urdf, urdf = check_json(tmp_path, ["--model", "double_pendulum", "--urdf", str(URDF)])
    status, other = check_json(tmp_path, ["--model", "double_pendulum", "--urdf", str(FORMATS[fmt])])
    assert status == status_urdf == 0
    rows = {r["check"]: r for r in urdf["results"]}
    assert [r["check"] for r in other["results"]] == list(rows)
    for row in other["results"]:
        assert row["status"] == rows[row["check"]]["status"] == "pass"
        assert abs(row["max_error"] - rows[row["check"]]["max_error"]) <= 1e-15, row["check"]


@pytest.mark.parametrize(
    ("original", "old", "new"),
    [
        (MJCF, 'mass="1.0"', 'mass="1.01"'),  # a wrong mass in the MJCF
        (XACRO, '<xacro:property name="l1" value="0.5"/>', '<xacro:property name="l1" value="0.51"/>'),
    ],
    ids=["mjcf-mass", "xacro-length"],
)
def test_a_planted_error_fails_crba_and_gravity(tmp_path, original, old, new):
    path = planted(tmp_path, original, old, new)
    status, report = check_json(tmp_path, ["--urdf", str(path), "--params", str(PARAMS)])
    assert status == 1
    failed = {r["check"] for r in report["results"] if not r["passed"]}
    assert {"crba", "gravity"} <= failed
    # and the same file unplanted passes against the same parameter set
    status, _ = check_json(tmp_path, ["--urdf", str(original), "--params", str(PARAMS)])
    assert status == 0


# --------------------------------------------------------------------------- strict numbers

BAD_NUMBERS = {
    "mjcf-suffix": (MJCF, 'mass="1.0"', 'mass="1.0x"', "body 'link1' <inertial> mass = '1.0x'"),
    "mjcf-nan": (MJCF, 'damping="0.05"', 'damping="nan"', "joint 'joint1' damping = 'nan'"),
    "mjcf-count": (
        MJCF,
        'diaginertia="0.0135 5.76e-5 0.0135"',
        'diaginertia="0.0135 5.76e-5"',
        "body 'link2' <inertial> diaginertia = '0.0135 5.76e-5': needs exactly 3 numbers, found 2",
    ),
    "xacro-suffix": (
        XACRO,
        'name="m1" value="1.0"',
        'name="m1" value="1.0x"',
        "link 'link1' <inertial><mass> value = '1.0x'",
    ),
    "xacro-nan": (
        XACRO,
        'name="I2" value="0.0135"',
        'name="I2" value="nan"',
        "link 'link2' <inertial><inertia> ixx = 'nan'",
    ),
    "xacro-count": (
        XACRO,
        '<origin xyz="0 ${y} 0" rpy="0 0 0"/>',
        '<origin xyz="0 ${y}" rpy="0 0 0"/>',
        "joint 'joint1' <origin> xyz = '0 0': needs exactly 3 numbers",
    ),
}


@pytest.mark.parametrize("case", BAD_NUMBERS)
def test_a_bad_number_is_one_line_and_status_2(tmp_path, capsys, case):
    original, old, new, where = BAD_NUMBERS[case]
    path = planted(tmp_path, original, old, new)
    assert main(["check", "--model", "double_pendulum", "--urdf", str(path)]) == 2
    line = one_error(capsys.readouterr().err)
    assert line.startswith(f"pendverify: error: {path}: {where}"), line
    if original == XACRO:
        assert line.endswith("(in the URDF xacro expanded it to)")


# --------------------------------------------------------------------------- xacro


def xacro_doc(body: str) -> str:
    return (
        f'<?xml version="1.0"?>\n<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">{body}</robot>\n'
    )


def test_xacro_find_of_a_package_not_found_is_refused_naming_it(tmp_path, monkeypatch):
    """Packages are found without ROS (tests/robot/test_ros_packages.py); an unknown one is one line."""
    monkeypatch.delenv("ROS_PACKAGE_PATH", raising=False)
    monkeypatch.delenv("AMENT_PREFIX_PATH", raising=False)
    path = tmp_path / "arm.urdf.xacro"
    path.write_text(xacro_doc('<xacro:include filename="$(find arm_description)/urdf/arm.xacro"/>'))
    with pytest.raises(UrdfShapeError) as info:
        load_description(path)
    message = str(info.value)
    assert message.startswith(f"{path}: xacro cannot expand it: ROS package 'arm_description' not found")
    assert "--package-path DIR" in message


def test_xacro_arguments_take_their_defaults_and_includes_resolve_beside_the_file(tmp_path):
    (tmp_path / "parts").mkdir()
    (tmp_path / "parts" / "joint.xacro").write_text(
        xacro_doc(
            '<xacro:macro name="damped" params="name d"><joint name="${name}" type="revolute">'
            '<parent link="base"/><child link="link1"/><axis xyz="1 0 0"/>'
            '<limit effort="1" velocity="1" lower="-1" upper="1"/>'
            '<dynamics damping="${d}"/></joint></xacro:macro>'
        )
    )
    main_file = tmp_path / "x.xacro"
    main_file.write_text(
        xacro_doc(
            '<xacro:arg name="b" default="0.25"/><xacro:include filename="parts/joint.xacro"/>'
            '<link name="base"/><link name="link1"><inertial><mass value="1"/>'
            '<inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>'
            '<xacro:damped name="j" d="$(arg b)"/>'
        )
    )
    loaded = load_description(main_file)
    assert loaded.format == "xacro"
    assert loaded.facts.joint_dynamics == {"j": JointDynamics(0.25, None)}
    assert loaded.model.damping.tolist() == [0.25]
    assert "expanded by xacro from x.xacro" in loaded.text


def test_an_undeclared_xacro_argument_is_refused(tmp_path):
    """No name:=value mappings are given, so an argument exists only with its declared default."""
    path = tmp_path / "a.xacro"
    path.write_text(xacro_doc('<link name="$(arg b)"/>'))
    with pytest.raises(
        UrdfShapeError, match=r"a.xacro: xacro cannot expand it: Undefined substitution argument b"
    ):
        load_description(path)
    path.write_text(xacro_doc('<xacro:arg name="b"/><link name="$(arg b)"/>'))
    with pytest.raises(
        UrdfShapeError, match=r"a.xacro: xacro cannot expand it: xacro:arg: missing attribute"
    ):
        load_description(path)


def test_xacro_elements_in_a_file_named_urdf_are_expanded_not_ignored(tmp_path):
    text = XACRO.read_text()
    path = tmp_path / "pendulum.urdf"
    path.write_text(text)
    assert load_description(path).format == "xacro"
    assert load_description(text).format == "xacro"  # XML text too


def test_what_xacro_prints_becomes_a_note(tmp_path):
    path = tmp_path / "a.xacro"
    path.write_text(xacro_doc('<xacro:include filename="none*.xacro"/><link name="a"/>'))
    notes = load_description(path).notes()
    assert notes[0] == "expanded by xacro, with the defaults of its xacro:arg arguments"
    assert (
        notes[1]
        == f'xacro printed: warning: Include tag\'s filename spec "{tmp_path}/none*.xacro" matched no files.'
    )


def test_xacro_refuses_a_doctype_as_the_urdf_reader_does(tmp_path):
    path = tmp_path / "a.xacro"
    path.write_text('<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY m "1.0">]>\n' + xacro_doc("")[22:])
    with pytest.raises(UrdfShapeError, match="XML with a DOCTYPE or entities is refused"):
        load_description(path)


# --------------------------------------------------------------------------- SDFormat

SDF = """<?xml version="1.0"?>
<sdf version="1.7">
  <model name="double_pendulum">
    <link name="base"/>
    <joint name="anchor" type="fixed"><parent>world</parent><child>base</child></joint>
    <link name="link1">
      <pose>0 0 0 0 0 0</pose>
      <inertial>
        <pose>0 0.25 0 0 0 0</pose>
        <mass>1.0</mass>
        <inertia><ixx>0.0208</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.0</iyy><iyz>0</iyz><izz>0.0208</izz></inertia>
      </inertial>
    </link>
    <joint name="joint1" type="revolute">
      <parent>base</parent><child>link1</child>
      <axis><xyz>1 0 0</xyz><dynamics><damping>0.05</damping></dynamics></axis>
    </joint>
    <link name="link2">
      <pose>0 0.5 0 0 0 0</pose>
      <inertial>
        <pose>0 0.22 0 0 0 0</pose>
        <mass>0.8</mass>
        <inertia><ixx>0.0135</ixx><ixy>0</ixy><ixz>0</ixz><iyy>0.0</iyy><iyz>0</iyz><izz>0.0135</izz></inertia>
      </inertial>
    </link>
    <joint name="joint2" type="revolute">
      <parent>link1</parent><child>link2</child>
      <axis><xyz>1 0 0</xyz><dynamics><damping>0.03</damping></dynamics></axis>
    </joint>
  </model>
</sdf>
"""


def test_an_sdf_is_refused_without_drake_naming_the_extra(tmp_path, capsys, monkeypatch):
    """Without pydrake (its import made to fail), one line names the extra to install."""
    monkeypatch.setitem(sys.modules, "pydrake.multibody.parsing", None)
    path = tmp_path / "double_pendulum.sdf"
    path.write_text(SDF)
    assert main(["check", "--model", "double_pendulum", "--urdf", str(path)]) == 2
    line = one_error(capsys.readouterr().err)
    assert line == (
        f"pendverify: error: {path}: an SDFormat description (<sdf>): reading it needs the optional extra: "
        "pip install 'pendverify[sdf]'"
    )


def test_an_sdf_builds_the_urdfs_model(tmp_path):
    pytest.importorskip("pydrake")
    path = tmp_path / "double_pendulum.sdf"
    path.write_text(SDF)
    sdf, urdf = load_description(path), load_description(URDF)
    assert sdf.format == "sdf"
    from_sdf = PinocchioSystem.for_model(REFERENCE_MODEL, path).geometry.params.as_dict()
    from_urdf = PinocchioSystem.for_model(REFERENCE_MODEL, URDF).geometry.params.as_dict()
    # Drake keeps a body's inertia about the body origin: shifting it back to the centre of mass
    # rounds each term of size m r² (and I) once, so the two agree to a few ulps of I + m r²
    lever = max(from_urdf["m1"] * from_urdf["r1"] ** 2, from_urdf["m2"] * from_urdf["r2"] ** 2)
    for key, value in from_urdf.items():
        assert abs(from_sdf[key] - value) <= 4 * np.finfo(float).eps * (abs(value) + lever), key
    assert sdf.facts.joint_dynamics["joint2"] == JointDynamics(0.03, None)
    assert np.array_equal(sdf.model.damping, urdf.model.damping)


def test_the_sdf_reader_reads_numbers_strictly():
    """Pure Python: runs whether or not this Pinocchio has SDFormat."""
    facts = read_sdf_strictly(SDF, "p.sdf")
    assert facts.joint_dynamics == {"joint1": JointDynamics(0.05, None), "joint2": JointDynamics(0.03, None)}
    for old, new, message in [
        (
            "<mass>1.0</mass>",
            "<mass>1.0x</mass>",
            "p.sdf: link 'link1' <mass> = '1.0x': '1.0x' is not a finite",
        ),
        ("<damping>0.05</damping>", "<damping>nan</damping>", "p.sdf: joint 'joint1' <damping> = 'nan'"),
        (
            "<xyz>1 0 0</xyz>",
            "<xyz>1 0</xyz>",
            "p.sdf: joint 'joint1' <xyz> = '1 0': needs exactly 3 numbers",
        ),
        ("<mass>0.8</mass>", "<mass>-0.8</mass>", "p.sdf: link 'link2' <mass> = '-0.8': must be ≥ 0"),
    ]:
        with pytest.raises(UrdfShapeError) as info:
            read_sdf_strictly(SDF.replace(old, new, 1), "p.sdf")
        assert str(info.value).startswith(message), str(info.value)


# --------------------------------------------------------------------------- every command


def test_certify_and_recheck_an_mjcf_and_a_xacro(tmp_path, capsys):
    for path, bundled in ((MJCF, "double_pendulum.mjcf.xml"), (XACRO, "double_pendulum.urdf")):
        out = tmp_path / path.name
        argv = [
            "certify",
            "--model",
            "double_pendulum",
            "--urdf",
            str(path),
            "-o",
            str(out),
            "--samples",
            "20",
        ]
        assert main(argv) == 0
        assert sorted(p.name for p in out.iterdir()) == sorted(
            [bundled, "double_pendulum.params.toml", "double_pendulum.cert.json"]
        )
        assert (out / bundled).read_text() == load_description(path).text
        assert main(["recheck", str(out / "double_pendulum.cert.json")]) == 0
    capsys.readouterr()


def test_rewriting_commands_take_a_xacro_and_refuse_an_mjcf():
    assert "<xacro" not in urdf_text(XACRO, "stress --analytic")
    with pytest.raises(UrdfShapeError, match="an MJCF description, but stress --analytic rewrites a URDF's"):
        urdf_text(MJCF, "stress --analytic")


def test_a_description_stem_leaves_its_formats_suffix_out():
    assert description_stem("a/arm.urdf.xacro") == "arm"
    assert description_stem("arm.xacro") == "arm"
    assert description_stem("arm.mjcf.xml") == "arm"
    assert description_stem("arm.xml") == "arm"
    assert description_stem("arm.urdf") == "arm"


def test_an_unknown_root_names_the_formats(tmp_path):
    path = tmp_path / "x.xml"
    path.write_text("<model/>")
    with pytest.raises(UrdfShapeError) as info:
        load_description(path)
    assert str(info.value) == (
        f"{path}: the root element is <model>: pendverify reads URDF (<robot>), xacro (*.xacro), "
        "MJCF (<mujoco>) and SDFormat (<sdf>)"
    )


@pytest.mark.parametrize("fmt", FORMATS)
def test_the_animation_draws_each_formats_visuals_where_the_urdfs_are(fmt):
    from pendverify.viz.geometry import VisualSystem

    def shapes(path):
        objects = VisualSystem.for_model(REFERENCE_MODEL, path).objects
        return [(o.parentJoint, type(o.geometry).__name__, o.placement.translation.tolist()) for o in objects]

    assert shapes(FORMATS[fmt]) == shapes(URDF)


def test_systems_on_one_read_description_leave_it_as_it_was():
    """``for_model`` on a description already read (the battery reads its URDF once): each
    system its own model copy at its own g; the description neither re-read nor changed."""
    loaded = load_description(MJCF)
    before = (loaded.model.gravity.linear.copy(), list(loaded.reading_notes))
    at_g = PinocchioSystem.for_model(REFERENCE_MODEL, loaded, 9.81)
    at_zero = PinocchioSystem.for_model(REFERENCE_MODEL, loaded, 0.0)
    assert at_g.model is not loaded.model and at_zero.model is not at_g.model
    assert np.array_equal(loaded.model.gravity.linear, before[0]) and loaded.reading_notes == before[1]
    q = np.array([0.3, -0.7])
    fresh = PinocchioSystem.for_model(REFERENCE_MODEL, MJCF, 9.81)
    assert np.array_equal(at_g.gravity(q), fresh.gravity(q))
    assert np.array_equal(at_zero.gravity(q), np.zeros(2)) and at_g.notes == fresh.notes


def test_mujoco_and_drake_are_imported_only_for_their_files():
    """A URDF's check, and everything the CLI imports, load neither MuJoCo nor Drake: they are
    imported when an MJCF or SDF file is read (each adds a quarter of a second or more)."""
    code = (
        "import sys, pendverify.cli, pendverify.api, pendverify.viz.geometry; "
        "from pendverify.robot.description import load_description; "
        f"load_description({str(URDF)!r}); "
        "print(sorted(m for m in ('mujoco', 'pydrake') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"
