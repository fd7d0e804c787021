"""The one place where a model's coordinates meet Pinocchio's joint coordinates.

A hand model uses coordinates θ (absolute or relative angles, any zero, any
sign); Pinocchio uses joint coordinates q.  They are related affinely,

    q = T (θ − θ0),       v = T θ̇,

with T constant and invertible.  Power is invariant (τ_pinᵀ v = τᵀ θ̇), which
fixes every other transform:

    M_θ   = Tᵀ M_q T          C_θ = Tᵀ C_q T          Ṁ_θ = Tᵀ Ṁ_q T
    τ_θ   = Tᵀ τ_q            τ_q = T⁻ᵀ τ_θ           (bias, gravity, forces)
    q̈     = T θ̈               θ̈  = T⁻¹ q̈
    M_θ⁻¹ = T⁻¹ M_q⁻¹ T⁻ᵀ     det M_θ = det(T)² det M_q

Example: the cart reference system's absolute angles against Pinocchio's chain, whose second
revolute joint measures θ2 − θ1:  T = [[1, 0, 0], [0, 1, 0], [0, −1, 1]].

Continuous (unbounded) joints take two configuration entries (cos φ, sin φ) in
Pinocchio; ``configuration`` writes them from the angle.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class CoordinateMap:
    T: np.ndarray
    theta0: np.ndarray
    #: Configuration entries per joint: 1 (angle or position) or 2 (cos, sin).
    joint_nq: tuple[int, ...]
    #: T⁻¹, computed once from T.
    T_inv: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        T = np.asarray(self.T, dtype=float)
        if T.ndim != 2 or T.shape[0] != T.shape[1] or abs(np.linalg.det(T)) < 1e-12:
            raise ValueError(f"T must be square and invertible, got {T!r}")
        object.__setattr__(self, "T", T)
        object.__setattr__(self, "theta0", np.asarray(self.theta0, dtype=float))
        object.__setattr__(self, "T_inv", np.linalg.inv(T))

    # --- states ------------------------------------------------------------------------
    def joint_positions(self, theta: np.ndarray) -> np.ndarray:
        """Joint angles/positions q = T (θ − θ0), one per joint."""
        return self.T @ (np.asarray(theta, dtype=float) - self.theta0)

    def configuration(self, theta: np.ndarray) -> np.ndarray:
        """Pinocchio's configuration vector (cos, sin for continuous joints)."""
        parts = []
        for angle, nq in zip(self.joint_positions(theta), self.joint_nq, strict=True):
            parts.append([angle] if nq == 1 else [np.cos(angle), np.sin(angle)])
        return np.concatenate(parts)

    def velocity(self, theta_dot: np.ndarray) -> np.ndarray:
        return self.T @ theta_dot

    # --- quantities --------------------------------------------------------------------
    def matrix_to_model(self, A_q: np.ndarray) -> np.ndarray:
        """M, C or Ṁ: Tᵀ A T."""
        return self.T.T @ A_q @ self.T

    def force_to_model(self, tau_q: np.ndarray) -> np.ndarray:
        return self.T.T @ tau_q

    def force_to_joints(self, tau_theta: np.ndarray) -> np.ndarray:
        return self.T_inv.T @ tau_theta

    def acceleration_to_model(self, a_q: np.ndarray) -> np.ndarray:
        return self.T_inv @ a_q

    def inverse_to_model(self, Minv_q: np.ndarray) -> np.ndarray:
        return self.T_inv @ Minv_q @ self.T_inv.T

    @property
    def amplification(self) -> float:
        """cond₂(T)²: how much the congruence Tᵀ·A·T can magnify rounding done in joint coordinates.

        1 for maps that only shift or flip angles; ((1 + √5)/2)⁴ ≈ 6.85 for the
        cart's relative second joint.
        """
        return float(np.linalg.cond(self.T)) ** 2

    @property
    def det_factor(self) -> float:
        """det M_θ / det M_q = det(T)²."""
        return float(np.linalg.det(self.T)) ** 2
