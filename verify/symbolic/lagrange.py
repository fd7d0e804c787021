"""The equations of motion derived from energies with SymPy: a third opinion.

From the kinetic energy T(q, q̇), the potential energy V(q), the Rayleigh
dissipation function R(q̇) and the power P = (B u + W w)ᵀ q̇ of the inputs and
disturbances, Lagrange's equations

    d/dt ∂T/∂q̇ − ∂T/∂q + ∂V/∂q + ∂R/∂q̇ = ∂P/∂q̇

take the form M q̈ + C q̇ + H + D q̇ = B u + W w with

    M = ∂²T/∂q̇²                                   (T must be ½ q̇ᵀ M(q) q̇)
    C_kj = Σ_i Γ_kji q̇_i,  Γ_kji = ½ (∂M_kj/∂q_i + ∂M_ki/∂q_j − ∂M_ij/∂q_k)
    H = ∂V/∂q,   D = ∂²R/∂q̇²,   B = ∂²P/∂q̇∂u,   W = ∂²P/∂q̇∂w.

C is the Christoffel form, the one with Ṁ − 2C skew-symmetric.  Energies outside
this class (T with terms linear in q̇, R not a quadratic form, P not bilinear in
q̇ and (u, w)) are rejected with a message naming the model.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import sympy as sp

from pendverify.analytic.forms import Energies
from pendverify.analytic.source_file import where
from pendverify.errors import PendverifyError
from pendverify.symbolic.zero_test import canonical, is_zero

if TYPE_CHECKING:
    from pendverify.analytic.symbolic_reading import SymbolicModel


@dataclass
class Lagrangian:
    """The quantities derived from one model's energies."""

    M: sp.Matrix
    C: sp.Matrix
    H: sp.Matrix
    V: sp.Expr
    D: sp.Matrix
    B: sp.Matrix
    W: sp.Matrix

    def namespace(self, sm: SymbolicModel) -> dict:
        """Names for a closed form's ``equals`` expression."""
        return dict(
            M=self.M,
            C=self.C,
            H=self.H,
            V=self.V,
            D=self.D,
            B=self.B,
            W=self.W,
            q=sm.column("q"),
            v=sm.column("v"),
            u=sm.column("u"),
            w=sm.column("w"),
        )


def christoffel(M: sp.Matrix, q, v) -> sp.Matrix:
    """C(q, q̇) from the Christoffel symbols of the first kind of M(q)."""
    n = len(q)
    C = sp.zeros(n, n)
    for k in range(n):
        for j in range(n):
            C[k, j] = sum(
                (sp.diff(M[k, j], q[i]) + sp.diff(M[k, i], q[j]) - sp.diff(M[i, j], q[k])) * v[i] / 2
                for i in range(n)
            )
    return C


def mass_matrix_rate(M: sp.Matrix, q, v) -> sp.Matrix:
    """Ṁ = Σ_i ∂M/∂q_i q̇_i."""
    return sum((sp.diff(M, qi) * vi for qi, vi in zip(q, v, strict=True)), sp.zeros(*M.shape))


def energies_of(sm: SymbolicModel) -> Energies:
    """The model's energies, or a PendverifyError if it gives none."""
    try:
        energies = sm.model.energies(*sm.arguments("qvuw"))
    except Exception as exc:
        raise PendverifyError(
            f"{where(sm.cls)}: {sm.cls.__name__}.energies cannot be read by SymPy "
            f"({type(exc).__name__}: {exc})"
        ) from None
    if energies is None:
        raise PendverifyError(
            f"{where(sm.cls)}: {sm.cls.__name__} defines no energies(q, v, u, w); the SymPy comparison "
            "derives the equations from T, V, R and the input power"
        )
    if not isinstance(energies, Energies):
        raise PendverifyError(
            f"{where(sm.cls)}: {sm.cls.__name__}.energies must return an Energies, "
            f"got {type(energies).__name__}"
        )
    return energies


_CACHE: dict[tuple, Lagrangian] = {}


def derive(sm: SymbolicModel) -> Lagrangian:
    """M, C, H, V, D, B, W from the model's energies (module docstring).

    Cached on what the derivation depends on (the ``energies`` function, the
    parameter set and the names of coordinates, inputs and disturbances), so
    that subclasses which only change closed forms share it.
    """
    cls = sm.cls
    key = (cls.energies, cls.params_type, cls.coordinates, cls.angular, cls.inputs, cls.disturbances)
    if key not in _CACHE:
        _CACHE[key] = _derive(sm)
    return _CACHE[key]


def _derive(sm: SymbolicModel) -> Lagrangian:
    energies = energies_of(sm)
    q, v, u, w = (list(sm.symbols[k]) for k in "qvuw")
    n, angles = len(q), sm.angles
    T, V, R, P = (
        sp.sympify(x) for x in (energies.kinetic, energies.potential, energies.dissipation, energies.power)
    )

    def require(expr, what: str) -> None:
        if not is_zero(expr, angles):
            raise PendverifyError(f"{where(sm.cls)}: {sm.cls.__name__}.energies: {what}")

    M = sp.hessian(T, v).applyfunc(lambda e: canonical(e, angles))
    vv = sp.Matrix(v)
    require(T - (vv.T * M * vv)[0] / 2, "the kinetic energy is not a quadratic form ½ q̇ᵀ M(q) q̇")
    for x in v:
        require(V.diff(x), f"the potential energy depends on the rate {x}")
    D = sp.hessian(R, v) if R != 0 else sp.zeros(n, n)
    require(R - (vv.T * D * vv)[0] / 2, "the dissipation is not a quadratic form ½ q̇ᵀ D q̇")
    Q = sp.Matrix([P.diff(x) for x in v])
    require(P - (Q.T * vv)[0], "the input power is not linear in the rates")
    B = Q.jacobian(u) if u else sp.zeros(n, 0)
    W = Q.jacobian(w) if w else sp.zeros(n, 0)
    for entry in Q - B * sm.column("u") - W * sm.column("w"):
        require(entry, "the input power is not (B u + W w)ᵀ q̇")
    if (B.free_symbols | W.free_symbols) & set(q + v):
        raise PendverifyError(
            f"{where(sm.cls)}: {sm.cls.__name__}.energies: the input power gives B or W depending on the "
            "state; the interface's input_matrix and disturbance_matrix are constant"
        )
    return Lagrangian(
        M=M,
        C=christoffel(M, q, v).applyfunc(lambda e: canonical(e, angles)),
        H=sp.Matrix([V.diff(x) for x in q]),
        V=V,
        D=D,
        B=B,
        W=W,
    )
