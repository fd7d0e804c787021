"""A model's quantities as CasADi ``Function`` objects: ``NAME_casadi.py`` (``export --casadi``).

The module builds each quantity once, when it is imported, as a ``casadi.Function`` of symbolic
(``SX``) arguments, so an optimal-control problem can differentiate and compose it or generate C
from it with CasADi's own tools::

    import NAME_casadi as model
    p = model.parameters({"m1": 1.0, …})      # the vector p, in the order of model.PARAMETERS
    model.M(q, p), model.Cqdot(q, v, p), model.G(q, p), model.qddot(q, v, u, w, p), …

The functions are those of the other languages (``pendverify.export.writers``): the same keys
(``M``, ``Cqdot``, ``G``, ``D``, ``B``, ``W``, ``det_M``, ``qddot``), the arguments q, v, u, w that
have entries, then ``p``.  Matrices are dense n × m, vectors n × 1, det M 1 × 1.  The common
subexpressions are computed once (``sympy.cse``); numbers are written exactly as doubles
(``ExactNumbers``); a function CasADi has no counterpart for is refused naming it.
"""

from __future__ import annotations

import math

from pendverify.errors import PendverifyError
from pendverify.export.closed_forms import QUANTITIES, ExportForms
from pendverify.export.names import c_name
from pendverify.export.writers import reduced, renamed, used

#: the names a function's body may not take for a coordinate or parameter: its arguments, the
#: module and the names the module defines
CASADI_RESERVED = frozenset("q v u w p out casadi PARAMETERS parameters".split())
#: SymPy function → CasADi's function of the same meaning
CASADI_FUNCTIONS = {
    **{name: f"casadi.{name}" for name in "sin cos tan exp log asin acos atan sinh cosh tanh".split()},
    "atan2": "casadi.atan2",
    "Abs": "casadi.fabs",
    "Max": "casadi.fmax",
    "Min": "casadi.fmin",
}
#: why ``export --casadi`` is refused without the package
NOT_INSTALLED = "the casadi package is not installed (pip install 'pendverify[casadi]')"


def casadi_printer():
    """SymPy's Python printer writing CasADi calls, numbers exact; strict about other functions."""
    from sympy.printing.pycode import PythonCodePrinter

    from pendverify.numerics.codegen.printers import ExactNumbers

    class CasadiPrinter(ExactNumbers, PythonCodePrinter):
        def _print_Pow(self, expr, rational=False):
            return self._hprint_Pow(expr, rational=rational, sqrt="casadi.sqrt")

        def _print_Pi(self, expr):
            return repr(math.pi)

        def _print_sign(self, expr):
            return f"casadi.sign({self._print(expr.args[0])})"

        def _print_Piecewise(self, expr):
            raise PendverifyError("export --casadi: a piecewise expression is not written as CasADi code")

    return CasadiPrinter({"user_functions": CASADI_FUNCTIONS, "strict": True, "standard": "python3"})


def write_casadi(forms: ExportForms, banner: list[str]) -> dict[str, str]:
    """``NAME_casadi.py`` (module docstring)."""
    prefix = c_name(forms.name)
    fields = [name for name, _, _ in forms.parameters]
    forms = renamed(forms, CASADI_RESERVED)
    printer = casadi_printer()
    lines = ['"""' + "\n".join(banner) + '\n"""', "", "import casadi", ""]
    lines += [
        "#: the parameters in the order of the vector p every function takes",
        f"PARAMETERS = {tuple(fields)!r}",
        "",
        "",
        "def parameters(values):",
        '    """The vector p of a mapping of the parameters\' values by name."""',
        "    return casadi.DM([float(values[name]) for name in PARAMETERS])",
        "",
        "",
    ]
    built = []
    sizes = {a: len(getattr(forms, a)) for a in "qvuwp"}
    for key, matrix in forms.quantities.items():
        arguments = [*forms.arguments(key), "p"]
        shared, entries = reduced(forms, matrix)
        body = [f'    {a} = casadi.SX.sym("{a}", {sizes[a]})' for a in arguments]
        body += [
            f"    {s.name} = {a}[{getattr(forms, a).index(s)}]"
            for a in "qvuwp"
            for s in used(forms, shared, entries, getattr(forms, a))
        ]
        body += [f"    {t.name} = {printer.doprint(e)}" for t, e in shared]
        body.append(f"    out = casadi.SX({matrix.rows}, {matrix.cols})")
        body += [
            f"    out[{i}, {j}] = {printer.doprint(entries[i * matrix.cols + j])}"
            for i in range(matrix.rows)
            for j in range(matrix.cols)
            if entries[i * matrix.cols + j] != 0
        ]
        names = ", ".join(f'"{a}"' for a in arguments)
        body.append(
            f'    return casadi.Function("{key}", [{", ".join(arguments)}], [out], [{names}], ["{key}"])'
        )
        lines += [f"def _{QUANTITIES[key][0]}():", f'    """{QUANTITIES[key][2]}."""', *body, "", ""]
        built.append(f"{key} = _{QUANTITIES[key][0]}()")
    lines += built
    return {f"{prefix}_casadi.py": "\n".join(lines) + "\n"}
