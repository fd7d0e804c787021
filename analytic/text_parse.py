"""Read a model written as text (TOML): its names, parameters, equations and URDF map.

A text model declares ``name``; ``[coordinates]`` (in order, each ``"angle"`` or
``"position"``); ``inputs`` and ``disturbances`` (optional lists of names);
``[parameters]`` (``m1 = { kind = "mass", unit = "kg" }``, the kinds of
``pendverify.analytic.params``); the equations as strings in SymPy syntax — ``M``
(rows of entries), ``C`` (matrix), ``C_plus_D`` (C with the friction inside, as
some derivations print it; needs ``D``) or ``Cqdot`` (the vector C·q̇), ``H``
(vector) and/or ``V`` (scalar; a missing H is ∂V/∂q, a missing V is integrated
from H), optional ``D``, ``B``, ``W``, ``det_M``, ``M_inv``, ``qddot`` — or, instead
of C, H, D, B and W, ``f``, the right-hand side of M q̈ = f(q, q̇, u, w) — or, instead of
all of them, ``equations``, the equations of motion whole (``lhs = rhs``, one per
coordinate, ``pendverify.analytic.text_equations``, or one matrix equation ``M*ddq + C*dq + G = B*u``
over the keys M, C, D, B, W, G (the gravity vector, as H) and h (the bias),
``pendverify.analytic.matrix_equation``) — with the rates named
``d<coordinate>`` and the accelerations ``dd<coordinate>``; and ``[urdf]`` (``joints``, ``transform``,
``offset``).  With ``notation = "latex"`` the equations are LaTeX and a
``[symbols]`` table maps the document's symbols (``pendverify.analytic.text_model_latex``).

Parsing is safe: no Python is run.  Each string may hold only numbers, the
declared names, + − * / ** and calls of sin, cos, tan, sqrt, exp (and pi); it is
read by ``pendverify.analytic.text_expression``, which builds the SymPy expression
itself, with bounded exact numbers and nesting
(``pendverify.analytic.expression_limits``).  Every problem is one line naming the
file, the key, what is wrong and where, quoting at most a short fragment.
"""

from __future__ import annotations

import difflib
import keyword
import math
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sp

from pendverify.analytic.matlab_model import read_matlab, whole_output
from pendverify.analytic.matrix_equation import matrix_text, read_matrix_equation
from pendverify.analytic.matrix_equation_parse import names_vectors
from pendverify.analytic.parameter_set import KIND_RULES
from pendverify.analytic.text_equations import latex_side, read_equations, split_equations
from pendverify.analytic.text_expression import FUNCTIONS, ExpressionError, fragment, read_expression
from pendverify.analytic.text_model_latex import parse_latex_equation, read_symbol_table, refuse_toml_escapes
from pendverify.display import shortened
from pendverify.documents import MISSING, Key, Table, check_keys, check_value, is_string, is_table, read_toml
from pendverify.errors import ExcerptError, ParameterError, PendverifyError, excerpt
from pendverify.file_kinds import expect_kind

CONSTANTS = {"pi": sp.pi}
TOP_KEYS = (
    "name", "notation", "coordinates", "inputs", "disturbances", "parameters", "symbols", "urdf",
    "M", "C", "C_plus_D", "Cqdot", "H", "V", "D", "B", "W", "f", "det_M", "M_inv", "qddot",
    "G", "h", "equations", "matlab", "balance",
)  # fmt: skip
#: the keys of a declaration without equations (a Python model file's ``DECLARATION``, the API's
#: ``declaration``): the equations come from elsewhere (``pendverify.analytic.mechanics_model``)
DECLARATION_KEYS = ("name", "coordinates", "inputs", "disturbances", "parameters", "urdf")
NOTATIONS = ("sympy", "latex")

# The rules of a text model's keys (``pendverify.documents``), read in the order
# notation, name, coordinates (each one's kind), inputs, disturbances, parameters (each one's
# declaration and unit); a rule's sentence is the problem after "FILE: key 'KEY': ".
NOTATION = Key(
    ((lambda v: v in NOTATIONS, lambda v: f"{v!r}: must be one of {', '.join(map(repr, NOTATIONS))}"),),
    required=False,
    default="sympy",
)
NAME = Key(((lambda v: is_string(v) and v.isidentifier(), "missing, or not a name (letters, digits, _)"),))
BALANCE = Key(((lambda v: isinstance(v, bool), "must be true or false"),), required=False, default=False)
COORDINATES = Key(
    ((lambda v: is_table(v) and bool(v), 'missing: a table such as theta1 = "angle", x = "position"'),)
)
COORDINATE_KIND = Key(
    ((lambda v: v in ("angle", "position"), lambda v: f'{v!r}: must be "angle" or "position"'),)
)
NAMES = Key(
    ((lambda v: isinstance(v, list) and all(map(is_string, v)), "must be a list of names"),),
    required=False,
    default=[],
)
PARAMETERS = Key(((is_table, 'missing: a table such as m1 = { kind = "mass", unit = "kg" }'),))
DECLARATION = Key(
    (
        (
            lambda d: (
                is_table(d)
                and is_string(d.get("kind"))
                and d["kind"] in KIND_RULES
                and not set(d) - {"kind", "unit", "doc"}
            ),
            f"must be {{ kind = ..., unit = ... }} with kind one of {', '.join(KIND_RULES)}",
        ),
    )
)
UNIT = Key(((is_string, "must be a string"),))


def _unknown(top_keys: tuple[str, ...]):
    """The rule for an unknown top-level key: the known keys it is close to, if any."""

    def rule(key: str) -> str:
        close = difflib.get_close_matches(key, top_keys, n=3)
        return f"unknown key{'; did you mean ' + ', '.join(close) + '?' if close else ''}"

    return rule


#: each equation: (shape as a string of dimension names, the argument groups it may use)
EQUATIONS = {
    "M": ("nn", "q"), "C": ("nn", "qv"), "C_plus_D": ("nn", "qv"), "Cqdot": ("n", "qv"), "H": ("n", "q"),
    "V": ("", "q"), "D": ("nn", ""), "B": ("nu", ""), "W": ("nw", ""), "f": ("n", "qvuw"),
    "det_M": ("", "q"), "M_inv": ("nn", "q"), "qddot": ("n", "qvuw"), "G": ("n", "q"), "h": ("n", "qv"),
    "equations": ("e", "qvuwa"),
}  # fmt: skip


@dataclass
class TextModelSpec:
    """What a text model file declares, its equations parsed into SymPy."""

    path: Path
    name: str
    coordinates: tuple[str, ...]
    angular: tuple[bool, ...]
    inputs: tuple[str, ...]
    disturbances: tuple[str, ...]
    parameters: dict[str, tuple[str, str]]  # name → (kind, unit)
    symbols: dict[str, tuple[sp.Symbol, ...]]  # "q", "v", "u", "w", "p"
    equations: dict[str, object] = field(default_factory=dict)  # key → sp.Matrix or scalar
    derived: dict[str, str] = field(default_factory=dict)  # key → how it was computed from others
    #: quantity → the file's own key for it where they differ (H → G of a matrix equation)
    written_names: dict[str, str] = field(default_factory=dict)
    notation: str = "sympy"
    #: with notation = "latex": the file's [symbols] table, each LaTeX key with what it reads as
    latex_symbols: dict[str, object] = field(default_factory=dict)
    #: with notation = "latex": the names its equations read by convention ("\\theta_1 → theta1")
    latex_conventions: list[str] = field(default_factory=list)
    urdf_joints: tuple[str, ...] = ()
    joint_transform: tuple | None = None
    joint_offset: tuple | None = None
    #: with a [matlab] table: the .m files read and where their outputs were written
    matlab: object = None
    #: balance = true: M q̈ = f are balance equations (M need not be the symmetric mass matrix)
    balance: bool = False


class Reader:
    def __init__(self, path: Path):
        self.path = path

    def fail(self, key: str, problem: str):
        raise PendverifyError(f"{self.path}: key '{shortened(key, 80)}': {problem}")

    def fail_at(self, key: str, problem: str, text: str, at: int):
        """The problem at position ``at`` of the key's ``text``: one error with a caret under it."""
        raise ExcerptError(f"{self.path}: key '{shortened(key, 80)}': {problem}", *excerpt(text, at))

    def rule(self, key: str, value, rule: str):
        """``fail`` as a ``pendverify.documents`` rule's ``fail`` (a text model's sentence shows no value)."""
        self.fail(key, rule)

    def value(self, data: dict, key: str, spec: Key, prefix: str = ""):
        """``data[key]`` (else the key's default, else None) checked by ``spec``'s rules."""
        value = data.get(key, None if spec.default is MISSING else spec.default)
        return check_value(prefix + key, value, spec, self.rule)

    def names(self, data: dict, key: str) -> tuple[str, ...]:
        value = self.value(data, key, NAMES)
        for name in value:
            self.identifier(key, name)
        return tuple(value)

    def identifier(self, key: str, name: str) -> None:
        if not name.isidentifier() or keyword.iskeyword(name) or name in FUNCTIONS or name in CONSTANTS:
            self.fail(
                key,
                f"{shortened(repr(name), 60)} is not a usable name (a Python identifier, not sin/cos/…/pi)",
            )

    def numbers(self, key: str, value, shape: tuple[int, ...]):
        """A list (or list of rows) of finite numbers of the given shape, as tuples."""
        try:
            array = sp.Matrix(value) if len(shape) == 2 else sp.Matrix([value])
        except (TypeError, ValueError, IndexError, sp.SympifyError):
            self.fail(key, f"must be {'rows of numbers' if len(shape) == 2 else 'a list of numbers'}")
        if (array.shape if len(shape) == 2 else (array.shape[1],)) != shape or not all(
            isinstance(x, int | float) and not isinstance(x, bool) and x == x and abs(x) != float("inf")
            for x in (value if len(shape) == 1 else [y for row in value for y in row])
        ):
            self.fail(key, f"must be finite numbers of shape {shape}")
        return tuple(map(float, value)) if len(shape) == 1 else tuple(tuple(map(float, row)) for row in value)


def parse_entry(reader: Reader, key: str, value, allowed: dict):
    """One expression: a string in SymPy syntax (or a plain number), read by ``text_expression``."""
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        reader.fail(key, f"each entry must be an expression string, got {shortened(repr(value), 60)}")
    if isinstance(value, float) and not math.isfinite(value):
        reader.fail(key, f"{value!r} is not finite")
    text = repr(value) if isinstance(value, float) else str(value)
    try:
        expr = read_expression(text, allowed)
    except ExpressionError as exc:
        reader.fail_at(key, f"{exc.why}, at character {exc.at + 1}", text, exc.at)
    if expr.has(sp.zoo, sp.oo, sp.nan):
        reader.fail(key, f"{fragment(text, 0)} is not finite")
    return expr


def parse_equation(reader: Reader, key: str, value, rows: int, cols: int | None, allowed: dict):
    """A matrix (rows × cols), a column vector (cols None, rows entries) or a scalar (rows 0)."""
    if rows == 0:
        return parse_entry(reader, key, value, allowed)
    want = (
        f"{rows} × {cols} (a list of {_count(rows, 'row')}, each a list of {_count(cols, 'entry')})"
        if cols is not None
        else _count(rows, "entry")
    )
    if cols is None:
        if not isinstance(value, list) or len(value) != rows or any(isinstance(x, list) for x in value):
            reader.fail(key, f"wrong shape: must be a vector of {want}")
        return sp.Matrix([parse_entry(reader, f"{key}[{i}]", x, allowed) for i, x in enumerate(value)])
    if (
        not isinstance(value, list)
        or len(value) != rows
        or not all(isinstance(r, list) and len(r) == cols for r in value)
    ):
        reader.fail(key, f"wrong shape: must be a matrix of {want}")
    return sp.Matrix(
        [
            [parse_entry(reader, f"{key}[{i},{j}]", x, allowed) for j, x in enumerate(r)]
            for i, r in enumerate(value)
        ]
    )


def _count(n: int, noun: str) -> str:
    """``1 row``, ``2 rows``, ``1 entry``, ``3 entries``."""
    plural = noun[:-1] + "ies" if noun.endswith("y") else noun + "s"
    return f"{n} {noun if n == 1 else plural}"


def read_text_model(path: str | Path) -> TextModelSpec:
    """Parse and check a text model file (module docstring)."""
    path = Path(path)
    try:
        data = read_toml(path, "model file")
    except ParameterError as exc:  # a syntax error: the file's, not a parameter's
        raise PendverifyError(str(exc)) from None
    expect_kind(data, path, "model")
    return read_text_document(path, data)


def read_text_document(path: Path, data: dict, top_keys: tuple[str, ...] = TOP_KEYS) -> TextModelSpec:
    """A text model's document (its TOML as a dict; ``path`` names it in messages), read and checked.

    ``top_keys``: the keys it may hold (a declaration without equations allows fewer).
    """
    reader = Reader(path)
    check_keys(
        data, Table(dict.fromkeys(top_keys, Key(required=False)), unknown=_unknown(top_keys)), reader.rule
    )
    notation = reader.value(data, "notation", NOTATION)
    if "symbols" in data and notation != "latex":
        reader.fail("symbols", 'a symbol table is for notation = "latex"')
    name = reader.value(data, "name", NAME)
    coords = reader.value(data, "coordinates", COORDINATES)
    for c in coords:
        reader.identifier(f"coordinates.{c}", c)
        reader.value(coords, c, COORDINATE_KIND, "coordinates.")
    inputs, disturbances = reader.names(data, "inputs"), reader.names(data, "disturbances")
    params = reader.value(data, "parameters", PARAMETERS)
    parameters = {}
    for p, decl in params.items():
        reader.identifier(f"parameters.{p}", p)
        reader.value(params, p, DECLARATION, "parameters.")
        unit = decl.get("unit", KIND_RULES[decl["kind"]][1])
        reader.value({"unit": unit}, "unit", UNIT, f"parameters.{p}.")
        parameters[p] = (decl["kind"], unit)
    rates = tuple(f"d{c}" for c in coords)
    accelerations = tuple(f"dd{c}" for c in coords)
    all_names = [*coords, *rates, *accelerations, *inputs, *disturbances, *parameters]
    twice = sorted({n for n in all_names if all_names.count(n) > 1})
    if twice:
        reader.fail(
            "coordinates",
            f"name(s) {', '.join(twice)} used twice among coordinates, d<coordinate> rates, "
            "dd<coordinate> accelerations, inputs, disturbances and parameters",
        )
    symbols = {
        "q": tuple(sp.Symbol(c, real=True) for c in coords),
        "v": tuple(sp.Symbol(r, real=True) for r in rates),
        "a": tuple(sp.Symbol(a, real=True) for a in accelerations),
        "u": tuple(sp.Symbol(n, real=True) for n in inputs),
        "w": tuple(sp.Symbol(n, real=True) for n in disturbances),
        "p": tuple(
            sp.Symbol(
                p, real=True, **({"positive": True} if k in ("mass", "length") else {"nonnegative": True})
            )
            for p, (k, _) in parameters.items()
        ),
    }
    spec = TextModelSpec(
        path, name, tuple(coords), tuple(k == "angle" for k in coords.values()),
        inputs, disturbances, parameters, symbols,
    )  # fmt: skip
    spec.notation = notation
    spec.balance = reader.value(data, "balance", BALANCE)
    _read_equations(reader, spec, data)
    _read_urdf(reader, spec, data.get("urdf", {}))
    return spec


def _read_equations(reader: Reader, spec: TextModelSpec, data: dict) -> None:
    n = len(spec.coordinates)
    dims = {"n": n, "u": len(spec.inputs), "w": len(spec.disturbances)}
    latex = None
    if spec.notation == "latex":
        refuse_toml_escapes(reader, data, EQUATIONS)
        everything = {s.name: s for g in "qvuwap" for s in spec.symbols[g]} | FUNCTIONS | CONSTANTS
        latex = read_symbol_table(reader, data.get("symbols"), everything, parse_entry, spec)
    outputs: dict = {}
    if "matlab" in data:
        if latex is not None:
            reader.fail(
                "matlab", 'the equations of a [matlab] table are read as SymPy, not notation = "latex"'
            )
        spec.matlab, outputs = read_matlab(reader, spec, data["matlab"])
        if not any(key in data for key in EQUATIONS):
            reader.fail(
                "matlab", "says which files, but no key says which output is which: give M, f, qddot, …"
            )
    scalars = {k: v for k, v in outputs.items() if not isinstance(v, sp.MatrixBase)}
    for key, (shape, groups) in EQUATIONS.items():
        if key not in data:
            continue
        allowed = {s.name: s for g in groups + "p" for s in spec.symbols[g]} | FUNCTIONS | CONSTANTS
        if outputs:
            spec.matlab.written[key] = data[key]
            rows = n if shape else 0
            cols = dims[shape[1]] if len(shape) == 2 else None
            whole = (
                whole_output(reader, spec.matlab, outputs, key, data[key], (rows, cols))
                if rows and shape != "e"
                else None
            )
            if whole is not None:
                spec.equations[key] = whole
                continue
            allowed = allowed | scalars
        if shape == "e":
            _read_whole_equations(reader, spec, data, key, allowed, latex)
            continue
        rows = n if shape else 0
        cols = dims[shape[1]] if len(shape) == 2 else None
        if latex is not None:
            spec.equations[key] = parse_latex_equation(reader, latex, key, data[key], rows, cols, allowed)
        else:
            spec.equations[key] = parse_equation(reader, key, data[key], rows, cols, allowed)
    for k in ("G", "h"):
        if k in data and "equations" not in data:
            reader.fail(
                k, "names a term of a matrix equation (under `equations`); without one, give H (and C)"
            )
    if latex is not None:
        spec.latex_conventions = [str(c) for c in latex.conventions_used()]
        table = latex.table
        written = {table.source[c]: v for c, v in table.entries.items() if c not in table.conventional}
        spec.latex_symbols = {c.latex: c.value for c in latex.conventions_used()} | written


def _read_whole_equations(reader: Reader, spec: TextModelSpec, data: dict, key: str, allowed, latex) -> None:
    """The ``equations`` key: M and f of M q̈ = f (``pendverify.analytic.text_equations``), or one
    matrix equation over the file's M, C, G, … (``pendverify.analytic.matrix_equation``)."""
    text = matrix_text(data[key])
    if text is not None and names_vectors(text, latex is not None, spec.coordinates):
        other = [k for k in ("f", "C_plus_D", "Cqdot") if k in data]
        if other:
            reader.fail(
                other[0], f"not with a matrix equation under '{key}': give its terms' keys (M, C, G, …)"
            )
        read_matrix_equation(reader, spec, key, text)
        return
    given = [
        k for k in ("M", "f", "C", "C_plus_D", "Cqdot", "H", "D", "B", "W", "qddot", "G", "h") if k in data
    ]
    if given:
        reader.fail(
            key, f"give the equations or their parts, not both (the file also gives {', '.join(given)})"
        )
    if latex is not None:
        side = latex_side(reader, latex)
    else:

        def side(k, text, names):
            return parse_entry(reader, k, text.strip(), names)

    split_equations(reader, spec, key, read_equations(reader, spec, key, data[key], allowed, side))


def _read_urdf(reader: Reader, spec: TextModelSpec, urdf) -> None:
    if not isinstance(urdf, dict) or set(urdf) - {"joints", "transform", "offset"}:
        reader.fail("urdf", "must be a table of joints, transform, offset")
    n = len(spec.coordinates)
    spec.urdf_joints = reader.names({"urdf.joints": urdf.get("joints", [])}, "urdf.joints")
    if "joints" in urdf and len(spec.urdf_joints) != n:
        reader.fail("urdf.joints", f"must name {n} joints, one per coordinate")
    if "transform" in urdf:
        spec.joint_transform = reader.numbers("urdf.transform", urdf["transform"], (n, n))
    if "offset" in urdf:
        spec.joint_offset = reader.numbers("urdf.offset", urdf["offset"], (n,))
