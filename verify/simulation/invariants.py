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
    name: str
    error: float  # relative to the energy scale, at the worst step
    tolerance: float  # relative, at the worst step
    passed: bool
    detail: str = ""

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def residual(dyn, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(E at every row of xs, r at every row)."""
    n = dyn.nv
    E = np.array([dyn.energy(x[:n], x[n : 2 * n]) for x in xs])
    r = E - E[0] - xs[:, 2 * n] + xs[:, 2 * n + 1]
    return E, r


def _gradient(dyn, x: np.ndarray) -> np.ndarray:
    """|∇r| at x: M q̇ for the rates, central differences of E for q, ±1 for the integrals."""
    n = dyn.nv
    q, v = x[:n], x[n : 2 * n]
    grad_q = np.empty(n)
    for i in range(n):
        h = GRADIENT_STEP * (1.0 + abs(q[i]))
        e = np.zeros(n)
        e[i] = h
        grad_q[i] = (dyn.energy(q + e, v) - dyn.energy(q - e, v)) / (2 * h)
    return np.abs(np.concatenate([grad_q, dyn.model.mass_matrix(q) @ v, [1.0, 1.0]]))


def energy_scale(dyn, xs: np.ndarray) -> float:
    n = dyn.nv
    kinetic = max(dyn.model.kinetic_energy(x[:n], x[n : 2 * n]) for x in xs)
    return float(kinetic + np.sum(dyn.model.gravity_scale()) * 2 + EPS)


def adaptive_bound(dyn, xs: np.ndarray, integrator, scale: float) -> np.ndarray:
    """Cumulative bound on |r| after each step of an adaptive run."""
    per_step = [
        SAFETY * np.sqrt(x.size) * _gradient(dyn, x) @ (integrator.atol + integrator.rtol * np.abs(x))
        + ROUNDING * EPS * scale
        for x in xs[:-1]
    ]
    return np.concatenate([[ROUNDING * EPS * scale], ROUNDING * EPS * scale + np.cumsum(per_step)])


def richardson_bound(r_h: np.ndarray, r_half_at_steps: np.ndarray, scale: float) -> np.ndarray:
    """Bound on |r| of an rk4 run from the same run at half the step (order 4)."""
    estimate = np.maximum.accumulate(np.abs(r_h - r_half_at_steps) * 16.0 / 15.0)
    steps = np.arange(1, r_h.size + 1)
    return SAFETY * estimate + ROUNDING * EPS * scale * steps


def evaluate(dyn, scene, steps_t, steps_x, bound: np.ndarray, scale: float) -> list[InvariantResult]:
    E, r = residual(dyn, steps_x)
    worst = int(np.argmax(np.abs(r) / bound))
    has_work = scene.actuation is not None or scene.disturbance is not None
    if scene.conservative:
        name = "energy drift |E(t) − E(0)|"
    elif has_work:
        name = "work–energy balance E(t) − E(0) − ∫q̇ᵀ(τ_u + w − Dq̇)dt"
    else:
        name = "dissipation balance E(t) − E(0) + ∫q̇ᵀDq̇ dt"
    results = [
        InvariantResult(
            name,
            float(abs(r[worst]) / scale),
            float(bound[worst] / scale),
            bool(np.all(np.abs(r) <= bound)),
            f"worst at t = {steps_t[worst]:.4g} s over {len(steps_t) - 1} steps",
        )
    ]
    if scene.damping is not None and not has_work:
        increase = np.diff(E)
        allowed = np.diff(bound)
        k = int(np.argmax(increase - allowed))
        results.append(
            InvariantResult(
                "energy never increases",
                float(max(increase[k], 0.0) / scale),
                float(allowed[k] / scale),
                bool(np.all(increase <= allowed)),
                f"largest step-to-step change {increase[k]:+.3g} J at t = {steps_t[k + 1]:.4g} s",
            )
        )
    return results
