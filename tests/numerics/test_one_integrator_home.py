"""One home for the integrators: RK4 is defined once (its tableau), and every RK4 in the package is
that tableau run by the one stepper, giving the numbers the hand-written method gave; Störmer–Verlet
and backward Euler are written once, in ``numerics.integrators.model_runs``.

Tolerances.  The tableau-driven step performs, operation for operation, the classical
x + h/6 (k1 + 2 k2 + 2 k3 + k4) with x + ½h k_i formed as h·(½ k_i) — the same rounding, a
product by ½ being exact — except that the last stage's time is t + 1·h where a driver
stepping over a grid wrote t_{n+1}; the two differ by at most one ulp of t_{n+1}, which
moves k4 by ≤ |∂f/∂t|·ulp(t_{n+1}) and x_new by h/6 of that.  So one step agrees to
``ROUNDING``·ε·max(1, ‖x_new‖∞) (one rounding of the final sum, with room for that
stage-time ulp on the forced systems below, whose |∂f/∂t| h ≤ ‖x‖).  Whole runs are compared
step by step, each classical step taken from the run's own previous state, so that no
difference is carried from one step to the next.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import (
    EULER,
    RK4,
    TABLEAUX,
    Tableau,
    explicit_rk_step,
    fixedstep_runner,
    model_runs,
)
from pendverify.simulation.integrate import integrate
from pendverify.simulation.scene import Integrator

from ..conftest import SEED, default_params

REPO = Path(__file__).resolve().parents[2]
PACKAGE = ("verify", "analytic", "viz")
HOME = REPO / "verify" / "numerics" / "integrators" / "tableaux.py"
RUNS_HOME = REPO / "verify" / "numerics" / "integrators" / "model_runs.py"
EPS = float(np.finfo(float).eps)
ROUNDING = 4

# --- a second RK4 anywhere in the package ------------------------------------------------------
#: what a hand-written RK4 leaves in the source: its fourth stage, its weights, its stability polynomial
RK4_SIGNS = (
    re.compile(r"\bk4\b"),
    re.compile(r"\b2(\.0)?\s*\*\s*k2\b"),
    re.compile(r"\(\s*1(\.0)?\s*,\s*2(\.0)?\s*,\s*2(\.0)?\s*,\s*1(\.0)?\s*\)"),
    re.compile(r"1\s*/\s*6(\.0)?\s*,\s*1\s*/\s*3(\.0)?\s*,\s*1\s*/\s*3(\.0)?\s*,\s*1\s*/\s*6"),
    re.compile(r"z\s*\*\*\s*4\s*/\s*24"),
)


#: what a hand-written Störmer–Verlet leaves: a function named for it, its half-step momentum, its
#: half kick p − ½h·∂H/∂q
STORMER_VERLET_SIGNS = (
    re.compile(r"def\s+\w*(verlet|leapfrog)\w*\s*\(", re.IGNORECASE),
    re.compile(r"\bp_?(half|½)\b"),
    re.compile(r"-\s*0\.5\s*\*\s*h\s*\*"),
)
#: what a hand-written backward Euler leaves: a function named for it, its residual y − x − h·f(y)
IMPLICIT_EULER_SIGNS = (
    re.compile(r"def\s+\w*(implicit|backward)_euler\w*\s*\(", re.IGNORECASE),
    re.compile(r"\b(\w+)\s*-\s*\w+\s*-\s*h\s*\*\s*\w+\(\1\)"),
)


def definitions(roots, signs=RK4_SIGNS) -> list[str]:
    """``path:line: text`` of every line under ``roots`` (Python files) bearing one of ``signs``."""
    found = []
    for root in roots:
        for path in sorted(Path(root).rglob("*.py")):
            for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if any(sign.search(line) for sign in signs):
                    found.append(f"{path}:{number}: {line.strip()}")
    return found


def test_rk4_is_defined_once_by_its_tableau():
    found = definitions(REPO / name for name in PACKAGE)
    assert len(found) == 1 and found[0].startswith(f"{HOME}:"), "RK4 written out again:\n" + "\n".join(found)


def test_the_search_finds_a_hand_written_rk4(tmp_path):
    """Planted: the classical method as the stress suite and the scene driver had it."""
    (tmp_path / "clean.py").write_text("x = x + h * f(x)\n")
    assert definitions([tmp_path]) == []
    (tmp_path / "stepper.py").write_text(
        "k1 = f(x)\nk2 = f(x + 0.5 * h * k1)\nk3 = f(x + 0.5 * h * k2)\nk4 = f(x + h * k3)\n"
        "x = x + (h / 6) * (k1 + 2 * k2 + 2 * k3 + k4)\n"
    )
    assert len(definitions([tmp_path])) == 2  # the fourth stage and the update
    (tmp_path / "stepper.py").write_text("B = np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6])\n")
    assert len(definitions([tmp_path])) == 1


@pytest.mark.parametrize(
    "signs", [STORMER_VERLET_SIGNS, IMPLICIT_EULER_SIGNS], ids=["Störmer–Verlet", "implicit Euler"]
)
def test_stormer_verlet_and_implicit_euler_are_written_once(signs):
    found = definitions((REPO / name for name in PACKAGE), signs)
    assert found, "the search no longer finds the method in its home"
    elsewhere = [line for line in found if not line.startswith(f"{RUNS_HOME}:")]
    assert not elsewhere, "written again outside numerics/integrators/model_runs.py:\n" + "\n".join(elsewhere)


def test_the_search_finds_a_hand_written_stormer_verlet_and_implicit_euler(tmp_path):
    """Planted: the two methods as the stress suite had them, each under another name."""
    (tmp_path / "clean.py").write_text("x = x + h * f(x)\nq_new = q + h * v\n")
    assert definitions([tmp_path], STORMER_VERLET_SIGNS + IMPLICIT_EULER_SIGNS) == []
    (tmp_path / "leap.py").write_text(
        "def step(q, p):\n    ph = p - 0.5 * h * grad(q)\n    q = q + h * solve(M(q), ph)\n"
        "    return q, ph - 0.5 * h * grad(q)\n"
    )
    assert len(definitions([tmp_path], STORMER_VERLET_SIGNS)) == 2  # the two half kicks
    (tmp_path / "backward.py").write_text("def advance(x):\n    G = z - x - h * rhs(z)\n")
    assert len(definitions([tmp_path], IMPLICIT_EULER_SIGNS)) == 1
    (tmp_path / "named.py").write_text("def backward_euler(f, x, h):\n    pass\n")
    assert len(definitions([tmp_path], IMPLICIT_EULER_SIGNS)) == 2


# --- the tableaux -----------------------------------------------------------------------------
def test_stability_functions_are_the_methods_polynomials():
    z = np.array([0.1, -1.0, -2.7 + 0.5j, 1.5j, -3.0])
    assert np.max(np.abs(RK4.stability(z) - (1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24))) <= 10 * EPS * 30
    assert np.max(np.abs(EULER.stability(z) - (1 + z))) <= 2 * EPS * 4


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (dict(weights=(1.0, 2.0, 2.0, 2.0)), "weights sum to 7.0, not 6.0"),
        (dict(c=(0.0, 0.5, 0.5, 0.5)), "c_4 = 0.5 is not the sum of row 4"),
        (dict(a=((), (0.5,), (0.0, 0.5), (0.0, 1.0))), "row 4 of a has 2 entries, expected 3"),
    ],
)
def test_an_inconsistent_tableau_is_refused(change, message):
    fields = dict(
        name="planted", order=4, a=RK4.a, c=RK4.c, weights=RK4.weights, denominator=6.0, reference=""
    )
    with pytest.raises(ValueError, match=re.escape(message)):
        Tableau(**{**fields, **change})


@pytest.mark.parametrize("name", sorted(TABLEAUX))
def test_each_tableau_converges_at_its_order(name):
    """x'' = −x from (1, 0) to T = 1: the error ratio between h and h/2 is 2^p (1 + O(h))."""
    tableau = TABLEAUX[name]

    def error(n):
        x, h = np.array([1.0, 0.0]), 1.0 / n
        for i in range(n):
            x = explicit_rk_step(lambda t, x: np.array([x[1], -x[0]]), i * h, x, h, tableau)
        return np.max(np.abs(x - [np.cos(1.0), -np.sin(1.0)]))

    n = 64 if tableau.order > 2 else 2048  # in the asymptotic range, far above rounding
    assert abs(np.log2(error(n) / error(2 * n)) - tableau.order) < 0.1


# --- equal to the hand-written RK4 ------------------------------------------------------------
def classical_rk4_step(f, t, x, t_next):
    """The method as the scene driver wrote it (stage times t + dt/2 and the grid's t_next)."""
    dt = t_next - t
    k1 = f(t, x)
    k2 = f(t + dt / 2, x + dt / 2 * k1)
    k3 = f(t + dt / 2, x + dt / 2 * k2)
    k4 = f(t_next, x + dt * k3)
    return x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)


_A6 = np.random.default_rng(SEED).normal(size=(6, 6))
SYSTEMS = {  # (f(t, x), dimension)
    "oscillator": (lambda t, x: np.array([x[1], -4.0 * x[0]]), 2),
    "damped pendulum": (lambda t, x: np.array([x[1], -9.81 * np.sin(x[0]) - 0.3 * x[1]]), 2),
    "forced Duffing": (
        lambda t, x: np.array([x[1], -0.2 * x[1] + x[0] - x[0] ** 3 + 0.3 * np.cos(1.2 * t)]),
        2,
    ),
    "forced linear": (lambda t, x: _A6 @ x + np.sin(3.0 * t) * np.ones(6), 6),
}


@pytest.mark.parametrize("system", sorted(SYSTEMS))
def test_one_tableau_step_is_the_classical_step(system):
    f, n = SYSTEMS[system]
    rng = np.random.default_rng(SEED)
    worst = 0.0
    for _ in range(200):
        x, t, h = rng.uniform(-2, 2, n), rng.uniform(0, 10), rng.uniform(1e-3, 0.1)
        expected = classical_rk4_step(f, t, x, t + h)
        got = explicit_rk_step(f, t, x, (t + h) - t, RK4)
        worst = max(worst, np.max(np.abs(got - expected)) / max(1.0, np.max(np.abs(expected))))
    assert worst <= ROUNDING * EPS, f"{system}: {worst / EPS:.2f} ε"


def test_the_step_comparison_sees_another_method():
    """Planted: RK4 with its last stage taken from k2 and k3 (consistent, order below 4)."""
    other = Tableau(
        "planted", 3, ((), (0.5,), (0.0, 0.5), (0.0, 0.5, 0.5)), RK4.c, RK4.weights, 6.0, "planted"
    )
    f, _ = SYSTEMS["damped pendulum"]
    x, t, h = np.array([0.4, -0.3]), 0.0, 0.05
    expected = classical_rk4_step(f, t, x, t + h)
    assert np.max(np.abs(explicit_rk_step(f, t, x, h, other) - expected)) > 1e3 * ROUNDING * EPS


@pytest.mark.parametrize("system", sorted(SYSTEMS))
def test_the_scene_driver_takes_the_classical_steps(system):
    """``simulation.integrate`` with rk4 (h = 5e-3 on its grid of 20 progress chunks, T = 0.5): each
    step the classical step from the run's own previous state, so no difference is carried."""
    f, n = SYSTEMS[system]
    x0, T = np.linspace(0.3, -0.4, n), 0.5
    run = integrate(f, x0, T, Integrator("rk4", step=5e-3), np.array([T]))
    assert len(run.steps_t) == 101
    for i in range(len(run.steps_t) - 1):
        expected = classical_rk4_step(f, run.steps_t[i], run.steps_x[i], run.steps_t[i + 1])
        error = np.max(np.abs(run.steps_x[i + 1] - expected))
        assert error <= ROUNDING * EPS * max(1.0, np.max(np.abs(expected))), f"{system} step {i}"


def test_the_model_runs_rk4_takes_the_classical_steps():
    model = MODELS["double_pendulum"](default_params("double_pendulum"))
    f = model_runs.state_derivative_of(model)
    q0, v0, h, n = np.array([0.4, -0.3]), np.array([0.2, 0.1]), 2e-3, 250
    run = model_runs.rk4(model, q0, v0, h, n)
    xs = np.column_stack([run.q, run.v])
    assert len(xs) == n + 1 and run.evaluations == RK4.stages * n
    for i in range(n):
        expected = classical_rk4_step(lambda t, x: f(x), 0.0, xs[i], h)  # autonomous: t is read by none
        error = np.max(np.abs(xs[i + 1] - expected))
        assert error <= ROUNDING * EPS * max(1.0, np.max(np.abs(expected))), f"step {i}"


# --- the compiled fast path runs the same tableaux --------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("model_name", sorted(MODELS))
@pytest.mark.parametrize("name", sorted(TABLEAUX))
def test_the_compiled_methods_take_the_tableau_steps(model_name, name):
    """``fixedstep_runner.integrate_fixed`` against ``explicit_rk_step`` on the generated module's
    own compiled ``_rhs``, each step from the compiled run's previous state."""
    model = MODELS[model_name](default_params(model_name))
    system = GeneratedSystem.from_model(model)
    packed, rhs = system.packed(), system.kernel.module._rhs

    def f(t, x):
        out = np.empty_like(x)
        rhs(packed, x, out)
        return out

    steps, T = 100, 0.5
    xs, nfev, ok = fixedstep_runner.integrate_fixed(name, system, np.full(2 * model.nv, 0.3), T, steps)
    assert ok and nfev == TABLEAUX[name].stages * steps
    for i in range(steps):
        expected = explicit_rk_step(f, 0.0, xs[i], T / steps, TABLEAUX[name])
        error = np.max(np.abs(xs[i + 1] - expected))
        assert error <= ROUNDING * EPS * max(1.0, np.max(np.abs(expected))), f"{model_name} {name} step {i}"
