"""Simulated stress cases on a model's closed form: stiff damping, a long horizon, g = 0."""

from __future__ import annotations

import math

import numpy as np

from pendverify.checks.trust import EPS, conditioning
from pendverify.numerics.integrators import model_runs as runs
from pendverify.numerics.integrators.tableaux import RK4
from pendverify.stress.framework import (
    BOUNDED_GROWTH,
    ENERGY_INCREASE_TOL,
    MIN_ORDER_RATIO,
    MIN_R2,
    MOMENTUM_K,
    ORDER_FRACTION,
    RK4_UNSTABLE,
    Case,
    Context,
    StressResult,
    model_of,
)


# --- what the runs show ---------------------------------------------------------------------------
def energy(model, q, v) -> float:
    return model.kinetic_energy(q, v) + model.potential_energy(q)


def energies(model, run: runs.IntegrationRecord) -> np.ndarray:
    return np.array([energy(model, q, v) for q, v in zip(run.q, run.v, strict=True)])


def momenta(model, run: runs.IntegrationRecord) -> np.ndarray:
    """p = M(q) q̇ at every recorded state."""
    return np.array([model.mass_matrix(q) @ v for q, v in zip(run.q, run.v, strict=True)])


def fit_slope(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Least-squares slope of y(t) and the fit's R² (1 for a perfect line)."""
    A = np.column_stack([t, np.ones_like(t)])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - A @ coef
    total = float(np.sum((y - y.mean()) ** 2))
    r2 = 1.0 - float(np.sum(resid**2)) / total if total > 0 else 1.0
    return float(coef[0]), r2


def rk4_growth(J: np.ndarray, h: float) -> float:
    """max |R(hλ)| over the eigenvalues λ of J, R the stability function of RK4's tableau."""
    return float(np.max(np.abs(RK4.stability(h * np.linalg.eigvals(J)))))


# --- simulations --------------------------------------------------------------------------------
def energy_scale(model, q, v) -> float:
    """½ q̇ᵀ M q̇ + Σ gravity_scale: a bound on |T| + |V| (J)."""
    return model.kinetic_energy(q, v) + float(np.sum(model.gravity_scale()))


def _kappa(model, q):

    return conditioning(model.mass_matrix(q), model.diagonal_scale(q))


def stiff_sim_case(name: str, params_fn, q0, light_params_fn, model_cls=None) -> Case:
    """Backward Euler from rest at ``q0`` on the stiff set; RK4 and RK45 beside it, RK45's step
    count next to its count on ``light_params_fn``'s set (the model at ordinary damping)."""

    def run(ctx: Context, name: str) -> StressResult:

        st = ctx.settings
        params = params_fn()
        model = model_of(params, model_cls, ctx)
        q0_, v0 = np.asarray(q0, dtype=float), np.zeros(model.nv)
        n = round(st.stiff_horizon / st.stiff_step)
        implicit = runs.implicit_euler(model, q0_, v0, st.stiff_step, n)
        E = energies(model, implicit)
        rise = float(np.max(np.diff(E))) / energy_scale(model, q0_, v0) if len(E) > 1 else 0.0
        stable = implicit.blew_up_at is None and bool(np.all(np.isfinite(E)))
        monotone = stable and rise <= ENERGY_INCREASE_TOL
        c = _kappa(model, q0_)
        result = StressResult(
            case=name,
            quantity="per-step energy rise, backward Euler (relative to |T|+|V| bound)",
            error=max(rise, 0.0) if stable else math.inf,
            tolerance=ENERGY_INCREASE_TOL,
            kappa_raw=c.kappa_raw,
            kappa_scaled=c.kappa_scaled,
            invariant=(
                f"backward Euler h={st.stiff_step:g} s, {n} steps over {st.stiff_horizon:g} s: "
                + (f"E never rises (largest step change {rise:+.1e} of scale)" if monotone else "E RISES")
            ),
            passed=False,
            note="" if stable else f"implicit method failed: {implicit.note}",
            level=c.level,
        )
        if not monotone:
            result.note = "; ".join(filter(None, [result.note, "explicit methods skipped"]))
            return result
        growth = rk4_growth(
            runs.jacobian(runs.state_derivative_of(model), np.concatenate([q0_, v0])), st.stiff_step
        )
        explicit = runs.rk4(model, q0_, v0, st.stiff_step, n)
        predicted, observed = growth > RK4_UNSTABLE, explicit.blew_up_at is not None
        adaptive = runs.rk45(model, q0_, v0, st.explicit_horizon)
        light = runs.rk45(model_of(light_params_fn(), model_cls, ctx), q0_, v0, st.explicit_horizon)
        per_horizon = adaptive.steps * st.stiff_horizon / st.explicit_horizon
        result.invariant += (
            f"; RK4 at h={st.stiff_step:g}: "
            + (f"blows up after {explicit.blew_up_at} steps" if observed else "stays finite")
            + f" (predicted growth ×{growth:.1e}/step); RK45 needs {adaptive.steps} steps for "
            f"{st.explicit_horizon:g} s (≈{per_horizon:.1e} for {st.stiff_horizon:g} s) vs "
            f"{light.steps} at default damping"
        )
        result.passed = predicted == observed and adaptive.blew_up_at is None and adaptive.steps > 0
        if predicted != observed:
            result.note = (
                f"RK4 stability predicted {'a blow-up' if predicted else 'none'}, observed the opposite"
            )
        return result

    return Case(name, "stiff damping", run)


def long_horizon_case(name: str, params_fn, start, model_cls=None) -> Case:
    """A mild, conservative set from rest at ``start`` over the long horizon: Störmer–Verlet's energy
    error stays bounded, RK4's drifts as an order-4 method's should."""

    def run(ctx: Context, name: str) -> StressResult:

        st = ctx.settings
        params = params_fn()
        model = model_of(params, model_cls, ctx)
        q0, v0 = np.asarray(start, dtype=float), np.zeros(model.nv)
        h, T = st.long_step, st.long_horizon
        n = round(T / h)
        record = max(1, n // 500)
        scale = energy_scale(model, q0, v0)

        def drift(traj):
            dE = (energies(model, traj) - energy(model, q0, v0)) / scale
            slope, r2 = fit_slope(traj.t, dE)
            return dE, slope, r2

        sv = runs.stormer_verlet(model, q0, v0, h, n, record)
        # the order test needs a slope, not the whole horizon: RK4 at h/2 runs ORDER_FRACTION of it
        n_half = 2 * max(1, round(n * ORDER_FRACTION))
        rk, rk_half = (
            runs.rk4(model, q0, v0, h, n, record),
            runs.rk4(model, q0, v0, h / 2, n_half, 2 * record),
        )
        finite = all(t.blew_up_at is None for t in (sv, rk, rk_half))
        dE_sv, slope_sv, _ = drift(sv)
        _, slope_rk, r2_rk = drift(rk)
        _, slope_half, r2_half = drift(rk_half)
        half = len(dE_sv) // 2
        early, late = float(np.max(np.abs(dE_sv[:half]))), float(np.max(np.abs(dE_sv[half:])))
        ratio = abs(slope_rk) / abs(slope_half) if slope_half != 0 else math.inf
        bounded = late <= BOUNDED_GROWTH * early + 4 * EPS
        linear = min(r2_rk, r2_half) >= MIN_R2 and ratio >= MIN_ORDER_RATIO
        invariant = (
            f"E drift slope (relative, per s): RK4 h={h:g} s {slope_rk:+.2e} (R² {r2_rk:.3f}), "
            f"h={h / 2:g} s {slope_half:+.2e} (R² {r2_half:.3f}, first {n_half * h / 2:g} s), "
            f"ratio {ratio:.1f}; "
            f"Störmer–Verlet h={h:g} s {slope_sv:+.2e}, |ΔE| ≤ {max(early, late):.1e} "
            f"(first half {early:.1e}, second half {late:.1e})"
        )
        c = _kappa(model, q0)
        notes = []
        if not bounded:
            notes.append("symplectic energy error grows")
        if not linear:
            notes.append(
                f"RK4 drift not a clean order-4 line (R² {min(r2_rk, r2_half):.2f}, ratio {ratio:.1f})"
            )
        return StressResult(
            case=name,
            quantity=f"Störmer–Verlet |ΔE|/E over {T:g} s: second half vs first half",
            error=late,
            tolerance=BOUNDED_GROWTH * early + 4 * EPS,
            kappa_raw=c.kappa_raw,
            kappa_scaled=c.kappa_scaled,
            invariant=invariant,
            passed=finite and bounded and linear,
            note="; ".join(notes),
        )

    return Case(name, "long horizon", run)


def zero_gravity_sim_case(name: str, params_fn, q0, v0, cyclic: int, label: str, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> StressResult:

        st = ctx.settings
        params = params_fn()
        model = model_of(params, model_cls, ctx)
        q0_, v0_ = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
        traj = runs.stormer_verlet(model, q0_, v0_, st.zero_g_step, st.zero_g_steps, record=10)
        p = momenta(model, traj)[:, cyclic]
        p_scale = float(np.max(np.abs(momenta(model, traj))))
        drift = float(np.max(np.abs(p - p[0]))) / p_scale
        tol = MOMENTUM_K * EPS * st.zero_g_steps
        dE = energies(model, traj)
        e_rel = float(np.max(np.abs(dE - dE[0]))) / energy_scale(model, q0_, v0_)
        c = _kappa(model, q0_)
        return StressResult(
            case=name,
            quantity=f"momentum {label} drift / |p|, Störmer–Verlet",
            error=drift,
            tolerance=tol,
            kappa_raw=c.kappa_raw,
            kappa_scaled=c.kappa_scaled,
            invariant=(
                f"{label} conserved to {drift:.1e} over {st.zero_g_steps} steps of "
                f"{st.zero_g_step:g} s; energy error ≤ {e_rel:.1e} (bounded)"
            ),
            passed=traj.blew_up_at is None and drift <= tol,
        )

    return Case(name, "zero gravity", run)
