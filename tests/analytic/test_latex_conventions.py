"""Names by convention in LaTeX model files (``pendverify.analytic.latex_names``).

A declared name needs no line in ``[symbols]``: ``m_1`` is m1, ``\\theta_1`` theta1,
``\\dot{\\theta}_1`` dtheta1, ``θ₁`` theta1, ``s_{1+2}`` sin(θ1 + θ2) — unless the table
says otherwise; ``pendverify show`` lists what the convention read.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import sympy as sp
import tomllib

from pendverify import api
from pendverify.analytic.latex_names import acceleration_symbol, conventions, spellings
from pendverify.analytic.latex_normalise import canonical_symbol
from pendverify.analytic.text_parse import read_text_model
from pendverify.cli import main
from pendverify.errors import PendverifyError

REPO = Path(__file__).resolve().parents[2]
HEAD = """name = "double_pendulum"
notation = "latex"
inputs = ["tau1", "tau2"]
"""
TABLES = """
[coordinates]
theta1 = "angle"
theta2 = "angle"

[parameters]
m1 = { kind = "mass", unit = "kg" }
m2 = { kind = "mass", unit = "kg" }
l1 = { kind = "length", unit = "m" }
l2 = { kind = "length", unit = "m" }
r1 = { kind = "offset", unit = "m" }
r2 = { kind = "offset", unit = "m" }
I1 = { kind = "inertia", unit = "kg·m²" }
I2 = { kind = "inertia", unit = "kg·m²" }
b1 = { kind = "damping", unit = "N·m·s/rad" }
b2 = { kind = "damping", unit = "N·m·s/rad" }
g = { kind = "gravity", unit = "m/s²" }
"""


def _model(tmp_path: Path, equations: str, symbols: str = "") -> Path:
    path = tmp_path / "model.toml"
    path.write_text(HEAD + equations + TABLES + symbols)
    return path


def _read(tmp_path: Path, latex: str, symbols: str = ""):
    """The vector H of a model file whose H is ``latex`` (H may use the coordinates only)."""
    spec = read_text_model(_model(tmp_path, f"H = '''\n{latex}\n'''\n", symbols))
    return spec.equations["H"], spec


def _names(spec):
    names = {s.name: s for g in "qvuwp" for s in spec.symbols[g]}
    return [names[n] for n in "theta1 theta2 m1 m2 l1 r1 r2 g".split()]


@pytest.mark.parametrize(
    "name, latex",
    [
        ("m1", ["m_1"]),
        ("g", ["g"]),
        ("mc", ["m_c"]),
        ("x12", ["x_{12}"]),
        ("theta1", ["\\theta_1"]),
        ("alpha", ["\\alpha"]),
        ("m_p", ["m_p"]),
    ],
)
def test_the_spellings_of_a_name(name, latex):
    assert spellings(name) == latex


def test_rates_accelerations_and_shorthands_of_the_coordinates():
    names = {n: sp.Symbol(n) for n in ("theta1", "theta2", "dtheta1", "dtheta2", "c1")}
    found = conventions(("theta1", "theta2"), ("c1",), names)
    th1, th2 = names["theta1"], names["theta2"]
    assert found["\\dot{\\theta}_1"].value == names["dtheta1"]
    assert (
        found["\\ddot{\\theta}_2"].value == acceleration_symbol("theta2") == sp.Symbol("ddtheta2", real=True)
    )
    assert found["s_{1+2}"].value == found["s_{12}"].value == sp.sin(th1 + th2)
    assert found["c_{2-1}"].value == sp.cos(th2 - th1)
    assert found["c_2"].value == sp.cos(th2)
    assert found["c_1"].value == names["c1"]  # a declared name wins over a shorthand


def test_a_file_without_symbols_reads_its_declared_names(tmp_path):
    H, spec = _read(
        tmp_path,
        r"\begin{bmatrix} m_1 g r_1\cos\theta_1 + m_2 g(l_1 c_1 + r_2 c_{1+2}) \\ "
        r"m_2 g r_2 \cos(θ₁ + θ_2) \end{bmatrix}",
    )
    t1, t2, m1, m2, l1, r1, r2, g = _names(spec)
    expected = sp.Matrix(
        [
            m1 * g * r1 * sp.cos(t1) + m2 * g * (l1 * sp.cos(t1) + r2 * sp.cos(t1 + t2)),
            m2 * g * r2 * sp.cos(t1 + t2),
        ]
    )
    assert (H - expected).expand() == sp.zeros(2, 1)
    assert "c_{1+2} → cos(theta1 + theta2)" in spec.latex_conventions
    assert "\\theta_1 → theta1" in spec.latex_conventions and "m_1 → m1" in spec.latex_conventions


def test_the_table_wins_over_the_convention(tmp_path):
    H, spec = _read(
        tmp_path,
        r"\begin{bmatrix} m_1 g \\ c_{1+2} \end{bmatrix}",
        "\n[symbols]\n'm_1' = \"m2\"\n'c_{1+2}' = \"l1\"\n",
    )
    _, _, _, m2, l1, _, _, g = _names(spec)
    assert list(H) == [m2 * g, l1]
    assert not any(c.startswith(("m_1", "c_{1+2}")) for c in spec.latex_conventions)


def test_an_acceleration_in_a_part_is_refused(tmp_path):
    path = _model(tmp_path, "H = '''\n\\begin{bmatrix} m_1\\ddot{\\theta}_1 \\\\ 0 \\end{bmatrix}\n'''\n")
    with pytest.raises(PendverifyError) as info:
        read_text_model(path)
    assert "key 'H'" in str(info.value) and "equations" in str(info.value)


def test_show_says_which_names_came_from_the_convention(capsys):
    example = REPO / "examples" / "cart_pole_latex.toml"
    assert main(["show", str(example)]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("names by convention: "))
    assert "m_c → mc" in line and "\\dot{\\theta} → dtheta" in line
    assert "b_\\theta" not in line  # from the file's table, not a convention
    assert api.read_model(example).conventions[0] == "m_c → mc"


@pytest.mark.parametrize(
    "example", ["double_pendulum_latex", "cart_double_pendulum_latex", "cart_pole_latex"]
)
def test_the_examples_keep_no_identity_line(example):
    path = REPO / "examples" / f"{example}.toml"
    table = tomllib.loads(path.read_text()).get("symbols", {})
    spec = read_text_model(path)
    names = {s.name: s for g in "qvuwp" for s in spec.symbols[g]}
    by_convention = conventions(spec.coordinates, (*spec.inputs, *spec.disturbances, *spec.parameters), names)
    identities = [
        k
        for k, v in table.items()
        if canonical_symbol(k) in by_convention and str(by_convention[canonical_symbol(k)].value) == v
    ]
    assert identities == []
    assert len(table) <= 7  # x_1…x_4, α, β, δ at most: real definitions only


def test_two_table_keys_for_one_symbol_are_one_declaration_when_they_agree(tmp_path):
    """``'θ_2'`` and ``'\\theta_2'`` read as one symbol: saying the same, they are one declaration."""
    latex = r"\begin{bmatrix} m_1 g \cos\theta_1 \\ m_2 g \cos\theta_2 \end{bmatrix}"
    table = "\n[symbols]\n'θ_2' = \"theta2\"\n'\\theta_2' = \"theta2\"\n'x_1' = \"m1\"\n'x_{1}' = \"1*m1\"\n"
    H, spec = _read(tmp_path, latex, table)
    t1, t2, m1, m2, _, _, _, g = _names(spec)
    assert list(H) == [m1 * g * sp.cos(t1), m2 * g * sp.cos(t2)]
    assert spec.latex_symbols["θ_2"] == t2 and "\\theta_2" not in spec.latex_symbols
    H, spec = _read(tmp_path, latex, "\n[symbols]\n'θ_2' = \"theta2\"\n")  # beside the convention
    assert list(H) == [m1 * g * sp.cos(t1), m2 * g * sp.cos(t2)]


def test_two_table_keys_for_one_symbol_that_disagree_are_refused(tmp_path):
    table = "\n[symbols]\n'θ_2' = \"theta2\"\n'\\theta_2' = \"theta1\"\n"
    with pytest.raises(PendverifyError) as info:
        _read(tmp_path, r"\begin{bmatrix} 0 \\ \cos\theta_2 \end{bmatrix}", table)
    message = str(info.value)
    assert "key 'symbols.\\theta_2'" in message
    assert "reads as the same symbol as 'θ_2', which says theta2, not theta1" in message
