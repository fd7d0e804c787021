"""A MATLAB/Octave function (or script) read into SymPy: its outputs as expressions, nothing run.

``pendverify.analytic.matlab_source`` cuts the file into statements; each is parsed by the LALR
grammar below (lark) and evaluated on SymPy values, one statement at a time, in order:

* a scalar is a SymPy expression, a matrix an ``ImmutableMatrix``; a vector argument
  (``in1``) is a ``VectorArgument``, whose entry k is ``in1(k)``, ``in1(k,:)``, ``in1(:,k)``,
  ``in1(k,1)`` or ``in1(1,k)`` (``matlabFunction`` writes either orientation), a structure
  argument (``p``) a ``StructArgument`` read by its fields (``p.m1``);
* ``+ -`` and the element-wise ``.* ./ .^`` broadcast a scalar over a matrix, ``*`` is the
  matrix product, ``/`` and ``^`` take a scalar divisor and exponent, ``'`` and ``.'`` transpose
  (every symbol is real); MATLAB's precedence: ``^`` above unary minus above ``*`` above ``+``,
  and ``^`` chains from the left (``2^3^2`` is 64);
* ``[a, b; c, d]`` builds a matrix from rows (blocks of matching sizes join), ``reshape(v, r, c)``
  and ``reshape(v, [r, c])`` refill column by column, ``zeros``, ``ones`` and ``eye`` make
  matrices, ``M(i, j) = x`` sets an entry (growing the matrix as MATLAB does), indices are
  1-based numbers, ``:`` or ranges ``a:b``;
* ``FUNCTIONS`` are the functions a model may call; a number is read exactly as written
  (``9.81`` is 981/100, ``1.0./2.0`` is 1/2): ``matlabFunction`` prints exact coefficients
  as decimals;
* ``if nargout > K`` (``>=``) blocks are read (every output is wanted); another condition is
  refused.

Bounds, as the text reader's (``pendverify.analytic.expression_limits``): exact numbers and
exponents, bracket nesting, and the size of an expression (``MAX_TREE``, counted over its tree
as SymPy's algorithms walk it, so that ``t2 = t1*t1; t3 = t2*t2; …`` is stopped before it
doubles past the limit).  Every problem is a ``SourceError`` at its line and column.
"""

from __future__ import annotations

import difflib
import functools
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp
from lark import Lark, Token, Tree
from lark.exceptions import UnexpectedEOF, UnexpectedInput, UnexpectedToken
from lark.lexer import Lexer

from pendverify.analytic import expression_limits as limits
from pendverify.analytic.matlab_source import CONTROL, MAX_FILE_BYTES, SourceError, Statement, Tok, tokens_of

FUNCTIONS = {
    "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "exp": sp.exp, "sqrt": sp.sqrt, "abs": sp.Abs,
    "log": sp.log, "asin": sp.asin, "acos": sp.acos, "atan": sp.atan, "sinh": sp.sinh, "cosh": sp.cosh,
    "tanh": sp.tanh, "sign": sp.sign,
}  # fmt: skip
#: functions of two arguments, element-wise (MATLAB's names of the operators among them)
BINARY_FUNCTIONS = {
    "atan2": sp.atan2,
    "power": limits.power,
    "times": lambda a, b: a * b,
    "plus": lambda a, b: a + b,
    "minus": lambda a, b: a - b,
    "rdivide": lambda a, b: a / b,
}
#: functions that build or refill matrices
MATRIX_FUNCTIONS = ("reshape", "zeros", "ones", "eye", "transpose", "ctranspose")
CONSTANTS = {"pi": sp.pi}
#: the most nodes an expression may have, counted over its tree (a 7-link arm's q̈ entry, printed
#: out whole, is about 10⁵; a doubling chain of assignments passes it within 17 lines)
MAX_TREE = 2_000_000

GRAMMAR = r"""
%declare NAME NUMBER FUNCTION END IF CMP ASSIGN ADD SUB MUL EMUL DIV EDIV POW EPOW TRANSPOSE COLON DOT
%declare _LPAR _RPAR _LSQB _RSQB _COMMA _ROWSEP

?statement: header | assign | condition | END -> end_block | expr -> bare

header: FUNCTION NAME ASSIGN NAME params? -> header_one
      | FUNCTION _LSQB names? _RSQB ASSIGN NAME params? -> header_many
      | FUNCTION NAME params? -> header_none
names: NAME (_COMMA NAME)*
params: _LPAR (NAME (_COMMA NAME)*)? _RPAR
condition: IF NAME CMP NUMBER
assign: NAME ASSIGN expr -> assign_name
      | NAME _LPAR arguments _RPAR ASSIGN expr -> assign_entry

arguments: index (_COMMA index)*
?index: expr | COLON -> colon | expr COLON expr -> span

?expr: sum
?sum: product ((ADD | SUB) product)*
?product: unary ((MUL | EMUL | DIV | EDIV) unary)*
?unary: power | SUB unary -> neg | ADD unary -> pos
?power: postfix ((POW | EPOW) exponent)*
?exponent: postfix | SUB exponent -> neg | ADD exponent -> pos
?postfix: atom | postfix TRANSPOSE -> transpose
?atom: NUMBER -> number
     | NAME -> name
     | NAME _LPAR arguments _RPAR -> call
     | NAME _LPAR _RPAR -> call
     | _LPAR expr _RPAR
     | _LSQB rows _RSQB -> matrix
     | NAME DOT NAME -> field
rows: row? (_ROWSEP row?)*
row: expr (_COMMA expr)*
"""

_TERMINALS = {"LPAR": "_LPAR", "RPAR": "_RPAR", "LSQB": "_LSQB", "RSQB": "_RSQB", "COMMA": "_COMMA"}
_TERMINALS["ROWSEP"] = "_ROWSEP"


class _Tokens(Lexer):
    """lark's lexer interface over the statement's tokens (``matlab_source`` made them)."""

    def __init__(self, lexer_conf):
        pass

    def lex(self, data: list[Tok]):
        for t in data:
            yield Token(_TERMINALS.get(t.type, t.type), t.text, line=t.line, column=t.column)


@functools.cache
def _parser() -> Lark:
    return Lark(GRAMMAR, start="statement", parser="lalr", lexer=_Tokens, maybe_placeholders=False)


@dataclass(frozen=True)
class VectorArgument:
    """A vector argument: its entries, in order; ``(k)``, ``(k,:)``, ``(:,k)`` all give entry k."""

    name: str
    entries: tuple

    def matrix(self) -> sp.ImmutableMatrix:
        return sp.ImmutableMatrix(self.entries)


@dataclass(frozen=True)
class StructArgument:
    """A structure argument, read by its fields."""

    name: str
    fields: dict


@dataclass(frozen=True)
class UnboundArgument:
    """An argument the declaration gives no meaning: reading it names the argument and the fix."""

    why: str


@dataclass
class MatlabFunction:
    """A ``.m`` file cut into statements: its function's name, outputs and arguments (a script has
    no name and no arguments; its outputs are the names it assigns)."""

    path: Path
    name: str | None
    outputs: tuple[str, ...]
    arguments: tuple[str, ...]
    statements: list[tuple[Statement, Tree]]


@dataclass
class Output:
    """An output's value and where it was written: the line of its last whole assignment, and the
    line of each entry (row, column; 0-based) set by itself since then."""

    value: object
    line: int
    entry_lines: dict = field(default_factory=dict)

    def line_of(self, position: tuple[int, ...]) -> int:
        return self.entry_lines.get(position, self.line)


def read_source(path: Path) -> str:
    """The file's text: UTF-8 (or Latin-1, as MATLAB writes on some systems), at most
    ``MAX_FILE_BYTES``; ``OSError`` and ``SourceError`` as they come."""
    size = path.stat().st_size
    if size > MAX_FILE_BYTES:
        raise SourceError(f"{size} bytes; a model file is read up to {MAX_FILE_BYTES} bytes", 1, 0)
    raw = path.read_bytes()
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def parse_function(path: Path, text: str) -> MatlabFunction:
    """The file's statements parsed (``SourceError`` at the first problem), nothing evaluated."""
    parsed, name, outputs, arguments = [], None, (), ()
    blocks: list[str] = []
    for statement in tokens_of(text):
        first = statement.tokens[0]
        if first.type == "NAME" and first.text in CONTROL and not _is_assignment(statement):
            raise SourceError(
                f"'{first.text}' is not read: a model file is straight-line code (assignments, and the "
                "'if nargout > K' blocks matlabFunction writes)",
                first.line,
                first.column,
            )
        tree = _parse(statement)
        if tree.data in ("header_one", "header_many", "header_none"):
            if name is not None or parsed:
                raise SourceError(
                    "a second function: a model file holds one function (give each in its own file)",
                    first.line,
                    first.column,
                )
            name, outputs, arguments = _header(tree)
            blocks.append("function")
            continue
        if tree.data == "condition":
            blocks.append("if")
        elif tree.data == "end_block":
            if not blocks:
                raise SourceError("'end' closes nothing", first.line, first.column)
            blocks.pop()
        parsed.append((statement, tree))
    if blocks and blocks[-1] == "if":
        last = parsed[-1][0].tokens[-1]
        raise SourceError("an 'if' is never closed by 'end'", last.line, last.column)
    return MatlabFunction(path, name, outputs, arguments, parsed)


def _is_assignment(statement: Statement) -> bool:
    return len(statement.tokens) > 1 and statement.tokens[1].type == "ASSIGN"


def _parse(statement: Statement) -> Tree:
    try:
        return _parser().parse(statement.tokens)
    except UnexpectedEOF:
        last = statement.tokens[-1]
        raise SourceError("the statement ends too early", last.line, last.column + len(last.text)) from None
    except UnexpectedToken as exc:
        token = exc.token
        if token.type == "$END":
            last = statement.tokens[-1]
            raise SourceError(
                "the statement ends too early", last.line, last.column + len(last.text)
            ) from None
        text = token.value.strip() or "a blank between elements"
        raise SourceError(f"unexpected '{text}'", token.line, token.column) from None
    except UnexpectedInput as exc:  # pragma: no cover - the lexer gives only known tokens
        raise SourceError(f"not read: {exc}", statement.line, 0) from None


def _header(tree: Tree) -> tuple[str, tuple[str, ...], tuple[str, ...]]:
    names = [t for t in tree.children if isinstance(t, Token) and t.type == "NAME"]
    subtrees = {c.data: c for c in tree.children if isinstance(c, Tree)}
    params = tuple(str(t) for t in subtrees["params"].children) if "params" in subtrees else ()
    if tree.data == "header_one":
        outputs, name = (str(names[0]),), str(names[1])
    elif tree.data == "header_many":
        outputs = tuple(str(t) for t in subtrees["names"].children) if "names" in subtrees else ()
        name = str(names[0])
    else:
        outputs, name = (), str(names[0])
    return name, outputs, params


@dataclass(frozen=True)
class Assignment:
    """A statement ``name = expression`` whose value is a scalar: the temporaries ``t2 = cos(q2);``
    that ``matlabFunction`` writes, and a model's scalar outputs."""

    index: int  # the statement's place in ``MatlabFunction.statements``
    name: str
    line: int
    last_line: int  # the line of its last token (a statement continued with ``...`` spans several)
    value: sp.Expr


def evaluate(function: MatlabFunction, bindings: dict[str, object]) -> dict[str, Output]:
    """The function's outputs (a script's: every name it assigns), its arguments bound to
    ``bindings`` (SymPy symbols, ``VectorArgument``\\ s, ``StructArgument``\\ s); ``SourceError``
    at the first problem."""
    return traced(function, bindings)[0]


def traced(
    function: MatlabFunction, bindings: dict[str, object], replaced: tuple[int, object] | None = None
) -> tuple[dict[str, Output], list[Assignment]]:
    """``evaluate``'s outputs and the scalar ``Assignment``\\ s made on the way; with ``replaced``
    (a statement's index, a value), that statement's name takes the value instead of its
    expression's (what the file would give were the statement's right-hand side that value)."""
    run = _Evaluation(dict(bindings), replaced)
    for index, (statement, tree) in enumerate(function.statements):
        run.index = index
        run.statement(statement, tree)
    return _outputs(function, run), run.scalars


def _outputs(function: MatlabFunction, run) -> dict[str, Output]:
    if function.name is None:
        return run.assigned
    missing = [o for o in function.outputs if o not in run.assigned]
    if missing:
        header = function.statements[0][0] if function.statements else None
        raise SourceError(
            f"output {missing[0]} of {function.name} is never assigned", header.line if header else 1, 0
        )
    return {o: run.assigned[o] for o in function.outputs}


class _Evaluation:
    def __init__(self, bindings: dict[str, object], replaced: tuple[int, object] | None = None):
        self.values = bindings
        self.arguments = set(bindings)
        self.assigned: dict[str, Output] = {}
        self.sizes: dict = {}
        self.replaced = replaced
        self.index = -1
        self.scalars: list[Assignment] = []

    # statements
    def statement(self, statement: Statement, tree: Tree) -> None:
        kind = tree.data
        if kind == "end_block":
            return
        if kind == "condition":
            name, cmp, number = (str(c) for c in tree.children[1:])
            if name != "nargout" or cmp not in (">", ">="):
                raise SourceError(
                    f"'if {name} {cmp} {number}' is not read: only the 'if nargout > K' blocks "
                    "matlabFunction writes (a model's outputs do not depend on a condition)",
                    statement.line,
                    tree.children[1].column,
                )
            return
        if kind == "bare":
            self.value(tree.children[0])
            return
        target = tree.children[0]
        line = statement.line
        if kind == "assign_name":
            replaced = self.replaced is not None and self.replaced[0] == self.index
            value = self.replaced[1] if replaced else self.value(tree.children[2])
            self._refuse_argument(target)
            self.values[str(target)] = value
            self.assigned[str(target)] = Output(value, line)
            if isinstance(value, sp.Expr) and not isinstance(value, sp.MatrixBase):
                last = max(t.line for t in statement.tokens)
                self.scalars.append(Assignment(self.index, str(target), line, last, value))
            return
        arguments, value = tree.children[1], self.value(tree.children[3])
        self._refuse_argument(target)
        name = str(target)
        current = self.values.get(name, sp.ImmutableMatrix(0, 0, []))
        if isinstance(current, sp.Expr):
            current = sp.ImmutableMatrix([[current]])
        if not isinstance(current, sp.MatrixBase):
            raise SourceError(
                f"'{name}' is not a matrix: its entries cannot be set", target.line, target.column
            )
        if isinstance(value, sp.MatrixBase):
            if value.shape != (1, 1):
                raise SourceError("an entry is set to a matrix: give one value", target.line, target.column)
            value = value[0, 0]
        positions = self._positions(arguments, current.shape, grow=True)
        matrix = current.as_mutable()
        for i, j in positions:
            if i >= matrix.rows:
                matrix = matrix.col_join(sp.zeros(i + 1 - matrix.rows, max(matrix.cols, 1)))
            if j >= matrix.cols:
                matrix = matrix.row_join(sp.zeros(matrix.rows, j + 1 - matrix.cols))
            matrix[i, j] = value
        result = sp.ImmutableMatrix(matrix)
        self.values[name] = result
        previous = self.assigned.get(name)
        entry_lines = dict(previous.entry_lines) if previous else {}
        entry_lines.update(dict.fromkeys(positions, line))
        self.assigned[name] = Output(result, previous.line if previous else line, entry_lines)

    def _refuse_argument(self, target: Token) -> None:
        if str(target) in self.arguments:
            raise SourceError(
                f"'{target}' is an argument: a model file does not assign its arguments",
                target.line,
                target.column,
            )
        if str(target) in FUNCTIONS or str(target) in CONSTANTS:
            raise SourceError(f"'{target}' names a function or constant", target.line, target.column)

    # expressions
    def value(self, node):
        if isinstance(node, Token):  # pragma: no cover - every token is wrapped by a rule
            raise SourceError(f"unexpected '{node}'", node.line, node.column)
        method = getattr(self, "_" + node.data)
        return method(node)

    def _number(self, node):
        token = node.children[0]
        try:
            limits.literal(token.value)  # digits and range, as the text reader bounds them
            return self._checked(sp.Rational(token.value), token)
        except limits.ExpressionTooLarge as exc:
            raise SourceError(str(exc), token.line, token.column) from None

    def _name(self, node):
        token = node.children[0]
        name = str(token)
        if name in self.values:
            return self._bound(token, self.values[name])
        if name in CONSTANTS:
            return CONSTANTS[name]
        if name in FUNCTIONS or name in BINARY_FUNCTIONS:
            raise SourceError(f"{name} must be called: {name}(…)", token.line, token.column)
        raise self._unknown(token)

    def _bound(self, token: Token, value):
        if isinstance(value, UnboundArgument):
            raise SourceError(value.why, token.line, token.column)
        return value.matrix() if isinstance(value, VectorArgument) else value

    def _unknown(self, token: Token) -> SourceError:
        known = [n for n in self.values if not n.startswith("_")]
        close = difflib.get_close_matches(str(token), known, n=3)
        where = "an argument, a declared name or a name assigned above"
        hint = f"; did you mean {', '.join(close)}?" if close else ""
        return SourceError(f"unknown name '{token}' (not {where}){hint}", token.line, token.column)

    def _field(self, node):
        owner, _, name = node.children
        value = self.values.get(str(owner))
        if not isinstance(value, StructArgument):
            raise SourceError(f"'{owner}' is not a structure argument", owner.line, owner.column)
        if str(name) not in value.fields:
            close = difflib.get_close_matches(str(name), list(value.fields), n=3)
            hint = f"; did you mean {', '.join(close)}?" if close else ""
            raise SourceError(f"'{owner}' has no field '{name}'{hint}", name.line, name.column)
        return value.fields[str(name)]

    def _neg(self, node):
        value = self.value(node.children[1])
        return self._checked(-value, node.children[0])

    def _pos(self, node):
        return self.value(node.children[1])

    def _transpose(self, node):
        value = self.value(node.children[0])
        return value.T if isinstance(value, sp.MatrixBase) else value

    def _sum(self, node):
        return self._chain(node, self._add)

    def _product(self, node):
        return self._chain(node, self._multiply)

    def _power(self, node):
        return self._chain(node, self._raise)

    def _chain(self, node, combine):
        children = node.children
        value = self.value(children[0])
        for k in range(1, len(children), 2):
            operator = children[k]
            value = combine(operator, value, self.value(children[k + 1]))
        return value

    def _add(self, op: Token, a, b):
        if op.type == "SUB":
            b = self._checked(-b, op) if not isinstance(b, sp.MatrixBase) else -b
        return self._elementwise(op, a, b, lambda x, y: x + y)

    def _multiply(self, op: Token, a, b):
        kind = op.type
        if kind == "MUL" and isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase):
            if a.shape == (1, 1) or b.shape == (1, 1):
                return self._elementwise(op, a, b, lambda x, y: x * y)
            if a.cols != b.rows:
                raise SourceError(
                    f"a {a.rows}×{a.cols} matrix times a {b.rows}×{b.cols} one: the sizes do not match",
                    op.line,
                    op.column,
                )
            return self._matrix_checked(a * b, op)
        if kind in ("DIV", "EDIV"):
            if kind == "DIV" and isinstance(b, sp.MatrixBase) and b.shape != (1, 1):
                raise SourceError(
                    "'/' by a matrix (a linear solve) is not read: divide by scalars, or use ./",
                    op.line,
                    op.column,
                )
            for divisor in b if isinstance(b, sp.MatrixBase) else (b,):
                if divisor == 0:
                    raise SourceError("division by zero", op.line, op.column)
            return self._elementwise(op, a, b, lambda x, y: x / y)
        return self._elementwise(op, a, b, lambda x, y: x * y)

    def _raise(self, op: Token, a, b):
        if op.type == "POW" and (
            (isinstance(a, sp.MatrixBase) and a.shape != (1, 1))
            or (isinstance(b, sp.MatrixBase) and b.shape != (1, 1))
        ):
            raise SourceError("'^' of a matrix is not read: use .^ for powers of entries", op.line, op.column)
        return self._elementwise(op, a, b, lambda x, y: limits.power(x, y))

    def _elementwise(self, op: Token, a, b, combine):
        a, b = _scalar(a), _scalar(b)
        try:
            if not isinstance(a, sp.MatrixBase) and not isinstance(b, sp.MatrixBase):
                return self._checked(combine(a, b), op)
            if isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase):
                if a.shape != b.shape:
                    raise SourceError(
                        f"'{op}' of a {a.rows}×{a.cols} and a {b.rows}×{b.cols} matrix: the sizes differ",
                        op.line,
                        op.column,
                    )
                entries = [combine(x, y) for x, y in zip(a, b, strict=True)]
                shape = a.shape
            elif isinstance(a, sp.MatrixBase):
                entries, shape = [combine(x, b) for x in a], a.shape
            else:
                entries, shape = [combine(a, y) for y in b], b.shape
        except limits.ExpressionTooLarge as exc:
            raise SourceError(str(exc), op.line, op.column) from None
        return self._matrix_checked(sp.ImmutableMatrix(*shape, entries), op)

    def _matrix(self, node):
        rows_node = node.children[0]
        rows = []
        for row in rows_node.children:
            blocks = [_as_matrix(self.value(e)) for e in row.children]
            blocks = [b for b in blocks if b.shape != (0, 0)]
            if not blocks:
                continue
            heights = {b.rows for b in blocks}
            if len(heights) > 1:
                raise SourceError("the elements of a row have different heights", _line(row), _column(row))
            rows.append(sp.ImmutableMatrix(sp.Matrix.hstack(*blocks)))
        if not rows:
            return sp.ImmutableMatrix(0, 0, [])
        if len({r.cols for r in rows}) > 1:
            raise SourceError(
                f"the rows of a matrix have different lengths ({', '.join(str(r.cols) for r in rows)})",
                _line(node),
                _column(node),
            )
        return _scalar(sp.ImmutableMatrix(sp.Matrix.vstack(*rows)))

    def _call(self, node):
        token = node.children[0]
        name = str(token)
        arguments = node.children[1].children if len(node.children) > 1 else []
        if name in self.values:  # indexing a variable or an argument
            value = self.values[name]
            if isinstance(value, UnboundArgument):
                self._bound(token, value)
            if not arguments:
                return value.matrix() if isinstance(value, VectorArgument) else value
            return self._index(token, value, node.children[1])
        values = [self.value(a) if not _is_index_only(a) else a for a in arguments]
        if any(isinstance(v, Tree) for v in values):
            raise SourceError(f"':' is an index, not an argument of {name}", token.line, token.column)
        if name in FUNCTIONS:
            if len(values) != 1:
                raise SourceError(f"{name} takes one argument, got {len(values)}", token.line, token.column)
            return self._map(token, FUNCTIONS[name], values[0])
        if name in BINARY_FUNCTIONS:
            return self._two(token, name, values)
        if name == "reshape":
            return self._reshape(token, values)
        if name in ("zeros", "ones", "eye"):
            return self._filled(token, name, values)
        if name in ("transpose", "ctranspose") and len(values) == 1:
            v = values[0]
            return v.T if isinstance(v, sp.MatrixBase) else v
        raise SourceError(
            f"'{name}' is not a function a model may call "
            f"({', '.join([*FUNCTIONS, *BINARY_FUNCTIONS, *MATRIX_FUNCTIONS])})",
            token.line,
            token.column,
        )

    def _map(self, token: Token, function, value):
        try:
            if isinstance(value, sp.MatrixBase):
                return self._matrix_checked(value.applyfunc(function), token)
            return self._checked(function(value), token)
        except limits.ExpressionTooLarge as exc:
            raise SourceError(str(exc), token.line, token.column) from None

    def _two(self, token: Token, name: str, values: list):
        if len(values) != 2:
            raise SourceError(f"{name} takes two arguments, got {len(values)}", token.line, token.column)
        combine = BINARY_FUNCTIONS[name]
        op = Token("EMUL", name, line=token.line, column=token.column)
        return self._elementwise(op, values[0], values[1], combine)

    def _reshape(self, token: Token, values: list):
        if len(values) == 2:
            size = _as_matrix(values[1])
            dims = list(size)
        else:
            dims = values[1:]
        if len(values) < 2 or len(dims) != 2 or not all(isinstance(d, sp.Integer) and d >= 0 for d in dims):
            raise SourceError(
                "reshape takes a matrix and two sizes (reshape(v, r, c) or reshape(v, [r, c]))",
                token.line,
                token.column,
            )
        source = _as_matrix(values[0])
        r, c = int(dims[0]), int(dims[1])
        if r * c != len(source):
            raise SourceError(
                f"reshape of {len(source)} entries into {r}×{c}: the counts differ", token.line, token.column
            )
        column_major = [source[k % source.rows, k // source.rows] for k in range(len(source))]
        return _scalar(sp.ImmutableMatrix(c, r, column_major).T)

    def _filled(self, token: Token, name: str, values: list):
        dims = values if len(values) != 1 else [values[0], values[0]]
        if len(values) == 1 and isinstance(values[0], sp.MatrixBase):
            dims = list(values[0])
        if len(dims) != 2 or not all(isinstance(d, sp.Integer) and 0 <= d <= 10_000 for d in dims):
            raise SourceError(f"{name} takes sizes: {name}(r, c) or {name}(n)", token.line, token.column)
        r, c = int(dims[0]), int(dims[1])
        if r * c > 1_000_000:
            raise SourceError(f"{name}({r}, {c}) is too large for a model", token.line, token.column)
        matrix = {"zeros": sp.zeros, "ones": sp.ones, "eye": sp.eye}[name](r, c)
        return _scalar(sp.ImmutableMatrix(matrix))

    # indexing
    def _index(self, token: Token, value, arguments: Tree):
        if isinstance(value, StructArgument):
            raise SourceError(
                f"'{token}' is a structure: read its fields ({token}.name)", token.line, token.column
            )
        if isinstance(value, VectorArgument):
            picks = self._vector_positions(token, value, arguments)
            picked = [value.entries[k] for k in picks]
            return picked[0] if len(picked) == 1 else sp.ImmutableMatrix(picked)
        matrix = _as_matrix(value)
        positions = self._positions(arguments, matrix.shape, grow=False)
        rows = sorted({i for i, _ in positions})
        cols = sorted({j for _, j in positions})
        if len(arguments.children) == 1:  # linear indexing: a column of the entries picked
            entries = [matrix[i, j] for i, j in positions]
            return entries[0] if len(entries) == 1 else sp.ImmutableMatrix(entries)
        return _scalar(sp.ImmutableMatrix([[matrix[i, j] for j in cols] for i in rows]))

    def _vector_positions(self, token: Token, value: VectorArgument, arguments: Tree) -> list[int]:
        n = len(value.entries)
        indices = arguments.children
        if len(indices) == 2:
            first, second = indices
            if _is_colon(second) or self._is_one(second):
                indices = [first]
            elif _is_colon(first) or self._is_one(first):
                indices = [second]
            else:
                raise SourceError(
                    f"'{token}' is a vector: index it by one number (or with ':' or 1 beside it)",
                    token.line,
                    token.column,
                )
        if len(indices) != 1:
            raise SourceError(f"'{token}' is a vector: index it by one number", token.line, token.column)
        return self._one_index(indices[0], n, token, grow=False)

    def _is_one(self, node) -> bool:
        if _is_index_only(node):
            return False
        value = self.value(node)
        return value == 1

    def _positions(self, arguments: Tree, shape: tuple[int, int], grow: bool) -> list[tuple[int, int]]:
        indices = arguments.children
        rows, cols = shape
        token = _first_token(arguments)
        if len(indices) == 1:
            picks = self._one_index(indices[0], rows * cols, token, grow)
            if grow and picks and max(picks) >= rows * cols:
                if rows > 1 and cols > 1:
                    raise SourceError("a matrix grows by (row, column) indices", token.line, token.column)
                if rows <= 1:
                    return [(0, k) for k in picks]
                return [(k, 0) for k in picks]
            return [(k % rows, k // rows) for k in picks]
        if len(indices) != 2:
            raise SourceError("a matrix takes one or two indices", token.line, token.column)
        picked_rows = self._one_index(indices[0], rows, token, grow)
        picked_cols = self._one_index(indices[1], cols, token, grow)
        return [(i, j) for j in picked_cols for i in picked_rows]

    def _one_index(self, node, size: int, token: Token, grow: bool) -> list[int]:
        if _is_colon(node):
            return list(range(size))
        if isinstance(node, Tree) and node.data == "span":
            low, high = self._integer(node.children[0]), self._integer(node.children[2])
            picks = list(range(low - 1, high))
        else:
            picks = [self._integer(node) - 1]
        limit = 100_000 if grow else size
        for k in picks:
            if not 0 <= k < limit:
                raise SourceError(f"index {k + 1} is outside 1…{size}", token.line, token.column)
        return picks

    def _integer(self, node) -> int:
        value = _scalar(self.value(node))
        if not isinstance(value, sp.Integer):
            token = _first_token(node)
            raise SourceError("an index must be a whole number", token.line, token.column)
        return int(value)

    # bounds
    def _checked(self, value, token: Token):
        try:
            value = limits.checked(value)
        except limits.ExpressionTooLarge as exc:
            raise SourceError(str(exc), token.line, token.column) from None
        if isinstance(value, sp.Basic) and value.has(sp.zoo, sp.oo, sp.nan):
            raise SourceError("the value is not finite", token.line, token.column)
        if _tree_size(value, self.sizes) > MAX_TREE:
            raise SourceError(
                f"an expression of more than {MAX_TREE:,} nodes: past what a model's entry needs",
                token.line,
                token.column,
            )
        return value

    def _matrix_checked(self, matrix, token: Token):
        for entry in matrix:
            self._checked(entry, token)
        return _scalar(sp.ImmutableMatrix(matrix))


def _tree_size(expr, sizes: dict) -> int:
    """The number of nodes of ``expr`` as a tree (shared subexpressions counted each time), each
    subexpression's size computed once (``sizes``)."""
    if not isinstance(expr, sp.Basic) or not expr.args:
        return 1
    known = sizes.get(expr)
    if known is not None:
        return known
    stack, order = [expr], []
    while stack:
        node = stack.pop()
        if node in sizes or not node.args:
            continue
        order.append(node)
        stack.extend(a for a in node.args if a.args and a not in sizes)
    for node in reversed(order):
        sizes[node] = 1 + sum(sizes.get(a, 1) for a in node.args)
    return sizes[expr]


def _scalar(value):
    if isinstance(value, sp.MatrixBase) and value.shape == (1, 1):
        return value[0, 0]
    return value


def _as_matrix(value) -> sp.ImmutableMatrix:
    if isinstance(value, sp.MatrixBase):
        return sp.ImmutableMatrix(value)
    if isinstance(value, VectorArgument):
        return value.matrix()
    return sp.ImmutableMatrix([[value]])


def _is_colon(node) -> bool:
    return isinstance(node, Tree) and node.data == "colon"


def _is_index_only(node) -> bool:
    return isinstance(node, Tree) and node.data in ("colon", "span")


def _first_token(node) -> Token:
    if isinstance(node, Token):
        return node
    for child in node.children:
        token = _first_token(child)
        if token is not None:
            return token
    return Token("NAME", "", line=1, column=0)  # pragma: no cover - a rule always holds a token


def _line(node) -> int:
    return _first_token(node).line


def _column(node) -> int:
    return _first_token(node).column
