"""A fitted coefficient written as a product of the parameters: −7.848 as −2·g·l1·m2.

The shape of a difference (``pendverify.diagnosis.patterns``) has numeric coefficients.  Each is
matched against q·p1^a1·…·pk^ak, a small fraction q (``candidates.FRACTIONS``: 1, 2, 3, 4, ½, ⅓,
…, 1/12) times a product of at most ``DEGREE`` parameter values, and written so when exactly one
such product fits:

* **Units first.** Only products with the coefficient's physical dimension are tried, so that a
  parameter worth 1 (m1 = 1 kg) or two lengths in ratio 2 do not make every product fit.  The
  entry's own unit is the units check's (``pendverify.checks.dimensions.required``: with
  L_i = m for a prismatic coordinate and 1 for an angle and E = kg·m²/s², M[i,j] is
  E·s²/(L_i·L_j), H[i] is E/L_i, ...); a coefficient's is that over the rates its basis function
  holds (q̇_k is L_k/s): a C[i,j] term c·q̇_k·f(q) has c = E·s²/(L_i·L_j·L_k), a C·q̇[i] term
  c·q̇_j·q̇_k·f(q) has c = E·s²/(L_i·L_j·L_k).  Parameters of a kind without a fixed unit (damping, or none
  declared) are not used; neither is a term that has no fixed-unit reading (a constant in C, a
  friction term of C·q̇): it keeps its number.
* **Exactly.** A product fits when |q·v − |c|| is within the coefficient's uncertainty
  (``Pattern.uncertainties``: the residual of the fit carried through its pseudo-inverse, so a
  badly conditioned fit gets a wide window) or ``FLOOR`` relative (the rounding of a product of
  ``DEGREE`` floats and of the fitted number, a few ε, with margin).
* **Unambiguous.** When two different products fit (l1 = 2·r1 makes 2·g·l1·m2 and 4·g·m2·r1
  the same number), the number is kept: the values cannot say which one the model holds.
"""

from __future__ import annotations

import dataclasses
import functools
from fractions import Fraction

import numpy as np
import sympy as sp

from pendverify.checks.dimensions import LENGTH, NONE, SECOND, inverse, mul, power, required
from pendverify.diagnosis.candidates import DIMENSIONS, FRACTIONS, NUMBER_DENOMINATOR, parameter_products

DEGREE = 4
FLOOR = 1e-12


def fixed_parameters(params) -> tuple[tuple[str, float, tuple], ...]:
    """(name, value, dimension) of each parameter whose kind has a fixed unit and whose value is > 0."""
    out = []
    if not dataclasses.is_dataclass(params):  # a parameter set without declared kinds: no units to go by
        return ()
    for f in dataclasses.fields(params):
        kind = f.metadata.get("kind", "")
        value = getattr(params, f.name, None)
        if kind in DIMENSIONS and isinstance(value, (int, float)) and np.isfinite(value) and value > 0:
            out.append((f.name, float(value), DIMENSIONS[kind]))
    return tuple(out)


@functools.lru_cache(maxsize=64)
def products_of(parameters: tuple, dimension: tuple) -> tuple[tuple[float, sp.Expr], ...]:
    """(value, expression) of every product of at most ``DEGREE`` parameters with ``dimension``."""
    symbols = tuple(sp.Symbol(name) for name, _, _ in parameters)
    values = tuple(value for _, value, _ in parameters)
    return tuple(
        (value, expr)
        for value, expr, combo in parameter_products(symbols, values, DEGREE)
        if tuple(int(x) for x in np.sum([parameters[i][2] for i in combo], axis=0)) == dimension
    )


#: the quantity of an entry → (its method, the number of rates a basis function of its difference has)
_METHODS = {
    "M": ("mass_matrix", 0),
    "H": ("gravity", 0),
    "V": ("potential_energy", 0),
    "detM": ("det_mass_matrix", 0),
    "C": ("coriolis_matrix", 1),
    "Cqdot": ("coriolis_force", 2),
}


def coefficient_dimension(quantity: str, index: tuple[int, ...], function, model) -> tuple | None:
    """The physical dimension (kg, m, s) of the coefficient of basis ``function`` in an entry of
    ``quantity`` at ``index`` (0-based): the entry's own (``pendverify.checks.dimensions.required``)
    over the rates in ``function`` (a rate of coordinate k is q_k/s); None when it has no fixed
    unit (module docstring)."""
    if quantity not in _METHODS:
        return None
    method, rates_expected = _METHODS[quantity]
    angular = tuple(bool(a) for a in model.angular)
    need, _ = required(method, tuple(index), angular)
    rates = {f"d{c}": k for k, c in enumerate(model.coordinates)}
    function = sp.sympify(function)
    powers = function.as_powers_dict()  # a rate's exponent in the basis function (dθ1² → 2)
    count = [(rates[s.name], int(powers.get(s, 1))) for s in function.free_symbols if s.name in rates]
    if need is None or sum(p for _, p in count) != rates_expected:
        return None
    out = need
    for k, p in count:
        rate = mul(NONE if angular[k] else LENGTH, inverse(SECOND))
        out = mul(out, inverse(power(rate, Fraction(p))))
    if any(x.denominator != 1 for x in out):
        return None
    return tuple(int(x) for x in out)


def written_coefficient(c: float, uncertainty: float, dimension: tuple, parameters: tuple) -> str | None:
    """|c| as "q·p1·p2…" when exactly one product of the parameters fits it (module docstring)."""
    window = max(uncertainty, FLOOR * abs(c))
    fits = set()
    for value, expr in products_of(parameters, dimension):
        quotient = abs(c) / value
        if not np.isfinite(quotient):  # (a coefficient of 1e300: no product of these values)
            continue
        ratio = Fraction(quotient).limit_denominator(NUMBER_DENOMINATOR)
        if ratio in FRACTIONS and abs(float(ratio) * value - abs(c)) <= window:
            fits.add(sp.Rational(ratio.numerator, ratio.denominator) * expr)
    if len(fits) != 1:
        return None
    text = str(fits.pop())
    for exponent, superscript in (("**2", "²"), ("**3", "³"), ("**4", "⁴")):
        text = text.replace(exponent, superscript)
    return text.replace("*", "·")


def coefficient_words(pattern, entry, model) -> list[str | None]:
    """Per term of ``pattern`` (the difference of ``entry``), its coefficient's magnitude as a product of
    ``model``'s parameters, or None to keep the number (module docstring)."""
    parameters = fixed_parameters(model.params)
    out = []
    for (c, _), function, uncertainty in zip(
        pattern.terms, pattern.functions, pattern.uncertainties, strict=True
    ):
        dimension = coefficient_dimension(entry.quantity, entry.index, function, model)
        out.append(None if dimension is None else written_coefficient(c, uncertainty, dimension, parameters))
    return out
