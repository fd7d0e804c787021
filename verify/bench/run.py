"""The whole work–precision study, in the order it must run.

1. the references of every state problem (and of the checked ensemble members),
   from the cache or computed in parallel processes — before any timing;
2. generation (or cache load) of the models' modules and compilation of their numba
   functions, timed apart;
3. the sweeps (``pendverify.bench.workprecision``), the observed orders;
4. the fast path against scipy: the single-trajectory ratio from the sweeps,
   the engine costs and the ensemble at the tolerance where scipy DOP853 first
   reaches the target error (``pendverify.bench.fast``);
5. the fast path's invariant checks on the state problems.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, field

import numpy as np

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
from pendverify.numerics import fixedstep


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
    invariants: list = field(default_factory=list)  # (problem, InvariantResult)
    engine_tolerance: float = math.nan  # rtol = atol of the engine and ensemble studies
    compile_seconds: float = 0.0
    reference_seconds: float = 0.0
    elapsed: float = 0.0

    def smallest_error(self) -> float:
        errs = [p.final_error for p in self.points if p.ok and p.problem != "long" and p.final_error > 0]
        errs += [p.max_error for p in self.points if p.ok and p.problem != "long" and p.max_error > 0]
        return min(errs) if errs else math.nan

    def largest_reference_bound(self) -> float:
        return max((r.error_bound for r in self.references.values()), default=math.nan)


def run_sweeps(problems, references, config: Config, log=print) -> list[Point]:
    from pendverify.simulation.engines import build

    points: list[Point] = []
    for problem in problems:
        ref = references.get(problem.key)
        start = time.perf_counter()
        points += fast_sweep(problem, config.tolerances, config, ref)
        spent = {"fast path": time.perf_counter() - start}
        if problem.metric == "state":
            rhs = build("aba", problem.dynamics.model, problem.fast)
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
    config: Config, log=print, blas: str = "not limited", workers: int | None = None
) -> Results:
    """Everything ``pendverify bench accuracy`` reports, measured in this process."""
    from pendverify.bench import fast as fastbench
    from pendverify.numerics import fastpath
    from pendverify.numerics.reference import references

    start = time.perf_counter()
    problems = make_problems(config)
    by_key = {p.key: p for p in problems}
    state = [p for p in problems if p.metric == "state"]
    chaotic = by_key.get("chaotic")
    jobs = [(p.fast, p.x0, p.duration, p.grid) for p in state]
    members = []
    if chaotic is not None and config.ensemble_size > 0:
        members = list(fastbench.ensemble_states(chaotic, config)[1 : config.ensemble_checked])
        jobs += [(chaotic.fast, x, chaotic.duration, np.array([0.0, chaotic.duration])) for x in members]
    log(f"references: {len(jobs)} problems at {config.digits[0]} and {config.digits[1]} digits")
    t0 = time.perf_counter()
    refs = references(jobs, *config.digits, workers=workers or os.cpu_count() or 1)
    results = Results(
        config,
        machine_info(blas),
        problems,
        {p.key: r for p, r in zip(state, refs[: len(state)], strict=True)},
    )
    results.reference_seconds = time.perf_counter() - t0
    results.compile_seconds = fastpath.warm_up() + fixedstep.warm_up()
    log(f"generated back ends compiled or loaded in {results.compile_seconds:.1f} s; sweeping")
    results.points = run_sweeps(problems, results.references, config, log)
    results.orders = order_fits(results.points)
    if chaotic is not None:
        results.single = fastbench.single_ratio(results.points, "chaotic", config.target_error)
        anchor = results.single.scipy or results.single.fast
        tol = anchor.setting if anchor is not None else min(config.tolerances)
        results.engine_tolerance = tol
        t0 = time.perf_counter()
        for key in config.engine_problems:
            if key in by_key:
                results.engines += fastbench.engine_study(by_key[key], tol, config, results.references[key])
        log(f"engines at rtol = atol = {tol:g}: {time.perf_counter() - t0:.1f} s")
        if config.ensemble_size > 0:
            t0 = time.perf_counter()
            member_refs = [results.references["chaotic"], *refs[len(state) :]]
            results.ensemble = fastbench.ensemble_study(chaotic, tol, config, member_refs)
            log(f"ensemble of {config.ensemble_size}: {time.perf_counter() - t0:.1f} s")
    t0 = time.perf_counter()
    results.invariants = fastbench.fast_invariants(problems)
    log(f"fast-path invariants: {time.perf_counter() - t0:.1f} s")
    results.elapsed = time.perf_counter() - start
    return results
