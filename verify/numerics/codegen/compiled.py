"""The numba functions of a generated module: ``_rhs_t``, ``_rhs``, ``_hamilton`` and ``_to_momentum``.

``_rhs_t(P, t, x, out)``: ẋ = (q̇, q̈) at time t for x = (q, q̇[, W_in, W_diss]), M q̈ = τ − bias
by the unrolled LDLᵀ solve, τ = B (u0 − K x) − D q̇ + f(t) with f(t) the packed forcing (a
sum of sinusoids per channel, ``pendverify.numerics.generate``); with the work integrals,
dW_in/dt = q̇ᵀ (B u + f(t)), dW_diss/dt = q̇ᵀ D q̇.  ``_rhs(P, x, out)`` is ``_rhs_t`` at t = 0,
for the callers of an autonomous field.

``_hamilton(P, y, out)``: (q̇, ṗ) at y = (q, p), p = M(q) q̇ (the canonical momentum).
q̇ = M(q)⁻¹ p by the same LDLᵀ solve.  ṗ: differentiating p = M(q) q̇ along a solution,

    ṗ = Ṁ q̇ + M q̈ = Ṁ(q, q̇) q̇ − bias(q, q̇) + τ,   Ṁ q̇ = Σ_k q̇_k (∂M/∂q_k) q̇,

with the model's own bias = C(q, q̇) q̇ + H(q): the vector field is the model's
equations in other variables, whatever C is.  When C is Christoffel-consistent
(C q̇ = Ṁ q̇ − ½ ∂(q̇ᵀ M q̇)/∂q, i.e. Ṁ − 2C skew along q̇) and H = ∂V/∂q, this is
Hamilton's ṗ = −∂H/∂q + τ = ½ q̇ᵀ (∂M/∂q) q̇ − ∂V/∂q + τ; SymPy's ``expand``
cancels the shared terms (``expressions.momentum_rate``).

``_to_momentum(P, x, y)``: y = (q, M(q) q̇).

``_hamilton`` has no time argument: it leaves the forcing out (its only caller is the
fixed-step methods of ``fixedstep``, and ``fixedstep_runner.integrate_fixed`` refuses a
system with forcing).

All three read the packed array P (layout in ``pendverify.numerics.generate``).

Inlining.  The integrators copied into the module (``codegen.templates``) call ``_rhs_t`` and
``_rhs`` at several sites (DOP853 four, the fixed-step methods five); numba's ``inline="always"``
types and lowers the whole body again at each, so the compile time grows with body × sites, while
what inlining saves per evaluation (a call, and the stage arrays known apart) is fixed.  Measured
on one core (a 2-core VM, numba 0.68; first compilation of DOP853 and the fixed-step ``_run``,
then their runs, the same functions called instead of inlined):

===============  ==========  ========================  =======================
model            body lines  compile, inlined / called  run when called
===============  ==========  ========================  =======================
single pendulum  45          11.9 s / 9.2 s            +21–27 % (euler, rk4)
triple pendulum  109         16.6 s / 9.1 s            +11–13 % (dop853, rk4)
5-link chain     303         32.7 s / 11.9 s           +3–5 % (rk4, euler)
===============  ==========  ========================  =======================

Inlining pays for itself while the body is short: up to ``INLINE_LINES`` lines it is inlined, a
longer body is called (compiling in about a third of the time for a few per cent of run time).
"""

from __future__ import annotations

from pendverify.errors import PendverifyError
from pendverify.numerics.codegen.expressions import Expressions, momentum_rate
from pendverify.numerics.codegen.ldlt import ldlt_lines
from pendverify.numerics.codegen.printers import numba_printer

HEADER = 2  # P[0] = n, P[1] = nu
#: the longest ``_rhs_t`` body (lines) that is inlined at its call sites (module docstring)
INLINE_LINES = 200


def _reads(ex: Expressions, state: str, rates: bool) -> list[str]:
    """Parameters from P, coordinates from ``state``, and (if ``rates``) v from ``state[n:]``."""
    n = ex.n
    lines = [f"p{k} = P[{HEADER + k}]  # {name}" for k, name in enumerate(ex.parameters)]
    lines += [f"q{k} = {state}[{k}]  # {name}" for k, name in enumerate(ex.coordinates)]
    if rates:
        lines += [f"v{k} = {state}[{n + k}]  # d{name}" for k, name in enumerate(ex.coordinates)]
    return lines


def _tau(ex: Expressions) -> list[str]:
    """ti = B (u0 − K x), td = −D v (D n × n), from q0…, v0… (v must be known)."""
    n, od = ex.n, HEADER + len(ex.parameters)
    lines = ["nu = int(P[1])", f"ob = {od + n * n}", f"ok = ob + {n}*nu", f"ou = ok + {2 * n}*nu"]
    lines += ["# tau = B (u0 - K x) - D v"]
    lines += [f"ti{i} = 0.0" for i in range(n)]
    lines += ["for j in range(nu):", f"    k = ok + {2 * n}*j"]
    kx = " + ".join([f"P[k + {k}]*q{k}" for k in range(n)] + [f"P[k + {n + k}]*v{k}" for k in range(n)])
    lines += [f"    u = P[ou + j] - ({kx})"]
    lines += [f"    ti{i} += P[ob + {i}*nu + j]*u" for i in range(n)]
    lines += [
        f"td{i} = -(" + " + ".join(f"P[{od + n * i + j}]*v{j}" for j in range(n)) + ")" for i in range(n)
    ]
    return lines


def lower(n: int) -> list[tuple[int, int]]:
    return [(i, j) for i in range(n) for j in range(i + 1)]


def mass_lines(ex: Expressions, reduced, pr) -> tuple[list[str], list[list[bool]]]:
    """m{i}_{j} = … for M's non-zero lower entries (CSE'd), and the structural zeros."""
    n = ex.n
    zero = [[True] * n for _ in range(n)]
    lines = []
    for (i, j), e in zip(lower(n), reduced, strict=True):
        zero[i][j] = zero[j][i] = e == 0
        if e != 0:
            lines.append(f"m{i}_{j} = {pr.doprint(e)}")
    if any(zero[i][i] for i in range(n)):
        raise PendverifyError(f"{ex.name}: mass_matrix has a diagonal entry that is identically zero")
    return lines, zero


def split(replacements, late: set) -> tuple[list, list]:
    """CSE replacements in two groups, keeping their order: those that need none of ``late``
    (directly or through an earlier replacement), and the rest."""
    early, rest, tainted = [], [], set(late)
    for sym, expr in replacements:
        if expr.free_symbols & tainted:
            tainted.add(sym)
            rest.append((sym, expr))
        else:
            early.append((sym, expr))
    return early, rest


def _function(name: str, args: str, body: list[str], inline: bool) -> list[str]:
    extra = ', inline="always"' if inline else ""
    return [
        f'@njit(cache=True, error_model="numpy"{extra})',
        f"def {name}({args}):",
        *[f"    {b}" for b in body],
        "",
    ]


def _cse(exprs, prefix: str):
    import sympy as sp

    return sp.cse(exprs, symbols=sp.numbered_symbols(prefix), order="canonical")


def _forcing(ex: Expressions) -> list[str]:
    """ti += f(t): after u0, [channels] then per channel g (n), amplitude, m, m × (ω, φ), when packed."""
    n = ex.n
    lines = ["# forcing f(t) = sum over channels c of g_c a_c sum_k sin(w_ck t + phi_ck)", "oc = ou + nu"]
    lines += ["if P.shape[0] > oc:", "    o = oc + 1", "    for c in range(int(P[oc])):"]
    lines += [f"        m = int(P[o + {n + 1}])", "        s = 0.0", "        for k in range(m):"]
    lines += [f"            s += math.sin(P[o + {n + 2} + 2*k]*t + P[o + {n + 3} + 2*k])"]
    lines += [f"        s *= P[o + {n}]"] + [f"        ti{i} += P[o + {i}]*s" for i in range(n)]
    lines += [f"        o += {n + 2} + 2*m"]
    return lines


def render_rhs(ex: Expressions) -> list[str]:
    """``_rhs_t(P, t, x, out)`` and the autonomous ``_rhs(P, x, out)`` (t = 0)."""
    n, pr = ex.n, numba_printer()
    pairs = lower(n)
    replacements, reduced = _cse([ex.mass[i, j] for i, j in pairs] + list(ex.bias), "e")
    body = _reads(ex, "x", True) + _tau(ex) + _forcing(ex)
    body += ["# M (lower triangle) and the bias C(q, v) v + H(q)"]
    body += [f"{pr.doprint(s)} = {pr.doprint(e)}" for s, e in replacements]
    mass, zero = mass_lines(ex, reduced[: len(pairs)], pr)
    body += mass
    for i, e in enumerate(reduced[len(pairs) :]):
        body.append(f"f{i} = ti{i} + td{i}" + ("" if e == 0 else f" - ({pr.doprint(e)})"))
    body += ["# M a = f: M = L diag(d) L^T", *ldlt_lines(n, zero)]
    body += [f"out[{i}] = v{i}" for i in range(n)] + [f"out[{n + i}] = a{i}" for i in range(n)]
    body += [
        f"if x.shape[0] > {2 * n}:",
        f"    out[{2 * n}] = " + " + ".join(f"v{i}*ti{i}" for i in range(n)),
        f"    out[{2 * n + 1}] = -(" + " + ".join(f"v{i}*td{i}" for i in range(n)) + ")",
    ]
    inline = len(body) <= INLINE_LINES
    autonomous = _function("_rhs", "P, x, out", ["_rhs_t(P, 0.0, x, out)"], inline=inline)
    return [*_function("_rhs_t", "P, t, x, out", body, inline=inline), "", *autonomous]


def render_hamilton(ex: Expressions) -> list[str]:
    n, pr = ex.n, numba_printer()
    pairs = lower(n)
    rate = momentum_rate(ex)
    replacements, reduced = _cse([ex.mass[i, j] for i, j in pairs] + rate, "e")
    early, late = split(replacements, set(ex.v))
    body = _reads(ex, "y", False) + [f"mom{i} = y[{n + i}]" for i in range(n)]
    body += ["# M (lower triangle)"] + [f"{pr.doprint(s)} = {pr.doprint(e)}" for s, e in early]
    mass, zero = mass_lines(ex, reduced[: len(pairs)], pr)
    body += [*mass, "# v = M^-1 p: M = L diag(d) L^T", *ldlt_lines(n, zero, rhs="mom", out="v")]
    body += (
        _tau(ex) + ["# pdot = Mdot v - bias + tau"] + [f"{pr.doprint(s)} = {pr.doprint(e)}" for s, e in late]
    )
    body += [f"out[{i}] = v{i}" for i in range(n)]
    body += [
        f"out[{n + i}] = ti{i} + td{i}" + ("" if e == 0 else f" + ({pr.doprint(e)})")
        for i, e in enumerate(reduced[len(pairs) :])
    ]
    return _function("_hamilton", "P, y, out", body, inline=False)


def render_to_momentum(ex: Expressions) -> list[str]:
    n, pr = ex.n, numba_printer()
    pairs = lower(n)
    replacements, reduced = _cse([ex.mass[i, j] for i, j in pairs], "e")
    body = _reads(ex, "x", False) + [f"{pr.doprint(s)} = {pr.doprint(e)}" for s, e in replacements]
    mass, zero = mass_lines(ex, reduced, pr)
    body += mass + [f"y[{i}] = q{i}" for i in range(n)]
    for i in range(n):
        terms = [f"m{max(i, j)}_{min(i, j)}*x[{n + j}]" for j in range(n) if not zero[i][j]]
        body.append(f"y[{n + i}] = " + " + ".join(terms))
    return _function("_to_momentum", "P, x, y", body, inline=False)
