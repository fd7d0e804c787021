"""Command lines of the conformance matrix: each command of ``matrix.COMMANDS`` for one cell's files.

``Files`` writes a cell's model, parameter file, robot description and scene into a folder (file
names fixed by system, format and description: pendverify's code cache keys on names and
contents, so a model compiled for one command is reused by the next).  ``command_lines`` gives
the argument lists of ``pendverify.cli.main`` a command takes; ``run`` calls ``main`` in-process
and returns (exit status, stdout + stderr), an exception escaping ``main`` being status
``"raised"`` with its type (never acceptable: every outcome is an exit status).
"""

from __future__ import annotations

import importlib.util
import traceback
from pathlib import Path

from pendverify.cli import main
from tests.conformance.formats import Model, write_model, write_parameters
from tests.conformance.systems import SYSTEMS, System, write_description
from tests.hard_limit import Hang, hard_limit

#: the initial coordinates of every scene: small angles and offsets, the i-th alternating in sign
INITIAL = (0.2, -0.15, 0.1, -0.05, 0.05)


class Files:
    """One cell's files in ``folder``."""

    def __init__(self, folder: Path, system: System, format_name: str, description: str, model: Model):
        self.folder, self.system = folder, system
        self.robot = write_description(system, description, folder)
        self.params = write_parameters(model, folder)
        self.model = write_model(model, format_name, folder) if format_name != "-" else None

    def export_language(self) -> list[str]:
        """The language options ``export`` writes this cell's model with: c, matlab, numpy and casadi
        (where the package is installed: the test extra has it) in turn over the model files' names
        (stable: the same cell always exports the same language)."""
        langs = [["--lang", "c"], ["--lang", "matlab"], ["--lang", "numpy"]]
        langs += [["--casadi"]] if importlib.util.find_spec("casadi") is not None else []
        return langs[sum(map(ord, self.model.name)) % len(langs)]

    def analytic(self) -> list[str]:
        return ["--analytic", str(self.model), "--urdf", str(self.robot), "--params", str(self.params)]

    def scene(self) -> Path:
        folder = self.folder / "scenes"
        folder.mkdir(exist_ok=True)
        path = folder / f"{self.model.stem}.toml"
        q = list(INITIAL[: self.system.dof])
        path.write_text(
            f'name = "{self.system.name} conformance"\nmodel = "{self.model}"\nparams = "{self.params}"\n'
            f'urdf = "{self.robot}"\nengine = "both"\n[initial]\nq = {q}\n'
            "[time]\nduration = 0.3\nsample_rate = 20.0\n"
            '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
            f"[effects]\ngravity = true\ndamping = {'true' if self.system.damping else 'false'}\n"
        )
        return path


def _certify(files: Files, keys: Path) -> list[list[str]]:
    out = files.folder / "certificates"
    certify = [
        "certify",
        *files.analytic(),
        "-o",
        str(out),
        "--samples",
        "30",
        "--key",
        str(keys / "pendverify-signing.key.pem"),
    ]
    recheck = ["recheck", str(out / f"{files.robot.name.split('.')[0]}.cert.json")]
    recheck += ["--trust", str(keys / "pendverify-signing.pub.pem")]
    return [certify, recheck]


def _export(files: Files, out: Path) -> list[list[str]]:
    """``export`` of the cell's model: without a robot (the code written, unverified), then checked
    against the cell's description (replacing the files), in the cell's language."""
    head = ["export", str(files.model), *files.export_language(), "-o", str(out)]
    return [head, [*head, "--force", "--urdf", str(files.robot), "--params", str(files.params)]]


def command_lines(command: str, files: Files, keys: Path) -> list[list[str]]:
    """The ``main`` argument lists ``command`` runs on ``files`` (all must give the cell's status)."""
    tmp = files.folder
    table = {
        "check": lambda: [["check", *files.analytic(), "--samples", "20"]],
        "check planted": lambda: [["check", *files.analytic(), "--samples", "20"]],
        "show": lambda: [["show", str(files.model)]],
        "show --robot": lambda: [["show", "--robot", str(files.robot)]],
        "sympy": lambda: [["sympy", "--analytic", str(files.model)]],
        # gravity's mutants: H has the fewest terms (M's of the 5-link chain run past CELL_LIMIT)
        "mutate": lambda: [["mutate", *files.analytic(), "--samples", "10", "--method", "gravity"]],
        "simulate": lambda: [["simulate", str(files.scene())]],
        "render": lambda: [["render", str(files.scene()), "-o", str(tmp / "out.html")]],
        "report": lambda: [
            [
                "report",
                "-o",
                str(tmp / "review"),
                "--scenes",
                str(files.scene().parent),
                "--samples",
                "20",
                "--no-erd",
            ]
        ],
        "certify+recheck": lambda: _certify(files, keys),
        "stress": lambda: [["stress", *files.analytic(), "--quick"]],
        "bench accuracy": lambda: [
            ["bench", "accuracy", "--scene", str(files.scene()), "--quick", "-o", str(tmp / "bench")]
        ],
        "export": lambda: _export(files, tmp / "code"),
    }
    return table[command]()


#: the most CPU time a command line may take [s] before its cell counts as hung (``tests.hard_limit``):
#: the slowest passing cell measured took about 36 s alone on a 2-core machine (a first compilation of
#: a model's generated code plus the command), so 5 minutes is a hang or unbounded work, whatever the
#: load on the machine
CELL_LIMIT = 300


def run(argv: list[str], capsys) -> tuple[int | str, str]:
    """``main(argv)`` in-process, its output captured by pytest's ``capsys`` (the way
    tests/commands do it): (exit status, "raised" or "timeout", what it printed)."""
    capsys.readouterr()
    trace = ""
    try:
        with hard_limit(CELL_LIMIT) as limit:
            status: int | str = main(argv)
    except SystemExit as exit_:  # argparse's usage errors
        status = exit_.code if isinstance(exit_.code, int) else 2
    except Hang:
        status = "timeout"
    except Exception:  # a traceback out of main: a failed cell, kept with its text
        status, trace = "raised", traceback.format_exc()
    if limit.fired:  # also where a command caught the Hang (a model's exception is bad input to it)
        status, trace = "timeout", limit.describe()
    captured = capsys.readouterr()
    return status, captured.out + captured.err + trace


__all__ = ["SYSTEMS", "Files", "command_lines", "run"]
