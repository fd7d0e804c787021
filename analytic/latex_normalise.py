"""LaTeX text made canonical for the grammar of ``pendverify.analytic.latex_parse``.

``normalise`` rewrites what only typesets (spacing, ``\\left``/``\\right``, fonts,
``\\underbrace``) and the spellings of one thing (``x_{1}`` and ``x_1``; ``\\dot\\theta``,
``\\dot{\\theta_1}`` and ``\\dot{\\theta}_1``; ``[ ]`` and ``\\{ \\}`` as parentheses) to one
form, and keeps for every character its position in the original, so that an error
can point at the LaTeX the user wrote.
"""

from __future__ import annotations

import re
import unicodedata

#: Unicode letters read as their LaTeX commands (φ and ϕ both as \\phi, as a reader reads them)
UNICODE = dict(
    zip(
        "αβγδεζηθϑικλμνξπρσςτυφϕχψωΓΔΘΛΞΠΣΥΦΨΩ",
        "alpha beta gamma delta epsilon zeta eta theta vartheta iota kappa lambda mu nu xi pi rho sigma "
        "varsigma tau upsilon phi phi chi psi omega Gamma Delta Theta Lambda Xi Pi Sigma Upsilon Phi Psi "
        "Omega".split(),
        strict=True,
    )
)
_SUBSCRIPT_DIGITS = str.maketrans("₀₁₂₃₄₅₆₇₈₉", "0123456789")
_FONTS = r"mathbf|boldsymbol|bm|mathrm|mathit|mathsf|mathnormal|text"
_SPACING = r"(?<!\\)\\[,;:! ]|\\q?quad\b|~|\\left\.|\\right\.|\\displaystyle\b"
_OPEN = r"\\left\s*\(|\\left\s*\[|\\left\s*\\\{|\\[bB]ig+l?\s*[(\[]|\\[bB]ig+l?\s*\\\{|\[|\\\{"
_CLOSE = r"\\right\s*\)|\\right\s*\]|\\right\s*\\\}|\\[bB]ig+r?\s*[)\]]|\\[bB]ig+r?\s*\\\}|\]|\\\}"


class Text:
    """A LaTeX string being normalised, with each character's position in the original."""

    def __init__(self, text: str):
        self.original = text
        self.text = text
        self.origin = list(range(len(text)))

    def sub(self, pattern: str, repl) -> None:
        out, origin, last = [], [], 0
        for m in re.finditer(pattern, self.text):
            out.append(self.text[last : m.start()])
            origin += self.origin[last : m.start()]
            new = m.expand(repl) if isinstance(repl, str) else repl(m)
            out.append(new)
            origin += [self.origin[m.start()] if m.start() < len(self.origin) else len(self.original)] * len(
                new
            )
            last = m.end()
        out.append(self.text[last:])
        origin += self.origin[last:]
        self.text, self.origin = "".join(out), origin

    def where(self, index: int) -> int:
        """The position in the original of normalised position ``index``."""
        return self.origin[index] if index < len(self.origin) else len(self.original)

    def remove_spans(self, spans: list[tuple[int, int]]) -> None:
        keep = [True] * len(self.text)
        for a, b in spans:
            for k in range(a, b):
                keep[k] = False
        self.text = "".join(c for c, k in zip(self.text, keep, strict=True) if k)
        self.origin = [o for o, k in zip(self.origin, keep, strict=True) if k]


def _closing(text: str, start: int) -> int:
    """Index of the brace closing the one at ``start``, or -1."""
    depth = 0
    for i in range(start, len(text)):
        if text[i] == "{" and (i == 0 or text[i - 1] != "\\"):
            depth += 1
        elif text[i] == "}" and (i == 0 or text[i - 1] != "\\"):
            depth -= 1
            if depth == 0:
                return i
    return -1


def _drop_braces(t: Text, command: str, label: str) -> None:
    """``\\command{X}`` (then ``label{…}`` if present) becomes X; an unclosed brace is an error."""
    while (m := re.search(rf"\\{command}\s*\{{", t.text)) is not None:
        end = _closing(t.text, m.end() - 1)
        if end < 0:
            raise Stop(t.where(m.start()), f"the brace opened by \\{command} is never closed")
        spans = [(m.start(), m.end()), (end, end + 1)]
        after = re.match(rf"\s*{re.escape(label)}\s*\{{", t.text[end + 1 :]) if label else None
        if after:
            open_at = end + 1 + after.end() - 1
            close = _closing(t.text, open_at)
            if close < 0:
                raise Stop(t.where(open_at), f"the brace of \\{command}'s label is never closed")
            spans.append((end + 1, close + 1))
        t.remove_spans(spans)


class Stop(Exception):
    def __init__(self, at: int, why: str):
        super().__init__(why)
        self.at, self.why = at, why


def normalise(text: str) -> Text:
    """The canonical form the grammar reads (module docstring), positions kept."""
    t = Text(text)
    _unicode(t)
    t.sub(_SPACING, " ")
    t.sub(_OPEN, "(")
    t.sub(_CLOSE, ")")
    t.sub(r"\\[dt]frac\b", r"\\frac")
    t.sub(r"\\cdot\b|\\times\b", "*")
    _drop_braces(t, "underbrace", "_")
    _drop_braces(t, "overbrace", "^")
    _drop_braces(t, f"(?:{_FONTS})", "")
    t.sub(r"\\(d?dot)\s*(\\[A-Za-z]+|[A-Za-z])", r"\\\1{\2}")  # \dot\theta → \dot{\theta}
    t.sub(r"\\(d?dot)\{\s*(\\[A-Za-z]+|[A-Za-z])\s*_\s*(\{[^{}]*\}|\w)\s*\}", r"\\\1{\2}_\3")
    t.sub(r"\\(d?dot)\{\s*(\\[A-Za-z]+|[A-Za-z])\s*\}", r"\\\1{\2}")
    t.sub(r"([_^])\s*\{\s*(\w)\s*\}", r"\1\2")  # x_{1} → x_1, x^{2} → x^2
    t.sub(r"\^\s*(\w)", r"^{\1}")  # powers always braced
    t.sub(r"\s+", " ")
    return t


def _unicode(t: Text) -> None:
    """θ → \\theta, θ₁ → \\theta_1, ẋ (x and a combining dot) → \\dot{x}, ẍ → \\ddot{x}."""
    t.sub(r"[^\x00-\x7f]", lambda m: unicodedata.normalize("NFD", m.group()))
    letters = "".join(UNICODE)
    t.sub(
        rf"([{letters}])(?=([A-Za-z])?)", lambda m: "\\" + UNICODE[m.group(1)] + (" " if m.group(2) else "")
    )
    t.sub(r"([₀-₉]+)", lambda m: "_{" + m.group(1).translate(_SUBSCRIPT_DIGITS) + "}")
    t.sub(r"(\\[A-Za-z]+|[A-Za-z])\s*\u0307", r"\\dot{\1}")
    t.sub(r"(\\[A-Za-z]+|[A-Za-z])\s*\u0308", r"\\ddot{\1}")


def canonical_symbol(key: str) -> str:
    """The form a symbol-table key takes after ``normalise``, without spaces."""
    return normalise(key).text.replace(" ", "")
