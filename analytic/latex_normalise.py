"""LaTeX text made canonical for the grammar of ``pendverify.analytic.latex_parse``.

``normalise`` rewrites what only typesets (spacing, ``\\left``/``\\right``, fonts,
``\\underbrace``) and the spellings of one thing (``x_{1}`` and ``x_1``; ``\\dot\\theta``,
``\\dot{\\theta_1}`` and ``\\dot{\\theta}_1``; ``[ ]`` and ``\\{ \\}`` as parentheses; ``θ₁`` and
``\\theta_1``; ``ẋ`` and ``\\dot{x}``; ``\\operatorname{sin}`` and ``\\sin``; ``array`` and
``matrix``; the transposes ``^T``, ``^\\top``, ``^{\\mathsf{T}}``) to one form, removes what a
paper's display adds around the mathematics (``\\label{…}``, ``\\nonumber``, the display's
environment and delimiters, ``\\\\[2pt]``'s spacing, a ``\\\\`` between the lines of an
``align``, whose ``&=`` becomes ``=``; a notebook's ``&&`` between every two cells of a matrix
becomes ``&``), and keeps for every character its position in the original, so that an error can
point at the LaTeX the user wrote.  ``toml_escapes`` tells LaTeX that TOML's double quotes
corrupted (``"\\theta"`` read as a tab and ``heta``) from LaTeX that holds real whitespace.
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


_DISPLAYS = r"equation|align|eqnarray|gather|multline|flalign|split|aligned|gathered|alignedat"
_FUNCTION_NAMES = r"sin|cos|tan|exp"
_MATRIX_ENVIRONMENTS = r"[bBpvV]?matrix|smallmatrix|array"


def normalise(text: str, transpose_letter: bool = True) -> Text:
    """The canonical form the grammar reads (module docstring), positions kept.

    ``transpose_letter``: ``^T`` and ``^{T}`` are transposes (false when T is a symbol).
    """
    t = Text(text)
    _unicode(t)
    _paper_layout(t)
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
    transposes = r"\^\s*\{\s*\\(?:top|intercal)\s*\}|\^\s*\\(?:top|intercal)(?![A-Za-z])"
    t.sub(transposes + (r"|\^\{T\}" if transpose_letter else ""), r"^{\\top}")
    t.sub(r"_\{([^{}]*)\}", lambda m: "_{" + re.sub(r"\s", "", m.group(1)) + "}")  # s_{1 + 2}
    t.sub(r"\s+", " ")
    return t


def _paper_layout(t: Text) -> None:
    """What a paper's display adds around the mathematics (module docstring), removed or made plain."""
    t.sub(r"\\(?:label|tag)\*?\s*\{[^{}]*\}|\\nonumber\b|\\notag\b", " ")
    t.sub(rf"\\(?:begin|end)\s*\{{(?:{_DISPLAYS})\*?\}}(?:\s*\{{\d+\}})?", " ")
    t.sub(r"^\s*(?:\$\$?|\\\[)|(?:\$\$?|\\\])\s*$", " ")  # $…$, $$…$$, \[…\]
    t.sub(r"(\\\\)\s*\[\s*-?[\d.]+\s*(?:pt|em|ex|mm|cm|in|bp|mu|sp|pc|dd)\s*\]", r"\1")  # \\[2pt]
    t.sub(r"&\s*(:?=:?)\s*&?|(:?=:?)\s*&", lambda m: m.group(1) or m.group(2))  # &=&, &=, &:=
    t.sub(r"(\\begin\s*\{array\})\s*\{[^{}]*\}", r"\1")  # the column specification
    t.sub(r"\\begin\s*\{array\}", r"\\begin{matrix}")
    t.sub(r"\\end\s*\{array\}", r"\\end{matrix}")
    t.sub(rf"\\(?:operatorname\*?|mathrm|text)\s*\{{\s*({_FUNCTION_NAMES})\s*\}}", r"\\\1")
    _line_breaks(t)
    _double_ampersands(t)


def _double_ampersands(t: Text) -> None:
    """A matrix whose every column separator is ``&&`` has ``&`` there instead.

    In amsmath ``a && b`` inside a ``bmatrix`` is three cells, the middle one empty; a notebook
    that writes every separator so means one.  ``&&`` is read as one separator only when every
    ``&`` of the matrix (at its own level, not in a matrix inside it) is half of an ``&&``: the
    matrix is then rectangular either way (every row has the same empty columns between its
    cells), and without them it is the matrix meant.  A matrix that mixes ``&&`` with single
    ``&`` is refused at its first ``&&``; ``a & & b`` (an empty cell between separators) is left
    as written, an error of the grammar.
    """
    frames: list[list[re.Match]] = []
    spans = []
    pattern = rf"\\(begin|end)\s*\{{(?:{_MATRIX_ENVIRONMENTS})\*?\}}|\\[&\\]|&&?"
    for m in re.finditer(pattern, t.text):
        if m.group(1) == "begin":
            frames.append([])
        elif m.group(1) == "end":
            separators = frames.pop() if frames else []
            doubled = [s for s in separators if s.group() == "&&"]
            if doubled and len(doubled) != len(separators):
                raise Stop(
                    t.where(doubled[0].start()),
                    "a matrix separating its columns with both '&&' and '&': '&&' is read as one "
                    "separator only when every separator of the matrix is '&&'",
                )
            spans += [(s.start() + 1, s.end()) for s in doubled]
        elif m.group().startswith("&") and frames:
            frames[-1].append(m)
    t.remove_spans(spans)


def _line_breaks(t: Text) -> None:
    """A ``\\\\`` outside every matrix ends a line of the display: it is a space."""
    depth, spans = 0, []
    for m in re.finditer(rf"\\(begin|end)\s*\{{(?:{_MATRIX_ENVIRONMENTS})\*?\}}|\\\\", t.text):
        if m.group(1) == "begin":
            depth += 1
        elif m.group(1) == "end":
            depth -= 1
        elif depth == 0:
            spans.append((m.start(), m.end()))
    t.remove_spans(spans)


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


#: TOML's escapes that turn the start of a LaTeX command into a control character
_ESCAPES = {"\b": ("b", "a backspace"), "\t": ("t", "a tab"), "\n": ("n", "a line break"),
            "\f": ("f", "a form feed"), "\r": ("r", "a carriage return")}  # fmt: skip
#: the commands that begin with t, n or r (a tab, line break or carriage return can be real)
_TNR_COMMANDS = {c for c in UNICODE.values() if c[0] in "tnr"} | {
    "tan", "times", "text", "textrm", "top", "to", "tfrac", "tilde", "nabla", "neq", "ne", "ni",
    "nonumber", "notag", "newline", "right", "rangle", "rbrace", "rbrack", "rm",
}  # fmt: skip


def toml_escapes(text: str) -> str | None:
    """Why ``text`` is LaTeX that TOML's double quotes corrupted, or None.

    In a double-quoted TOML string ``\\b \\t \\n \\f \\r`` are escapes: ``"\\beta"`` is a
    backspace and ``eta``, ``"\\theta"`` a tab and ``heta``, ``"\\frac"`` a form feed and ``rac``;
    every other backslash-letter pair is a TOML error, so LaTeX in double quotes whose commands
    all begin with b, t, n, f or r is read silently corrupted.  A backspace, a form feed or any
    other control character but tab, line break and carriage return is never written in LaTeX:
    each is refused.  A tab, a line break or a carriage return can be real (a ``'''…'''`` block
    is written over lines, indented with tabs); one is refused when the letters right after it
    spell, after the escape's letter, a LaTeX command (``heta`` after a tab: ``\\theta``).  A tab
    indents and a carriage return ends a line: neither is followed by such letters in real
    LaTeX.  A line of real LaTeX may start with ``u`` (``\\nu``) or ``e`` (``\\ne``), so a line
    break is refused only if besides the text holds no backslash (double quotes that TOML read
    leave one only where ``\\\\`` was written, while LaTeX in single quotes keeps its commands')
    or the letters are three or more (``abla``, ``onumber``), which start no line of LaTeX.
    """
    found: dict[str, str] = {}
    for m in re.finditer(r"([\x00-\x08\x0b-\x1f\x7f])([A-Za-z]*)|([\t\n\r])([A-Za-z]+)", text):
        control, letters = (m.group(1), m.group(2)) if m.group(1) else (m.group(3), m.group(4))
        letter, _ = _ESCAPES.get(control, ("", ""))
        if m.group(3) and not (
            letter + letters in _TNR_COMMANDS and (control != "\n" or "\\" not in text or len(letters) >= 3)
        ):
            continue
        found.setdefault(control, f"\\{letter}{letters}" if letter and letters else "")
    if not found:
        return None
    turned = " and ".join(
        f"\\{_ESCAPES[c][0]} into {_ESCAPES[c][1]}" + (f' (in "{word}")' if word else "")
        if c in _ESCAPES
        else f"a control character U+{ord(c):04X}"
        for c, word in found.items()
    )
    return (
        f"this LaTeX was written in double quotes: TOML turned {turned}; "
        "use single quotes '…' or '''…''' (no escapes)"
    )


def canonical_symbol(key: str) -> str:
    """The form a symbol-table key takes after ``normalise``, without spaces."""
    return normalise(key).text.replace(" ", "")
