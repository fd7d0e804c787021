"""The fast path: compiled closed form = the project's closed form, scipy's DOP853 step for step,
agreement with the high-precision reference, ensembles = single runs, and the scene invariants."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pendverify import fastpath, fixedstep, kernels, reference, taylor
from pendverify.analytic import MODELS
from pendverify.dynamics import build_dynamics
from pendverify.fastpath import FastPathError, FastSystem
from pendverify.scene import load_scene, parse_scene
from pendverify.workprecision import make_problem

from .conftest import SEED, assert_close, default_params

REPO = Path(__file__).resolve().parents[1]
RHS_RTOL = 1e-12  # two evaluations of the same closed form in a different order
STEP_RTOL = 1e-11  # the same DOP853 steps, stage sums rounded in a different order
ACCURACY_FACTOR = 100.0  # stated accuracy: final error ≤ 100 · rtol · (1 + ‖x‖∞) for rtol ≤ 1e-8, T ≤ 2 s
REF_DIGITS = (20, 26)


@pytest.fixture(autouse=True)
def _cache(tmp_path, monkeypatch):
    monkeypatch.setenv("PENDVERIFY_CACHE", str(tmp_path / "cache"))


def _forced_system(model):
    """The model with friction and a state feedback on every input."""
    rng = np.random.default_rng(SEED)
    B = model.input_matrix()
    K = rng.normal(size=(B.shape[1], 2 * model.nv))
    u0 = rng.normal(size=B.shape[1])
    return FastSystem.from_model(model, D=np.diag(model.damping_matrix()), B=B, K=K, u0=u0)


@pytest.mark.parametrize("name", tuple(MODELS))
@pytest.mark.parametrize("forced", [False, True], ids=["free", "forced"])
def test_compiled_rhs_is_the_closed_form(name, forced):
    model = MODELS[name](default_params(name))
    system = _forced_system(model) if forced else FastSystem.from_model(model)
    rng = np.random.default_rng(SEED)
    for _ in range(50):
        x = rng.uniform(-3, 3, 2 * model.nv)
        q, v = x[: model.nv], x[model.nv :]
        tau = system.B @ (system.u0 - system.K @ x) - system.D * v
        expected = model.inverse_mass_matrix(q) @ (tau - model.bias(q, v))
        assert_close(system.rhs(x)[model.nv :], expected, RHS_RTOL, f"{name=} {forced=} {x=}")
        generic = taylor.field(taylor.float_system(system), list(x))
        assert_close(generic, system.rhs(x), RHS_RTOL, f"reference field {name=} {x=}")


def test_work_rates_are_the_simulators():
    doc = {
        "model": "double_pendulum",
        "initial": {"q": [0.3, 0.4]},
        "time": {"duration": 1.0},
        "integrator": {"method": "DOP853"},
        "effects": {
            "gravity": True,
            "damping": True,
            "actuation": {"type": "pd", "kp": [2.0, 1.0], "kd": [0.3, 0.2], "target": [1.0, 0.5]},
        },
    }
    dyn = build_dynamics(parse_scene(doc, "<test>"), "closed_form")
    system = FastSystem.from_dynamics(dyn)
    rng = np.random.default_rng(SEED)
    for _ in range(20):
        x = np.append(rng.uniform(-2, 2, 4), [0.0, 0.0])
        assert_close(system.rhs(x), dyn.rhs(0.0, x), RHS_RTOL, f"{x=}")


@pytest.mark.parametrize("key", ["chaotic", "cart_lqr"])
def test_dop853_takes_scipys_steps(key):
    problem = make_problem(key, 1.0)
    grid = problem.grid
    for tol in (1e-5, 1e-9):
        ours = fastpath.integrate(problem.fast, problem.x0, 1.0, tol, tol)
        theirs = solve_ivp(problem.fast.scipy_rhs(), (0, 1.0), problem.x0, "DOP853", rtol=tol, atol=tol)
        assert (ours.nfev, ours.steps) == (theirs.nfev, len(theirs.t) - 1), f"{key=} {tol=}"
        assert_close(ours.x, theirs.y[:, -1], STEP_RTOL, f"{key=} {tol=}")
        dense = fastpath.integrate(problem.fast, problem.x0, 1.0, tol, tol, t_out=grid)
        sol = solve_ivp(
            problem.fast.scipy_rhs(), (0, 1.0), problem.x0, "DOP853", rtol=tol, atol=tol, dense_output=True
        )
        assert_close(dense.dense, sol.sol(grid).T, STEP_RTOL, f"dense output {key=} {tol=}")


@pytest.mark.parametrize("key, duration", [("mild", 2.0), ("chaotic", 1.0), ("cart_lqr", 2.0)])
def test_fast_path_agrees_with_the_reference_to_its_stated_accuracy(key, duration):
    problem = make_problem(key, duration, 16)
    ref = reference.reference(problem.fast, problem.x0, duration, problem.grid, *REF_DIGITS)
    assert ref.error_bound < 1e-18, ref.describe()
    for tol in (1e-8, 1e-10, 1e-12):
        res = fastpath.integrate(problem.fast, problem.x0, duration, tol, tol, t_out=problem.grid)
        stated = ACCURACY_FACTOR * tol * (1 + np.max(np.abs(ref.hi)))
        err = ref.final_error(res.x)
        assert err <= stated, f"{key=} {tol=}: final error {err:.2e} > {stated:.2e}"
        assert np.all(np.isfinite(res.dense))


def test_headline_accuracy_on_the_chaotic_pendulum():
    """The README's claim: rtol = atol = 1e-11 reaches a final error ≤ 1e-10 over T = 2 s."""
    problem = make_problem("chaotic", 2.0, 4)
    ref = reference.reference(problem.fast, problem.x0, 2.0, problem.grid, *REF_DIGITS)
    res = fastpath.integrate(problem.fast, problem.x0, 2.0, 1e-11, 1e-11)
    assert ref.final_error(res.x) <= 1e-10, ref.final_error(res.x)


def test_reference_is_cached_under_the_problem_hash():
    problem = make_problem("chaotic", 0.2, 4)
    first = reference.reference(problem.fast, problem.x0, 0.2, problem.grid, 16, 20)
    again = reference.reference(problem.fast, problem.x0, 0.2, problem.grid, 16, 20)
    assert not first.cached and again.cached
    assert np.array_equal(first.hi, again.hi) and np.array_equal(first.lo, again.lo)
    moved = problem.x0 + np.array([1e-15, 0, 0, 0])
    assert reference.problem_key(problem.fast, moved, 0.2, problem.grid, 16, 20) != first.key
    # the double-double reference reproduces itself exactly
    assert np.all(first.errors(first.hi) <= np.abs(first.lo))


def test_energy_of_the_reference_is_the_models():
    model = MODELS["cart_double_pendulum"](default_params("cart_double_pendulum"))
    system = FastSystem.from_model(model)
    rng = np.random.default_rng(SEED)
    offsets = []
    for _ in range(10):
        x = rng.uniform(-2, 2, 6)
        e = taylor.energy_above_minimum(taylor.float_system(system), list(x))
        offsets.append(e - model.kinetic_energy(x[:3], x[3:]) - model.potential_energy(x[:3]))
    assert np.ptp(offsets) < 1e-12, "E − V_min must differ from the model's E by a constant"
    x0 = rng.uniform(-1, 1, 6)
    assert reference.relative_energy_error(system, x0, x0)[0] == 0.0


def test_ensemble_is_the_single_runs():
    problem = make_problem("chaotic", 0.5)
    X0 = problem.x0 + np.random.default_rng(SEED).uniform(-0.05, 0.05, (6, 4)) * [1, 1, 0, 0]
    X, nfev = fastpath.integrate_ensemble(problem.fast, X0, 0.5, 1e-9, 1e-9, threads=2)
    for i, x0 in enumerate(X0):
        single = fastpath.integrate(problem.fast, x0, 0.5, 1e-9, 1e-9)
        assert np.array_equal(X[i], single.x) and nfev[i] == single.nfev, f"member {i}"


@pytest.mark.parametrize("name", ["chaotic_double_pendulum", "damped_double_pendulum", "cart_rods_falling"])
def test_fast_path_passes_the_simulators_invariants(name):
    run = fastpath.simulate(load_scene(REPO / "scenes" / f"{name}.toml"))
    assert run.invariants, name
    assert run.passed, [(i.name, i.error, i.tolerance) for i in run.invariants]
    assert np.all(np.isfinite(run.x))


@pytest.mark.parametrize(
    "name, key",
    [("torque_driven_double_pendulum", "effects.actuation"), ("cart_lqr_push", "effects.disturbance")],
)
def test_time_varying_effects_are_refused_by_name(name, key):
    with pytest.raises(FastPathError, match=key):
        fastpath.simulate(load_scene(REPO / "scenes" / f"{name}.toml"))


def test_cached_kernels_are_current():
    """numba's cache checks only a function's own file: modules that inline the kernels record their stamp."""
    stamp = kernels.source_stamp()
    for module in (fastpath, fixedstep):
        assert module.KERNELS_STAMP == stamp, (
            f"pendverify.kernels changed: set KERNELS_STAMP = {stamp!r} in {module.__name__}"
        )
        assert module.CACHE
