"""A model derived with ``sympy.physics.mechanics``, made into a model class like a text model.

Accepted: a ``LagrangesMethod`` (its ``mass_matrix`` and ``forcing``: M q̈ = forcing; the
equations are formed first if they are not), a ``KanesMethod`` after ``kanes_equations``
(its ``mass_matrix`` and ``forcing`` in the generalised speeds u' — required to be the
coordinates' rates, each kinematic differential equation q̇_i = u_j, so that u' is q̈; a
Kane model in other speeds is refused, since M would not be the one Pinocchio computes),
or a pair ``(mass_matrix, forcing)`` in the dynamic symbols, its rows in the coordinates'
order.  M is taken as the mass matrix and the forcing as f of M q̈ = f(q, q̇, u, w); f goes
the one way every right-hand side goes (``pendverify.analytic.text_model._split_f``: H,
C·q̇, D, B, W, each checked), so the model is a ``BiasOnlyModel`` whose parts say
"derived: from …".

What SymPy does not say — which coordinate is an angle, what kind of quantity each
parameter is, which URDF joint is which coordinate — comes from a *declaration*: a mapping
with the keys of a text model file but no equations (``DECLARATION_KEYS``: ``name``,
``coordinates`` (name → "angle"/"position", in order), ``inputs``, ``disturbances``,
``parameters`` (name → {kind, unit}), ``urdf`` (joints, transform, offset)).  Names are
matched BY NAME: the dynamic symbol ``theta1(t)`` is coordinate ``theta1``, its derivatives
``dtheta1`` and ``ddtheta1``; a symbol (or a dynamic symbol, as inputs often are) is the
parameter, input or disturbance of its name.  A name the declaration does not give is
refused, naming it.

The class keeps what it was made from (``derivation``, a ``Derivation``: the method object, the
declaration, the map of the method's dynamic symbols to the model's): a repair is searched
among the items the user wrote — a body's mass or inertia, a load, a term of the Lagrangian
(``pendverify.diagnosis.mechanics_source``) — and each candidate rebuilt through the pair form
``(M', forcing')`` with the same declaration (``rebuilt``).  It is a class attribute: a model
instance pickles without it, and the class pickles by reference as before.
"""

from __future__ import annotations

import dataclasses
import types
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import sympy as sp
from sympy.core.function import AppliedUndef

from pendverify.analytic.text_model import build_model_class, complete_equations
from pendverify.analytic.text_parse import DECLARATION_KEYS, Reader, TextModelSpec, read_text_document
from pendverify.display import shortened
from pendverify.errors import PendverifyError

#: what a mechanics object is named in messages and in ``spec.derived``
_KINDS = ("LagrangesMethod", "KanesMethod")


def is_mechanics(obj) -> bool:
    """Whether ``obj`` is what this module reads: a Lagrange or Kane method, or an (M, forcing) pair."""
    if type(obj).__name__ in _KINDS and type(obj).__module__.startswith("sympy.physics.mechanics"):
        return True
    return (
        isinstance(obj, tuple)
        and len(obj) == 2
        and all(isinstance(x, sp.MatrixBase) for x in obj)
        and obj[0].rows == obj[0].cols == obj[1].rows
        and obj[1].cols == 1
    )


def _name(f) -> str:
    return f.func.__name__ if isinstance(f, AppliedUndef) else str(f)


def _lagrange(reader: Reader, method):
    if method.eom is None:
        method.form_lagranges_equations()
    M, F = method.mass_matrix, method.forcing
    if M.cols != M.rows:
        reader.fail("method", "has constraints (Lagrange multipliers): give an unconstrained LagrangesMethod")
    return M, F, [_name(q) for q in method.q], {}


def _kane(reader: Reader, method):
    try:
        M, F = method.mass_matrix, method.forcing
    except (ValueError, AttributeError):
        reader.fail("method", "KanesMethod without equations: call its kanes_equations(bodies, loads) first")
    q, u = list(method.q), list(method.u)
    t = sp.Symbol("t") if not q else q[0].args[0]
    try:
        kd = method.kindiffdict()
    except AttributeError:
        reader.fail("method", "KanesMethod without kinematic differential equations")
    speeds = {}
    for qi in q:
        value = kd.get(qi.diff(t))
        if value not in u or value in speeds:
            reader.fail(
                "method",
                f"its generalised speeds are not the coordinates' rates: {_name(qi)}' = "
                f"{shortened(str(value), 60)}; write the kinematic differential equations as u_i = q_i'",
            )
        speeds[value] = qi
    return M, F, [_name(qi) for qi in q], speeds


def _mapped(reader: Reader, spec: TextModelSpec, expr, speeds: dict, what: str):
    """``expr`` in the model's symbols: dynamic symbols and symbols matched by name (module docstring)."""
    names = {s.name: s for g in "qvuwp" for s in spec.symbols[g]}
    order = {c: k for k, c in enumerate(spec.coordinates)}
    replace = {}
    for d in expr.atoms(sp.Derivative):
        base = d.expr
        n = sum(count for _, count in d.variable_count)
        if base in speeds:
            base, n = speeds[base], n + 1
        name = _name(base)
        if name not in order or n > 2:
            reader.fail(what, f"holds {shortened(str(d), 60)}, which is no coordinate's rate or acceleration")
        replace[d] = spec.symbols["v" if n == 1 else "a"][order[name]]
    for f in expr.atoms(AppliedUndef):
        if f in speeds:
            replace.setdefault(f, spec.symbols["v"][order[_name(speeds[f])]])
        elif _name(f) in names:
            replace.setdefault(f, names[_name(f)])
    mapped = expr.xreplace(replace)
    for f in mapped.atoms(AppliedUndef):
        reader.fail(what, f"holds the dynamic symbol {_name(f)}, which the declaration does not name")
    mapped = mapped.xreplace({s: names[s.name] for s in mapped.free_symbols if s.name in names})
    allowed = set(names.values()) | set(spec.symbols["a"])
    stray = sorted(s.name for s in mapped.free_symbols - allowed)
    if stray:
        reader.fail(
            what,
            f"uses {', '.join(stray)}, which the declaration does not name "
            "(declare each as a coordinate, parameter, input or disturbance)",
        )
    return mapped


@dataclass(frozen=True, eq=False)
class Derivation:
    """What a mechanics model class was made from (module docstring)."""

    method: object  # the LagrangesMethod, KanesMethod or (M, forcing) pair, as given
    kind: str  # "LagrangesMethod", "KanesMethod" or "(mass_matrix, forcing)"
    declaration: Mapping
    source: str
    spec: TextModelSpec
    speeds: dict  # Kane: each generalised speed → the coordinate whose rate it is
    M: sp.Matrix  # the mass matrix in the model's symbols, rows in the declaration's order
    forcing: sp.Matrix
    #: items written otherwise than in ``method``: {position among the derivation's items (in
    #: ``pendverify.diagnosis.mechanics_source.source_items``'s order): the expression written}
    #: — a derivation with one item edited (``edited``), M and forcing its own
    written: tuple = ()

    def in_model_symbols(self, expr, what: str = "derivation"):
        """``expr`` (in the method's dynamic symbols) in the model's symbols (module docstring)."""
        return _mapped(Reader(Path(self.source)), self.spec, sp.sympify(expr), self.speeds, what)

    def rebuilt(self, M, forcing):
        """The model class of the pair ``(M, forcing)`` (the model's symbols) with this declaration,
        in a module of its own (never registered: the model file's module is left alone)."""
        module = types.ModuleType(f"{self.spec.name}_rebuilt")
        return mechanics_model((M, forcing), self.declaration, self.source, module)

    def edited(self, position: int, expr, M, forcing):
        """The model class of this derivation with item ``position`` written as ``expr`` (the
        model's symbols) and M q̈ = forcing what it gives: rebuilt through the pair form, and
        keeping the method's items for a repair to edit (the corpus plants errors this way)."""
        cls = self.rebuilt(M, forcing)
        written = (*(w for w in self.written if w[0] != position), (position, expr))
        cls.derivation = dataclasses.replace(
            self, M=cls.derivation.M, forcing=cls.derivation.forcing, written=written
        )
        return cls


def mechanics_model(method, declaration: Mapping, source: str | Path = "<declaration>", module=None):
    """The model class of a ``sympy.physics.mechanics`` derivation and its declaration (docstring).

    ``source`` names the declaration in messages (a model file, or ``<declaration>``);
    ``module``: the model file's module the class is to live in.  Raises ``PendverifyError``.
    """
    path = Path(str(source))
    reader = Reader(path)
    if not isinstance(declaration, Mapping):
        reader.fail("declaration", "must be a mapping of name, coordinates, inputs, parameters and urdf")
    spec = read_text_document(path, dict(declaration), DECLARATION_KEYS)
    kind = type(method).__name__
    if kind == "LagrangesMethod":
        M, F, order, speeds = _lagrange(reader, method)
    elif kind == "KanesMethod":
        M, F, order, speeds = _kane(reader, method)
    else:
        M, F = method
        order, speeds, kind = list(spec.coordinates), {}, "(mass_matrix, forcing)"
    if sorted(order) != sorted(spec.coordinates):
        reader.fail(
            "coordinates",
            f"declares {', '.join(spec.coordinates)} but the {kind} has coordinates {', '.join(order)}",
        )
    perm = [order.index(c) for c in spec.coordinates]
    M = _mapped(reader, spec, M.extract(perm, perm), speeds, f"{kind} mass matrix")
    F = _mapped(reader, spec, F.extract(perm, [0]), speeds, f"{kind} forcing")
    if M.free_symbols & set(spec.symbols["a"]):
        reader.fail(f"{kind} mass matrix", "holds accelerations")
    if F.free_symbols & set(spec.symbols["a"]):
        reader.fail(
            f"{kind} forcing", "holds accelerations: M q̈ = forcing must be solved for q̈'s coefficients"
        )
    spec.equations["M"], spec.equations["f"] = M, F
    spec.derived["M"] = f"the {kind}'s mass matrix"  # f's parts say "from the …'s forcing: …"
    spec.derived["f"] = f"the {kind}'s forcing"
    derivation = Derivation(method, kind, dict(declaration), str(source), spec, speeds, M, F)
    complete_equations(reader, spec)
    cls = build_model_class(spec, module)
    cls.derivation = derivation
    return cls


def model_file_declaration(module, path: Path):
    """The model class a Python model file declares by ``METHOD`` and ``DECLARATION``, or None."""
    if not hasattr(module, "METHOD"):
        return None
    if not hasattr(module, "DECLARATION"):
        raise PendverifyError(
            f"{path}: defines METHOD but no DECLARATION (its coordinates, parameters, urdf)"
        )
    if not is_mechanics(module.METHOD):
        raise PendverifyError(
            f"{path}: METHOD must be a LagrangesMethod, a KanesMethod or a (mass_matrix, forcing) pair "
            f"of SymPy matrices, got a {type(module.METHOD).__name__}"
        )
    return mechanics_model(module.METHOD, module.DECLARATION, path, module)
