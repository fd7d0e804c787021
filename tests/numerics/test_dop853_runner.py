"""The fast path: compiled closed form = the project's closed form, scipy's DOP853 step for step,
agreement with the high-precision reference, ensembles = single runs, and the scene invariants."""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import DOP853, solve_ivp
from scipy.integrate._ivp import dop853_coefficients

from pendverify.analytic import MODELS
from pendverify.bench.workprecision import make_problem
from pendverify.errors import FastPathError
from pendverify.numerics import reference
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import dop853_runner, taylor
from pendverify.simulation import compiled_scene
from pendverify.simulation.dynamics import build_dynamics
from pendverify.simulation.scene import load_scene, parse_scene

from ..conftest import SEED, assert_close, default_params

REPO = Path(__file__).resolve().parents[2]
RHS_RTOL = 1e-12  # two evaluations of the same closed form in a different order
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
    return GeneratedSystem.from_model(model, D=np.diag(model.damping_matrix()), B=B, K=K, u0=u0)


@pytest.mark.parametrize("name", tuple(MODELS))
@pytest.mark.parametrize("forced", [False, True], ids=["free", "forced"])
def test_compiled_rhs_is_the_closed_form(name, forced):
    model = MODELS[name](default_params(name))
    system = _forced_system(model) if forced else GeneratedSystem.from_model(model)
    rng = np.random.default_rng(SEED)
    for _ in range(50):
        x = rng.uniform(-3, 3, 2 * model.nv)
        q, v = x[: model.nv], x[model.nv :]
        tau = system.B @ (system.u0 - system.K @ x) - system.D @ v
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
    system = GeneratedSystem.from_dynamics(dyn)
    rng = np.random.default_rng(SEED)
    for _ in range(20):
        x = np.append(rng.uniform(-2, 2, 4), [0.0, 0.0])
        assert_close(system.rhs(x), dyn.rhs(0.0, x), RHS_RTOL, f"{x=}")


# --- scipy's DOP853, step for step ------------------------------------------------------
# The two implementations compute the same DOP853 step but round its sums in another order
# (numba's loops against numpy's dot, whose blocking and FMA use depend on the CPU), so no
# fixed tolerance on the final state is an argument: on the chaotic pendulum the flow
# amplifies ulp-level differences (|Φ(T, t)| up to ≈ 120 over 1 s), and they perturb the
# error estimate, which cancels to ≈ rtol of its terms, so the *step sizes* differ too (up
# to ≈ 1e-7 relative here); solve_ivp's final state then differs from ours by a change of
# truncation error (1.2e-10 at rtol 1e-5 here), which no rounding argument bounds.  So
# each of our accepted steps (y_k, h_k) is compared with scipy's DOP853 started from
# that very state, and scipy's DOP853 replayed on our steps with our whole trajectory, each
# against the bound that rounding explains:
#
# β_k, one step.  Every stage input x_s = y + h Σ_{j<s} a_sj K_j and y_new (row 12 of A
# is b) is a dot product of ≤ 12 terms, times h, plus y: ≤ 14 roundings in any order, so
# each implementation is within γ_14 (|y| + h Σ_j |a_sj| |K_j|) of exact arithmetic
# (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed., §3.1), γ_m = m u/(1 − m u),
# u = ε/2; two implementations, twice that: δx_s.  A stage input's δx_s reaches y_new
# through ∂y_new/∂x_s = h Σ_t b_t G_st, G_st = ∂K_t/∂x_s (all orders in h J, signed
# coefficients; J = ∂f/∂x frozen at y, exact to first order in u but for J's O(h) change over
# the step).  β_k = δx_12 + Σ_s |∂y_new/∂x_s| δx_s.
# No safety factor: β assumes every rounding aligned.
#
# Trajectory.  The step discrepancies are rounding-sized, so linearisation holds: the replay ends
# within Σ_k |Φ(T, t_{k+1})| β_k of our final state (Φ(t, s) = ∂x(t)/∂x(s), from the
# variational equation); a dense output at t inside step k within Σ_{j<k} |Φ(t, t_{j+1})| β_j
# plus the interpolant's own rounding (``_dense_rounding``).
#
# Step sizes.  h_{k+1} = h_k min(10, 0.9 err_k^(−1/8)), err_k from a = Σ_t E_t K_t (E5 and E3
# rows), whose terms cancel.  From the same (y_k, h_k) the a's differ by
# Δa ≤ 2γ_14 |E| |K| + Σ_s |∂a/∂x_s| δx_s; with ρ = ‖Δa/sc‖/‖a/sc‖ (sc the error scale),
# |Δ log err| ≤ 2ρ_5 + max(ρ_5, ρ_3) ≤ 3ρ, so the next step sizes differ by ≤ η h_{k+1},
# η = 3ρ/8 + 8ε (pow and two products, each side) + 2ε T/h_{k+1} (t + h − t rounds).
# Checked where neither step k nor k+1 follows a rejected trial: after one, our controller
# remembers it (no growth), a fresh scipy solver does not.
STEP_ROUNDINGS = 14  # ≤ 12-term dot product, × h, + y (stage inputs, y_new); a = E·K / sc: 13 + 1
DENSE_STAGE_ROUNDINGS = 17  # the 3 dense-output stages: ≤ 15-term dot product, × h, + y
DENSE_ROUNDINGS = 33  # F = h D K: 16-term dot, × h (17); Horner, 7 levels of + and ×, 1 − ξ, + y_old (16)
FLOW_TOL = 1e-10  # the variational equation: Φ to ~1e-7 relative, ample for a bound
T_STEPS = 1.0
_A = dop853_coefficients.A  # 16 × 16: the 12 stages, row 12 = b (y_new), rows 13–15 the dense stages
_B = dop853_coefficients.B
_E = (dop853_coefficients.E5, dop853_coefficients.E3)
# scipy's interpolant: y_old + Σ_r p_r(ξ) F_r with F_r = h Σ_t W_rt K_t in exact arithmetic
_W = np.zeros((7, 16))
_W[0, :12] = _B  # F0 = y_new − y_old
_W[1, :12], _W[1, 0] = -_B, 1.0 - _B[0]  # F1 = h K0 − F0
_W[2, :12], _W[2, 0], _W[2, 12] = 2 * _B, 2 * _B[0] - 1.0, -1.0  # F2 = 2 F0 − h (K12 + K0)
_W[3:] = dop853_coefficients.D
_DY = np.array([1.0, -1.0, 2.0, 0, 0, 0, 0])  # how F0…F6 carry y_new's own rounding


def _gamma(m: int) -> float:
    u = np.finfo(float).eps / 2
    return m * u / (1 - m * u)


def _jacobian(f, x):
    """∂f/∂x by central differences (≈ 1e-10 relative: ample for a bound)."""
    J = np.empty((x.size, x.size))
    for i in range(x.size):
        e = np.zeros(x.size)
        e[i] = 1e-6 * (1 + abs(x[i]))
        J[:, i] = (f(0.0, x + e) - f(0.0, x - e)) / (2 * e[i])
    return J


@functools.cache
def _flow_jacobians(key: str):
    """t ↦ Φ(t, 0) along the problem's trajectory, from the variational equation."""
    problem = make_problem(key, T_STEPS)
    f, n = problem.fast.scipy_rhs(), problem.x0.size

    def variational(_, z):
        return np.concatenate([f(0.0, z[:n]), (_jacobian(f, z[:n]) @ z[n:].reshape(n, n)).ravel()])

    z0 = np.concatenate([problem.x0, np.eye(n).ravel()])
    sol = solve_ivp(variational, (0, T_STEPS), z0, "DOP853", rtol=FLOW_TOL, atol=FLOW_TOL, dense_output=True)
    return lambda t: sol.sol(np.atleast_1d(t))[n:].T.reshape(-1, n, n)


def _slopes_and_rounding(f, y, h):
    """The 16 slopes K of the step (y, h), G_st = ∂K_t/∂x_s, and δx_s (see the comment above)."""
    n = y.size
    K = np.zeros((16, n))
    for s in range(16):
        K[s] = f(0.0, y + h * (_A[s, :s] @ K[:s]))
    J = _jacobian(f, y)
    G = np.zeros((16, 16, n, n))
    for t in range(16):
        G[:, t] = J @ (h * np.tensordot(_A[t, :t], G[:, :t], axes=(0, 1)))
        G[t, t] = J
    roundings = np.array([STEP_ROUNDINGS] * 13 + [DENSE_STAGE_ROUNDINGS] * 3)
    dx = 2 * np.array([_gamma(m) for m in roundings])[:, None] * (np.abs(y) + h * np.abs(_A) @ np.abs(K))
    dx[0] = 0.0  # x_0 = y itself
    return K, G, dx


def _propagated(sensitivity, dx):
    """Σ_s |∂z/∂x_s| δx_s for s ≥ 1."""
    return np.einsum("...sab,sb->...a", np.abs(sensitivity[..., 1:, :, :]), dx[1 : sensitivity.shape[-3]])


def _step_size_jitter(K, G, dx, y, y_new, tol, t_over_h):
    """η: the relative difference of the next step sizes that rounding explains (comment above)."""
    sc = tol + np.maximum(np.abs(y), np.abs(y_new)) * tol
    rho = 0.0
    for E in _E:
        a = E @ K[:13]
        da = 2 * _gamma(STEP_ROUNDINGS) * (np.abs(E) @ np.abs(K[:13]))
        da += _propagated(np.tensordot(E, G[:13, :13], axes=(0, 1)), dx)
        rho = max(rho, np.linalg.norm(da / sc) / np.linalg.norm(a / sc))
    eps = np.finfo(float).eps
    return 3 / 8 * rho + 8 * eps + 2 * eps * t_over_h


def _dense_rounding(xi, h, K, G, dx, y):
    """Bound on two implementations' dense output at ξ (a row per ξ) from the same step: 2γ_33 of
    the magnitudes summed (F_r and the Horner scheme over p_r(ξ)), y_new's rounding δx_12 as F0…F2
    carry it, and each stage input's δx_s through ∂Q/∂x_s = h Σ_t w_t G_st, w = p(ξ) W."""
    a, b = xi[:, None], 1 - xi[:, None]
    p = np.hstack([a, a * b, a * a * b, a * a * b * b, a**3 * b * b, a**3 * b**3, a**4 * b**3])
    F = h * np.abs(_W @ K) + h * np.abs(_W) @ np.abs(K)  # |F_r| and the magnitudes summed into it
    local = 2 * _gamma(DENSE_ROUNDINGS) * (np.abs(y) + p @ F)
    local += np.abs(p @ _DY)[:, None] * dx[12]
    return local + _propagated(h * np.einsum("mt,stab->msab", p @ _W, G), dx)


@dataclass
class _Comparison:
    counts: tuple  # (our nfev, our steps, scipy's nfev, scipy's steps)
    refused: int  # our accepted steps that scipy's controller rejects
    step: np.ndarray  # per step: |ours − scipy's step from our state| / β_k (max over components)
    control: np.ndarray  # per comparable step: |Δh_{k+1}| / (η h_{k+1})
    final: float  # |ours − replay| / bound at T (max over components)
    final_err: float  # ‖ours − replay‖∞ at T
    final_bound: float  # ‖bound‖∞ at T
    dense: float  # the same at the grid times
    replay_of_scipy: float  # |replay of solve_ivp's own steps − solve_ivp| / our final bound


def _compare_with_scipy(key, tol, ours_system=None, scipy_tol=None) -> _Comparison:
    """Our DOP853 on ``ours_system`` (default: the problem's) at ``tol`` against scipy's on the
    problem at ``scipy_tol`` (default ``tol``), as argued above."""
    problem = make_problem(key, T_STEPS)
    f, x0, grid, T = problem.fast.scipy_rhs(), problem.x0, problem.grid, T_STEPS
    ours_system, scipy_tol = ours_system or problem.fast, scipy_tol or tol
    ours = dop853_runner.integrate(ours_system, x0, T, tol, tol, record=True)
    dense = dop853_runner.integrate(ours_system, x0, T, tol, tol, t_out=grid, record=True)
    assert np.array_equal(dense.steps_t, ours.steps_t) and np.array_equal(dense.dense[0], x0)
    theirs = solve_ivp(f, (0, T), x0, "DOP853", rtol=scipy_tol, atol=scipy_tol)
    t, X, N = ours.steps_t, ours.steps_x, ours.steps
    flow = _flow_jacobians(key)
    to_zero = np.linalg.inv(flow(t))  # Φ(0, t_k)
    beta = np.zeros((N, x0.size))
    step, control, refused, dense_ratio = [], [], 0, 0.0
    replay, after_rejection = np.array(x0, float), True  # the first step's trials are unknown
    for k in range(N):
        y, h = X[k], t[k + 1] - t[k]
        K, G, dx = _slopes_and_rounding(f, y, h)
        beta[k] = dx[12] + _propagated(h * np.tensordot(_B, G[:, :12], axes=(0, 1)), dx)
        one = DOP853(f, 0.0, y, h, rtol=1.0, atol=1.0, first_step=h)  # accepts any of these steps
        one.step()
        assert one.t == h, f"scipy did not take the step {k} as one step"
        step.append(np.max(np.abs(one.y - X[k + 1]) / beta[k]))

        ctl = DOP853(f, 0.0, y, T - t[k], rtol=scipy_tol, atol=scipy_tol, first_step=h)
        ctl.step()
        refused += ctl.t != h
        clean, after_rejection = not after_rejection and ctl.t == h, True
        if ctl.t == h and k + 1 < N:
            nfev = ctl.nfev
            ctl.step()
            after_rejection = ctl.nfev - nfev > dop853_coefficients.N_STAGES
            if clean and not after_rejection:
                h_next = t[k + 2] - t[k + 1]
                eta = _step_size_jitter(K, G, dx, y, one.y, scipy_tol, T / h_next)
                control.append(abs(ctl.step_size - h_next) / (eta * h_next))

        rep = DOP853(f, 0.0, replay, h, rtol=1.0, atol=1.0, first_step=h)
        rep.step()
        inside = np.nonzero((grid > t[k]) & (grid <= t[k + 1]))[0]
        if inside.size:
            carried = np.abs(flow(grid[inside])[:, None] @ to_zero[None, 1 : k + 1])  # Φ(t, t_{j+1}), j < k
            bound = np.einsum("mjab,jb->ma", carried, beta[:k])
            bound += _dense_rounding((grid[inside] - t[k]) / h, h, K, G, dx, y)
            err = np.abs(dense.dense[inside] - rep.dense_output()(grid[inside] - t[k]).T)
            dense_ratio = max(dense_ratio, float(np.max(err / bound)))
        replay = rep.y

    final_bound = np.einsum("jab,jb->a", np.abs(flow(T)[0] @ to_zero[1:]), beta)
    final_err = np.abs(ours.x - replay)
    again = np.array(x0, float)
    for h in np.diff(theirs.t):
        rep = DOP853(f, 0.0, again, h, rtol=1.0, atol=1.0, first_step=h)
        rep.step()
        again = rep.y
    return _Comparison(
        counts=(ours.nfev, ours.steps, theirs.nfev, len(theirs.t) - 1),
        refused=int(refused),
        step=np.array(step),
        control=np.array(control),
        final=float(np.max(final_err / final_bound)),
        final_err=float(np.max(final_err)),
        final_bound=float(np.max(final_bound)),
        dense=dense_ratio,
        replay_of_scipy=float(np.max(np.abs(again - theirs.y[:, -1]) / final_bound)),
    )


def test_the_stages_are_compiled_once():
    """A step's stages and the dense output's extra stages call ``_stages`` with other bounds:
    one compilation serves both (``dop853._stages``: constants passed as ``np.int64``, which
    numba would otherwise type by their value and compile again)."""
    system = GeneratedSystem.from_model(MODELS["double_pendulum"](default_params("double_pendulum")))
    res = dop853_runner.integrate(system, np.array([0.4, -0.3, 0.0, 0.2]), 0.5, 1e-8, 1e-8, t_out=[0.25])
    assert res.steps > 1
    assert len(system.kernel.module._stages.signatures) == 1, system.kernel.module._stages.signatures


@pytest.mark.parametrize("key", ["chaotic", "cart_lqr"])
@pytest.mark.parametrize("tol", [1e-5, 1e-9])
def test_dop853_takes_scipys_steps(key, tol):
    c = _compare_with_scipy(key, tol)
    ours_nfev, ours_steps, their_nfev, their_steps = c.counts
    assert (ours_nfev, ours_steps) == (their_nfev, their_steps), f"{key=} {tol=}"
    assert c.refused == 0, f"scipy rejects {c.refused} of our steps {key=} {tol=}"
    assert np.all(c.step <= 1), f"one step: {c.step.max():.3g} × β {key=} {tol=}"
    assert c.control.size >= ours_steps // 4, f"too few steps to compare the controller {key=} {tol=}"
    assert np.all(c.control <= 1), f"next step size: {c.control.max():.3g} × η {key=} {tol=}"
    assert c.final <= 1, f"final state: {c.final_err:.3g}, {c.final:.3g} × bound {key=} {tol=}"
    assert c.dense <= 1, f"dense output: {c.dense:.3g} × bound {key=} {tol=}"
    # the replay is solve_ivp's DOP853 (bit for bit here; a BLAS may round the dot products differently)
    assert c.replay_of_scipy <= 1, f"replay of solve_ivp: {c.replay_of_scipy:.3g} × bound {key=} {tol=}"


@pytest.mark.parametrize("key", ["chaotic", "cart_lqr"])
@pytest.mark.parametrize("tol", [1e-5, 1e-9])
def test_the_step_checks_catch_a_planted_difference(key, tol):
    """The bounds are tight enough to fail: a right-hand side off by 1e-9 relative (gravity) and
    a controller at twice the tolerance."""
    fast = make_problem(key, T_STEPS).fast
    params = fast.params.copy()
    params[fast.kernel.parameters.index("g")] *= 1 + 1e-9
    c = _compare_with_scipy(key, tol, ours_system=dataclasses.replace(fast, params=params))
    assert c.step.max() > 10 and c.final > 10 and c.dense > 10, (c.step.max(), c.final, c.dense)
    c = _compare_with_scipy(key, 2 * tol, scipy_tol=tol)
    assert c.counts[:2] != c.counts[2:] and c.control.max() > 10, (c.counts, c.control.max())


@pytest.mark.parametrize("key, duration", [("mild", 2.0), ("chaotic", 1.0), ("cart_lqr", 2.0)])
def test_fast_path_agrees_with_the_reference_to_its_stated_accuracy(key, duration):
    problem = make_problem(key, duration, 16)
    ref = reference.reference(problem.fast, problem.x0, duration, problem.grid, *REF_DIGITS)
    assert ref.error_bound < 1e-18, ref.describe()
    for tol in (1e-8, 1e-10, 1e-12):
        res = dop853_runner.integrate(problem.fast, problem.x0, duration, tol, tol, t_out=problem.grid)
        stated = ACCURACY_FACTOR * tol * (1 + np.max(np.abs(ref.hi)))
        err = ref.final_error(res.x)
        assert err <= stated, f"{key=} {tol=}: final error {err:.2e} > {stated:.2e}"
        assert np.all(np.isfinite(res.dense))


def test_headline_accuracy_on_the_chaotic_pendulum():
    """The README's claim: rtol = atol = 1e-11 reaches a final error ≤ 1e-10 over T = 2 s."""
    problem = make_problem("chaotic", 2.0, 4)
    ref = reference.reference(problem.fast, problem.x0, 2.0, problem.grid, *REF_DIGITS)
    res = dop853_runner.integrate(problem.fast, problem.x0, 2.0, 1e-11, 1e-11)
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


@pytest.mark.parametrize("name", tuple(MODELS))
def test_energy_of_the_reference_is_the_models(name):
    """E − V_min (generated) − the model's own E is the constant −V_min: the spread of the
    offsets over states is the rounding of two evaluations of E ≈ 1e2 J, 1e-12 ≫ 20 ε·|E|."""
    model = MODELS[name](default_params(name))
    system = GeneratedSystem.from_model(model)
    rng = np.random.default_rng(SEED)
    offsets, n = [], model.nv
    for _ in range(10):
        x = rng.uniform(-2, 2, 2 * n)
        e = taylor.energy_above_minimum(taylor.float_system(system), list(x))
        offsets.append(e - model.kinetic_energy(x[:n], x[n:]) - model.potential_energy(x[:n]))
    assert np.ptp(offsets) < 1e-12, "E − V_min must differ from the model's E by a constant"
    assert abs(np.mean(offsets) + system.potential_minimum) < 1e-12
    x0 = rng.uniform(-1, 1, 2 * n)
    assert reference.relative_energy_error(system, x0, x0)[0] == 0.0


def test_ensemble_is_the_single_runs():
    problem = make_problem("chaotic", 0.5)
    X0 = problem.x0 + np.random.default_rng(SEED).uniform(-0.05, 0.05, (6, 4)) * [1, 1, 0, 0]
    X, nfev = dop853_runner.integrate_ensemble(problem.fast, X0, 0.5, 1e-9, 1e-9, threads=2)
    for i, x0 in enumerate(X0):
        single = dop853_runner.integrate(problem.fast, x0, 0.5, 1e-9, 1e-9)
        assert np.array_equal(X[i], single.x) and nfev[i] == single.nfev, f"member {i}"


@pytest.mark.parametrize("name", ["chaotic_double_pendulum", "damped_double_pendulum", "cart_rods_falling"])
def test_fast_path_passes_the_simulators_invariants(name):
    run = compiled_scene.simulate_compiled(load_scene(REPO / "scenes" / f"{name}.toml"))
    assert run.invariants, name
    assert run.passed, [(i.name, i.error, i.tolerance) for i in run.invariants]
    assert np.all(np.isfinite(run.x))


def test_laws_with_jumps_are_refused_by_name():
    """A sine compiles (tests/numerics/test_fast_forcing.py); an impulse does not."""
    with pytest.raises(FastPathError, match=r"effects\.disturbance"):
        compiled_scene.simulate_compiled(load_scene(REPO / "scenes" / "cart_lqr_push.toml"))
