"""The shape of a difference: hand − Pinocchio of one entry over the states, as a short formula.

The difference d(s) of an entry over the judged states is fitted by a few functions of the
basis its quantity allows:

* M, H, V, D, det M: functions of q alone — 1, and sin and cos of each angle, of twice
  each angle, and of the sums and differences of two and of three angles (the arguments
  a closed form of a chain of revolute joints is built from; det M brings the doubled
  angles through cos²); for many angles, at most ``MAX_ARGUMENTS`` arguments: those of three
  angles go first, then those of two (a count bound on the basis, which grows as n³);
* C: those, and those times each rate q̇k (C is linear in q̇, and a friction inside C
  is a constant);
* C·q̇: those times each rate q̇k and each product q̇j·q̇k.

M⁻¹ and q̈ are rational in the trigonometric functions and have no short basis; they are
not fitted.  The fit is greedy (orthogonal matching pursuit: the basis function most
correlated with what is left, then a least-squares fit on all chosen ones), at most
``MAX_TERMS`` functions, and it stops when the relative residual ‖d − fit‖/‖d‖ is at
most ``PATTERN_RESIDUAL``.  A difference made of k of the basis functions, sampled at more
states than k, is recovered with a residual at rounding level: d is computed from values
of size |hand| + |Pinocchio| with a rounding of a few ε of them, so the residual of an exact
fit is a few ε·(|hand| + |Pinocchio|)/|d| — 1e-9 covers differences down to ~1e-6 of the
entry's size (smaller ones are not fitted: the report gives the entry, not a shape).
"""

from __future__ import annotations

import functools
import itertools
import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from pendverify.diagnosis.entries import EntryDifference
from pendverify.diagnosis.finding import Finding

MAX_TERMS = 6
PATTERN_RESIDUAL = 1e-9
#: a coefficient's uncertainty is this many times what the fit's residual moves it by: the noise of
#: d in the fitted functions' span is of the size of the residual (the part outside it), per
#: dimension, so the coefficient of function k moves by about ‖r‖·‖row k of A_S⁺‖; 10 covers
#: the few chosen dimensions and a residual below its mean
COEFFICIENT_SAFETY = 10.0
#: a fitted coefficient below this fraction of the largest is rounding, not a term
NEGLIGIBLE = 1e-9
FITTED = ("M", "H", "V", "D", "detM", "C", "Cqdot")


@dataclass(frozen=True)
class Pattern:
    """A fitted shape: ``terms`` as (coefficient, basis function's name), and the relative residual."""

    terms: tuple[tuple[float, str], ...]
    residual: float
    #: each term's basis function as a SymPy expression over the model's names
    functions: tuple = ()
    #: each coefficient's uncertainty (absolute): how far it may be from the exact coefficient of
    #: the difference (``COEFFICIENT_SAFETY`` times the residual through the fit's pseudo-inverse)
    uncertainties: tuple = ()

    def formula(self, written=None) -> str:
        """The fit as a formula; ``written``: per term, its coefficient's magnitude in words (a product
        of parameters, ``pendverify.diagnosis.monomials``) or None to print the number."""
        if not self.terms:
            return "0"
        out = ""
        for k, (c, name) in enumerate(self.terms):
            sign = "−" if c < 0 else "+"
            number = written[k] if written and written[k] else f"{abs(c):.6g}"
            magnitude = number if name == "1" else f"{number}·{name}"
            out += f" {sign} {magnitude}" if out else (f"−{magnitude}" if c < 0 else magnitude)
        return out

    def kind(self) -> str:
        if [n for _, n in self.terms] == ["1"]:
            return "constant"
        return f"{len(self.terms)} term{'s' if len(self.terms) > 1 else ''}"


#: the most trigonometric arguments a basis holds: sums and differences of three angles are left
#: out beyond it, then those of two (n angles give 2n + 2·C(n, 2) + 4·C(n, 3) arguments: 590 for
#: 10 angles, 42 720 for 40, each a basis column at every state and a SymPy expression)
MAX_ARGUMENTS = 2500


def _group_count(n: int, size: int) -> int:
    return math.comb(n, size) * 2 ** (size - 1)


def _arguments(Q, angular, names):
    """(name, values, SymPy expression) of the trigonometric arguments of the basis, at most
    ``MAX_ARGUMENTS`` of them (module docstring)."""
    idx = [i for i, a in enumerate(angular) if a]
    symbols = {i: _symbol(names[i]) for i in idx}
    out = [(names[i], Q[:, i], symbols[i]) for i in idx]
    out += [(f"2·{names[i]}", 2 * Q[:, i], 2 * symbols[i]) for i in idx]
    count = len(out)
    for size in (2, 3):
        count += _group_count(len(idx), size)
        if count > MAX_ARGUMENTS:
            break
        for group in itertools.combinations(idx, size):
            for signs in itertools.product((1, -1), repeat=size - 1):
                values = Q[:, group[0]].copy()
                text, expr = names[group[0]], symbols[group[0]]
                for s, j in zip(signs, group[1:], strict=True):
                    values = values + s * Q[:, j]
                    text += f" {'+' if s > 0 else '−'} {names[j]}"
                    expr = expr + s * symbols[j]
                out.append((text, values, expr))
    return out


def _symbol(name: str) -> sp.Symbol:
    return sp.Symbol(name, real=True)  # as pendverify.analytic.symbolic_reading names them


def position_basis(Q, angular, names) -> list[tuple[str, np.ndarray, sp.Expr]]:
    """(name, values at the states Q, its SymPy expression when called) of 1 and sin, cos of every
    argument; the expressions are made for the functions a fit keeps only (SymPy's sin of a sum
    takes milliseconds, and a basis holds thousands)."""
    basis = [("1", np.ones(len(Q)), _one)]
    for text, values, argument in _arguments(Q, angular, names):
        basis.append((f"sin({text})", np.sin(values), functools.partial(sp.sin, argument)))
        basis.append((f"cos({text})", np.cos(values), functools.partial(sp.cos, argument)))
    return basis


def _one():
    return sp.S.One


def basis_for(quantity: str, Q, V, angular, names) -> list[tuple[str, np.ndarray, sp.Expr]]:
    """The basis a quantity's entries allow (module docstring), each function with its expression."""
    position = position_basis(Q, angular, names)
    if quantity in ("M", "H", "V", "D", "detM"):
        return position
    rates = [(f"d{n}", V[:, k], _symbol(f"d{n}")) for k, n in enumerate(names)]
    linear = [
        (r if p == "1" else f"{r}·{p}", rv * pv, functools.partial(_times, (rs,), ps))
        for r, rv, rs in rates
        for p, pv, ps in position
    ]
    if quantity == "C":
        return position + linear
    products = []
    for (a, av, a_s), (b, bv, b_s) in itertools.combinations_with_replacement(rates, 2):
        product = f"{a}²" if a == b else f"{a}·{b}"
        for p, pv, ps in position:
            products.append(
                (
                    product if p == "1" else f"{product}·{p}",
                    av * bv * pv,
                    functools.partial(_times, (a_s, b_s), ps),
                )
            )
    return linear + products


def _times(factors, function):
    """The product of ``factors`` and ``function()``: a basis function's expression, made when asked."""
    out = function()
    for f in factors:
        out = f * out
    return out


def fit(d, basis) -> Pattern | None:
    """The sparse fit of d by the basis (module docstring), or None when none is close enough."""
    norm = float(np.linalg.norm(d))
    if not np.isfinite(norm) or norm == 0:
        return None
    A = np.column_stack([b[1] for b in basis])
    scale = np.linalg.norm(A, axis=0)
    usable = scale > 0
    unit = np.where(usable, A / np.where(usable, scale, 1.0), 0.0)
    chosen: list[int] = []
    residual, coeff = d.copy(), np.zeros(0)
    for _ in range(min(MAX_TERMS, len(d) - 1)):
        k = int(np.argmax(np.abs(unit.T @ residual)))
        if k in chosen:
            break
        chosen.append(k)
        coeff, *_ = np.linalg.lstsq(A[:, chosen], d, rcond=None)
        residual = d - A[:, chosen] @ coeff
        if np.linalg.norm(residual) <= PATTERN_RESIDUAL * norm:
            break
    relative = float(np.linalg.norm(residual) / norm)
    if relative > PATTERN_RESIDUAL:
        return None
    largest = float(np.max(np.abs(coeff)))
    moved = (
        COEFFICIENT_SAFETY
        * float(np.linalg.norm(residual))
        * np.linalg.norm(np.linalg.pinv(A[:, chosen]), axis=1)
    )
    found = sorted(zip(coeff, chosen, moved, strict=True), key=lambda ckm: ckm[1])
    kept = [(float(c), k, float(m)) for c, k, m in found if abs(c) > NEGLIGIBLE * largest]
    return Pattern(
        tuple((c, basis[k][0]) for c, k, _ in kept),
        relative,
        tuple(basis[k][2]() for _, k, _ in kept),
        tuple(m for _, _, m in kept),
    )


def entry_pattern(entry: EntryDifference, batch) -> Pattern | None:
    """The shape of one entry's difference hand − Pinocchio over the judged states, if it has one."""
    if entry.quantity not in FITTED:
        return None
    Q, V = batch.Q[entry.states], batch.V[entry.states]
    model = batch.model
    basis = basis_for(entry.quantity, Q, V, model.angular, model.coordinates)
    with np.errstate(all="ignore"):
        return fit(entry.hand - entry.pin, basis)


def pattern_finding(entry: EntryDifference, pattern: Pattern, coordinates, written=None) -> Finding:
    """The ``pattern`` finding: ``M[2,2]: hand − Pinocchio = 0.0416 (constant, residual 3e-16)``;
    ``written``: per term, its coefficient as a product of parameters, or None (``Pattern.formula``)."""
    label = entry.label(coordinates).split(" (")[0]
    message = (
        f"{label}: hand − Pinocchio = {pattern.formula(written)} ({pattern.kind()}, "
        f"residual {pattern.residual:.1g})"
    )
    details = {"terms": [[c, name] for c, name in pattern.terms], "residual": pattern.residual}
    if written and any(written):
        details["coefficients"] = list(written)
    return Finding("pattern", message, entry.quantity, tuple(i + 1 for i in entry.index), details)
