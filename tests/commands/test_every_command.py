"""Every command on every shipped example model, and on a model written in this test.

The issue's promise is that a user's model file reaches every command.  Each row of
``COMMANDS`` builds one command line for a model file (with its URDF and parameter
file); each is run on each example of ``examples/`` that has a URDF and on a model
written here (the cart-pole's formulas in a file of its own), and must exit 0.  Each
command's power to fail on a planted error is tested where the command is (analytic/test_plugin,
simulation/test_scene_model_files, viz/test_review_folder, certify/test_certify,
stress/test_stress_generic, ...); here one planted mass-matrix error must fail ``check``
through the same rows.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from pendverify.certify.names import set_name
from pendverify.cli import main
from pendverify.robot.description import description_stem

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
#: an initial state per example for the scenes (the model's own coordinates)
STEMS = {
    "cart_pole": [0.0, 0.3],
    "hanging_double_pendulum": [0.8, -0.4],
    "triple_pendulum": [1.0, 0.4, -0.3],
    "furuta_pendulum": [0.2, 0.3],
    "minimal_double_pendulum": [0.4, 0.9],  # the text model's (examples/minimal_double_pendulum_text.toml)
    "cart_double_pendulum": [0.0, 0.3, -0.2],  # the LaTeX model's (examples/cart_double_pendulum_latex.toml)
}
TEXT_ONLY = ("minimal_double_pendulum", "cart_double_pendulum")


class Model:
    """A model file with its URDF and parameter file, and a short scene on it."""

    def __init__(
        self, model: Path, stem: str, tmp_path: Path, urdf: Path | None = None, params: Path | None = None
    ):
        self.model, self.stem, self.tmp = model, stem, tmp_path
        self.urdf, self.params = urdf or EXAMPLES / f"{stem}.urdf", params or EXAMPLES / f"{stem}.toml"

    def files(self) -> list[str]:
        return ["--analytic", str(self.model), "--urdf", str(self.urdf), "--params", str(self.params)]

    def scene(self) -> Path:
        folder = self.tmp / "scenes"
        folder.mkdir(exist_ok=True)
        path = folder / f"{self.stem}.toml"
        path.write_text(
            f'name = "{self.stem} swing"\nmodel = "{self.model}"\nparams = "{self.params}"\n'
            f'urdf = "{self.urdf}"\nengine = "both"\n[initial]\nq = {STEMS[self.stem]}\n'
            "[time]\nduration = 0.5\nsample_rate = 20.0\n"
            '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
            "[effects]\ngravity = true\ndamping = true\n"
        )
        return path


def _certify(m: Model) -> list[list[str]]:
    out = m.tmp / "certificates"
    name = set_name(m.stem, description_stem(m.urdf), "test")  # the model's name (its stem), the URDF's
    certify = ["certify", *m.files(), "-o", str(out), "--samples", "100"]
    trusted = ["--run-embedded-code"] if str(m.model).endswith(".py") else []  # a text model is data
    return [certify, ["recheck", str(out / f"{name}.cert.json"), *trusted]]


#: command → the command lines it takes to run it (each must exit 0)
COMMANDS = {
    "check": lambda m: [["check", *m.files(), "--samples", "50"]],
    "sympy": lambda m: [["sympy", "--analytic", str(m.model)]],
    "mutate": lambda m: [["mutate", *m.files(), "--samples", "10", "--method", "mass_matrix"]],
    "simulate": lambda m: [["simulate", str(m.scene())]],
    "render": lambda m: [["render", str(m.scene()), "-o", str(m.tmp / "out.html")]],
    "report": lambda m: [
        ["report", "-o", str(m.tmp / "review"), "--scenes", str(m.scene().parent), "--samples", "20"]
    ],
    "stress": lambda m: [["stress", *m.files(), "--quick"]],
    "certify+recheck": _certify,
    "bench": lambda m: [
        ["bench", "accuracy", "--scene", str(m.scene()), "--quick", "-o", str(m.tmp / "bench")]
    ],
}

#: the bench's accuracy study on a model's scene (≈ 10 to 35 s: its fixed-step methods compiled) and
#: certify+recheck (≈ 5 to 25 s: the battery) are slow, and most of that is compiling the model's
#: code: they run here on the model written in this test; on the shipped examples and the text
#: models the conformance matrix (tests/conformance: every system and format, the text and LaTeX
#: formats included, through these two commands) and the certificate tests (certify/test_certify:
#: every shipped example; analytic/test_text_model: the SymPy-syntax example) cover them
SLOW_COMMANDS = ("bench", "certify+recheck")
COMMAND_PARAMS = [pytest.param(c, marks=pytest.mark.slow) if c in SLOW_COMMANDS else c for c in COMMANDS]
FAST_COMMANDS = [c for c in COMMANDS if c not in SLOW_COMMANDS]

WRITTEN_HERE = '''"""The cart-pole, written again in a file of this test: a user's own model."""

from pendverify.analytic.plugin import load_model_class

Base = load_model_class({base!r})


class CartPoleOfMine(Base):
    """Same formulas, another class in another file."""
'''


def _written_here(tmp_path: Path) -> Path:
    path = tmp_path / "cart_pole_of_mine.py"
    path.write_text(WRITTEN_HERE.format(base=str(EXAMPLES / "cart_pole.py")))
    return path


@pytest.mark.parametrize("command", FAST_COMMANDS)
@pytest.mark.parametrize("stem", [s for s in STEMS if s not in TEXT_ONLY])
def test_each_command_on_each_example(command, stem, tmp_path, capsys):
    model = Model(EXAMPLES / f"{stem}.py", stem, tmp_path)
    for argv in COMMANDS[command](model):
        assert main(argv) == 0, (argv, capsys.readouterr())


@pytest.mark.parametrize("command", COMMAND_PARAMS)
def test_each_command_on_a_model_written_here(command, tmp_path, capsys):
    model = Model(_written_here(tmp_path), "cart_pole", tmp_path)
    for argv in COMMANDS[command](model):
        assert main(argv) == 0, (argv, capsys.readouterr())


#: the equations as text, no Python: (model file, stem of STEMS, URDF, parameter file)
TEXT_MODELS = {
    "sympy syntax": (
        "minimal_double_pendulum_text.toml",
        "minimal_double_pendulum",
        "double_pendulum.urdf",
        None,
    ),
    "seed 001 in LaTeX": (
        "cart_double_pendulum_latex.toml",
        "cart_double_pendulum",
        "cart_double_pendulum.urdf",
        EXAMPLES.parent / "analytic" / "params" / "cart_double_pendulum.toml",
    ),
}


@pytest.mark.parametrize("command", FAST_COMMANDS)
@pytest.mark.parametrize("kind", list(TEXT_MODELS))
def test_each_command_on_a_text_model(kind, command, tmp_path, capsys):
    """A model written as text (TOML, SymPy syntax or LaTeX): every command takes it too."""
    text, stem, urdf, params = TEXT_MODELS[kind]
    model = Model(EXAMPLES / text, stem, tmp_path, EXAMPLES.parent / "urdf" / urdf, params)
    for argv in COMMANDS[command](model):
        assert main(argv) == 0, (argv, capsys.readouterr())


def test_a_planted_error_in_the_model_written_here_fails_check(tmp_path, capsys):
    path = _written_here(tmp_path)
    path.write_text(
        path.read_text()
        + "\n    def mass_matrix(self, q):\n"
        + "        M = super().mass_matrix(q)\n"
        + "        M[0, 0] *= 1.001\n"
        + "        return M\n"
    )
    (argv,) = COMMANDS["check"](Model(path, "cart_pole", tmp_path))
    assert main(argv) == 1
