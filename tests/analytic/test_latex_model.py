"""Models written in LaTeX: the seed documents' own equations, verified as they stand.

``examples/double_pendulum_latex.toml`` holds seed 000's M, C (with its friction)
and H pasted from the document; ``examples/cart_double_pendulum_latex.toml`` holds
seed 001's f(y, ẏ, u, w) and det M(y), and its M completed (the printed one has two
rows and is refused).  Every way of giving the same equations — the built-in Python
class, a text file in SymPy syntax, LaTeX — must give the same check table; a typo
in the LaTeX must fail; unreadable LaTeX must say where reading stopped.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
import sympy as sp

from pendverify.analytic.latex_normalise import canonical_symbol
from pendverify.analytic.latex_parse import LatexError, LatexReader, SymbolTable
from pendverify.cli import main
from tests.analytic.one_coordinate_models import FORMS
from tests.error_message import one_error

REPO = Path(__file__).resolve().parents[2]
#: the source documents of the two reference systems, copied into the repository
DOCUMENTS = Path(__file__).resolve().parent / "data" / "reference_systems"
ROW = re.compile(r"^(\S+)\s+(\w+)\s+([0-9.e+-]+)\s+([0-9.e+-]+)\s+.*\s(pass|FAIL|fail)\s*$")
SEED = {
    "double_pendulum": (
        REPO / "examples" / "double_pendulum_latex.toml",
        REPO / "urdf" / "double_pendulum.urdf",
        REPO / "analytic" / "params" / "double_pendulum.toml",
        "double_pendulum.txt",
    ),
    "cart_double_pendulum": (
        REPO / "examples" / "cart_double_pendulum_latex.toml",
        REPO / "urdf" / "cart_double_pendulum.urdf",
        REPO / "analytic" / "params" / "cart_double_pendulum.toml",
        "cart_double_pendulum.txt",
    ),
}

# The same equations in SymPy syntax (the text-file way of giving them).
SYMPY_EQUATIONS = {
    "double_pendulum": """
M = [
  ["I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2) + 2*m2*l1*r2*cos(theta2)", "I2 + m2*r2**2 + m2*l1*r2*cos(theta2)"],
  ["I2 + m2*r2**2 + m2*l1*r2*cos(theta2)", "I2 + m2*r2**2"],
]
C_plus_D = [
  ["-m2*l1*r2*sin(theta2)*dtheta2 + b1", "-m2*l1*r2*sin(theta2)*(dtheta1 + dtheta2)"],
  ["m2*l1*r2*sin(theta2)*dtheta1", "b2"],
]
H = ["m1*g*r1*cos(theta1) + m2*g*(l1*cos(theta1) + r2*cos(theta1 + theta2))", "m2*g*r2*cos(theta1 + theta2)"]
D = [["b1", "0"], ["0", "b2"]]
B = [["1", "0"], ["0", "1"]]
""",
    "cart_double_pendulum": """
M = [
  ["m + m1 + m2", "l1*(m1 + m2)*cos(theta1)", "m2*l2*cos(theta2)"],
  ["l1*(m1 + m2)*cos(theta1)", "l1**2*(m1 + m2)", "l1*l2*m2*cos(theta1 - theta2)"],
  ["m2*l2*cos(theta2)", "l1*l2*m2*cos(theta1 - theta2)", "l2**2*m2"],
]
f = [
  "l1*(m1 + m2)*dtheta1**2*sin(theta1) + m2*l2*dtheta2**2*sin(theta2) - d1*dq + u + w1",
  "-l1*l2*m2*dtheta2**2*sin(theta1 - theta2) + g*(m1 + m2)*l1*sin(theta1) - d2*dtheta1 + w2",
  "l1*l2*m2*dtheta1**2*sin(theta1 - theta2) + g*l2*m2*sin(theta2) - d3*dtheta2 + w3",
]
det_M = "l1**2*l2**2*m2*(m*m1 + m1**2*sin(theta1)**2 + m1*m2*sin(theta1)**2 + m*m2*sin(theta1 - theta2)**2)"
""",
}


def _latex_equations(text: str) -> dict[str, str]:
    """The LaTeX strings of an example file: key → the text between its ''' quotes."""
    return {m.group(1): m.group(2).strip() for m in re.finditer(r"^(\w+) = '''\n(.*?)'''", text, re.S | re.M)}


def _sympy_version(model: str, tmp_path: Path) -> Path:
    """The example's model with its LaTeX equations replaced by SYMPY_EQUATIONS."""
    text = SEED[model][0].read_text()
    head = text.split("[coordinates]")[0]
    head = re.sub(r"^notation = .*\n", "", head, flags=re.M)
    head = re.sub(r"^(\w+) = '''\n.*?'''\n", "", head, flags=re.S | re.M)
    head = re.sub(r"^[DB] = '.*'\n", "", head, flags=re.M)
    tables = "[coordinates]" + text.split("[coordinates]")[1]
    tables = re.sub(r"\[symbols\].*?(?=\n# |\n\[urdf\])", "", tables, flags=re.S)
    path = tmp_path / f"{model}_sympy.toml"
    path.write_text(head + SYMPY_EQUATIONS[model] + "\n" + tables)
    return path


def _table(capsys, *args: str) -> tuple[int, dict, str]:
    code = main(["check", *args])
    captured = capsys.readouterr()
    rows = {
        m.group(2): (float(m.group(3)), float(m.group(4)), m.group(5))
        for m in map(ROW.match, captured.out.splitlines())
        if m
    }
    return code, rows, captured.err.strip()


def _check(capsys, model_file: Path, model: str) -> tuple[int, dict, str]:
    _, urdf, params, _ = SEED[model]
    return _table(capsys, "--analytic", str(model_file), "--urdf", str(urdf), "--params", str(params))


# --- the seeds, as written -------------------------------------------------------------
@pytest.mark.parametrize("model", list(SEED))
def test_every_way_of_giving_a_seed_yields_the_same_check_table(model, tmp_path, capsys):
    latex_file, urdf, params, _ = SEED[model]
    code_latex, latex, err = _check(capsys, latex_file, model)
    assert code_latex == 0, err
    code_text, text, err = _check(capsys, _sympy_version(model, tmp_path), model)
    assert code_text == 0, err
    # the same equations in two notations become the same SymPy expressions: the same numbers
    assert latex == text
    code_builtin, builtin, err = _table(
        capsys, "--model", model, "--urdf", str(urdf), "--params", str(params)
    )
    assert code_builtin == 0, err
    # the built-in class writes more (det M, M⁻¹, C as a matrix for the cart): the rows of the
    # equations both give agree in verdict and are both inside their tolerances (which differ:
    # each is scaled by the size of the terms of the formula as written)
    common = latex.keys() & builtin.keys()
    assert {"crba", "rnea", "gravity", "aba", "energy"} <= common
    for check in common:
        assert latex[check][2] == builtin[check][2] == "pass"
        assert latex[check][0] <= latex[check][1] and builtin[check][0] <= builtin[check][1]


@pytest.mark.parametrize("model", list(SEED))
def test_the_example_latex_is_the_seed_documents_own_text(model):
    latex_file, _, _, seed = SEED[model]
    document = (DOCUMENTS / seed).read_text()
    equations = _latex_equations(latex_file.read_text())
    assert equations
    for key, latex in equations.items():
        if model == "cart_double_pendulum" and key == "M":  # the document lost the third row
            printed_rows = latex.split("\\\\\n")[0]
            assert printed_rows in document
            continue
        assert latex in document, f"{key} is not verbatim from {seed}"


def test_seed_001s_printed_M_is_refused_for_having_two_rows(tmp_path, capsys):
    latex_file = SEED["cart_double_pendulum"][0]
    text = latex_file.read_text()
    printed = (
        r"\begin{bmatrix} m+m_1+m_2 & l_1(m_1+m_2)\cos\theta_1 & m_2l_2\cos\theta_2 \\ "
        r"l_1(m_1+m_2)\cos\theta_1 & l_1^2(m_1+m_2) & l_1l_2m_2\cos(\theta_1-\theta_2) \end{bmatrix}"
    )
    assert printed in (DOCUMENTS / SEED["cart_double_pendulum"][3]).read_text()
    bad = tmp_path / "printed_M.toml"
    bad.write_text(re.sub(r"^M = '''\n.*?'''", lambda _: f"M = '''\n{printed}\n'''", text, flags=re.S | re.M))
    code, _, err = _check(capsys, bad, "cart_double_pendulum")
    assert code == 2
    assert len(err.splitlines()) == 1
    assert "key 'M'" in err and "2 rows of 3 entries" in err and "3 × 3" in err


@pytest.mark.parametrize(
    "model, old, new, check",
    [
        ("double_pendulum", r"\alpha + 2\beta\cos(", r"\alpha + 3\beta\cos(", "crba"),  # both sides of M
        ("double_pendulum", r"m_1gr_1\cos(", r"m_1gr_2\cos(", "gravity"),
        ("cart_double_pendulum", r"g(m_1+m_2)l_1\sin", r"g(m_1+m_2)l_2\sin", "gravity"),
        ("cart_double_pendulum", r"+ m m_2 \sin^2 (\theta_1", r"+ m m_1 \sin^2 (\theta_1", "det"),
    ],
)
def test_a_typo_in_the_latex_fails_its_check(model, old, new, check, tmp_path, capsys):
    text = SEED[model][0].read_text()
    assert old in text
    bad = tmp_path / "typo.toml"
    bad.write_text(text.replace(old, new))
    code, rows, err = _check(capsys, bad, model)
    assert code == 1, err
    assert rows[check][2].lower() == "fail"


def test_the_two_sides_of_a_display_must_agree(tmp_path, capsys):
    text = SEED["double_pendulum"][0].read_text()
    bad = tmp_path / "sides.toml"
    bad.write_text(
        text.replace(r"\delta + \beta\cos(x_2) & \delta \end", r"\delta + \beta\cos(x_1) & \delta \end")
    )
    code, _, err = _check(capsys, bad, "double_pendulum")
    assert code == 2 and len(err.splitlines()) == 1
    assert "key 'M'" in err and "right-hand sides 1 and 2 differ" in err


# --- bad LaTeX model files: one line naming file, key and problem ----------------------------
@pytest.mark.parametrize(
    "old, new, words",
    [
        ("'\\alpha' = ", "'\\gamma' = ", ["key 'M'", "unknown symbol or command '\\alpha'"]),
        (r"\sin(\theta_2)\dot{\theta}_2 + b_1", r"\sin(\theta_2\dot{\theta}_2 + b_1", ["key 'C_plus_D'", "at character 82: unexpected '&' (a '(' opened before it is not closed)"]),
        (r"\delta + \beta\cos(x_2) & \delta \end", r"\delta + \beta\cos(x_2) & \delta + \dot{\theta}_1 \end",
         ["key 'M'"]),
        ("notation = \"latex\"", "notation = \"tex\"", ["key 'notation'", "'tex'"]),
        ("'\\beta' = \"m2*l1*r2\"", "'\\beta' = \"m2*l1*r7\"", ["key 'symbols.\\beta'", "r7"]),
        ("'x_1' = \"theta1\"", "'x_1' = \"theta1\"\n'x_{1}' = \"theta2\"",
         ["symbols.x_{1}", "same symbol as 'x_1', which says theta1, not theta2"]),
        (r"D = '\begin{bmatrix} b_1 & 0 \\ 0 & b_2 \end{bmatrix}'", "", ["key 'C_plus_D'", "needs D"]),
        (r"\delta + \beta\cos(\theta_2) & \delta \end{bmatrix} =", r"\delta + \beta\cos(\theta_2) \end{bmatrix} =",
         ["key 'M'", "rows have"]),
    ],
)  # fmt: skip
def test_each_bad_latex_model_is_refused_with_one_line(old, new, words, tmp_path, capsys):
    text = SEED["double_pendulum"][0].read_text()
    assert old in text
    bad = tmp_path / "bad.toml"
    bad.write_text(text.replace(old, new, 1))
    code, _, err = _check(capsys, bad, "double_pendulum")
    assert code == 2
    headline, _, _ = one_error(err)
    assert str(bad) in headline
    for word in words:
        assert word in headline


def test_a_non_symmetric_latex_M_is_refused(tmp_path, capsys):
    text = SEED["cart_double_pendulum"][0].read_text()
    bad = tmp_path / "asym.toml"
    bad.write_text(text.replace(r"m_2l_2\cos\theta_2 & l_1l_2m_2\cos(\theta_1-\theta_2) & l_2^2m_2",
                                r"m_2l_2\cos\theta_1 & l_1l_2m_2\cos(\theta_1-\theta_2) & l_2^2m_2"))  # fmt: skip
    code, _, err = _check(capsys, bad, "cart_double_pendulum")
    assert code == 2 and len(err.splitlines()) == 1
    assert "key 'M'" in err and "not symmetric" in err


@pytest.mark.parametrize(
    "old, new, words",
    [
        (r"- \begin{bmatrix} d_1\dot{q} \\", r"- \begin{bmatrix} d_1\cos\theta_1\dot{q} \\", ["depends on the coordinates"]),
        (r"+ \begin{bmatrix} u \\ 0 \\ 0 \end{bmatrix}", r"+ \begin{bmatrix} u^2 \\ 0 \\ 0 \end{bmatrix}", ["∂f/∂u"]),
        (r"m_2l_2(\dot{\theta}_2)^2\sin\theta_2", r"m_2l_2(\dot{\theta}_2)^3\sin\theta_2", ["quadratic in q̇"]),
    ],
)  # fmt: skip
def test_an_f_that_is_not_the_standard_form_is_refused(old, new, words, tmp_path, capsys):
    text = SEED["cart_double_pendulum"][0].read_text()
    assert old in text
    bad = tmp_path / "f.toml"
    bad.write_text(text.replace(old, new))
    code, _, err = _check(capsys, bad, "cart_double_pendulum")
    assert code == 2 and len(err.splitlines()) == 1, err
    assert "key 'f'" in err
    for word in words:
        assert word in err


# --- the reader itself ---------------------------------------------------------------------------
def _reader(**names) -> LatexReader:
    symbols = {k: sp.Symbol(v) for k, v in names.items()}
    return LatexReader(SymbolTable({canonical_symbol(k): v for k, v in symbols.items()}, dict(names)))


READER = _reader(**{
    "\\theta_1": "t1", "\\theta_2": "t2", "\\dot{\\theta}_1": "w1", "\\ddot{\\theta}_1": "a1",
    "m_1": "m1", "m_2": "m2", "g": "g", "r_1": "r1", "x_{12}": "x12", "\\alpha": "al", "u": "u",
})  # fmt: skip
t1, t2, w1, a1, m1, m2, g, r1, x12, al, u = sp.symbols("t1 t2 w1 a1 m1 m2 g r1 x12 al u")


@pytest.mark.parametrize(
    "latex, expected",
    [
        (r"m_1gr_1\cos(\theta_1)", m1 * g * r1 * sp.cos(t1)),  # implicit products of declared symbols
        (r"\sin^2\theta_1", sp.sin(t1) ** 2),
        (r"\sin^{2}(\theta_1 - \theta_2)", sp.sin(t1 - t2) ** 2),
        (r"\cos \theta_1 \sin \theta_2", sp.cos(t1) * sp.sin(t2)),
        (r"\left( m_1 + m_2 \right) \cdot g", (m1 + m2) * g),
        (r"\left[ m_1 \times g \right]", m1 * g),
        (r"\dot\theta_1 + \dot{\theta_1} + \dot{\theta}_1 + \ddot{\theta}_1", 3 * w1 + a1),
        (r"\mathbf{u} + \boldsymbol{\alpha}", u + al),
        (r"\frac{1}{2} m_1 \dot{\theta}_1^2", m1 * w1**2 / 2),
        (r"\dfrac{m_1}{m_2}\,\sqrt{g}", m1 / m2 * sp.sqrt(g)),
        (r"x_{12} x_{12}", x12**2),
        (r"m_1 \left\{ g \right\} - \underbrace{m_2}_{=:\mu}", m1 * g - m2),
        (r"= m_1 g.", m1 * g),  # a continuation line and a sentence's full stop
        (r"f(\theta_1) = m_1 g", m1 * g),  # a label is dropped
        (r"\begin{pmatrix} m_1 & 0 \\ 0 & m_2 \\ \end{pmatrix}", sp.Matrix([[m1, 0], [0, m2]])),
        (r"\begin{bmatrix} 1 & 2 \end{bmatrix} \begin{bmatrix} m_1 \\ m_2 \end{bmatrix}", sp.Matrix([[m1 + 2 * m2]])),
        (r"-2.5\alpha", -2.5 * al),
        # a notebook's matrices: every column separator written &&
        (r"\begin{bmatrix} m_1 && 0 \\ 0 && m_2 \end{bmatrix}", sp.Matrix([[m1, 0], [0, m2]])),
        (r"\left[\begin{array}{ccc} m_1 && g && 0 \\ 0 && m_2&&g \end{array}\right]",
         sp.Matrix([[m1, g, 0], [0, m2, g]])),
        (r"\begin{bmatrix} m_1 && g \end{bmatrix} \begin{bmatrix} 1 & 0 \\ 0 & 1 \end{bmatrix}",
         sp.Matrix([[m1, g]])),  # each matrix by its own separators
    ],
)  # fmt: skip
def test_the_reader_reads_latex_as_written(latex, expected):
    value, _ = READER.read(latex)
    difference = value - expected
    if isinstance(difference, sp.MatrixBase):
        assert difference.is_zero_matrix
    else:
        assert sp.simplify(difference) == 0


@pytest.mark.parametrize(
    "latex, at, words",
    [
        (r"m_1 + \gamma", 7, "'\\gamma'"),
        (r"m_1 + (m_2", 11, "ends too early"),
        (r"m_1 + m_2)", 10, "unexpected ')'"),
        (r"m_1 + k", 7, "'k'"),
        (r"x_12", 1, "'x_1'"),  # in LaTeX x_12 is x₁·2: x_{12} is the declared symbol
        (r"m_1 \underbrace{m_2", 5, "never closed"),
        (r"\begin{bmatrix} 1 & 0 \end{pmatrix}", None, "closed by"),
        (r"\begin{vmatrix} 1 & 0 \end{vmatrix}", None, "not a matrix"),
        # && is one separator only where every separator is &&; an empty cell stays an error
        (r"\begin{bmatrix} m_1 && 0 \\ 0 & m_2 \end{bmatrix}", 21, "both '&&' and '&'"),
        (r"\begin{bmatrix} m_1 & & 0 \\ 0 & & m_2 \end{bmatrix}", 23, "unexpected '&'"),
    ],
)
def test_unreadable_latex_says_where_reading_stopped(latex, at, words):
    with pytest.raises(LatexError) as info:
        READER.read(latex)
    message = str(info.value)
    assert words in message
    if at is not None:
        headline, fragment, column = one_error(message)
        assert f"at character {at}:" in headline
        assert fragment == latex and column == at - 1  # the caret under the character named


def test_show_prints_the_latex_model_as_read(capsys):
    assert main(["show", str(SEED["cart_double_pendulum"][0])]) == 0
    out = capsys.readouterr().out
    assert "det_mass_matrix = l1**2*l2**2*m2*" in out
    assert "gravity (derived: from f" in out and "coriolis_force (derived: from f" in out


# --- LaTeX in TOML's double quotes: \b \t \n \f \r are escapes there -----------------------------
ONE = FORMS["LaTeX, each entry alone"][1]  # the single pendulum, each entry bare LaTeX


@pytest.mark.parametrize(
    "old, new, key, words",
    [
        ("D = 'b'", r'D = "\beta"', "D", [r'TOML turned \b into a backspace (in "\beta")']),
        (r"H = 'm g l \sin\theta'", r'H = "m g l \theta"', "H", [r'\t into a tab (in "\theta")']),
        ("M = 'm l^2'", r'M = "\frac{m l^3}{l}"', "M", [r'\f into a form feed (in "\frac")']),
        ("M = 'm l^2'", r'M = "m_p l \beta \theta"', "M",
         [r'\b into a backspace (in "\beta") and \t into a tab (in "\theta")']),
        ("M = 'm l^2'", r'M = [["\frac{m l^3}{l}"]]', "M[0,0]", [r'(in "\frac")']),
        ("M = 'm l^2'", r'M = "\\frac{m l^3}{l} \nabla"', "M", [r'\n into a line break (in "\nabla")']),
        ("M = 'm l^2'", "M = 'm l^2'\n" r'equations = "m l^2 \\ddot\\theta = \tau"', "equations",
         [r'(in "\tau")']),
        ("[coordinates]", '[symbols]\n"\\beta" = "b"\n\n[coordinates]', "symbols",
         [r'a key was written in double quotes: TOML turned \b into a backspace (in "\beta")']),
    ],
)  # fmt: skip
def test_latex_in_double_quotes_that_toml_corrupted_is_refused_in_one_line(
    old, new, key, words, tmp_path, capsys
):
    assert old in ONE
    path = tmp_path / "quotes.toml"
    path.write_text(ONE.replace(old, new, 1))
    code = main(["show", str(path)])
    headline, _, _ = one_error(capsys.readouterr().err)
    assert code == 2
    assert headline.startswith(f"pendverify: error: {path}: key '{key}': ")
    for word in [*words, "use single quotes '…' or '''…'''"]:
        assert word in headline, headline


@pytest.mark.parametrize(
    "old, new",
    [
        # escaped backslashes in double quotes: what the LaTeX means
        (r"H = 'm g l \sin\theta'", r'H = "m g l \\sin\\theta"'),
        # real line breaks and tabs in a block: layout, read as spaces
        ("M = 'm l^2'", "M = '''\n\t\\begin{bmatrix}\n\tm l^2\n\t\\end{bmatrix}\n'''"),
        ("C = '0'", "C = '''\n0\n'''"),
    ],
)
def test_latex_with_real_whitespace_or_escaped_backslashes_reads(old, new, tmp_path, capsys):
    assert old in ONE
    path = tmp_path / "fine.toml"
    path.write_text(ONE.replace(old, new, 1))
    assert main(["show", str(path)]) == 0, capsys.readouterr().err


def test_unreadable_latex_in_single_quotes_is_still_refused_where_it_stops(tmp_path, capsys):
    path = tmp_path / "typo.toml"
    path.write_text(ONE.replace(r"H = 'm g l \sin\theta'", r"H = 'm g l eta'", 1))
    code = main(["show", str(path)])
    headline, fragment, column = one_error(capsys.readouterr().err)
    assert code == 2 and "key 'H'" in headline and "unknown symbol or command 'e'" in headline
    assert fragment[column:].startswith("eta")
