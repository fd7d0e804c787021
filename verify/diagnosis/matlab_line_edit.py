"""A confirmed repair of a ``.m`` model written as the one line of the file to change.

``matlabFunction`` computes an entry through temporaries (``t7 = -11*t2.*t3/10 - …;`` on one line,
``W = reshape([…,t7,…],[3,3]);`` on another), and one temporary often serves several entries
(M's symmetric pair).  The diagnosis confirms a repair entry by entry: each entry ``(key,
position)`` written ``old`` should be ``new``.  Its line edit is a scalar assignment ``name =
expression`` of a file whose value is one of those entries' ``old``, or its negative (OptimTraj's
acrobot returns −M entry by entry), such that, were its right-hand side that entry's ``new`` (or
its negative), the file's outputs would change in exactly the repaired entries, each to its
``new``, and nowhere else (the file is evaluated again, ``matlab_parse.traced``; the earliest such
line is printed).  So the line edit is the confirmed repair itself, not a guess at it.

The new right-hand side is written in the file's own names: the temporaries assigned before the
line (and the names it gives its arguments' entries, ``q2 = in1(2,:)``) replace the sub-expressions
they stand for, largest first, and the result is accepted only when putting their values back gives
the repaired value exactly; otherwise there is no line edit (the entry's repair is printed whole).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass
from pathlib import Path

import sympy as sp

from pendverify.analytic.matlab_parse import Assignment, traced
from pendverify.symbolic.zero_test import is_zero, probe

#: the largest value compared or rewritten (in SymPy operations): beyond it the exact zero test and
#: the substitutions cost more than a diagnosis may spend, and a printed line would not be read
MAX_OPS = 400


@dataclass(frozen=True)
class LineEdit:
    """The line of a ``.m`` file to change: where it is, as the file writes it and as repaired."""

    path: Path
    line: int
    written: str
    suggested: str


def line_edit(source, changes: dict, angles: tuple = ()) -> LineEdit | None:
    """The line edit of the repair ``changes`` ({(key, position): (old, new)}, the equation keys'
    entries) in the files of ``source`` (a ``MatlabSource``), or None (module docstring).
    ``angles``: the model's angle symbols, for the exact zero test of a difference."""
    cells = {}
    for (key, position), (old, new) in changes.items():
        found = _cell(source, key, position)
        if found is None:
            return None
        name, cell, sign = found
        cells[name, cell] = (sign * old, sign * new)
    names = {name for name, _ in cells}
    files = {source.outputs[name][0] for name in names}
    if len(files) != 1:
        return None
    (path,) = files
    function, bindings, text = source.functions[path]
    before, scalars = traced(function, bindings)
    for assignment in scalars:  # in the file's order: the earliest line that is the repair
        for (old, new), sign in itertools.product(cells.values(), (1, -1)):
            if _same(assignment.value, sign * old, angles):
                edit = _tried(source, path, assignment, sign * new, before, cells, scalars, text, angles)
                if edit is not None:
                    return edit
    return None


def _tried(
    source, path: Path, assignment: Assignment, new, before, cells, scalars, text, angles
) -> LineEdit | None:
    """The edit ``assignment``'s right-hand side → ``new``, if it changes exactly ``cells``."""
    function, bindings, _ = source.functions[path]
    after, _ = traced(function, bindings, (assignment.index, new))
    used = source.used  # read off the declaration's text: once, not per output
    for name, output in before.items():
        if name not in used:
            continue  # a script's temporary: every name a script assigns is an output
        value, changed = output.value, after[name].value
        for cell in _cells(value):
            was, now = _at(value, cell), _at(changed, cell)
            if (name, cell) in cells:
                if not _same(now, cells[name, cell][1], angles):
                    return None
            elif not _same(now, was, angles):
                return None
    rewritten = _in_file_names(new, [s for s in scalars if s.index < assignment.index], angles)
    if rewritten is None:
        return None
    lines = text.split("\n")[assignment.line - 1 : assignment.last_line]
    written = " ".join(line.strip().rstrip("\r") for line in lines)
    return LineEdit(path, assignment.line, written, f"{assignment.name} = {sp.octave_code(rewritten)};")


def _cell(source, key: str, position: tuple[int, ...]):
    """(output name, its cell, its sign) of an equation entry (``MatlabSource.output_cell``), or
    None; an entry written as a matrix output's name is not one scalar assignment's."""
    found = source.output_cell(key, position)
    if found is None or key in source.whole:
        return found
    return None if isinstance(source.outputs[found[0]][1].value, sp.MatrixBase) else found


def _cells(value) -> list[tuple[int, int]]:
    if isinstance(value, sp.MatrixBase):
        return [(i, j) for i in range(value.rows) for j in range(value.cols)]
    return [(0, 0)]


def _at(value, cell: tuple[int, int]):
    return value[cell] if isinstance(value, sp.MatrixBase) else value


def _same(a, b, angles: tuple) -> bool:
    """Whether two values are equal as functions: the same expression, else decided exactly
    (``zero_test.is_zero``) where their symbols agree and a 50-digit probe finds no difference."""
    if a == b:
        return True
    if not all(isinstance(x, sp.Expr) and not isinstance(x, sp.MatrixBase) for x in (a, b)):
        return False
    if a.free_symbols != b.free_symbols or sp.count_ops(a) + sp.count_ops(b) > 2 * MAX_OPS:
        return False
    difference = a - b
    return not probe(difference) and is_zero(difference, angles)


def _in_file_names(expr, earlier: list[Assignment], angles: tuple):
    """``expr`` with the values of the ``earlier`` assignments replaced by their names, largest
    first (module docstring), or None when that does not give ``expr`` back."""
    if sp.count_ops(expr) > MAX_OPS:
        return None
    stand_ins, seen = {}, set()
    for a in sorted(earlier, key=lambda a: (-sp.count_ops(a.value), a.index)):
        if a.value.is_number or a.value in seen:
            continue
        seen.add(a.value)
        stand_ins[a.name] = (sp.Dummy(a.name), a.value)
    out = expr
    for dummy, value in stand_ins.values():
        out = out.subs(value, dummy)
    back = out.xreplace({dummy: value for dummy, value in stand_ins.values()})
    if not _same(back, expr, angles):
        return None
    return out.xreplace({dummy: sp.Symbol(name, real=True) for name, (dummy, _) in stand_ins.items()})
