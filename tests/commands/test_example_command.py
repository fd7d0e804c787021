"""``pendverify example``: the list, each example laid out as the manual names its files and checked as the
printed commands say, files already there, refusals."""

from __future__ import annotations

import shlex
from pathlib import Path

import pinocchio as pin
import pytest

from pendverify.cli import main
from pendverify.shipped import shipped_folder
from pendverify.simulation.scene import load_scene
from pendverify.worked_examples import EXAMPLES, NAMES, find_example

REQUIRED = {
    "cart_pole",
    "furuta_pendulum",
    "triple_pendulum",
    "hanging_double_pendulum",
    "minimal_double_pendulum",
    "double_pendulum",
    "cart_double_pendulum",
}


def printed_commands(out: str, program: str) -> list[list[str]]:
    """The output's ``pendverify PROGRAM ...`` lines, as argument lists without ``pendverify``."""
    lines = [line.strip() for line in out.splitlines()]
    return [shlex.split(line)[1:] for line in lines if line.startswith(f"pendverify {program} ")]


def test_the_list_names_every_example_with_its_dof_and_files(capsys):
    assert main(["example"]) == 0
    out = capsys.readouterr().out
    assert REQUIRED <= set(NAMES)
    rows = {line.split()[0]: line for line in out.splitlines() if line.split() and line.split()[0] in NAMES}
    assert set(rows) == set(NAMES)
    for example in EXAMPLES:
        row = rows[example.name]
        assert f"{example.dof} dof" in row
        assert all(str(f.path) in row for f in example.files), row


def test_a_name_alone_shows_what_the_example_holds(capsys):
    assert main(["example", "furuta_pendulum"]) == 0
    out = capsys.readouterr().out
    for f in find_example("furuta_pendulum").files:
        assert str(f.path) in out
    assert "pendverify example furuta_pendulum DIR" in out


@pytest.mark.parametrize("name", NAMES)
def test_a_copied_example_runs_as_the_printed_commands_say(name, tmp_path, capsys):
    example = find_example(name)
    folder = tmp_path / "copy"
    assert main(["example", name, str(folder)]) == 0
    out = capsys.readouterr().out
    copied = sorted(str(p.relative_to(folder).as_posix()) for p in folder.rglob("*") if p.is_file())
    assert copied == sorted(str(f.path) for f in example.files)
    for f in example.files:
        assert (folder / f.path).read_bytes() == f.source.read_bytes(), f.path
        assert f"{folder / f.path}" in out, f.path

    robot = pin.buildModelFromUrdf(str(folder / example.urdf.path))
    assert robot.nv == example.dof

    checks = printed_commands(out, "check")
    assert len(checks) == len(example.models) + len(example.descriptions)
    for args in checks:
        assert main([*args, "--samples", "5", "--no-erd", "--quiet"]) == 0, args
        capsys.readouterr()
    [simulate] = printed_commands(out, "simulate")
    scene = load_scene(simulate[1])
    assert len(scene.q0) == example.dof
    copies = {(folder / f.path).resolve() for f in example.files}
    for used in (scene.model_file, scene.urdf):  # a plug-in scene runs on the copies
        if used is not None:
            assert Path(used).resolve() in copies, used


def test_the_copied_scene_simulates_with_the_copied_model(tmp_path, capsys):
    assert main(["example", "cart_pole", str(tmp_path)]) == 0
    assert main(["simulate", str(tmp_path / "scenes" / "cart_pole_lqr_push.toml")]) == 0
    assert "all invariants hold" in capsys.readouterr().out


def test_the_manual_s_paths_run_unchanged_in_the_folder(tmp_path, monkeypatch, capsys):
    """In the folder, ``--urdf urdf/double_pendulum.urdf --params examples/...`` as the manual prints it."""
    monkeypatch.chdir(tmp_path)
    assert main(["example", "minimal_double_pendulum", "."]) == 0
    out = capsys.readouterr().out
    manual = (
        "pendverify check --analytic examples/minimal_double_pendulum.py "
        "--urdf urdf/double_pendulum.urdf --params examples/minimal_double_pendulum.toml"
    )
    assert f"  {manual}" in out.splitlines()
    args = shlex.split(manual)[1:]
    assert main([*args, "--samples", "5", "--no-erd", "--quiet"]) == 0


def test_two_examples_share_a_folder_and_a_second_copy_changes_nothing(tmp_path, capsys):
    """``urdf/double_pendulum.urdf`` is in two examples: the second copy leaves it, and says so."""
    assert main(["example", "minimal_double_pendulum", str(tmp_path)]) == 0
    urdf = tmp_path / "urdf" / "double_pendulum.urdf"
    before = urdf.stat()
    capsys.readouterr()
    assert main(["example", "double_pendulum", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "already there" in next(line for line in out.splitlines() if str(urdf) in line)
    assert (urdf.stat().st_ino, urdf.stat().st_mtime_ns) == (before.st_ino, before.st_mtime_ns)
    assert main(["example", "double_pendulum", str(tmp_path)]) == 0
    assert capsys.readouterr().out.count("already there") == len(find_example("double_pendulum").files)


def test_an_unknown_name_is_one_line_listing_the_known_ones(tmp_path, capsys):
    assert main(["example", "cart_pol", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "unknown example 'cart_pol'" in err
    assert all(name in err for name in NAMES)
    assert list(tmp_path.iterdir()) == []


def all_files(folder: Path) -> list[str]:
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*"))


def test_an_existing_file_with_other_content_is_refused_and_nothing_is_written(tmp_path, capsys):
    (tmp_path / "examples").mkdir()
    (tmp_path / "examples" / "cart_pole.toml").write_text("mine\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "examples/cart_pole.toml" in err and "other content" in err and "--force" in err
    assert all_files(tmp_path) == ["examples", "examples/cart_pole.toml"]
    assert (tmp_path / "examples" / "cart_pole.toml").read_text(encoding="utf-8") == "mine\n"


def test_force_replaces_the_existing_files(tmp_path, capsys):
    (tmp_path / "examples").mkdir()
    (tmp_path / "examples" / "cart_pole.toml").write_text("mine\n", encoding="utf-8")
    (tmp_path / "notes.txt").write_text("kept\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(tmp_path), "--force"]) == 0
    example = find_example("cart_pole")
    assert (tmp_path / "examples" / "cart_pole.toml").read_bytes() == example.params.source.read_bytes()
    assert (tmp_path / "notes.txt").read_text(encoding="utf-8") == "kept\n"


def test_a_folder_in_the_place_of_a_file_is_refused_even_with_force(tmp_path, capsys):
    (tmp_path / "examples" / "cart_pole.urdf").mkdir(parents=True)
    assert main(["example", "cart_pole", str(tmp_path), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cart_pole.urdf" in err and "a folder, not a file" in err
    assert all_files(tmp_path) == ["examples", "examples/cart_pole.urdf"]


def test_a_file_in_the_place_of_a_subfolder_is_refused_even_with_force(tmp_path, capsys):
    (tmp_path / "scenes").write_text("mine\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(tmp_path), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "scenes is a file, not a folder" in err
    assert all_files(tmp_path) == ["scenes"]


def test_a_subfolder_linked_elsewhere_is_refused_and_nothing_is_written_there(tmp_path, capsys):
    """``DIR/urdf`` a link to another folder: writing through it would write outside DIR."""
    elsewhere, folder = tmp_path / "elsewhere", tmp_path / "copy"
    elsewhere.mkdir()
    folder.mkdir()
    (folder / "urdf").symlink_to(elsewhere, target_is_directory=True)
    assert main(["example", "minimal_double_pendulum", str(folder), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "symbolic link" in err and "only inside" in err
    assert list(elsewhere.iterdir()) == []
    assert all_files(folder) == ["urdf"]


def test_a_folder_holding_other_files_is_accepted(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("kept\n", encoding="utf-8")
    assert main(["example", "triple_pendulum", str(tmp_path)]) == 0
    assert (tmp_path / "examples" / "triple_pendulum.py").is_file()


def test_a_file_in_place_of_the_folder_is_refused(tmp_path, capsys):
    target = tmp_path / "taken"
    target.write_text("x\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(target)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "taken" in err and "not a folder" in err
    assert target.read_text(encoding="utf-8") == "x\n"


@pytest.mark.sweep
def test_the_reference_systems_sweeps_are_copied_and_the_printed_sweep_certifies(tmp_path, capsys):
    """Every copied sweep reads; the printed ``certify --sweep`` runs on the copy (its count cut to 2)."""
    from pendverify.certify.sweep import load_sweep

    with_sweeps = [e for e in EXAMPLES if e.sweeps]
    assert {"double_pendulum", "cart_double_pendulum"} <= {e.name for e in with_sweeps}
    for example in with_sweeps:
        folder = tmp_path / example.name
        assert main(["example", example.name, str(folder)]) == 0
        out = capsys.readouterr().out
        for sweep in example.sweeps:
            assert load_sweep(folder / sweep.path).model.name == example.name
        [certify] = printed_commands(out, "certify")
        first = folder / example.sweeps[0].path
        assert certify[:3] == ["certify", "--sweep", str(first)]
    first = tmp_path / "double_pendulum" / "sweeps" / "double_pendulum_200.toml"
    text = first.read_text(encoding="utf-8")
    assert text.count("count = 200") == 1
    first.write_text(text.replace("count = 200", "count = 2"), encoding="utf-8")
    args = ["certify", "--sweep", str(first), "--workers", "1", "-o", str(tmp_path / "certified"), "--quiet"]
    assert main(args) == 0
    assert len(list((tmp_path / "certified").glob("*.cert.json"))) == 2


def test_every_example_s_scene_is_a_shipped_scene():
    shipped = {p.name for p in shipped_folder("scenes").glob("*.toml")}
    assert {e.scene.name for e in EXAMPLES} <= shipped


def test_check_on_a_copy_fails_when_its_latex_is_wrong(tmp_path, capsys):
    """The copied files are what is checked: a sign flipped in the copied LaTeX C fails."""
    assert main(["example", "cart_pole", str(tmp_path)]) == 0
    latex = tmp_path / "examples" / "cart_pole_latex.toml"
    text = latex.read_text(encoding="utf-8")
    right = r"-m_p r\sin(\theta)\dot{\theta}"
    assert text.count(right) == 1
    latex.write_text(text.replace(right, right[1:]), encoding="utf-8")
    examples = tmp_path / "examples"
    files = ["--urdf", str(examples / "cart_pole.urdf"), "--params", str(examples / "cart_pole.toml")]
    assert main(["check", "--analytic", str(latex), *files, "--samples", "5", "--no-erd", "--quiet"]) == 1
