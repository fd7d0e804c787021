"""Functions written once and copied into every generated module.

The DOP853 stepper (``pendverify.numerics.integrators.dop853``) and the fixed-step methods
(``pendverify.numerics.integrators.fixedstep``) are written there as plain Python functions
marked ``@template(...)``, calling placeholders (``_rhs = placeholder("_rhs")``) for
the model-specific functions.  ``copy`` reads their source with ``inspect`` and
writes it into a generated module, decorated ``@njit(cache=True, error_model="numpy",
...)`` there, with the module-level constants they read as exact literals, so that
each calls that model's ``_rhs`` (or ``_hamilton``) directly — inlined where its body is short
(``codegen.compiled``) — and numba caches them
with the module.  Why copied and not passed as an argument: numba specialises a
function on a dispatcher argument, but its on-disk cache keys that specialisation on
the dispatcher object, so a new process never hits it and compiles again (≈ 10 s per
model); a ``types.FunctionType`` argument (explicit signature) is cached once for all
models, but every call then goes through a pointer, not inlined, and a whole DOP853
run took 1.7–1.8× as long.
"""

from __future__ import annotations

import ast
import inspect
import textwrap
import types

import numpy as np

from pendverify.errors import PendverifyError


def template(**options):
    """Mark a function to be copied into generated modules, compiled with numba ``options``."""

    def mark(func):
        func.numba_options = {"cache": True, "error_model": "numpy", **options}
        return func

    return mark


def placeholder(name: str):
    """Stands for a function every generated module defines (``_rhs``, ``_hamilton``...)."""

    def missing(*args):
        raise NotImplementedError(f"{name} exists only in generated modules (pendverify.numerics.generate)")

    missing.__name__ = missing.__qualname__ = name
    missing.placeholder = True
    return missing


def global_names(func) -> set[str]:
    """The names ``func``'s source reads without binding them itself (its arguments, assignments,
    loop targets): the module-level names it uses, besides builtins and attribute names."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(func)))
    bound = {node.arg for node in ast.walk(tree.body[0].args) if isinstance(node, ast.arg)}
    read = set()
    for node in ast.walk(tree.body[0]):
        if isinstance(node, ast.Name):
            (read if isinstance(node.ctx, ast.Load) else bound).add(node.id)
    return read - bound


def _literal(module: types.ModuleType, name: str) -> str:
    value = vars(module)[name]
    if isinstance(value, np.ndarray):
        flat = ", ".join(repr(float(x)) for x in value.ravel())
        return f"{name} = np.array([{flat}]).reshape({value.shape!r})"
    if isinstance(value, float):
        return f"{name} = {float(value)!r}"
    if isinstance(value, int):
        return f"{name} = {int(value)}"
    raise PendverifyError(f"{module.__name__}.{name}: cannot copy a {type(value).__name__}")


def copy(*modules: types.ModuleType) -> str:
    """The templates of ``modules`` (in definition order) and the constants they read, as source."""
    functions, constants = [], {}
    for module in modules:
        names = set()
        for func in vars(module).values():
            if callable(func) and getattr(func, "numba_options", None) and func.__module__ == module.__name__:
                functions.append(func)
                names |= global_names(func)
        for name in sorted(names):
            value = vars(module).get(name)
            skip = value is None or callable(value) or isinstance(value, types.ModuleType)
            if skip:
                continue
            line = _literal(module, name)
            if constants.setdefault(name, line) != line:
                raise PendverifyError(
                    f"template constant {name} differs between {', '.join(m.__name__ for m in modules)}"
                )
    chunks = []
    for func in functions:
        lines = inspect.getsource(func).splitlines()
        start = next(i for i, line in enumerate(lines) if line.startswith("def "))
        options = ", ".join(f"{k}={v!r}" for k, v in func.numba_options.items())
        chunks.append(f"@njit({options})\n" + "\n".join(lines[start:]) + "\n")
    header = [
        f"# copied from {', '.join(m.__name__ for m in modules)} (templates), constants as exact literals"
    ]
    return "\n".join(header + list(constants.values())) + "\n\n\n" + "\n\n".join(chunks)
