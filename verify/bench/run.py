"""The whole work–precision study, in the order it must run.

1. the references of every state problem (and of the checked ensemble members),
   from the cache or computed in parallel processes — before any timing;
2. generation (or cache load) of the models' modules and compilation of their numba
   functions, timed apart;
3. the sweeps (``pendverify.bench.workprecision``), the observed orders;
4. the fast path against scipy on the configuration's anchor problem (``Config.anchor``:
   the reference systems' chaotic one, or a user's scene's state problem): the single-trajectory
   ratio from the sweeps, the engine costs and the ensemble at the tolerance where scipy
   DOP853 first reaches the target error (``pendverify.bench.fast``);
5. the fast path's invariant checks on the state problems.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

from pendverify.bench import fast as fastbench
from pendverify.bench.problems import engine_rhs
from pendverify.bench.timing import machine_info
from pendverify.bench.workprecision import (
    Config,
    Point,
    fast_sweep,
    fixed_sweep,
    make_problems,
    order_fits,
    scipy_sweep,
)
from pendverify.display import html_fields
from pendverify.numerics.integrators import dop853_runner, fixedstep_runner
from pendverify.numerics.reference import references


@dataclass
class Results:
    config: Config
    machine: dict
    problems: list
    references: dict  # problem key -> Reference (state problems)
    points: list = field(default_factory=list)
    orders: list = field(default_factory=list)
    engines: list = field(default_factory=list)  # fastbench.EngineRow
    single: object = None  # fastbench.SingleRatio
    ensemble: list = field(default_factory=list)  # fastbench.EnsembleRow
    invariants: list = field(default_factory=list)  # (problem, invariants' Evidence)
    engine_tolerance: float = math.nan  # rtol = atol of the engine and ensemble studies
    compile_seconds: float = 0.0
    reference_seconds: float = 0.0
    elapsed: float = 0.0

    def __repr__(self) -> str:
        return (
            f"<Results {len(self.problems)} problem(s), {len(self.points)} points, {len(self.orders)} order "
            f"fits, {len(self.engines)} engine rows; smallest error {self.smallest_error():.2e}; "
            f"{self.elapsed:.1f} s>"
        )

    def _repr_html_(self) -> str:
        fields = [
            ("problems", ", ".join(getattr(p, "key", str(p)) for p in self.problems)),
            ("points", len(self.points)),
            ("smallest error", f"{self.smallest_error():.2e}"),
            ("compile, references, total [s]", f"{self.compile_seconds:.1f}, {self.reference_seconds:.1f}, "
             f"{self.elapsed:.1f}"),
        ]  # fmt: skip
        return html_fields("bench accuracy", fields)

    def smallest_error(self) -> float:
        state = [p for p in self.points if p.ok and p.metric == "state"]
        errs = [p.final_error for p in state if p.final_error > 0]
        errs += [p.max_error for p in state if p.max_error > 0]
        return min(errs) if errs else math.nan

    @property
    def anchor(self):
        """The state problem of the single-trajectory ratio, engine study and ensemble (or None)."""
        return next((p for p in self.problems if p.key == self.config.anchor and p.metric == "state"), None)

    def largest_reference_bound(self) -> float:
        return max((r.error_bound for r in self.references.values()), default=math.nan)


def run_sweeps(problems, references, config: Config, log=print) -> list[Point]:
    points: list[Point] = []
    for problem in problems:
        ref = references.get(problem.key)
        start = time.perf_counter()
        points += fast_sweep(problem, config.tolerances, config, ref)
        spent = {"fast path": time.perf_counter() - start}
        if problem.metric == "state":
            rhs = engine_rhs(problem, "aba")
            for method in config.scipy_methods:
                start = time.perf_counter()
                tols = config.tolerances if method == "DOP853" else config.other_tolerances
                points += scipy_sweep(problem, method, rhs, tols, config, ref)
                spent[method] = time.perf_counter() - start
        start = time.perf_counter()
        table = config.long_fixed if problem.metric == "energy" else config.fixed
        for method, (largest, halvings) in table.items():
            points += fixed_sweep(problem, method, largest, halvings, config, ref)
        spent["fixed step"] = time.perf_counter() - start
        log(
            f"  {problem.key} (T = {problem.duration:g} s): "
            + ", ".join(f"{k} {v:.1f} s" for k, v in spent.items())
        )
    return points


def run_benchmark(
    config: Config,
    log=print,
    blas: str = "not limited",
    workers: int | None = None,
    specs: dict | None = None,
) -> Results:
    """Everything ``pendverify bench accuracy`` reports, measured in this process.

    ``specs``: the problems by key (``problems.ProblemSpec``; default: the reference systems' table);
    ``config.horizons`` says which run and for how long, ``config.anchor`` which one anchors
    the single-trajectory ratio, the engine study and the ensemble."""

    start = time.perf_counter()
    problems = make_problems(config, specs)
    by_key = {p.key: p for p in problems}
    state = [p for p in problems if p.metric == "state"]
    results = Results(config, machine_info(blas), problems, {})
    anchor = results.anchor
    jobs = [(p.fast, p.x0, p.duration, p.grid) for p in state]
    members = []
    if anchor is not None and config.ensemble_size > 0:
        members = list(fastbench.ensemble_states(anchor, config)[1 : config.ensemble_checked])
        jobs += [(anchor.fast, x, anchor.duration, np.array([0.0, anchor.duration])) for x in members]
    log(f"references: {len(jobs)} problems at {config.digits[0]} and {config.digits[1]} digits")
    t0 = time.perf_counter()
    refs = references(jobs, *config.digits, workers=workers or os.cpu_count() or 1)
    results.references = {p.key: r for p, r in zip(state, refs[: len(state)], strict=True)}
    results.reference_seconds = time.perf_counter() - t0
    systems = [p.fast for p in problems]
    results.compile_seconds = dop853_runner.warm_up(systems) + fixedstep_runner.warm_up(systems)
    log(f"generated back ends compiled or loaded in {results.compile_seconds:.1f} s; sweeping")
    results.points = run_sweeps(problems, results.references, config, log)
    results.orders = order_fits(results.points)
    if anchor is not None:
        results.single = fastbench.single_ratio(results.points, anchor.key, config.target_error)
        best = results.single.scipy or results.single.fast
        tol = best.setting if best is not None else min(config.tolerances)
        results.engine_tolerance = tol
        t0 = time.perf_counter()
        for key in config.engine_problems:
            if key in by_key:
                results.engines += fastbench.engine_study(by_key[key], tol, config, results.references[key])
        log(f"engines at rtol = atol = {tol:g}: {time.perf_counter() - t0:.1f} s")
        if config.ensemble_size > 0:
            t0 = time.perf_counter()
            member_refs = [results.references[anchor.key], *refs[len(state) :]]
            results.ensemble = fastbench.ensemble_study(anchor, tol, config, member_refs)
            log(f"ensemble of {config.ensemble_size}: {time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    results.invariants = fastbench.fast_invariants(problems)
    log(f"fast-path invariants: {time.perf_counter() - t0:.1f} s")
    results.elapsed = time.perf_counter() - start
    return results
