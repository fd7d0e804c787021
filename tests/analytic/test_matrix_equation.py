"""The equation of motion in matrix form (``equations = ["M*ddq + C*dq + G = B*u"]``) over the file's keys.

The minimal double pendulum's parts (``examples/minimal_double_pendulum_text.toml``, and LaTeX parts
like ``examples/double_pendulum_latex.toml``) with each form of the matrix equation verify against
its URDF (every check row passes); the gravity vector's sign flipped in the equation fails
``gravity``; each malformed equation is one error with a caret under the place.
"""

from __future__ import annotations

from pathlib import Path

import pytest

import pendverify
from pendverify.analytic.matrix_equation_parse import MatrixEquationError, read_terms
from pendverify.analytic.plugin import load_model_class
from pendverify.api import read_model
from pendverify.errors import PendverifyError
from tests.error_message import one_error

REPO = Path(__file__).resolve().parents[2]
TEXT = REPO / "examples" / "minimal_double_pendulum_text.toml"
LATEX = REPO / "examples" / "double_pendulum_latex.toml"
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
SAMPLES = 60  # the special states plus 60 random ones, as tests/analytic/test_whole_equations.py

H1 = "g*((m1*r1 + m2*l1)*cos(theta1) + m2*r2*cos(theta1 + theta2))"
H2 = "g*m2*r2*cos(theta1 + theta2)"
#: C·q̇ of the file's C, written out
CV1 = "-m2*l1*r2*sin(theta2)*(2*dtheta1*dtheta2 + dtheta2**2)"
CV2 = "m2*l1*r2*sin(theta2)*dtheta1**2"


def _replace(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new)


def text_file(tmp_path: Path, equation: str, name: str = "matrix.toml", **changes) -> Path:
    """The minimal double pendulum's text file without V, its H named G, with ``equation``.

    ``changes``: key → its new TOML line(s) (None drops the key).
    """
    head, tables = TEXT.read_text().split("[coordinates]", 1)
    keys = {"M": None, "C": None, "H": None, "V": None, "D": None, "B": None}
    blocks, current = {}, None
    for line in head.splitlines():
        start = line.split(" = ", 1)[0]
        if start in keys:
            current = start
        elif line.startswith(("name", "inputs")):
            current = "keep:" + line
        elif not line.startswith((" ", "]")):
            current = None
        if current is not None:
            blocks.setdefault(current, []).append(line)
    blocks.pop("V"), blocks.pop("H")
    blocks["G"] = ["G = [", f'  "{H1}",', f'  "{H2}",', "]"]
    for key, value in changes.items():
        blocks.pop(key, None)
        if value is not None:
            blocks[key] = [value]
    body = "\n".join(line for lines in blocks.values() for line in lines)
    body += f"\nequations = [{equation!r}]\n\n[coordinates]" + tables
    path = tmp_path / name
    path.write_text(body)
    return path


def latex_file(tmp_path: Path, equation: str, name: str = "matrix_latex.toml", **changes) -> Path:
    """``examples/double_pendulum_latex.toml``'s M, its C without the friction, D, B and its H named
    G, with ``equation``; named and parametrised as the minimal double pendulum.

    ``changes``: old text → new text, applied last (a planted error).
    """
    text = LATEX.read_text()
    for old, new in {
        'name = "double_pendulum"': 'name = "minimal_double_pendulum"',
        'l2 = { kind = "length", unit = "m", doc = "length of link 2, for drawing only" }\n': "",
        "C_plus_D = '''": "C = '''",
        r"\dot{\theta}_2 + b_1 &": r"\dot{\theta}_2 &",
        r"x_4 + b_1 &": r"x_4 &",
        r"\dot{\theta}_1 & b_2": r"\dot{\theta}_1 & 0",
        r"x_3 & b_2": r"x_3 & 0",
        "\nH = '''": "\nG = '''",
        "\n[coordinates]": f"\nequations = '''{equation}'''\n\n[coordinates]",
        **changes,
    }.items():
        text = _replace(text, old, new)
    path = tmp_path / name
    path.write_text(text)
    return path


def _check(path: Path) -> pendverify.CheckReport:
    return pendverify.check(path, URDF, PARAMS, samples=SAMPLES, explain=False)


TEXT_FORMS = {
    "standard": ("M*ddq + C*dq + D*dq + G = B*u", {}),
    "arguments": ("M(q)*ddq + C(q, dq)*dq + D*dq + G(q) = B*u", {}),
    "H and tau alone": ("M*ddq + C*dq + D*dq + H = tau", {"B": None, "G": f'H = ["{H1}", "{H2}"]'}),
    "rearranged": ("M*ddq = B*u - C*dq - D*dq - G", {}),
    "G on the right": ("M*ddq + C*dq + D*dq = u + G", {"B": None, "G": f'G = ["-({H1})", "-({H2})"]'}),
    "bias h": ("M*ddq + h(q, dq) + D*dq = B*u", {"C": None, "G": f'h = ["{CV1} + {H1}", "{CV2} + {H2}"]'}),
    "zero on the right": ("-M*ddq - C*dq - D*dq - G + B*u = 0", {}),
}
#: the LaTeX file's B line: dropped where τ alone stands for B u with B = I
NO_B = "B = '\\begin{bmatrix} 1 & 0 \\\\ 0 & 1 \\end{bmatrix}'\n"
LATEX_FORMS = {
    "standard, τ alone": (r"M(q)\ddot{q} + C(q,\dot{q})\dot{q} + D\dot{q} + G(q) = \tau", {NO_B: ""}),
    "bold, rearranged": (
        r"\mathbf{M}(\mathbf{q})\ddot{\mathbf{q}} = B\mathbf{u} - \mathbf{C}(\mathbf{q},\dot{\mathbf{q}})"
        r"\,\dot{\mathbf{q}} - D \cdot \dot{\mathbf{q}} - \mathbf{G}(\mathbf{q})",
        {},
    ),
    "unicode": ("M q̈ + C q̇ + D q̇ + G = B τ", {}),
}


@pytest.mark.parametrize("form", list(TEXT_FORMS))
def test_each_sympy_form_verifies(form, tmp_path):
    equation, changes = TEXT_FORMS[form]
    report = _check(text_file(tmp_path, equation, **changes))
    assert report.status == "pass", (form, report)
    assert {"crba", "rnea", "gravity", "aba", "energy", "damping"} <= set(report.checks), form
    assert all(report[c].status == "pass" for c in report.checks), (form, report)
    if form != "bias h":  # the bias h gives C·q̇ only: coriolis and skew need C itself
        assert {"coriolis", "skew"} <= set(report.checks), form


@pytest.mark.parametrize("form", list(LATEX_FORMS))
def test_each_latex_form_verifies(form, tmp_path):
    equation, changes = LATEX_FORMS[form]
    report = _check(latex_file(tmp_path, equation, **changes))
    assert report.status == "pass", (form, report)
    assert {"crba", "rnea", "gravity", "coriolis", "skew", "aba", "energy", "damping"} <= set(report.checks)
    assert all(report[c].status == "pass" for c in report.checks), (form, report)


def test_the_gravity_sign_wrong_in_the_equation_fails_gravity(tmp_path):
    """``+ G = B u`` written ``− G = B u`` while G is the true gravity vector: H = −G, gravity fails."""
    report = _check(text_file(tmp_path, "M*ddq + C*dq + D*dq - G = B*u"))
    assert report["gravity"].status == "fail"
    latex = latex_file(tmp_path, r"M\ddot{q} + C\dot{q} + D\dot{q} = B u + G")
    assert _check(latex)["gravity"].status == "fail"


def test_a_damping_sign_wrong_in_the_equation_fails_damping(tmp_path):
    report = _check(text_file(tmp_path, "M*ddq + C*dq - D*dq + G = B*u"))
    assert report["damping"].status == "fail"


def test_show_says_where_each_part_came_from(tmp_path):
    equation, changes = TEXT_FORMS["G on the right"]
    derived = {e.method: e.derived for e in read_model(text_file(tmp_path, equation, **changes)).equations}
    assert derived["gravity"].startswith("−G: the matrix equation puts G where"), derived
    assert derived["input_matrix"].startswith("I: the matrix equation's u alone"), derived
    assert derived["mass_matrix"] is None and derived["coriolis_matrix"] is None
    standard = read_model(text_file(tmp_path, TEXT_FORMS["standard"][0], name="s.toml")).equations
    derived = {e.method: e.derived for e in standard}
    assert derived["gravity"].startswith("G: the matrix equation puts G where"), derived
    assert derived["input_matrix"] is None
    bias = read_model(
        text_file(tmp_path, *TEXT_FORMS["bias h"][:1], name="h.toml", **TEXT_FORMS["bias h"][1])
    )
    derived = {e.method: e.derived for e in bias.equations}
    assert derived["coriolis_force"] == "from the matrix equation's f: the part quadratic in q̇", derived


def test_no_gravity_term_is_zero_gravity_and_fails(tmp_path):
    path = text_file(tmp_path, "M*ddq + C*dq + D*dq = B*u", G=None)
    assert _check(path)["gravity"].status == "fail"


REFUSALS = [
    # (equation, changes, words in the headline, the text at the caret)
    ("M*ddq + K*dq + D*dq + G = B*u", {}, "unknown name 'K'", "K*dq"),
    ("M*dq + C*dq + D*dq + G = B*u", {}, "M multiplies q̈, not this", "dq + C"),
    ("M*ddq + C*ddq + D*dq + G = B*u", {}, "C multiplies q̇, not this", "ddq + D"),
    ("M*ddq + C + D*dq + G = B*u", {}, "C is a matrix: it multiplies q̇", " + D*dq"),
    ("M*ddq + C*dq + D*dq + G*dq = B*u", {}, "G is a vector: nothing multiplies it", "dq = B"),
    ("M*ddq + C*dq + C*dq + D*dq + G = B*u", {}, "C appears twice", "C*dq + D"),
    ("M*ddq + C*dq + D*dq + G = B*u + tau", {}, "tau appears twice", "tau"),
    ("M*ddq + C*dq + D*dq + G = B*u", {"M": None}, "M is not given in the file", "M*ddq"),
    ("C*dq + D*dq + G = B*u", {}, "no M q̈ term", "C*dq"),
    ("M*ddq + C*dq + D*dq + G + dq = B*u", {}, "q̇ without its matrix", "dq = B"),
    ("M(t)*ddq + C*dq + D*dq + G = B*u", {}, "an argument of M must be q or q̇", "t)*ddq"),
    ("M*ddq + C*dq + D*dq + G = B*u = 0", {}, "a matrix equation has one '='", "= 0"),
    ("M*ddq + C*dq + D*dq + G + = B*u", {}, "a term is missing here", "= B*u"),
    ("M*ddq + C*dq + D*dq + G = B*u ; x", {}, "unexpected ';'", "; x"),
    ("M*ddq + C*dq + D*dq + 2*G = B*u", {}, "unexpected '2'", "2*G"),
    ("M*ddq + C*dq + 0 + G = B*u", {}, "0 stands only alone", "0 + G"),
]


@pytest.mark.parametrize("equation, changes, words, at", REFUSALS)
def test_what_is_not_a_matrix_equation_is_refused_with_a_caret(equation, changes, words, at, tmp_path):
    with pytest.raises(PendverifyError) as info:
        load_model_class(text_file(tmp_path, equation, **changes))
    headline, fragment, column = one_error(str(info.value))
    assert "matrix.toml: key 'equations'" in headline and words in headline, headline
    assert column is not None and fragment[column:].startswith(at), (fragment, column, at)


def test_a_latex_refusal_points_at_the_place(tmp_path):
    equation = r"M(q)\ddot{q} + C(q,\dot{q})\ddot{q} + D\dot{q} + G(q) = B u"
    with pytest.raises(PendverifyError) as info:
        load_model_class(latex_file(tmp_path, equation))
    headline, fragment, column = one_error(str(info.value))
    assert "C multiplies q̇, not this" in headline, headline
    assert fragment[column:].startswith(r"\ddot{q} + D"), (fragment, column)


@pytest.mark.parametrize(
    "equation, changes, words",
    [
        (
            "M*ddq + C*dq + G = B*u",
            {},
            "key 'D': given, but the matrix equation under 'equations' does not use it",
        ),
        ("M*ddq + C*dq + D*dq + G = B*u", {"H": f'H = ["{H1}", "{H2}"]'}, "key 'H': given, but"),
        ("M*ddq + C*dq + D*dq + G = w", {"B": None}, "the file declares no disturbances w"),
        ("M*ddq + C*dq + D*dq + G + H = B*u", {"H": f'H = ["{H1}", "{H2}"]'}, "give G or H"),
        ("M*ddq + C*dq + D*dq + G = B*u", {"f": 'f = ["0", "0"]'}, "key 'f': not with a matrix equation"),
    ],
)
def test_keys_the_equation_does_not_match_are_refused_in_one_line(equation, changes, words, tmp_path):
    with pytest.raises(PendverifyError) as info:
        load_model_class(text_file(tmp_path, equation, **changes))
    headline, _, _ = one_error(str(info.value))
    assert words in headline, headline


def test_inputs_without_an_input_term_are_refused(tmp_path):
    with pytest.raises(PendverifyError, match="declares inputs tau1, tau2: the matrix equation needs B u"):
        load_model_class(text_file(tmp_path, "M*ddq + C*dq + D*dq + G = 0", B=None))


def test_G_without_a_matrix_equation_is_refused(tmp_path):
    path = text_file(tmp_path, "unused = 0")
    path.write_text(_replace(path.read_text(), "equations = ['unused = 0']\n", ""))
    with pytest.raises(PendverifyError, match="key 'G': names a term of a matrix equation"):
        load_model_class(path)


def test_a_coordinate_named_q_keeps_scalar_equations(tmp_path):
    """With a coordinate q, ``ddq`` is its acceleration: the string is a scalar equation."""
    path = tmp_path / "one.toml"
    path.write_text(
        'name = "one"\ninputs = ["u"]\nequations = ["m*ddq + m*g*sin(q) = u"]\n'
        '[coordinates]\nq = "angle"\n[parameters]\nm = { kind = "mass" }\ng = { kind = "gravity" }\n'
    )
    spec = load_model_class(path).text_spec
    assert "coefficients of the accelerations" in spec.derived["M"]


@pytest.mark.parametrize(
    "equation, latex, read",
    [
        (
            r"\mathbf{M}\ddot{\mathbf{q}} + \mathbf{h}(\mathbf{q},\dot{\mathbf{q}})"
            r" = \mathbf{B}\boldsymbol{\tau}",
            True,
            [(1, "M", "ddq"), (1, "h", None), (-1, "B", "tau")],
        ),
        (r"\mathbf{\ddot q}\,? = 0", True, None),
        (
            r"M\ddot q + W w = B u - G",
            True,
            [(1, "M", "ddq"), (1, "W", "w"), (-1, "B", "u"), (1, "G", None)],
        ),
        ("-M*ddq - h + B*u = 0", False, [(-1, "M", "ddq"), (-1, "h", None), (1, "B", "u")]),
        ("0 = M*ddq + W*w - tau", False, [(-1, "M", "ddq"), (-1, "W", "w"), (1, None, "tau")]),
    ],
)
def test_terms_and_their_signs(equation, latex, read):
    """Each term moved to the left-hand side: (sign, key, vector) as written, LaTeX fonts dropped."""
    if read is None:
        with pytest.raises(MatrixEquationError, match="unexpected '\\?'"):
            read_terms(equation, latex)
        return
    terms = read_terms(equation, latex)
    found = [(t.sign, t.key and t.key.name, t.vector and t.vector.name) for t in terms]
    assert found == read, found


def test_a_V_that_disagrees_with_the_equations_gravity_is_refused(tmp_path):
    v = 'V = "g*((m1*r1 + m2*l1)*sin(theta1) + m2*r2*sin(theta1 + theta2))"'
    assert load_model_class(text_file(tmp_path, "M*ddq + C*dq + D*dq + G = B*u", V=v)).text_spec
    with pytest.raises(PendverifyError, match=r"key 'V': ∂V/∂q is not the gravity vector H \(−G: the matrix"):
        load_model_class(text_file(tmp_path, "M*ddq + C*dq + D*dq - G = B*u", name="bad.toml", V=v))
