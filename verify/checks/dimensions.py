"""The physical dimension of every entry of a model's closed forms, from its parameters' kinds.

Every parameter declares a kind (``pendverify.analytic.parameter_set.KIND_RULES``) and every
coordinate is an angle or a position (``ClosedFormModel.angular``; a text model's
``[coordinates]``, a declaration's ``coordinates``), so each term a model writes has a
physical dimension, and each entry of M, C, H, ... has the one its place in the equations of
motion gives it.  ``read_units`` reads the model with SymPy (``SymbolicModel``) and names every
entry whose terms disagree, and every entry whose terms agree on the wrong dimension: an error
that no robot file is needed to see (``m*l`` in an entry of kg·m² is wrong whatever the values).
The ``units`` check (``pendverify.checks.units``) reports it.

What each entry must be
-----------------------
A coordinate q_j is an angle (rad: dimensionless) or a position (m).  The generalized force τ_i
is conjugate to q_i: τ_i·q̇_i is a power (kg·m²/s³), so [τ_i] = kg·m²/s² / [q_i] (N·m for an
angle, N for a position).  Every term of M q̈ + C q̇ + D q̇ + H = B u + W w is a τ, so

    [M_ij] = [τ_i]·s²/[q_j]     two angles: kg·m²; two positions: kg; one of each: kg·m
    [C_ij] = [D_ij] = [τ_i]·s/[q_j]
    [H_i] = [(C q̇)_i] = [τ_i]
    [V] = kg·m²/s²              an energy; H_i = ∂V/∂q_i gives [V]/[q_i] = [τ_i] again
    [det M] = Π_i [τ_i]·s²/[q_i]  each product Π_i M_iσ(i) of the determinant has it, whatever σ
    [(M⁻¹)_ij] = [q_i]/([τ_j]·s²)  (q̈ = M⁻¹ τ)
    [q̈_i] = [q_i]/s²

[B_ij] = [τ_i]/[u_j] and [W_ij] = [τ_i]/[w_j], but no model declares the units of its inputs and
disturbances; B, W and a model's forms beyond the interface (its own f, ...) are held to the
agreement of each entry's terms only.

The dimension of a term
-----------------------
Recursively, with a *wildcard* (None) wherever the dimension cannot be decided:

* a parameter: its kind's (mass kg, length and offset m, inertia kg·m², gravity m/s²); a damping
  coefficient is N·m·s/rad on a revolute joint and N·s/m on a prismatic one, which the kind
  does not say: a wildcard, as is a symbol whose kind is not declared;
* q_j, q̇_j: [q_j], [q_j]/s; an input u or a disturbance w: a wildcard (its unit is not declared);
* an integer or a fraction up to 9 over 12: a pure number (a derivation's 2, 1/2, 4/3, 1/12); π
  likewise; a decimal (9.81, 0.5) or a larger integer (10) may be a quantity written by its value
  (g, a length): a wildcard, and so is a number standing alone as a term of a sum
  (``m*l**2 + 0.01``, ``1 + cos(θ)``), whatever it is;
* a product: the product of its factors' dimensions (a wildcard if one is); x**r for a number
  r: [x]^r (a square root is r = 1/2); a power with a symbolic exponent needs a dimensionless
  base and exponent, and is dimensionless;
* sin, cos, tan, exp, log, the hyperbolic and inverse functions: the argument must be
  dimensionless and the result is; atan2(y, x): y and x agree, the result is dimensionless;
  Abs(x): [x]; Max, Min and a Piecewise's values agree;
* a sum: the dimension its decided terms share; two decided terms that differ are a *clash*;
* anything else (a function of the model's own): a wildcard, its arguments searched for clashes.

Never a false alarm: in a model whose every sum is homogeneous, every dimension decided above is
the term's true dimension, given the declared kinds and coordinates; so a clash, or a decided
entry whose dimension is not its place's, is an error of the model (or of a declaration), never of
the rule.  Whatever the rule cannot decide, it does not claim.

Representation: a dimension is its vector of exponents of kg, m and s (fractions: a
square root halves them), compared and hashed as a tuple.  ``sympy.physics.units``' ``Dimension`` is a
SymPy expression that must be canonicalised (``dimsys_SI.get_dimensional_dependencies``, which
returns that same vector as a dict) before two can be compared or grouped, at every product.
Measured on the 238 non-zero entries of the built-in and worked examples' models (SymPy's reading
excluded, best of 5 on the project's 2-core VM): 0.027 s with vectors, 0.12 s with ``Dimension``
objects canonicalised once each.  The vectors are the canonical form itself, a wildcard is None,
and a fractional exponent is a ``Fraction``; the three base dimensions are all a closed form can
hold (no current, no temperature), so nothing of ``sympy.physics.units`` is missed.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from fractions import Fraction

import sympy as sp

from pendverify.analytic import parameter_set
from pendverify.analytic.forms import entry_position
from pendverify.analytic.source_file import where
from pendverify.analytic.symbolic_reading import SymbolicModel, entries
from pendverify.analytic.text_model import METHODS
from pendverify.diagnosis.notation import Notation
from pendverify.diagnosis.slots import QUANTITY, entry_label
from pendverify.display import shortened
from pendverify.errors import PendverifyError

#: a dimension: the exponents of kg, m and s
Dim = tuple[Fraction, Fraction, Fraction]


def _dim(kg=0, m=0, s=0) -> Dim:
    return (Fraction(kg), Fraction(m), Fraction(s))


NONE = _dim()
LENGTH = _dim(m=1)
SECOND = _dim(s=1)
ENERGY = _dim(1, 2, -2)
#: each parameter kind's dimension (``parameter_set.KIND_DIMENSIONS``); damping's depends on its
#: joint: not decided (module docstring)
KIND_DIMENSIONS: dict[str, Dim | None] = {
    kind: None if d is None else _dim(*d) for kind, d in parameter_set.KIND_DIMENSIONS.items()
}
#: the functions whose argument must be dimensionless and whose value is
PURE_FUNCTIONS = (
    sp.sin, sp.cos, sp.tan, sp.cot, sp.sec, sp.csc, sp.asin, sp.acos, sp.atan, sp.acot,
    sp.sinh, sp.cosh, sp.tanh, sp.asinh, sp.acosh, sp.atanh, sp.exp, sp.log,
)  # fmt: skip
#: the largest numerator and denominator of an integer or fraction read as a pure number: a
#: derivation's coefficients (2, 1/2, 4/3, 1/12, 9 cos² θ); 10 may be g written by its value
PURE_NUMERATOR, PURE_DENOMINATOR = 9, 12
#: the largest denominator of a decimal exponent read as a fraction (x**0.5 is a square root)
EXPONENT_DENOMINATOR = 12
#: the widest a term is printed in a message
TERM_WIDTH = 70


def mul(a: Dim, b: Dim) -> Dim:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def power(a: Dim, r: Fraction) -> Dim:
    return (a[0] * r, a[1] * r, a[2] * r)


def inverse(a: Dim) -> Dim:
    return power(a, Fraction(-1))


_SUPERSCRIPTS = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")


def unit_text(d: Dim) -> str:
    """A dimension as SI units: ``kg·m²/s²``, ``1/s``, ``dimensionless``."""

    def factor(name: str, e: Fraction) -> str:
        if e == 1:
            return name
        if e.denominator == 1:
            return name + str(e.numerator).translate(_SUPERSCRIPTS)
        return f"{name}^({e})"

    names = ("kg", "m", "s")
    top = [factor(n, e) for n, e in zip(names, d, strict=True) if e > 0]
    bottom = [factor(n, -e) for n, e in zip(names, d, strict=True) if e < 0]
    if not top and not bottom:
        return "dimensionless"
    text = "·".join(top) or "1"
    if bottom:
        text += "/" + ("·".join(bottom) if len(bottom) == 1 else f"({'·'.join(bottom)})")
    return text


@dataclasses.dataclass
class DimensionReader:
    """The dimension of a model's expressions (module docstring), collecting the clashes it meets."""

    symbols: dict[sp.Symbol, Dim | None]
    render: Callable[[sp.Expr], str] = str
    #: each parameter's declared kind, named beside a parameter standing alone as a term
    kinds: dict[sp.Symbol, str] = dataclasses.field(default_factory=dict)
    clashes: list[str] = dataclasses.field(default_factory=list)

    def term(self, expr) -> str:
        return shortened(self.render(expr), TERM_WIDTH)

    def named(self, expr) -> str:
        """A term as ``term`` writes it, with its kind when it is one parameter (``a1, an inertia,``)."""
        kind = self.kinds.get(expr) if isinstance(expr, sp.Symbol) else None
        if not kind:
            return self.term(expr)
        return f"{self.term(expr)}, declared {'an' if kind[0] in 'aeiou' else 'a'} {kind},"

    def of(self, expr) -> Dim | None:
        """[expr], or None where it cannot be decided; clashes inside are appended to ``clashes``."""
        if isinstance(expr, sp.Symbol):
            return self.symbols.get(expr)
        if isinstance(expr, sp.NumberSymbol):
            return NONE
        if isinstance(expr, sp.Rational) and abs(expr.p) <= PURE_NUMERATOR and expr.q <= PURE_DENOMINATOR:
            return NONE
        if isinstance(expr, sp.Number):  # a decimal, g = 10: maybe a quantity written by its value
            return None
        if isinstance(expr, sp.Add):
            return self.agree(expr, expr.args, top=False)
        if isinstance(expr, sp.Mul):
            dims = [self.of(a) for a in expr.args]
            if any(d is None for d in dims):
                return None
            out = NONE
            for d in dims:
                out = mul(out, d)
            return out
        if isinstance(expr, sp.Pow):
            return self.pow(expr)
        if isinstance(expr, PURE_FUNCTIONS):
            for arg in expr.args:
                self.dimensionless(arg, f"the argument of {type(expr).__name__}")
            return NONE
        if isinstance(expr, sp.atan2):
            y, x = expr.args
            dy, dx = self.of(y), self.of(x)
            if dy is not None and dx is not None and dy != dx:
                self.clashes.append(
                    f"atan2's arguments {self.term(y)} and {self.term(x)} have {unit_text(dy)} and "
                    f"{unit_text(dx)}: they must agree"
                )
            return NONE
        if isinstance(expr, sp.sign):
            self.of(expr.args[0])
            return NONE
        if isinstance(expr, sp.Abs):
            return self.of(expr.args[0])
        if isinstance(expr, (sp.Max, sp.Min)):
            return self.agree(expr, expr.args, top=False)
        if isinstance(expr, sp.Piecewise):
            return self.agree(expr, [value for value, _ in expr.args], top=False)
        for arg in expr.args:  # a function of the model's own: not decided, its arguments still read
            if isinstance(arg, sp.Basic):
                self.of(arg)
        return None

    def pow(self, expr: sp.Pow) -> Dim | None:
        base, exponent = expr.args
        if isinstance(exponent, sp.Rational):
            r = Fraction(int(exponent.p), int(exponent.q))
        elif isinstance(exponent, sp.Float):
            r = Fraction(float(exponent)).limit_denominator(EXPONENT_DENOMINATOR)
            if float(r) != float(exponent):  # not a simple fraction: undecided
                self.of(base)
                return None
        else:
            self.dimensionless(base, "the base of a power with a symbolic exponent")
            self.dimensionless(exponent, "an exponent")
            return NONE
        d = self.of(base)
        return None if d is None else power(d, r)

    def dimensionless(self, expr, what: str) -> None:
        d = self.of(expr)
        if d is not None and d != NONE:
            self.clashes.append(f"{what}, {self.term(expr)}, has {unit_text(d)}: it must be dimensionless")

    def agree(self, expr, terms, top: bool, required: Dim | None = None, place: str = "") -> Dim | None:
        """The dimension the decided ``terms`` share; a clash when they differ (module docstring).

        A number standing alone is not decided.  The clash names each group of terms of another
        dimension than the reference group's: the group of ``required`` if present, else the
        largest (the first of the largest on a tie)."""
        groups: dict[Dim, list] = {}
        for t in terms:
            d = None if isinstance(t, sp.Number) else self.of(t)
            if d is not None:
                groups.setdefault(d, []).append(t)
        if len(groups) <= 1:
            return next(iter(groups), None)
        reference = required if required in groups else max(groups, key=lambda d: len(groups[d]))
        odd = [
            f"the term{'s' if len(ts) > 1 else ''} {', '.join(self.named(t) for t in ts)} "
            f"{'have' if len(ts) > 1 else 'has'} {unit_text(d)}"
            for d, ts in groups.items()
            if d != reference
        ]
        where = "" if top else f"in {self.term(expr)}, "
        others = self.term(sp.Add(*groups[reference]))
        said = f"{where}{'; '.join(odd)} but {others} has {unit_text(reference)}"
        self.clashes.append(said + (f" ({place})" if place else ""))
        return None


def _coordinates(angular: tuple[bool, ...], names: tuple[str, ...], indices) -> str:
    """The coordinates an entry belongs to, with their kinds: ``the angle theta``, ``the position x
    and the angle theta``, ``the angle theta alone`` (a diagonal entry)."""
    said = [f"the {'angle' if angular[i] else 'position'} {names[i]}" for i in indices]
    if len(said) == 2 and indices[0] == indices[1]:
        return f"{said[0]} alone"
    return " and ".join(said)


def required(
    method: str, position: tuple[int, ...], angular: tuple[bool, ...], names: tuple[str, ...] = ()
) -> tuple[Dim | None, str]:
    """(the dimension entry ``position`` of ``method`` must have, the rule in words naming the
    coordinates ``names``, q1, q2, … if not given), or (None, "") where the interface does not fix
    it (module docstring)."""
    names = names or tuple(f"q{i + 1}" for i in range(len(angular)))
    q = [NONE if a else LENGTH for a in angular]
    tau = [mul(ENERGY, inverse(d)) for d in q]
    name = QUANTITY.get(method, method)
    if method == "potential_energy":
        return ENERGY, f"V is an energy, {unit_text(ENERGY)}"
    if method == "det_mass_matrix":
        d = NONE
        for i in range(len(q)):
            d = mul(d, mul(mul(tau[i], power(SECOND, Fraction(2))), inverse(q[i])))
        return d, f"det M is the product of M's diagonal units, {unit_text(d)}"
    if len(position) == 2 and method in ("mass_matrix", "coriolis_matrix", "damping_matrix",
                                         "inverse_mass_matrix"):  # fmt: skip
        i, j = position
        rules = {
            "mass_matrix": mul(mul(tau[i], power(SECOND, Fraction(2))), inverse(q[j])),
            "coriolis_matrix": mul(mul(tau[i], SECOND), inverse(q[j])),
            "damping_matrix": mul(mul(tau[i], SECOND), inverse(q[j])),
            "inverse_mass_matrix": mul(q[i], inverse(mul(tau[j], power(SECOND, Fraction(2))))),
        }
        d = rules[method]
        return d, f"an entry of {name} for {_coordinates(angular, names, (i, j))} is {unit_text(d)}"
    if len(position) == 1 and method in ("gravity", "coriolis_force", "acceleration"):
        i = position[0]
        d = tau[i] if method != "acceleration" else mul(q[i], power(SECOND, Fraction(-2)))
        return d, f"an entry of {name} for {_coordinates(angular, names, (i,))} is {unit_text(d)}"
    return None, ""


def symbol_dimensions(sm: SymbolicModel) -> dict[sp.Symbol, Dim | None]:
    """The dimension of each parameter, coordinate and rate (inputs and disturbances: not decided)."""
    dims: dict[sp.Symbol, Dim | None] = {s: KIND_DIMENSIONS.get(kind) for s, kind in sm.kinds.items()}
    for q, v, angle in zip(sm.symbols["q"], sm.symbols["v"], sm.cls.angular, strict=True):
        dims[q] = NONE if angle else LENGTH
        dims[v] = mul(dims[q], inverse(SECOND))
    return dims


def _location(model_cls, method: str) -> str:
    """Where a method's entries are written in the model's file, without the file: the key of a
    text model (and how a derived one is derived), ``Class.method`` of a class."""
    spec = getattr(model_cls, "text_spec", None)
    if spec is None:
        return f"{model_cls.__name__}.{method}"
    key = next((k for k, (m, _) in METHODS.items() if m == method), method)
    how = f" (derived: {spec.derived[key]})" if key in spec.derived else ""
    return f"key {key}{how}"


def _without_file(model_cls, exc: Exception) -> str:
    """An error about the model without the file's path it starts with: the reading is cached by the
    file's name and contents, and the report names the file where it is now (``checks.units``)."""
    text, head = str(exc), f"{where(model_cls)}: "
    return text[len(head) :] if text.startswith(head) else text


def read_units(model_cls) -> dict:
    """The dimensions of every entry of ``model_cls``'s written closed forms, as plain data.

    ``{"not_run": reason}`` when SymPy cannot read the model; else ``entries`` (the non-zero
    entries read), ``decided`` (those whose dimension was decided), ``unread`` ({method: why
    SymPy could not read it}) and ``findings``: one per entry whose terms clash or whose
    decided dimension is not its place's, each with its ``quantity``, 1-based ``index``,
    ``label`` (``M[2,2]``), ``location`` (the key or ``Class.method``) and ``message`` (the
    terms in the model's own notation and both dimensions)."""
    try:
        sm = SymbolicModel.of(model_cls)
    except PendverifyError as exc:
        return {"not_run": f"SymPy cannot read the model ({_without_file(model_cls, exc)})"}
    notation = Notation.of(model_cls)
    reader = DimensionReader(symbol_dimensions(sm), notation.render, dict(sm.kinds))
    names = tuple(reader.term(q) for q in sm.symbols["q"])  # in the model's notation
    out: dict = {"entries": 0, "decided": 0, "unread": {}, "findings": []}
    for method, form in model_cls.written_closed_forms().items():
        try:
            value = sm.evaluate(method, form.args)
        except PendverifyError as exc:
            out["unread"][method] = _without_file(model_cls, exc)
            continue
        shape = value.shape if isinstance(value, sp.MatrixBase) else None
        for index, expr in enumerate(entries(value)):
            if expr == 0:
                continue
            position = entry_position(method, shape, index) if shape else ()
            label = entry_label(method, value, index)
            d, clashes = entry_dimension(reader, expr, *required(method, position, model_cls.angular, names))
            out["entries"] += 1
            out["decided"] += d is not None
            if clashes:
                out["findings"].append(
                    {
                        "quantity": QUANTITY.get(method),
                        "index": [p + 1 for p in position],
                        "label": label,
                        "location": _location(model_cls, method),
                        "message": f"{label}: {'; '.join(clashes)}",
                    }
                )
    return out


def entry_dimension(
    reader: DimensionReader, expr, need: Dim | None, place: str
) -> tuple[Dim | None, list[str]]:
    """(the dimension of one entry, or None where undecided; its clashes: terms that disagree, and a
    decided dimension other than ``need``, the entry's place's as ``required`` gives it with ``place``)."""
    reader.clashes = []
    d = reader.agree(expr, sp.Add.make_args(expr), top=True, required=need, place=place)
    if d is not None and need is not None and d != need:
        reader.clashes.append(f"{reader.named(expr)} has {unit_text(d)} but {place}")
    return d, reader.clashes


__all__ = ["KIND_DIMENSIONS", "DimensionReader", "entry_dimension", "read_units", "required", "unit_text"]
