"""Text model files (TOML): the minimal double pendulum written as text equals the Python one.

``examples/minimal_double_pendulum_text.toml`` holds the equations of
``examples/minimal_double_pendulum.py`` as SymPy strings; its check table must be
the Python model's (same checks, errors to rounding, same verdicts), a typo in M
must fail crba, and every bad input is refused with one line naming the file and key.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from pendverify.analytic.plugin import load_model_class
from pendverify.cli import main
from tests.error_message import one_error

REPO = Path(__file__).resolve().parents[2]
TEXT = REPO / "examples" / "minimal_double_pendulum_text.toml"
PYTHON = REPO / "examples" / "minimal_double_pendulum.py"
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
ROW = re.compile(r"^(\S+)\s+(\w+)\s+([0-9.e+-]+)\s+([0-9.e+-]+)\s+.*\s(pass|FAIL|fail)\s*$")


def _table(capsys, model: Path, params: Path = PARAMS) -> tuple[int, dict]:
    code = main(["check", "--analytic", str(model), "--urdf", str(URDF), "--params", str(params)])
    captured = capsys.readouterr()
    _table.err = captured.err.strip()
    out = captured.out
    rows = {
        m.group(2): (float(m.group(3)), float(m.group(4)), m.group(5))
        for m in map(ROW.match, out.splitlines())
        if m
    }
    return code, rows


def test_the_text_model_check_table_equals_the_python_models(capsys):
    code_py, python = _table(capsys, PYTHON)
    code_text, text = _table(capsys, TEXT)
    assert code_py == code_text == 0
    assert python.keys() == text.keys() and len(text) >= 7
    for check, (error, tolerance, verdict) in python.items():
        assert text[check][2] == verdict
        assert text[check][1] == pytest.approx(tolerance, rel=1e-6)
        assert abs(text[check][0] - error) <= 0.05 * tolerance  # rounding: both far below the tolerance


def test_the_text_model_writes_what_the_python_model_writes():
    assert load_model_class(TEXT).hand_written() == load_model_class(PYTHON).hand_written()


def test_a_typo_in_one_entry_of_M_fails_crba(tmp_path, capsys):
    bad = tmp_path / "typo.toml"
    bad.write_text(TEXT.read_text().replace('"I2 + m2*r2**2"]', '"I2 + m2*r2**3"]'))
    code, rows = _table(capsys, bad)
    assert code == 1
    assert rows["crba"][2].lower() == "fail"


BAD = [
    ("unknown name", ('"I2 + m2*r2**2"]', '"I2 + m2*rr2**2"]'), ["key 'M[1,1]'", "'rr2'", "r2"]),
    ("wrong shape", ("H = [\n", 'H = ["0",\n'), ["key 'H'", "wrong shape"]),
    (
        "not symmetric",
        ('["I2 + m2*r2**2 + m2*l1*r2*cos(theta2)", "I2 + m2*r2**2"]', '["I2 + m2*r2**2", "I2 + m2*r2**2"]'),
        ["key 'M'", "not symmetric"],
    ),
    ("python code", ('"0"]', "\"__import__('os')\"]"), ["key 'C[1,1]'", "only sin, cos"]),
    ("attribute", ('"0"]', '"g.__class__"]'), ["key 'C[1,1]'", "Attribute"]),
    ("bad kind", ('kind = "gravity"', 'kind = "acceleration"'), ["key 'parameters.g'", "kind one of"]),
    ("kind not a name", ('kind = "gravity"', "kind = [1]"), ["key 'parameters.g'", "kind one of"]),
    (
        "unit not a string",
        ('kind = "gravity", unit = "m/s²"', 'kind = "gravity", unit = 3'),
        ["key 'parameters.g.unit'", "string"],
    ),
    ("rate in M", ('"I2 + m2*r2**2"]', '"I2 + m2*r2**2*dtheta1"]'), ["key 'M[1,1]'", "'dtheta1'"]),
    ("xor", ('"g*m2*r2*cos(theta1 + theta2)"', '"g*m2^r2"'), ["key 'H[1]'", "**"]),
]


@pytest.mark.parametrize("what, change, words", BAD, ids=[b[0] for b in BAD])
def test_each_bad_text_model_is_refused_with_one_line(tmp_path, capsys, what, change, words):
    text = TEXT.read_text()
    assert change[0] in text, what
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace(change[0], change[1], 1))
    code = main(["show", str(bad)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    headline, _, _ = one_error(err)
    assert str(bad) in headline
    for word in words:
        assert word in err, (word, err)


@pytest.mark.parametrize(
    "value, words",
    [("nan", ["parameters.g", "finite"]), (None, ["parameters.g", "missing"])],
    ids=["nan", "missing"],
)
def test_a_non_finite_or_missing_parameter_is_refused_with_one_line(tmp_path, capsys, value, words):
    lines = [line for line in PARAMS.read_text().splitlines() if not line.startswith("g =")]
    if value is not None:
        lines.append(f"g = {value}")
    params = tmp_path / "p.toml"
    params.write_text("\n".join(lines) + "\n")
    code, _ = _table(capsys, TEXT, params)
    err = _table.err
    assert code == 2 and len(err.splitlines()) == 1
    for word in words:
        assert word in err, (word, err)


def test_H_is_derived_from_V_when_only_V_is_given(tmp_path, capsys):
    text = TEXT.read_text()
    start = text.index("H = [")
    only_v = tmp_path / "only_v.toml"
    only_v.write_text(text[:start] + text[text.index("V = ", start) :])
    assert "gravity" in load_model_class(only_v).hand_written()
    code, rows = _table(capsys, only_v)
    assert code == 0 and rows["gravity"][2] == "pass"


def test_show_prints_each_equation(capsys):
    assert main(["show", str(TEXT)]) == 0
    out = capsys.readouterr().out
    for method in load_model_class(PYTHON).hand_written():
        assert f"{method} =" in out
    assert "cos(theta2)" in out


def test_sympy_runs_on_the_text_model(capsys):
    assert main(["sympy", "--analytic", str(TEXT)]) == 0


def test_mutate_runs_on_the_text_model(capsys):
    args = ["--analytic", str(TEXT), "--urdf", str(URDF), "--params", str(PARAMS), "--samples", "10"]
    assert main(["mutate", *args, "--method", "coriolis_matrix"]) in (0, 1)
    assert "coriolis_matrix" in capsys.readouterr().out


def test_a_certified_text_model_keeps_its_text_as_model_toml_and_rechecks(tmp_path, capsys):
    examples = Path(__file__).resolve().parents[2] / "examples"
    urdf = examples.parent / "urdf" / "double_pendulum.urdf"
    argv = ["certify", "--analytic", str(examples / "minimal_double_pendulum_text.toml"), "--urdf", str(urdf)]
    argv += [
        "--params",
        str(examples / "minimal_double_pendulum.toml"),
        "-o",
        str(tmp_path),
        "--samples",
        "30",
    ]
    assert main(argv) == 0
    name = "minimal_double_pendulum-double_pendulum"  # the model's name, then the URDF's
    copy = tmp_path / f"{name}.model.toml"
    assert copy.read_text() == (examples / "minimal_double_pendulum_text.toml").read_text()
    assert not (tmp_path / f"{name}.model.py").exists()
    assert main(["recheck", str(tmp_path / f"{name}.cert.json")]) == 0


def test_a_text_models_module_does_not_claim_its_text_as_python_source():
    """Tools that read a module's ``__file__`` as Python (inspect, Hypothesis) must not parse LaTeX."""
    import inspect
    import sys
    import warnings

    from pendverify.analytic.source_file import defining_file, where
    from pendverify.numerics.codegen.cache import model_key

    latex = REPO / "examples" / "double_pendulum_latex.toml"
    cls = load_model_class(latex)
    module = sys.modules[cls.__module__]
    assert getattr(module, "__file__", None) is None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(TypeError):
            inspect.getsourcefile(module)
    # the text file is still the class's file: for messages and for the generated-code key
    assert defining_file(cls) == defining_file(cls.params_type) == str(latex)
    assert where(cls) == str(latex)
    assert model_key(cls) is not None
