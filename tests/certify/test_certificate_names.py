"""A set certified on a URDF is named after its model, then the URDF when that is another name;
certificates named by the URDF alone (issued before that rule) are still rechecked."""

from __future__ import annotations

import dataclasses
import json

import pytest

from pendverify.analytic.params import default_parameter_file
from pendverify.certify.battery import BatterySettings
from pendverify.certify.issue import certification_input, issue
from pendverify.certify.names import set_name
from pendverify.cli import main
from pendverify.errors import BundleNameError
from pendverify.robot.writer import urdf_for
from pendverify.shipped import shipped_file

from ..conftest import default_params

FAST = ["--samples", "30"]
CART_POLE = [str(shipped_file("examples", f"cart_pole{suffix}")) for suffix in (".py", ".urdf", ".toml")]


@pytest.mark.parametrize(
    ("model", "urdf", "name"),
    [
        ("cart_pole", "cart_pole", "cart_pole"),  # the URDF of the model's own name adds nothing
        ("cart_pole", "cart_pole_heavy", "cart_pole_heavy"),  # nor one whose name starts with it
        ("cart_pole", "cart_pole-3", "cart_pole-3"),  # a sweep's set
        ("cart_pole", "cart_poles", "cart_pole-cart_poles"),  # another word
        ("double_pendulum", "erd_double_pendulum", "double_pendulum-erd_double_pendulum"),
        ("minimal_double_pendulum", "double_pendulum", "minimal_double_pendulum-double_pendulum"),
    ],
)
def test_a_set_on_a_urdf_is_named_after_its_model_then_the_urdf(model, urdf, name):
    assert set_name(model, urdf, "x.urdf") == name


def test_a_name_too_long_for_a_file_is_refused():
    with pytest.raises(
        BundleNameError, match=r"x\.urdf: key 'bundle name \(the model's name, then the URDF's\)'"
    ):
        set_name("m" * 100, "u" * 100, "x.urdf")


def test_a_model_file_on_its_own_urdf_is_named_after_the_model(tmp_path):
    out = tmp_path / "certs"
    argv = ["certify", "--analytic", CART_POLE[0], "--urdf", CART_POLE[1], "--params", CART_POLE[2]]
    assert main([*argv, "-o", str(out), *FAST]) == 0
    assert sorted(p.name for p in out.iterdir()) == [
        "cart_pole.cert.json",
        "cart_pole.model.py",
        "cart_pole.params.toml",
        "cart_pole.urdf",
    ]


def test_a_built_in_model_on_a_urdf_of_another_name_is_named_after_both(tmp_path, capsys):
    urdf = tmp_path / "bench_rig.urdf"
    urdf.write_text(urdf_for(default_params("double_pendulum")))
    out = tmp_path / "certs"
    argv = ["certify", "--model", "double_pendulum", "--urdf", str(urdf), "-o", str(out), *FAST]
    assert main(argv) == 0
    cert = out / "double_pendulum-bench_rig.cert.json"
    assert json.loads(cert.read_text())["name"] == "double_pendulum-bench_rig"
    assert main(["recheck", str(cert)]) == 0


def test_a_certificate_named_by_its_urdf_alone_is_still_rechecked(tmp_path, capsys):
    """The old rule (the URDF's stem alone) made certificates that recheck reads by the name they record."""
    urdf = tmp_path / "bench_rig.urdf"
    urdf.write_text(urdf_for(default_params("double_pendulum")))
    target = certification_input(urdf=str(urdf), urdf_params=str(default_parameter_file("double_pendulum")))
    assert target.name == "double_pendulum-bench_rig"
    old = dataclasses.replace(target, name="bench_rig")
    issued = issue(old, BatterySettings(samples=30), tmp_path / "certs")
    assert issued.path.name == "bench_rig.cert.json"
    assert main(["recheck", str(issued.path)]) == 0
    assert "recheck passed" in capsys.readouterr().out
