"""Bring your own model: a model file loaded by path, verified with the same table and JSON.

The shipped examples (``examples/``) and the two seed modules themselves go
through ``--analytic``; every malformed model file is a clear error (exit 2)
naming the file and the problem.
"""

from __future__ import annotations

import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic.plugin import load_model_class
from pendverify.checks.catalogue import CHECK_NAMES, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.errors import PendverifyError
from pendverify.targets import plugin_target

from ..conftest import SEED

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
HANGING = [
    "--analytic",
    str(EXAMPLES / "hanging_double_pendulum.py"),
    "--urdf",
    str(EXAMPLES / "hanging_double_pendulum.urdf"),
    "--params",
    str(EXAMPLES / "hanging_double_pendulum.toml"),
]
CART_POLE = [
    str(EXAMPLES / "cart_pole.py"),
    str(EXAMPLES / "cart_pole.urdf"),
    str(EXAMPLES / "cart_pole.toml"),
]


def test_example_model_file_is_verified_end_to_end(tmp_path, capsys):
    out_json = tmp_path / "report.json"
    assert main(["check", *HANGING, "--samples", "60", "--json", str(out_json)]) == 0
    out = capsys.readouterr().out
    assert "all checks pass" in out
    assert "coordinate map declared by HangingDoublePendulum" in out
    report = json.loads(out_json.read_text())
    assert report["passed"] is True
    assert {r["check"] for r in report["results"]} == {"units", *CHECK_NAMES}
    assert {r["model"] for r in report["results"]} == {"hanging_double_pendulum:hanging_double_pendulum"}
    for r in report["results"]:
        assert r["max_error"] <= r["tolerance"] < 1e-11, r  # eps-level, not a loose tolerance


@pytest.mark.parametrize("name", ["double_pendulum", "cart_double_pendulum"])
def test_seed_modules_load_through_the_same_path(capsys, name):
    argv = [
        "check",
        "--analytic",
        str(REPO / "analytic" / f"{name}.py"),
        "--urdf",
        str(REPO / "urdf" / f"{name}.urdf"),
        "--params",
        str(REPO / "analytic" / "params" / f"{name}.toml"),
        "--samples",
        "40",
    ]
    assert main(argv) == 0
    assert "all checks pass" in capsys.readouterr().out


def test_a_planted_error_in_a_model_file_fails(tmp_path, capsys):
    source = (EXAMPLES / "hanging_double_pendulum.py").read_text()
    wrong = source.replace(
        "return np.array([[0.0, s * v[1]], [-s * v[0], 0.0]])",
        "return np.array([[0.0, s * v[1]], [s * v[0], 0.0]])",
    )
    assert wrong != source
    path = tmp_path / "wrong.py"
    path.write_text(wrong)
    argv = ["check", "--analytic", str(path), *HANGING[2:], "--samples", "20"]
    assert main(argv) == 1
    out = capsys.readouterr().out
    assert "FAIL" in out and "coriolis" in out


@pytest.mark.parametrize(
    ("stem", "generator"),
    [("hanging_double_pendulum", "hanging_double_pendulum_urdf"), ("cart_pole", "cart_pole_urdf")],
)
def test_committed_example_urdfs_match_their_generators(stem, generator):
    from pendverify.analytic.params import load_parameter_file

    cls = load_model_class(EXAMPLES / f"{stem}.py")
    module = sys.modules[cls.__module__]
    _, _, params = load_parameter_file(EXAMPLES / f"{stem}.toml", {cls.name: cls.params_type})
    assert (EXAMPLES / f"{stem}.urdf").read_text() == getattr(module, generator)(params), (
        f"examples/{stem}.urdf is stale: regenerate it with python examples/{stem}.py"
    )


# --- the cart-pole and the cart-position gap of the tolerance ------------------------------------
def _cart_pole_results(max_position: float | None):
    target = plugin_target(*CART_POLE)
    states = sample_states(target.model, 150, SEED)
    if max_position is not None:
        states = [dataclasses.replace(s, q=s.q * np.array([max_position / 10.0, 1.0])) for s in states]
    return run_checks("cart_pole", target.model, target.system, states, SEED)


def test_cart_pole_passes_with_the_cart_within_two_metres():
    failing = [r.check for r in _cart_pole_results(2.0) if not r.passed]
    assert not failing, failing


def test_cart_pole_passes_over_the_full_sampled_rail():
    failing = [r.check for r in _cart_pole_results(None) if not r.passed]
    assert not failing, failing


# --- bad model files -------------------------------------------------------------------------
GOOD = (EXAMPLES / "hanging_double_pendulum.py").read_text()


def _run_file(tmp_path, capsys, text, extra=()):
    path = tmp_path / "model.py"
    path.write_text(text)
    status = main(["check", "--analytic", str(path), *HANGING[2:], *extra])
    return status, capsys.readouterr().err, str(path)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x = 1\n", "defines no subclass of pendverify.ClosedFormModel, no functions M, C, G, no METHOD"),
        ("def broken(:\n", "line 1: importing it failed: SyntaxError"),
        ("import numpy\nraise RuntimeError('boom')\n", "line 2: importing it failed: RuntimeError: boom"),
        (
            GOOD + "\n\nclass Second(HangingDoublePendulum):\n    pass\n",
            "defines 2 ClosedFormModel subclasses (HangingDoublePendulum, Second)",
        ),
        (
            GOOD.replace("    def gravity(self, q):", "    def _unused(self, q):"),
            "methods of the interface not implemented: gravity",
        ),
        (
            GOOD.replace('    model = "hanging_double_pendulum"', '    model = "other"'),
            "params_type.model is 'other' but name is 'hanging_double_pendulum'",
        ),
        (
            GOOD.replace('    urdf_joints = ("joint1", "joint2")', "    urdf_joints = ()"),
            "set urdf_joints = (...) in class HangingDoublePendulum",
        ),
        (
            GOOD.replace('    urdf_joints = ("joint1", "joint2")', '    urdf_joints = ("joint1", "elbow")'),
            "elbow not in the URDF; the URDF's joint2 not declared",
        ),
        (
            GOOD.replace(
                "joint_transform = ((1.0, 0.0), (-1.0, 1.0))", "joint_transform = ((1.0, 0.0), (2.0, 0.0))"
            ),
            "is not invertible",
        ),
        (
            GOOD.replace("joint_offset = (math.pi / 2, math.pi / 2)", "joint_offset = (1.0,)"),
            "joint_offset = (1.0,) must be finite numbers of shape (2,)",
        ),
    ],
    ids=[
        "no-class",
        "syntax",
        "raises",
        "two-classes",
        "abstract",
        "params-name",
        "no-joints",
        "wrong-joint",
        "singular-T",
        "offset-shape",
    ],
)
def test_bad_model_files_are_named_errors(tmp_path, capsys, text, message):
    status, err, path = _run_file(tmp_path, capsys, text)
    assert status == 2
    assert err.startswith(f"pendverify: error: {path}"), err
    assert message in err, err


def test_parameter_file_of_another_model_is_rejected(tmp_path, capsys):
    argv = ["check", *HANGING[:4], "--params", str(REPO / "analytic" / "params" / "double_pendulum.toml")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "key 'model' = 'double_pendulum': must be 'hanging_double_pendulum', the model defined in" in err


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--analytic", "missing.py", "--urdf", "x.urdf"], "model file not found: missing.py (relative to "),
        # a model SymPy cannot read has nothing to check without a URDF (one it reads: its units alone)
        (["--analytic", str(REPO / "tests" / "analytic" / "data" / "pendulum_functions.py")], "give --urdf"),
        ([*HANGING, "--model", "double_pendulum"], "not both"),
    ],
)
def test_incomplete_command_lines_are_errors(capsys, argv, message):
    assert main(["check", *argv]) == 2
    assert message in capsys.readouterr().err


def test_loader_needs_a_python_file(tmp_path):
    path = tmp_path / "model.txt"
    path.write_text("x")
    with pytest.raises(PendverifyError, match="a model file is Python source"):
        load_model_class(path)


# --- a model that gives only the force C·q̇ --------------------------------------------------------
def _bias_only_source() -> str:
    matrix = """    def coriolis_matrix(self, q, v):
        _, _, k = self._constants()
        s = k * self.math.sin(q[0] - q[1])
        return np.array([[0.0, s * v[1]], [-s * v[0], 0.0]])
"""
    force = """    def coriolis_force(self, q, v):
        _, _, k = self._constants()
        s = k * self.math.sin(q[0] - q[1])
        return np.array([s * v[1] ** 2, -s * v[0] ** 2])
"""
    text = (
        GOOD.replace(matrix, force)
        .replace("(ClosedFormModel):", "(BiasOnlyModel):")
        .replace("**STANDARD_CLOSED_FORMS,", "**BiasOnlyModel.closed_forms,")
        .replace("from pendverify.analytic import ", "from pendverify.analytic import BiasOnlyModel, ", 1)
    )
    assert "coriolis_matrix" not in text and "import BiasOnlyModel, " in text
    return text


def test_a_model_with_only_the_force_c_qdot_is_verified(tmp_path, capsys):
    path = tmp_path / "bias_only.py"
    path.write_text(_bias_only_source())
    out_json = tmp_path / "r.json"
    assert (
        main(["check", "--analytic", str(path), *HANGING[2:], "--samples", "30", "--json", str(out_json)])
        == 0
    )
    out = capsys.readouterr().out
    assert "coriolis, skew not run: HangingDoublePendulum gives the force C·q̇ (coriolis_force)" in out
    checks = {r["check"] for r in json.loads(out_json.read_text())["results"]}
    assert checks == {"units", *CHECK_NAMES} - {"coriolis", "skew"}

    from pendverify.symbolic.compare import EQUAL, compare

    report = compare(load_model_class(path))
    assert report.passed
    assert [c.status for c in report.comparisons if c.method == "coriolis_force"] == [EQUAL]

    wrong = tmp_path / "bias_wrong.py"
    wrong.write_text(_bias_only_source().replace("-s * v[0] ** 2])", "s * v[0] ** 2])"))
    assert main(["check", "--analytic", str(wrong), *HANGING[2:], "--samples", "10"]) == 1
    assert "rnea" in [line.split()[1] for line in capsys.readouterr().out.splitlines() if "FAIL" in line]
    mutate = ["mutate", "--analytic", str(path), *HANGING[2:], "--method", "coriolis_force"]
    assert main(mutate) == 0
    assert "detection rate 100.0% (22/22 non-equivalent mutants)" in capsys.readouterr().out


# --- the interface table ----------------------------------------------------------------------------
#: what each shipped model writes itself (``hand_written``), in the interface's order
MINIMAL = "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix"
HAND_WRITTEN = {
    "double_pendulum": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix det_mass_matrix "
        "inverse_mass_matrix acceleration gravity_scale diagonal_scale special_states"
    ),
    "cart_double_pendulum": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix disturbance_matrix "
        "det_mass_matrix inverse_mass_matrix acceleration gravity_scale diagonal_scale special_states"
    ),
    "cart_pole.py": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix disturbance_matrix "
        "det_mass_matrix inverse_mass_matrix acceleration gravity_scale special_states"
    ),
    "furuta_pendulum.py": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix disturbance_matrix "
        "det_mass_matrix inverse_mass_matrix acceleration gravity_scale diagonal_scale special_states"
    ),
    "hanging_double_pendulum.py": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix det_mass_matrix "
        "inverse_mass_matrix acceleration gravity_scale diagonal_scale special_states"
    ),
    "triple_pendulum.py": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix det_mass_matrix "
        "inverse_mass_matrix acceleration gravity_scale diagonal_scale special_states"
    ),
    "minimal_double_pendulum.py": MINIMAL,
    "minimal_double_pendulum_text.toml": MINIMAL,
    "double_pendulum_latex.toml": MINIMAL,
    "cart_pole_latex.toml": (
        "mass_matrix coriolis_matrix gravity potential_energy damping_matrix input_matrix disturbance_matrix "
        "det_mass_matrix"
    ),
    "cart_double_pendulum_latex.toml": (
        "mass_matrix coriolis_force gravity potential_energy damping_matrix input_matrix disturbance_matrix "
        "det_mass_matrix"
    ),
}


@pytest.mark.parametrize("name", sorted(HAND_WRITTEN))
def test_hand_written_is_read_from_the_interface_table(name):
    from pendverify.analytic import MODELS

    cls = MODELS[name] if name in MODELS else load_model_class(EXAMPLES / name)
    assert cls.hand_written() == tuple(HAND_WRITTEN[name].split())


def test_the_interface_table_gives_arguments_kinds_and_the_standard_closed_forms():
    from pendverify.analytic.forms import (
        COMPOSED,
        DEFAULT,
        DERIVED,
        INTERFACE,
        OPTIONAL,
        REQUIRED,
        STANDARD_CLOSED_FORMS,
        STATES,
        TOLERANCE,
        ClosedForm,
    )
    from pendverify.analytic.interface import BiasOnlyModel, ClosedFormModel

    assert {name: m.args for name, m in INTERFACE.items()} == {
        "mass_matrix": "q",
        "coriolis_matrix": "qv",
        "coriolis_force": "qv",
        "gravity": "q",
        "potential_energy": "q",
        "damping_matrix": "",
        "input_matrix": "",
        "disturbance_matrix": "",
        "det_mass_matrix": "q",
        "inverse_mass_matrix": "q",
        "acceleration": "qvuw",
        "gravity_scale": "",
        "diagonal_scale": "q",
        "special_states": "",
        "bias": "qv",
        "kinetic_energy": "qv",
    }
    kinds = {
        kind: [n for n, m in INTERFACE.items() if m.kind == kind]
        for kind in {m.kind for m in INTERFACE.values()}
    }
    assert kinds == {
        REQUIRED: ["mass_matrix", "coriolis_matrix", "coriolis_force", "gravity"],
        OPTIONAL: ["potential_energy"],
        DEFAULT: ["damping_matrix", "input_matrix", "disturbance_matrix"],
        DERIVED: ["det_mass_matrix", "inverse_mass_matrix", "acceleration"],
        TOLERANCE: ["gravity_scale", "diagonal_scale"],
        STATES: ["special_states"],
        COMPOSED: ["bias", "kinetic_energy"],
    }
    # every method the interface derives says how, and nothing else does
    written = (REQUIRED, DEFAULT, OPTIONAL)
    assert all(bool(m.derived[0]) == (m.kind not in written) for m in INTERFACE.values())
    assert INTERFACE["det_mass_matrix"].derived == ("det M", "from M (LU)")
    # the abstract methods of the interface are the required ones (C·q̇ in a BiasOnlyModel)
    assert ClosedFormModel.__abstractmethods__ == set(kinds[REQUIRED]) - {"coriolis_force"}
    assert BiasOnlyModel.__abstractmethods__ == set(kinds[REQUIRED]) - {"coriolis_matrix"}
    # every method of the table is a method of the interface
    assert all(callable(getattr(BiasOnlyModel, name)) for name in INTERFACE)
    assert STANDARD_CLOSED_FORMS == {
        "mass_matrix": ClosedForm("q"),
        "coriolis_matrix": ClosedForm("qv"),
        "gravity": ClosedForm("q"),
        "potential_energy": ClosedForm("q"),
        "damping_matrix": ClosedForm(""),
        "input_matrix": ClosedForm(""),
        "disturbance_matrix": ClosedForm(""),
        "det_mass_matrix": ClosedForm("q"),
        "inverse_mass_matrix": ClosedForm("q"),
    }
    assert list(STANDARD_CLOSED_FORMS) == [n for n in INTERFACE if n in STANDARD_CLOSED_FORMS]
