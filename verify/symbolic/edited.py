"""A model with some entries of its closed forms replaced by other expressions.

``edited_model(model, sm, edits)`` is an instance of a subclass of the model's class whose
edited methods call the original and overwrite the edited entries (``edits``: {method:
[(row-major index, original expression, new expression), ...]}); the other entries keep
their original rounding, and methods that call an edited one see the edit, as they would in
source code.  Numerically the new entries are lambdified onto ``math``; read by SymPy
(``self.math`` is SymPy's, ``pendverify.analytic.symbolic_reading``) they are the new
expressions themselves with the arguments substituted, so the generated NumPy code
(``pendverify.numerics.codegen.vectorised``) and a second symbolic reading see the edited
model.  ``pendverify mutate`` plants its mutants this way; a repair
(``pendverify.diagnosis.repair``) is confirmed on the model edited this way.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from pendverify.analytic.symbolic_reading import SYMBOLIC_MATH, SymbolicModel, entries, to_sympy
from pendverify.errors import PendverifyError
from pendverify.numerics.codegen.vectorised import METHODS, NUMERIC_EDITS


def _edited_method(cls, sm: SymbolicModel, method: str, changes, readable: bool):
    args = cls.closed_forms[method].args
    symbols = sm.flat_arguments(args) + list(sm.parameters.values())
    functions = [
        (index, sp.lambdify(symbols, expr, modules="math", docstring_limit=0)) for index, _, expr in changes
    ]
    original = getattr(cls, method)
    scalar = not isinstance(sm.closed_forms[method], sp.MatrixBase)

    def edited(self, *a):
        flat = [x for arg in a for x in np.ravel(np.asarray(arg, dtype=object))]
        values = [getattr(self.params, name) for name in sm.parameters]
        if readable and self.math is SYMBOLIC_MATH:
            mapping = dict(zip(symbols, [sp.sympify(x) for x in (*flat, *values)], strict=True))
            if scalar:
                return changes[0][2].xreplace(mapping)
            shape = np.shape(original(self, *a))
            out = np.array(to_sympy(original(self, *a)), dtype=object).reshape(shape)
            for index, _, expr in changes:
                out.flat[index] = expr.xreplace(mapping)
            return out
        flat = [float(x) for x in flat]
        values = [float(v) for v in values]
        if scalar:
            return float(functions[0][1](*flat, *values))
        out = np.array(original(self, *a), dtype=float)
        for index, f in functions:
            out.flat[index] = f(*flat, *values)
        return out

    edited.__name__ = method
    return edited


_READERS: dict[tuple, tuple[str, ...]] = {}


def _readers(model, sm: SymbolicModel, methods: tuple[str, ...]) -> tuple[str, ...]:
    """The model's other methods whose value reads an entry of ``methods`` (a hand-written q̈ that
    calls M): read by SymPy on the model with every entry of ``methods`` a fresh symbol, once per
    class and methods.  Every method, if that reading fails: then none shares generated code."""
    cls = type(model)
    key = (cls, methods)
    if key not in _READERS:
        marks = {
            m: [(i, e, sp.Dummy(f"edited_{m}_{i}")) for i, e in enumerate(entries(sm.closed_forms[m]))]
            for m in methods
        }
        symbols = {d for changes in marks.values() for _, _, d in changes}
        others = [m for m in cls.own_methods() if m in METHODS and m not in methods]
        try:
            probe = SymbolicModel.of(edited_model(model, sm, marks, "Probe", readable=True).__class__)
            readers = [
                m
                for m in others
                if symbols & set().union(*map(_free, entries(probe.evaluate(m, METHODS[m]))))
            ]
        except PendverifyError:  # a model SymPy reads only in part: share nothing
            readers = others
        _READERS[key] = tuple(readers)
    return _READERS[key]


def _free(expr) -> set:
    return getattr(sp.sympify(expr), "free_symbols", set())


def edited_model(model, sm: SymbolicModel, edits: dict, name: str = "Edited", readable: bool = True):
    """``model`` with the entries of ``edits`` ({method: changes}) replaced (module docstring).

    ``readable=False``: SymPy cannot read the edited methods (they take floats only), so the
    checks evaluate them with their own Python state by state instead of generating NumPy code
    for each edited model (``pendverify mutate``'s hundreds of mutants: generating costs more
    than it saves there); their other methods use the model's generated code
    (``pendverify.numerics.codegen.vectorised.generated``)."""
    cls = type(model)
    namespace = {
        method: _edited_method(cls, sm, method, changes, readable) for method, changes in edits.items()
    }
    namespace["__module__"] = cls.__module__  # messages name the model's own file
    if not readable:  # the generated code of the methods that do not read an edited one is the model's own
        namespace[NUMERIC_EDITS] = (cls, tuple(edits) + _readers(model, sm, tuple(edits)))
    edited = type(f"{cls.__name__}{name}", (cls,), namespace)(model.params)
    if {"gravity_scale", "diagonal_scale"} - set(cls.hand_written()):
        # derived tolerance scales stay the original's, as hand-written ones would
        edited.use_derived_scales(model.derived_scales())
    return edited
