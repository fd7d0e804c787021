"""Right-hand sides ``fun(t, x)`` for scipy, one per dynamics engine, and their cost per call.

Engines (the generalized force is the problem's τ = B (u0 − K x) − D q̇ in every case):

==================  =========================================================================
engine              q̈
==================  =========================================================================
``closed_form``     the project's closed form as ``pendverify.simulation.dynamics`` evaluates it:
                    M(q)⁻¹ (τ − C(q, q̇) q̇ − H(q)) with numpy, model coordinates
``compiled``        the fast path's compiled closed form
                    (``pendverify.numerics.integrators.dop853_runner``), called from Python:
                    what is left is scipy's own overhead
``aba``             ``pinocchio.aba(q, v, τ)``
``crba_cholesky``   ``crba`` → ``cholesky.decompose`` → ``cholesky.solve(τ − rnea(q, v, 0))``
``minverse``        ``computeMinverse(q) @ (τ − rnea(q, v, 0))``
==================  =========================================================================

The Pinocchio engines integrate in Pinocchio's joint coordinates (q = T (θ − θ0),
v = T θ̇, ``pendverify.robot.coordinates``), as a user of Pinocchio would; states are
mapped back to the model's coordinates before they are compared.  The force law
is affine in the state, so it is mapped once: τ_q = G x_q + c with
G = T⁻ᵀ [−B K_θ T⁻¹, −(B K_θ̇ + D) T⁻¹] and c = T⁻ᵀ B (u0 − K_θ θ0).
"""

from __future__ import annotations

import timeit
from dataclasses import dataclass

import numpy as np

from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for
from pendverify.simulation.engine_names import PINOCCHIO_ENGINES


@dataclass
class EngineRhs:
    """A scipy right-hand side and the maps between its state and the model's."""

    engine: str
    fun: object  # fun(t, x) -> ẋ
    to_engine: object  # model state -> engine state
    to_model: object  # engine states (..., 2n) -> model states

    def per_call(self, x_model: np.ndarray, number: int = 500, repeat: int = 5) -> float:
        """Seconds per call at x (minimum over ``repeat`` batches of ``number`` calls)."""
        x = self.to_engine(np.asarray(x_model, float))
        fun = self.fun
        return min(timeit.repeat(lambda: fun(0.0, x), number=number, repeat=repeat)) / number


def _identity(x):
    return x


def closed_form_rhs(model, fast) -> EngineRhs:
    n = model.nv
    B, K, u0, D = fast.B, fast.K, fast.u0, fast.D
    forced = not fast.conservative

    def fun(t, x):
        q, v = x[:n], x[n:]
        tau = (B @ (u0 - K @ x) - D @ v) if forced else np.zeros(n)
        return np.concatenate([v, model.inverse_mass_matrix(q) @ (tau - model.bias(q, v))])

    return EngineRhs("closed_form", fun, _identity, _identity)


def compiled_rhs(fast) -> EngineRhs:
    return EngineRhs("compiled", fast.scipy_rhs(), _identity, _identity)


def pinocchio_rhs(engine: str, system, fast) -> EngineRhs:
    """``aba``, ``crba_cholesky`` or ``minverse`` on a ``PinocchioSystem`` (joint coordinates)."""
    import pinocchio as pin

    if engine not in PINOCCHIO_ENGINES:
        raise ValueError(
            f"unknown Pinocchio engine {engine!r}; expected one of {', '.join(PINOCCHIO_ENGINES)}"
        )
    cmap = system.cmap
    if any(nq != 1 for nq in cmap.joint_nq):
        raise ValueError("the engines integrate joint angles directly: continuous joints are not supported")
    m, d = system.model, system.data
    n = m.nv
    T, T_inv = cmap.T, np.linalg.inv(cmap.T)
    K_q, K_v = fast.K[:, :n], fast.K[:, n:]
    G = T_inv.T @ np.hstack([-fast.B @ K_q @ T_inv, -(fast.B @ K_v + fast.D) @ T_inv])
    c = T_inv.T @ fast.B @ (fast.u0 - K_q @ cmap.theta0)
    forced = not fast.conservative
    zero = np.zeros(n)

    def tau(x):
        return G @ x + c if forced else zero

    if engine == "aba":

        def fun(t, x):
            q, v = x[:n], x[n:]
            return np.concatenate([v, pin.aba(m, d, q, v, tau(x))])

    elif engine == "crba_cholesky":

        def fun(t, x):
            q, v = x[:n], x[n:]
            bias = pin.rnea(m, d, q, v, zero)
            pin.crba(m, d, q)
            pin.cholesky.decompose(m, d)
            return np.concatenate([v, pin.cholesky.solve(m, d, tau(x) - bias)])

    else:

        def fun(t, x):
            q, v = x[:n], x[n:]
            bias = pin.rnea(m, d, q, v, zero)
            return np.concatenate([v, pin.computeMinverse(m, d, q) @ (tau(x) - bias)])

    def to_engine(x):
        return np.concatenate([T @ (x[:n] - cmap.theta0), T @ x[n:]])

    def to_model(xs):
        xs = np.asarray(xs, float)
        return np.concatenate([xs[..., :n] @ T_inv.T + cmap.theta0, xs[..., n:] @ T_inv.T], axis=-1)

    return EngineRhs(engine, fun, to_engine, to_model)


def build(engine: str, model, fast, system=None) -> EngineRhs:
    """The right-hand side of ``engine`` for a closed-form model and its packed force law."""
    if engine == "closed_form":
        return closed_form_rhs(model, fast)
    if engine == "compiled":
        return compiled_rhs(fast)
    if system is None:
        system = PinocchioSystem.from_urdf(model.name, urdf_for(model.params), model.params.g)
    return pinocchio_rhs(engine, system, fast)
