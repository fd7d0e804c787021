"""A model class's hand-written closed forms as NumPy functions over a batch of states.

Each closed form the class writes itself (``ClosedFormModel.own_methods``: M, C or C·q̇, H, V, D, B, W,
det M, M⁻¹, q̈, the tolerance scales, the bias and T when written) is read as SymPy
expressions by ``SymbolicModel`` — the model's own code called with symbols for q, q̇, u, w
and the parameters — its common subexpressions are eliminated (``sympy.cse``) and it is
printed as one function of the module this writes::

    def mass_matrix(P, Q, V, U, W):      # P: the parameters in the field order of params_type
        N = Q.shape[0]                   # Q, V, U, W: (N, ·), one row per state
        q1 = Q[:, 1]
        c0 = numpy.cos(q1)
        out = numpy.empty((N, 2, 2))
        out[:, 0, 0] = p4 + 2*p5*c0
        ...
        return out                       # (N, rows, columns); (N,) for a scalar

Every operation is one of NumPy's elementwise ufuncs on arrays of the N states, so a call
evaluates all states at once, and a state's value depends neither on the others nor on N.
Numbers are written exactly: a float as its ``repr``, a rational p/q as the correctly
rounded quotient.  The expressions are SymPy's arrangement of the model's formulas (terms
collected and ordered), so a value may differ from the model's own Python in the last
bits; the checks' tolerances are some ε wide, and a failing state is judged again with
the model's own code in high precision (``pendverify.checks.precision``).

A method SymPy cannot read (a branch on a value, a numerical solve, ``np.cos`` instead of
``self.math.cos``), or whose expressions hold a function NumPy has no ufunc for, is not
generated: ``MISSING`` in the module names it with the reason, and the checks evaluate it
with the model's own Python, state by state (``pendverify.checks.closed_forms``).

The module is cached on disk and verified before it runs as the compiled fast path's is
(``pendverify.numerics.codegen.cache``, ``docs/code-cache.md``).
"""

from __future__ import annotations

import dataclasses
import functools
import types

from pendverify.analytic.forms import INTERFACE, STATES
from pendverify.numerics.codegen.printers import numpy_printer

#: the methods that may be generated (every one of the interface but the special states),
#: each with its arguments from the state (q, q̇, u, w)
METHODS = {name: method.args for name, method in INTERFACE.items() if method.kind != STATES}
GENERATOR = "vectorised-1"  # bump when the generated code changes meaning


def _renamed(sm) -> dict:
    """{the model's symbol: its name in the generated code}: p0…, q0…, v0…, u0…, w0…."""
    import sympy as sp

    names = {}
    params = [sm.parameters[f.name] for f in dataclasses.fields(sm.cls.params_type)]
    for i, s in enumerate(params):
        names[s] = sp.Symbol(f"p{i}")
    for kind in "qvuw":
        for i, s in enumerate(sm.symbols[kind]):
            names[s] = sp.Symbol(f"{kind}{i}")
    return names


def _function(method: str, value, names: dict) -> list[str]:
    """The lines of one generated function (a PrintMethodNotImplementedError if NumPy cannot)."""
    import sympy as sp

    from pendverify.errors import PendverifyError

    matrix = isinstance(value, sp.MatrixBase)
    entries = tuple(e.xreplace(names) for e in (value if matrix else [value]))
    if any(e.has(sp.zoo, sp.oo, -sp.oo, sp.nan) for e in entries):
        raise PendverifyError("its expressions are infinite or NaN as SymPy reads them (a division by zero)")
    return list(_printed(method, value.shape if matrix else None, entries))


@functools.lru_cache(maxsize=512)
def _printed(method: str, shape: tuple[int, int] | None, entries: tuple) -> tuple[str, ...]:
    """The function of ``method`` computing ``entries`` (a matrix of ``shape``, or a scalar).

    A pure function of its arguments, kept for the process: a class made from another
    (``pendverify mutate``'s mutants) prints again only the methods whose expressions differ.
    """
    import sympy as sp

    printer = numpy_printer()
    replacements, reduced = sp.cse(list(entries), symbols=sp.numbered_symbols("c"), order="canonical")
    used = set().union(*(e.free_symbols for e in [*reduced, *(r for _, r in replacements)]))
    parameters = sorted((s for s in used if s.name[0] == "p"), key=lambda s: int(s.name[1:]))
    body = [f"{p.name} = P[{p.name[1:]}]" for p in parameters]
    arrays = {"q": "Q", "v": "V", "u": "U", "w": "W"}
    for s in sorted((s for s in used if s.name[0] in arrays), key=lambda s: s.name):
        body.append(f"{s.name} = {arrays[s.name[0]]}[:, {s.name[1:]}]")
    for symbol, expr in replacements:
        body.append(f"{symbol.name} = {printer.doprint(expr)}")
    if shape is not None:
        rows, cols = shape
        body.append(f"out = numpy.empty((N, {rows}, {cols}))")
        for k, expr in enumerate(reduced):
            body.append(f"out[:, {k // cols}, {k % cols}] = {printer.doprint(expr)}")
    else:
        body.append("out = numpy.empty(N)")
        body.append(f"out[:] = {printer.doprint(reduced[0])}")
    body.append("return out")
    return (f"def {method}(P, Q, V, U, W):", "    N = Q.shape[0]", *(f"    {line}" for line in body))


def render(model_cls) -> str:
    """The module of ``model_cls``'s generated closed forms (see the module docstring)."""
    from sympy.printing.codeprinter import PrintMethodNotImplementedError

    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.errors import PendverifyError

    written = [m for m in model_cls.own_methods() if m in METHODS]
    functions: list[str] = []
    generated: list[str] = []
    missing: dict[str, str] = {}
    try:
        sm = SymbolicModel.of(model_cls)
    except PendverifyError as exc:
        sm, missing = None, dict.fromkeys(written, str(exc))
    if sm is not None:
        names = _renamed(sm)
        for method in written:
            try:
                lines = _function(method, sm.evaluate(method, METHODS[method]), names)
            except PendverifyError as exc:
                missing[method] = str(exc)
                continue
            except PrintMethodNotImplementedError as exc:
                missing[method] = f"its expressions use a function NumPy has no ufunc for ({exc})"
                continue
            functions += ["", "", *lines]
            generated.append(method)
    header = [
        f'"""Generated by pendverify.numerics.codegen.vectorised ({GENERATOR}) from model '
        f'{model_cls.name!r}; do not edit."""',
        "",
        "import numpy",
        "",
        f"PARAMETERS = {tuple(f.name for f in dataclasses.fields(model_cls.params_type))!r}",
        f"MISSING = {missing!r}",
    ]
    registry = ["", "", "FUNCTIONS = {", *(f"    {m!r}: {m}," for m in generated), "}", ""]
    return "\n".join(header + functions + registry)


def generated(model_cls) -> types.ModuleType | types.SimpleNamespace:
    """The generated module of ``model_cls`` (``FUNCTIONS``, ``MISSING``): from memory, from the
    signed on-disk cache (``codegen.cache``, where a second process finds it without SymPy),
    or generated.

    A class edited numerically (``pendverify.symbolic.edited`` with ``readable=False``: a
    mutant) shares its base's module less the edited methods and the methods that read them
    (a hand-written q̈ calling M), which its own Python evaluates: the others are the base's
    code, so generating them again for each of hundreds of mutants would print the same
    functions (0.3 s each for a 5-link chain)."""
    from pendverify.numerics.codegen.cache import Family, kernel

    edited = vars(model_cls).get(NUMERIC_EDITS)
    if edited is not None:
        base, methods = edited
        module = generated(base)
        why = "edited numerically (a mutant): evaluated with its own Python"
        return types.SimpleNamespace(
            PARAMETERS=module.PARAMETERS,
            FUNCTIONS={m: f for m, f in module.FUNCTIONS.items() if m not in methods},
            MISSING={**module.MISSING, **dict.fromkeys(methods, why)},
        )
    return kernel(model_cls, family=Family("vectorised", render, numba=False)).module


#: the class attribute of a class edited numerically: (its base, the edited methods and their readers)
NUMERIC_EDITS = "numeric_edits"
