"""The plain-Python part of a generated module: ``field``, ``energy`` and ``potential``.

They are generic over the number type — float, numpy arrays, ``mpmath.mpf``,
``Decimal`` and the Taylor ``Series`` of ``pendverify.numerics.integrators.taylor`` — so the
high-precision references and the mpmath energies run the model's own closed forms:

    field(p, x, N, sincos)    ẋ = (q̇, M(q)⁻¹ (τ − bias(q, q̇))) as a list,
    energy(p, x, N, sincos)   E = ½ q̇ᵀ M(q) q̇ + V(q),  V from the model's ``potential_energy``,
    potential(p, q, N, sincos)  V(q),
    mass(p, q, N, sincos)       M(q) as a list of rows,

``p`` the system's numbers in the caller's type (``{"params", "D", "B", "K",
"u0"}``, ``pendverify.numerics.integrators.taylor.exact_system``), ``N`` that type's constructor
and ``sincos(u)`` the pair (sin u, cos u) in it.  Only +, −, ×, ÷ and one ``sincos``
per distinct trigonometric argument are used: every sin/cos argument of the
expressions is collected, ``s_k, c_k = sincos(arg_k)`` computed once, and the
symbols substituted before ``sympy.cse``; tan becomes s/c.  Numbers are exact in
the caller's type (``printers.generic_printer``).  M q̇ = f is solved by the same
LDLᵀ as the compiled code.  τ = B (u0 − K x) − D q̇ is ``_force``, copied here, which
skips the zero entries (exact for any type).

A model whose closed forms use another function (sqrt, exp, abs…) gets
``FIELD_ERROR`` (or ``ENERGY_ERROR``, also when V cannot be read) instead of the
function: the compiled back ends do not need these, and the Taylor path raises it
as a ``PendverifyError`` when asked.  ``FIELD_DIGEST`` is the SHA-256 of this part
of the source: what a reference solution depends on (``reference.problem_key``); ``mass``,
which no reference solution reads (the 50-digit M of ``pendverify.stress.trust_study`` does),
follows it, outside the digest, and is left out with the field.
"""

from __future__ import annotations

import hashlib
import inspect
from typing import TYPE_CHECKING

from pendverify.numerics.codegen.compiled import lower
from pendverify.numerics.codegen.ldlt import ldlt_lines
from pendverify.numerics.codegen.printers import Unsupported, generic_printer

if TYPE_CHECKING:
    from pendverify.numerics.codegen.expressions import Expressions


def _force(p, x, n):
    """τ = B (u0 − K x) − D q̇ with zero entries skipped (exact constants, any number type, D n × n)."""
    B, K, u0, D = p["B"], p["K"], p["u0"], p["D"]
    tau = [0] * n
    for j in range(len(u0)):
        u = u0[j]
        for k in range(2 * n):
            if K[j][k] != 0:
                u = u - K[j][k] * x[k]
        for i in range(n):
            if B[i][j] != 0:
                tau[i] = tau[i] + B[i][j] * u
    for i in range(n):
        for j in range(n):
            if D[i][j] != 0:
                tau[i] = tau[i] - D[i][j] * x[n + j]
    return tau


def trig_symbols(exprs):
    """(exprs with sin/cos/tan of each distinct argument replaced by s_k, c_k, [(s_k, c_k, arg_k)])."""
    import sympy as sp

    exprs = [sp.sympify(e).replace(sp.tan, lambda a: sp.sin(a) / sp.cos(a)) for e in exprs]
    args = sorted({f.args[0] for e in exprs for f in e.atoms(sp.sin, sp.cos)}, key=sp.default_sort_key)
    pairs = [(sp.Symbol(f"s{k}", real=True), sp.Symbol(f"c{k}", real=True), a) for k, a in enumerate(args)]
    table = {}
    for s, c, a in pairs:
        table[sp.sin(a)], table[sp.cos(a)] = s, c
    return [e.xreplace(table) for e in exprs], pairs


def _body(ex: Expressions, exprs, state: str, rates: bool):
    """Reads, sincos lines and CSE'd assignments for ``exprs``; returns (lines, reduced)."""
    import sympy as sp

    pr, n = generic_printer(), ex.n
    exprs, pairs = trig_symbols(exprs)
    lines = (
        [f"{', '.join(str(s) for s in ex.p)}{',' if len(ex.p) == 1 else ''} = p['params']"] if ex.p else []
    )
    lines += [f"q{k} = {state}[{k}]" for k in range(n)]
    if rates:
        lines += [f"v{k} = {state}[{n + k}]" for k in range(n)]
    lines += [f"{s}, {c} = sincos({pr.doprint(a)})" for s, c, a in pairs]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("e"), order="canonical")
    lines += [f"{s} = {pr.doprint(e)}" for s, e in replacements]
    return lines, reduced, pr


def _function(name: str, args: str, doc: str, body: list[str]) -> list[str]:
    return [f"def {name}({args}):", f'    """{doc}"""', *[f"    {b}" for b in body], ""]


def _field(ex: Expressions) -> list[str]:
    n, pairs = ex.n, lower(ex.n)
    body, reduced, pr = _body(ex, [ex.mass[i, j] for i, j in pairs] + list(ex.bias), "x", True)
    zero = [[True] * n for _ in range(n)]
    for (i, j), e in zip(pairs, reduced[: len(pairs)], strict=True):
        zero[i][j] = zero[j][i] = e == 0
        if e != 0:
            body.append(f"m{i}_{j} = {pr.doprint(e)}")
    body.append(f"tau = _force(p, x, {n})")
    for i, e in enumerate(reduced[len(pairs) :]):
        body.append(f"f{i} = tau[{i}]" + ("" if e == 0 else f" - ({pr.doprint(e)})"))
    body += ldlt_lines(n, zero, one="1")
    body.append("return [" + ", ".join([f"v{i}" for i in range(n)] + [f"a{i}" for i in range(n)]) + "]")
    return _function(
        "field", "p, x, N, sincos", "ẋ = (q̇, M⁻¹ (τ − C q̇ − H)) in the caller's number type.", body
    )


def _mass(ex: Expressions) -> list[str]:
    n, pairs = ex.n, lower(ex.n)
    body, reduced, pr = _body(ex, [ex.mass[i, j] for i, j in pairs], "q", False)
    entry = {pair: pr.doprint(e) for pair, e in zip(pairs, reduced, strict=True)}
    rows = ["[" + ", ".join(entry[max(i, j), min(i, j)] for j in range(n)) + "]" for i in range(n)]
    body.append("return [" + ", ".join(rows) + "]")
    return _function("mass", "p, q, N, sincos", "M(q) in the caller's number type, row by row.", body)


def _energy(ex: Expressions) -> list[str]:
    import sympy as sp

    n, v, M = ex.n, ex.v, ex.mass
    twice_kinetic = sum(M[i, i] * v[i] ** 2 for i in range(n)) + 2 * sum(
        M[i, j] * v[i] * v[j] for i in range(n) for j in range(i)
    )
    body, (kin2, pot), pr = _body(ex, [twice_kinetic, ex.potential], "x", True)
    body.append(f"return ({pr.doprint(kin2)})/2 + ({pr.doprint(pot)})")
    energy = _function("energy", "p, x, N, sincos", "E = ½ q̇ᵀ M q̇ + V(q) in the caller's number type.", body)
    body, (pot,), pr = _body(ex, [ex.potential], "q", False)
    body.append(f"return {pr.doprint(sp.sympify(pot))}")
    return energy + _function("potential", "p, q, N, sincos", "V(q) in the caller's number type.", body)


def render_generic(ex: Expressions) -> str:
    """The generic part of the module (see the module docstring), FIELD_DIGEST first."""
    chunks, field_error, energy_error, mass = [], "", "", ""
    try:
        chunks.append("\n".join(_field(ex)))
        mass = "\n".join(_mass(ex))
    except Unsupported as exc:
        field_error = (
            f"its closed forms use {exc}: the Taylor path evaluates + − × ÷, integer powers, sin, cos"
        )
    if ex.potential is None:
        energy_error = "potential_energy cannot be read as an expression in q"
    else:
        try:
            chunks.append("\n".join(_energy(ex)))
        except Unsupported as exc:
            energy_error = (
                f"its energy uses {exc}: the Taylor path evaluates + − × ÷, integer powers, sin, cos"
            )
    body = "\n".join(
        [
            f"FIELD_ERROR = {field_error!r}",
            f"ENERGY_ERROR = {energy_error!r}",
            "",
            "",
            inspect.getsource(_force),
            "",
            *chunks,
        ]
    )
    digest = hashlib.sha256(body.encode()).hexdigest()
    head = "# --- generic over the number type (plain Python) ---\n" + f"FIELD_DIGEST = {digest!r}\n"
    return head + body + ("\n\n" + mass if mass else "")
