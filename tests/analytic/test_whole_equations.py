"""Equations of motion given whole (``equations = ["lhs = rhs", …]``): M and f extracted, then split.

The double pendulum of ``examples/minimal_double_pendulum_text.toml`` written as its two
Euler–Lagrange equations, in SymPy syntax and in LaTeX (one ``align`` block), verifies
against its URDF as the parts do; a factor 2 on one term fails; each way of writing
something that is not an equation of motion is refused with one line naming the equation.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import pendverify
from pendverify.analytic.plugin import load_model_class
from pendverify.api import read_model
from pendverify.errors import PendverifyError
from tests.error_message import one_error

REPO = Path(__file__).resolve().parents[2]
TEXT = REPO / "examples" / "minimal_double_pendulum_text.toml"
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
SAMPLES = 60  # the special states plus 60 random ones: every check sees each term nonzero

EQ1 = (
    "(I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2) + 2*m2*l1*r2*cos(theta2))*ddtheta1"
    " + (I2 + m2*r2**2 + m2*l1*r2*cos(theta2))*ddtheta2"
    " - m2*l1*r2*sin(theta2)*(2*dtheta1*dtheta2 + dtheta2**2) + b1*dtheta1"
    " + g*((m1*r1 + m2*l1)*cos(theta1) + m2*r2*cos(theta1 + theta2)) = tau1"
)
EQ2 = (
    "(I2 + m2*r2**2 + m2*l1*r2*cos(theta2))*ddtheta1 + (I2 + m2*r2**2)*ddtheta2"
    " + m2*l1*r2*sin(theta2)*dtheta1**2 + b2*dtheta2 + g*m2*r2*cos(theta1 + theta2) = tau2"
)
LATEX = r"""
\begin{align}
(\alpha + 2\beta\cos\theta_2)\ddot{\theta}_1 + (\delta + \beta\cos\theta_2)\ddot{\theta}_2
  - \beta\sin\theta_2\,(2\dot{\theta}_1\dot{\theta}_2 + \dot{\theta}_2^2) + b_1\dot{\theta}_1
  + g\left((m_1 r_1 + m_2 l_1)\cos\theta_1 + m_2 r_2\cos(\theta_1 + \theta_2)\right) &= \tau_1 \\[2pt]
(\delta + \beta\cos\theta_2)\ddot{\theta}_1 + \delta\,\ddot{\theta}_2 + \beta\sin\theta_2\,\dot{\theta}_1^2
  + b_2\dot{\theta}_2 + g m_2 r_2\cos(\theta_1 + \theta_2) &= \tau_2 \label{eq:eom}
\end{align}
"""
#: only the shorthands: every other symbol (\theta_1, \dot{\theta}_1, \ddot{\theta}_1, \tau_1, m_1 …)
#: is the model's name by convention (``pendverify.analytic.latex_names``)
SYMBOLS = r"""
[symbols]
'\alpha' = "I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2)"
'\beta' = "m2*l1*r2"
'\delta' = "I2 + m2*r2**2"
"""


def _toml_string(text: str) -> str:
    return "'''" + text + "'''"


def equations_file(tmp_path: Path, equations: list[str] | str, latex: bool = False, name="eq.toml") -> Path:
    """The minimal double pendulum's text file with its M, C, H, V, D, B replaced by ``equations``."""
    head, tables = TEXT.read_text().split("[coordinates]", 1)
    lines = [line for line in head.splitlines() if line.startswith(("name", "inputs"))]
    if isinstance(equations, str):
        value = _toml_string(equations)
    else:
        value = "[\n" + "".join(f"  {_toml_string(e) if latex else repr(e)},\n" for e in equations) + "]"
    if latex:
        lines.append('notation = "latex"')
    lines.append(f"equations = {value}")
    body = "\n".join(lines) + "\n\n[coordinates]" + tables + (SYMBOLS if latex else "")
    path = tmp_path / name
    path.write_text(body.replace("'\"", '"').replace("\"'", '"'))
    return path


def _check(path: Path) -> pendverify.CheckReport:
    return pendverify.check(path, URDF, PARAMS, samples=SAMPLES, explain=False)


def test_scalar_equations_verify_as_the_parts_do(tmp_path):
    report = _check(equations_file(tmp_path, [EQ1, EQ2]))
    parts = pendverify.check(TEXT, URDF, PARAMS, samples=SAMPLES, explain=False)
    assert report.status == "pass", report
    # the equations give C·q̇, not a matrix C: every check the parts take but coriolis and skew
    assert set(report.checks) == set(parts.checks) - {"coriolis", "skew"}
    assert {"crba", "rnea", "gravity", "aba", "energy", "damping"} <= set(report.checks)


def test_show_says_how_the_equations_were_split(tmp_path):
    reading = read_model(equations_file(tmp_path, [EQ1, EQ2]))
    derived = {e.method: e.derived for e in reading.equations}
    assert "coefficients of the accelerations" in derived["mass_matrix"]
    assert "the equations' f" in derived["gravity"] and "the equations' f" in derived["input_matrix"]


def test_accelerations_on_the_right_hand_side_read_as_the_same_equation(tmp_path):
    lhs, rhs = EQ2.split(" = ")
    flipped = f"{rhs} = {lhs}"
    report = _check(equations_file(tmp_path, [EQ1, flipped]))
    assert report.status == "pass", report


@pytest.mark.parametrize(
    "old, new, check",
    [
        ("(I2 + m2*r2**2)*ddtheta2", "2*(I2 + m2*r2**2)*ddtheta2", "crba"),  # one M entry doubled
        ("+ m2*l1*r2*sin(theta2)*dtheta1**2", "+ 2*m2*l1*r2*sin(theta2)*dtheta1**2", "rnea"),  # C·q̇
    ],
)
def test_a_factor_2_in_one_term_fails(old, new, check, tmp_path):
    assert old in EQ2
    report = _check(equations_file(tmp_path, [EQ1, EQ2.replace(old, new)]))
    assert report[check].status == "fail"


def test_latex_align_block_verifies(tmp_path):
    report = _check(equations_file(tmp_path, LATEX, latex=True))
    assert report.status == "pass", report


def test_latex_one_string_per_equation_verifies_and_a_typo_fails(tmp_path):
    rows = [r for r in LATEX.split(r"\\[2pt]")]
    good = [rows[0].replace(r"\begin{align}", ""), rows[1].replace(r"\end{align}", "")]
    assert _check(equations_file(tmp_path, good, latex=True)).status == "pass"
    bad = [good[0], good[1].replace(r"\delta\,\ddot{\theta}_2", r"2\delta\,\ddot{\theta}_2")]
    assert _check(equations_file(tmp_path, bad, latex=True, name="bad.toml"))["crba"].status == "fail"


@pytest.mark.parametrize(
    "equations, words",
    [
        ([EQ1, EQ2.replace(" = tau2", " + tau2")], "equations[1]': is not an equation lhs = rhs: no '='"),
        ([EQ1, EQ2 + " = 0"], "equations[1]': is not an equation lhs = rhs: 2 '=' signs"),
        ([EQ1], "gives 1 equation for 2 coordinates"),
        ([EQ1, EQ2, EQ2], "gives 3 equations for 2 coordinates"),
        ([EQ1, "g*m2*r2*cos(theta1 + theta2) = tau2"], "equations[1]': no acceleration"),
        (
            [EQ1, EQ2.replace("*ddtheta2", "*ddtheta2**2")],
            "equations[1]': is not linear in the accelerations",
        ),
        ([EQ1, EQ2.replace("= tau2", "= tau2*dtheta1")], "not f0(q, q̇) + B·u with a constant B"),
        ([EQ1, EQ2.replace("tau2", "tau3")], "unknown name 'tau3'"),
    ],
)
def test_what_is_not_an_equation_of_motion_is_refused_in_one_line(equations, words, tmp_path):
    with pytest.raises(PendverifyError) as info:
        load_model_class(equations_file(tmp_path, equations))
    headline, _, _ = one_error(str(info.value))
    assert "eq.toml" in headline
    assert words in headline, headline


def test_a_doubled_gravity_term_that_is_no_gradient_is_refused(tmp_path):
    bad = EQ2.replace("b2*dtheta2 + g*m2*r2", "b2*dtheta2 + 2*g*m2*r2")
    with pytest.raises(PendverifyError, match="key 'H': is not the gradient of any potential"):
        load_model_class(equations_file(tmp_path, [EQ1, bad]))


def test_equations_and_parts_together_are_refused(tmp_path):
    path = equations_file(tmp_path, [EQ1, EQ2])
    path.write_text(path.read_text().replace("equations =", 'B = [["1", "0"], ["0", "1"]]\nequations ='))
    with pytest.raises(PendverifyError, match="give the equations or their parts, not both"):
        load_model_class(path)
