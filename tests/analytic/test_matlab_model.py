"""MATLAB/Octave ``.m`` files read as data (``pendverify.analytic.matlab_parse``, ``matlab_model``).

Each syntax test writes a function in one of the forms ``matlabFunction`` and hand derivations
use and compares what is read with the value MATLAB's own rules give, worked out by hand in the
test (column-major ``reshape``, ``^`` chaining from the left, unary minus below ``^``, ``[a -b]``
two elements).  The hostile inputs are refused in one line at their place, and nothing runs.
"""

from __future__ import annotations

import pytest
import sympy as sp

from pendverify.analytic.matlab_parse import MAX_TREE, VectorArgument, evaluate, parse_function
from pendverify.analytic.matlab_source import SourceError
from pendverify.analytic.text_model import load_text_model
from pendverify.errors import ExcerptError, PendverifyError
from pendverify.numerics.codegen.cache import forget, model_key
from tests.cli_run import run_main
from tests.error_message import one_error

a, b, c, d, x = sp.symbols("a b c d x", real=True)


def read(tmp_path, text: str, **bindings):
    path = tmp_path / "f.m"
    path.write_text(text)
    return {k: o.value for k, o in evaluate(parse_function(path, text), bindings).items()}


def test_matlabfunction_layout(tmp_path):
    """Unpacked vector arguments, temporaries, a column-major reshape and a nargout block."""
    text = (
        "function [W,RHS] = dyn(in1,F,in3)\n%DYN\n%    [W,RHS] = DYN(IN1,F,IN3)\n\n"
        "q = in1(1,:);\nL = in3(2,:);\nt2 = cos(q);\nt3 = L.*t2.*2.0;\n"
        "W = reshape([L.^2,t3,-t3,1.0./2.0],[2,2]);\n"
        "if nargout > 1\n    RHS = [F;-L.*sin(q).*9.81];\nend\n"
    )
    q, L, F = sp.symbols("q L F")
    out = read(tmp_path, text, in1=VectorArgument("in1", (q, x)), F=F, in3=VectorArgument("in3", (a, L)))
    assert out["W"] == sp.ImmutableMatrix(
        [[L**2, -2 * L * sp.cos(q)], [2 * L * sp.cos(q), sp.Rational(1, 2)]]
    )
    assert out["RHS"] == sp.ImmutableMatrix([F, -sp.Rational(981, 100) * L * sp.sin(q)])


def test_row_oriented_vector_argument(tmp_path):
    """``in1(:,2)``: matlabFunction indexes a row vector argument by column."""
    out = read(tmp_path, "function y = f(in1)\ny = in1(:,2).*in1(1);\n", in1=VectorArgument("in1", (a, b)))
    assert out["y"] == a * b


@pytest.mark.parametrize(
    ("expression", "expected"),
    [
        ("2^3^2", sp.Integer(64)),  # ^ chains from the left
        ("-a^2", -(a**2)),  # unary minus is below ^
        ("a.*-4.0", -4 * a),  # a sign right after an operator
        ("2^-1", sp.Rational(1, 2)),
        ("1.2e+1./a", 12 / a),
        ("a' + b.'", a + b),  # transposes of scalars
        ("(a+b)*(c-d)/2", (a + b) * (c - d) / 2),
        ("atan2(a, b) + abs(c)", sp.atan2(a, b) + sp.Abs(c)),
        ("3./a", 3 / a),  # 3./a is 3 ./ a
    ],
)
def test_operators_follow_matlab(tmp_path, expression, expected):
    out = read(tmp_path, f"function y = f(a,b,c,d)\ny = {expression};\n", a=a, b=b, c=c, d=d)
    assert sp.simplify(out["y"] - expected) == 0


def test_matrix_literals_continuations_and_comments(tmp_path):
    text = (
        "%{\nA block comment: y = eval('x');\n%}\n"
        "function [m, n, k] = f(a, b)  % a trailing comment\n"
        "m = [a -b; a - b, ...  a continuation\n      b];\n"
        "n = [a b]';\n"
        "k = zeros(2,2);\nk(2,1) = a;\nk(3,3) = b;\r\n"
        "end\n"
    )
    out = read(tmp_path, text, a=a, b=b)
    assert out["m"] == sp.ImmutableMatrix([[a, -b], [a - b, b]])
    assert out["n"] == sp.ImmutableMatrix([a, b])
    assert out["k"] == sp.ImmutableMatrix([[0, 0, 0], [a, 0, 0], [0, 0, b]])


def test_structure_and_placeholder_arguments(tmp_path):
    out = read(tmp_path, "function y = f(~, p)\ny = p.m1 * p.l;\n", p=_struct(m1=a, l=b))
    assert out["y"] == a * b


def _struct(**fields):
    from pendverify.analytic.matlab_parse import StructArgument

    return StructArgument("p", fields)


def test_a_script_assigns_its_outputs(tmp_path):
    out = read(tmp_path, "M = [a, 0; 0, b];\nG = [0; a*9.81];\n", a=a, b=b)
    assert set(out) == {"M", "G"}


@pytest.mark.parametrize(
    ("body", "why"),
    [
        ("y = eval('a');", "'eval' runs code"),
        ("y = system('touch {sentinel}');", "'system' runs code"),
        ("!touch {sentinel}", "'!' runs a shell command"),
        ("y = feval(@sin, a);", "'feval' runs code"),
        ("y = a.^99999;", "exponent"),
        ("y = " + "(" * 150 + "a" + ")" * 150 + ";", "nested more than 100 deep"),
        ("y = 1e400;", "beyond a double's range"),
        ("for k = 1:3\ny = a;\nend", "'for' is not read"),
        ("y = 'text';", "character array"),
        ("if a > 1\ny = a;\nend", "only the 'if nargout > K' blocks"),
        ("y = b2;", "unknown name 'b2'"),
        ("y = [a, b; a];", "different lengths"),
    ],
)
def test_hostile_and_unread_input_is_refused_at_its_place(tmp_path, body, why):
    sentinel = tmp_path / "ran"
    text = "function y = f(a, b)\n" + body.format(sentinel=sentinel) + "\n"
    path = tmp_path / "f.m"
    path.write_text(text)
    with pytest.raises(SourceError) as caught:
        evaluate(parse_function(path, text), {"a": a, "b": b})
    assert why in caught.value.why and caught.value.line >= 2
    assert not sentinel.exists()


def test_a_doubling_chain_is_stopped_before_it_grows_past_the_bound(tmp_path):
    lines = ["function y = f(a)", "t1 = a + 1;"]
    lines += [f"t{k + 1} = t{k}.*t{k} + t{k};" for k in range(1, 40)]
    lines += ["y = t40;"]
    text = "\n".join(lines) + "\n"
    path = tmp_path / "f.m"
    with pytest.raises(SourceError) as caught:
        evaluate(parse_function(path, text), {"a": a})
    assert f"{MAX_TREE:,} nodes" in caught.value.why and caught.value.line < 30


# ---------------------------------------------------------------- a declaration of .m files

DECLARATION = """name = "pendulum_m"
M = "M"
H = "G"
C = [["0"]]
[coordinates]
theta = "angle"
[parameters]
m = {{ kind = "mass" }}
l = {{ kind = "length" }}
g = {{ kind = "gravity" }}
[matlab]
files = ["pend.m"]
{arguments}
"""
PENDULUM = (
    "function [M,G] = pend(in1,m,l,g)\nM = m.*l.^2;\nif nargout > 1\n    G = g.*l.*m.*sin(in1(1,:));\nend\n"
)


def _declaration(tmp_path, arguments='[matlab.arguments]\nin1 = ["theta"]', body=PENDULUM):
    (tmp_path / "pend.m").write_text(body)
    path = tmp_path / "pend.toml"
    path.write_text(DECLARATION.format(arguments=arguments))
    return path


def test_a_declaration_reads_its_functions(tmp_path):
    cls = load_text_model(_declaration(tmp_path))
    theta, m, length, g = (sp.Symbol(n) for n in ("theta", "m", "l", "g"))
    spec = cls.text_spec
    plain = {
        s: sp.Symbol(s.name) for s in spec.equations["M"].free_symbols | spec.equations["H"].free_symbols
    }
    assert spec.equations["M"].xreplace(plain) == sp.Matrix([[m * length**2]])
    assert spec.equations["H"].xreplace(plain) == sp.Matrix([g * length * m * sp.sin(theta)])


def test_an_undeclared_argument_is_named_with_the_fix(tmp_path):
    with pytest.raises(ExcerptError) as caught:
        load_text_model(_declaration(tmp_path, arguments=""))
    assert "pend.m, line 4" in caught.value.headline
    assert "argument 'in1' of pend is not declared" in caught.value.headline


def test_a_declared_name_that_does_not_exist_is_refused(tmp_path):
    with pytest.raises(
        PendverifyError, match=r"key 'matlab.arguments.in1': 'thetaa' is not a declared name.*theta"
    ):
        load_text_model(_declaration(tmp_path, arguments='[matlab.arguments]\nin1 = ["thetaa"]'))


def test_a_wrong_shape_names_both(tmp_path):
    body = PENDULUM.replace("M = m.*l.^2;", "M = [m, l];")
    with pytest.raises(PendverifyError, match=r"key 'M': M of pend.m is 1×2; M is 1×1"):
        load_text_model(_declaration(tmp_path, body=body))


def test_the_error_is_one_message_with_a_caret(tmp_path):
    path = _declaration(tmp_path, body=PENDULUM.replace("m.*l.^2", "m.*l.^2 + system('ls')"))
    done = run_main(["show", str(path)])
    headline, fragment, column = one_error(done.stderr.removeprefix("pendverify: error: "))
    assert done.returncode == 2 and "pend.m, line 2, column" in headline and "'system' runs code" in headline
    assert fragment[column:].startswith("system")


def test_a_m_file_given_alone_says_how_to_declare_it(tmp_path):
    (tmp_path / "pend.m").write_text(PENDULUM)
    done = run_main(["show", str(tmp_path / "pend.m")])
    assert done.returncode == 2 and "read through a declaration" in done.stderr
    assert 'files = ["pend.m"]' in done.stderr


def test_editing_a_m_file_changes_the_generated_code_key(tmp_path):
    """The code cache keys on the .m files too: an edited function is never run from stale code."""
    path = _declaration(tmp_path)
    before = model_key(load_text_model(path))
    (tmp_path / "pend.m").write_text(PENDULUM.replace("m.*l.^2", "2.*m.*l.^2"))
    forget()
    after = model_key(load_text_model(path))
    assert before is not None and after is not None and before != after


def test_an_unsymmetric_matrix_names_balance_equations(tmp_path):
    """A mass matrix that is not symmetric is refused (a typo's first sign), naming the way to
    declare balance equations, whose matrix need not be."""
    body = "M = [m, l; 2*l, m];\nf = [0; -m*g*l*sin(theta)];\n"
    (tmp_path / "eq.m").write_text(body)
    declaration = DECLARATION.format(arguments="").replace('files = ["pend.m"]', 'files = ["eq.m"]')
    declaration = declaration.replace('M = "M"\nH = "G"\nC = [["0"]]\n', 'M = "M"\nf = "f"\n')
    declaration = declaration.replace("[coordinates]\ntheta", "[coordinates]\ntheta")
    path = tmp_path / "eq.toml"
    path.write_text(declaration.replace('theta = "angle"', 'theta = "angle"\nphi = "angle"'))
    with pytest.raises(PendverifyError, match=r"key 'M': not symmetric.*declare balance = true"):
        load_text_model(path)
    path.write_text(path.read_text().replace('name = "pendulum_m"', 'name = "pendulum_m"\nbalance = true'))
    cls = load_text_model(path)
    assert cls.text_spec.derived["qddot"] == "M⁻¹ f of the balance equations"


def test_a_certificate_takes_m_files_beside_the_declaration_only(tmp_path):
    """A certificate's bundle holds the .m files beside the model file: one elsewhere is refused
    before any work, naming it; one beside it is embedded by its name."""
    from pendverify.certify.model_source import ModelSource

    path = _declaration(tmp_path)
    assert ModelSource.of_file(path).companions == (("pend.m", PENDULUM),)
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "pend.m").write_text(PENDULUM)
    path.write_text(path.read_text().replace('files = ["pend.m"]', 'files = ["sub/pend.m"]'))
    with pytest.raises(
        PendverifyError, match=r"key 'matlab.files': .*sub/pend.m is not beside the model file"
    ):
        ModelSource.of_file(path)


def test_a_file_past_the_size_bound_is_one_line(tmp_path, monkeypatch):
    import pendverify.analytic.matlab_parse as matlab_parse

    monkeypatch.setattr(matlab_parse, "MAX_FILE_BYTES", 64)
    path = _declaration(tmp_path)
    done = run_main(["show", str(path)])
    headline, fragment, column = one_error(done.stderr.removeprefix("pendverify: error: "))
    assert done.returncode == 2 and fragment == "" and column is None
    assert "key 'matlab.files'" in headline and "a model file is read up to 64 bytes" in headline
