"""A model's quantities written as code: C99, MATLAB/Octave and NumPy, common subexpressions named.

Every file starts with ``banner`` lines (the model file and its SHA-256, the parameter set, the
certificate's digest when ``certify`` exports, and how the code was verified).  In each language
a quantity is one function of the coordinates ``q``, the rates ``v`` (C·q̇ and q̈), the inputs
``u`` and disturbances ``w`` (q̈; left out of C and MATLAB signatures where the model has none)
and the parameters ``p``; its common subexpressions are computed once (``sympy.cse``) as temporaries
``t0, t1, …`` (``tmp_0, …`` where a model name is ``t<k>``):

* **C99** (``NAME.h``, ``NAME.c``; the header's declarations ``extern "C"`` in C++):
  ``typedef struct { double m1; … } NAME_params;`` and
  ``void NAME_mass_matrix(const double q[n], const NAME_params *p, double out[n*n])``, and so on:
  no allocation, ``double`` arrays, matrices row-major (``out[i*cols + j]``);
* **MATLAB/Octave** (``NAME_mass_matrix.m``, …): ``function M = NAME_mass_matrix(q, p)`` with ``q``
  a vector and ``p`` a structure (``p.m1``), and ``NAME_matlab.toml``, the declaration that reads
  them back (``docs/matlab.md``);
* **NumPy** (``NAME_numpy.py``): the NumPy-functions model format (``M(q, p)``, ``Cqdot(q, v, p)``,
  ``G(q, p)``, ``D(p)``, ``B(p)``, ``W(p)``, ``det_M(q, p)``, ``qddot(q, v, u, w, p)`` and
  ``DECLARATION``: ``pendverify.analytic.numpy_model``), so that the module is itself a model
  pendverify reads; a model of q̈ alone is written as ``DYNAMICS`` code, ``qddot(q, v, u, **p)``
  with u the inputs then the disturbances, B, D and W in its declaration
  (``pendverify.analytic.python_dynamics``).
"""

from __future__ import annotations

import dataclasses
import json
import re

import sympy as sp

from pendverify.errors import PendverifyError
from pendverify.export.closed_forms import QUANTITIES, ExportForms
from pendverify.export.names import c_name
from pendverify.numerics.codegen.printers import numpy_printer

#: C's keywords, the names its math library declares and the functions' arguments: a coordinate
#: or parameter so named is renamed ``name_`` in a function's body
C_RESERVED = frozenset(
    """auto break case char const continue default do double else enum extern float for goto if inline
    int long register restrict return short signed sizeof static struct switch typedef union unsigned
    void volatile while _Bool _Complex _Imaginary sin cos tan exp log sqrt pow fabs atan2 asin acos atan
    sinh cosh tanh y0 y1 yn j0 j1 jn gamma out p q v u w""".split()
)


#: the names a MATLAB function's body may not take for a coordinate or parameter: its arguments,
#: its output names and the functions the printed code calls
MATLAB_RESERVED = frozenset(
    "q v u w p M Cqdot G D B W det_M qddot pi sin cos tan exp log sqrt abs reshape".split()
)
#: the same for a NumPy module's functions (float: det M is returned as float(...))
NUMPY_RESERVED = frozenset("q v u w p numpy float".split())
C_KEYWORDS = frozenset(
    """auto break case char const continue default do double else enum extern float for goto if inline
    int long register restrict return short signed sizeof static struct switch typedef union unsigned
    void volatile while _Bool _Complex _Imaginary""".split()
)


def renamed(forms: ExportForms, reserved: frozenset) -> ExportForms:
    """``forms`` with each coordinate, rate, input, disturbance and parameter whose name is
    ``reserved`` in the language renamed ``name_`` in the expressions (its declared name stays:
    the struct's field, the declaration's entry)."""
    symbols = (*forms.q, *forms.v, *forms.u, *forms.w, *forms.p)
    local: dict[str, str] = {}
    for s in symbols:
        name = s.name
        while name in reserved or name in local.values():
            name += "_"
        local[s.name] = name
    if all(k == v for k, v in local.items()):
        return forms
    swap = {s: sp.Symbol(local[s.name], real=True) for s in symbols}
    return dataclasses.replace(
        forms,
        quantities={k: m.xreplace(swap) for k, m in forms.quantities.items()},
        **{group: tuple(swap[s] for s in getattr(forms, group)) for group in "qvuwp"},
    )


def _temporaries(forms: ExportForms):
    taken = {s.name for s in (*forms.q, *forms.v, *forms.u, *forms.w, *forms.p)}
    prefix = "t" if not any(re.fullmatch(r"t\d+", n) for n in taken) else "tmp_"
    return sp.numbered_symbols(prefix, real=True)


def reduced(forms: ExportForms, matrix: sp.Matrix):
    """(temporaries [(symbol, expression)], the entries row-major) of one quantity."""
    entries = [matrix[i, j] for i in range(matrix.rows) for j in range(matrix.cols)]
    return sp.cse(entries, symbols=_temporaries(forms), optimizations="basic")


def used(forms: ExportForms, shared, entries, group: tuple) -> list[sp.Symbol]:
    found = set().union(*(e.free_symbols for _, e in shared), *(e.free_symbols for e in entries))
    return [s for s in group if s in found]


# -------------------------------------------------------------------------------- C99


def write_c(forms: ExportForms, banner: list[str]) -> dict[str, str]:
    """``NAME.h`` and ``NAME.c`` (module docstring)."""
    prefix = c_name(forms.name)
    fields = [p.name for p in forms.p]
    keywords = sorted(set(fields) & C_KEYWORDS)
    if keywords:
        raise PendverifyError(
            f"export --lang c: the parameter {keywords[0]!r} is a C keyword, which a field of the "
            "parameters' struct cannot be named; rename it in the model"
        )
    forms = renamed(forms, C_RESERVED)
    comment = ["/*", *(f" * {line}" for line in banner), " */"]
    struct = ["typedef struct {", *(f"    double {name};" for name in fields), f"}} {prefix}_params;"]
    guard = f"{prefix.upper()}_H"
    cplusplus = ["#ifdef __cplusplus", 'extern "C" {', "#endif", ""]
    header = [*comment, f"#ifndef {guard}", f"#define {guard}", "", *cplusplus, *struct, ""]
    source = [*comment, "#include <math.h>", f'#include "{prefix}.h"', ""]
    for key, matrix in forms.quantities.items():
        method, _, what = QUANTITIES[key]
        signature = [
            *(f"const double {a}[{len(getattr(forms, a))}]" for a in forms.arguments(key)),
            f"const {prefix}_params *p",
            f"double out[{matrix.rows * matrix.cols}]",
        ]
        declaration = f"void {prefix}_{method}({', '.join(signature)})"
        layout = {"matrix": "row-major", "vector": "a vector", "number": "out[0]"}[forms.shape(key)]
        header += [f"/* {what}: out is {matrix.rows} × {matrix.cols}, {layout} */", f"{declaration};", ""]
        shared, entries = reduced(forms, matrix)
        body = [
            f"    const double {s.name} = {a}[{getattr(forms, a).index(s)}];"
            for a in "qvuw"
            for s in used(forms, shared, entries, getattr(forms, a))
        ]
        params = used(forms, shared, entries, forms.p)
        body += [f"    const double {s.name} = p->{fields[forms.p.index(s)]};" for s in params]
        body += [f"    const double {t.name} = {sp.ccode(e, standard='c99')};" for t, e in shared]
        body += [f"    out[{k}] = {sp.ccode(e, standard='c99')};" for k, e in enumerate(entries)]
        if not params:
            body.insert(0, "    (void)p;")
        source += [f"{declaration}", "{", *body, "}", ""]
    header += ["#ifdef __cplusplus", "}", "#endif", "", f"#endif /* {guard} */", ""]
    return {f"{prefix}.h": "\n".join(header), f"{prefix}.c": "\n".join(source)}


# ---------------------------------------------------------------------------- MATLAB


def _matlab_output(forms: ExportForms, key: str) -> str:
    declared = {s.name for s in (*forms.q, *forms.v, *forms.p)} | set(forms.inputs) | set(forms.disturbances)
    return key if key not in declared else f"{key}_out"


def write_matlab(forms: ExportForms, banner: list[str]) -> dict[str, str]:
    """One ``.m`` function per quantity and the declaration that reads them (module docstring)."""
    prefix = c_name(forms.name)
    fields = [p.name for p in forms.p]
    declared, forms = forms, renamed(forms, MATLAB_RESERVED)
    files: dict[str, str] = {}
    keys: dict[str, str] = {}
    for key, matrix in forms.quantities.items():
        method, _, what = QUANTITIES[key]
        output = _matlab_output(declared, key)
        arguments = [*forms.arguments(key), "p"]
        lines = [
            f"function {output} = {prefix}_{method}({','.join(arguments)})",
            f"%{prefix.upper()}_{method.upper()}",
        ]
        lines += [f"%    {what}", *(f"%    {line}" for line in banner), ""]
        shared, entries = reduced(forms, matrix)
        lines += [
            f"{s.name} = {a}({getattr(forms, a).index(s) + 1});"
            for a in "qvuw"
            for s in used(forms, shared, entries, getattr(forms, a))
        ]
        lines += [f"{s.name} = p.{fields[forms.p.index(s)]};" for s in used(forms, shared, entries, forms.p)]
        lines += [f"{t.name} = {sp.octave_code(e)};" for t, e in shared]
        column_major = [entries[i * matrix.cols + j] for j in range(matrix.cols) for i in range(matrix.rows)]
        values = ",".join(sp.octave_code(e) for e in column_major)
        lines.append(f"{output} = reshape([{values}],[{matrix.rows},{matrix.cols}]);")
        files[f"{prefix}_{method}.m"] = "\n".join(lines) + "\n"
        keys["H" if key == "G" else key] = output
    declaration = forms.declaration()
    toml = [f"# {line}" for line in banner]
    toml += [f"name = {json.dumps(declaration['name'])}"]
    toml += [
        f"inputs = {json.dumps(declaration['inputs'])}",
        f"disturbances = {json.dumps(declaration['disturbances'])}",
    ]
    toml += [f"{k} = {json.dumps(v)}" for k, v in keys.items()]
    toml += ["", "[coordinates]", *(f"{c} = {json.dumps(k)}" for c, k in declaration["coordinates"].items())]
    toml += ["", "[parameters]"]
    toml += [
        f'{n} = {{ kind = "{d["kind"]}", unit = {json.dumps(d["unit"])} }}'
        for n, d in declaration["parameters"].items()
    ]
    if "urdf" in declaration:
        toml += ["", "[urdf]", *(f"{k} = {json.dumps(v)}" for k, v in declaration["urdf"].items())]
    toml += ["", "[matlab]", f"files = {json.dumps(list(files))}", "", "[matlab.arguments]"]
    vectors = {"q": forms.coordinates, "v": forms.rates, "u": forms.inputs, "w": forms.disturbances}
    needed = {a for key in forms.quantities for a in forms.arguments(key)}
    toml += [f"{a} = {json.dumps(list(names))}" for a, names in vectors.items() if a in needed]
    toml += ['p = "struct"']
    files[f"{prefix}_matlab.toml"] = "\n".join(toml) + "\n"
    return files


# ----------------------------------------------------------------------------- NumPy


def write_numpy(forms: ExportForms, banner: list[str]) -> dict[str, str]:
    """``NAME_numpy.py``: a NumPy-functions model file, or ``DYNAMICS`` code for a model of q̈
    alone (module docstring)."""
    prefix = c_name(forms.name)
    declared, forms = forms, renamed(forms, NUMPY_RESERVED)
    lines = ['"""' + "\n".join(banner) + '\n"""', "", "import numpy", "", ""]
    if "M" not in forms.quantities:
        return {f"{prefix}_numpy.py": "\n".join(lines + _numpy_dynamics(forms, declared)) + "\n"}
    for key in forms.quantities:
        arguments = [*QUANTITIES[key][1], "p"]
        lines += _numpy_function(forms, key, arguments, {a: a for a in QUANTITIES[key][1]})
    lines.append(f"DECLARATION = {forms.declaration()!r}")
    return {f"{prefix}_numpy.py": "\n".join(lines) + "\n"}


def _numpy_dynamics(forms: ExportForms, declared: ExportForms) -> list[str]:
    """q̈ as ``DYNAMICS`` code, ``qddot(q, v, u, **p)``, u the inputs then the disturbances, and
    its declaration with B, D and W written as a text model writes them."""
    lines = _numpy_function(forms, "qddot", ["q", "v", "u", "**p"], forms.dynamics_arrays())
    return [*lines, "DYNAMICS = qddot", f"DECLARATION = {declared.dynamics_declaration()!r}"]


def _numpy_function(forms: ExportForms, key: str, arguments: list[str], unpack: dict) -> list[str]:
    """The function ``key(arguments)`` returning ``key``'s value; ``unpack`` says which array each
    argument group (q, v, u, w) is read from."""
    fields = {s: name for s, (name, _, _) in zip(forms.p, forms.parameters, strict=True)}
    printer = numpy_printer()
    matrix = forms.quantities[key]
    shared, entries = reduced(forms, matrix)
    lines = [f"def {key}({', '.join(arguments)}):", f'    """{QUANTITIES[key][2]}."""']
    for group in QUANTITIES[key][1]:
        symbols = getattr(forms, group)
        if symbols:
            lines.append(f"    {', '.join(s.name for s in symbols)}, = {unpack[group]}")
    lines += [f"    {s.name} = p[{fields[s]!r}]" for s in used(forms, shared, entries, forms.p)]
    lines += [f"    {t.name} = {printer.doprint(e)}" for t, e in shared]
    shape = forms.shape(key)
    if shape == "number":
        lines.append(f"    return float({printer.doprint(entries[0])})")
    else:
        rows = [
            "[" + ", ".join(printer.doprint(entries[i * matrix.cols + j]) for j in range(matrix.cols)) + "]"
            for i in range(matrix.rows)
        ]
        size = f"({matrix.rows},)" if shape == "vector" else f"({matrix.rows}, {matrix.cols})"
        lines.append(f"    return numpy.array([{', '.join(rows)}], dtype=float).reshape{size}")
    return [*lines, "", ""]
