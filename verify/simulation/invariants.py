"""Physics invariants checked after every run, with bounds derived from the integrator.

With E = T + V and the work integrals W_in = ∫ q̇ᵀ (B u + W w) dt and
W_diss = ∫ q̇ᵀ D q̇ dt carried in the integrated state, the balance residual

    r(t) = E(t) − E(0) − W_in(t) + W_diss(t)

is exactly conserved (dr/dt = 0) by the true flow.  Which invariant applies
follows from the scene's effects:

* conservative (no damping, actuation or disturbance): r = E(t) − E(0), the
  energy drift;
* damping only: E never increases, and r = E(t) − E(0) + ∫ q̇ᵀ D q̇ dt;
* actuation or disturbance: the work–energy balance r = 0.

Bound on r.  Because the exact flow conserves r, the error committed in one
step, δx, changes r by ∇r·δx and is never undone or amplified, so
|r(t_k)| ≤ Σ_{j≤k} |∇r(x_j)|·|δx_j|.  An adaptive method keeps the RMS of
δx_i / (atol + rtol |x_i|) below one, hence |δx_i| ≤ √N (atol + rtol |x_i|);
SAFETY covers the error estimator being an estimate, and a rounding term
ROUNDING·ε·E_scale per step covers floating point.  For the fixed-step rk4 the
step error is estimated by Richardson extrapolation against a run at half the
step: |r_h − r_{h/2}|·16/15.  Errors are reported relative to E_scale, the
largest kinetic energy plus the potential energy's range.

Two figures, never one for the other.  Each invariant reports the **largest error**
over the run (``max_error``, relative, with ``max_error_abs`` in J and the time
``max_error_t``) and, separately, the **worst ratio** error/tolerance: the error and
the tolerance at the step where that ratio is largest (``error``, ``tolerance``,
``worst_t``), which decides the verdict.  The bound grows along the run, so the two
usually fall at different steps: on the chaotic scene the largest energy error is
1.2e-8 J at the end, while the worst ratio is at an early step.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SAFETY = 4.0
ROUNDING = 64.0
EPS = float(np.finfo(float).eps)
GRADIENT_STEP = 1e-7


@dataclass(frozen=True)
class InvariantResult:
    """One invariant: its largest error and, apart, its worst error/tolerance ratio.

    Errors are relative to ``scale`` (the energy scale, J); times in s.
    """

    name: str
    error: float  # relative, at the step with the worst error/tolerance ratio
    tolerance: float  # relative, at that same step
    passed: bool
    detail: str = ""
    max_error: float = 0.0  # relative: the largest error over the run
    max_error_t: float = 0.0  # s: where the largest error is
    worst_t: float = 0.0  # s: where the worst error/tolerance ratio is
    scale: float = 1.0  # J: what the errors are relative to (nan: each state's own scale)

    @property
    def max_error_abs(self) -> float:
        """The largest error in J (nan when each state's error is relative to its own scale)."""
        return self.max_error * self.scale

    @property
    def ratio(self) -> float:
        return self.error / self.tolerance if self.tolerance > 0 else float("inf")

    def __repr__(self) -> str:
        verdict = "holds" if self.passed else "FAILS"
        figures = f"error {self.error:.3g}, tolerance {self.tolerance:.3g}"
        return f"<InvariantResult {self.name!r}: {figures}: {verdict}>"

    def as_dict(self) -> dict:
        return {**self.__dict__, "max_error_abs": self.max_error_abs}

    def figures(self) -> str:
        """The two figures in words: the largest error and the worst ratio, each with where."""
        absolute = f" ({self.max_error_abs:.3g} J)" if np.isfinite(self.scale) else ""
        return (
            f"largest {self.max_error:.3g}{absolute} at t = {self.max_error_t:.4g} s; "
            f"worst ratio {self.error:.3g}/{self.tolerance:.3g} at t = {self.worst_t:.4g} s"
        )


def figures_of(name: str, errors: np.ndarray, bounds: np.ndarray, times, scale: float, detail: str):
    """An InvariantResult from per-step errors and bounds (absolute) at ``times``."""
    errors, bounds = np.asarray(errors, dtype=float), np.asarray(bounds, dtype=float)
    worst = int(np.argmax(errors / bounds))
    largest = int(np.argmax(errors))
    return InvariantResult(
        name,
        float(errors[worst] / scale),
        float(bounds[worst] / scale),
        bool(np.all(errors <= bounds)),
        detail,
        max_error=float(errors[largest] / scale),
        max_error_t=float(times[largest]),
        worst_t=float(times[worst]),
        scale=float(scale),
    )


class TrajectoryEnergies:
    """E, M q̇ and T at the rows of a trajectory, and H's scale, for the invariants: per state.

    This one evaluates a ``Dynamics`` state by state (``energy``: Pinocchio's under ABA, the
    hand model's otherwise; ``M q̇`` and T: the hand model's).  The fast path passes a
    subclass that evaluates the model's generated functions on all rows at once
    (``pendverify.numerics.energies``).  ``Q``, ``V``: (rows, n) arrays of q and q̇.
    """

    def __init__(self, dyn):
        self.dyn = dyn
        self.nv = dyn.nv

    def energy(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        return np.array([self.dyn.energy(q, v) for q, v in zip(Q, V, strict=True)])

    def momentum(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        """M(q) q̇ at each row."""
        model = self.dyn.model
        return np.array([model.mass_matrix(q) @ v for q, v in zip(Q, V, strict=True)]).reshape(Q.shape)

    def kinetic(self, Q: np.ndarray, V: np.ndarray) -> np.ndarray:
        model = self.dyn.model
        return np.array([model.kinetic_energy(q, v) for q, v in zip(Q, V, strict=True)])

    def gravity_scale(self) -> np.ndarray:
        return np.asarray(self.dyn.model.gravity_scale(), dtype=float)


def energies_of(dyn) -> TrajectoryEnergies:
    """``dyn`` itself when it is a ``TrajectoryEnergies``, else the per-state view of a ``Dynamics``."""
    return dyn if isinstance(dyn, TrajectoryEnergies) else TrajectoryEnergies(dyn)


def residual(dyn, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(E at every row of xs, r at every row)."""
    view = energies_of(dyn)
    n = view.nv
    E = view.energy(xs[:, :n], xs[:, n : 2 * n])
    r = E - E[0] - xs[:, 2 * n] + xs[:, 2 * n + 1]
    return E, r


def gradients(dyn, xs: np.ndarray) -> np.ndarray:
    """|∇r| at every row of xs: M q̇ for the rates, central differences of E for q, ±1 for the integrals."""
    view = energies_of(dyn)
    n = view.nv
    Q, V = xs[:, :n], xs[:, n : 2 * n]
    grad_q = np.empty((xs.shape[0], n))
    for i in range(n):
        h = GRADIENT_STEP * (1.0 + np.abs(Q[:, i]))
        up, down = Q.copy(), Q.copy()
        up[:, i] += h
        down[:, i] -= h
        grad_q[:, i] = (view.energy(up, V) - view.energy(down, V)) / (2 * h)
    ones = np.ones((xs.shape[0], 2))
    return np.abs(np.concatenate([grad_q, view.momentum(Q, V), ones], axis=1))


def energy_scale(dyn, xs: np.ndarray) -> float:
    view = energies_of(dyn)
    n = view.nv
    kinetic = float(np.max(view.kinetic(xs[:, :n], xs[:, n : 2 * n])))
    return float(kinetic + np.sum(view.gravity_scale()) * 2 + EPS)


def adaptive_bound(dyn, xs: np.ndarray, integrator, scale: float) -> np.ndarray:
    """Cumulative bound on |r| after each step of an adaptive run."""
    X = xs[:-1]
    G = gradients(dyn, X)
    weights = integrator.atol + integrator.rtol * np.abs(X)
    per_step = SAFETY * np.sqrt(X.shape[1]) * np.einsum("ij,ij->i", G, weights) + ROUNDING * EPS * scale
    return np.concatenate([[ROUNDING * EPS * scale], ROUNDING * EPS * scale + np.cumsum(per_step)])


def richardson_bound(r_h: np.ndarray, r_half_at_steps: np.ndarray, scale: float) -> np.ndarray:
    """Bound on |r| of an rk4 run from the same run at half the step (order 4)."""
    estimate = np.maximum.accumulate(np.abs(r_h - r_half_at_steps) * 16.0 / 15.0)
    steps = np.arange(1, r_h.size + 1)
    return SAFETY * estimate + ROUNDING * EPS * scale * steps


def evaluate(dyn, scene, steps_t, steps_x, bound: np.ndarray, scale: float) -> list[InvariantResult]:
    E, r = residual(dyn, steps_x)
    has_work = scene.actuation is not None or scene.disturbance is not None
    if scene.conservative:
        name = "energy drift |E(t) − E(0)|"
    elif has_work:
        name = "work–energy balance E(t) − E(0) − ∫q̇ᵀ(τ_u + w − Dq̇)dt"
    else:
        name = "dissipation balance E(t) − E(0) + ∫q̇ᵀDq̇ dt"
    steps = f"over {len(steps_t) - 1} steps"
    results = [figures_of(name, np.abs(r), bound, steps_t, scale, steps)]
    if scene.damping is not None and not has_work:
        increase = np.diff(E)
        k = int(np.argmax(increase))
        detail = f"largest step-to-step change {increase[k]:+.3g} J at t = {steps_t[k + 1]:.4g} s"
        rises = np.maximum(increase, 0.0)
        allowed = np.diff(bound)
        results.append(figures_of("energy never increases", rises, allowed, steps_t[1:], scale, detail))
    return results
