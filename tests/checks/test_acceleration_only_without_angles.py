"""A model given by q̈ alone with no angular coordinate (two carriages on x and y rails).

Its gravity scale is taken from the URDF over a grid of the angles (``checks.batch.
urdf_gravity_scale``); with no angle the grid was stacked from nothing (ValueError, exit 3).
"""

from __future__ import annotations

import pytest

from pendverify.cli import main

MODEL = """name = "xy_table"
inputs = ["force"]
qddot = ["force / (m1 + m2)", "{ddy}"]
B = [["1"], ["0"]]
[coordinates]
x = "position"
y = "position"
[parameters]
m1 = {{ kind = "mass" }}
m2 = {{ kind = "mass" }}
g = {{ kind = "gravity" }}
[urdf]
joints = ["sx", "sy"]
"""
PARAMS = 'model = "xy_table"\n[parameters]\nm1 = 1.0\nm2 = 0.5\ng = 9.81\n'
INERTIA = '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/>'
LIMIT = '<limit lower="-10" upper="10" effort="100" velocity="100"/>'
URDF = f"""<robot name="xy"><link name="base"/>
  <joint name="sx" type="prismatic"><parent link="base"/><child link="a"/><axis xyz="1 0 0"/>{LIMIT}</joint>
  <link name="a"><inertial><mass value="1.0"/>{INERTIA}</inertial></link>
  <joint name="sy" type="prismatic"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>{LIMIT}</joint>
  <link name="b"><inertial><mass value="0.5"/>{INERTIA}</inertial></link></robot>
"""


@pytest.mark.parametrize(
    ("ddy", "status"),
    [("0", 0), ("force / m2", 1)],  # the y carriage is not driven; a planted drive must fail aba
)
def test_a_model_of_positions_alone_is_checked(tmp_path, capsys, ddy, status):
    (tmp_path / "xy.toml").write_text(MODEL.format(ddy=ddy))
    (tmp_path / "params.toml").write_text(PARAMS)
    (tmp_path / "xy.urdf").write_text(URDF)
    argv = ["check", "--analytic", str(tmp_path / "xy.toml"), "--urdf", str(tmp_path / "xy.urdf")]
    argv += ["--params", str(tmp_path / "params.toml"), "--samples", "10"]
    assert main(argv) == status, capsys.readouterr()
    assert "aba" in capsys.readouterr().out
