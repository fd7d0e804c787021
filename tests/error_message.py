"""The shape of a bad-input message on stderr: one error, with a caret under the place when known.

A message is its headline (``pendverify: error: FILE: key 'K': rule``) on one line, followed —
for an expression read by ``text_expression`` or ``latex_parse`` at a known place — by the
fragment of the expression (at most ``EXCERPT_WIDTH`` characters and the "…" of its cut ends)
and a line holding only a caret under the place (``pendverify.errors.ExcerptError``).
"""

from __future__ import annotations

from pendverify.errors import EXCERPT_WIDTH


def one_error(err: str) -> tuple[str, str, int | None]:
    """(the headline, the fragment or "", the caret's column in the fragment or None); asserts the shape."""
    lines = err.strip("\n").splitlines()
    assert len(lines) in (1, 3), err[-2000:]
    if len(lines) == 1:
        return lines[0], "", None
    headline, fragment, caret = lines
    assert fragment.startswith("  ") and caret.startswith("  "), err[-2000:]
    assert len(fragment) - 2 <= EXCERPT_WIDTH + 2, f"the fragment quotes too much: {fragment[:200]}…"
    assert caret.rstrip().endswith("^") and set(caret.rstrip()[:-1]) <= {" "}, err[-2000:]
    column = len(caret.rstrip()) - 1 - 2
    assert column <= len(fragment) - 2, err[-2000:]
    return headline, fragment[2:], column
