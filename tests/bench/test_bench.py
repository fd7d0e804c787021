"""``pendverify bench accuracy --quick`` end to end on a small configuration: outputs written,
errors fall as tolerances tighten, fixed-step orders match theory, references are accurate enough.
No test looks at a wall time."""

from __future__ import annotations

import csv
import io
import itertools
import math
from dataclasses import replace

import numpy as np
import pytest

from pendverify.bench import run as benchrun
from pendverify.bench import workprecision
from pendverify.bench.report import ratios
from pendverify.cli import main
from pendverify.simulation import engines
from pendverify.simulation.engine_names import RHS_ENGINES

ORDER_TOLERANCE = 0.3
REFERENCE_MARGIN = 1000.0
ENGINE_RTOL = 1e-12  # every engine computes the same q̈ (ε-level, relative to max(1, |q̈|))

SMALL = replace(
    workprecision.QUICK,
    name="test",
    horizons={"mild": 1.0, "chaotic": 0.5, "cart_lqr": 1.0, "long": 20.0},
    tolerances=(1e-4, 1e-7, 1e-10),
    other_tolerances=(1e-4, 1e-7),
    fixed={
        "euler": (2.0**-7, 6),
        "symplectic_euler": (2.0**-7, 6),
        "implicit_midpoint": (2.0**-5, 6),
        "rk4": (2.0**-4, 5),
    },
    long_fixed={"symplectic_euler": (2.0**-4, 2), "implicit_midpoint": (2.0**-4, 2), "rk4": (2.0**-3, 2)},
    repeats=1,
    run_budget=0.5,
    grid_intervals=16,
    digits=(20, 26),
    ensemble_size=16,
    ensemble_checked=2,
    engine_problems=("chaotic",),
    ensemble_variants=("threads", "serial", "vectorised"),
)


def run_quick(argv: list[str], config):
    """(exit status, the Results it measured) of ``pendverify bench accuracy --quick ARGV`` with
    ``config`` in place of QUICK (on the run's generated-code cache, ``conftest``)."""
    captured = {}
    real = benchrun.run_benchmark

    def keep(*args, **kwargs):
        captured["results"] = real(*args, **kwargs)
        return captured["results"]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(workprecision, "QUICK", config)
        mp.setattr(benchrun, "run_benchmark", keep)
        status = main(["bench", "accuracy", "--quick", *argv])
    return status, captured["results"]


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    """Run the CLI once in --quick mode, with the small configuration; keep what it measured."""
    out = tmp_path_factory.mktemp("bench")
    status, results = run_quick(["-o", str(out)], SMALL)
    return status, out, results


@pytest.mark.slow
def test_quick_run_writes_plot_csv_and_table(bench):
    status, out, results = bench
    assert status == 0
    png = (out / "work_precision.png").read_bytes()
    assert png.startswith(b"\x89PNG"), "not a PNG"
    rows = list(csv.DictReader(io.StringIO((out / "work_precision.csv").read_text())))
    assert len(rows) == len(results.points)
    assert {r["problem"] for r in rows} == set(SMALL.horizons)
    table = (out / "work_precision.md").read_text()
    for heading in ("The fast path against scipy", "Dynamics engines", "observed order", "References"):
        assert heading in table, heading
    assert set(ratios(results)) == {"single", "ensemble"}


def _series(results, problem, method):
    pts = [p for p in results.points if p.problem == problem and p.method == method and p.ok]
    return sorted(pts, key=lambda p: -p.setting)


@pytest.mark.slow
@pytest.mark.parametrize("method", ["DOP853 (fast path)", "DOP853 (scipy)", "RK45 (scipy)", "LSODA (scipy)"])
@pytest.mark.parametrize("problem", ["mild", "chaotic", "cart_lqr"])
def test_errors_decrease_as_tolerances_tighten(bench, problem, method):
    pts = _series(bench[2], problem, method)
    assert len(pts) >= 2, f"{problem=} {method=}: fewer than two tolerances measured"
    errors = [p.final_error for p in pts]
    assert all(np.isfinite(errors)), f"{problem=} {method=} {errors=}"
    assert all(b < a for a, b in itertools.pairwise(errors)), f"{problem=} {method=} {errors=}"


@pytest.mark.slow
def test_energy_error_of_the_long_run_falls_with_tolerance(bench):
    errors = [p.energy_max for p in _series(bench[2], "long", "DOP853 (fast path)")]
    assert all(b < a for a, b in itertools.pairwise(errors)), errors


@pytest.mark.slow
@pytest.mark.parametrize("method", sorted(workprecision.FIXED_METHODS))
@pytest.mark.parametrize("problem", ["mild", "cart_lqr"])
def test_observed_orders_match_theory(bench, problem, method):
    (fit,) = [o for o in bench[2].orders if o.problem == problem and o.method == method]
    assert fit.points >= 3, f"{problem=} {method=}: only {fit.points} errors in the asymptotic window"
    assert abs(fit.observed - fit.theory) <= ORDER_TOLERANCE, f"{problem=} {method=} {fit=}"


@pytest.mark.slow
def test_references_are_a_thousand_times_more_accurate_than_any_error(bench):
    results = bench[2]
    assert results.smallest_error() / results.largest_reference_bound() >= REFERENCE_MARGIN


@pytest.mark.slow
def test_fast_path_and_scipy_dop853_agree_at_every_tolerance(bench):
    """Same algorithm, same steps: the fast path's errors are scipy DOP853's (the engine differs by rounding).

    Double pendulum only: Pinocchio's joint angles are the model's there, so the
    error norms, hence the steps, coincide (the cart's joint 2 measures θ2 − θ1).
    """
    results = bench[2]
    for problem in ("mild", "chaotic"):
        fast = {p.setting: p for p in _series(results, problem, "DOP853 (fast path)")}
        for p in _series(results, problem, "DOP853 (scipy)"):
            ours = fast[p.setting]
            assert math.isclose(ours.final_error, p.final_error, rel_tol=0.1, abs_tol=1e-12), (
                problem,
                p.setting,
            )


@pytest.mark.slow
def test_ensemble_is_as_accurate_as_scipy_on_each_member(bench):
    """ "At the same accuracy": each member as accurate as scipy DOP853 + aba run on it alone."""
    rows = {row.variant: row for row in bench[2].ensemble}
    (alone,) = [rows.pop(v) for v in list(rows) if v.startswith("scipy DOP853 + aba")]
    assert alone.checked == SMALL.ensemble_checked and np.isfinite(alone.max_error)
    assert len(rows) == 3, list(rows)
    for name, row in rows.items():
        assert row.size == SMALL.ensemble_size and row.checked == SMALL.ensemble_checked, row
        if name.startswith("fast path"):
            assert math.isclose(row.max_error, alone.max_error, rel_tol=0.1, abs_tol=1e-12), (row, alone)
        assert np.isfinite(row.max_error), row


@pytest.mark.slow
def test_fast_path_passes_the_invariants(bench):
    checked = bench[2].invariants
    assert {key for key, _, _ in checked} == {"mild", "chaotic", "cart_lqr"}
    for key, invariants, _ in checked:
        assert invariants and all(i.passed for i in invariants), (key, invariants)


@pytest.mark.parametrize("key", ["chaotic", "cart_lqr"])
def test_every_engine_computes_the_same_acceleration(key):
    problem = workprecision.make_problem(key, 1.0)
    rng = np.random.default_rng(7)
    n = problem.fast.nv
    built = {name: engines.build(name, problem.dynamics.model, problem.fast) for name in RHS_ENGINES}
    for _ in range(10):
        x = rng.uniform(-2, 2, 2 * n)
        expected = built["compiled"].fun(0.0, x)
        for name, rhs in built.items():
            xdot = rhs.fun(0.0, rhs.to_engine(x))
            # ẋ maps like a velocity: the linear part of to_model
            got = rhs.to_model(xdot) - rhs.to_model(np.zeros_like(xdot))
            err = np.max(np.abs(got - expected) / np.maximum(1.0, np.abs(expected)))
            assert err <= ENGINE_RTOL, f"{key=} {name=} {x=}: {err:.2e}"


def test_step_counts_halve_the_step():
    counts = workprecision.step_counts(2.0, 2.0**-4, 3, 16)
    assert counts == [32, 64, 128, 256]
    assert all(2.0 / c <= 2.0**-4 for c in counts)
