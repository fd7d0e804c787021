"""A repair as a minimal edit of the model file's own text: the terms the user wrote kept as written.

A text model file's entry is a string the user wrote, in LaTeX (``notation = "latex"``) or in
SymPy syntax.  The repair of an entry, old → new (SymPy expressions), is shown as that string
with only the changed term rewritten:

1. **Where**: the entry's text in the file — its cell of a matrix (``\\begin{bmatrix}`` rows split
   at ``\\\\``, cells at ``&``; a TOML list of lists), its row of a vector, or a scalar's
   right-hand side — taken only when the file's own reader reads it as the entry
   (``is_zero`` of the difference).  A display with two right-hand sides gives the first.
2. **The terms**: the text split at its ``+`` and ``−`` outside every bracket, each term read
   alone by the same reader.
3. **The edit**, Δ = new − old, the first that fits of: a term's sign flipped (Δ = −2·t), a term
   dropped (Δ = −t), one word of a term replaced by another (``lc1`` by ``lc2``, ``\\cos`` by
   ``\\sin``: ``one_word``); else the cheaper (fewer SymPy operations printed) of one term rewritten,
   t → t + Δ (the term it makes simplest), and Δ appended as a term.  A rewritten or appended
   term is printed by the notation's printer (``Notation.render``), and in LaTeX SymPy's
   ``\\sin{\\left(\\theta \\right)}`` is written ``\\sin\\theta`` (``\\sin(\\theta_1 + \\theta_2)``
   for a sum), as derivations print it.
4. **Confirmed**: the edited text, read by the file's reader, is ``new`` (``is_zero``).

When a step fails (the text is not found, a term does not read alone, the edited text does not
read as ``new``), ``None`` is returned and the caller prints the entry whole.
"""

from __future__ import annotations

import re

import sympy as sp

from pendverify.analytic.latex_names import conventions
from pendverify.analytic.latex_normalise import canonical_symbol, normalise
from pendverify.analytic.latex_parse import LatexReader, SymbolTable
from pendverify.analytic.text_expression import read_expression
from pendverify.analytic.text_parse import CONSTANTS, FUNCTIONS
from pendverify.diagnosis.clock import now
from pendverify.documents import read_toml
from pendverify.errors import PendverifyError
from pendverify.symbolic.zero_test import is_zero, probe

#: what a piece of text that does not read as an expression raises (the readers' own errors)
UNREADABLE = (PendverifyError, ValueError, TypeError, ArithmeticError)
_OPENING, _CLOSING = "{([", "})]"
#: characters after which a + or − is a sign of what follows, not a term's separator
_NOT_BETWEEN_TERMS = "^_({[=&*/,"


def plain(expr):
    """``expr`` over plain symbols of the same names (the readers give them different assumptions)."""
    expr = sp.sympify(expr)
    return expr.xreplace({s: sp.Symbol(s.name) for s in expr.free_symbols})


#: the CPU time a repair's minimal edit may take (``minimal_edit``): past it, or for an entry whose
#: comparisons are larger than ``MAX_EDIT_OPS`` operations (a q̈ written out: 20,000, whose one exact
#: comparison took 19 s), the entry is printed whole by the caller, in SymPy's syntax
EDIT_SECONDS = 2.0
MAX_EDIT_OPS = 2000


class _OutOfTime(Exception):
    """A minimal edit past its bound (``EDIT_SECONDS``, ``MAX_EDIT_OPS``)."""


class SourceText:
    """The file's text of each entry and a reader for pieces of it (module docstring)."""

    def __init__(self, spec):
        self.spec = spec
        #: the clock time (``pendverify.diagnosis.clock``) a minimal edit's comparisons stop at, or None
        self.until: float | None = None
        self.latex = spec.notation == "latex"
        names = {s.name: s for g in "qvuwap" for s in spec.symbols.get(g, ())}
        self.names = names | FUNCTIONS | CONSTANTS
        self.angles = [
            sp.Symbol(c) for c, angular in zip(spec.coordinates, spec.angular, strict=True) if angular
        ]
        self.data = read_toml(spec.path, "model file")
        if self.latex:
            declared = (*spec.inputs, *spec.disturbances, *spec.parameters)
            entries = {k: c.value for k, c in conventions(spec.coordinates, declared, self.names).items()}
            for key, value in spec.latex_symbols.items():
                entries[canonical_symbol(key)] = sp.sympify(value)
            self.reader = LatexReader(SymbolTable(entries, {k: k for k in entries}))

    def read(self, text: str):
        """What ``text`` reads as in this file, over plain symbols, or None."""
        try:
            value = self.reader.read(text)[0] if self.latex else read_expression(text.strip(), self.names)
        except UNREADABLE:
            return None
        return None if isinstance(value, sp.MatrixBase) else plain(value)

    def same(self, a, b) -> bool:
        """Whether ``a`` and ``b`` are equal: most pieces of text tried are not, and a numeric probe
        (``probe``, 50 digits) says so at once; the exact test decides the rest.  Within a
        ``minimal_edit`` (``until`` set), a comparison past its bound, or of an expression too large
        to decide within it, raises ``_OutOfTime``."""
        try:
            difference = sp.sympify(a) - sp.sympify(b)
        except UNREADABLE:
            return False
        if self.until is not None and (now() > self.until or sp.count_ops(difference) > MAX_EDIT_OPS):
            raise _OutOfTime
        try:
            return not probe(difference) and is_zero(difference, self.angles)
        except UNREADABLE:
            return False

    def entry_text(self, key: str, position: tuple[int, ...], expr) -> str | None:
        """The text the file writes for the entry at ``position`` of ``key``, if it reads as ``expr``."""
        value = self.data.get(key)
        target = plain(expr)
        for text in self._candidates(value, position):
            read = self.read(text)
            if read is not None and self.same(read, target):
                return text.strip()
        return None

    def _candidates(self, value, position) -> list[str]:
        if isinstance(value, list):  # a TOML list of rows, or of a vector's entries
            item = value
            for i in position:
                item = item[i] if isinstance(item, list) and i < len(item) else None
            return [item] if isinstance(item, str) else []
        if not isinstance(value, str):
            return []
        if not self.latex:
            return [value] if not position else []
        return latex_cells(value, position)


def latex_cells(text: str, position: tuple[int, ...]) -> list[str]:
    """The original text of the cell at ``position`` of every matrix in ``text`` (a scalar, ():
    every right-hand side of the chain ``LABEL = A = B``)."""
    t = normalise(text)
    s = t.text

    def original(a: int, b: int) -> str:
        while a < b and s[a] == " ":
            a += 1
        while b > a and s[b - 1] == " ":
            b -= 1
        return text[t.where(a) : t.where(b - 1) + 1] if b > a else ""

    if not position:
        sides, depth, start = [], 0, 0
        for i, c in enumerate(s):
            depth += (c in _OPENING) - (c in _CLOSING)
            if c == "=" and depth == 0:
                sides.append((start, i))
                start = i + 1
        sides.append((start, len(s)))
        return [original(a, b) for a, b in sides if "\\begin" not in s[a:b]]
    row, col = position if len(position) == 2 else (position[0], 0)
    out = []
    for m in re.finditer(r"\\begin\{[A-Za-z]*matrix\*?\}(\{[^{}]*\})?", s):
        cells, depth, start, r, c = {}, 0, m.end(), 0, 0
        i = m.end()
        while i < len(s):
            if s.startswith("\\begin{", i):
                depth += 1
            elif s.startswith("\\end{", i):
                if depth == 0:
                    cells[(r, c)] = (start, i)
                    break
                depth -= 1
            elif s[i] in _OPENING:
                depth += 1
            elif s[i] in _CLOSING:
                depth -= 1
            elif depth == 0 and s[i] == "&":
                cells[(r, c)] = (start, i)
                c, start = c + 1, i + 1
            elif depth == 0 and s.startswith("\\\\", i):
                cells[(r, c)] = (start, i)
                r, c, start = r + 1, 0, i + 2
                i += 1
            i += 1
        if (row, col) in cells:
            out.append(original(*cells[(row, col)]))
    return out


def terms(text: str) -> list[tuple[int, int, int]]:
    """(sign position or −1, start, end) of each term of ``text`` at bracket depth 0 (module docstring)."""
    out, depth, sign, start = [], 0, -1, 0
    last = ""  # the last character that is not a space
    for i, c in enumerate(text):
        if c in _OPENING:
            depth += 1
        elif c in _CLOSING:
            depth -= 1
        elif c in "+-" and depth == 0 and not last:  # the leading sign
            sign, start = i, i + 1
        elif c in "+-" and depth == 0 and last not in _NOT_BETWEEN_TERMS and not _exponent(text, i):
            out.append((sign, start, i))
            sign, start = i, i + 1
        if not c.isspace():
            last = c
    out.append((sign, start, len(text)))
    trimmed = []
    for p, a, b in out:
        while a < b and text[a].isspace():
            a += 1
        while b > a and text[b - 1].isspace():
            b -= 1
        if b > a:
            trimmed.append((p, a, b))
    return trimmed


def _exponent(text: str, i: int) -> bool:
    """Whether the sign at ``i`` is a number's exponent (1e-5)."""
    return i >= 2 and text[i - 1] in "eE" and text[i - 2].isdigit()


def _signed(text: str, sign: int) -> int:
    return -1 if sign >= 0 and text[sign] == "-" else 1


#: SymPy's ``\\sin{\\left(X \\right)}`` with no bracket inside X
_SYMPY_FUNCTION = r"\\(sin|cos|tan|exp)\{\\left\(((?:(?!\\left|\\right).)*?) \\right\)\}"


def latex_style(latex: str) -> str:
    """SymPy's LaTeX as a derivation writes it: ``\\sin\\theta``, ``\\sin(\\theta_1 + \\theta_2)``."""

    def function(m):
        inner = m.group(2)
        if re.fullmatch(r"\\[A-Za-z]+(_\{?\w+\}?)?", inner):
            return f"\\{m.group(1)}{inner}"
        if re.fullmatch(r"[A-Za-z](_\{?\w+\}?)?", inner):
            return f"\\{m.group(1)} {inner}"
        return f"\\{m.group(1)}({inner})"

    previous = None
    while previous != latex:  # innermost first
        previous = latex
        latex = re.sub(_SYMPY_FUNCTION, function, latex)
    return latex.replace("\\left(", "(").replace(" \\right)", ")").replace("\\right)", ")")


def minimal_edit(source: SourceText, text: str, old, new, render) -> str | None:
    """``text`` (which reads as ``old``) with the fewest of its terms changed so that it reads as
    ``new``, checked by reading it (module docstring); ``render`` prints a SymPy term.  None past
    ``EDIT_SECONDS`` of CPU time or for comparisons beyond ``MAX_EDIT_OPS``."""
    source.until = now() + EDIT_SECONDS
    try:
        return _minimal_edit(source, text, old, new, render)
    except _OutOfTime:
        return None
    finally:
        source.until = None


def _minimal_edit(source: SourceText, text: str, old, new, render) -> str | None:
    spans = terms(text)
    values = []
    for sign, a, b in spans:
        value = source.read(text[a:b])
        if value is None:
            return None
        values.append(_signed(text, sign) * value)
    delta = sp.expand(plain(new) - plain(old))

    # the printer knows the model's own symbols, not the plain ones compared here
    back = {sp.Symbol(x.name): x for x in sp.sympify(old).free_symbols | sp.sympify(new).free_symbols}

    def show(expr) -> str:
        out = render(sp.sympify(expr).xreplace(back))
        return latex_style(out) if source.latex else out

    def replaced(k: int, body: str | None) -> str:
        """Term k (with its sign) replaced by ``body`` ("- x", "+ x", or "x" first), or dropped (None)."""
        sign, a, b = spans[k]
        head, rest = text[: sign if sign >= 0 else a].rstrip(), text[b:]
        if body is None:
            if not head:
                rest = re.sub(r"^\s*\+\s*", "", rest)
            return (head + rest).strip() or "0"
        return f"{head} {body}{rest}" if head else body.removeprefix("+ ") + rest

    def piece(expr, first: bool) -> str:
        if sp.sympify(expr).could_extract_minus_sign():
            return f"- {show(-expr)}" if not first else f"-{show(-expr)}"
        return show(expr) if first else f"+ {show(expr)}"

    for k, (sign, a, b) in enumerate(spans):
        if source.same(delta + 2 * values[k], 0):  # the term's sign flipped
            body = text[a:b]
            if sign >= 0 and text[sign] == "-":
                flipped = f"+ {body}"
            else:
                flipped = f"-{body}" if k == 0 else f"- {body}"
            return _confirmed(source, replaced(k, flipped), new)
        if source.same(delta + values[k], 0):  # the term dropped
            return _confirmed(source, replaced(k, None), new)
    swapped = one_word(source, text, spans, values, delta, new)
    if swapped is not None:
        return swapped
    options = []
    for k in range(len(spans)):
        rewritten = sp.expand(values[k] + delta)
        # a decimal factor put right leaves 0.9999999999999999·x (1.1 − 0.1 in binary): written as
        # the whole number it is to rounding; the edited text is read back and compared below
        whole = {f: sp.Integer(round(f)) for f in rewritten.atoms(sp.Float) if abs(f - round(f)) <= 1e-12}
        rewritten = sp.factor_terms(rewritten.xreplace(whole))
        options.append((sp.count_ops(rewritten), k, rewritten))
    ops, k, rewritten = min(options, key=lambda o: o[:2])
    if sp.count_ops(delta) + 1 < ops:
        return _confirmed(source, f"{text.rstrip()} {piece(delta, False)}", new)
    return _confirmed(source, replaced(k, piece(rewritten, k == 0)), new)


#: a word of a model's text: a name (``lc2``, ``theta_1``, ``m_{2}``) or a LaTeX command (``\\sin``)
_WORD = re.compile(r"\\?[A-Za-z][A-Za-z0-9]*(?:_(?:\{[^{}]*\}|[A-Za-z0-9]+))?")
#: words tried in place of another, besides the entry's own and the names of the edit's symbols
_FUNCTION_WORDS = {False: ("sin", "cos"), True: ("\\sin", "\\cos")}
#: the readings one search for a word may take (a term of 10 words, 20 words to try in each)
MAX_WORD_READS = 400


def one_word(source: SourceText, text: str, spans, values, delta, new) -> str | None:
    """``text`` with one word of one term replaced by another word, when that term then reads as
    itself + Δ (a parameter typed for another, ``sin`` for ``cos``), confirmed by reading the whole
    text; None when no single word does it within ``MAX_WORD_READS`` readings."""
    words = {m.group() for m in _WORD.finditer(text)} | set(_FUNCTION_WORDS[source.latex])
    if not source.latex:
        words |= {x.name for x in sp.sympify(new).free_symbols}
    reads = 0
    for k, (_, a, b) in enumerate(spans):
        wanted = values[k] + delta
        for found in _WORD.finditer(text, a, b):
            for word in sorted(words - {found.group()}):
                if reads >= MAX_WORD_READS:
                    return None
                term = text[a : found.start()] + word + text[found.end() : b]
                reads += 1
                value = source.read(term)
                if value is None or not source.same(_signed(text, spans[k][0]) * value, wanted):
                    continue
                edited = text[: found.start()] + word + text[found.end() :]
                return _confirmed(source, edited, new)
    return None


def _confirmed(source: SourceText, edited: str, new) -> str | None:
    read = source.read(edited)
    return edited if read is not None and source.same(read, plain(new)) else None
