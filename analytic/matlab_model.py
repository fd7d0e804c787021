"""A text model's ``[matlab]`` table: its equations read from MATLAB/Octave ``.m`` files.

The declaration is a text model file (``pendverify.analytic.text_parse``) without equations of
its own, or with some, plus::

    [matlab]
    files = ["PendulumODEMatrices.m"]      # beside the declaration (or a path relative to it)

    [matlab.arguments]                     # what each argument of the functions is
    in1 = ["x", "theta1", "theta2", "dx", "dtheta1", "dtheta2"]   # a vector: its entries in order
    in3 = ["m", "M", "L", "g"]
    p = "struct"                           # a structure whose fields are the declared names
    empty = 0                              # a number

    [matlab.arguments."other.m"]           # the arguments of one file, where they differ

An argument named as a declared name (a coordinate, a rate ``d<coordinate>``, an input, a
disturbance, a parameter) is that name without a line here.  A file may also be a script (no
``function`` line): its names are the declared ones.

Every output of every file (a script's: every name it assigns) is a name the equations use:
an equation key is a scalar output's name in an expression (``M = [["-M11", "-M12"], …]``, as
OptimTraj's acrobot returns −M entry by entry), or a string naming a matrix output, whole or
negated (``M = "W"``, ``f = "RHS"``, ``qddot = "-out1"``).  Each key is then read as the text
model reads it: completed, checked and turned into a model class, so every command takes it.

``MatlabSource`` records where each output was written, so that the diagnosis names the
``.m`` file's line of an entry and prints its repair in MATLAB syntax (``sympy.octave_code``).
"""

from __future__ import annotations

import difflib
import re
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from pendverify.analytic.matlab_parse import (
    MatlabFunction,
    Output,
    StructArgument,
    UnboundArgument,
    VectorArgument,
    evaluate,
    parse_function,
    read_source,
)
from pendverify.analytic.matlab_source import SourceError
from pendverify.display import shortened
from pendverify.errors import ExcerptError, excerpt

MATLAB_KEYS = ("files", "arguments")


@dataclass
class MatlabSource:
    """The ``.m`` files a declaration reads and where each of their outputs was written."""

    files: tuple[Path, ...] = ()
    #: output name → (file, its Output)
    outputs: dict[str, tuple[Path, Output]] = field(default_factory=dict)
    #: equation key → output name, for a key given as one matrix output (``M = "W"``, ``"-W"``)
    whole: dict[str, str] = field(default_factory=dict)
    #: equation key → its value in the declaration (a string, or lists of them)
    written: dict[str, object] = field(default_factory=dict)
    #: file → (its statements, the arguments it was evaluated with, its text): what a line edit
    #: of a repair (``pendverify.analytic.matlab_edit``) evaluates again
    functions: dict[Path, tuple[MatlabFunction, dict, str]] = field(default_factory=dict)

    def entry_text(self, key: str, position: tuple[int, ...]) -> str | None:
        """The declaration's text of the entry at ``position`` of ``key`` (``"-M12"``), if it has one."""
        item = self.written.get(key)
        for i in position:
            item = item[i] if isinstance(item, list) and i < len(item) else None
        return item if isinstance(item, str) else None

    @property
    def used(self) -> set[str]:
        """The outputs the declaration's equations read (a script's other names are temporaries)."""
        texts, stack = [], list(self.written.values())
        while stack:
            item = stack.pop()
            if isinstance(item, list):
                stack += item
            elif isinstance(item, str):
                texts.append(item)
        words = {w for text in texts for w in re.findall(r"[A-Za-z_]\w*", text)}
        return (words & set(self.outputs)) | set(self.whole.values())

    def output_cell(self, key: str, position: tuple[int, ...]) -> tuple[str, tuple[int, int], int] | None:
        """(output name, its cell, the sign the declaration gives it) of the entry at ``position`` of
        equation ``key``, if known: a cell of a whole matrix output (``M = "W"``, ``"-W"``), or an
        entry the declaration writes as one output (``"-M12"``: cell (0, 0))."""
        if key in self.whole:
            name = self.whole[key]
            sign = -1 if str(self.written.get(key, "")).strip().startswith("-") else 1
            value = self.outputs[name][1].value
            cell = position if len(position) == 2 else (*position, 0)
            if isinstance(value, sp.MatrixBase) and value.shape[0] == 1 and len(position) == 1:
                cell = (0, position[0])
            return name, cell, sign
        text = self.entry_text(key, position)
        if text is None:
            return None
        stripped = text.strip()
        name = stripped.lstrip("+-").strip()
        if name not in self.outputs:
            return None
        return name, (0, 0), -1 if stripped.startswith("-") else 1

    def line_of(self, key: str, position: tuple[int, ...]) -> tuple[Path, int] | None:
        """(file, line) where the entry at ``position`` of equation ``key`` was written, if known
        (``output_cell``)."""
        found = self.output_cell(key, position)
        if found is None:
            return None
        name, cell, _ = found
        path, output = self.outputs[name]
        return path, output.line_of(cell) if key in self.whole else output.line


def read_matlab(reader, spec, table) -> tuple[MatlabSource, dict[str, object]]:
    """The files of ``[matlab]`` read (``reader.fail`` on a problem of the table, an ``ExcerptError``
    at the file's line on a problem of a file): the source record and {output name: value}."""
    if not isinstance(table, dict) or set(table) - set(MATLAB_KEYS):
        extra = sorted(set(table) - set(MATLAB_KEYS)) if isinstance(table, dict) else []
        reader.fail(
            "matlab", f"must be a table of {', '.join(MATLAB_KEYS)}" + (f"; not {extra[0]}" if extra else "")
        )
    files = table.get("files")
    if not isinstance(files, list) or not files or not all(isinstance(f, str) and f for f in files):
        reader.fail("matlab.files", 'missing, or not a list of file names (files = ["dynamics.m"])')
    arguments = table.get("arguments", {})
    if not isinstance(arguments, dict):
        reader.fail("matlab.arguments", "must be a table: each argument's name = what it is")
    declared = _declared(spec)
    source = MatlabSource()
    values: dict[str, object] = {}
    for given in files:
        path = (spec.path.parent / given) if not Path(given).is_absolute() else Path(given)
        if path.suffix.lower() != ".m":
            reader.fail("matlab.files", f"{shortened(repr(given), 60)} is not a .m file")
        text, function = _read_file(reader, path)
        bindings = _bindings(reader, function, arguments, declared)
        try:
            outputs = evaluate(function, bindings)
        except SourceError as exc:
            _fail_at(path, text, exc)
        source.files += (path,)
        source.functions[path] = (function, bindings, text)
        for name, output in outputs.items():
            if name in values:
                reader.fail(
                    "matlab.files", f"output {name} is written by two files ({source.outputs[name][0].name})"
                )
            if name in declared:
                reader.fail(
                    "matlab.files",
                    f"output {name} of {path.name} has the name of a declared name: rename one of them",
                )
            source.outputs[name] = (path, output)
            values[name] = output.value
    source.files = tuple(source.files)
    return source, values


def _declared(spec) -> dict[str, sp.Symbol]:
    return {s.name: s for group in "qvuwp" for s in spec.symbols[group]}


def _read_file(reader, path: Path) -> tuple[str, MatlabFunction]:
    """The file's text and its statements parsed."""
    try:
        text = read_source(path)
    except FileNotFoundError:
        reader.fail("matlab.files", f"{path}: no such file")
    except IsADirectoryError:
        reader.fail("matlab.files", f"{path}: a folder, not a .m file")
    except OSError as exc:
        reader.fail("matlab.files", f"{path}: cannot be read ({exc.strerror or exc})")
    except SourceError as exc:  # larger than a model file is read
        reader.fail("matlab.files", f"{path}: {exc.why}")
    try:
        return text, parse_function(path, text)
    except SourceError as exc:
        _fail_at(path, text, exc)


def _fail_at(path: Path, text: str, exc: SourceError):
    lines = text.split("\n")
    line = lines[exc.line - 1].rstrip("\r") if 0 < exc.line <= len(lines) else ""
    fragment, column = excerpt(line, exc.column)
    raise ExcerptError(
        f"{path}, line {exc.line}, column {exc.column + 1}: {exc.why}", fragment, column
    ) from None


def _bindings(reader, function: MatlabFunction, arguments: dict, declared: dict) -> dict[str, object]:
    """Each argument of ``function`` bound to what the declaration says it is."""
    if function.name is None:  # a script: the declared names
        return dict(declared)
    own = arguments.get(function.path.name, {})
    if not isinstance(own, dict):
        reader.fail(f"matlab.arguments.{function.path.name}", "must be a table of the file's arguments")
    bindings: dict[str, object] = {}
    for name in function.arguments:
        if name == "~":
            continue
        key = f"matlab.arguments.{function.path.name}.{name}" if name in own else f"matlab.arguments.{name}"
        meaning = own.get(name, arguments.get(name) if not isinstance(arguments.get(name), dict) else None)
        if meaning is None:
            if name in declared:
                bindings[name] = declared[name]
                continue
            bindings[name] = UnboundArgument(
                f"argument '{name}' of {function.name} is not declared: say what it is under "
                f'[matlab.arguments] ({name} = ["q1", "q2", …] for a vector, or a declared name)'
            )
            continue
        bindings[name] = _meaning(reader, key, name, meaning, declared)
    return bindings


def _meaning(reader, key: str, name: str, meaning, declared: dict):
    if meaning == "struct":
        return StructArgument(name, dict(declared))
    if isinstance(meaning, bool):
        reader.fail(key, 'must be a declared name, a list of them, "struct" or a number')
    if isinstance(meaning, int | float):
        return sp.Rational(str(meaning))
    if isinstance(meaning, str):
        return _name(reader, key, meaning, declared)
    if isinstance(meaning, list) and meaning:
        return VectorArgument(name, tuple(_entry(reader, key, m, declared) for m in meaning))
    if isinstance(meaning, dict) and meaning:
        return StructArgument(name, {f: _name(reader, f"{key}.{f}", v, declared) for f, v in meaning.items()})
    reader.fail(key, 'must be a declared name, a list of them, "struct", a table of fields or a number')


def _entry(reader, key: str, value, declared: dict):
    if isinstance(value, int | float) and not isinstance(value, bool):
        return sp.Rational(str(value))
    return _name(reader, key, value, declared)


def _name(reader, key: str, value, declared: dict) -> sp.Symbol:
    if not isinstance(value, str) or value not in declared:
        close = difflib.get_close_matches(str(value), list(declared), n=3)
        hint = f"; did you mean {', '.join(close)}?" if close else ""
        reader.fail(
            key,
            f"{shortened(repr(value), 60)} is not a declared name (a coordinate, a rate d<coordinate>, "
            f"an input, a disturbance or a parameter){hint}",
        )
    return declared[value]


def whole_output(reader, source: MatlabSource, values: dict, key: str, value, shape: tuple[int, int | None]):
    """The equation ``key`` given as one matrix output's name (``"W"``, ``"-RHS"``), checked against
    its shape (rows, columns; None: a column vector, a row is taken as one), or None when the
    value is not such a name."""
    if not isinstance(value, str):
        return None
    text = value.strip()
    sign = -1 if text.startswith("-") else 1
    name = text.lstrip("+-").strip()
    output = values.get(name)
    rows, cols = shape
    if output is not None and not isinstance(output, sp.MatrixBase) and rows == 1 and cols in (1, None):
        output = sp.ImmutableMatrix([[output]])  # a 1×1 output is a scalar, as MATLAB has it
    if not isinstance(output, sp.MatrixBase):
        return None
    matrix = output
    if cols is None:
        if matrix.rows == 1 and matrix.cols == rows:
            matrix = matrix.T
        cols = 1
    if matrix.shape != (rows, cols):
        path, _ = source.outputs[name]
        reader.fail(key, f"{name} of {path.name} is {output.rows}×{output.cols}; {key} is {rows}×{cols}")
    source.whole[key] = name
    return sp.Matrix(matrix) * sign
