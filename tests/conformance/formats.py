"""Model writers: one system's closed forms in each model format pendverify accepts.

``FORMATS`` is the registry: format name → ``Format`` (its writer, the file suffix, whether
pendverify reads it as closed forms SymPy can see, and a reason to skip it when the installed
pendverify does not accept the format yet).  A writer takes a ``Model`` (a system, the robot
description its numbers are checked against, its closed forms and an optional ``Plant``) and
returns the text of the model file.  The formats follow docs/models.md and docs/text-latex.md:

* ``class``: a ``ClosedFormModel`` subclass and its ``ParameterSet`` (``self.math.cos``);
  ``class_object_arrays`` the same returning ``dtype=object`` arrays;
* ``text``: SymPy strings in TOML (M, C, H, V, D, B);
* ``latex``: ``notation = "latex"``, each matrix a ``bmatrix`` printed by ``sympy.latex``;
* ``equations``: the equations of motion whole, one per coordinate (accelerations ``ddq<i>``);
* ``matrix_equation``: ``M*ddq + C*dq + D*dq + H = B*u`` with the matrices as keys;
* ``mechanics``: ``METHOD`` and ``DECLARATION``; the file embeds ``derivation.py`` and builds
  the ``KanesMethod`` itself (with armature, the ``(mass_matrix, forcing)`` pair);
* ``dynamics_f`` and ``dynamics_qddot``: dynamics as code, ẋ = f(x, u) and q̈ = qddot(q, v, u),
  NumPy code solving M q̈ = B u − C q̇ − H − D q̇;
* ``numpy_functions``: plain functions M(q, p), C(q, v, p), G(q, p), V(q, p), D(p), B(p) with a
  ``DECLARATION`` (skipped, with the reason, where pendverify has no
  ``pendverify.analytic.numpy_model``).

A ``Plant`` multiplies one entry of M (and its mirror: M stays symmetric), C or H by 11/10: an
error of 10 % in one term of the derivation, which every check that sees the entry must catch.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
from collections.abc import Callable
from pathlib import Path

import sympy as sp

from tests.conformance.closed_forms import ClosedForms, model_forms
from tests.conformance.systems import SYSTEMS, System

HERE = Path(__file__).resolve().parent
FACTOR = sp.Rational(11, 10)


@dataclasses.dataclass(frozen=True)
class Plant:
    """A planted error: ``matrix`` ("M", "C" or "H") entry (i, j) (0-based; j = 0 for H) × 11/10."""

    matrix: str
    i: int
    j: int = 0

    @property
    def names(self) -> tuple[str, ...]:
        """The entry as pendverify's diagnosis names it (1-based; M's mirror entry too)."""
        if self.matrix == "H":
            return (f"H[{self.i + 1}]",)
        names = (f"{self.matrix}[{self.i + 1},{self.j + 1}]",)
        return names + ((f"M[{self.j + 1},{self.i + 1}]",) if self.matrix == "M" else ())

    def apply(self, forms: ClosedForms) -> ClosedForms:
        matrix = getattr(forms, self.matrix).copy()
        matrix[self.i, self.j] = FACTOR * matrix[self.i, self.j]
        if self.matrix == "M":
            matrix[self.j, self.i] = matrix[self.i, self.j]
        return dataclasses.replace(forms, **{self.matrix: matrix})


@dataclasses.dataclass(frozen=True)
class Model:
    """What a writer writes: a system's closed forms for a description, maybe with a planted error."""

    system: System
    description: str
    plant: Plant | None = None

    @property
    def forms(self) -> ClosedForms:
        forms = model_forms(self.system.name, self.description)
        return self.plant.apply(forms) if self.plant else forms

    @property
    def kinds(self) -> dict[str, str]:
        return self.system.parameter_kinds(self.description)

    def coordinates(self) -> dict[str, str]:
        return {
            f"q{i + 1}": "angle" if kind == "revolute" else "position"
            for i, (kind, _) in enumerate(self.system.joints)
        }

    def declaration(self) -> dict:
        """The declaration of the mechanics, dynamics-as-code and NumPy-function formats."""
        return {
            "name": self.system.name,
            "coordinates": self.coordinates(),
            "inputs": list(self.system.inputs),
            "parameters": {name: {"kind": kind} for name, kind in self.kinds.items()},
            "urdf": {"joints": list(self.system.joint_names)},
        }


def _rows(matrix: sp.Matrix) -> list[list[str]]:
    return [[str(matrix[i, j]) for j in range(matrix.shape[1])] for i in range(matrix.shape[0])]


def _vector(matrix: sp.Matrix) -> list[str]:
    return [str(e) for e in matrix]


def _toml_value(value) -> str:
    """A TOML value of strings, numbers and lists of them (JSON's syntax is TOML's for these)."""
    return json.dumps(value)


def _toml_tables(model: Model) -> str:
    lines = ["", "[coordinates]"]
    lines += [f'{name} = "{kind}"' for name, kind in model.coordinates().items()]
    lines += ["", "[parameters]"]
    lines += [f'{name} = {{ kind = "{kind}" }}' for name, kind in model.kinds.items()]
    lines += ["", "[urdf]", f"joints = {_toml_value(list(model.system.joint_names))}", ""]
    return "\n".join(lines)


def _toml_head(model: Model, notation: str | None = None) -> list[str]:
    head = [f'name = "{model.system.name}"']
    if notation:
        head.append(f'notation = "{notation}"')
    head.append(f"inputs = {_toml_value(list(model.system.inputs))}")
    return head


def _has_damping(model: Model) -> bool:
    return model.system.damping


def write_text(model: Model) -> str:
    f = model.forms
    keys = {"M": _rows(f.M), "C": _rows(f.C), "H": _vector(f.H), "V": str(f.V), "B": _rows(f.B)}
    if _has_damping(model):
        keys["D"] = _rows(f.D)
    return "\n".join(
        [*_toml_head(model), *(f"{k} = {_toml_value(v)}" for k, v in keys.items())]
    ) + _toml_tables(model)


def _latex_names(forms: ClosedForms) -> dict[sp.Symbol, str]:
    names = {dq: rf"\dot{{q}}_{{{i + 1}}}" for i, dq in enumerate(forms.dq)}
    names.update({tau: rf"\tau_{{{i + 1}}}" for i, tau in enumerate(forms.inputs)})
    return names


def _latex(expr, forms: ClosedForms) -> str:
    return sp.latex(expr, symbol_names=_latex_names(forms), mat_str="bmatrix", mat_delim="")


def write_latex(model: Model) -> str:
    f = model.forms
    keys = {"M": f.M, "C": f.C, "H": f.H, "V": f.V, "B": f.B}
    if _has_damping(model):
        keys["D"] = f.D
    lines = [*_toml_head(model, "latex")]
    lines += [f"{k} = '{_latex(v, f)}'" for k, v in keys.items()]
    return "\n".join(lines) + _toml_tables(model)


def _equations(forms: ClosedForms, damping: bool) -> list[str]:
    n = len(forms.q)
    ddq = sp.Matrix(sp.symbols([f"ddq{i + 1}" for i in range(n)]))
    dq = sp.Matrix(forms.dq)
    lhs = forms.M * ddq + forms.C * dq + forms.H + (forms.D * dq if damping else sp.zeros(n, 1))
    rhs = forms.B * sp.Matrix(forms.inputs) if forms.inputs else sp.zeros(n, 1)
    return [f"{lhs[i]} = {rhs[i]}" for i in range(n)]


def write_equations(model: Model) -> str:
    equations = _equations(model.forms, _has_damping(model))
    return "\n".join([*_toml_head(model), f"equations = {_toml_value(equations)}"]) + _toml_tables(model)


def write_matrix_equation(model: Model) -> str:
    f = model.forms
    damping = _has_damping(model)
    equation = "M*ddq + C*dq + " + ("D*dq + " if damping else "") + "H = B*u"
    keys = {"M": _rows(f.M), "C": _rows(f.C), "H": _vector(f.H), "B": _rows(f.B)}
    if damping:
        keys["D"] = _rows(f.D)
    lines = [*_toml_head(model), f"equations = {_toml_value([equation])}"]
    lines += [f"{k} = {_toml_value(v)}" for k, v in keys.items()]
    return "\n".join(lines) + _toml_tables(model)


def _class_method(name: str, args: str, body: list[str], unpack: list[str]) -> list[str]:
    return [
        f"    def {name}(self{args}):",
        *(f"        {line}" for line in unpack),
        *(f"        {b}" for b in body),
        "",
    ]


def _array(rows, dtype: str = "") -> str:
    tail = f", dtype={dtype})" if dtype else ")"
    if rows and isinstance(rows[0], list):
        return "np.array([" + ", ".join("[" + ", ".join(r) + "]" for r in rows) + "]" + tail
    return "np.array([" + ", ".join(rows) + "]" + tail


def write_class(model: Model, dtype: str = "") -> str:
    """A ``ClosedFormModel`` subclass; every method unpacks q, q̇ and the parameters into locals.
    With ``dtype="object"`` every array is built as an object array (a style that keeps SymPy
    entries as they are, numerically an array of Python floats)."""
    f, system = model.forms, model.system
    n = system.dof
    params = list(model.kinds)
    q_names = ", ".join(str(s) for s in f.q) + ("," if n == 1 else "")
    v_names = ", ".join(str(s) for s in f.dq) + ("," if n == 1 else "")
    unpack_p = ["p = self.params", f"{', '.join(params)} = {', '.join('p.' + k for k in params)}"]
    trig = ["cos, sin = self.math.cos, self.math.sin"]
    unpack_q = [f"{q_names} = q"]
    unpack_v = [f"{v_names} = v"]
    dq = sp.Matrix(f.dq)
    kinetic = sp.expand((dq.T * f.M * dq)[0, 0] / 2)
    dissipation = sp.expand((dq.T * f.D * dq)[0, 0] / 2) if system.damping else sp.Integer(0)
    inputs = sp.Matrix(f.inputs)
    power = sp.expand((inputs.T * f.B.T * dq)[0, 0])
    u_names = ", ".join(str(s) for s in f.inputs) + ("," if len(f.inputs) == 1 else "")
    fields = [f'    {k}: float = quantity("{kind}", "{k} [SI]")' for k, kind in model.kinds.items()]
    lines = [
        f'"""The {system.name} of the conformance matrix as a ClosedFormModel (tests/conformance)."""',
        "",
        "import dataclasses",
        "",
        "import numpy as np",
        "",
        "from pendverify.analytic import ClosedFormModel",
        "from pendverify.analytic.forms import Energies",
        "from pendverify.analytic.parameter_set import ParameterSet, quantity",
        "",
        "",
        "@dataclasses.dataclass(frozen=True)",
        "class Params(ParameterSet):",
        f'    model = "{system.name}"',
        *fields,
        "",
        "",
        "class Model(ClosedFormModel):",
        f'    name = "{system.name}"',
        "    params_type = Params",
        f"    coordinates = {tuple(model.coordinates())!r}",
        f"    angular = {tuple(k == 'angle' for k in model.coordinates().values())!r}",
        f"    inputs = {tuple(system.inputs)!r}",
        f"    urdf_joints = {tuple(system.joint_names)!r}",
        "",
    ]
    lines += _class_method(
        "mass_matrix", ", q", [f"return {_array(_rows(f.M), dtype)}"], unpack_p + trig + unpack_q
    )
    lines += _class_method(
        "coriolis_matrix",
        ", q, v",
        [f"return {_array(_rows(f.C), dtype)}"],
        unpack_p + trig + unpack_q + unpack_v,
    )
    lines += _class_method(
        "gravity", ", q", [f"return {_array(_vector(f.H), dtype)}"], unpack_p + trig + unpack_q
    )
    lines += _class_method("potential_energy", ", q", [f"return {f.V}"], unpack_p + trig + unpack_q)
    if system.damping:
        lines += _class_method("damping_matrix", "", [f"return {_array(_rows(f.D), dtype)}"], unpack_p)
    lines += _class_method("input_matrix", "", [f"return {_array(_rows(f.B), dtype)}"], [])
    lines += _class_method(
        "energies",
        ", q, v, u, w",
        [
            f"return Energies(kinetic={kinetic}, potential={f.V}, dissipation={dissipation}, power={power})",
        ],
        [*unpack_p, *trig, *unpack_q, *unpack_v, f"{u_names} = u"],
    )
    return "\n".join(lines)


def write_mechanics(model: Model) -> str:
    """The derivation module's text, the chain, ``METHOD`` and ``DECLARATION``.

    A planted error is a change of the derived equations: the file takes the ``(mass_matrix,
    forcing)`` pair and adds ΔM to M and −(ΔC q̇ + ΔH) to the forcing (the difference between the
    planted and the true closed forms, in the plain symbols, turned into dynamic symbols)."""
    chain = model.system.chain()
    armatures = model.system.armatures(model.description)
    for joint, a in zip(chain, armatures, strict=False):
        joint["armature"] = a
    text = (HERE / "derivation.py").read_text() + f"\n\nCHAIN = {chain!r}\n"
    if model.plant is None:
        method = "mass_matrix_and_forcing(CHAIN)" if armatures else "kane(CHAIN)"
        text += f"METHOD = {method}\n"
    else:
        true = dataclasses.replace(model, plant=None).forms
        planted = model.forms
        dq = sp.Matrix(true.dq)
        delta_m = _rows(planted.M - true.M)
        delta_f = _vector(-((planted.C - true.C) * dq + (planted.H - true.H)))
        n = model.system.dof
        text += (
            f"_q = dynamicsymbols({' '.join(str(s) for s in true.q)!r}, seq=True)\n"
            f"_plain = {{**{{sp.Symbol(f'dq{{i + 1}}'): _q[i].diff() for i in range({n})}}, "
            f"**{{sp.Symbol(f'q{{i + 1}}'): _q[i] for i in range({n})}}}}\n"
            "_M, _F = mass_matrix_and_forcing(CHAIN)\n"
            f"METHOD = (_M + sp.Matrix({delta_m!r}).applyfunc(sp.sympify).subs(_plain), "
            f"_F + sp.Matrix({delta_f!r}).applyfunc(sp.sympify).subs(_plain))\n"
        )
    return text + f"DECLARATION = {model.declaration()!r}\n"


def _numpy_code(expr) -> str:
    return sp.pycode(expr, fully_qualified_modules=False).replace("math.", "np.")


def _numpy_body(model: Model, f: ClosedForms) -> list[str]:
    n = model.system.dof
    params = list(model.kinds)
    lines = [f"    {', '.join(str(s) for s in f.q)}{',' if n == 1 else ''} = q"]
    lines += [f"    {', '.join(str(s) for s in f.dq)}{',' if n == 1 else ''} = v"]
    lines += [f"    {k} = parameters[{k!r}]" for k in params]
    M = "[" + ", ".join("[" + ", ".join(_numpy_code(e) for e in f.M.row(i)) + "]" for i in range(n)) + "]"
    C = "[" + ", ".join("[" + ", ".join(_numpy_code(e) for e in f.C.row(i)) + "]" for i in range(n)) + "]"
    H = "[" + ", ".join(_numpy_code(e) for e in f.H) + "]"
    B = "[" + ", ".join("[" + ", ".join(_numpy_code(e) for e in f.B.row(i)) + "]" for i in range(n)) + "]"
    D = "[" + ", ".join("[" + ", ".join(_numpy_code(e) for e in f.D.row(i)) + "]" for i in range(n)) + "]"
    lines += [
        f"    M = np.array({M}, dtype=float)",
        f"    C = np.array({C}, dtype=float)",
        f"    H = np.array({H}, dtype=float)",
        f"    B = np.array({B}, dtype=float).reshape({n}, {len(f.inputs)})",
        f"    D = np.array({D}, dtype=float)",
        "    return np.linalg.solve(M, B @ np.asarray(u, dtype=float) - C @ v - H - D @ v)",
    ]
    return lines


def _dynamics_declaration(model: Model, signature: str) -> dict:
    f = model.forms
    declaration = {**model.declaration(), "dynamics": signature, "B": _rows(f.B)}
    if model.system.damping:
        declaration["D"] = _rows(f.D)
    return declaration


def _write_dynamics(model: Model, signature: str) -> str:
    f, n = model.forms, model.system.dof
    params = ", ".join(model.kinds)
    lines = [
        f'"""The {model.system.name} of the conformance matrix as dynamics code (tests/conformance)."""',
        "",
        "import numpy as np",
        "",
        "from numpy import cos, sin",
        "",
        "",
        "def qddot_of(q, v, u, parameters):",
        *_numpy_body(model, f),
        "",
        "",
    ]
    if signature == "f(x, u)":
        lines += [
            f"def f(x, u, *, {params}):",
            "    x = np.asarray(x, dtype=float)",
            f"    q, v = x[:{n}], x[{n}:]",
            "    parameters = dict(" + ", ".join(f"{k}={k}" for k in model.kinds) + ")",
            "    return np.concatenate([v, qddot_of(q, v, u, parameters)])",
            "",
            "",
            "DYNAMICS = f",
        ]
    else:
        lines += [
            f"def qddot(q, v, u, *, {params}):",
            "    parameters = dict(" + ", ".join(f"{k}={k}" for k in model.kinds) + ")",
            "    return qddot_of(np.asarray(q, dtype=float), np.asarray(v, dtype=float), u, parameters)",
            "",
            "",
            "DYNAMICS = qddot",
        ]
    lines.append(f"DECLARATION = {_dynamics_declaration(model, signature)!r}")
    return "\n".join(lines) + "\n"


def write_numpy_functions(model: Model) -> str:
    f, n = model.forms, model.system.dof
    params = list(model.kinds)

    def function(name: str, args: str, body: str, uses_q: bool, uses_v: bool) -> list[str]:
        lines = [f"def {name}({args}):"]
        if uses_q:
            lines.append(f"    {', '.join(str(s) for s in f.q)}{',' if n == 1 else ''} = q")
        if uses_v:
            lines.append(f"    {', '.join(str(s) for s in f.dq)}{',' if n == 1 else ''} = v")
        lines += [f"    {k} = p.{k}" for k in params]
        return [*lines, f"    return {body}", "", ""]

    def matrix(m: sp.Matrix) -> str:
        rows = ", ".join(
            "[" + ", ".join(_numpy_code(m[i, j]) for j in range(m.shape[1])) + "]" for i in range(m.shape[0])
        )
        return f"np.array([{rows}], dtype=float).reshape({m.shape[0]}, {m.shape[1]})"

    lines = [
        f'"""The {model.system.name} of the conformance matrix as NumPy functions (tests/conformance)."""',
        "",
        "import numpy as np",
        "from numpy import cos, sin",
        "",
        "",
    ]
    lines += function("M", "q, p", matrix(f.M), True, False)
    lines += function("C", "q, v, p", matrix(f.C), True, True)
    lines += function(
        "G", "q, p", f"np.array([{', '.join(_numpy_code(e) for e in f.H)}], dtype=float)", True, False
    )
    lines += function("V", "q, p", f"float({_numpy_code(f.V)})", True, False)
    if model.system.damping:
        lines += function("D", "p", matrix(f.D), False, False)
    lines += function("B", "p", matrix(f.B), False, False)
    lines.append(f"DECLARATION = {model.declaration()!r}")
    return "\n".join(lines) + "\n"


def _octave(expr) -> str:
    return sp.octave_code(expr)


def matlab_function(name: str, outputs: dict[str, sp.Matrix], arguments: dict[str, list | None]) -> str:
    """A function file as ``matlabFunction`` writes one: the vector arguments unpacked (``q1 =
    in1(1,:);``), common subexpressions as ``t2 = …;`` temporaries, each matrix output refilled
    column by column (``reshape([…],[r,c])``) or a column literal, outputs after the first inside
    ``if nargout > K`` blocks."""
    entries = [e for m in outputs.values() for e in m.T]  # column-major, as reshape reads them
    temporaries = sp.numbered_symbols("t", start=2)
    shared, reduced = sp.cse(entries, symbols=temporaries, optimizations="basic")
    lines = [
        f"function [{','.join(outputs)}] = {name}({','.join(arguments)})",
        f"%{name.upper()}",
        f"%    [{','.join(outputs).upper()}] = {name.upper()}({','.join(arguments).upper()})",
        "",
        "%    Written by tests/conformance/formats.py in the style of matlabFunction.",
        "",
    ]
    for argument, names in arguments.items():  # a vector argument unpacked; a scalar (None) as it is
        lines += [f"{n} = {argument}({k + 1},:);" for k, n in enumerate(names or ())]
    lines += [f"{t} = {_octave(e)};" for t, e in shared]
    at = 0
    for k, (output, matrix) in enumerate(outputs.items()):
        values = [_octave(e) for e in reduced[at : at + len(matrix)]]
        at += len(matrix)
        if matrix.shape == (1, 1):
            body = f"{output} = {values[0]};"
        elif matrix.cols == 1:
            body = f"{output} = [{';'.join(values)}];"
        else:
            body = f"{output} = reshape([{','.join(values)}],[{matrix.rows},{matrix.cols}]);"
        lines += [body] if k == 0 else [f"if nargout > {k}", f"    {body}", "end"]
    return "\n".join(lines) + "\n"


def matlab_files(model: Model, stem: str) -> dict[str, str]:
    """The ``.m`` files of the MATLAB format: M(in1, in2) and [C, G, B, V](in1, in2), in1 the
    coordinates (and rates), in2 the parameters; D stays in the declaration, in SymPy syntax."""
    f = model.forms
    params = list(model.kinds)
    q, dq = [str(s) for s in f.q], [str(s) for s in f.dq]
    return {
        f"{stem}_M.m": matlab_function(f"{stem}_M", {"M": f.M}, {"in1": q, "in2": params}),
        f"{stem}_terms.m": matlab_function(
            f"{stem}_terms",
            {"C": f.C, "G": f.H, "B": f.B, "V": sp.Matrix([f.V])},
            {"in1": q + dq, "in2": params},
        ),
    }


def write_matlab(model: Model, stem: str) -> str:
    """The declaration: which output is which key, and what in1 and in2 are in each file."""
    f = model.forms
    names = list(matlab_files(model, stem))
    lines = [*_toml_head(model), 'M = "M"', 'C = "C"', 'H = "G"', 'B = "B"', 'V = "V"']
    if _has_damping(model):
        lines.append(f"D = {_toml_value(_rows(f.D))}")
    lines += ["", "[matlab]", f"files = {_toml_value(names)}", ""]
    lines += [f'[matlab.arguments."{names[0]}"]', f"in1 = {_toml_value([str(s) for s in f.q])}"]
    lines += [f"in2 = {_toml_value(list(model.kinds))}", ""]
    lines += [f'[matlab.arguments."{names[1]}"]', f"in1 = {_toml_value([str(s) for s in f.q + f.dq])}"]
    lines += [f"in2 = {_toml_value(list(model.kinds))}"]
    return "\n".join(lines) + "\n" + _toml_tables(model)


def _numpy_functions_missing() -> str | None:
    if importlib.util.find_spec("pendverify.analytic.numpy_model") is None:
        return "this pendverify has no NumPy-functions model format (pendverify.analytic.numpy_model)"
    return None


@dataclasses.dataclass(frozen=True)
class Format:
    """A model format: its writer, file suffix, whether SymPy sees its closed forms, a skip reason."""

    #: (model) → the model file's text; with companions, (model, the file's stem) → its text
    write: Callable[..., str]
    suffix: str
    symbolic: bool
    #: the reason to skip the format's cells (None: pendverify takes it)
    missing: Callable[[], str | None] = lambda: None
    #: the other files the model file reads, {name: text}, from the model and the file's stem
    companions: Callable[[Model, str], dict[str, str]] | None = None


FORMATS: dict[str, Format] = {
    "class": Format(write_class, ".py", symbolic=True),
    "class_object_arrays": Format(lambda m: write_class(m, "object"), ".py", symbolic=True),
    "text": Format(write_text, ".toml", symbolic=True),
    "latex": Format(write_latex, ".toml", symbolic=True),
    "equations": Format(write_equations, ".toml", symbolic=True),
    "matrix_equation": Format(write_matrix_equation, ".toml", symbolic=True),
    "mechanics": Format(write_mechanics, ".py", symbolic=True),
    "dynamics_f": Format(lambda m: _write_dynamics(m, "f(x, u)"), ".py", symbolic=False),
    "dynamics_qddot": Format(lambda m: _write_dynamics(m, "qddot(q, v, u)"), ".py", symbolic=False),
    "numpy_functions": Format(write_numpy_functions, ".py", symbolic=False, missing=_numpy_functions_missing),
    "matlab": Format(write_matlab, ".toml", symbolic=True, companions=matlab_files),
}


def write_model(model: Model, format_name: str, folder: Path) -> Path:
    """Write ``model`` in ``format_name`` into ``folder`` under a name fixed by system and format
    (the code cache keys on file names and contents: the same model is compiled once)."""
    fmt = FORMATS[format_name]
    tag = "planted" if model.plant else "true"
    stem = f"{model.system.name}_{format_name}_{model.description}_{tag}"
    path = folder / f"{stem}{fmt.suffix}"
    if fmt.companions is None:
        path.write_text(fmt.write(model))
        return path
    for name, text in fmt.companions(model, stem).items():
        (folder / name).write_text(text)
    path.write_text(fmt.write(model, stem))
    return path


def write_parameters(model: Model, folder: Path) -> Path:
    from tests.conformance.systems import parameter_file

    path = folder / f"{model.system.name}_{model.description}.params.toml"
    path.write_text(parameter_file(model.system, model.description))
    return path


__all__ = ["FORMATS", "SYSTEMS", "Format", "Model", "Plant", "write_model", "write_parameters"]
