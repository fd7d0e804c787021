"""The command line's conventions: help, global options in any position, ``--json -``, ``--version``.

Every registered subcommand (nested ones too) is walked: its help must have a one-line
description, every option's default and examples that parse.  The global options
``--debug``, ``--quiet`` and ``--json`` are accepted before and after the command's name
and refused (status 2) by the commands that have no use for them; ``--json -`` leaves
nothing but the JSON on standard output.
"""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from pendverify.cli import build_parser, main, parse
from tests.cli_parsers import subcommands

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"


COMMANDS = [names for names, _ in subcommands(build_parser())]


def help_text(argv: list[str], capsys, monkeypatch) -> str:
    monkeypatch.setenv("COLUMNS", "100")
    with pytest.raises(SystemExit) as exit_:
        main([*argv, "--help"])
    assert exit_.value.code == 0
    return capsys.readouterr().out


def entries(text: str, section: str) -> list[str]:
    """The entries of a help section ("options", "positional arguments"), each on one line."""
    lines = text.split(f"\n{section}:\n", 1)[1].split("\n\n", 1)[0].splitlines()
    out: list[str] = []
    for line in lines:
        if re.match(r"^  \S", line):
            out.append(line.strip())
        else:
            out[-1] += " " + line.strip()
    return out


def test_the_walk_finds_every_command_and_the_nested_ones():
    assert {"check", "certify", "recheck", "simulate", "bench", "keygen", "show"} <= {n[0] for n in COMMANDS}
    assert ("bench", "accuracy") in COMMANDS and ("bench", "certify") in COMMANDS


@pytest.mark.parametrize("names", COMMANDS, ids=" ".join)
def test_every_command_help_has_a_description_each_default_and_examples(names, capsys, monkeypatch):
    parser = dict(subcommands(build_parser()))[names]
    text = help_text(list(names), capsys, monkeypatch)
    summary = parser.description.splitlines()[0]
    assert summary.strip() and len(summary) <= 100, summary
    assert f"\n{summary}\n" in text  # the one-line description, printed as one line
    options = entries(text, "options")
    assert any(e.startswith("--debug ") for e in options), f"{' '.join(names)}: no --debug (use add_command)"
    for entry in options:
        if not entry.startswith("-h, --help"):
            assert "(default" in entry or "default:" in entry, f"{' '.join(names)}: no default in {entry!r}"
    optional_positionals = [a.dest for a in parser._actions if not a.option_strings and a.nargs == "?"]
    for entry in entries(text, "positional arguments") if optional_positionals else ():
        if entry.split()[0] in optional_positionals:
            assert "default" in entry, entry
    examples = text.split("\nexamples:\n", 1)[1].split("\n\n", 1)[0].splitlines()
    assert examples, f"{' '.join(names)}: no example"
    for example in examples:
        line = re.split(r" [|>] |\s{2,}", example.strip())[0]  # not a pipe, redirection or comment
        argv = shlex.split(line)
        assert argv[0] == "pendverify" and argv[1 : 1 + len(names)] == list(names), example
        args = parse(argv[1:])  # every example is a valid command line
        assert callable(args.func)


def test_the_top_level_help_has_examples_and_the_exit_statuses(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    with pytest.raises(SystemExit):
        main(["--help"])
    text = capsys.readouterr().out
    for example in text.split("\nexamples:\n", 1)[1].split("\n\n", 1)[0].splitlines():
        parse(shlex.split(re.split(r" [|>] ", example.strip())[0])[1:])
    assert "exit status: 0 passed, 1 a verification failed, 2 bad input or usage" in text


def test_user_facing_help_names_no_seed_documents(capsys, monkeypatch):
    for names in [(), *COMMANDS]:
        text = help_text(list(names), capsys, monkeypatch)
        for banned in ("seed 000", "seed 001", "seeds'", "seed's", "../shared"):
            assert banned not in text, f"{' '.join(names)}: {banned!r}"


def test_defaults_in_the_help_are_the_library_constants(capsys, monkeypatch):
    from pendverify.certify.battery import BatterySettings
    from pendverify.checks.sampling import DEFAULT_RANDOM_STATES, DEFAULT_SEED
    from pendverify.robot.geometry import MODEL_FORM_RTOL
    from pendverify.stress.framework import SEED
    from pendverify.symbolic.mutate import DEFAULT_MUTATION_STATES

    def option(names, flag):
        text = help_text(names, capsys, monkeypatch)
        return next(e for e in entries(text, "options") if e.startswith(flag + " "))

    settings = BatterySettings()
    expected = {
        (("check",), "--samples"): DEFAULT_RANDOM_STATES,
        (("check",), "--seed"): DEFAULT_SEED,
        (("check",), "--model-form-rtol"): MODEL_FORM_RTOL,
        (("report",), "--samples"): DEFAULT_RANDOM_STATES,
        (("report",), "--seed"): DEFAULT_SEED,
        (("mutate",), "--samples"): DEFAULT_MUTATION_STATES,
        (("mutate",), "--seed"): DEFAULT_SEED,
        (("stress",), "--seed"): SEED,
        (("certify",), "--samples"): settings.samples,
        (("certify",), "--seed"): settings.seed,
    }
    for (names, flag), value in expected.items():
        shown = re.search(r"\(default:? ([^);]+)", option(list(names), flag))
        assert shown and float(shown[1].replace(",", "")) == float(value), (names, flag, value)


# --- the global options -----------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["--debug", "--quiet", "--json", "r.json", "check"],
        ["check", "--debug", "--quiet", "--json", "r.json"],
        ["--debug", "check", "--json", "r.json", "--quiet"],
        ["--quiet", "check", "--model", "double_pendulum", "--debug", "--json=r.json"],
    ],
)
def test_global_options_in_any_position(argv):
    args = parse(argv)
    assert (args.debug, args.quiet, args.json) == (True, True, "r.json")


def test_global_options_default_off():
    args = parse(["check"])
    assert (args.debug, args.quiet, args.json) == (False, False, None)


def test_nested_commands_take_the_global_options_at_every_level():
    for argv in (
        ["--debug", "bench", "certify", "--json", "-"],
        ["bench", "--debug", "certify", "--json", "-"],
        ["bench", "certify", "--debug", "--json", "-"],
    ):
        args = parse(argv)
        assert args.debug and args.json == "-" and args.benchmark == "certify"


@pytest.mark.parametrize(
    "argv, message",
    [
        (
            ["--json", "x.json", "show", "m.py"],
            "--json: `pendverify show` writes no report; it takes --debug",
        ),
        (["--quiet", "show", "m.py"], "--quiet: `pendverify show` has no verdict line to keep"),
        (["--json", "x.json", "keygen", "-o", "k"], "--json: `pendverify keygen` writes no report"),
        (["--json", "-", "bench", "accuracy"], "--json: `pendverify bench accuracy` writes no report"),
        # after the command's name: the same sentence as before it
        (["show", "m.py", "--json", "x.json"], "--json: `pendverify show` writes no report"),
        (["example", "--quiet"], "--quiet: `pendverify example` has no verdict line to keep"),
        (["bench", "accuracy", "--json", "-"], "--json: `pendverify bench accuracy` writes no report"),
    ],
)
def test_a_global_option_a_command_does_not_take_is_a_usage_error(argv, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(argv)
    assert exit_.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith(f"pendverify: error: {message}")


def test_debug_after_the_command_prints_the_traceback(monkeypatch, capsys):
    from pendverify.commands import check as check_command

    def broken(args):
        raise RuntimeError("an invariant of the code")

    monkeypatch.setattr(check_command, "run", broken)
    assert main(["check", "--debug"]) == 3
    err = capsys.readouterr().err
    assert "Traceback (most recent call last)" in err
    assert err.splitlines()[-1].startswith("pendverify: internal error: RuntimeError")
    assert main(["check"]) == 3
    assert "Traceback" not in capsys.readouterr().err


# --- --quiet and --json - ---------------------------------------------------------------------

CHECK = ["check", "--model", "double_pendulum", "--no-erd", "--samples", "20"]


def test_json_dash_writes_only_the_json_on_stdout(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([*CHECK, "--json", "-"]) == 0
    out, err = capsys.readouterr()
    report = json.loads(out)  # the whole of stdout is the document
    assert report["passed"] is True and report["results"]
    assert len(err.splitlines()) > 3 and err.rstrip().endswith("all checks pass")  # the table, on stderr
    assert not (tmp_path / "-").exists(), "a file named '-' was written"
    assert list(tmp_path.iterdir()) == []


def test_json_dash_with_quiet_leaves_the_verdict_line_on_stderr(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["--quiet", *CHECK, "--json", "-"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["passed"] is True
    assert len(err.splitlines()) == 1 and err.rstrip().endswith("all checks pass")


def test_quiet_prints_only_the_verdict_line_and_the_json_file_is_still_written(tmp_path, capsys):
    path = tmp_path / "r.json"
    assert main([*CHECK, "--quiet", "--json", str(path)]) == 0
    out = capsys.readouterr().out
    assert out.splitlines() == [out.strip()] and out.rstrip().endswith("all checks pass")
    assert json.loads(path.read_text())["passed"] is True


def test_without_quiet_the_json_file_is_named(tmp_path, capsys):
    path = tmp_path / "r.json"
    assert main([*CHECK, "--json", str(path)]) == 0
    assert capsys.readouterr().out.splitlines()[-1] == f"report written to {path}"


def short_scene(tmp_path: Path) -> Path:
    path = tmp_path / "swing.toml"
    path.write_text(
        'name = "short swing"\nmodel = "double_pendulum"\nengine = "both"\n[initial]\nq = [0.4, 0.9]\n'
        "[time]\nduration = 0.5\nsample_rate = 20.0\n"
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
        "[effects]\ngravity = true\ndamping = true\n"
    )
    return path


def test_simulate_json_dash_and_quiet(tmp_path, capsys):
    scene = short_scene(tmp_path)
    assert main(["simulate", str(scene), "--json", "-", "--quiet"]) == 0
    out, err = capsys.readouterr()
    document = json.loads(out)
    assert document["scene"] == "short swing" and document["passed"] is True
    assert {i["name"] for i in document["invariants"]} and document["engine_comparison"]["passed"] is True
    assert err.splitlines() == ["all invariants hold"]


def test_simulate_quiet_prints_only_the_verdict(tmp_path, capsys):
    scene = short_scene(tmp_path)
    assert main(["simulate", str(scene), "--quiet"]) == 0
    assert capsys.readouterr().out.splitlines() == ["all invariants hold"]


def test_certify_and_recheck_json(tmp_path, capsys):
    params = REPO / "analytic" / "params" / "double_pendulum.toml"
    out = tmp_path / "certified"
    assert main(["certify", str(params), "-o", str(out), "--samples", "50", "--json", "-", "--quiet"]) == 0
    stdout, stderr = capsys.readouterr()
    issued = json.loads(stdout)
    assert issued["certified"] is True and Path(issued["certificate"]).is_file()
    assert issued["items"] and all(i["passed"] for i in issued["items"])
    assert stderr.splitlines() == [stderr.strip()] and stderr.startswith("certified: ")
    report = tmp_path / "recheck.json"
    assert main(["recheck", issued["certificate"], "--json", str(report), "--quiet"]) == 0
    assert capsys.readouterr().out.startswith("recheck passed: ")
    rechecked = json.loads(report.read_text())
    assert rechecked["passed"] is True and rechecked["differences"] == []
    assert rechecked["digest"] == issued["digest"]
    assert [i["name"] for i in rechecked["items"]] == [i["name"] for i in issued["items"]]


def test_an_unwritable_json_path_is_refused_before_any_work(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main([*CHECK, "--json", str(blocker / "r.json")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.startswith("pendverify: error: ") and "is a file, not a folder" in err


# --- python -m pendverify and --version --------------------------------------------------------


def run_module(*argv: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "pendverify", *argv], capture_output=True, text=True, timeout=120
    )


def test_python_m_pendverify_version_names_pinocchio_and_python():
    import platform

    import pinocchio

    from pendverify import __version__

    done = run_module("--version")
    assert done.returncode == 0, done.stderr
    expected = (
        f"pendverify {__version__} (Pinocchio {pinocchio.__version__}, Python {platform.python_version()})"
    )
    assert done.stdout.strip() == expected


def test_python_m_pendverify_keeps_the_exit_status_contract():
    done = run_module("nonsense")
    assert done.returncode == 2 and "invalid choice: 'nonsense'" in done.stderr


def test_building_the_command_line_imports_neither_pinocchio_nor_sympy():
    code = (
        "import sys; import pendverify; from pendverify.cli import build_parser; build_parser(); "
        "print(sorted(m for m in ('pinocchio', 'sympy') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


TINY_SWEEP = """
model = "double_pendulum"
mode = "random"
count = 2
seed = 3
samples = 20
duration = 0.3
[ranges]
m1 = [0.5, 2.0]
"""


def test_certify_sweep_json_dash_is_the_summary(tmp_path, capsys):
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(TINY_SWEEP)
    out = tmp_path / "certified"
    argv = ["certify", "--sweep", str(sweep), "-o", str(out), "--workers", "1", "--json", "-", "--quiet"]
    assert main(argv) == 0
    stdout, stderr = capsys.readouterr()
    summary = json.loads(stdout)
    assert (summary["sets"], summary["passed"], summary["failed"], summary["written"]) == (2, 2, 0, 2)
    assert summary["certified"] is True and summary["worst_ratio"]
    assert all(0 <= w["ratio"] < 1 for w in summary["worst_ratio"].values())
    assert len(list(out.glob("*.cert.json"))) == 2
    assert stderr.splitlines()[-1] == f"2 certificate(s) written to {out}"


def test_keygen_quiet_prints_the_fingerprint_alone(tmp_path, capsys):
    assert main(["keygen", "-o", str(tmp_path / "keys"), "--quiet"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 1 and lines[0].startswith("fingerprint: ")
    assert len(list((tmp_path / "keys").iterdir())) == 2
