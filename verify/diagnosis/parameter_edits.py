"""The edits of a parameter set a repair search gives a model's code, simplest first.

``pendverify.diagnosis.parameter_repair`` gives a model SymPy cannot read an edited parameter
set and asks whether every check then passes; this module is what it tries (``parameter_edits``),
each edit a ``ParameterEdit``: p → k·p, two parameters of one dimension exchanged, one given
for another, p ± a product of parameters with p's dimension.  The order and the factors are
argued in ``parameter_repair``'s docstring.
"""

from __future__ import annotations

import copy
import dataclasses
from dataclasses import dataclass
from fractions import Fraction

import numpy as np
import sympy as sp

from pendverify.analytic.parameter_set import KIND_DIMENSIONS
from pendverify.diagnosis.monomials import fixed_parameters, products_of
from pendverify.errors import ParameterError

#: the factors of steps 1 and 3 (``parameter_repair``'s docstring)
FIRST_SCALES = (Fraction(2), Fraction(1, 2), Fraction(-1))
LATER_SCALES = (Fraction(4), Fraction(1, 4), Fraction(3), Fraction(1, 3), Fraction(12), Fraction(1, 12))
#: distinct parameters in a product added to or taken from a parameter (m·l² has two)
ADDED_FACTORS = 2
#: edits screened at most
EDITS = 400


@dataclass(frozen=True)
class ParameterEdit:
    """One edit of the parameter set the code is given (module docstring)."""

    kind: str  # "scale", "exchange", "other" or "add"
    name: str  # the parameter whose value the code is given otherwise
    other: str = ""  # exchange, other: the parameter whose value it gets
    factor: Fraction = Fraction(1)  # scale
    term: sp.Expr = sp.S.Zero  # add: the product added (with its sign)

    def given(self, values: dict[str, float]) -> dict[str, float]:
        """The values the code is given in place of ``values``' (only those that change)."""
        if self.kind == "scale":
            return {self.name: float(self.factor) * values[self.name]}
        if self.kind == "exchange":
            return {self.name: values[self.other], self.other: values[self.name]}
        if self.kind == "other":
            return {self.name: values[self.other]}
        symbols = {sp.Symbol(n): v for n, v in values.items()}
        return {self.name: values[self.name] + float(self.term.xreplace(symbols))}

    def applied(self, params):
        """``params`` with the edit, of the same type: validated as a set is where the values keep
        the kinds' rules, else the same set with the values replaced (module docstring)."""
        changes = self.given(params.as_dict())
        try:
            return params.replace(**changes)
        except (ParameterError, ValueError, ArithmeticError, TypeError):
            edited = copy.copy(params)
            for name, value in changes.items():
                object.__setattr__(edited, name, value)
            return edited

    def parameters(self) -> set[str]:
        """The parameters the edit involves (``Perturbation.why_not_alone``)."""
        extra = {self.other} if self.other else {str(s) for s in self.term.free_symbols}
        return {self.name} | extra

    def written(self) -> str:
        """What the code is given now (SymPy syntax): ``m2``; ``l1, l2`` for an exchange."""
        return f"{self.name}, {self.other}" if self.kind == "exchange" else self.name

    def suggested(self) -> str:
        """What the code is to be given instead: ``m2/2``; ``l2, l1`` for an exchange."""
        p = sp.Symbol(self.name)
        if self.kind == "scale":
            return str(sp.Rational(self.factor.numerator, self.factor.denominator) * p)
        if self.kind == "exchange":
            return f"{self.other}, {self.name}"
        return self.other if self.kind == "other" else str(p + self.term)

    def given_words(self) -> str:
        """ "the code is given m2/2 for m2" (the edit, in words)."""
        if self.kind == "exchange":
            return f"the code is given {self.other} for {self.name} and {self.name} for {self.other}"
        return f"the code is given {self.suggested()} for {self.name}"

    def meaning(self, kinds: dict[str, str]) -> str:
        """What the code does, if the edit is the repair, in the user's terms."""
        p = sp.Symbol(self.name)
        if self.kind == "scale":
            used = sp.Rational(self.factor.denominator, self.factor.numerator) * p
            return f"the code uses {_pretty(used)} where the robot has {self.name}"
        if self.kind == "exchange":
            return (
                f"the code uses {self.name} where {self.other} belongs, "
                f"and {self.other} where {self.name} belongs"
            )
        if self.kind == "other":
            return f"the code uses {self.name} where {self.other} belongs"
        out = f"the code uses {self.name} where {_pretty(p + self.term)} belongs"
        masses = [s for s in self.term.free_symbols if kinds.get(str(s)) == "mass"]
        if kinds.get(self.name) == "inertia" and masses:  # m·l²: an inertia about another point
            if self.term.could_extract_minus_sign():
                axis = f"the parallel-axis term {_pretty(-self.term)} counted twice"
                return f"{out} ({axis}: an inertia about the pivot where the centre of mass's belongs?)"
            axis = f"the parallel-axis term {_pretty(self.term)}"
            return f"{out} ({axis}: an inertia about the centre of mass where the pivot's belongs?)"
        return out


def _pretty(expr) -> str:
    """``2·m2``, ``m2·r2²``, ``−g``: an expression as the messages write it."""
    text = str(expr)
    for exponent, superscript in (("**2", "²"), ("**3", "³")):
        text = text.replace(exponent, superscript)
    return text.replace("*", "·").replace("-", "−")


def alike(a: str, b: str, kinds: dict, values: dict) -> bool:
    """Whether parameters ``a`` and ``b`` have one dimension (a damping coefficient only with another)
    and different values: one can stand for the other."""
    da, db = KIND_DIMENSIONS.get(kinds[a]), KIND_DIMENSIONS.get(kinds[b])
    same = da == db if da is not None else kinds[a] == kinds[b] is not None
    return a != b and same and values[a] != values[b]


def parameter_edits(params, read=None) -> list[ParameterEdit]:
    """The edits tried, in order (module docstring), at most ``EDITS``; ``read``: the parameters the
    code reads (``read_parameters``; None: all).  An edit changes what the code is given for a
    parameter it reads; an exchange with one it does not read is the other given for it (l → lc,
    where the code reads l and not lc), and is tried as that."""
    kinds = {f.name: f.metadata.get("kind") for f in dataclasses.fields(params)}
    values = params.as_dict()
    every = [n for n in kinds if np.isfinite(values[n]) and values[n] != 0]
    names = [n for n in every if read is None or n in read]

    out = [ParameterEdit("scale", n, factor=k) for k in FIRST_SCALES for n in names]
    out += [
        ParameterEdit("exchange", a, b)
        for i, a in enumerate(names)
        for b in names[i + 1 :]
        if alike(a, b, kinds, values)
    ]
    out += [ParameterEdit("other", a, b) for a in names for b in every if alike(a, b, kinds, values)]
    out += [ParameterEdit("scale", n, factor=k) for k in LATER_SCALES for n in names]
    fixed = fixed_parameters(params)
    for name in names:
        dimension = KIND_DIMENSIONS.get(kinds[name])
        if dimension is None:
            continue
        products = [
            expr
            for _, expr in products_of(fixed, dimension)
            if len(expr.free_symbols) <= ADDED_FACTORS and expr != sp.Symbol(name)
        ]
        for expr in sorted(products, key=lambda e: (sp.Poly(e).total_degree(), str(e))):
            out += [ParameterEdit("add", name, term=expr), ParameterEdit("add", name, term=-expr)]
    return out[:EDITS]
