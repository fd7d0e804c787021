"""Expressions in text and LaTeX models are bounded: huge exact numbers and deep nesting are refused
with one line naming the key and the limit; long pasted sums are read; messages quote a fragment.

Each planted file runs ``pendverify show`` (or ``check``) in-process under a hard bound on its CPU
time (``tests.cli_run``), so a regression that hangs fails instead of stalling the suite.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from pendverify.analytic.expression_limits import MAX_BITS, MAX_EXPONENT, MAX_NESTING
from tests.cli_run import Done, run_main
from tests.error_message import one_error

REPO = Path(__file__).resolve().parents[2]
TEXT = REPO / "examples" / "minimal_double_pendulum_text.toml"
LATEX = REPO / "examples" / "double_pendulum_latex.toml"
URDF = REPO / "urdf" / "double_pendulum.urdf"
TEXT_PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
LATEX_PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"


def run(*args: str) -> Done:
    return run_main(list(args))


def text_model(tmp_path: Path, v_prefix: str) -> Path:
    """The text double pendulum with ``v_prefix`` added in front of its V."""
    source = TEXT.read_text()
    assert 'V = "g*(' in source
    path = tmp_path / "model.toml"
    path.write_text(source.replace('V = "g*(', f'V = "{v_prefix} + g*(', 1))
    return path


def latex_model(tmp_path: Path, h_first: str, h_second: str | None = None) -> Path:
    """The LaTeX double pendulum with H replaced by the vector (h_first, h_second)."""
    source = LATEX.read_text()
    start = source.index("H = '''\n")
    end = source.index("'''", start + 8)
    second = h_second if h_second is not None else r"m_2gr_2\cos(\theta_1 + \theta_2)"
    path = tmp_path / "model.toml"
    vector = f"\\begin{{bmatrix}} {h_first} \\\\ {second} \\end{{bmatrix}}"
    path.write_text(source[:start] + f"H = '''\n{vector}\n" + source[end:])
    return path


def assert_refused(result: Done, *words: str) -> None:
    err = result.stderr.strip()
    assert result.returncode == 2, err[-2000:]
    headline, _, _ = one_error(err)
    assert "Traceback" not in err and "internal error" not in err
    assert len(headline) < 600, f"the message quotes too much ({len(headline)} characters)"
    for word in words:
        assert word in err, (word, err)


HUGE_TEXT = {
    "10**10**10": ["key 'V'", "exponent", f"±{MAX_EXPONENT}"],
    "theta1**(9**9**9)": ["key 'V'", "exponent", f"±{MAX_EXPONENT}"],
    "2**100000000": ["key 'V'", "exponent", f"±{MAX_EXPONENT}"],
    "3**1000": ["key 'V'", f"{MAX_BITS} bits"],
    "2**1000*2**1000*m1": ["key 'V'", f"{MAX_BITS} bits"],
    "1" * 400: ["key 'V'", "digits"],
    "1e400": ["key 'V'", "double"],
    "10.0**10**5": ["key 'V'", "double"],
    "exp(1000)*m1": ["key 'V'", "exp(1000)", "double"],
    "m1/(1 - 1)": ["key 'V'", "division by zero"],
}


@pytest.mark.parametrize("expr", list(HUGE_TEXT), ids=list(HUGE_TEXT))
def test_a_huge_exact_number_in_a_text_model_is_refused_naming_the_key_and_limit(tmp_path, expr):
    assert_refused(run("show", str(text_model(tmp_path, expr))), *HUGE_TEXT[expr])


def test_a_huge_number_in_a_symbols_value_is_refused_naming_the_key(tmp_path):
    source = LATEX.read_text()
    assert "[symbols]\n" in source
    path = tmp_path / "model.toml"
    path.write_text(source.replace("[symbols]\n", "[symbols]\n'\\kappa' = \"9**9**9\"\n", 1))
    assert_refused(run("show", str(path)), "symbols.\\kappa", "exponent", f"±{MAX_EXPONENT}")


@pytest.mark.parametrize(
    "latex", [r"10^{10^{10}}", r"\theta_2^{9^{9^{9}}}", r"2^{1000}2^{1000}", r"\exp(1000)m_1", "9" * 400]
)
def test_a_huge_exact_number_in_latex_is_refused_naming_the_key_and_limit(tmp_path, latex):
    result = run("show", str(latex_model(tmp_path, latex)))
    assert_refused(result, "key 'H'")
    assert any(word in result.stderr for word in (str(MAX_EXPONENT), f"{MAX_BITS} bits", "double", "digits"))


def test_small_powers_and_large_finite_floats_are_still_read(tmp_path):
    fine = "theta1**2 + 2**1000*m1 + 1e300*m1 + theta1**-3 + 2**(1/3) + theta2**1024"
    path = text_model(tmp_path, f"0*({fine})")
    result = run("show", str(path))
    assert result.returncode == 0, result.stderr


def test_2000_nested_calls_are_refused_with_the_depth_and_the_limit(tmp_path):
    text = run("show", str(text_model(tmp_path, "sin(" * 2000 + "theta1" + ")" * 2000)))
    assert_refused(text, "key 'V'", "2000 deep", f"limit is {MAX_NESTING}", "character")
    latex = run("show", str(latex_model(tmp_path, "\\sin(" * 2000 + "\\theta_1" + ")" * 2000)))
    assert_refused(latex, "key 'H'", "2000 deep", f"limit is {MAX_NESTING}")


def test_a_tower_of_powers_is_refused_as_too_deep(tmp_path):
    assert_refused(run("show", str(text_model(tmp_path, "**".join(["theta1"] * 500)))), "key 'V'", "deep")


def test_nesting_at_the_limit_is_read(tmp_path):
    depth = MAX_NESTING - 2  # the V around it adds its own brackets
    result = run("show", str(text_model(tmp_path, "0*" + "sin(" * depth + "theta1" + ")" * depth)))
    assert result.returncode == 0, result.stderr


@pytest.mark.slow
def test_a_pasted_5000_term_sum_is_read_and_checked(tmp_path):
    terms = " + ".join(f"{i}*m1*theta1**{i % 7}*cos(theta2)**{i % 5}*l1**{i % 3}" for i in range(1, 5001))
    path = text_model(tmp_path, f"{terms} - ({terms})")
    result = run("check", "--analytic", str(path), "--urdf", str(URDF), "--params", str(TEXT_PARAMS))
    assert result.returncode == 0, result.stderr[-2000:]
    assert "all checks pass" in result.stdout


def test_a_pasted_800_term_latex_sum_is_read_and_checked(tmp_path):
    terms = " + ".join(f"{i}m_1\\cos(\\theta_1)^{{{i % 4}}}" for i in range(1, 401))
    gravity = r"m_1gr_1\cos(\theta_1) + m_2g(l_1\cos(\theta_1) + r_2\cos(\theta_1 + \theta_2))"
    first = f"{gravity} + {terms} - ({terms})"
    path = latex_model(tmp_path, first)
    result = run("check", "--analytic", str(path), "--urdf", str(URDF), "--params", str(LATEX_PARAMS))
    assert result.returncode == 0, result.stderr[-2000:]
    assert "all checks pass" in result.stdout


def test_an_error_in_a_4000_character_expression_quotes_a_fragment_and_its_position(tmp_path):
    terms = " + ".join(f"{i}*m1*theta1" for i in range(1, 400))
    assert len(terms) > 4000
    result = run("show", str(text_model(tmp_path, f"{terms} + m1*rr2")))
    assert_refused(result, "key 'V'", "'rr2'", "at character")
    latex = run("show", str(latex_model(tmp_path, " + ".join(["m_1"] * 1500) + r" + \zeta")))
    assert_refused(latex, "key 'H'", "\\zeta", "character")


@pytest.mark.parametrize(
    "expr, words",
    [
        ("__import__('os').system('touch MARKER')", ["only sin, cos"]),
        ("m1.__class__", ["Attribute"]),
        ("m1 ^ 2", ["**"]),
        ("lambda: 0", ["unknown name 'lambda'"]),
        ("1/0", ["division by zero"]),
        ("sin(theta1, theta2)", ["one argument"]),
        ("'text'", ["string"]),
        ("2j", ["not a number"]),
        ("m1 $ 2", ["'$' is not allowed"]),
        ("(m1 + 2", ["not closed"]),
    ],
)
def test_what_is_not_an_expression_is_still_refused(tmp_path, expr, words):
    result = run("show", str(text_model(tmp_path, expr)))
    assert_refused(result, "key 'V'", *words)
    assert not (tmp_path / "MARKER").exists() and not Path("MARKER").exists()


def test_a_4000_character_name_is_quoted_shortened(tmp_path):
    long_name = "q" * 4000
    source = TEXT.read_text().replace('theta2 = "angle"', f'theta2 = "angle"\n{long_name}x = "sideways"', 1)
    path = tmp_path / "model.toml"
    path.write_text(source)
    assert_refused(run("show", str(path)), "coordinates.", "must be")
