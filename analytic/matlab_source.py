"""A MATLAB/Octave ``.m`` file cut into statements of tokens, without running anything.

The subset read is what ``matlabFunction`` writes and what hand derivations of equations of
motion use: ``function`` headers, assignments (``t2 = cos(q2);``, ``M(1,2) = …;``), the
``if nargout > K`` blocks ``matlabFunction`` puts around later outputs, ``end``, comments
(``%`` to the end of a line, ``%{ … %}`` blocks) and line continuations (``...``).

Tokens follow MATLAB's lexical rules where they matter:

* ``'`` right after a name, a number, a closing bracket or another transpose is the transpose;
  anywhere else it would open a character array, which a model does not hold (refused);
* inside ``[ … ]``, a new line or ``;`` ends a row and blanks separate elements where MATLAB's
  do: between two operands (``[a b]``), and before a sign that is glued to what follows
  (``[a -b]`` is two elements, ``[a - b]`` and ``[a-b]`` one);
* ``;``, ``,`` and the end of a line end a statement outside brackets.

A ``!`` at the start of a statement (MATLAB's shell escape) and words that run code (``eval``,
``system``, ``feval``, …) are refused by name: the file is data.  Each token keeps its line and
column, so every problem is reported at its place (``SourceError``).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from pendverify.analytic.expression_limits import MAX_NESTING

#: the largest ``.m`` file read: a 7-link arm's ``matlabFunction`` output is a few hundred kB
MAX_FILE_BYTES = 8 * 1024 * 1024

#: words that would run code or reach outside the file: named in the refusal
RUNS_CODE = frozenset(
    {
        "eval", "evalin", "evalc", "feval", "system", "unix", "dos", "shell", "run", "load",
        "assignin", "builtin", "str2func", "inline", "cellfun", "arrayfun", "py", "java", "perl",
        "python", "web", "delete", "save", "fopen", "exist", "input", "keyboard", "uiimport",
    }
)  # fmt: skip
#: control words of MATLAB that a model's straight-line code does not hold
CONTROL = frozenset(
    {"for", "while", "switch", "case", "otherwise", "try", "catch", "return", "break", "continue",
     "global", "persistent", "parfor", "spmd", "classdef", "else", "elseif", "do", "until"}
)  # fmt: skip
KEYWORDS = {"function": "FUNCTION", "end": "END", "endfunction": "END", "endif": "END", "if": "IF"}

_NUMBER = re.compile(r"(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?")
_NAME = re.compile(r"[A-Za-z]\w*")
#: operators, longest first
_OPERATORS = (
    (".^", "EPOW"), (".*", "EMUL"), ("./", "EDIV"), (".'", "TRANSPOSE"), ("==", "CMP"), (">=", "CMP"),
    ("<=", "CMP"), ("~=", "CMP"), ("!=", "CMP"), ("~", "NAME"), ("**", "POW"), ("^", "POW"),
    ("*", "MUL"), ("/", "DIV"),
    ("+", "ADD"), ("-", "SUB"), ("(", "LPAR"), (")", "RPAR"), ("[", "LSQB"), ("]", "RSQB"),
    (",", "COMMA"), ("=", "ASSIGN"), (":", "COLON"), (">", "CMP"), ("<", "CMP"), (".", "DOT"),
)  # fmt: skip
_OPERAND_END = {"NAME", "NUMBER", "RPAR", "RSQB", "TRANSPOSE", "END"}
_OPERAND_START = {"NAME", "NUMBER", "LPAR", "LSQB"}


class SourceError(ValueError):
    """A problem at ``line`` (1-based) and ``column`` (0-based) of the file: ``why``."""

    def __init__(self, why: str, line: int, column: int):
        super().__init__(why)
        self.why, self.line, self.column = why, line, column


@dataclass(frozen=True)
class Tok:
    """A token: its type (a grammar terminal), its text and its place."""

    type: str
    text: str
    line: int
    column: int


@dataclass
class Statement:
    """One statement's tokens, and the line it starts on."""

    tokens: list[Tok]
    line: int


def _logical_lines(text: str) -> list[tuple[int, str]]:
    """(line number, text) of each line without comments, ``...`` continuations kept as blanks
    (columns stay those of the file) and ``%{ … %}`` blocks removed."""
    out, block = [], 0
    for number, line in enumerate(text.split("\n"), start=1):
        stripped = line.strip()
        if stripped == "%{":
            block += 1
            continue
        if stripped == "%}" and block:
            block -= 1
            continue
        if block:
            continue
        out.append((number, line.rstrip("\r")))
    return out


def tokens_of(text: str) -> list[Statement]:
    """The file's statements (module docstring); ``SourceError`` at the first problem."""
    statements: list[Statement] = []
    current: list[Tok] = []
    brackets: list[str] = []  # the open brackets, innermost last: "(" or "["

    def end_statement() -> None:
        if current:
            statements.append(Statement(list(current), current[0].line))
            current.clear()

    continued = False
    for number, line in _logical_lines(text):
        at, glued = 0, False
        if not continued and not brackets and line.lstrip().startswith("!"):
            raise SourceError(
                "'!' runs a shell command: a model file is read as data, and nothing in it is run",
                number,
                len(line) - len(line.lstrip()),
            )
        continued = False
        while at < len(line):
            c = line[at]
            if c in " \t":
                at += 1
                glued = False
                continue
            if c == "%" or c == "#":
                break
            if line.startswith("...", at):
                continued = True
                break
            previous = current[-1] if current else None
            in_matrix = bool(brackets) and brackets[-1] == "["
            if c == "'":
                if previous is not None and previous.type in _OPERAND_END and (glued or not in_matrix):
                    current.append(Tok("TRANSPOSE", "'", number, at))
                    at += 1
                    continue
                raise SourceError("a character array ('…') is not part of a model's equations", number, at)
            if c == '"':
                raise SourceError('a string ("…") is not part of a model\'s equations', number, at)
            if c == ";" or (c == "," and not brackets):
                if in_matrix and c == ";":
                    current.append(Tok("ROWSEP", ";", number, at))
                elif brackets:
                    raise SourceError(f"';' inside '{brackets[-1]}' is not read", number, at)
                else:
                    end_statement()
                at += 1
                glued = True
                continue
            token = _one_token(line, at, number)
            if in_matrix and not glued and previous is not None and previous.type in _OPERAND_END:
                sign_glued = token.type in ("ADD", "SUB") and at + 1 < len(line) and line[at + 1] not in " \t"
                if token.type in _OPERAND_START or sign_glued:
                    current.append(Tok("COMMA", " ", number, at))
            if token.type in ("LPAR", "LSQB"):
                brackets.append(token.text)
                if len(brackets) > MAX_NESTING:
                    raise SourceError(f"brackets nested more than {MAX_NESTING} deep", number, at)
            elif token.type in ("RPAR", "RSQB"):
                want = "(" if token.type == "RPAR" else "["
                if not brackets or brackets[-1] != want:
                    raise SourceError(f"'{token.text}' closes no '{want}'", number, at)
                brackets.pop()
            elif token.type == "NAME" and token.text in RUNS_CODE and not _is_field(current):
                raise SourceError(
                    f"'{token.text}' runs code or reaches outside the file: a model file is read as data, "
                    "and nothing in it is run",
                    number,
                    at,
                )
            current.append(token)
            at += len(token.text)
            glued = True
        if _in_matrix(brackets) and not continued:
            current.append(Tok("ROWSEP", "\n", number, len(line)))
        elif not brackets and not continued:
            end_statement()
    if brackets:
        last = current[-1] if current else Tok("", "", 1, 0)
        raise SourceError(f"a '{brackets[-1]}' is never closed", last.line, last.column)
    end_statement()
    return statements


def _in_matrix(brackets: list[str]) -> bool:
    """Whether the innermost open bracket is a matrix literal's."""
    return bool(brackets) and brackets[-1] == "["


def _is_field(current: list[Tok]) -> bool:
    """Whether the next name follows a ``.`` (a structure's field, ``p.load``)."""
    return bool(current) and current[-1].type == "DOT"


def _one_token(line: str, at: int, number: int) -> Tok:
    m = _NUMBER.match(line, at)
    if m and not (line[at] == "." and m.end() == at + 1):
        end = m.end()
        if m.group().endswith(".") and end < len(line) and line[end] in "*/^'":
            end -= 1  # 2./x is 2 ./ x, as MATLAB reads it
        if end < len(line) and (line[end].isalnum() or line[end] == "_"):
            raise SourceError(f"'{line[at : end + 1]}' is not a number", number, at)
        return Tok("NUMBER", line[at:end], number, at)
    m = _NAME.match(line, at)
    if m:
        word = m.group()
        return Tok(KEYWORDS.get(word, "NAME"), word, number, at)
    for text, kind in _OPERATORS:
        if line.startswith(text, at):
            return Tok(kind, text, number, at)
    raise SourceError(f"'{line[at]}' is not read in a model file", number, at)
