"""The fast path against scipy: engine costs, single-trajectory and ensemble ratios, invariants.

Engines.  For each engine (``pendverify.simulation.engines``) on one problem: the cost of
one right-hand-side call (minimum over batches of calls at the initial state),
and a whole scipy DOP853 integration at the tolerance of the single-trajectory
comparison (min and median wall time, nfev).  The share of the time spent
outside the right-hand side is 1 − nfev · (cost per call) / (wall time): scipy's
stage bookkeeping, array allocation and the Python calls themselves.

Single trajectory.  On the anchor problem (``Config.anchor``: the reference systems' chaotic one,
T = 2 s, or a user's scene's state problem) the target is a final-state error ≤
``target_error``.  From the sweeps, each method's point at the loosest
tolerance that reaches it is taken (the tolerance a user would pick; both
DOP853s take the same steps, so it is the same tolerance); the ratio is fast
path / scipy, minimum (and median) wall times from the same run.

Ensemble.  ``ensemble_size`` initial states on the anchor problem, its q + U(±spread)ⁿ
with its rates (seeded; the first member is the unperturbed state), integrated at the same
tolerance.  Alternatives measured: the fast path on every core (one compiled
DOP853 per trajectory, threads), the fast path on one thread, and scipy DOP853
on the stacked system with a numpy-vectorised closed form (one shared step
size).  The per-trajectory cost is wall time / ensemble size; the accuracy is
checked on ``ensemble_checked`` members against their own references, next to
the accuracy of scipy's DOP853 + aba run alone on the same members (the
accuracy an ensemble must match: perturbed chaotic states are not all as easy
as the base state at the same tolerance).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pendverify.bench.problems import Problem, engine_rhs
from pendverify.bench.timing import measure
from pendverify.bench.workprecision import Config, Point
from pendverify.numerics.integrators.dop853_runner import integrate, integrate_ensemble
from pendverify.simulation.compiled_scene import simulate_compiled
from pendverify.simulation.engine_names import RHS_ENGINES


@dataclass(frozen=True)
class EngineRow:
    problem: str
    engine: str
    per_call: float  # s per right-hand-side call (nan for the fast path: calls are inside the kernel)
    t_min: float
    t_median: float
    nfev: int
    final_error: float

    @property
    def outside_share(self) -> float:
        if not math.isfinite(self.per_call):
            return math.nan
        return max(0.0, 1.0 - self.nfev * self.per_call / self.t_min)


def engine_study(problem: Problem, tol: float, config: Config, ref) -> list[EngineRow]:
    from scipy.integrate import solve_ivp

    rows = []
    for name in RHS_ENGINES:
        rhs = engine_rhs(problem, name)
        if rhs is None:  # crba_cholesky, minverse on a URDF with continuous joints
            continue
        x0 = rhs.to_engine(problem.x0)
        per_call = rhs.per_call(problem.x0)

        def run(rhs=rhs, x0=x0):
            return solve_ivp(rhs.fun, (0.0, problem.duration), x0, method="DOP853", rtol=tol, atol=tol)

        t_min, t_med, sol = measure(run, config.repeats)
        err = ref.final_error(rhs.to_model(sol.y[:, -1])) if ref is not None else math.nan
        rows.append(
            EngineRow(problem.key, f"{rhs.engine} + scipy DOP853", per_call, t_min, t_med, int(sol.nfev), err)
        )

    def fast():
        return integrate(problem.fast, problem.x0, problem.duration, tol, tol)

    t_min, t_med, res = measure(fast, config.repeats)
    err = ref.final_error(res.x) if ref is not None else math.nan
    rows.append(
        EngineRow(
            problem.key, "fast path (compiled DOP853 + closed form)", math.nan, t_min, t_med, res.nfev, err
        )
    )
    return rows


@dataclass(frozen=True)
class SingleRatio:
    problem: str
    target: float
    fast: Point | None
    scipy: Point | None

    @property
    def ratio(self) -> float:
        if self.fast is None or self.scipy is None:
            return math.nan
        return self.fast.t_min / self.scipy.t_min

    @property
    def ratio_median(self) -> float:
        if self.fast is None or self.scipy is None:
            return math.nan
        return self.fast.t_median / self.scipy.t_median


def loosest_reaching(points: list[Point], problem: str, method: str, target: float) -> Point | None:
    """The point at the loosest tolerance whose final error meets ``target`` (what a user would pick)."""
    ok = [
        p for p in points if p.problem == problem and p.method == method and p.ok and p.final_error <= target
    ]
    return max(ok, key=lambda p: p.setting) if ok else None


def single_ratio(points: list[Point], problem: str, target: float) -> SingleRatio:
    return SingleRatio(
        problem,
        target,
        loosest_reaching(points, problem, "DOP853 (fast path)", target),
        loosest_reaching(points, problem, "DOP853 (scipy)", target),
    )


@dataclass(frozen=True)
class EnsembleRow:
    variant: str
    size: int
    t_min: float
    t_median: float
    per_trajectory: float  # s, from t_min
    max_error: float  # over the checked members, final state
    checked: int


def ensemble_states(problem: Problem, config: Config) -> np.ndarray:
    rng = np.random.default_rng(config.seed)
    X0 = np.tile(problem.x0, (config.ensemble_size, 1))
    n = problem.fast.nv
    X0[1:, :n] += rng.uniform(-config.ensemble_spread, config.ensemble_spread, (config.ensemble_size - 1, n))
    return X0


def vectorised_rhs(fast, size: int):
    """fun(t, y) of the stacked ensemble, y = (x_1, …, x_m), with the closed form on numpy arrays."""
    from pendverify.numerics.integrators.taylor import field, float_system

    system = float_system(fast)
    nx = 2 * fast.nv

    def fun(t, y):
        X = y.reshape(size, nx)
        return np.stack(field(system, list(X.T)), axis=1).ravel()

    return fun


def ensemble_study(problem: Problem, tol: float, config: Config, member_refs: list) -> list[EnsembleRow]:
    """``member_refs``: references of the first members of ``ensemble_states`` (may be empty)."""
    from scipy.integrate import solve_ivp

    X0 = ensemble_states(problem, config)
    m, T = X0.shape[0], problem.duration

    def error(X):
        errs = [ref.final_error(X[i]) for i, ref in enumerate(member_refs)]
        return max(errs) if errs else math.nan

    rows = []
    if member_refs:  # the usual choice on the checked members: the accuracy to match
        rhs = engine_rhs(problem, "aba")
        finals = [
            rhs.to_model(
                solve_ivp(rhs.fun, (0.0, T), rhs.to_engine(X0[i]), method="DOP853", rtol=tol, atol=tol).y[
                    :, -1
                ]
            )
            for i in range(len(member_refs))
        ]
        nan = math.nan
        label = "scipy DOP853 + aba, each checked member alone (accuracy only)"
        rows.append(EnsembleRow(label, len(finals), nan, nan, nan, error(np.array(finals)), len(member_refs)))
    variants = (("threads", "fast path, all cores", None), ("serial", "fast path, 1 thread", 1))
    for key, label, threads in variants:
        if key not in config.ensemble_variants:
            continue

        def run(threads=threads):
            return integrate_ensemble(problem.fast, X0, T, tol, tol, threads=threads)

        t_min, t_med, (X, _) = measure(run, config.repeats)
        rows.append(EnsembleRow(label, m, t_min, t_med, t_min / m, error(X), len(member_refs)))
    if "vectorised" not in config.ensemble_variants:
        return rows
    fun = vectorised_rhs(problem.fast, m)

    def stacked():
        return solve_ivp(fun, (0.0, T), X0.ravel(), method="DOP853", rtol=tol, atol=tol)

    t_min, t_med, sol = measure(stacked, config.repeats)
    X = sol.y[:, -1].reshape(m, -1)
    rows.append(
        EnsembleRow(
            "scipy DOP853, numpy-vectorised closed form",
            m,
            t_min,
            t_med,
            t_min / m,
            error(X),
            len(member_refs),
        )
    )
    return rows


def fast_invariants(problems: list[Problem]) -> list[tuple[str, list]]:
    """The scene invariants of each state problem, on the fast path (``compiled_scene.simulate_compiled``)."""

    out = []
    for problem in problems:
        if problem.metric != "state":
            continue
        run = simulate_compiled(problem.scene)
        out.append((problem.key, run.invariants, run.result.steps))
    return out
