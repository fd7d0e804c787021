"""`render --trajectory RUN.npz`: a saved run is data, and its work is bounded before it starts.

Planted: an npz whose metadata names a Python model file that writes a marker (refused
without `--analytic FILE`, the marker absent; drawn with it), a run spanning 1e9 s (refused
by the frame limit before any frame is computed), an npz member that declares 1e9 samples
in a few kB (refused from its header), and metadata JSON nested 100 000 deep.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from pendverify.cli import main
from pendverify.viz.animation import MAX_FRAMES_VARIABLE, Trajectory

from ..commands.test_exit_codes import error_line, one_error
from ..conftest import default_params

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
MINIMAL = "minimal_double_pendulum"
CLI_TIMEOUT_S = 120


def built_in_run(path: Path, duration: float = 1.0, samples: int = 20) -> Path:
    """An npz of the built-in double pendulum whose t spans ``duration`` seconds."""
    t = np.linspace(0.0, duration, samples)
    q = np.column_stack([np.sin(t), np.cos(t)])
    metadata = {"model": "double_pendulum", "parameters": default_params("double_pendulum").as_dict()}
    np.savez(path, t=t, q=q, metadata=np.array(json.dumps(metadata)))
    return path


@pytest.fixture
def plugin_run(tmp_path) -> tuple[Path, Path, Path]:
    """(npz, the Python model file it names, the marker that file writes when imported).

    The run is simulated from the shipped example; then the model file it names is replaced
    by one that defines the same model and writes a marker when imported (the attack).
    """
    folder = tmp_path / "example"
    assert main(["example", MINIMAL, str(folder)]) == 0
    scene = folder / "scenes" / f"{MINIMAL}_release.toml"
    scene.write_text(scene.read_text().replace("duration = 5.0", "duration = 0.3"))
    npz = tmp_path / "run.npz"
    assert main(["simulate", str(scene), "-o", str(npz)]) == 0
    model_file = folder / "examples" / f"{MINIMAL}.py"
    marker = tmp_path / "imported.marker"
    planted = model_file.read_text() + f"\nopen({str(marker)!r}, 'w').close()\n"
    model_file.write_text(planted)
    return npz, model_file, marker


def test_a_saved_run_never_imports_the_python_model_file_it_names(plugin_run, tmp_path, capsys):
    npz, model_file, marker = plugin_run
    meta = json.loads(str(np.load(npz)["metadata"]))
    assert Path(meta["model_file"]).resolve() == model_file.resolve()
    out = tmp_path / "run.html"
    assert main(["render", "--trajectory", str(npz), "-o", str(out)]) == 2
    line = error_line(capsys)
    assert "metadata.model_file" in line and model_file.name in line and "--analytic FILE" in line
    assert not marker.exists(), "the model file the npz names was imported"
    assert not out.exists()


def test_a_saved_run_of_a_model_file_renders_with_that_file_given(plugin_run, tmp_path, capsys):
    npz, model_file, marker = plugin_run
    out = tmp_path / "run.html"
    assert main(["render", "--trajectory", str(npz), "--analytic", str(model_file), "-o", str(out)]) == 0
    assert out.stat().st_size > 0 and marker.exists()  # the user's own file, run because given
    assert "note:" not in capsys.readouterr().out
    renamed = tmp_path / "mine.py"
    renamed.write_text(model_file.read_text())
    assert main(["render", "--trajectory", str(npz), "--analytic", str(renamed), "-o", str(out)]) == 0
    note = capsys.readouterr().out.splitlines()[0]
    assert note.startswith("note: the run names the model file ") and note.endswith(f"--analytic {renamed}")
    assert f"{MINIMAL}.py" in note


def test_a_saved_plugin_run_renders_with_its_model_file_given_and_its_recorded_urdf(tmp_path, capsys):
    run = tmp_path / "cart_pole.npz"
    assert main(["simulate", str(REPO / "scenes" / "cart_pole_lqr_push.toml"), "-o", str(run)]) == 0
    out = tmp_path / "replay.html"
    assert main(["render", "--trajectory", str(run), "-o", str(out)]) == 2  # the npz does not run code
    assert "--analytic FILE" in capsys.readouterr().err
    model = str(EXAMPLES / "cart_pole.py")
    assert main(["render", "--trajectory", str(run), "--analytic", model, "-o", str(out)]) == 0
    assert "cart-pole LQR after a push" in out.read_text()


def test_the_analytic_file_must_define_the_runs_model(plugin_run, tmp_path, capsys):
    npz, _, _ = plugin_run
    other = EXAMPLES / "cart_pole.py"
    assert (
        main(["render", "--trajectory", str(npz), "--analytic", str(other), "-o", str(tmp_path / "x.html")])
        == 2
    )
    line = error_line(capsys)
    assert "metadata.model" in line and "'cart_pole', not the run's" in line


def test_analytic_is_refused_without_a_plugin_run(tmp_path, capsys):
    npz = built_in_run(tmp_path / "run.npz")
    model = str(EXAMPLES / f"{MINIMAL}.py")
    assert (
        main(["render", "--trajectory", str(npz), "--analytic", model, "-o", str(tmp_path / "x.html")]) == 2
    )
    assert "built-in model 'double_pendulum'" in error_line(capsys)
    scene = REPO / "scenes" / "damped_double_pendulum.toml"
    assert main(["render", str(scene), "--analytic", model, "-o", str(tmp_path / "x.html")]) == 2
    assert "--analytic is for --trajectory" in error_line(capsys)


def test_a_text_model_named_by_a_saved_run_is_read(tmp_path):
    """A text model runs nothing: the run names it and it is read without --analytic."""
    folder = tmp_path / "example"
    assert main(["example", MINIMAL, str(folder)]) == 0
    scene = folder / "scenes" / "text.toml"
    text = (folder / "scenes" / f"{MINIMAL}_release.toml").read_text()
    text = text.replace(f'/{MINIMAL}.py"', f'/{MINIMAL}_text.toml"').replace(
        "duration = 5.0", "duration = 0.3"
    )
    scene.write_text(text)
    npz = tmp_path / "run.npz"
    assert main(["simulate", str(scene), "-o", str(npz)]) == 0
    traj = Trajectory.from_npz(npz)
    assert traj.model_cls is not None and traj.model_cls.name == MINIMAL


def run_cli(argv: list[str], **env: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "pendverify", *argv],
        capture_output=True,
        text=True,
        timeout=CLI_TIMEOUT_S,
        env={**os.environ, **env},
    )


def test_a_run_spanning_1e9_s_is_refused_by_the_frame_limit(tmp_path):
    npz = built_in_run(tmp_path / "long.npz", duration=1e9)
    done = run_cli(["render", "--trajectory", str(npz), "-o", str(tmp_path / "x.html")])
    assert done.returncode == 2, done.stderr
    line = one_error(done.stderr)
    assert "key 't'" in line and "5e+10 frames" in line and "limit of 90000" in line
    assert MAX_FRAMES_VARIABLE in line
    assert not (tmp_path / "x.html").exists()


def test_the_frame_limit_is_overridable(tmp_path, monkeypatch, capsys):
    npz = built_in_run(tmp_path / "run.npz", duration=1.0)  # 51 frames at 50 fps
    out = str(tmp_path / "x.html")
    monkeypatch.setenv(MAX_FRAMES_VARIABLE, "40")
    assert main(["render", "--trajectory", str(npz), "-o", out]) == 2
    assert "limit of 40" in error_line(capsys)
    monkeypatch.setenv(MAX_FRAMES_VARIABLE, "60")
    assert main(["render", "--trajectory", str(npz), "-o", out]) == 0
    monkeypatch.setenv(MAX_FRAMES_VARIABLE, "many")
    assert main(["render", "--trajectory", str(npz), "-o", out]) == 2
    assert f"key '{MAX_FRAMES_VARIABLE}' = 'many'" in error_line(capsys)


def test_an_array_declaring_1e9_samples_is_refused_from_its_header(tmp_path):
    """A few kB of zip that would inflate to 8 GB: refused before anything is loaded."""
    npz = tmp_path / "bomb.npz"
    with zipfile.ZipFile(npz, "w", zipfile.ZIP_DEFLATED) as archive:
        with archive.open("t.npy", "w", force_zip64=True) as member:
            header = {"descr": "<f8", "fortran_order": False, "shape": (10**9,)}
            np.lib.format.write_array_header_1_0(member, header)
            member.write(bytes(1 << 20))
        for name, array in (("q", np.zeros((2, 2))), ("metadata", np.array("{}"))):
            with archive.open(f"{name}.npy", "w") as member:
                np.save(member, array)
    assert npz.stat().st_size < 100_000
    done = run_cli(["render", "--trajectory", str(npz), "-o", str(tmp_path / "x.html")])
    assert done.returncode == 2, done.stderr
    line = one_error(done.stderr)
    assert "key 't' = (1000000000,)" in line and "PENDVERIFY_MAX_SAMPLES" in line


@pytest.mark.parametrize(
    ("arrays", "expected"),
    [
        (
            {"t": np.array(["a", "b"]), "q": np.zeros((2, 2)), "metadata": np.array("{}")},
            "key 't' = '<U1': must be an array of real numbers",
        ),
        (
            {"t": np.arange(2.0), "q": np.zeros((2, 2), complex), "metadata": np.array("{}")},
            "key 'q' = 'complex128'",
        ),
        ({"t": np.arange(2.0), "q": np.zeros((2, 2))}, "key 'metadata' = None: missing array"),
    ],
)
def test_arrays_of_the_wrong_kind_are_refused(tmp_path, capsys, arrays, expected):
    npz = tmp_path / "run.npz"
    np.savez(npz, **arrays)
    assert main(["render", "--trajectory", str(npz), "-o", str(tmp_path / "x.html")]) == 2
    assert expected in error_line(capsys)


def test_metadata_nested_100000_deep_is_refused_in_one_line(tmp_path, capsys):
    npz = tmp_path / "deep.npz"
    depth = 100_000
    np.savez(npz, t=np.arange(3.0), q=np.zeros((3, 2)), metadata=np.array("[" * depth + "]" * depth))
    assert main(["render", "--trajectory", str(npz), "-o", str(tmp_path / "x.html")]) == 2
    assert "key 'metadata' = None: not JSON: nested too deeply" in error_line(capsys)


def test_a_long_scene_name_is_shortened_in_the_title(tmp_path, capsys):
    npz = tmp_path / "run.npz"
    built_in_run(npz)
    with np.load(npz) as saved:
        meta = json.loads(str(saved["metadata"]))
        t, q = saved["t"], saved["q"]
    meta["scene"] = "x" * 4000
    np.savez(npz, t=t, q=q, metadata=np.array(json.dumps(meta)))
    assert len(Trajectory.from_npz(npz).title) <= 80


def test_a_scene_too_long_to_animate_is_refused_before_it_is_simulated(tmp_path, monkeypatch, capsys):
    scene = REPO / "scenes" / "damped_double_pendulum.toml"
    monkeypatch.setenv(MAX_FRAMES_VARIABLE, "50")  # the scene runs for more than 1 s
    assert main(["render", str(scene), "-o", str(tmp_path / "x.html")]) == 2
    line = error_line(capsys)
    assert "key 'time.duration'" in line and "limit of 50" in line
    assert "trajectory" not in capsys.readouterr().out


def test_simulate_html_checks_the_frame_limit_before_simulating(tmp_path, monkeypatch, capsys):
    """`simulate --html` is bounded as `render` is: refused from the scene's duration, no run made."""
    scene = REPO / "scenes" / "damped_double_pendulum.toml"
    monkeypatch.setenv(MAX_FRAMES_VARIABLE, "10")
    npz = tmp_path / "run.npz"
    code = main(["simulate", str(scene), "-o", str(npz), "--html", str(tmp_path / "x.html")])
    assert code == 2
    line = error_line(capsys)
    assert "time.duration" in line and "limit of 10" in line
    assert not npz.exists() and not (tmp_path / "x.html").exists()
