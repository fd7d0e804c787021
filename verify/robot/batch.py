"""Pinocchio at every state of a batch, in a closed-form model's coordinates.

``PinocchioSystem``'s methods wrap each bare Pinocchio call (1–5 µs) in 15–35 µs of
Python: validating the state, mapping it to joint coordinates, mapping the result
back.  ``PinocchioBatch`` maps the whole batch at once with NumPy, calls each bare
function in one tight loop over the states with the system's own model and data,
and maps the stacked results back — the same NumPy calls on stacked arrays, which
NumPy carries out state by state with the same BLAS/LAPACK calls, so every number is
the bit-for-bit equal of the per-state method's.  Each quantity is computed once, when
first asked for.

A system that evaluates Pinocchio at other angles than it is given (the stress
catalogue's ``ReducedAngleSystem``) says so by ``pinocchio_batch_source() -> (system,
map of the angles)``; any other wrapper has no batch (``batch_source`` is None).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pendverify.robot.system import PinocchioSystem


def batch_source(system):
    """(the PinocchioSystem evaluated, the map applied to the angles or None), or None."""
    if type(system) is PinocchioSystem:
        return system, None
    hook = getattr(type(system), "pinocchio_batch_source", None)
    if hook is None:
        return None
    base, angles = hook(system)
    return (base, angles) if type(base) is PinocchioSystem else None


_symmetric = PinocchioSystem._symmetric  # Pinocchio fills only the upper triangle of M and M⁻¹


def _mv(A, x):
    return (A @ x[..., None])[..., 0]


class PinocchioBatch:
    """Pinocchio's quantities at states θ (N, n), θ̇ (N, n) of ``system``, in the model's coordinates."""

    def __init__(self, system, theta: np.ndarray, theta_dot: np.ndarray):
        source = batch_source(system)
        if source is None:
            raise TypeError(f"{type(system).__name__} has no batch evaluation")
        self.system, angles = source
        theta = np.asarray(theta, dtype=float)
        if angles is not None:
            theta = angles(theta)
        n = self.system.model.nv
        if theta.shape[-1:] != (n,) or theta_dot.shape != theta.shape:
            raise ValueError("states of the wrong size")
        if not (np.all(np.isfinite(theta)) and np.all(np.isfinite(theta_dot))):
            raise ValueError("a state that is not finite")  # the per-state methods say which
        cmap = self.system.cmap
        self.q = configurations(cmap, theta)
        self.v = np.ascontiguousarray(_mv(cmap.T, np.ascontiguousarray(theta_dot, dtype=float)))
        self.N = len(theta)
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
        n = self.system.model.nv
        return self._once("crba", lambda: self._loop(pin.crba, self.q, shape=(n, n)))

    # --- in the model's coordinates (as PinocchioSystem's methods) -----------------------
    def mass_matrix(self) -> np.ndarray:
        T = self.system.cmap.T
        return self._once("M", lambda: T.T @ _symmetric(self.crba_upper()) @ T)

    def det_mass_matrix(self) -> np.ndarray:
        return self._once(
            "det", lambda: np.linalg.det(_symmetric(self.crba_upper())) * self.system.cmap.det_factor
        )

    def inverse_mass_matrix(self) -> np.ndarray:
        def compute():
            n = self.system.model.nv
            Ti = self.system.cmap.T_inv
            return Ti @ _symmetric(self._loop(pin.computeMinverse, self.q, shape=(n, n))) @ Ti.T

        return self._once("Minv", compute)

    def bias(self) -> np.ndarray:
        def compute():
            zero = np.zeros(self.system.model.nv)
            tau = self._loop(lambda m, d, q, v: pin.rnea(m, d, q, v, zero), self.q, self.v)
            return _mv(self.system.cmap.T.T, tau)

        return self._once("bias", compute)

    def gravity(self) -> np.ndarray:
        return self._once(
            "H", lambda: _mv(self.system.cmap.T.T, self._loop(pin.computeGeneralizedGravity, self.q))
        )

    def coriolis_matrix(self) -> np.ndarray:
        def compute():
            n, T = self.system.model.nv, self.system.cmap.T
            return T.T @ self._loop(pin.computeCoriolisMatrix, self.q, self.v, shape=(n, n)) @ T

        return self._once("C", compute)

    def mass_matrix_derivative(self) -> np.ndarray:
        """Ṁ by Pinocchio's RNEA derivatives with gravity off (``PinocchioSystem.mass_matrix_derivative``)."""

        def compute():
            system = self.system
            m, d, n = system._no_gravity, system._no_gravity_data, system.model.nv
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
        """q̈ by ABA for generalized forces given in the model's coordinates (N, n)."""
        if not np.all(np.isfinite(tau_theta)):
            raise ValueError("a generalized force that is not finite")
        cmap = self.system.cmap
        tau = _mv(cmap.T_inv.T, np.ascontiguousarray(tau_theta, dtype=float))
        self.aba_torques = tau
        return _mv(cmap.T_inv, self._loop(pin.aba, self.q, self.v, tau))

    def kinetic_energy(self) -> np.ndarray:
        return self._once("KE", lambda: self._loop(pin.computeKineticEnergy, self.q, self.v, shape=()))

    def potential_energy(self) -> np.ndarray:
        return self._once("V", lambda: self._loop(pin.computePotentialEnergy, self.q, shape=()))


def configurations(cmap, theta: np.ndarray) -> np.ndarray:
    """Pinocchio's configuration at each state θ (N, n), as ``CoordinateMap.configuration`` one at a time."""
    positions = _mv(cmap.T, np.asarray(theta, dtype=float) - cmap.theta0)
    parts = []
    for k, nq in enumerate(cmap.joint_nq):
        angle = np.ascontiguousarray(positions[:, k])
        if nq == 1:
            parts.append(angle)
        else:  # np.cos of each number, as one state's map takes it (an array's SIMD loop may round otherwise)
            parts += [np.array([np.cos(x) for x in angle]), np.array([np.sin(x) for x in angle])]
    return np.ascontiguousarray(np.stack(parts, axis=-1))
