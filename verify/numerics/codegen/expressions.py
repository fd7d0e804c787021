"""The closed forms of a model class as SymPy expressions: M(q), the bias C(q, q̇)·q̇ + H(q), V(q)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from pendverify.errors import PendverifyError


@dataclass(frozen=True)
class Expressions:
    """M(q), the bias and V(q) of a model class, in SymPy (symbols renamed p0…, q0…, v0…)."""

    name: str
    coordinates: tuple[str, ...]
    angular: tuple[bool, ...]
    parameters: tuple[str, ...]  # field order of params_type
    q: tuple  # SymPy symbols q0 … q{n-1}
    v: tuple  # v0 … v{n-1}
    p: tuple  # p0 … p{n_p-1}
    mass: object  # sp.Matrix n × n
    bias: object  # sp.Matrix n × 1
    potential: object  # sp.Expr, or None when ``potential_energy`` cannot be read

    @property
    def n(self) -> int:
        return len(self.coordinates)


def expressions(model_cls) -> Expressions:
    """Read M, the bias and V of ``model_cls`` with ``SymbolicModel`` (a PendverifyError if it cannot)."""
    # deferred on purpose: SymPy loads only when a model is generated, not when its module is cached
    import sympy as sp

    from pendverify.analytic.source_file import where
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.symbolic.zero_test import is_zero

    sm = SymbolicModel.of(model_cls)
    n = len(model_cls.coordinates)
    mass, bias = sm.evaluate("mass_matrix", "q"), sm.evaluate("bias", "qv")
    if not isinstance(mass, sp.MatrixBase) or mass.shape != (n, n):
        raise PendverifyError(f"{where(model_cls)}: mass_matrix must return an {n} × {n} array")
    if not isinstance(bias, sp.MatrixBase) or bias.shape != (n, 1):
        raise PendverifyError(f"{where(model_cls)}: bias (C·q̇ + H) must return {n} entries")
    try:
        potential = sm.evaluate("potential_energy", "q")
    except PendverifyError:
        potential = None  # only the energy of the Taylor path needs it: it says so when asked
    if isinstance(potential, sp.MatrixBase):
        potential = potential[0] if potential.shape == (1, 1) else None
    q, v = sm.symbols["q"], sm.symbols["v"]
    p = tuple(sm.parameters[f.name] for f in dataclasses.fields(model_cls.params_type))
    allowed = set(q) | set(v) | set(p)
    for what, expr in (("mass_matrix", mass), ("bias", bias), ("potential_energy", potential)):
        stray = sorted(s.name for s in getattr(expr, "free_symbols", set()) - allowed)
        if stray and what == "potential_energy":
            potential = None
        elif stray:
            raise PendverifyError(f"{where(model_cls)}: {what} depends on {', '.join(stray)}")
    if mass.has(*v):
        raise PendverifyError(f"{where(model_cls)}: mass_matrix depends on the rates")
    if potential is not None and potential.has(*v):
        potential = None
    for i in range(n):
        for j in range(i):
            diff = mass[i, j] - mass[j, i]
            if sp.expand(diff) != 0 and not is_zero(diff, sm.angles):
                raise PendverifyError(
                    f"{where(model_cls)}: mass_matrix is not symmetric (entries {i},{j} and {j},{i})"
                )
    rename = {s: sp.Symbol(f"p{k}", real=True) for k, s in enumerate(p)}
    rename |= {s: sp.Symbol(f"q{k}", real=True) for k, s in enumerate(q)}
    rename |= {s: sp.Symbol(f"v{k}", real=True) for k, s in enumerate(v)}
    return Expressions(
        model_cls.name,
        tuple(model_cls.coordinates),
        tuple(bool(a) for a in model_cls.angular),
        tuple(f.name for f in dataclasses.fields(model_cls.params_type)),
        tuple(rename[s] for s in q),
        tuple(rename[s] for s in v),
        tuple(rename[s] for s in p),
        mass.xreplace(rename),
        bias.xreplace(rename),
        None if potential is None else sp.sympify(potential).xreplace(rename),
    )


def momentum_rate(ex: Expressions):
    """ṗ − τ = Ṁ(q, q̇) q̇ − bias(q, q̇), Ṁ q̇ = Σ_k q̇_k (∂M/∂q_k) q̇, each entry in its shorter form.

    ``sp.expand`` cancels the Christoffel terms the bias shares with Ṁ q̇ when the model's
    C is Christoffel-consistent (what is left is ½ q̇ᵀ ∂M/∂q q̇ − H); the unexpanded
    difference is kept when expanding makes an entry longer."""
    import sympy as sp

    n = ex.n
    out = []
    for i in range(n):
        mdot = sum(ex.v[k] * sp.diff(ex.mass[i, j], ex.q[k]) * ex.v[j] for j in range(n) for k in range(n))
        raw = mdot - ex.bias[i, 0]
        expanded = sp.expand(raw)
        out.append(expanded if sp.count_ops(expanded) <= sp.count_ops(raw) else raw)
    return out
