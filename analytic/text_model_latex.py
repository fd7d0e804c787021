"""The LaTeX side of a text model: its ``[symbols]`` table and its equations in LaTeX.

With ``notation = "latex"`` every equation value is LaTeX (``pendverify.analytic.
latex_parse``): one string holding the whole matrix or vector (a ``bmatrix``), or a
list of rows of LaTeX entries.  ``[symbols]`` maps each LaTeX symbol the equations
use to an expression in SymPy syntax over the model's names (coordinates, their
rates ``d<coordinate>``, inputs, disturbances, parameters): usually just a name
(``'\\theta_1' = "theta1"``), or a definition (``'\\beta' = "m2*l1*r2"``).  Two keys
that read as the same symbol (``x_1`` and ``x_{1}``, ``'θ_2'`` and ``'\\theta_2'``) are one
declaration when they say the same (their expressions' difference expands to zero), and
refused when they do not.
"""

from __future__ import annotations

import re

import sympy as sp

from pendverify.analytic.latex_names import conventions
from pendverify.analytic.latex_normalise import canonical_symbol, toml_escapes
from pendverify.analytic.latex_parse import LatexError, LatexReader, SymbolTable
from pendverify.display import shortened


def refuse_toml_escapes(reader, data: dict, keys) -> None:
    """Refuse LaTeX that TOML's double quotes corrupted (``latex_normalise.toml_escapes``): the
    strings under ``keys`` (each entry of a list by its index) and the ``[symbols]`` table's keys."""

    def walk(key: str, value, index: tuple[int, ...] = ()):
        if isinstance(value, str):
            why = toml_escapes(value)
            if why is not None:
                reader.fail(key + (f"[{','.join(map(str, index))}]" if index else ""), why)
        elif isinstance(value, list):
            for i, x in enumerate(value):
                walk(key, x, (*index, i))

    for key in keys:
        walk(key, data.get(key))
    table = data.get("symbols")
    if isinstance(table, dict):
        for key in table:
            why = toml_escapes(key)
            if why is not None:
                reader.fail("symbols", f"a key {why[len('this LaTeX ') :]}")


def read_symbol_table(reader, table, allowed: dict, parse_entry, spec) -> LatexReader:
    """The names by convention (``latex_names``) and the ``[symbols]`` table over them (the table
    wins), read into a ``LatexReader``; each table value is parsed by ``parse_entry``."""
    if table is None:
        table = {}
    if not isinstance(table, dict):
        reader.fail("symbols", "must be a table such as '\\beta' = \"m2*l1*r2\"")
    declared = (*spec.inputs, *spec.disturbances, *spec.parameters)
    by_convention = conventions(spec.coordinates, declared, allowed)
    entries = {k: c.value for k, c in by_convention.items()}
    source = {k: k for k in by_convention}
    written: dict[str, str] = {}
    for key, value in table.items():
        if not isinstance(value, str):
            reader.fail(
                f"symbols.{key}", "must be a model name or an expression in SymPy syntax, as a string"
            )
        try:
            canonical = canonical_symbol(key)
        except LatexError as exc:
            reader.fail(f"symbols.{key}", str(exc))
        if not canonical or any(c in re.sub(r"_\{[^{}]*\}", "", canonical) for c in "+-*/=&()"):
            reader.fail(f"symbols.{key}", "is not one LaTeX symbol (a letter or command, with a subscript)")
        parsed = parse_entry(reader, f"symbols.{key}", value, allowed)
        if canonical in written:
            if sp.expand(parsed - entries[canonical]) != 0:
                reader.fail(
                    f"symbols.{key}",
                    f"reads as the same symbol as '{written[canonical]}', which says "
                    f"{shortened(sp.sstr(entries[canonical]), 60)}, not {shortened(sp.sstr(parsed), 60)}",
                )
            continue  # the same declaration twice: the first spelling names it
        entries[canonical] = parsed
        source[canonical] = written[canonical] = key
    conventional = {k: c for k, c in by_convention.items() if k not in written}
    return LatexReader(SymbolTable(entries, source, conventional))


def parse_latex_equation(reader, latex: LatexReader, key: str, value, rows: int, cols: int | None, allowed):
    """One equation in LaTeX: a matrix (rows × cols), a column vector (cols None) or a scalar (rows 0)."""

    read_as_ddot = {c.value for c in latex.table.conventional.values() if c.latex.startswith("\\ddot")}

    def read(k: str, text):
        if not isinstance(text, str):
            reader.fail(k, f"must be LaTeX, as a string, got {shortened(repr(text), 60)}")
        try:
            value = latex.read(text)[0]
        except LatexError as exc:
            if exc.at is None:
                reader.fail(k, exc.why)
            reader.fail_at(k, exc.why, exc.text, exc.at)
        if value.free_symbols & read_as_ddot and not (set(allowed.values()) >= read_as_ddot):
            where = re.search(r"\\ddot|\u0308|[ẍÿ]", text)
            reader.fail_at(
                k,
                "an acceleration (\\ddot): this is an equation of motion, not "
                f"{key}; give it under `equations`",
                text,
                where.start() if where else 0,
            )
        return value

    if isinstance(value, list):
        if cols is None or rows == 0:
            value = [value] if rows == 0 else [[x] for x in value]
        elif not all(isinstance(r, list) for r in value):
            reader.fail(
                key,
                "wrong shape: a matrix is one LaTeX string (a bmatrix) or a list of rows, "
                f"each a list of LaTeX entries; with {rows} coordinate{'s' if rows != 1 else ''} "
                f"{key} must be {rows} × {cols}",
            )
        parsed = sp.Matrix(
            [[read(f"{key}[{i},{j}]", x) for j, x in enumerate(r)] for i, r in enumerate(value)]
        )
        if any(isinstance(x, sp.MatrixBase) for x in parsed):
            reader.fail(key, "an entry of the list is itself a matrix")
    else:
        parsed = read(key, value)
    want = (rows, cols if cols is not None else 1)
    if rows == 0:
        if isinstance(parsed, sp.MatrixBase):
            if parsed.shape != (1, 1):
                reader.fail(key, f"wrong shape: the LaTeX gives a {_shape(parsed)}, {key} is a scalar")
            parsed = parsed[0, 0]
    else:
        if not isinstance(parsed, sp.MatrixBase):
            parsed = sp.Matrix([[parsed]])
        if cols is None and parsed.rows == 1 and parsed.cols == rows and rows > 1:
            parsed = parsed.T  # a vector printed as a row
        if parsed.shape != want:
            kind = f"{rows} × {cols}" if cols is not None else f"a vector of {rows}"
            given = _shape(parsed)
            reader.fail(
                key,
                f"wrong shape: the LaTeX gives {given}; with {rows} coordinate{'s' if rows != 1 else ''} "
                f"{key} must be {kind}",
            )
    stray = parsed.free_symbols - set(allowed.values())
    accelerations = sorted(s.name for s in stray & read_as_ddot)
    if accelerations:
        reader.fail(
            key,
            f"holds the acceleration {', '.join(accelerations)} (a \\ddot): this is an equation of motion, "
            f"not {key}; give it under `equations`",
        )
    if stray:
        names = ", ".join(sorted(s.name for s in stray))
        reader.fail(key, f"depends on {names}, which {key} may not (its arguments: {_args(allowed)})")
    return parsed


def _shape(m) -> str:
    return f"{m.rows} row{'s' if m.rows != 1 else ''} of {m.cols} entr{'ies' if m.cols != 1 else 'y'}"


def _args(allowed: dict) -> str:
    return ", ".join(k for k, v in allowed.items() if isinstance(v, sp.Symbol)) or "none"
