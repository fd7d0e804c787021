"""example-robot-data's double pendulums: a model no one here wrote."""

from __future__ import annotations

import importlib.metadata
import json
import math
from pathlib import Path

import pytest

import pendverify
from pendverify.cli import main
from pendverify.errors import PendverifyError
from pendverify.robot import erd
from pendverify.robot.erd import family_urdfs
from pendverify.robot.system import PinocchioSystem
from pendverify.simulation.scene import load_scene
from pendverify.viz.review_folder import scene_targets

REPO = Path(__file__).resolve().parents[2]


def test_urdfs_are_found_in_the_installed_distribution():
    found = family_urdfs()
    assert {"double_pendulum", "double_pendulum_simple", "double_pendulum_continuous"} <= set(found)
    assert all(path.is_file() for path in found.values())


def test_simple_urdf_parameters_are_read_off_exactly():
    system = PinocchioSystem.from_urdf("double_pendulum", family_urdfs()["double_pendulum_simple"])
    p = system.geometry.params
    expected = dict(m1=0.2, m2=0.3, l1=0.1, r1=0.05, r2=0.1, I1=0.000177083, I2=0.001015625, b1=0.05, b2=0.05)
    for key, value in expected.items():
        assert getattr(p, key) == pytest.approx(value, rel=1e-15), key
    # link 1 points up at q = 0: θ1 = q1 + π/2; axis +x, so no sign change
    assert system.geometry.cmap.theta0[0] == pytest.approx(math.pi / 2, rel=1e-15)
    assert system.geometry.cmap.T.tolist() == [[1.0, 0.0], [0.0, 1.0]]
    assert system.geometry.model_form is None and system.allowance.tolist() == [0.0, 0.0]


def test_mesh_urdf_off_line_centre_of_mass_is_reported():
    system = PinocchioSystem.from_urdf("double_pendulum", family_urdfs()["double_pendulum"])
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
    found = family_urdfs()
    a = PinocchioSystem.from_urdf("double_pendulum", found["double_pendulum"]).geometry.params
    b = PinocchioSystem.from_urdf("double_pendulum", found["double_pendulum_continuous"]).geometry.params
    assert a == b


# --- example-robot-data not installed: an optional extra -------------------------------------------------
def _without_erd(monkeypatch):
    """Make importlib.metadata find no example-robot-data distribution, as in an install without the extra."""
    real = importlib.metadata.distribution

    def distribution(name):
        if name == erd.DISTRIBUTION:
            raise importlib.metadata.PackageNotFoundError(name)
        return real(name)

    monkeypatch.setattr(importlib.metadata, "distribution", distribution)


SKIPPED_LINE = (
    "note: example-robot-data is not installed: its double-pendulum URDFs are skipped "
    "(pip install 'pendverify[erd]')"
)


def test_installed_finds_the_distribution_or_says_none(monkeypatch):
    assert erd.installed() is not None
    _without_erd(monkeypatch)
    assert erd.installed() is None


def test_default_check_without_erd_skips_its_urdfs_in_one_note_line(monkeypatch, capsys, tmp_path):
    _without_erd(monkeypatch)
    out = tmp_path / "report.json"
    assert main(["check", "--samples", "5", "--json", str(out)]) == 0  # exit status unchanged
    text = capsys.readouterr().out
    assert text.count("example-robot-data") == 1 and SKIPPED_LINE in text.splitlines()
    assert "erd:" not in text
    document = json.loads(out.read_text())
    assert set(document["states"]) == {"double_pendulum", "cart_double_pendulum"}
    assert document["skipped"] == [SKIPPED_LINE.removeprefix("note: ")]

    assert main(["check", "--model", "double_pendulum", "--samples", "5"]) == 0
    assert SKIPPED_LINE in capsys.readouterr().out.splitlines()


@pytest.mark.parametrize(
    "argv",
    [
        ["--no-erd"],
        ["--model", "cart_double_pendulum"],
        ["--params", str(REPO / "analytic" / "params" / "double_pendulum.toml")],
    ],
    ids=["--no-erd", "the cart", "a parameter file"],
)
def test_no_note_where_example_robot_data_would_not_be_checked(monkeypatch, capsys, argv):
    _without_erd(monkeypatch)
    assert main(["check", *argv, "--samples", "5"]) == 0
    assert "example-robot-data" not in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv",
    [
        ["check", "--urdf", "erd:double_pendulum"],
        ["check", "--model", "double_pendulum", "--urdf", "erd:double_pendulum"],
        ["certify", "--model", "double_pendulum", "--urdf", "erd:double_pendulum", "-o", "OUT"],
    ],
    ids=["check", "check --model", "certify"],
)
def test_naming_an_erd_urdf_without_it_is_a_one_line_error(monkeypatch, capsys, tmp_path, argv):
    _without_erd(monkeypatch)
    argv = [str(tmp_path / "out") if a == "OUT" else a for a in argv]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert captured.err == (
        "pendverify: error: erd:double_pendulum: example-robot-data is not installed "
        "(pip install 'pendverify[erd]')\n"
    )
    assert not (tmp_path / "out").exists()


def test_the_api_skips_and_says_so_and_erd_false_says_nothing(monkeypatch):
    _without_erd(monkeypatch)
    report = pendverify.check("double_pendulum", samples=5)
    assert report.models == ("double_pendulum",) and report.passed
    assert report.skipped == [erd.SKIPPED] and SKIPPED_LINE in report.table().splitlines()
    assert "example-robot-data is not installed" in report._repr_html_()
    quiet = pendverify.check("double_pendulum", samples=5, erd=False)
    assert quiet.skipped == [] and "example-robot-data" not in quiet.table()
    with pytest.raises(PendverifyError, match=r"^erd:double_pendulum_simple: example-robot-data is not"):
        pendverify.check("erd:double_pendulum_simple")


def test_the_review_folder_skips_them_too(monkeypatch):
    scene = load_scene(REPO / "scenes" / "damped_double_pendulum.toml")
    assert [t.label for t in scene_targets([scene]).targets][1:] == [f"erd:{stem}" for stem in family_urdfs()]
    _without_erd(monkeypatch)
    selection = scene_targets([scene])
    assert [t.label for t in selection.targets] == ["double_pendulum"]
    assert selection.skipped == [erd.SKIPPED]
    assert scene_targets([scene], erd=False).skipped == []
