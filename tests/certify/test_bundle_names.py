"""Names are not paths: a set's name never makes certify write outside -o."""

from __future__ import annotations

import json
import os
from pathlib import Path
from types import SimpleNamespace

import pytest

from pendverify.certify.bundle import write_bundle
from pendverify.certify.issue import check_sweep_names
from pendverify.certify.names import NAME_PATTERN, check_name
from pendverify.cli import main
from pendverify.errors import BundleNameError, CertificateError

from ..conftest import default_params

BAD = ["../../escape", "/tmp/abs", "", "two\nlines", "nul\x00byte", ".", "..", "C:evil", "dir\\file", "ends."]


@pytest.mark.parametrize("name", BAD)
def test_the_rule_refuses_every_name_that_is_a_path(name):
    with pytest.raises(BundleNameError) as caught:
        check_name(name, "set.toml", "name")
    message = str(caught.value)
    assert message.startswith(f"set.toml: key 'name' = {name!r}: a bundle name must match {NAME_PATTERN}")
    assert "\n" not in message.replace(repr(name), "")  # one line, whatever the name holds


@pytest.mark.parametrize("name", ["double_pendulum", "erd_double_pendulum", "arm-007", "a", "v1.2_b"])
def test_ordinary_names_pass(name):
    assert check_name(name, "set.toml", "name") == name


@pytest.mark.parametrize(
    "name", ["../../escape", "/tmp/pendverify-escape", "a\\b", "two\nlines", "C:x", ".."]
)
def test_a_parameter_file_s_name_is_checked_where_it_is_read(name, tmp_path, capsys):
    params = tmp_path / "set.toml"
    text = default_params("double_pendulum").to_toml("placeholder")
    params.write_text(text.replace('name = "placeholder"', f"name = {json.dumps(name)}"))
    out = tmp_path / "deep" / "out"
    assert main(["certify", str(params), "-o", str(out), "--samples", "20", "--force"]) == 2
    err = capsys.readouterr().err
    assert f"{params}: key 'name' = " in err and "a bundle name must match" in err
    assert [p.name for p in tmp_path.iterdir()] == ["set.toml"]
    assert not list(tmp_path.parent.glob("escape*")) and not list(Path("/tmp").glob("pendverify-escape*"))


def test_a_urdf_stem_is_checked(tmp_path, capsys):
    from pendverify.robot.writer import urdf_for

    urdf = tmp_path / "my robot.urdf"
    urdf.write_text(urdf_for(default_params("double_pendulum")))
    args = ["certify", "--model", "double_pendulum", "--urdf", str(urdf), "-o", str(tmp_path / "out")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert f"{urdf}: key 'URDF file name (its stem names the bundle)' = 'my robot'" in err


def test_sweep_set_names_are_checked_before_any_set_runs():
    sweep = SimpleNamespace(sets=[("arm-0", {}), ("../arm-1", {})])
    with pytest.raises(BundleNameError, match=r"sweep.toml: key 'set name .*' = '../arm-1'"):
        check_sweep_names(sweep, "sweep.toml")


def _bundle(tmp_path, name: str, force: bool = True):
    params = default_params("double_pendulum")
    cert = {"schema": "x", "checks": [], "settings": {}, "model": "double_pendulum"}
    return write_bundle(tmp_path / "out", name, params, "<robot/>", cert, force, description_format="urdf")


def test_a_bundle_write_outside_the_folder_is_refused_even_past_the_name_check(tmp_path):
    (tmp_path / "out").mkdir()
    with pytest.raises(CertificateError, match="outside the output folder"):
        _bundle(tmp_path, "../escape")
    assert not list(tmp_path.glob("escape*"))


def test_a_planted_symlink_is_not_followed_out_of_the_folder_even_with_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    victim = tmp_path / "victim.cert.json"
    victim.write_text("precious")
    os.symlink(victim, out / "set.cert.json")
    with pytest.raises(
        CertificateError, match=r"resolves to .*victim\.cert\.json, outside the output folder"
    ):
        _bundle(tmp_path, "set")
    assert victim.read_text() == "precious" and not (out / "set.urdf").exists()


def test_a_symlinked_output_folder_is_fine(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    os.symlink(real, tmp_path / "out")
    assert _bundle(tmp_path, "set").name == "set.cert.json"
    assert (real / "set.cert.json").is_file() and (real / "set.urdf").is_file()
