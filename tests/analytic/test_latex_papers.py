"""Displays as papers print them: each construct of a published derivation read and verified.

The double-pendulum reference system's M, C, D, B, H and det M written the ways papers and
lecture notes print them — a label before the matrix (``\\mathbf{M}(\\mathbf{q}) &=``,
``C(q, \\dot q) :=``, ``\\det M =``), ``align``'s ``&=`` and ``eqnarray``'s ``&=&`` with a
second line, ``\\\\[2pt]`` row spacing, ``\\begin{array}{cc}`` inside ``\\left[ … \\right]``,
a row transposed (``[a, b]^T``, ``^\\top``, ``^{\\mathsf{T}}``), ``\\operatorname{sin}``,
``\\mathrm{cos}``, a function applied without parentheses (``\\cos 2\\theta_2``,
``\\cos\\theta_1``), ``\\label``, ``\\nonumber``, spacing and a sentence's punctuation, and the
shorthands ``s_2``, ``c_1``, ``c_{1+2}`` and ``c_{12}`` — with no ``[symbols]`` line for any
name the file declares.  Each file is checked with ``api.check`` against the shipped URDF and
parameters (every row must pass), and a planted typo in each display must fail its check.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from pendverify import api
from pendverify.cli import main
from tests.analytic.test_latex_conventions import HEAD
from tests.analytic.test_latex_conventions import TABLES as CONVENTION_TABLES
from tests.error_message import one_error

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"

TABLES = (
    CONVENTION_TABLES
    + r"""
[symbols]
'\alpha' = "I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2)"
'\beta' = "m2*l1*r2"
'\delta' = "I2 + m2*r2**2"

[urdf]
joints = ["joint1", "joint2"]
"""
)

#: one display per key, each printed as a paper prints it
DISPLAYS = {
    # align, a bold label with arguments, array in \left[ \right], \\[2pt], \label, \nonumber, a comma
    "M": r"""
\mathbf{M}(\mathbf{q}) &= \left[ \begin{array}{cc}
  \alpha + 2\beta\cos\theta_2 & \delta + \beta c_2 \\[2pt]
  \delta + \beta\,\mathrm{cos}\,\theta_2 & \delta
\end{array} \right] \label{eq:mass} \nonumber,
""",
    # eqnarray's &=& over two lines, := label, \operatorname{sin}, implicit dotted rates
    "C": r"""
C(q, \dot q) &:=& \begin{pmatrix} -\beta \operatorname{sin}\theta_2\, \dot\theta_2
  & -\beta s_2 (\dot{\theta}_1 + \dot{\theta_2}) \\
  \beta\sin(\theta_2)\dot{\theta}_1 & 0 \end{pmatrix} \\
  &=& \beta\sin\theta_2 \begin{bmatrix} -\dot\theta_2 & -\dot\theta_1 - \dot\theta_2 \\
  \dot\theta_1 & 0 \end{bmatrix}.
""",
    # a row transposed, the shorthands c_1, c_{1+2}, c_{12}, \quad and \; spacing
    "H": r"""
\mathbf{H} = \Big[\, m_1 g r_1 c_1 + m_2 g (l_1 c_1 + r_2 c_{1+2}), \quad m_2 g r_2\; c_{12} \,\Big]^T
""",
    "D": r"D = \begin{bmatrix} b_1 & 0 \\ 0 & b_2 \end{bmatrix}^{\mathsf{T}}",
    "B": r"\mathbf{B} = \begin{bmatrix} 1 & 0 \\ 0 & 1 \end{bmatrix}^\top",
    # det M with a double angle applied without parentheses: β² cos² θ2 = β²(1 + cos 2θ2)/2
    "det_M": r"\det M = \alpha\delta - \delta^2 - \tfrac{1}{2}\beta^2 (1 + \cos 2\theta_2)",
}


def _file(tmp_path: Path, displays: dict[str, str]) -> Path:
    body = "".join(f"{key} = '''{value}'''\n" for key, value in displays.items())
    path = tmp_path / "paper.toml"
    path.write_text(HEAD + body + TABLES)
    return path


def test_the_paper_displays_verify(tmp_path):
    displays = dict(DISPLAYS)
    report = api.check(_file(tmp_path, displays), URDF, PARAMS)
    rows = {r.name: r for r in report.results}
    assert {"crba", "rnea", "gravity", "coriolis", "skew", "aba", "energy", "damping", "det"} <= rows.keys()
    for check, row in rows.items():
        assert row.status == "pass", f"{check}: {row.error} > {row.tolerance}"
    assert report.passed


@pytest.mark.parametrize(
    "key, old, new, check",
    [
        ("M", r"\alpha + 2\beta\cos\theta_2 &", r"\alpha + 2\beta\cos 2\theta_2 &", "crba"),
        ("C", r"-\beta s_2 (\dot{\theta}_1", r"-\beta s_2 (2\dot{\theta}_1", "coriolis"),
        ("H", r"m_1 g r_1 c_1 +", r"m_2 g r_1 c_1 +", "gravity"),
        ("det_M", r"\cos 2\theta_2", r"\cos 2\theta_1", "det"),
        ("det_M", r"\tfrac{1}{2}\beta^2", r"\tfrac{1}{2}\beta", "det"),
    ],
)
def test_a_typo_in_a_paper_display_fails_its_check(key, old, new, check, tmp_path):
    displays = dict(DISPLAYS)
    assert old in displays[key]
    displays[key] = displays[key].replace(old, new)
    if key == "C":  # the display's second line must agree with the first: give the first alone
        displays[key] = displays[key].split("\\\\\n  &=&")[0]
    report = api.check(_file(tmp_path, displays), URDF, PARAMS)
    rows = {r.name: r for r in report.results}
    assert rows[check].status.lower() == "fail"
    assert not report.passed


# --- a malformed display: one error, the fragment, a caret under the place -------------------------
@pytest.mark.parametrize(
    "key, old, new, offender, words",
    [
        # an undeclared Greek letter
        ("M", r"\alpha + 2\beta\cos\theta_2 &", r"\alpha + 2\beta\cos\vartheta_2 &", r"\vartheta",
         ["unknown symbol or command '\\vartheta'", "declare it"]),
        # an undeclared Unicode letter: read as its command, the fix named
        ("M", r"\delta + \beta c_2 \\[2pt]", r"\delta + \beta\cos φ \\[2pt]", "φ",
         ["unknown symbol 'φ' (read as \\phi)", "declare it"]),
        # an equation of motion pasted as a part
        ("det_M", r"\alpha\delta -", r"\alpha\delta\ddot{\theta}_1 -", r"\ddot",
         ["this is an equation of motion", "under `equations`"]),
        # a bracket closed twice
        ("det_M", r"(1 + \cos 2\theta_2)", r"(1 + \cos 2\theta_2) m_2)", ")",
         ["unexpected ')'"]),
        # a transpose of nothing
        ("B", r"\end{bmatrix}^\top", r"\end{bmatrix} + ^\top", "^", ["unexpected"]),
    ],
)  # fmt: skip
def test_a_malformed_display_is_one_error_with_a_caret_under_the_place(
    key, old, new, offender, words, tmp_path, capsys
):
    displays = dict(DISPLAYS)
    assert old in displays[key]
    displays[key] = displays[key].replace(old, new)
    code = main(["show", str(_file(tmp_path, displays))])
    err = capsys.readouterr().err
    assert code == 2
    headline, fragment, column = one_error(err)
    assert f"key '{key}'" in headline
    for word in words:
        assert word in headline, headline
    assert fragment[column:].startswith(offender), (fragment, column)


def test_2000_nested_brackets_show_a_short_fragment_with_a_caret(tmp_path, capsys):
    displays = dict(DISPLAYS)
    displays["det_M"] = "m_1" + r"\sin(" * 2000 + "m_1" + ")" * 2000
    code = main(["show", str(_file(tmp_path, displays))])
    headline, fragment, column = one_error(capsys.readouterr().err)
    assert code == 2 and "2000 deep" in headline and "limit is 100" in headline
    assert len(fragment) <= 82 and fragment[column] == "("


def test_a_notebooks_double_ampersands_verify_and_a_typo_among_them_fails(tmp_path):
    """Every column separator of M and C written ``&&``, as a published notebook writes them."""
    displays = dict(DISPLAYS)
    for key in ("M", "C"):
        assert displays[key].count(" & ") >= 2
        displays[key] = displays[key].replace(" & ", " && ").replace("\n  & -", "\n  && -")
    report = api.check(_file(tmp_path, displays), URDF, PARAMS)
    assert report.passed and {r.name for r in report.results} >= {"crba", "coriolis"}
    displays["M"] = displays["M"].replace(
        r"\alpha + 2\beta\cos\theta_2 &&", r"\alpha + 2\beta\cos 2\theta_2 &&"
    )
    report = api.check(_file(tmp_path, displays), URDF, PARAMS)
    assert {r.name: r.status.lower() for r in report.results}["crba"] == "fail"
