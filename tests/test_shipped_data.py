"""Shipped data: found in the installed package, report's default, and a wheel carrying every file."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from pendverify.api import review_scenes
from pendverify.cli import build_parser
from pendverify.errors import InputError
from pendverify.shipped import FOLDERS, shipped_file, shipped_folder
from pendverify.worked_examples import EXAMPLES

REPO = Path(__file__).resolve().parents[1]
SCENE_PATH = re.compile(r'^(?:model|params|urdf)\s*=\s*"(\.\./[^"]+)"', re.MULTILINE)

#: folder in the clone -> where it lands in the wheel, and which of its files must be there
SHIPPED_IN_CLONE = {
    "examples": ("pendverify/examples", "*"),
    "scenes": ("pendverify/scenes", "*"),
    "sweeps": ("pendverify/sweeps", "*"),
    "urdf": ("pendverify/urdf", "*.urdf"),
    "analytic/params": ("pendverify/analytic/params", "*.toml"),
}


def test_every_kind_of_shipped_data_is_a_folder_of_files():
    for kind in FOLDERS:
        folder = shipped_folder(kind)
        assert folder.is_dir(), kind
        assert any(folder.iterdir()), kind


def test_every_example_file_is_shipped():
    for example in EXAMPLES:
        for f in example.files:
            assert f.source.is_file(), f"{example.name}: {f.kind}/{f.name}"


def test_the_shipped_scenes_relative_paths_resolve_to_shipped_files():
    scenes = sorted(shipped_folder("scenes").glob("*.toml"))
    relative = [(scene, path) for scene in scenes for path in SCENE_PATH.findall(scene.read_text("utf-8"))]
    assert relative, "no scene names a file beside it: the test would check nothing"
    for scene, path in relative:
        assert (scene.parent / path).is_file(), f"{scene.name}: {path}"


def test_report_reviews_the_shipped_scenes_by_default():
    assert review_scenes(None) == sorted(shipped_folder("scenes").glob("*.toml"))
    assert shipped_file("scenes", "cart_pole_lqr_push.toml") in review_scenes(None)
    assert shipped_folder("scenes").samefile(REPO / "scenes")  # this checkout is the one installed


def test_report_names_its_default_in_its_help(capsys):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["report", "--help"])
    assert "scenes installed with pendverify" in " ".join(capsys.readouterr().out.split())


def test_report_refuses_a_folder_without_scenes(tmp_path):
    with pytest.raises(InputError, match="no scene files"):
        review_scenes(str(tmp_path))


def _copy_sources(target: Path) -> None:
    """The files a wheel is built from, copied (a build in the clone would leave build/ there)."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(REPO / name, target / name)
    for folder in ("verify", "analytic", "viz", "urdf", "examples", "scenes", "sweeps"):
        shutil.copytree(REPO / folder, target / folder, ignore=ignore)


@pytest.mark.slow
def test_a_wheel_carries_every_shipped_file(tmp_path):
    source, out = tmp_path / "src", tmp_path / "wheel"
    source.mkdir()
    _copy_sources(source)
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--quiet", "-w", str(out), str(source)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert built.returncode == 0, built.stderr[-2000:]
    [wheel] = out.glob("pendverify-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())

    expected = {"pendverify/py.typed", "pendverify/__main__.py"}
    for folder, (inside, pattern) in SHIPPED_IN_CLONE.items():
        files = [p for p in (REPO / folder).glob(pattern) if p.is_file() and p.suffix != ".pyc"]
        assert files, folder
        expected |= {f"{inside}/{p.name}" for p in files}
    missing = sorted(expected - names)
    assert not missing, missing
