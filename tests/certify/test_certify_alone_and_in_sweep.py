"""One certificate for one set: a set certified alone and the same set certified in a sweep give
the same certificate, field by field, but for the fields each run makes its own (``date``, and
``digest``, which covers it: ``pendverify.certify.issue.write_certificate``)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from pendverify.certify.issue import certification_input, issue
from pendverify.certify.sweep import load_sweep
from pendverify.cli import main

pytestmark = pytest.mark.sweep  # every test certifies a set alone and in a sweep

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
PER_RUN = ("date", "digest")  # write_certificate's docstring names them
SETTINGS = 'mode = "random"\ncount = 2\nseed = 11\nsamples = 50\nduration = 0.2\n'


def _builtin_sweep(folder: Path) -> Path:
    sweep = folder / "sweep.toml"
    sweep.write_text(f'model = "double_pendulum"\n{SETTINGS}[ranges]\nm1 = [0.5, 2.0]\n')
    return sweep


def _plugin_sweep(folder: Path) -> Path:
    """A model file whose URDF reading has notes (its declared coordinate map)."""
    for suffix in ("py", "urdf", "toml"):
        shutil.copy(EXAMPLES / f"hanging_double_pendulum.{suffix}", folder / f"hanging.{suffix}")
    sweep = folder / "sweep.toml"
    text = f'model = "hanging.py"\nbase = "hanging.toml"\nurdf = "hanging.urdf"\n{SETTINGS}'
    sweep.write_text(text + "[ranges]\nm1 = [0.5, 2.0]\n")
    return sweep


def _alone(folder: Path, name: str, model_file: Path | None):
    """The set as ``certify`` reads it, from the files the sweep wrote for it: its parameter
    file; with a model file, its URDF and parameter file."""
    params = str(folder / f"{name}.params.toml")
    if model_file is None:
        return certification_input(params_file=params)
    return certification_input(
        urdf=str(folder / f"{name}.urdf"), urdf_params=params, analytic=str(model_file)
    )


@pytest.mark.parametrize("plugin", [False, True], ids=["built-in", "model file"])
def test_a_set_alone_and_in_a_sweep_has_one_certificate(tmp_path, plugin):
    sweep_file = (_plugin_sweep if plugin else _builtin_sweep)(tmp_path)
    swept = tmp_path / "swept"
    assert main(["certify", "--sweep", str(sweep_file), "-o", str(swept), "--workers", "1"]) == 0
    sweep = load_sweep(sweep_file)
    name = sweep.sets[0][0]
    model_file = tmp_path / "hanging.py" if plugin else None
    issued = issue(_alone(swept, name, model_file), sweep.settings, tmp_path / "alone")
    assert issued.certified, issued

    alone = json.loads(issued.path.read_text())
    in_sweep = json.loads((swept / f"{name}.cert.json").read_text())
    assert alone.keys() == in_sweep.keys()
    for key in alone.keys() - set(PER_RUN):
        assert alone[key] == in_sweep[key], key
    if plugin:  # the notes compared are not only empty ones
        assert in_sweep["notes"] and "coordinate map declared by" in in_sweep["notes"][0]
