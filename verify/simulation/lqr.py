"""LQR about an equilibrium of any model with inputs, linearised two ways.

State x = (q − q*, q̇) in the model's coordinates, input u; q* is one of the model's
``special_states()`` (the scene's ``equilibrium``, default "upright": for the cart
both rods upright, q* = 0) and must be an equilibrium, H(q*) ≈ 0
(``pendverify.simulation.effects.equilibrium_tolerance``).  The linear model
ẋ ≈ A x + B u is computed

* from Pinocchio: ``computeABADerivatives`` at the equilibrium gives ∂q̈/∂q,
  ∂q̈/∂v and ∂q̈/∂τ = M⁻¹ in joint coordinates; with τ_q = T⁻ᵀ (B_u u − D θ̇)
  the map to the model's coordinates is
      ∂θ̈/∂θ = T⁻¹ (∂q̈/∂q) T,   ∂θ̈/∂θ̇ = T⁻¹ ((∂q̈/∂v) T − M⁻¹ T⁻ᵀ D),   ∂θ̈/∂u = T⁻¹ M⁻¹ T⁻ᵀ B_u;
* from the closed form: at rest the velocity terms C(q, q̇) q̇ are quadratic and
  vanish to first order, and ∂M⁻¹/∂q multiplies H(q*) ≈ 0, so
  ∂θ̈/∂θ = −M(q*)⁻¹ ∂H/∂q(q*), ∂θ̈/∂θ̇ = −M(q*)⁻¹ D and ∂θ̈/∂u = M(q*)⁻¹ B_u.
  ∂H/∂q is the complex-step derivative of the model's own ``gravity`` (exact to
  rounding: Im H(q + i h e_j) / h with h = 1e-20), evaluated with ``self.math`` set
  to ``cmath``'s functions; a model whose closed form does not carry complex
  numbers gets central differences instead (error ≈ ε^(2/3), reported as the
  linearisation difference).  For the cart, −∂H/∂q = diag(0, g (m1+m2) l1, g m2 l2).

The two must agree to rounding; the gain K = R⁻¹ Bᵀ P solves the continuous
algebraic Riccati equation (scipy) for the closed-form pair.
"""

from __future__ import annotations

import cmath
import copy
import types
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import scipy.linalg

from pendverify.analytic import ClosedFormModel

COMPLEX_STEP = 1e-20
COMPLEX_MATH = types.SimpleNamespace(
    cos=cmath.cos, sin=cmath.sin, tan=cmath.tan, sqrt=cmath.sqrt, exp=cmath.exp, pi=cmath.pi
)


@dataclass(frozen=True)
class Linearisation:
    A: np.ndarray
    B: np.ndarray


def _state_space(d_theta: np.ndarray, d_thetadot: np.ndarray, d_u: np.ndarray) -> Linearisation:
    n = d_theta.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [d_theta, d_thetadot]])
    B = np.vstack([np.zeros((n, d_u.shape[1])), d_u])
    return Linearisation(A, B)


def gravity_jacobian(model: ClosedFormModel, q_star: np.ndarray) -> np.ndarray:
    """∂H/∂q at q*: complex step through the model's own ``gravity``, else central differences."""
    n = model.nv
    try:
        shadow = copy.copy(model)
        shadow.math = COMPLEX_MATH
        columns = []
        for j in range(n):
            z = q_star.astype(complex)
            z[j] += 1j * COMPLEX_STEP
            H = np.asarray(shadow.gravity(z))
            if not np.iscomplexobj(H):
                raise TypeError("gravity dropped the imaginary part")
            columns.append(H.imag.astype(float) / COMPLEX_STEP)
        return np.column_stack(columns)
    except (TypeError, ValueError, AttributeError):
        columns = []
        for j in range(n):
            h = np.cbrt(np.finfo(float).eps) * (1.0 + abs(q_star[j]))
            e = np.zeros(n)
            e[j] = h
            columns.append((model.gravity(q_star + e) - model.gravity(q_star - e)) / (2 * h))
        return np.column_stack(columns)


def closed_form_linearisation(model: ClosedFormModel, D: np.ndarray, q_star: np.ndarray) -> Linearisation:
    M_inv = model.inverse_mass_matrix(q_star)
    G = -gravity_jacobian(model, q_star)
    return _state_space(M_inv @ G, -M_inv @ D, M_inv @ model.input_matrix())


def pinocchio_linearisation(
    system, model: ClosedFormModel, D: np.ndarray, q_star: np.ndarray
) -> Linearisation:
    cmap = system.cmap
    q = cmap.configuration(q_star)
    v = np.zeros(system.model.nv)
    ddq_dq, ddq_dv, Minv = pin.computeABADerivatives(
        system.model, system.data, q, v, np.zeros(system.model.nv)
    )
    Minv = np.triu(Minv) + np.triu(Minv, 1).T
    T, T_inv = cmap.T, np.linalg.inv(cmap.T)
    d_theta = T_inv @ ddq_dq @ T
    d_thetadot = T_inv @ (ddq_dv @ T - Minv @ T_inv.T @ D)
    d_u = T_inv @ Minv @ T_inv.T @ model.input_matrix()
    return _state_space(d_theta, d_thetadot, d_u)


def linearisation_error(a: Linearisation, b: Linearisation) -> float:
    """max |difference| / max |entry|, over A and B."""
    scale = max(np.max(np.abs(a.A)), np.max(np.abs(a.B)))
    return max(np.max(np.abs(a.A - b.A)), np.max(np.abs(a.B - b.B))) / scale


def lqr_gain(lin: Linearisation, Q: np.ndarray, R: np.ndarray) -> np.ndarray:
    P = scipy.linalg.solve_continuous_are(lin.A, lin.B, Q, R)
    return np.linalg.solve(R, lin.B.T @ P)
