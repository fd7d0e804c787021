"""LQR for the cart about its upright equilibrium, linearised two ways.

State x = (q, θ1, θ2, q̇, θ̇1, θ̇2) (absolute angles, as the seed), input u the
cart force; x = 0, u = 0 is an equilibrium (both rods upright).  The linear
model ẋ ≈ A x + B u is computed

* from Pinocchio: ``computeABADerivatives`` at the equilibrium gives ∂q̈/∂q,
  ∂q̈/∂v and ∂q̈/∂τ = M⁻¹ in joint coordinates; with τ_q = T⁻ᵀ (B_u u − D θ̇)
  the map to the seed's coordinates is
      ∂θ̈/∂θ = T⁻¹ (∂q̈/∂q) T,   ∂θ̈/∂θ̇ = T⁻¹ ((∂q̈/∂v) T − M⁻¹ T⁻ᵀ D),   ∂θ̈/∂u = T⁻¹ M⁻¹ T⁻ᵀ B_u;
* from the closed form: at rest upright the velocity terms of f are quadratic
  and vanish to first order, so ∂θ̈/∂θ = M(0)⁻¹ G, ∂θ̈/∂θ̇ = −M(0)⁻¹ D and
  ∂θ̈/∂u = M(0)⁻¹ B_u, with G = ∂f/∂θ = diag(0, g (m1+m2) l1, g m2 l2).

The two must agree to rounding; the gain K = R⁻¹ Bᵀ P solves the continuous
algebraic Riccati equation (scipy) for the closed-form pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import scipy.linalg

from pendverify.analytic import CartDoublePendulum


@dataclass(frozen=True)
class Linearisation:
    A: np.ndarray
    B: np.ndarray


def _state_space(d_theta: np.ndarray, d_thetadot: np.ndarray, d_u: np.ndarray) -> Linearisation:
    n = d_theta.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [d_theta, d_thetadot]])
    B = np.vstack([np.zeros((n, d_u.shape[1])), d_u])
    return Linearisation(A, B)


def closed_form_linearisation(model: CartDoublePendulum, D: np.ndarray) -> Linearisation:
    p = model.params
    M0_inv = model.inverse_mass_matrix(np.zeros(3))
    G = np.diag([0.0, p.g * (p.m1 + p.m2) * p.l1, p.g * p.m2 * p.l2])
    return _state_space(M0_inv @ G, -M0_inv @ D, M0_inv @ model.input_matrix())


def pinocchio_linearisation(system, model: CartDoublePendulum, D: np.ndarray) -> Linearisation:
    cmap = system.cmap
    q = cmap.configuration(np.zeros(3))
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
