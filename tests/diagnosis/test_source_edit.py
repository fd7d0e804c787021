"""The repair as a minimal edit of the user's own text (``pendverify.diagnosis.source_edit``): the
pieces, and the fall-back to the whole entry printed when the file's text is not the entry."""

from __future__ import annotations

from pathlib import Path

import sympy as sp

from pendverify import api
from pendverify.diagnosis.notation import Notation
from pendverify.diagnosis.source_edit import latex_style, terms

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _pieces(text):
    return [(text[p] if p >= 0 else "", text[a:b]) for p, a, b in terms(text)]


def test_terms_split_at_the_top_level_signs_only():
    assert _pieces("-a + b") == [("-", "a"), ("+", "b")]
    assert _pieces("a - b*c**-1 + 1e-5*x") == [("", "a"), ("-", "b*c**-1"), ("+", "1e-5*x")]
    assert _pieces("\\frac{a-b}{2} - c^{-1}") == [("", "\\frac{a-b}{2}"), ("-", "c^{-1}")]
    assert _pieces("m_2g(l_1\\cos(\\theta_1) + r) + b") == [("", "m_2g(l_1\\cos(\\theta_1) + r)"), ("+", "b")]


def test_sympys_functions_are_written_as_a_derivation_writes_them():
    theta1, x, y = sp.symbols("theta_1 x y")
    assert latex_style(sp.latex(sp.cos(theta1) * sp.sin(x + y))) == "\\sin(x + y) \\cos\\theta_{1}"
    assert latex_style(sp.latex(sp.sin(sp.cos(sp.Symbol("theta"))))) == "\\sin(\\cos\\theta)"
    assert latex_style(sp.latex(sp.sin(x))) == "\\sin x"


def test_an_entry_whose_text_is_not_in_the_file_is_printed_whole():
    """An entry the file does not write as ``old`` (a planted model, a file changed since): SymPy's
    LaTeX of both, as before, never a string the file does not hold."""
    cls = api.load_model(EXAMPLES / "cart_pole_latex.toml")
    notation = Notation.of(cls)
    mp, g, r, theta = (next(s for s in notation.names if s.name == n) for n in ("mp", "g", "r", "theta"))
    written = mp * g * r * sp.sin(theta)  # the file's H[2] is −m_p g r sin θ
    assert notation.entry_edit("gravity", 1, written, -written) == (
        notation.render(written),
        notation.render(-written),
    )
    # the file's own entry gets the user's text
    assert notation.entry_edit("gravity", 1, -written, written) == (
        "-m_p g r\\sin\\theta",
        "m_p g r\\sin\\theta",
    )


def test_a_word_typed_for_another_is_replaced_in_the_users_own_text():
    """``\\sin`` written for ``\\cos`` (or one parameter for another) is one word of the user's text
    replaced, the rest kept as written; a change no single word makes is not shown as one."""
    cls = api.load_model(EXAMPLES / "cart_pole_latex.toml")
    notation = Notation.of(cls)
    mp, g, r, theta = (next(s for s in notation.names if s.name == n) for n in ("mp", "g", "r", "theta"))
    written = -mp * g * r * sp.sin(theta)
    assert notation.entry_edit("gravity", 1, written, -mp * g * r * sp.cos(theta)) == (
        "-m_p g r\\sin\\theta",
        "-m_p g r\\cos\\theta",
    )
    # twice the term is no word of the text: the term rewritten, never a word that reads otherwise
    old, new = notation.entry_edit("gravity", 1, written, 2 * written)
    assert old == "-m_p g r\\sin\\theta" and new != old and "\\cos" not in new


def test_a_minimal_edit_past_its_bound_prints_the_entry_whole(monkeypatch):
    """A comparison larger than ``MAX_EDIT_OPS`` (a q̈ written out, whose one exact comparison took
    19 s) or past ``EDIT_SECONDS`` of CPU time: the edited entry printed whole, in SymPy's LaTeX,
    beside the user's text, never an edited string left unconfirmed."""
    from pendverify.diagnosis import source_edit

    cls = api.load_model(EXAMPLES / "cart_pole_latex.toml")
    notation = Notation.of(cls)
    mp, g, r, theta = (next(s for s in notation.names if s.name == n) for n in ("mp", "g", "r", "theta"))
    written = -mp * g * r * sp.sin(theta)
    whole = ("-m_p g r\\sin\\theta", notation.render(-written))  # the file's text, the edit whole
    assert notation.entry_edit("gravity", 1, written, -written) == (
        "-m_p g r\\sin\\theta",
        "m_p g r\\sin\\theta",
    )
    monkeypatch.setattr(source_edit, "MAX_EDIT_OPS", -1)
    assert notation.entry_edit("gravity", 1, written, -written) == whole
    monkeypatch.setattr(source_edit, "MAX_EDIT_OPS", 10**9)
    monkeypatch.setattr(source_edit, "EDIT_SECONDS", -1.0)
    assert notation.entry_edit("gravity", 1, written, -written) == whole
