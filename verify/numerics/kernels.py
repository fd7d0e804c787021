"""The closed forms compiled: right-hand sides for numba kernels, and the packed system they read.

``_rhs(P, x, out)`` writes ẋ for x = (q, q̇[, W_in, W_diss]) in the *model's*
coordinates (``double_pendulum``: θ1 from the horizontal, θ2 relative; cart: q
and absolute angles from upright), under the generalized force

    τ = B (u0 − K x) − D q̇,

which covers every time-invariant scene: conservative (K = 0, D = 0), joint
friction (diagonal D), PD control (B = I, K = [kp kd], u0 = kp·target), LQR
about upright (B = e_q, K the gain), a constant input (K = 0).  With the two
work integrals in the state, dW_in/dt = q̇ᵀ B u and dW_diss/dt = q̇ᵀ D q̇, as in
``pendverify.simulation.dynamics``.

Equations: the double pendulum with the seed's constants α, β, δ and
G1 = g (m1 r1 + m2 l1), G2 = g m2 r2 (``pendverify.analytic.double_pendulum``),

    q̈ = adj M (τ − C q̇ − H) / det M,   det M = α δ − δ² − β² cos² θ2;

the cart with the seed's f(y, ẏ) and det M and the adjugate of M
(``pendverify.analytic.cart_double_pendulum``).  One function per model with
literal sizes, so numba keeps every quantity in registers, and inlined into the
steppers (``inline="always"``: 35 % less time per evaluation here, for a few
seconds more compilation).  ``FastSystem``
packs the constants and the force law; the tests check ``_rhs`` against the
models' own closed forms at ε level.
"""

from __future__ import annotations

import hashlib
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from pendverify.errors import InputError

MODEL_IDS = {"double_pendulum": 0, "cart_double_pendulum": 1}


def source_stamp() -> str:
    """A hash of this file: the kernels compiled into other modules' cached code."""
    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()[:16]


def cache_allowed(stamp: str, module: str) -> bool:
    """Whether ``module``, which inlines these kernels, may use numba's on-disk cache.

    numba checks only a cached function's own file, so a module compiled with an
    older version of this file would keep running it.  Each such module records
    the stamp of the kernels it was written for; on a mismatch it compiles
    afresh every session (correct, only slower) and this warns.
    """
    if stamp == source_stamp():
        return True
    warnings.warn(
        f"pendverify.numerics.kernels changed: set the kernels stamp in {module} to {source_stamp()!r} "
        "to re-enable numba's cache",
        stacklevel=2,
    )
    return False


class FastPathError(InputError):
    """A scene uses an effect the fast path does not compile."""


# --- right-hand sides ---------------------------------------------------------------------
# The kernels take one packed float array P (``FastSystem.packed``), not a tuple of
# arrays: each array argument costs reference counting on every call, which here
# would be several times the dynamics itself.
#
#   P[0] model id, P[1] n, P[2] nu, P[3:9] constants, P[9:12] D,
#   then B (n × nu, row-major), K (nu × 2n), u0 (nu).
C0, D0, B0 = 3, 9, 12  # offsets of the constants, of D and of B in P


@njit(cache=True, error_model="numpy", inline="always")
def _dp_tau(P, q0, q1, v0, v1):
    """(τ_in, τ_diss) of the double pendulum: B (u0 − K x) and −D q̇."""
    nu = int(P[2])
    ok = B0 + 2 * nu
    ou = ok + 4 * nu
    ti0 = ti1 = 0.0
    for j in range(nu):
        k = ok + 4 * j
        u = P[ou + j] - (P[k] * q0 + P[k + 1] * q1 + P[k + 2] * v0 + P[k + 3] * v1)
        ti0 += P[B0 + j] * u
        ti1 += P[B0 + nu + j] * u
    return ti0, ti1, -P[D0] * v0, -P[D0 + 1] * v1


@njit(cache=True, error_model="numpy", inline="always")
def _cart_tau(P, q0, q1, q2, v0, v1, v2):
    """(τ_in, τ_diss) of the cart: B (u0 − K x) and −D ẏ (absolute rates)."""
    nu = int(P[2])
    ok = B0 + 3 * nu
    ou = ok + 6 * nu
    ti0 = ti1 = ti2 = 0.0
    for j in range(nu):
        k = ok + 6 * j
        u = P[ou + j] - (
            P[k] * q0 + P[k + 1] * q1 + P[k + 2] * q2 + P[k + 3] * v0 + P[k + 4] * v1 + P[k + 5] * v2
        )
        ti0 += P[B0 + j] * u
        ti1 += P[B0 + nu + j] * u
        ti2 += P[B0 + 2 * nu + j] * u
    return ti0, ti1, ti2, -P[D0] * v0, -P[D0 + 1] * v1, -P[D0 + 2] * v2


@njit(cache=True, error_model="numpy", inline="always")
def _dp_rhs(P, x, out):
    w1, w2 = x[2], x[3]
    ti0, ti1, td0, td1 = _dp_tau(P, x[0], x[1], w1, w2)
    a, b, d, g1, g2 = P[C0], P[C0 + 1], P[C0 + 2], P[C0 + 3], P[C0 + 4]
    s2, c2 = math.sin(x[1]), math.cos(x[1])
    c1, c12 = math.cos(x[0]), math.cos(x[0] + x[1])
    r1 = ti0 + td0 + b * s2 * (2.0 * w1 * w2 + w2 * w2) - (g1 * c1 + g2 * c12)
    r2 = ti1 + td1 - b * s2 * w1 * w1 - g2 * c12
    m12 = d + b * c2
    det = a * d - d * d - (b * c2) * (b * c2)
    out[0] = w1
    out[1] = w2
    out[2] = (d * r1 - m12 * r2) / det
    out[3] = (-m12 * r1 + (a + 2.0 * b * c2) * r2) / det
    if x.shape[0] > 4:
        out[4] = w1 * ti0 + w2 * ti1
        out[5] = -(w1 * td0 + w2 * td1)


@njit(cache=True, error_model="numpy", inline="always")
def _cart_mass(P, c1, c2, c12):
    """The six distinct entries of the cart's M(y) (cos θ1, cos θ2, cos(θ1 − θ2) given)."""
    m, m1, m2, l1, l2 = P[C0], P[C0 + 1], P[C0 + 2], P[C0 + 3], P[C0 + 4]
    m12 = m1 + m2
    return m + m12, l1 * m12 * c1, m2 * l2 * c2, l1 * l1 * m12, l1 * l2 * m2 * c12, l2 * l2 * m2


@njit(cache=True, error_model="numpy", inline="always")
def _cart_solve(P, s1, c1, c2, s12, c12, f0, f1, f2):
    """M(y)⁻¹ f by the adjugate and the seed's det M."""
    m, m1, m2, l1, l2 = P[C0], P[C0 + 1], P[C0 + 2], P[C0 + 3], P[C0 + 4]
    m12 = m1 + m2
    p00, p01, p02, p11, p12, p22 = _cart_mass(P, c1, c2, c12)
    a00, a01, a02 = p11 * p22 - p12 * p12, p02 * p12 - p01 * p22, p01 * p12 - p02 * p11
    a11, a12, a22 = p00 * p22 - p02 * p02, p01 * p02 - p00 * p12, p00 * p11 - p01 * p01
    det = l1 * l1 * l2 * l2 * m2 * (m * m1 + m1 * m12 * s1 * s1 + m * m2 * s12 * s12)
    return (
        (a00 * f0 + a01 * f1 + a02 * f2) / det,
        (a01 * f0 + a11 * f1 + a12 * f2) / det,
        (a02 * f0 + a12 * f1 + a22 * f2) / det,
    )


@njit(cache=True, error_model="numpy", inline="always")
def _cart_rhs(P, x, out):
    w0, w1, w2 = x[3], x[4], x[5]
    ti0, ti1, ti2, td0, td1, td2 = _cart_tau(P, x[0], x[1], x[2], w0, w1, w2)
    m1, m2, l1, l2, g = P[C0 + 1], P[C0 + 2], P[C0 + 3], P[C0 + 4], P[C0 + 5]
    m12, k = m1 + m2, l1 * l2 * m2
    s1, c1 = math.sin(x[1]), math.cos(x[1])
    s2, c2 = math.sin(x[2]), math.cos(x[2])
    s12, c12 = math.sin(x[1] - x[2]), math.cos(x[1] - x[2])
    f0 = l1 * m12 * w1 * w1 * s1 + m2 * l2 * w2 * w2 * s2 + ti0 + td0
    f1 = -k * w2 * w2 * s12 + g * m12 * l1 * s1 + ti1 + td1
    f2 = k * w1 * w1 * s12 + g * m2 * l2 * s2 + ti2 + td2
    a0, a1, a2 = _cart_solve(P, s1, c1, c2, s12, c12, f0, f1, f2)
    out[0] = w0
    out[1] = w1
    out[2] = w2
    out[3] = a0
    out[4] = a1
    out[5] = a2
    if x.shape[0] > 6:
        out[6] = w0 * ti0 + w1 * ti1 + w2 * ti2
        out[7] = -(w0 * td0 + w1 * td1 + w2 * td2)


@njit(cache=True, error_model="numpy", inline="always")
def _rhs(P, x, out):
    """ẋ into ``out``; x = (q, q̇) or (q, q̇, W_in, W_diss), model coordinates."""
    if P[0] == 0.0:
        _dp_rhs(P, x, out)
    else:
        _cart_rhs(P, x, out)


# --- the packed system ---------------------------------------------------------------
@dataclass(frozen=True)
class FastSystem:
    """A closed-form model and a time-invariant force law τ = B (u0 − K x) − D q̇, packed."""

    model: str
    constants: np.ndarray  # dp: α, β, δ, G1, G2 [SI]; cart: m, m1, m2, l1, l2, g
    D: np.ndarray  # (n,) viscous friction per coordinate
    B: np.ndarray  # (n, nu) input map
    K: np.ndarray  # (nu, 2n) state feedback
    u0: np.ndarray  # (nu,) feed-forward input

    @property
    def nv(self) -> int:
        return self.D.shape[0]

    @property
    def conservative(self) -> bool:
        return not (np.any(self.D) or np.any(self.K) or np.any(self.u0))

    def packed(self) -> np.ndarray:
        """The one array the kernels take (layout above ``C0``)."""
        n, nu = self.nv, self.B.shape[1]
        head = np.zeros(B0)
        head[0], head[1], head[2] = MODEL_IDS[self.model], n, nu
        head[C0 : C0 + self.constants.size] = self.constants
        head[D0 : D0 + n] = self.D
        return np.concatenate([head, self.B.ravel(), self.K.ravel(), self.u0])

    @classmethod
    def from_model(cls, model, D=None, B=None, K=None, u0=None) -> FastSystem:
        """Pack a ``ClosedFormModel`` with its parameter set's g; no forces unless given."""
        p, n = model.params, model.nv
        if model.name == "double_pendulum":
            c = [model.alpha, model.beta, model.delta, p.g * (p.m1 * p.r1 + p.m2 * p.l1), p.g * p.m2 * p.r2]
        elif model.name == "cart_double_pendulum":
            c = [p.m, p.m1, p.m2, p.l1, p.l2, p.g]
        else:
            raise FastPathError("<fast path>", "model", model.name, f"one of {', '.join(MODEL_IDS)}")
        B = np.zeros((n, 0)) if B is None else np.asarray(B, float).reshape(n, -1)
        nu = B.shape[1]
        K = np.zeros((nu, 2 * n)) if K is None else np.asarray(K, float).reshape(nu, 2 * n)
        u0 = np.zeros(nu) if u0 is None else np.asarray(u0, float).reshape(nu)
        D = np.zeros(n) if D is None else np.asarray(D, float).reshape(n)
        return cls(
            model.name, np.array(c, dtype=float), D, np.ascontiguousarray(B), np.ascontiguousarray(K), u0
        )

    @classmethod
    def from_dynamics(cls, dyn, source: str = "<fast path>") -> FastSystem:
        """The force law of a built scene (``simulation.dynamics.Dynamics``), or a FastPathError."""
        n = dyn.nv
        if dyn.w_of is not None:
            raise FastPathError(source, "effects.disturbance", dyn.w_of.kind, "not compiled: time-varying")
        D = None
        if dyn.D is not None:
            D = np.diag(dyn.D)
            if np.any(dyn.D - np.diag(D)):
                raise FastPathError(source, "effects.damping", dyn.D.tolist(), "a diagonal D")
        B = K = u0 = None
        law = dyn.u_of
        if law is not None:
            B = dyn.model.input_matrix()
            if law.kind == "constant":
                u0 = law.value
            elif law.kind == "pd":
                K = np.hstack([np.diag(law.kp), np.diag(law.kd)])
                u0 = law.kp * law.target
            elif law.kind == "lqr" and law.saturation is None:
                K, u0 = law.K, np.zeros(B.shape[1])
            else:
                raise FastPathError(
                    source,
                    "effects.actuation",
                    law.kind,
                    "compiled laws are constant, pd and lqr without saturation (u affine in x)",
                )
            K = np.zeros((B.shape[1], 2 * n)) if K is None else K
        return cls.from_model(dyn.model, D, B, K, u0)

    # --- evaluations -----------------------------------------------------------------
    def rhs(self, x: np.ndarray) -> np.ndarray:
        out = np.empty_like(x, dtype=float)
        _rhs(self.packed(), np.asarray(x, float), out)
        return out

    def scipy_rhs(self):
        """fun(t, x) for ``solve_ivp`` calling the compiled right-hand side."""
        P = self.packed()

        def fun(t, x):
            out = np.empty(x.shape[0])
            _rhs(P, x, out)
            return out

        return fun
