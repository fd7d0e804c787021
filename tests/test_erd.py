"""example-robot-data's double pendulums: a model no one here wrote."""

from __future__ import annotations

import math

import pytest

from pendverify.robot.erd import double_pendulum_urdfs
from pendverify.robot.system import PinocchioSystem


def test_urdfs_are_found_in_the_installed_distribution():
    found = double_pendulum_urdfs()
    assert {"double_pendulum", "double_pendulum_simple", "double_pendulum_continuous"} <= set(found)
    assert all(path.is_file() for path in found.values())


def test_simple_urdf_parameters_are_read_off_exactly():
    system = PinocchioSystem.from_urdf("double_pendulum", double_pendulum_urdfs()["double_pendulum_simple"])
    p = system.geometry.params
    expected = dict(m1=0.2, m2=0.3, l1=0.1, r1=0.05, r2=0.1, I1=0.000177083, I2=0.001015625, b1=0.05, b2=0.05)
    for key, value in expected.items():
        assert getattr(p, key) == pytest.approx(value, rel=1e-15), key
    # link 1 points up at q = 0: θ1 = q1 + π/2; axis +x, so no sign change
    assert system.geometry.cmap.theta0[0] == pytest.approx(math.pi / 2, rel=1e-15)
    assert system.geometry.cmap.T.tolist() == [[1.0, 0.0], [0.0, 1.0]]
    assert system.geometry.model_form is None and system.allowance.tolist() == [0.0, 0.0]


def test_mesh_urdf_off_line_centre_of_mass_is_reported():
    system = PinocchioSystem.from_urdf("double_pendulum", double_pendulum_urdfs()["double_pendulum"])
    form = system.geometry.model_form
    assert "off the joint-1→joint-2 line" in form.what
    assert any(
        "off the joint-1→joint-2 line" in note and "within the model-form threshold" in note
        for note in system.notes
    )
    # m1·g·d with d = 2.1727e-6 m from the URDF's inertial origin, 7.6e-6 of H1's size
    assert system.allowance[0] == pytest.approx(0.26703 * 9.81 * 2.1727e-6, rel=1e-3)
    assert form.relative == pytest.approx(7.6e-6, rel=1e-2)
    assert system.geometry.params.r1 == pytest.approx(math.hypot(0.036012, 2.1727e-6), rel=1e-12)


def test_continuous_joints_are_read_like_revolute_ones():
    found = double_pendulum_urdfs()
    a = PinocchioSystem.from_urdf("double_pendulum", found["double_pendulum"]).geometry.params
    b = PinocchioSystem.from_urdf("double_pendulum", found["double_pendulum_continuous"]).geometry.params
    assert a == b
