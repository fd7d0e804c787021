"""A newcomer's first hour: each message names the user's file in the user's terms and the next step.

A missing, unreadable or wrong-kind file gets its own sentence; a file given to ``check`` without
its option is told the option; ``pendverify`` alone lists the commands; the help lists them in a
newcomer's order and reads the defaults of negative flags the right way round; a TOML model without
``[urdf]`` is told to add that table.
"""

from __future__ import annotations

import argparse
import shutil
from pathlib import Path

import pytest

from pendverify.cli import COMMAND_ORDER, build_parser, command_modules, main
from pendverify.documents import file_kind
from pendverify.errors import COPY_EXAMPLES
from pendverify.file_kinds import toml_kind
from pendverify.shipped import shipped_file
from tests.cli_parsers import subcommands

CART_POLE = {suffix: shipped_file("examples", f"cart_pole{suffix}") for suffix in (".py", ".urdf", ".toml")}
LATEX_MODEL = shipped_file("examples", "cart_pole_latex.toml")


def error(capsys) -> str:
    """The one error line a failed command printed."""
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("pendverify: error: "), err
    return err.removeprefix("pendverify: error: ").rstrip("\n")


# --- missing, unreadable, wrong-kind files ---------------------------------------------------------
@pytest.mark.parametrize(
    ("argv", "what"),
    [
        (["check", "--params", "examples/x.toml"], "parameter file"),
        (["check", "--analytic", "examples/x.toml", "--urdf", "x.urdf"], "model file"),
        (["check", "--model", "double_pendulum", "--urdf", "examples/x.urdf"], "robot description"),
        (["simulate", "examples/x.toml"], "scene file"),
        (["show", "examples/x.py"], "model file"),
    ],
)
def test_a_missing_file_is_named_with_the_folder_it_was_looked_for_in(
    argv, what, tmp_path, monkeypatch, capsys
):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    name = next(a for a in argv if a.startswith("examples/"))
    assert (
        error(capsys) == f"{what} not found: {name} (relative to {tmp_path}); check the path; {COPY_EXAMPLES}"
    )


def test_an_absolute_missing_path_says_no_folder(tmp_path, capsys):
    assert main(["check", "--params", str(tmp_path / "x.toml")]) == 2
    assert error(capsys).startswith(f"parameter file not found: {tmp_path / 'x.toml'}; check the path")


def test_an_unreadable_file_and_a_folder_each_get_their_sentence(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    inside_a_file = tmp_path / "file" / "p.toml"  # the OS refuses it: a file is not a folder
    assert main(["check", "--params", str(inside_a_file)]) == 2
    assert error(capsys) == (
        f"cannot read the parameter file (Not a directory): {inside_a_file}; make it readable "
        "(ls -l shows its permissions) or give a copy you can read"
    )
    assert main(["simulate", str(tmp_path)]) == 2
    assert error(capsys) == f"a folder, not a scene file: {tmp_path}; give the scene file inside it"


@pytest.mark.parametrize(
    ("argv", "given", "expected", "found", "step"),
    [
        (
            ["check", "--params", CART_POLE[".py"]],
            CART_POLE[".py"],
            "parameter file",
            "model file",
            "--analytic",
        ),
        (["check", "--params", LATEX_MODEL], LATEX_MODEL, "parameter file", "model file", "--analytic FILE"),
        (
            ["simulate", CART_POLE[".toml"]],
            CART_POLE[".toml"],
            "scene file",
            "parameter file",
            "--params FILE",
        ),
        (
            ["check", "--analytic", CART_POLE[".urdf"], "--urdf", CART_POLE[".urdf"]],
            CART_POLE[".urdf"],
            "model file",
            "robot description",
            "--urdf FILE",
        ),
        (
            ["check", "--analytic", CART_POLE[".toml"], "--urdf", CART_POLE[".urdf"]],
            CART_POLE[".toml"],
            "model file",
            "parameter file",
            "--params FILE",
        ),
    ],
)
def test_a_file_of_another_kind_is_told_what_it_is_and_where_it_goes(
    argv, given, expected, found, step, capsys
):
    assert main([str(a) for a in argv]) == 2
    text = error(capsys)
    assert text.startswith(f"not a {expected} but a {found}: {given}; "), text
    assert step in text


def test_a_file_whose_keys_tell_no_kind_is_left_to_its_reader(tmp_path, capsys):
    odd = tmp_path / "odd.toml"
    odd.write_text('colour = "red"\n')
    assert toml_kind({"colour": "red"}) is None and file_kind(odd) is None
    assert main(["check", "--params", str(odd)]) == 2
    assert (
        error(capsys)
        == f"{odd}: key 'colour' = 'red': unknown key; a parameter file has model, name, parameters"
    )


def test_the_kinds_of_the_shipped_files():
    assert file_kind(CART_POLE[".py"]) == "model" and file_kind(LATEX_MODEL) == "model"
    assert file_kind(CART_POLE[".urdf"]) == "description" and file_kind(CART_POLE[".toml"]) == "params"
    assert file_kind(shipped_file("scenes", "cart_pole_lqr_push.toml")) == "scene"
    assert file_kind(shipped_file("sweeps", "double_pendulum_200.toml")) == "sweep"
    assert file_kind(shipped_file("examples", "double_pendulum.mjcf.xml")) == "description"


# --- a TOML model without [urdf] --------------------------------------------------------------------
def test_a_text_model_without_urdf_is_told_to_add_the_table(tmp_path, capsys):
    text = LATEX_MODEL.read_text(encoding="utf-8")
    model = tmp_path / "mine.toml"
    model.write_text(text[: text.index("[urdf]")], encoding="utf-8")
    argv = [
        "check",
        "--analytic",
        str(model),
        "--urdf",
        str(CART_POLE[".urdf"]),
        "--params",
        str(CART_POLE[".toml"]),
    ]
    assert main(argv) == 2
    message = error(capsys)
    assert message.startswith(f"{model}: model cart_pole does not say which URDF joint each coordinate is: ")
    assert 'add a [urdf] table with joints = ["<URDF joint of x>", "<URDF joint of theta>"]' in message
    for internal in ("urdf_joints", "plug-in", "CartPole", "declares"):
        assert internal not in message, internal
    model.write_text(text, encoding="utf-8")  # the table back: it runs
    assert main([*argv, "--samples", "5", "--quiet"]) == 0


def test_a_declaration_without_urdf_is_told_in_its_own_terms():
    import pendverify

    declaration = {
        "name": "point",
        "dynamics": "qddot(q, v, u)",
        "coordinates": {"x": "position", "theta": "angle"},
        "parameters": {"m": {"kind": "mass"}, "g": {"kind": "gravity"}},
        "inputs": ["f"],
        "B": [["1"], ["0"]],
    }

    def qddot(q, v, u, m, g):
        return [u[0] / m, -g * q[1]]

    with pytest.raises(
        pendverify.PendverifyError, match=r'add "urdf": \{"joints": \["<URDF joint of x>", "<URDF joint of'
    ):
        pendverify.check(qddot, CART_POLE[".urdf"], {"m": 1.0, "g": 9.81}, declaration=declaration)


# --- check FILE -------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("files", "suggestion"),
    [
        (["my.py"], "`pendverify check --analytic my.py`"),
        (["arm.urdf"], "`pendverify check --urdf arm.urdf`"),
        (["robot.xacro"], "`pendverify check --urdf robot.xacro`"),
        ([str(LATEX_MODEL)], f"`pendverify check --analytic {LATEX_MODEL}`"),
        (
            [str(CART_POLE[".py"]), str(CART_POLE[".urdf"]), str(CART_POLE[".toml"])],
            f"`pendverify check --analytic {CART_POLE['.py']} --urdf {CART_POLE['.urdf']} "
            f"--params {CART_POLE['.toml']}`",
        ),
    ],
)
def test_check_with_a_bare_file_suggests_the_option(files, suggestion, capsys):
    assert main(["check", *files]) == 2
    assert (
        error(capsys)
        == f"check takes its files by option, not as {', '.join(files)}: did you mean {suggestion}?"
    )


def test_check_with_a_bare_file_of_no_known_kind_lists_the_options(capsys):
    assert main(["check", "notes.txt"]) == 2
    options = "--analytic (a model file: .py or a text model), --urdf (a robot description), --params"
    assert error(capsys).endswith(f"{options} (a parameter file)")


# --- the command list -------------------------------------------------------------------------------
def test_pendverify_alone_lists_the_commands_and_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as stop:
        main([])
    assert stop.value.code == 2
    err = capsys.readouterr().err
    for name in ("check", "show", "example", "simulate", "certify", "bench"):
        assert f"\n    {name} " in err, name
    assert err.rstrip().endswith("error: give a command (`pendverify COMMAND --help`: what it takes)")


def test_the_commands_come_in_a_newcomers_order(capsys):
    names = [names[0] for names, _ in subcommands(build_parser()) if len(names) == 1]
    assert names[:6] == ["check", "show", "example", "simulate", "render", "report"]
    assert names[-1] == "bench" and names.index("certify") < names.index("recheck") < names.index("keygen")
    assert set(COMMAND_ORDER) == set(command_modules()), "a command module missing from COMMAND_ORDER"


# --- help ---------------------------------------------------------------------------------------------
def test_a_negative_flags_default_is_off(capsys, monkeypatch):
    """``--no-X`` is not given by default: its help says "off" (never the "on" of what it stores)."""
    monkeypatch.setenv("COLUMNS", "200")
    found = 0
    for names, parser in subcommands(build_parser()):
        text = parser.format_help()
        for action in parser._actions:
            if isinstance(action, argparse._StoreFalseAction):
                found += 1
                line = next(
                    line for line in text.splitlines() if line.strip().startswith(action.option_strings[0])
                )
                assert "(default: off" in line, (names, line)
                assert "(default: on" not in line, (names, line)
    assert found >= 3  # check --no-erd, --no-explain; report --no-erd


def test_check_help_names_every_kind_of_model_file(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "300")
    parser = dict(subcommands(build_parser()))[("check",)]
    line = next(line for line in parser.format_help().splitlines() if line.strip().startswith("--analytic"))
    for kind in ("ClosedFormModel subclass", "SymPy mechanics", "dynamics as code", "text model", "LaTeX"):
        assert kind in line, kind


# --- the review page, a folder of scenes with a model file beside them ---------------------------------
SCENE = """name = "short swing"
model = "double_pendulum"
[initial]
q = [0.3, 0.2]
v = [0.0, 0.0]
[time]
duration = 0.2
sample_rate = 50.0
[integrator]
method = "DOP853"
rtol = 1e-9
atol = 1e-9
[effects]
gravity = true
"""


def test_report_skips_a_non_scene_toml_and_shows_no_absolute_path(tmp_path, capsys):
    scenes = tmp_path / "my-scenes"
    scenes.mkdir()
    (scenes / "swing.toml").write_text(SCENE)
    shutil.copy(CART_POLE[".toml"], scenes / "cart_pole.toml")  # a parameter file beside the scene
    shutil.copy(LATEX_MODEL, scenes / "model.toml")  # and a text model
    out = tmp_path / "review"
    argv = ["report", "-o", str(out), "--scenes", str(scenes), "--samples", "5", "--no-erd"]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "note: skipped cart_pole.toml: a parameter file, not a scene" in printed
    assert "note: skipped model.toml: a model file, not a scene" in printed
    page = (out / "index.html").read_text(encoding="utf-8")
    assert "swing.toml" in page and str(tmp_path) not in page and str(Path.cwd()) not in page
    assert main(["report", "-o", str(out), "--scenes", str(tmp_path / "none"), "--force"]) == 2
    assert error(capsys).startswith(f"folder of scenes not found: {tmp_path / 'none'}; check the path")
    (scenes / "broken.toml").write_text('model = "double_pendulum"\nspeed = 3\n')  # no kind: read, refused
    assert main([*argv, "--force"]) == 2
    assert "broken.toml" in error(capsys)
