"""The back ends generated from the model besides ``_rhs``: the Hamiltonian form and the fixed-step
methods, the generic field and energy of the Taylor references, V_min, plug-in scenes.

Every check below is paired with a planted error it must catch.  Bounds are first-order
rounding bounds in u = ε/2 (Higham, §3.1: a sum of products with k roundings is within
γ_k·|e| of exact, |e| the expression with every term replaced by its magnitude), as in
``tests/numerics/test_generate.py``, whose exact reference and bound β they reuse.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from pendverify.analytic import MODELS
from pendverify.bench.workprecision import make_problem
from pendverify.checks.sampling import sample_states
from pendverify.errors import PendverifyError
from pendverify.numerics import reference
from pendverify.numerics.codegen.expressions import expressions, momentum_rate
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import dop853_runner, fixedstep, fixedstep_runner, taylor
from pendverify.simulation import compiled_scene
from pendverify.simulation.scene import load_scene

from .test_generate import (
    SEED,
    WHEEL,
    Reference,
    WheelPole,
    _cache,  # noqa: F401 - the module-scoped cache fixture (autouse), shared
    _example,
    _forces,
    _gamma,
    _magnitude,
    _seed,
    planted_cart_pole,
)

REPO = Path(__file__).resolve().parents[2]
EPS = np.finfo(float).eps
STATES = 12
CASES = ["double_pendulum", "cart_double_pendulum", "cart_pole", "triple_pendulum"]


def _model(case: str):
    return _seed(case) if case in MODELS else _example(REPO / "examples" / f"{case}.py")


def _with_g(system: GeneratedSystem, factor: float) -> GeneratedSystem:
    params = system.params.copy()
    params[system.kernel.parameters.index("g")] *= factor
    return dataclasses.replace(system, params=params)


# --- the Hamiltonian form ---------------------------------------------------------------------
class _Canonical:
    """_to_momentum then _hamilton at a state, against the exact values and their bounds.

    q̇.  p̂ = Σ_j m̂_ij v_j has k_M + n roundings (k_M ≥ the operations of an entry of M); _hamilton
    evaluates M again (M̂', within γ_{k_M}|M|) and solves by LDLᵀ, backward stable with
    |ΔM| ≤ γ_{3n+1}|C||Cᵀ| (C the Cholesky factor), so to first order
    |v̂ − v| ≤ β_v = |M⁻¹| (2γ_{k_M + n} |M||v| + γ_{3n+1} |C||Cᵀ||v|).
    ṗ.  At _hamilton's own v̂, ṗ = Ṁ(q, v̂) v̂ − bias(q, v̂) + τ is a sum of products (the
    expression ``momentum_rate``) plus τ: within γ_k (|rate| + |τ|), |rate| its magnitude,
    k its operation count + 6n + 2nu + 8 for τ and the sums (as β of ``test_generate``).
    """

    def __init__(self, model, system: GeneratedSystem):
        self.model, self.system = model, system
        self.ref = Reference(model, expressions(type(model)))
        ex, values = self.ref.ex, self.ref.values
        rate = [r.xreplace(values) for r in momentum_rate(ex)]
        args = (*ex.q, *ex.v)
        self.rate_exact = sp.lambdify(args, rate, modules="mpmath")
        self.rate_abs = sp.lambdify(args, [_magnitude(r) for r in rate])
        self.k_rate = max(sp.count_ops(r) for r in momentum_rate(ex)) + 6 * ex.n + 2 * system.B.shape[1] + 8

    def errors(self, x, hamilton_system: GeneratedSystem | None = None) -> tuple[float, float]:
        """(max |v̂ − v| / β_v, max |ṗ − exact| / bound) at x; _hamilton of ``hamilton_system``."""
        s, n = self.system, self.model.nv
        y, out = np.empty(2 * n), np.empty(2 * n)
        s.module._to_momentum(s.packed(), x, y)
        h = hamilton_system or s
        h.module._hamilton(h.packed(), y, out)
        q, v, vh = x[:n], x[n:], out[:n]
        mass, _, mass_abs, _ = (np.array(a, float) for a in self.ref._float(*x))
        chol = np.abs(np.linalg.cholesky(mass))
        k_m = self.ref.ops + n
        beta_v = np.abs(np.linalg.inv(mass)) @ (
            2 * _gamma(k_m) * mass_abs @ np.abs(v) + _gamma(3 * n + 1) * chol @ chol.T @ np.abs(v)
        )
        xs = np.concatenate([q, vh])
        tau = s.B @ (s.u0 - s.K @ xs) - s.D @ vh
        tau_abs = np.abs(s.B) @ (np.abs(s.u0) + np.abs(s.K) @ np.abs(xs)) + np.abs(s.D) @ np.abs(vh)
        with mpmath.workdps(40):
            exact = np.array([float(r) for r in self.rate_exact(*[mpmath.mpf(float(a)) for a in xs])]) + tau
        bound = _gamma(self.k_rate) * (np.abs(np.array(self.rate_abs(*xs), float)) + 2 * tau_abs)
        return _ratio(np.abs(vh - v), beta_v), _ratio(np.abs(out[n:] - exact), bound)


def _ratio(err, bound) -> float:
    """max err / bound, where a zero bound (at rest, no force: exact zeros) allows only zero."""
    err, bound = np.asarray(err, float), np.asarray(bound, float)
    return float(
        np.max(np.where(bound > 0, err / np.where(bound > 0, bound, 1), np.where(err > 0, np.inf, 0)))
    )


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("forced", [False, True], ids=["free", "forced"])
def test_hamiltonian_form_is_the_models(case, forced):
    model = _model(case)
    system = GeneratedSystem.from_model(model, *_forces(model, forced, np.random.default_rng(SEED)))
    canonical = _Canonical(model, system)
    for state in sample_states(model, STATES, SEED):
        x = np.concatenate([state.q, state.v])
        ev, ep = canonical.errors(x)
        assert ev <= 1.0, f"q̇ of _hamilton: {ev:.3g} β_v {case} {state.label}"
        assert ep <= 1.0, f"ṗ of _hamilton: {ep:.3g} × bound {case} {state.label}"


def test_hamiltonian_checks_catch_planted_errors(tmp_path):
    """A planted M (momentum from the mutant, velocity from the original) and g off by 1e-9."""
    model = _model("cart_pole")
    system = GeneratedSystem.from_model(model)
    planted = GeneratedSystem.from_model(planted_cart_pole(tmp_path))
    canonical = _Canonical(model, system)
    x = np.array([0.1, 0.7, 0.4, -1.2])
    ev, _ = _Canonical(model, planted).errors(x, hamilton_system=system)
    assert ev > 1e3, ev
    _, ep = canonical.errors(x, hamilton_system=_with_g(system, 1 + 1e-9))
    assert ep > 10, ep


# --- the fixed-step methods -------------------------------------------------------------------
STEPS = {"euler": 8000, "symplectic_euler": 8000, "implicit_midpoint": 400, "rk4": 100}


def _fixed_errors(system, reference_system, method: str, x0, T: float) -> tuple[float, float]:
    """(‖x_h − x*‖∞, Richardson estimate E), x* the compiled DOP853 of ``reference_system`` at 1e-13.

    x_h − x* = C h^p + O(h^{p+1}), so E = ‖x_h − x_{h/2}‖∞ / (1 − 2^−p) = ‖C‖ h^p (1 + O(h)) and,
    once h is in the asymptotic range (the O(h) factor below 1: checked by the planted case
    failing by orders of magnitude, not by tuning), ‖x_h − x*‖∞ ≤ 2E + the DOP853 error,
    ≤ 100 · 1e-13 · (1 + ‖x‖∞) (the fast path's stated accuracy)."""
    steps, p = STEPS[method], fixedstep.METHODS[method]
    coarse, _, ok1 = fixedstep_runner.integrate_fixed(method, system, x0, T, steps, steps)
    fine, _, ok2 = fixedstep_runner.integrate_fixed(method, system, x0, T, 2 * steps, 2 * steps)
    assert ok1 and ok2
    exact = dop853_runner.integrate(reference_system, x0, T, 1e-13, 1e-13).x
    estimate = np.max(np.abs(coarse[-1] - fine[-1])) / (1 - 2.0**-p)
    slack = 100 * 1e-13 * (1 + np.max(np.abs(exact)))
    return float(np.max(np.abs(coarse[-1] - exact))), float(2 * estimate + slack)


@pytest.mark.slow
@pytest.mark.parametrize("case", ["double_pendulum", "cart_double_pendulum", "cart_pole"])
@pytest.mark.parametrize("method", tuple(STEPS))
def test_fixed_step_methods_follow_the_models_flow(case, method):
    model = _model(case)
    system = GeneratedSystem.from_model(model, *_forces(model, True, np.random.default_rng(SEED)))
    x0 = np.full(2 * model.nv, 0.3)
    err, bound = _fixed_errors(system, system, method, x0, 0.5)
    assert err <= bound, f"{case} {method}: {err:.3g} > {bound:.3g}"


@pytest.mark.slow
@pytest.mark.parametrize("method", tuple(STEPS))
def test_planted_mass_matrix_changes_the_fixed_step_result(tmp_path, method):
    original = GeneratedSystem.from_model(_model("cart_pole"))
    planted = GeneratedSystem.from_model(planted_cart_pole(tmp_path))
    assert planted.kernel.digest != original.kernel.digest
    x0 = np.array([0.1, 0.7, 0.4, -1.2])
    err, bound = _fixed_errors(planted, original, method, x0, 0.5)
    assert err > 100 * bound, f"{method}: the planted M moves the result by only {err:.3g} ({bound:.3g})"


# --- the generic field and energy -------------------------------------------------------------
def _mp_field(system, x, digits=40):
    with mpmath.workdps(digits):
        numbers = taylor.exact_system(system)
        return np.array([float(a) for a in taylor.field(numbers, [mpmath.mpf(float(v)) for v in x])])


@pytest.mark.parametrize("case", [*CASES, "furuta_pendulum", "hanging_double_pendulum"])
def test_generic_field_on_mpmath_is_the_models_closed_form(case):
    """The generated field in 40-digit mpmath (exact parameters: rounding ≈ 1e-40) is within β of
    ``test_generate``'s reference, and
    the model's own numpy M⁻¹(τ − b) is within β of it (β bounds the float model's rounding)."""
    model = _model(case)
    D, B, K, u0 = _forces(model, True, np.random.default_rng(SEED))
    system = GeneratedSystem.from_model(model, D, B, K, u0)
    ref = Reference(model, expressions(type(model)))
    n, nu = model.nv, system.B.shape[1]
    worst_planted = 0.0
    for state in sample_states(model, STATES, SEED):
        x = np.concatenate([state.q, state.v])
        tau = system.B @ (system.u0 - system.K @ x) - system.D @ state.v
        tau_abs = np.abs(system.B) @ (np.abs(system.u0) + np.abs(system.K) @ np.abs(x)) + np.abs(
            system.D
        ) @ np.abs(state.v)
        exact = ref.exact(x, tau)
        beta = ref.beta(x, exact, tau_abs, nu)
        generic = _mp_field(system, x)
        assert np.array_equal(generic[:n], state.v)
        # test_generate's reference folds parameter products into double Floats (SymPy) before
        # its 40-digit solve: a float evaluation with fewer roundings than β allows for
        assert np.all(np.abs(generic[n:] - exact) <= beta), f"{case} {state.label}"
        own = model.inverse_mass_matrix(state.q) @ (tau - model.bias(state.q, state.v))
        assert np.all(np.abs(own - generic[n:]) <= beta), f"{case} {state.label}"
        planted = _mp_field(_with_g(system, 1 + 1e-9), x) if "g" in system.kernel.parameters else generic
        worst_planted = max(worst_planted, float(np.max(np.abs(own - planted[n:]) / beta)))
    if "g" in system.kernel.parameters:
        assert worst_planted > 1.0, f"g off by 1e-9 is not seen: {worst_planted:.3g} β"


@pytest.mark.parametrize("case", [*CASES, "furuta_pendulum"])
def test_generic_mass_on_mpmath_is_the_models_mass_matrix(case):
    """The generated ``mass`` in 40-digit mpmath is the model's M to its float rounding (M's entries
    are sums of a few products of parameters and cosines: ≤ 16 ε of the largest entry); the
    numbers of another parameter set (every parameter × (1 + 1e-6)) are far off."""
    model = _model(case)
    system = GeneratedSystem.from_model(model)

    def mass(system, q):
        with mpmath.workdps(40):
            numbers = taylor.exact_system(system)
            rows = system.module.mass(
                numbers, [mpmath.mpf(float(v)) for v in q], mpmath.mpf, taylor.series_sincos
            )
            return np.array([[float(m) for m in row] for row in rows])

    moved = dataclasses.replace(system, params=system.params * (1 + 1e-6))
    for state in sample_states(model, 8, SEED):
        M = model.mass_matrix(state.q)
        scale = np.max(np.abs(M))
        assert np.max(np.abs(mass(system, state.q) - M)) <= 16 * EPS * scale, f"{case} {state.label}"
        assert np.max(np.abs(mass(moved, state.q) - M)) > 1e-8 * scale, f"{case} {state.label}"


def test_generic_field_runs_on_float_numpy_decimal_and_mpf():
    """The same code on every number type: float and numpy agree with mpmath to 1e-12 relative (a
    few hundred roundings of a well-conditioned state), Decimal at 30 digits to 1e-25."""
    from decimal import Decimal, localcontext

    model = _seed("cart_double_pendulum")
    system = GeneratedSystem.from_model(model, *_forces(model, True, np.random.default_rng(SEED)))
    x = np.array([0.1, 0.4, -0.3, 0.2, -0.5, 0.7])
    exact = _mp_field(system, x)
    scale = np.max(np.abs(exact))
    as_float = np.array(taylor.field(taylor.float_system(system), list(x)))
    as_numpy = np.array(taylor.field(taylor.float_system(system), [np.array([v, v]) for v in x]))
    assert np.max(np.abs(as_float - exact)) <= 1e-12 * scale
    assert np.max(np.abs(as_numpy[:, 1] - exact)) <= 1e-12 * scale
    with localcontext() as ctx:
        ctx.prec = 30
        dec = taylor.field(taylor.exact_system(system, Decimal), [Decimal(float(v)) for v in x])
        assert all(isinstance(v, Decimal) for v in dec)
        with mpmath.workdps(40):
            precise = taylor.field(taylor.exact_system(system), [mpmath.mpf(float(v)) for v in x])
            assert (
                max(abs(mpmath.mpf(str(a)) - b) for a, b in zip(dec, precise, strict=True)) <= 1e-25 * scale
            )


@pytest.mark.slow
def test_a_function_other_than_sin_and_cos_is_refused_by_the_taylor_path_only():
    class RootPole(WheelPole):
        def gravity(self, q):
            p = self.params
            return np.array([0.0, -self._k() * p.g * self.math.sin(q[1]) * self.math.sqrt(p.mp / p.mc), 0.0])

    model = RootPole(WHEEL)
    system = GeneratedSystem.from_model(model)
    x = np.array([0.1, 0.4, -0.2, 0.3, 0.5, -0.1])
    expected = np.linalg.solve(model.mass_matrix(x[:3]), -model.bias(x[:3], x[3:]))
    assert np.allclose(system.rhs(x)[3:], expected, rtol=1e-12, atol=1e-12)  # the compiled path works
    assert dop853_runner.integrate(system, x, 0.1, 1e-8, 1e-8).x.shape == (6,)
    with pytest.raises(PendverifyError, match="Taylor path"):
        taylor.exact_system(system)
    assert np.isfinite(system.potential_minimum)  # V has no sqrt: the energy still works


# --- V_min ---------------------------------------------------------------------------------------
def _known_minimum(model) -> float:
    p = model.params
    if model.name == "double_pendulum":
        return -abs(p.g * (p.m1 * p.r1 + p.m2 * p.l1)) - abs(p.g * p.m2 * p.r2)
    return -p.g * ((p.m1 + p.m2) * p.l1 + p.m2 * p.l2)


@pytest.mark.parametrize("name", tuple(MODELS))
def test_potential_minimum_of_the_seeds(name):
    """BFGS stops when its forward-difference gradient is ≤ gtol = 1e-5; that gradient is within
    δg = λ_max √ε / 2 + 2ε|V*| / √ε of the true one, and near a non-degenerate minimum
    V − V* ≤ |∇V|² / (2 λ_min) (λ the Hessian's eigenvalues at the minimum).  The value is V at
    a point: never below V* by more than its rounding, 4ε|V*|.  A minimum off by 1e-6 fails."""
    model = _seed(name)
    system = GeneratedSystem.from_model(model)
    known = _known_minimum(model)
    q_star = {"double_pendulum": [-math.pi / 2, 0.0], "cart_double_pendulum": [0.0, math.pi, math.pi]}[name]
    angles = np.array(model.angular)
    H = np.zeros((angles.sum(),) * 2)
    h = 1e-4
    qa = np.array(q_star, float)
    idx = np.nonzero(angles)[0]
    for i, a in enumerate(idx):  # central differences: O(h²) ≈ 1e-8 relative, ample for a bound
        for j, b in enumerate(idx):
            e_a, e_b = np.eye(model.nv)[a] * h, np.eye(model.nv)[b] * h
            H[i, j] = (
                model.potential_energy(qa + e_a + e_b)
                - model.potential_energy(qa + e_a - e_b)
                - model.potential_energy(qa - e_a + e_b)
                + model.potential_energy(qa - e_a - e_b)
            ) / (4 * h * h)
    lam = np.linalg.eigvalsh(H)
    dg = lam.max() * math.sqrt(EPS) / 2 + 2 * EPS * abs(known) / math.sqrt(EPS)
    above = (1e-5 + dg) ** 2 / (2 * lam.min())
    v_min = system.potential_minimum
    assert known - 4 * EPS * abs(known) <= v_min <= known + above, (v_min, known, above)
    assert not (known * (1 + 1e-6) - 4 * EPS * abs(known) <= v_min <= known * (1 + 1e-6) + above)


# --- references and scenes ---------------------------------------------------------------------
def test_short_reference_agrees_with_scipys_dop853():
    """The Taylor reference of the generated field against scipy's DOP853 on the generated rhs at
    rtol = atol = 1e-12: within the stated accuracy 100 · rtol · (1 + ‖x‖∞) (T ≤ 2 s); the
    reference of a problem with g off by 1e-7 is not."""
    problem = make_problem("chaotic", 0.5, 4)
    ref = reference.reference(problem.fast, problem.x0, 0.5, problem.grid, 20, 26, cache=False)
    sol = solve_ivp(problem.fast.scipy_rhs(), (0, 0.5), problem.x0, "DOP853", rtol=1e-12, atol=1e-12)
    stated = 100 * 1e-12 * (1 + np.max(np.abs(ref.hi)))
    assert ref.error_bound < 1e-16 and ref.final_error(sol.y[:, -1]) <= stated
    planted = _with_g(problem.fast, 1 + 1e-7)
    moved = reference.reference(planted, problem.x0, 0.5, problem.grid, 20, 26, cache=False)
    assert moved.final_error(sol.y[:, -1]) > 100 * stated
    assert reference.problem_key(planted, problem.x0, 0.5, problem.grid) != reference.problem_key(
        problem.fast, problem.x0, 0.5, problem.grid
    )


def test_fast_path_runs_a_plugin_scene():
    run = compiled_scene.simulate_compiled(load_scene(REPO / "scenes" / "damped_triple_pendulum.toml"))
    assert run.system.model == "triple_pendulum" and run.invariants
    assert run.passed, [(i.name, i.error, i.tolerance) for i in run.invariants]
