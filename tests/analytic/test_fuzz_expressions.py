"""Property-based fuzz of the expressions of text and LaTeX models: random nesting, huge exponents,
huge numbers, long sums — ``pendverify show`` ends with status 0, 1 or 2, never 3, never a hang.

Hypothesis builds an expression (SymPy syntax, or LaTeX) and puts it into the text double
pendulum's V, or into the first entry of the LaTeX double pendulum's H; ``main(["show", …])``
runs in-process under a hard bound (``HARD_LIMIT_S`` seconds of CPU time, ``tests.hard_limit``:
a hang raises out of it and fails the example; load on the machine does not).  Status 2 must
come with exactly one short error line, and no run prints a traceback.  Seeded and without an
example database, so every run tries the same inputs.
"""

from __future__ import annotations

import contextlib
import io
import signal
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, seed, settings
from hypothesis import strategies as st

from pendverify.cli import main
from tests.error_message import one_error
from tests.hard_limit import hard_limit

REPO = Path(__file__).resolve().parents[2]
TEXT = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
LATEX = (REPO / "examples" / "double_pendulum_latex.toml").read_text()
HARD_LIMIT_S = 30
FUZZ_SEED = 20261201
FUZZ = settings(max_examples=30, deadline=None, database=None, suppress_health_check=list(HealthCheck))

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGPROF"), reason="needs SIGPROF for the hard bound")


def run_show(model_text: str) -> tuple[int, str]:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "model.toml"
        path.write_text(model_text)
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            with hard_limit(HARD_LIMIT_S) as limit:
                code = main(["show", str(path)])
    assert not limit.fired, f"show swallowed its hang: {limit.describe()}"
    return code, err.getvalue()


def assert_contract(code: int, err: str) -> None:
    assert code in (0, 1, 2), err[-2000:]
    assert "Traceback" not in err and "internal error" not in err, err[-2000:]
    if code == 2:
        headline, _, _ = one_error(err)
        assert len(headline) < 1000, f"the message quotes too much: {headline[:300]}…"


# --- SymPy syntax ------------------------------------------------------------------------------
TEXT_LEAVES = st.sampled_from(
    ["theta1", "theta2", "m1", "g", "l1", "pi", "0", "1", "2", "0.5", "1e300", "1e400", "9" * 400,
     "10**10**10", "9**9**9", "2**100000000", "3**1000", "2**1024", "1/0", "0**-1", "rr2", "'s'"]
)  # fmt: skip


def _text_node(children):
    binary = st.tuples(children, st.sampled_from(["+", "-", "*", "/", "**"]), children).map(
        lambda t: f"({t[0]} {t[1]} {t[2]})"
    )
    call = st.tuples(st.sampled_from(["sin", "cos", "tan", "sqrt", "exp"]), children).map(
        lambda t: f"{t[0]}({t[1]})"
    )
    unary = children.map(lambda c: f"-{c}")
    power_tower = st.tuples(children, st.integers(2, 6)).map(lambda t: "**".join([t[0]] * t[1]))
    return st.one_of(binary, call, unary, power_tower)


def long_sum(leaf: str, terms: int) -> str:
    return " + ".join(f"{leaf}*theta1**{k % 9}" for k in range(terms))


TEXT_EXPRESSIONS = st.one_of(
    st.recursive(TEXT_LEAVES, _text_node, max_leaves=12),
    st.tuples(st.integers(1, 3000), st.sampled_from(["sin(", "(", "cos(-"])).map(
        lambda t: t[1] * t[0] + "theta1" + ")" * t[0]
    ),
    st.tuples(st.integers(1, 6000), TEXT_LEAVES).map(
        lambda t: " + ".join([f"{t[1]}*theta1**{t[0] % 9}"] * t[0])
    ),
    st.integers(0, 10**6).map(lambda k: f"theta1**{k}"),
    st.integers(0, 2000).map(lambda k: f"(theta1 + m1)**{k} * 0"),
)


@seed(FUZZ_SEED)
@FUZZ
@given(expr=TEXT_EXPRESSIONS)
def test_any_text_expression_is_read_or_refused_in_one_line(expr):
    assert 'V = "g*(' in TEXT
    code, err = run_show(TEXT.replace('V = "g*(', f'V = "{expr} + g*(', 1))
    assert_contract(code, err)


# --- LaTeX -------------------------------------------------------------------------------------
LATEX_LEAVES = st.sampled_from(
    [r"\theta_1", r"\theta_2", "m_1", "g", "l_1", "2", "0.5", "9" * 400, r"10^{10^{10}}",
     r"9^{9^{9}}", r"\theta_2^{9^{9^{9}}}", r"2^{1000}", r"\zeta", "x_3"]
)  # fmt: skip


def _latex_node(children):
    binary = st.tuples(children, st.sampled_from(["+", "-", r"\cdot", " ", "/"]), children).map(
        lambda t: f"({t[0]} {t[1]} {t[2]})"
    )
    frac = st.tuples(children, children).map(lambda t: rf"\frac{{{t[0]}}}{{{t[1]}}}")
    power = st.tuples(children, children).map(lambda t: f"{{{t[0]}}}^{{{t[1]}}}")
    call = st.tuples(st.sampled_from([r"\sin", r"\cos", r"\exp", r"\sqrt"]), children).map(
        lambda t: f"{t[0]}{{{t[1]}}}" if t[0] == r"\sqrt" else f"{t[0]}({t[1]})"
    )
    return st.one_of(binary, frac, power, call)


LATEX_EXPRESSIONS = st.one_of(
    st.recursive(LATEX_LEAVES, _latex_node, max_leaves=12),
    st.integers(1, 3000).map(lambda k: "\\sin(" * k + r"\theta_1" + ")" * k),
    st.integers(1, 3000).map(lambda k: "{" * k + r"\theta_1" + "}" * k),
    st.integers(1, 900).map(lambda k: " + ".join([r"m_1\cos(\theta_1)^{2}"] * k)),
    st.integers(0, 10**6).map(lambda k: rf"\theta_1^{{{k}}}"),
)


@seed(FUZZ_SEED)
@FUZZ
@given(expr=LATEX_EXPRESSIONS)
def test_any_latex_expression_is_read_or_refused_in_one_line(expr):
    start = LATEX.index("H = '''\n")
    end = LATEX.index("'''", start + 8)
    second = r"m_2gr_2\cos(\theta_1 + \theta_2)"
    vector = f"\\begin{{bmatrix}} {expr} \\\\ {second} \\end{{bmatrix}}"
    code, err = run_show(LATEX[:start] + f"H = '''\n{vector}\n" + LATEX[end:])
    assert_contract(code, err)
