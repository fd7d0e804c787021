"""Where a model's code is, which of its parts use a parameter, and which parameters it reads.

For the messages and the search of ``pendverify.diagnosis.parameter_repair``: a model SymPy
cannot read is named by what its source defines (``DYNAMICS f`` and the declaration's B, D, W;
the NumPy functions M, C, G, …; a class's methods), and a part *uses* a parameter when its value
changes with that parameter moved by a quarter at some of the given states.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from pendverify.analytic.forms import INTERFACE
from pendverify.analytic.numpy_model import FUNCTIONS, NumpyFunctionModel
from pendverify.analytic.python_dynamics import PythonDynamicsModel
from pendverify.analytic.source_file import where
from pendverify.diagnosis.parameter_edits import ParameterEdit

#: the interface's methods beyond its closed forms that evaluate the model's code
EVALUATED = ("coriolis_force", "acceleration")
#: the matrices a dynamics-as-code declaration writes, by their methods
_DECLARED = {"damping_matrix": "D", "input_matrix": "B", "disturbance_matrix": "W"}


def location(model_cls) -> tuple[str, dict[str, str]]:
    """(where the code is: its file and what it defines, its parts: method → the name the code
    gives it)."""
    if issubclass(model_cls, PythonDynamicsModel):
        name = f"DYNAMICS {getattr(model_cls.dynamics, '__name__', 'function')}"
        declared = {m: f'DECLARATION["{k}"]' for m, k in _DECLARED.items() if m in model_cls.hand_written()}
        return f"{model_cls.source}, {name}", {"acceleration": "DYNAMICS", **declared}
    if issubclass(model_cls, NumpyFunctionModel):
        parts = {FUNCTIONS[key][2]: key for key in model_cls.functions}
        if "h" in model_cls.functions:
            parts |= {"coriolis_force": "h", "gravity": parts.get("gravity", "h")}
        return f"{model_cls.source}, functions {', '.join(model_cls.functions)}", parts
    written = [m for m in model_cls.hand_written() if INTERFACE[m].closed_form or m in EVALUATED]
    parts = {m: f"{model_cls.__name__}.{m}" for m in written}
    return f"{where(model_cls)}, class {model_cls.__name__}", parts


def parts_using(model, states, name: str, parts: dict[str, str]) -> list[str]:
    """The parts of ``model``'s code (``parts``: method → the name the code gives it) whose values
    change with parameter ``name`` (moved by a quarter) at some state of ``states``."""
    other = type(model)(ParameterEdit("scale", name, factor=Fraction(5, 4)).applied(model.params))
    rows = [{"q": s.q, "v": s.v, "u": s.u, "w": s.w} for s in states]
    out = []
    with np.errstate(all="ignore"):
        for method, part in parts.items():
            for row in rows:
                args = [row[a] for a in INTERFACE[method].args]
                try:
                    a = np.asarray(getattr(model, method)(*args), dtype=float)
                    b = np.asarray(getattr(other, method)(*args), dtype=float)
                except Exception:  # the user's code at moved values: not seen to use it
                    break
                if a.shape != b.shape or not np.array_equal(a, b):
                    out.append(part)
                    break
    return list(dict.fromkeys(out))


def read_parameters(model, states) -> set[str]:
    """The parameters ``model``'s code reads: those some part of it changes with at ``states``."""
    _, parts = location(type(model))
    return {n for n in model.params.as_dict() if parts_using(model, states, n, parts)}


def uses(found: list[str], name: str, parts: dict[str, str]) -> str:
    """ "M, G use m2": the parts that use a parameter, or all of them when none was seen to."""
    names = found or list(dict.fromkeys(parts.values()))
    return f"{', '.join(names)} use{'s' if len(names) == 1 else ''} {name}"
