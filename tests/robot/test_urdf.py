"""URDFs: the committed files are what the generator writes; shapes are validated."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import DoublePendulum
from pendverify.checks.catalogue import run_checks
from pendverify.checks.sampling import sample_states
from pendverify.errors import UrdfShapeError, UserFileError
from pendverify.robot.description import load_description
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for

from ..conftest import SEED, default_params

REPO = Path(__file__).resolve().parents[2]


def test_committed_urdfs_match_the_generator(model_name):
    committed = (REPO / "urdf" / f"{model_name}.urdf").read_text()
    assert committed == urdf_for(default_params(model_name)), (
        f"urdf/{model_name}.urdf is stale: regenerate it with pendverify.robot.writer.urdf_for"
    )


def test_visuals_are_primitive_shapes(model_name):
    text = urdf_for(default_params(model_name))
    assert "<mesh" not in text
    assert text.count("<visual") >= 4


def test_urdf_round_trips_every_parameter():
    params = default_params("double_pendulum").replace(I1=0.0123456789012345, r2=0.1 + 1e-15)
    system = PinocchioSystem.from_urdf("double_pendulum", urdf_for(params), params.g)
    read = system.geometry.params
    for key in ("m1", "m2", "l1", "r1", "r2", "I1", "I2", "b1", "b2"):
        assert getattr(read, key) == pytest.approx(getattr(params, key), rel=4e-16, abs=0), key


def test_point_masses_work_in_pinocchio():
    """Zero rotational inertia is legal: every check still passes at eps level."""
    params = default_params("double_pendulum").replace(I1=0.0, I2=0.0)
    model = DoublePendulum(params)
    system = PinocchioSystem.from_urdf("double_pendulum", urdf_for(params), params.g)
    results = run_checks("point masses", model, system, sample_states(model, 40, SEED), SEED)
    assert all(r.passed for r in results), [r.name for r in results if not r.passed]
    assert np.isfinite(system.acceleration(np.zeros(2), np.zeros(2), np.zeros(2))).all()


def test_wrong_chain_is_a_clear_error():
    cart = urdf_for(default_params("cart_double_pendulum"))
    with pytest.raises(
        UrdfShapeError, match="expected a chain of joints revolute → revolute, found prismatic"
    ):
        PinocchioSystem.from_urdf("double_pendulum", cart, source="cart.urdf")


def test_non_parallel_axes_are_a_clear_error():
    text = urdf_for(default_params("double_pendulum"))
    bent = text.replace('<axis xyz="1 0 0"/>', '<axis xyz="0 0 1"/>', 1)
    with pytest.raises(
        UrdfShapeError, match=r"bent.urdf: joint axes .* are not parallel: not a planar chain"
    ):
        PinocchioSystem.from_urdf("double_pendulum", bent, source="bent.urdf")


def test_vertical_axis_is_a_clear_error():
    text = urdf_for(default_params("double_pendulum")).replace('<axis xyz="1 0 0"/>', '<axis xyz="0 0 1"/>')
    with pytest.raises(
        UrdfShapeError, match="is not horizontal: the chain does not swing in a vertical plane"
    ):
        PinocchioSystem.from_urdf("double_pendulum", text, source="flat.urdf")


def test_unparsable_and_missing_urdf(tmp_path):
    with pytest.raises(UserFileError, match=r"robot description not found: .*nothing\.urdf; check the path"):
        load_description(tmp_path / "nothing.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'></robot>")
    with pytest.raises(UrdfShapeError, match=r"bad\.urdf: malformed XML at line 1, column \d+: mismatched"):
        load_description(bad)
    # well-formed XML that Pinocchio refuses: its own reason, not a generic sentence
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'/></robot>")
    with pytest.raises(UrdfShapeError, match=r"bad\.urdf: Pinocchio cannot parse it as URDF: .*j"):
        load_description(bad)


def test_reversed_axis_and_offset_are_read_off_the_geometry():
    """A URDF with joint 2's axis flipped and link 1 pointing up still verifies."""
    params = default_params("double_pendulum")
    text = urdf_for(params)
    # turn the whole chain by +90° (link 1 up at q = 0) and flip joint 2's axis
    text = text.replace(
        '<joint name="joint1" type="revolute">\n    <parent link="base"/>\n    <child link="link1"/>\n'
        '    <origin xyz="0 0 0" rpy="0 0 0"/>',
        '<joint name="joint1" type="revolute">\n    <parent link="base"/>\n    <child link="link1"/>\n'
        '    <origin xyz="0 0 0" rpy="1.5707963267948966 0 0"/>',
    )
    head, tail = text.split('<joint name="joint2"')
    text = head + '<joint name="joint2"' + tail.replace('<axis xyz="1 0 0"/>', '<axis xyz="-1 0 0"/>', 1)
    system = PinocchioSystem.from_urdf("double_pendulum", text, params.g)
    assert system.geometry.cmap.theta0[0] == pytest.approx(np.pi / 2)
    assert system.geometry.cmap.T[1, 1] == -1.0
    model = DoublePendulum(params)
    results = run_checks("turned", model, system, sample_states(model, 40, SEED), SEED)
    assert all(r.passed for r in results), [(r.name, r.error) for r in results if not r.passed]


@pytest.mark.parametrize(
    ("call", "key"),
    [
        (lambda s: s.mass_matrix([0.1, float("nan")]), "q[1]"),
        (lambda s: s.bias([0.1, 0.2], [float("inf"), 0.0]), "v[0]"),
        (lambda s: s.acceleration([0.1, 0.2], [0.0, 0.0], [0.0, float("nan")]), "tau[1]"),
    ],
)
def test_non_finite_states_are_refused_not_propagated(call, key):
    from pendverify.errors import InputError

    system = PinocchioSystem.from_urdf(
        "double_pendulum", urdf_for(default_params("double_pendulum")), 9.81, "dp.urdf"
    )
    with pytest.raises(
        InputError, match=rf"dp\.urdf: key '{re.escape(key)}' = .*: a state entry must be a finite number"
    ):
        call(system)


def test_a_model_without_a_urdf_writer_is_a_clear_error():
    from pendverify.analytic.plugin import load_model_class, plugin_parameters
    from pendverify.analytic.reference_urdfs import WRITERS
    from pendverify.errors import PendverifyError
    from pendverify.robot.writer import urdf_for

    examples = Path(__file__).resolve().parents[2] / "examples"
    cls = load_model_class(examples / "cart_pole.py")
    params = plugin_parameters(cls, "cart_pole.py", str(examples / "cart_pole.toml"))
    assert set(WRITERS) == {"double_pendulum", "cart_double_pendulum"}
    with pytest.raises(PendverifyError, match="no URDF writer for model 'cart_pole': give the URDF"):
        urdf_for(params)


def test_a_model_naming_an_unknown_geometry_reader_is_a_clear_error(tmp_path):
    from pendverify.analytic.reference_geometry import READERS
    from pendverify.errors import UnknownNameError
    from pendverify.robot.system import geometry_for

    class Renamed(DoublePendulum):
        geometry_reader = "no_such_reader"

    urdf = tmp_path / "double.urdf"
    urdf.write_text(urdf_for(default_params("double_pendulum")))
    assert set(READERS) == {"double_pendulum", "cart_double_pendulum"}
    assert PinocchioSystem.for_model(DoublePendulum, urdf).geometry.params is not None
    with pytest.raises(UnknownNameError, match="no_such_reader"):
        PinocchioSystem.for_model(Renamed, urdf)
    pinocchio_model = load_description(urdf).model
    with pytest.raises(UnknownNameError, match="double_pendulum, cart_double_pendulum"):
        geometry_for(Renamed, pinocchio_model, str(urdf), None)
