"""Names by convention: how a LaTeX model file's declared names are spelled in LaTeX.

A LaTeX model file declares its coordinates, inputs, disturbances and parameters; each
declared name is read in the LaTeX by convention, with no line in ``[symbols]``:

* a name of one letter is itself (``g``, ``m``, ``I``); a Greek letter's name is its
  command (``alpha`` ← ``\\alpha``, ``theta`` ← ``\\theta``);
* a letter or a Greek letter's name followed by more is that letter with the rest as its
  subscript: ``m1`` ← ``m_1`` (and ``m_{1}``), ``mc`` ← ``m_c``, ``x12`` ← ``x_{12}``,
  ``theta1`` ← ``\\theta_1``, ``m_p`` ← ``m_p``;
* the rate ``d<c>`` of a coordinate ``c`` is the dotted coordinate: ``dtheta1`` ←
  ``\\dot{\\theta}_1`` (also ``\\dot\\theta_1`` and ``\\dot{\\theta_1}``, which
  ``latex_normalise`` reads as the same symbol), ``dx`` ← ``\\dot{x}``;
* the acceleration of ``c`` is the double-dotted coordinate, ``\\ddot{\\theta}_1``: the
  symbol ``acceleration_symbol("theta1")`` (``ddtheta1``), which no key of the
  parts (M, C, H, …) may use and whole equations of motion do;
* Unicode is read as its command (``latex_normalise``): ``θ₁`` and ``θ_1`` as
  ``\\theta_1``, ``ẋ`` as ``\\dot{x}``.

Shorthands of the robotics literature (Underactuated Robotics writes ``s_{1+2}`` for
sin(θ1 + θ2)) are read when the coordinates carry one-digit indices, one coordinate per
index (``theta1``, ``theta2``; or ``q``, ``theta1``, ``theta2``): ``s_1`` = sin θ1,
``c_1`` = cos θ1, ``s_{12}`` = ``s_{1+2}`` = sin(θ1 + θ2) (three indices likewise),
``s_{1-2}`` = sin(θ1 − θ2), and the same with ``c``.

The ``[symbols]`` table wins over every convention (a key that reads as the same symbol
replaces the convention's reading), a declared name's spelling wins over a shorthand
(a parameter ``c1`` is ``c_1``, never cos θ1), and a spelling two names would share
(parameters ``m1`` and ``m_1``) is not a convention at all.  ``pendverify show`` lists
the conventions a file's equations used.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass

import sympy as sp

from pendverify.analytic.latex_normalise import canonical_symbol

GREEK = (
    "alpha beta gamma delta epsilon varepsilon zeta eta theta vartheta iota kappa lambda mu nu xi "
    "pi varpi rho varrho sigma varsigma tau upsilon phi varphi chi psi omega "
    "Gamma Delta Theta Lambda Xi Pi Sigma Upsilon Phi Psi Omega"
).split()
_GREEK_LONGEST_FIRST = sorted(GREEK, key=len, reverse=True)


def acceleration_symbol(coordinate: str) -> sp.Symbol:
    """The symbol of a coordinate's acceleration in a LaTeX model (``\\ddot{\\theta}_1`` → ``ddtheta1``)."""
    return sp.Symbol(f"dd{coordinate}", real=True)


@dataclass(frozen=True)
class Convention:
    """One LaTeX spelling read by convention: its canonical LaTeX and what it reads as."""

    latex: str
    value: sp.Expr

    def __str__(self) -> str:
        return f"{self.latex} → {sp.sstr(self.value)}"


def _split(name: str) -> tuple[str, str] | None:
    """(the LaTeX of the name's letter, its subscript), or None for a name of one letter."""
    for greek in _GREEK_LONGEST_FIRST:
        if name.startswith(greek):
            return "\\" + greek, name[len(greek) :].lstrip("_")
    if name[0].isalpha() and name[0].isascii():
        return name[0], name[1:].lstrip("_")
    return None


def spellings(name: str) -> list[str]:
    """The LaTeX spellings (canonical) of a declared name (module docstring)."""
    split = _split(name)
    if split is None:
        return []
    letter, rest = split
    if not rest:
        return [canonical_symbol(letter)]
    if not rest.isalnum():
        return []
    return [canonical_symbol(f"{letter}_{{{rest}}}")]


def _dotted(spelling: str, dots: str) -> str:
    letter, _, sub = spelling.partition("_")
    return canonical_symbol(f"\\{dots}{{{letter}}}" + (f"_{sub}" if sub else ""))


def conventions(
    coordinates: tuple[str, ...], names: tuple[str, ...], symbols: dict[str, sp.Expr]
) -> dict[str, Convention]:
    """Every LaTeX spelling the convention reads, canonical LaTeX → ``Convention``.

    ``coordinates`` in order, ``names`` every other declared name (inputs, disturbances,
    parameters), ``symbols`` each model name (rates included) → its SymPy symbol.
    """
    found: dict[str, list[sp.Expr]] = {}
    for name in (*coordinates, *names):
        for spelling in spellings(name):
            found.setdefault(spelling, []).append(symbols[name])
            if name in coordinates:
                found.setdefault(_dotted(spelling, "dot"), []).append(symbols["d" + name])
                found.setdefault(_dotted(spelling, "ddot"), []).append(acceleration_symbol(name))
    out = {k: Convention(k, v[0]) for k, v in found.items() if len(v) == 1}
    for latex, value in _shorthands(coordinates, symbols).items():
        if latex not in found:
            out[latex] = Convention(latex, value)
    return out


def _shorthands(coordinates: tuple[str, ...], symbols: dict[str, sp.Expr]) -> dict[str, sp.Expr]:
    """``s_1``, ``c_{12}``, ``s_{1+2}``, ``c_{1-2}`` … over coordinates with one-digit indices."""
    by_index: dict[str, list[str]] = {}
    for c in coordinates:
        m = re.fullmatch(r"[^\W\d_]+_?(\d)", c)
        if m:
            by_index.setdefault(m.group(1), []).append(c)
    index = {k: symbols[v[0]] for k, v in sorted(by_index.items()) if len(v) == 1}
    out: dict[str, sp.Expr] = {}
    for f, fn in (("s", sp.sin), ("c", sp.cos)):
        for i, angle in index.items():
            out[f"{f}_{i}"] = fn(angle)
        for size in (2, 3):
            for group in itertools.combinations(index, size):
                angle = sp.Add(*(index[k] for k in group))
                out[f"{f}_{{{''.join(group)}}}"] = fn(angle)
                out[f"{f}_{{{'+'.join(group)}}}"] = fn(angle)
        for i, j in itertools.permutations(index, 2):
            out[f"{f}_{{{i}-{j}}}"] = fn(index[i] - index[j])
    return out


__all__ = ["GREEK", "Convention", "acceleration_symbol", "conventions", "spellings"]
