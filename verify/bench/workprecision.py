"""Work–precision benchmark: how much wall time each digit of accuracy costs.

Problems (``pendverify.bench.problems``): scenes, so the fast path's invariant checks run
on the very same dynamics; by default the shipped scenes ``scenes/bench`` (``problems.shipped_problems``:
mild, chaotic, cart_lqr, long), or a user's scene, any model (``--scene``).  Each carries
its metric: "state" problems are compared against references, "energy" ones by the
relative energy error alone.

Metrics per point: the error at the final time (max over components of
|x − x_ref|, rad, m, rad/s, m/s), the max error over G + 1 equally spaced dense
points, the relative energy error |E − E(0)| / (E(0) − V_min) at the final time
and its max over the dense points (conservative problems), the number of
right-hand-side evaluations and of steps, and the wall time of the integration
alone: one warm-up run (for the adaptive methods, the untimed dense-output run
of the same integration), then the minimum and the median of ``repeats`` runs,
with the garbage collector off (runs shorter than 5 ms are batched within a
sample, as ``timeit`` does).  Dense output comes from that
untimed run; dense output does not change the steps.

References (``pendverify.numerics.reference``) are Taylor-series solutions in high
precision of the model's generated field, checked at a second precision; their own error
bound is reported next to the smallest error plotted.

Methods.  Adaptive: scipy's RK45, DOP853, Radau and LSODA with ``rtol = atol``,
on Pinocchio's ``aba`` (the usual choice), and the fast path (compiled DOP853 on
the right-hand side generated from the model, ``pendverify.numerics.integrators.dop853_runner``).
Fixed step, compiled from the model too (``pendverify.numerics.integrators.fixedstep``):
explicit Euler, symplectic Euler, implicit midpoint and RK4 with halving steps;
their observed order is the least-squares slope of log error against log h over
the points whose error lies in the asymptotic window [1e-11, 1e-2].  A scipy
method stops tightening once one run exceeds the configuration's time budget
(the table says where).  scipy is not run on the energy-only (long) problems: a single run
there takes seconds to minutes with a Python right-hand side, and the fast path
takes exactly scipy's DOP853 steps (same tableau, initial step and error
control), so its energy line is scipy DOP853's line.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace

import numpy as np

from pendverify.bench.problems import Problem, ProblemSpec, build_problem, shipped_problems
from pendverify.bench.timing import measure
from pendverify.numerics.integrators import fixedstep, fixedstep_runner
from pendverify.numerics.integrators.dop853_runner import integrate as fast_integrate
from pendverify.numerics.reference import energy_errors

ORDER_WINDOW = (1e-11, 1e-2)
SCIPY_METHODS = ("RK45", "DOP853", "Radau", "LSODA")
FIXED_METHODS = tuple(fixedstep.METHODS)


@dataclass(frozen=True)
class Config:
    name: str
    horizons: dict  # problem key -> T [s]
    tolerances: tuple  # rtol = atol of the fast path and scipy's DOP853
    other_tolerances: tuple  # of RK45, Radau, LSODA
    fixed: dict  # method -> (largest step [s], number of halvings)
    long_fixed: dict  # the same for the long run
    repeats: int = 5
    run_budget: float = 2.0  # s: a scipy method stops tightening after a run this long
    grid_intervals: int = 64
    digits: tuple = (30, 40)  # reference and check precision
    ensemble_size: int = 1000
    ensemble_checked: int = 4  # members checked against their own reference (the first is the base state)
    ensemble_spread: float = 0.05  # rad, m: uniform perturbation of every coordinate around the anchor
    target_error: float = 1e-10
    scipy_methods: tuple = SCIPY_METHODS
    anchor: str = "chaotic"  # the state problem of the single-trajectory ratio, engines and ensemble
    engine_problems: tuple = ("chaotic", "cart_lqr")
    energy_only: tuple = ("long",)  # the problems compared by their energy alone, never their states
    ensemble_variants: tuple = ("threads", "serial", "vectorised")
    seed: int = 20260301
    scene_horizon: float = 10.0  # s: a user's scene is compared over min(its duration, this)
    scene_long: float = 1000.0  # s: the energy-only run of a conservative user's scene


FULL = Config(
    name="full",
    horizons={"mild": 10.0, "chaotic": 2.0, "cart_lqr": 5.0, "long": 1000.0},
    tolerances=tuple(10.0**-k for k in range(3, 14)),
    other_tolerances=tuple(10.0**-k for k in range(3, 14)),
    fixed={
        "euler": (2.0**-7, 9),
        "symplectic_euler": (2.0**-7, 9),
        "implicit_midpoint": (2.0**-5, 9),
        "rk4": (2.0**-4, 8),
    },
    long_fixed={
        "euler": (2.0**-5, 6),
        "symplectic_euler": (2.0**-4, 6),
        "implicit_midpoint": (2.0**-4, 6),
        "rk4": (2.0**-3, 6),
    },
    run_budget=2.0,
)
QUICK = replace(
    FULL,
    name="quick",
    horizons={"mild": 5.0, "chaotic": 2.0, "cart_lqr": 3.0, "long": 200.0},
    tolerances=(1e-3, 1e-5, 1e-7, 1e-9, 1e-11),
    other_tolerances=(1e-3, 1e-6, 1e-9),
    fixed={
        "euler": (2.0**-7, 5),
        "symplectic_euler": (2.0**-7, 5),
        "implicit_midpoint": (2.0**-5, 5),
        "rk4": (2.0**-4, 5),
    },
    long_fixed={
        "euler": (2.0**-5, 3),
        "symplectic_euler": (2.0**-4, 3),
        "implicit_midpoint": (2.0**-4, 3),
        "rk4": (2.0**-3, 3),
    },
    run_budget=0.3,
    digits=(24, 32),
    ensemble_checked=1,
    engine_problems=("chaotic",),
    ensemble_variants=("threads",),
    scene_horizon=3.0,
    scene_long=200.0,
)


# --- problems --------------------------------------------------------------------------------
def make_problem(spec: ProblemSpec | str, duration: float, grid_intervals: int = 64) -> Problem:
    """A problem over ``duration``: a ``ProblemSpec``, or the key of a default problem (``scenes/bench``)."""
    spec = shipped_problems(FULL.energy_only)[spec] if isinstance(spec, str) else spec
    return build_problem(spec, duration, grid_intervals)


def make_problems(config: Config, specs: dict | None = None) -> list[Problem]:
    """The problems of ``config.horizons`` from ``specs`` (default: the shipped ``scenes/bench``)."""
    specs = shipped_problems(config.energy_only) if specs is None else specs
    return [make_problem(specs[k], T, config.grid_intervals) for k, T in config.horizons.items()]


# --- one point of the plot -----------------------------------------------------------------------
@dataclass
class Point:
    problem: str
    method: str  # e.g. "DOP853 (scipy)", "DOP853 (fast path)", "rk4"
    engine: str  # aba, compiled, ...
    kind: str  # adaptive | fixed
    setting: float  # rtol = atol, or the step h [s]
    metric: str = "state"  # the problem's: "state" or "energy"
    final_error: float = math.nan
    max_error: float = math.nan
    energy_final: float = math.nan
    energy_max: float = math.nan
    nfev: int = 0
    steps: int = 0
    t_min: float = math.nan
    t_median: float = math.nan
    repeats: int = 0
    ok: bool = True
    note: str = ""

    @property
    def plotted_error(self) -> float:
        return self.energy_max if self.metric == "energy" else self.final_error


CSV_FIELDS = (
    "problem",
    "method",
    "engine",
    "kind",
    "setting",
    "final_error",
    "max_error",
    "energy_final",
    "energy_max",
    "nfev",
    "steps",
    "t_min",
    "t_median",
    "repeats",
    "ok",
    "note",
)


def _errors(point: Point, problem: Problem, ref, final_state, grid_states) -> None:
    if ref is not None:
        point.final_error = ref.final_error(final_state)
        point.max_error = float(np.max(ref.errors(grid_states)))
    if problem.conservative:
        point.energy_final, point.energy_max = energy_errors(
            problem.fast, problem.x0, grid_states, final_state
        )


# --- sweeps ----------------------------------------------------------------------------------------
def scipy_sweep(problem: Problem, method: str, rhs, tolerances, config: Config, ref) -> list[Point]:
    """scipy's ``method`` on the engine ``rhs`` at each tolerance, tightening until the time budget."""
    from scipy.integrate import solve_ivp

    x0 = rhs.to_engine(problem.x0)
    span = (0.0, problem.duration)
    label = f"{method} (scipy)"
    points, costs = [], []
    for tol in tolerances:
        point = Point(problem.key, label, rhs.engine, "adaptive", tol, problem.metric)
        guess = costs[-1] ** 2 / costs[-2] if len(costs) > 1 else (3 * costs[-1] if costs else 0.0)
        if guess > config.run_budget:
            points.append(
                replace(point, ok=False, note=f"skipped: a run would take about {guess:.2g} s > budget")
            )
            break

        def run(tol=tol):
            return solve_ivp(rhs.fun, span, x0, method=method, rtol=tol, atol=tol)

        start = time.perf_counter()  # the warm-up run, with dense output (untimed)
        dense = solve_ivp(rhs.fun, span, x0, method=method, rtol=tol, atol=tol, dense_output=True)
        first = time.perf_counter() - start
        if dense.status != 0:
            points.append(replace(point, ok=False, note=dense.message))
            continue
        if first > config.run_budget:
            points.append(replace(point, ok=False, note=f"skipped: one run took {first:.2g} s > budget"))
            break
        point.t_min, point.t_median, sol = measure(run, config.repeats, first)
        costs.append(point.t_min)
        point.repeats, point.nfev, point.steps = config.repeats, int(sol.nfev), len(sol.t) - 1
        _errors(point, problem, ref, rhs.to_model(sol.y[:, -1]), rhs.to_model(dense.sol(problem.grid).T))
        points.append(point)
    return points


def fast_sweep(problem: Problem, tolerances, config: Config, ref) -> list[Point]:
    points = []
    for tol in tolerances:
        point = Point(problem.key, "DOP853 (fast path)", "compiled", "adaptive", tol, problem.metric)

        def run(tol=tol):
            return fast_integrate(problem.fast, problem.x0, problem.duration, tol, tol)

        start = time.perf_counter()  # the warm-up run, with dense output (untimed)
        dense = fast_integrate(problem.fast, problem.x0, problem.duration, tol, tol, t_out=problem.grid)
        point.t_min, point.t_median, res = measure(run, config.repeats, time.perf_counter() - start)
        point.repeats, point.nfev, point.steps = config.repeats, res.nfev, res.steps
        _errors(point, problem, ref, res.x, dense.dense)
        points.append(point)
    return points


def step_counts(duration: float, largest: float, halvings: int, intervals: int) -> list[int]:
    """Step counts N = intervals·2^j, h = duration / N ≤ largest, halving ``halvings`` times."""
    j0 = max(0, math.ceil(math.log2(duration / (intervals * largest)) - 1e-12))
    return [intervals * 2 ** (j0 + i) for i in range(halvings + 1)]


def fixed_sweep(
    problem: Problem, method: str, largest: float, halvings: int, config: Config, ref
) -> list[Point]:
    points = []
    g = config.grid_intervals
    for steps in step_counts(problem.duration, largest, halvings, g):
        h = problem.duration / steps
        point = Point(problem.key, method, "compiled", "fixed", h, problem.metric, steps=steps)

        def run(steps=steps):
            return fixedstep_runner.integrate_fixed(
                method, problem.fast, problem.x0, problem.duration, steps, steps // g
            )

        point.t_min, point.t_median, (grid, nfev, ok) = measure(run, config.repeats)
        point.repeats, point.nfev = config.repeats, nfev
        if not ok:
            points.append(replace(point, ok=False, note="diverged or an implicit step did not converge"))
            continue
        _errors(point, problem, ref, grid[-1], grid)
        points.append(point)
    return points


# --- observed orders ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class OrderFit:
    problem: str
    method: str
    theory: int
    observed: float  # nan when fewer than 3 points lie in the window
    points: int


def observed_order(hs, errors, window=ORDER_WINDOW) -> tuple[float, int]:
    hs, errors = np.asarray(hs, float), np.asarray(errors, float)
    keep = np.isfinite(errors) & (errors >= window[0]) & (errors <= window[1])
    if np.sum(keep) < 3:
        return math.nan, int(np.sum(keep))
    slope = np.polyfit(np.log(hs[keep]), np.log(errors[keep]), 1)[0]
    return float(slope), int(np.sum(keep))


def order_fits(points: list[Point]) -> list[OrderFit]:
    fits = []
    keys = sorted({(p.problem, p.method) for p in points if p.kind == "fixed"}, key=str)
    for problem, method in keys:
        pts = [p for p in points if p.problem == problem and p.method == method and p.ok]
        slope, n = observed_order([p.setting for p in pts], [p.plotted_error for p in pts])
        fits.append(OrderFit(problem, method, fixedstep.METHODS[method], slope, n))
    return fits
