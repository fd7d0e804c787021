"""``pendverify example``: the list, each example copied and checked as the printed commands say, refusals."""

from __future__ import annotations

import shlex
from pathlib import Path

import pinocchio as pin
import pytest

from pendverify.cli import main
from pendverify.shipped import shipped_folder
from pendverify.simulation.scene import load_scene
from pendverify.worked_examples import EXAMPLES, NAMES, find_example, scene_for_folder

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
        assert all(f.name in row for f in example.files), row


def test_a_name_alone_shows_what_the_example_holds(capsys):
    assert main(["example", "furuta_pendulum"]) == 0
    out = capsys.readouterr().out
    for f in find_example("furuta_pendulum").files:
        assert f.name in out
    assert "pendverify example furuta_pendulum DIR" in out


@pytest.mark.parametrize("name", NAMES)
def test_a_copied_example_runs_as_the_printed_commands_say(name, tmp_path, capsys):
    example = find_example(name)
    folder = tmp_path / "copy"
    assert main(["example", name, str(folder)]) == 0
    out = capsys.readouterr().out
    assert sorted(p.name for p in folder.iterdir()) == sorted(f.name for f in example.files)
    for f in example.files:
        if f is not example.scene:
            assert (folder / f.name).read_bytes() == f.source.read_bytes(), f.name
    assert "../" not in (folder / example.scene.name).read_text(encoding="utf-8")

    robot = pin.buildModelFromUrdf(str(folder / example.urdf.name))
    assert robot.nv == example.dof

    checks = printed_commands(out, "check")
    assert len(checks) == len(example.models) + len(example.descriptions)
    for args in checks:
        assert main([*args, "--samples", "5", "--no-erd", "--quiet"]) == 0, args
        capsys.readouterr()
    [simulate] = printed_commands(out, "simulate")
    scene = load_scene(simulate[1])
    assert len(scene.q0) == example.dof
    for used in (scene.model_file, scene.urdf):  # a plug-in scene runs on the copies
        if used is not None:
            assert Path(used).resolve().parent == folder.resolve(), used


def test_the_copied_scene_simulates_with_the_copied_model(tmp_path, capsys):
    assert main(["example", "cart_pole", str(tmp_path)]) == 0
    assert main(["simulate", str(tmp_path / "cart_pole_lqr_push.toml")]) == 0
    assert "all invariants hold" in capsys.readouterr().out


def test_a_scene_path_to_a_file_not_copied_is_a_catalogue_error():
    text = 'model = "../examples/cart_pole.py"\nurdf = "../urdf/other.urdf"\n'
    local = scene_for_folder(text, {"cart_pole.py", "other.urdf"})
    assert local == 'model = "cart_pole.py"\nurdf = "other.urdf"\n'
    with pytest.raises(ValueError, match=r"other\.urdf"):
        scene_for_folder(text, {"cart_pole.py"})


def test_an_unknown_name_is_one_line_listing_the_known_ones(tmp_path, capsys):
    assert main(["example", "cart_pol", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "unknown example 'cart_pol'" in err
    assert all(name in err for name in NAMES)
    assert list(tmp_path.iterdir()) == []


def test_an_existing_file_is_refused_and_nothing_is_written(tmp_path, capsys):
    (tmp_path / "cart_pole.toml").write_text("mine\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "cart_pole.toml" in err and "--force" in err
    assert [p.name for p in tmp_path.iterdir()] == ["cart_pole.toml"]
    assert (tmp_path / "cart_pole.toml").read_text(encoding="utf-8") == "mine\n"


def test_force_replaces_the_existing_files(tmp_path, capsys):
    (tmp_path / "cart_pole.toml").write_text("mine\n", encoding="utf-8")
    (tmp_path / "notes.txt").write_text("kept\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(tmp_path), "--force"]) == 0
    example = find_example("cart_pole")
    assert (tmp_path / "cart_pole.toml").read_bytes() == example.params.source.read_bytes()
    assert (tmp_path / "notes.txt").read_text(encoding="utf-8") == "kept\n"


def test_a_folder_in_the_place_of_a_file_is_refused_even_with_force(tmp_path, capsys):
    (tmp_path / "cart_pole.urdf").mkdir()
    assert main(["example", "cart_pole", str(tmp_path), "--force"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cart_pole.urdf" in err
    assert [p.name for p in tmp_path.iterdir()] == ["cart_pole.urdf"]


def test_a_folder_holding_other_files_is_accepted(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("kept\n", encoding="utf-8")
    assert main(["example", "triple_pendulum", str(tmp_path)]) == 0
    assert (tmp_path / "triple_pendulum.py").is_file()


def test_a_file_in_place_of_the_folder_is_refused(tmp_path, capsys):
    target = tmp_path / "taken"
    target.write_text("x\n", encoding="utf-8")
    assert main(["example", "cart_pole", str(target)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "taken" in err and "not a folder" in err
    assert target.read_text(encoding="utf-8") == "x\n"


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
            assert load_sweep(folder / sweep.name).model.name == example.name
        [certify] = printed_commands(out, "certify")
        first = folder / example.sweeps[0].name
        assert certify[:3] == ["certify", "--sweep", str(first)]
    first = tmp_path / "double_pendulum" / "double_pendulum_200.toml"
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
    latex = tmp_path / "cart_pole_latex.toml"
    text = latex.read_text(encoding="utf-8")
    right = r"-m_p r\sin(\theta)\dot{\theta}"
    assert text.count(right) == 1
    latex.write_text(text.replace(right, right[1:]), encoding="utf-8")
    files = ["--urdf", str(tmp_path / "cart_pole.urdf"), "--params", str(tmp_path / "cart_pole.toml")]
    assert main(["check", "--analytic", str(latex), *files, "--samples", "5", "--no-erd", "--quiet"]) == 1
