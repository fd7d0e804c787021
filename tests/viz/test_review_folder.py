"""``pendverify report`` on a user's scenes (``pendverify.viz.review_folder``): it checks every model
the scenes simulate.

A folder with built-in scenes gives a page whose check table holds their models (and
example-robot-data's double pendulums); a folder with a triple-pendulum scene and a Furuta
scene gives one holding both plug-in models against their URDFs; a plug-in whose mass matrix
is wrong (planted) makes the page and the exit code fail; a plug-in scene without a URDF is
refused before any work.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pendverify.cli import main

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"


def _scene(folder: Path, stem: str, q: list[float], model: Path | None = None, urdf: bool = True) -> Path:
    model = model or EXAMPLES / f"{stem}.py"
    urdf_line = f'urdf = "{EXAMPLES / f"{stem}.urdf"}"\n' if urdf else ""
    path = folder / f"{stem}.toml"
    path.write_text(
        f'name = "{stem} swing"\nmodel = "{model}"\nparams = "{EXAMPLES / f"{stem}.toml"}"\n{urdf_line}'
        f'engine = "closed_form"\n[initial]\nq = {q}\n[time]\nduration = 0.5\nsample_rate = 20.0\n'
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n[effects]\ngravity = true\n'
    )
    return path


def _report(tmp_path: Path, scenes: Path) -> tuple[int, dict, str]:
    out = tmp_path / "review"
    code = main(["report", "-o", str(out), "--scenes", str(scenes), "--samples", "20"])
    return code, json.loads((out / "report.json").read_text()), (out / "index.html").read_text()


def _built_in_scene(folder: Path, model: str, q: list[float]) -> Path:
    path = folder / f"{model}.toml"
    path.write_text(
        f'name = "{model} swing"\nmodel = "{model}"\n'
        f'engine = "closed_form"\n[initial]\nq = {q}\n[time]\nduration = 0.5\nsample_rate = 20.0\n'
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n[effects]\ngravity = true\n'
    )
    return path


def _built_in_scenes(folder: Path) -> list[str]:
    _built_in_scene(folder, "double_pendulum", [1.0, 0.4])
    _built_in_scene(folder, "cart_double_pendulum", [0.0, 0.1, -0.05])
    return ["double_pendulum", "cart_double_pendulum"]


def _plugin_scenes(folder: Path) -> list[str]:
    _scene(folder, "triple_pendulum", [1.0, 0.4, -0.3])
    _scene(folder, "furuta_pendulum", [0.2, 0.3])
    return ["triple_pendulum", "furuta_pendulum"]


ERD_DOUBLE_PENDULUMS = {"erd:double_pendulum", "erd:double_pendulum_continuous", "erd:double_pendulum_simple"}


@pytest.mark.parametrize(
    ("write_scenes", "models"),
    [
        pytest.param(
            _built_in_scenes,
            {"double_pendulum", "cart_double_pendulum", *ERD_DOUBLE_PENDULUMS},
            id="built-in",
        ),
        pytest.param(
            _plugin_scenes,
            {"triple_pendulum:triple_pendulum", "furuta_pendulum:furuta_pendulum"},
            id="plug-in",
        ),
    ],
)
def test_report_checks_the_models_its_scenes_use(write_scenes, models, tmp_path, capsys):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    stems = write_scenes(scenes)
    code, report, page = _report(tmp_path, scenes)
    assert code == 0, capsys.readouterr().out
    assert {r["model"] for r in report["results"]} == models, {r["model"] for r in report["results"]}
    assert all(r["passed"] for r in report["results"])
    for stem in stems:
        assert f"{stem} swing" in page


def test_a_planted_mass_matrix_error_in_a_scenes_model_fails_the_report(tmp_path, capsys):
    wrong = tmp_path / "wrong_triple.py"
    wrong.write_text(
        "import numpy as np\n"
        "from pendverify.analytic.plugin import load_model_class\n\n"
        f"Base = load_model_class({str(EXAMPLES / 'triple_pendulum.py')!r})\n\n\n"
        "class Wrong(Base):\n"
        "    def mass_matrix(self, q):\n"
        "        M = super().mass_matrix(q)\n"
        "        return M * np.array([[1.01, 1, 1], [1, 1, 1], [1, 1, 1]])\n"
    )
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    _scene(scenes, "triple_pendulum", [1.0, 0.4, -0.3], model=wrong)
    code, report, _ = _report(tmp_path, scenes)
    assert code == 1
    crba = [r for r in report["results"] if r["check"] == "crba"]
    assert crba and not crba[0]["passed"]


def test_a_plugin_scene_without_urdf_is_refused_before_any_work(tmp_path, capsys):
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    _scene(scenes, "triple_pendulum", [1.0, 0.4, -0.3], urdf=False)
    out = tmp_path / "review"
    assert main(["report", "-o", str(out), "--scenes", str(scenes), "--samples", "20"]) != 0
    err = capsys.readouterr().err
    assert "triple_pendulum.toml: key 'urdf'" in err and "against its URDF" in err
    assert not out.exists()
