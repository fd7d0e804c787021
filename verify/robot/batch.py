"""Pinocchio at a batch of states, in a closed-form model's coordinates: the one evaluator.

``PinocchioBatch(system, θ, θ̇)`` maps the states (N, n) to Pinocchio's configurations
and velocities at once (``CoordinateMap``: q = T (θ − θ0), v = T θ̇; continuous joints as
(cos, sin)), calls each bare Pinocchio function in one tight loop over the states with the
system's own model and data, and maps the stacked results back:

    M_θ = Tᵀ M_q T,   C_θ = Tᵀ C_q T,   Ṁ_θ = Tᵀ Ṁ_q T,   τ_θ = Tᵀ τ_q,
    θ̈ = T⁻¹ q̈,   M_θ⁻¹ = T⁻¹ M_q⁻¹ T⁻ᵀ,   det M_θ = det(T)² det M_q.

Each quantity is computed once, when first asked for.  One state is the batch of one:
``PinocchioSystem``'s methods (``mass_matrix(θ)``, ``acceleration(θ, θ̇, τ)``, …) call this.
Pinocchio's C++ fills only the upper triangle of M and M⁻¹ (``symmetrised``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pendverify.validate import finite_state


def symmetrised(upper: np.ndarray) -> np.ndarray:
    """The symmetric matrix (or stack) whose upper triangle Pinocchio filled."""
    return np.triu(upper) + np.swapaxes(np.triu(upper, 1), -1, -2)


def _mv(A, x):
    return (A @ x[..., None])[..., 0]


def finite_rows(key: str, X, n: int, source: str) -> np.ndarray:
    """``X`` as (N, n) floats; the first row that is not finite, or not n long, raises
    ``finite_state``'s error naming ``key``."""
    X = np.asarray(X, dtype=float)
    if X.ndim != 2 or X.shape[1] != n or not np.all(np.isfinite(X)):
        rows = X.reshape(-1, X.shape[-1]) if X.ndim >= 1 and X.size else [X]
        for row in rows:
            finite_state(key, row, n, source)
        raise ValueError(f"{key}: states of shape {X.shape}, expected (N, {n})")
    return np.ascontiguousarray(X)


def configurations(cmap, theta: np.ndarray) -> np.ndarray:
    """Pinocchio's configuration at each state θ (N, n) (``CoordinateMap.configuration``, row by row)."""
    positions = np.ascontiguousarray(_mv(cmap.T, np.asarray(theta, dtype=float) - cmap.theta0))
    if all(nq == 1 for nq in cmap.joint_nq):
        return positions
    parts = []
    for k, nq in enumerate(cmap.joint_nq):
        angle = positions[:, k]
        parts += [angle] if nq == 1 else [np.cos(angle), np.sin(angle)]
    return np.ascontiguousarray(np.stack(parts, axis=-1))


class PinocchioBatch:
    """Pinocchio's quantities at states θ (N, n), θ̇ (N, n) of ``system``, in the model's coordinates.

    ``system`` is a ``PinocchioSystem`` (its Pinocchio model and data, the gravity-free copy
    for Ṁ, the coordinate map and the source named in errors); θ and θ̇ are finite (N, n)
    float arrays (``PinocchioSystem.at`` checks them).
    """

    def __init__(self, system, theta: np.ndarray, theta_dot: np.ndarray):
        self.system = system
        self.N = len(theta)
        self.q = configurations(system.cmap, theta)
        self.v = np.ascontiguousarray(_mv(system.cmap.T, theta_dot))
        self._cache: dict[str, object] = {}
        #: the joint torques of the last ``acceleration`` (what ``bench certify`` times ABA on)
        self.aba_torques: np.ndarray | None = None

    @property
    def computed(self) -> tuple[str, ...]:
        """The quantities computed so far (``crba``, ``M``, ``Minv``, ``bias``, ``H``, ``C``, ``Mdot``, …)."""
        return tuple(self._cache)

    def _once(self, name, compute):
        if name not in self._cache:
            self._cache[name] = compute()
        return self._cache[name]

    def _loop(self, f, *arrays, shape=None) -> np.ndarray:
        """f(model, data, *rows) at every state, stacked (the tight loop over bare Pinocchio calls)."""
        pm, data = self.system.model, self.system.data
        out = np.empty((self.N, *(shape if shape is not None else (pm.nv,))))
        if len(arrays) == 1:
            (a,) = arrays
            for i in range(self.N):
                out[i] = f(pm, data, a[i])
        else:
            for i, rows in enumerate(zip(*arrays, strict=True)):
                out[i] = f(pm, data, *rows)
        return out

    # --- joint-space quantities, each once ----------------------------------------------
    def crba_upper(self) -> np.ndarray:
        """CRBA's M in joint coordinates, upper triangle (N, n, n)."""
        n = self.system.model.nv
        return self._once("crba", lambda: self._loop(pin.crba, self.q, shape=(n, n)))

    # --- in the model's coordinates -------------------------------------------------------
    def mass_matrix(self) -> np.ndarray:
        """M(θ) by CRBA, symmetrised."""
        T = self.system.cmap.T
        return self._once("M", lambda: T.T @ symmetrised(self.crba_upper()) @ T)

    def det_mass_matrix(self) -> np.ndarray:
        """det of the CRBA matrix by LU (numpy), times det(T)²."""
        return self._once(
            "det", lambda: np.linalg.det(symmetrised(self.crba_upper())) * self.system.cmap.det_factor
        )

    def inverse_mass_matrix(self) -> np.ndarray:
        """M(θ)⁻¹ by computeMinverse, symmetrised."""

        def compute():
            n = self.system.model.nv
            Ti = self.system.cmap.T_inv
            return Ti @ symmetrised(self._loop(pin.computeMinverse, self.q, shape=(n, n))) @ Ti.T

        return self._once("Minv", compute)

    def bias(self) -> np.ndarray:
        """C(θ, θ̇)·θ̇ + H(θ) by RNEA at zero acceleration."""

        def compute():
            zero = np.zeros(self.system.model.nv)
            tau = self._loop(lambda m, d, q, v: pin.rnea(m, d, q, v, zero), self.q, self.v)
            return _mv(self.system.cmap.T.T, tau)

        return self._once("bias", compute)

    def gravity(self) -> np.ndarray:
        """H(θ) by computeGeneralizedGravity."""
        return self._once(
            "H", lambda: _mv(self.system.cmap.T.T, self._loop(pin.computeGeneralizedGravity, self.q))
        )

    def coriolis_matrix(self) -> np.ndarray:
        """Pinocchio's Coriolis matrix (computeCoriolisMatrix)."""

        def compute():
            n, T = self.system.model.nv, self.system.cmap.T
            return T.T @ self._loop(pin.computeCoriolisMatrix, self.q, self.v, shape=(n, n)) @ T

        return self._once("C", compute)

    def mass_matrix_derivative(self) -> np.ndarray:
        """Ṁ by Pinocchio's analytic RNEA derivatives, independent of its Coriolis matrix.

        With gravity off and q̇ = 0, τ(q, 0, a) = M(q) a, so ∂τ/∂q(q, 0, e_j)·q̇ = Ṁ e_j.
        """

        def compute():
            system = self.system
            m, d, n = system.model_without_gravity, system.data_without_gravity, system.model.nv
            zero, unit = np.zeros(n), [np.eye(n)[j].copy() for j in range(n)]
            dtau = np.empty((n, self.N, n, n))
            derivatives = pin.computeRNEADerivatives
            for i, q in enumerate(self.q):
                for j in range(n):
                    dtau[j, i] = derivatives(m, d, q, zero, unit[j])[0]
            columns = [_mv(dtau[j], self.v) for j in range(n)]
            T = system.cmap.T
            return T.T @ np.stack(columns, axis=-1) @ T

        return self._once("Mdot", compute)

    def acceleration(self, tau_theta: np.ndarray) -> np.ndarray:
        """θ̈ by ABA for generalized forces given in the model's coordinates (N, n)."""
        cmap = self.system.cmap
        tau_theta = finite_rows("tau", tau_theta, self.system.model.nv, self.system.source)
        tau = np.ascontiguousarray(_mv(cmap.T_inv.T, tau_theta))
        self.aba_torques = tau
        return _mv(cmap.T_inv, self._loop(pin.aba, self.q, self.v, tau))

    def kinetic_energy(self) -> np.ndarray:
        """T(θ, θ̇) by computeKineticEnergy."""
        return self._once("KE", lambda: self._loop(pin.computeKineticEnergy, self.q, self.v, shape=()))

    def potential_energy(self) -> np.ndarray:
        """V(θ) by computePotentialEnergy (Pinocchio's zero)."""
        return self._once("V", lambda: self._loop(pin.computePotentialEnergy, self.q, shape=()))
