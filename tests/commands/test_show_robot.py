"""``pendverify show --robot FILE``: each joint as Pinocchio will use it, each number with its origin."""

from __future__ import annotations

from pathlib import Path

import pytest

from pendverify import api
from pendverify.cli import main

REPO = Path(__file__).resolve().parents[2]
CART = REPO / "examples" / "cart_pole.urdf"
XACRO = REPO / "examples" / "double_pendulum.xacro"


def rows(out: str) -> dict[tuple[str, str], str]:
    """{(joint, quantity): the row's text} of the printed summary."""
    found, joint = {}, None
    for line in out.splitlines():
        if line.startswith("joint "):
            joint = line.split()[1].rstrip(":")
        elif line.startswith("  ") and joint is not None:
            found[(joint, line.split()[0])] = line
    return found


def test_a_urdfs_joints_masses_and_origins_are_printed(capsys):
    assert main(["show", "--robot", str(CART)]) == 0
    out = capsys.readouterr().out
    table = rows(out)
    assert out.startswith(f"robot {CART} (URDF), as Pinocchio will use it: 2 joints")
    assert "gravity: none in the file" in out
    assert "cart_slider: prismatic" in out and "pole_hinge: continuous" in out
    mass = table[("pole_hinge", "mass")]
    assert " 0.4 " in mass and mass.endswith("written in the file")
    assert table[("pole_hinge", "axis")].split()[1:4] == ["0", "-1", "0"]
    assert table[("pole_hinge", "com")].split()[1:4] == ["0", "0", "-0.3"]
    # the cart-pole's URDF declares no <dynamics>: Pinocchio's 0, and the file's silence, are said
    assert table[("cart_slider", "damping")].endswith("absent from the file: 0")


def test_the_summary_follows_the_file_a_changed_mass_shows(tmp_path, capsys):
    changed = tmp_path / "cart_pole.urdf"
    text = CART.read_text()
    assert '<mass value="0.4"/>' in text
    changed.write_text(text.replace('<mass value="0.4"/>', '<mass value="0.404"/>'))
    summary = api.read_robot(changed)
    masses = {j.name: q.value for j in summary.joints for q in j.quantities if q.name == "mass"}
    assert masses["pole_hinge"] == (0.404,)


def test_a_xacros_numbers_come_from_its_expansion(capsys):
    assert main(["show", "--robot", str(XACRO)]) == 0
    table = rows(capsys.readouterr().out)
    assert table[("joint1", "mass")].endswith("expanded by xacro")
    assert table[("joint1", "armature")].endswith("a URDF has none: 0")


def test_show_needs_a_model_or_a_robot(capsys):
    assert main(["show"]) == 2
    assert "give a MODEL file, --robot FILE, or both" in capsys.readouterr().err


def test_a_missing_robot_file_is_one_line(tmp_path, capsys):
    assert main(["show", "--robot", str(tmp_path / "nope.urdf")]) == 2
    err = capsys.readouterr().err
    assert "nope.urdf" in err and "robot description not found" in err and "Traceback" not in err


def test_an_mjcfs_numbers_say_what_mujoco_made_of_them(capsys):
    """gymnasium's double pendulum on a cart: inertias from geoms, damping from the default
    class, and its gravity vector as written (1e-5 along x)."""
    gymnasium = pytest.importorskip("gymnasium")
    path = Path(gymnasium.__file__).parent / "envs" / "mujoco" / "assets" / "inverted_double_pendulum.xml"
    assert main(["show", "--robot", str(path)]) == 0
    out = capsys.readouterr().out
    table = rows(out)
    assert "(MJCF)" in out.splitlines()[0]
    assert "gravity: 1e-05 0 -9.81 m/s² (written in the file)" in out
    assert table[("hinge", "mass")].endswith("computed by MuJoCo from geoms")
    assert table[("hinge", "damping")].endswith("from default class 'main'")
    assert table[("hinge2", "frame")].split()[1:4] == ["0", "0", "0.6"]
