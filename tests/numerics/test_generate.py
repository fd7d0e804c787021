"""The right-hand side generated from a model's closed forms = the model, at ε level; the cache.

Tolerance, from conditioning.  Every implementation compared here evaluates the
same function a = M(q)⁻¹ (τ − b(q, q̇)) in floating point, in its own order.  For
the generated one the error is bounded, to first order in u = ε/2 and
componentwise (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed.,
§3.1, §7.2 and Thm 10.4):

* each entry of M, of the bias b and of τ = B (u0 − K x) − D q̇ is a sum of
  products evaluated with at most k roundings, so its error is at most γ_k·|e|,
  where |e| is the same expression with every term replaced by its magnitude
  (``_magnitude``: sums and products of |terms|; a sin/cos of a computed argument
  counts 1 + |argument|, for the argument's own rounding).  k = the largest
  operation count of an entry (``count_ops``: a bound on the roundings along any
  path of any evaluation order, CSE included) + 6n + 2nu + 8 for τ (D q̇: n products,
  n − 1 sums) and f = τ − b;
* the solve (root-free Cholesky M = L diag(d) Lᵀ, no pivoting: M is SPD) is
  backward stable: (M + ΔM) â = f with |ΔM| ≤ γ_{3n+1} |L||D||Lᵀ| = γ_{3n+1} |C||Cᵀ|,
  C the Cholesky factor.

Hence |â − a| ≤ β = |M⁻¹| (γ_k (|M|·|a| + |τ| + |b|) + γ_{3n+1} |C||Cᵀ| |a|), entry by
entry: the generated value is checked against the exact value (mpmath, 40
digits, on the same double inputs) to β.  The models' own closed forms (adjugate /
det, n ≤ 3) are checked against the exact value to the same β, so the two differ
by at most 2β; that is the tolerance of the pairwise comparison.
β carries the conditioning of the state (|M⁻¹||M|,
and the cancellation between τ, Coriolis and gravity terms): over the sampled
states it runs from ≈ 50 u at benign states up to ≈ 2e5 u (seeds) and 6e5 u
(triple pendulum) relative to max(1, |a|) — tighter than the fixed 1e-12 ≈ 9e3 u
of ``tests/numerics/test_dop853_runner.py`` where the state is benign, looser where it is
ill-conditioned.  The errors observed are ≤ 4 % of β (≤ 40 u ≈ 4e-15 relative to
max(1, |a|)); the last test prints them.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import ClassVar

import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from pendverify.analytic import MODELS
from pendverify.analytic.interface import BiasOnlyModel
from pendverify.analytic.parameter_set import ParameterSet, quantity
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import load_model_class
from pendverify.checks.sampling import sample_states
from pendverify.errors import PendverifyError
from pendverify.numerics.codegen import cache as code_cache
from pendverify.numerics.codegen import expressions as codegen_expressions
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import dop853_runner

REPO = Path(__file__).resolve().parents[2]
#: the model files of examples/ but those SymPy cannot read (NumPy functions: no code is generated)
NOT_GENERATED = ("__init__.py", "corpus_double_pendulum_functions.py")
EXAMPLES = sorted(p for p in (REPO / "examples").glob("*.py") if p.name not in NOT_GENERATED)
SEED = 1234
U = np.finfo(float).eps / 2
STATES = 30  # random states per case, after the model's special states
#: largest error seen, in units of β, per comparison: printed by the last test
OBSERVED: dict[str, float] = {}


@pytest.fixture(scope="module", autouse=True)
def _cache():
    """The run's cache (``conftest``), nothing from memory: each model is generated and compiled
    once per run, and the module's kernels come from the disk or the generator, not another module."""
    code_cache.forget()
    yield
    code_cache.forget()


def _gamma(k: int) -> float:
    return k * U / (1 - k * U)


# --- an exact reference and the error bound ----------------------------------------------------
def _magnitude(e):
    """The expression with every term replaced by its magnitude (module docstring)."""
    if e.is_Atom:
        return sp.Abs(e)
    if e.is_Add:
        return sp.Add(*[_magnitude(a) for a in e.args])
    if e.is_Mul:
        return sp.Mul(*[_magnitude(a) for a in e.args])
    if e.is_Pow and e.exp.is_Integer and e.exp > 0:
        return _magnitude(e.base) ** e.exp
    if isinstance(e, (sp.sin, sp.cos)):
        arg = e.args[0]
        return sp.Integer(1) + (0 if arg.is_Atom else _magnitude(arg))
    raise NotImplementedError(f"no magnitude rule for {type(e).__name__}")


@dataclasses.dataclass
class Reference:
    """The exact solution and the bound β for one model class and parameter set."""

    model: object
    ex: codegen_expressions.Expressions

    def __post_init__(self):
        ex, p = self.ex, self.model.params
        self.values = {s: float(getattr(p, name)) for s, name in zip(ex.p, ex.parameters, strict=True)}
        args = (*ex.q, *ex.v)
        mass, bias = ex.mass.xreplace(self.values), ex.bias.xreplace(self.values)
        self._exact = sp.lambdify(args, (mass, bias), modules="mpmath")
        self._float = sp.lambdify(args, (mass, bias, mass.applyfunc(_magnitude), bias.applyfunc(_magnitude)))
        self.ops = max(sp.count_ops(e) for e in [*ex.mass, *ex.bias])

    def exact(self, x, tau):
        """M⁻¹ (τ − b) in 40-digit arithmetic from the double inputs."""
        with mpmath.workdps(40):
            mass, bias = self._exact(*[mpmath.mpf(float(v)) for v in x[: 2 * self.ex.n]])
            f = mpmath.matrix([mpmath.mpf(0) + t for t in tau]) - mpmath.matrix(bias)
            return np.array([float(a) for a in mpmath.lu_solve(mpmath.matrix(mass), f)])

    def beta(self, x, a, tau_abs, nu: int) -> np.ndarray:
        """The componentwise bound on |â − a| (module docstring)."""
        n = self.ex.n
        mass, _, mass_abs, bias_abs = (np.array(v, float) for v in self._float(*x[: 2 * n]))
        chol = np.abs(np.linalg.cholesky(mass))  # |L||D||Lᵀ| = |L D^½||D^½ Lᵀ|
        k = self.ops + 6 * n + 2 * nu + 8
        perturbation = _gamma(k) * (mass_abs @ np.abs(a) + tau_abs + bias_abs.ravel()) + _gamma(3 * n + 1) * (
            chol @ chol.T @ np.abs(a)
        )
        return np.abs(np.linalg.inv(mass)) @ perturbation


def _forces(model, forced: bool, rng):
    """(D, B, K, u0) for ``from_model``: none, or friction and a state feedback on every input."""
    if not forced:
        return None, None, None, None
    B = model.input_matrix()
    return (
        np.abs(np.diag(model.damping_matrix())),
        B,
        rng.normal(size=(B.shape[1], 2 * model.nv)),
        rng.normal(size=B.shape[1]),
    )


def _note(what: str, ratio: float) -> None:
    OBSERVED[what] = max(OBSERVED.get(what, 0.0), ratio)


def _check_model(model, forced: bool, work: bool, tag: str = ""):
    """Generated rhs = exact to β, = the model's M⁻¹(τ − b) to 2β."""
    rng = np.random.default_rng(SEED)
    D, B, K, u0 = _forces(model, forced, rng)
    system = GeneratedSystem.from_model(model, D, B, K, u0)
    ref = Reference(model, codegen_expressions.expressions(type(model)))
    n, nu = model.nv, system.B.shape[1]
    for state in sample_states(model, STATES, SEED):
        x = np.concatenate([state.q, state.v, [0.0, 0.0] if work else []])
        q, v = state.q, state.v
        xs = x[: 2 * n]
        u = system.u0 - system.K @ xs
        tau_in, tau_diss = system.B @ u, -system.D @ v
        tau = tau_in + tau_diss
        tau_abs = np.abs(system.B) @ (np.abs(system.u0) + np.abs(system.K) @ np.abs(xs)) + np.abs(
            system.D
        ) @ np.abs(v)
        got = system.rhs(x)
        context = f"{tag} {state.label} {x=}"
        assert np.all(np.isfinite(got)), context
        assert np.array_equal(got[:n], v), context
        exact = ref.exact(x, tau)
        beta = ref.beta(x, exact, tau_abs, nu)
        err = np.max(np.abs(got[n : 2 * n] - exact) / beta)
        assert err <= 1.0, f"generated vs exact: {err:.3g} β {context}"
        _note(f"{tag} generated vs exact", err)
        relative_beta = np.max(beta) / max(1.0, np.max(np.abs(exact))) / U
        _note(f"{tag} β relative to max(1, |a|)", relative_beta)
        OBSERVED[f"{tag} β relative to max(1, |a|), smallest"] = min(
            OBSERVED.get(f"{tag} β relative to max(1, |a|), smallest", np.inf), relative_beta
        )
        own = model.inverse_mass_matrix(q) @ (tau - model.bias(q, v))
        assert np.all(np.abs(own - exact) <= beta), f"model vs exact {context}"
        _note(f"{tag} model vs exact", np.max(np.abs(own - exact) / beta))
        err = np.max(np.abs(got[n : 2 * n] - own) / beta)
        assert err <= 2.0, f"generated vs model: {err:.3g} β {context}"
        _note(f"{tag} generated vs model", err)
        rel = np.max(np.abs(got[n : 2 * n] - own)) / max(1.0, np.max(np.abs(own)))
        _note(f"{tag} generated vs model, relative to max(1, |a|)", rel / U)
        if work:
            # v·τ_in and v·(D v): ≤ 4n + nu + 4 roundings of terms bounded by |v|·|τ|
            k = _gamma(4 * n + 2 * nu + 8)
            w_in, w_diss = v @ tau_in, v @ (system.D @ v)
            assert abs(got[2 * n] - w_in) <= 2 * k * (np.abs(v) @ tau_abs), context
            assert abs(got[2 * n + 1] - w_diss) <= 2 * k * (np.abs(v) @ np.abs(system.D) @ np.abs(v)), context
    return system


def _seed(name: str):
    return MODELS[name](load_parameter_file(default_parameter_file(name))[2])


def _example(path: Path):
    cls = load_model_class(path)
    # a worked example's parameters are NAME.toml beside it, a corpus model's NAME_params.toml
    found = [p for p in (path.with_suffix(".toml"), path.with_name(f"{path.stem}_params.toml")) if p.exists()]
    params = load_parameter_file(found[-1], {cls.name: cls.params_type})[2]
    return cls(params)


# --- the seeds: generated = model ---------------------------------------------------------------
@pytest.mark.parametrize("name", tuple(MODELS))
@pytest.mark.parametrize("forced", [False, True], ids=["free", "forced"])
@pytest.mark.parametrize("work", [False, True], ids=["state", "work"])
def test_seed_generated_equals_model(name, forced, work):
    system = _check_model(_seed(name), forced, work, tag=name)
    assert system.kernel.module.MODEL == name and system.kernel.module.N == len(MODELS[name].coordinates)


# --- plug-ins ------------------------------------------------------------------------------------
@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
@pytest.mark.parametrize("forced", [False, True], ids=["free", "forced"])
def test_plugin_generated_equals_model(path, forced):
    _check_model(_example(path), forced, work=True, tag=path.stem)


@dataclasses.dataclass(frozen=True)
class WheelPoleParams(ParameterSet):
    """A cart-pole with a reaction wheel at the pole's tip (test model), SI units."""

    model = "wheel_pole"

    mc: float = quantity("mass", "cart [kg]")
    mp: float = quantity("mass", "pole [kg]")
    mw: float = quantity("mass", "wheel [kg]")
    r: float = quantity("offset", "pivot to the pole's centre of mass [m]")
    l: float = quantity("length", "pivot to the wheel's axle [m]")  # noqa: E741
    I: float = quantity("inertia", "pole about its centre of mass [kg·m²]")  # noqa: E741
    Iw: float = quantity("inertia", "wheel about its axle [kg·m²]")
    g: float = quantity("gravity", "[m/s²]")


class WheelPole(BiasOnlyModel):
    """x (cart), θ (pole from upright), φ (wheel relative to the pole): 3 coordinates, M_xφ = 0.

    T = ½ mc ẋ² + ½ mp |ṗ_pole|² + ½ I θ̇² + ½ mw |ṗ_wheel|² + ½ Iw (θ̇ + φ̇)², V = k g cos θ,
    k = mp r + mw l; the only velocity coupling is M_xθ = k cos θ, so C q̇ = (−k sin θ θ̇², 0, 0).
    """

    name = "wheel_pole"
    params_type = WheelPoleParams
    coordinates = ("x", "theta", "phi")
    angular = (False, True, True)
    inputs = ("force", "motor")
    urdf_joints: ClassVar[tuple[str, ...]] = ()

    def _k(self):
        p = self.params
        return p.mp * p.r + p.mw * p.l

    def mass_matrix(self, q):
        p, c = self.params, self.math.cos(q[1])
        j = p.I + p.mp * p.r**2 + p.mw * p.l**2
        return np.array(
            [[p.mc + p.mp + p.mw, self._k() * c, 0.0], [self._k() * c, j + p.Iw, p.Iw], [0.0, p.Iw, p.Iw]]
        )

    def coriolis_force(self, q, v):
        return np.array([-self._k() * self.math.sin(q[1]) * v[1] ** 2, 0.0, 0.0])

    def gravity(self, q):
        return np.array([0.0, -self._k() * self.params.g * self.math.sin(q[1]), 0.0])

    def gravity_scale(self):
        return np.array([0.0, self._k() * self.params.g, 0.0])

    def potential_energy(self, q):
        return self._k() * self.params.g * self.math.cos(q[1])

    def damping_matrix(self):
        return np.diag([0.1, 0.01, 0.001])

    def input_matrix(self):
        return np.array([[1.0, 0.0], [0.0, -1.0], [0.0, 1.0]])

    def det_mass_matrix(self, q):
        return float(np.linalg.det(self.mass_matrix(q)))

    def inverse_mass_matrix(self, q):
        return np.linalg.inv(self.mass_matrix(q))

    def acceleration(self, q, v, u, w):
        return np.linalg.solve(self.mass_matrix(q), self.input_matrix() @ u - self.bias(q, v))

    def special_states(self):
        return {"upright": np.zeros(3), "horizontal": np.array([0.3, math.pi / 2, 1.0])}


WHEEL = WheelPoleParams(mc=1.5, mp=0.5, mw=0.3, r=0.25, l=0.5, I=0.01, Iw=0.002, g=9.81)


@pytest.mark.parametrize("forced", [False, True], ids=["free", "forced"])
def test_three_coordinate_model_written_here(forced):
    system = _check_model(WheelPole(WHEEL), forced, work=True, tag="wheel_pole")
    source = system.kernel.path.read_text()
    assert "m2_0" not in source and "E2_0" not in source  # M_xφ = 0 and no fill-in: skipped
    assert "L2_1" in source


def test_asymmetric_mass_matrix_is_refused():
    class Skewed(WheelPole):
        def mass_matrix(self, q):
            m = super().mass_matrix(q)
            m[0, 2] = 0.1 * self.params.mc
            return m

    with pytest.raises(PendverifyError, match="not symmetric"):
        code_cache.kernel(Skewed)


# --- the cache (fixture fresh_cache: conftest.py) ----------------------------------------------------


def _listing(folder: Path) -> dict[str, int]:
    return {str(p.relative_to(folder)): p.stat().st_mtime_ns for p in folder.rglob("*") if p.is_file()}


def test_cache_is_used_on_a_second_call(fresh_cache, monkeypatch):
    model = _seed("double_pendulum")
    first = GeneratedSystem.from_model(model)
    x = np.array([0.3, -0.2, 0.5, 0.1])
    expected = first.rhs(x)
    assert first.kernel.origin == "generated"
    assert first.kernel.path.parent == fresh_cache
    assert first.kernel.path.name.endswith(f"{first.kernel.digest[:24]}.py")
    assert GeneratedSystem.from_model(model).kernel.origin == "memory"
    code_cache.forget()  # as a new process: only the disk remains (numba's files recorded first)
    before = _listing(fresh_cache)
    assert any(name.endswith(".nbi") for name in before)  # numba's cache of the compiled rhs

    def no_sympy(*args, **kwargs):
        raise AssertionError("the model was read again")

    monkeypatch.setattr(codegen_expressions, "expressions", no_sympy)
    second = GeneratedSystem.from_model(model)
    assert second.kernel.origin == "disk"
    assert second.kernel.digest == first.kernel.digest
    assert np.array_equal(second.rhs(x), expected)
    assert _listing(fresh_cache) == before  # nothing written, nothing rewritten


_CHILD = """
import json, sys
import numpy as np
from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.analytic.plugin import load_model_class
from pendverify.numerics import generate
seed = MODELS["double_pendulum"](load_parameter_file(default_parameter_file("double_pendulum"))[2])
cls = load_model_class(sys.argv[1])  # a plug-in: imported under a name salted per process
plugin = cls(load_parameter_file(sys.argv[1][:-3] + ".toml", {cls.name: cls.params_type})[2])
result = {}
from pendverify.numerics.integrators import dop853_runner
from pendverify.numerics.integrators import fixedstep_runner, taylor
for model in (seed, plugin):
    system = generate.GeneratedSystem.from_model(model)
    x = np.array([0.3, -0.2, 0.5, 0.1])
    out = system.rhs(x).tolist()
    out += dop853_runner.integrate(system, x, 0.05, 1e-8, 1e-8).x.tolist()
    out += fixedstep_runner.integrate_fixed("implicit_midpoint", system, x, 0.05, 4)[0][-1].tolist()
    out += [float(v) for v in taylor.field(taylor.float_system(system), list(x))]
    entry = dict(origin=system.kernel.origin, out=out)
    for name in ("_rhs", "_dop853", "_run"):
        stats = getattr(system.module, name).stats
        entry[name] = (sum(stats.cache_hits.values()), sum(stats.cache_misses.values()))
    result[model.name] = entry
result["sympy"] = "sympy" in sys.modules
print(json.dumps(result))
"""


@pytest.mark.slow
def test_a_fresh_process_neither_generates_nor_compiles(fresh_cache):
    env = dict(os.environ, PENDVERIFY_CACHE=str(fresh_cache.parent))

    def child():
        argv = [sys.executable, "-c", _CHILD, str(REPO / "examples" / "cart_pole.py")]
        done = subprocess.run(argv, env=env, capture_output=True, text=True, check=True)
        return json.loads(done.stdout.strip().splitlines()[-1])

    first, second = child(), child()
    assert first["sympy"] and not second["sympy"], (first, second)  # the second does not import SymPy
    for name in ("double_pendulum", "cart_pole"):
        assert first[name]["origin"] == "generated", first
        assert second[name]["origin"] == "disk", second
        for function in ("_rhs", "_dop853", "_run"):  # (cache hits, cache misses = compilations)
            assert first[name][function] == [0, 1], (function, first)
            assert second[name][function] == [1, 0], (function, second)
        assert second[name]["out"] == first[name]["out"]


def planted_cart_pole(folder: Path):
    """examples/cart_pole.py with M_11 = I + 2 m_p r² instead of I + m_p r² (written to ``folder``)."""
    source = (REPO / "examples" / "cart_pole.py").read_text()
    old = "return np.array([[p.mc + p.mp, k], [k, p.I + p.mp * p.r**2]])"
    assert source.count(old) == 1
    planted = folder / "cart_pole.py"
    planted.write_text(source.replace(old, old.replace("p.I + p.mp * p.r**2", "p.I + 2 * p.mp * p.r**2")))
    shutil.copy(REPO / "examples" / "cart_pole.toml", folder / "cart_pole.toml")
    return _example(planted)


def test_planted_change_in_mass_matrix_changes_digest_and_result(tmp_path):
    original, mutant = _example(REPO / "examples" / "cart_pole.py"), planted_cart_pole(tmp_path)
    a, b = GeneratedSystem.from_model(original), GeneratedSystem.from_model(mutant)
    assert a.kernel.digest != b.kernel.digest and a.kernel.path != b.kernel.path
    x = np.array([0.1, 0.7, 0.4, -1.2])
    assert np.max(np.abs(a.rhs(x) - b.rhs(x))) > 1e-3
    # the mutant's kernel is the mutant's closed form (its inverse_mass_matrix was left alone: use M)
    q, v = x[:2], x[2:]
    assert np.allclose(b.rhs(x)[2:], np.linalg.solve(mutant.mass_matrix(q), -mutant.bias(q, v)), rtol=1e-13)


def test_digest_does_not_depend_on_parameter_values():
    cls = MODELS["double_pendulum"]
    params = load_parameter_file(default_parameter_file(cls.name))[2]
    a = GeneratedSystem.from_model(cls(params))
    b = GeneratedSystem.from_model(cls(params.replace(m1=2 * params.m1)))
    assert a.kernel.digest == b.kernel.digest
    assert not np.array_equal(a.packed(), b.packed())
    n, nu = 2, 0
    assert a.packed().shape == (2 + len(a.kernel.parameters) + n * n + 3 * n * nu + nu,)


# --- integration -------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", tuple(MODELS))
def test_generated_stepper_is_scipys_dop853(name):
    """The generated module's DOP853 and scipy's on the generated rhs: the same steps, and states
    within both accuracies.

    Both runs are DOP853 at rtol = atol = 1e-10 over 1 s (T ≤ 2 s): each is within the fast
    path's stated accuracy 100 · rtol · (1 + ‖x‖∞) of the exact flow, so they differ by at
    most twice that (``tests/numerics/test_dop853_runner.py`` compares the steps themselves to rounding).
    """
    model = _seed(name)
    rng = np.random.default_rng(SEED)
    D, B, K, u0 = _forces(model, True, rng)
    gen = GeneratedSystem.from_model(model, D, B, 0.1 * K, u0)
    x0 = np.append(np.full(2 * model.nv, 0.4), [0.0, 0.0])
    rtol = 1e-10
    t_out = np.linspace(0.0, 1.0, 5)
    ours = dop853_runner.integrate(gen, x0, 1.0, rtol, rtol, t_out=t_out, record=True)
    plain = dop853_runner.integrate(gen, x0, 1.0, rtol, rtol)
    steps = solve_ivp(gen.scipy_rhs(), (0.0, 1.0), x0, method="DOP853", rtol=rtol, atol=rtol)
    assert steps.success and (plain.nfev, plain.steps) == (steps.nfev, len(steps.t) - 1)
    sol = solve_ivp(gen.scipy_rhs(), (0.0, 1.0), x0, method="DOP853", rtol=rtol, atol=rtol, t_eval=t_out)
    bound = 2 * 100 * rtol * (1 + np.max(np.abs(sol.y)))
    assert np.max(np.abs(sol.y[:, -1] - ours.x)) <= bound
    assert np.max(np.abs(sol.y.T - ours.dense)) <= bound


# --- benchmark (printed, never asserted) ---------------------------------------------------------------
def test_benchmark_prints_ratios(capsys):
    from pendverify.bench.generated import per_call

    rows = per_call(calls=20_000, repeats=3, scipy_calls=200)
    with capsys.disabled():
        print()
        for r in rows:
            print(
                f"  {r['model']:22s} {r['forces']:20s} generated {r['generated_ns']:6.1f} ns  "
                f"scipy wrapper / Pinocchio aba {r['scipy_ratio']:.2f}"
            )
        for what, ratio in sorted(OBSERVED.items()):
            unit = "u" if "relative" in what else "β"
            label = what if "smallest" in what else f"{what}, largest"
            print(f"  {label}: {ratio:.3g} {unit}")
    assert {r["model"] for r in rows} == set(MODELS)


# --- a certificate's embedded model: the key of its text, not of a file that is gone --------------
_EMBEDDED_CHILD = """
import json, sys
from pathlib import Path
from pendverify.analytic.params import load_parameter_file
from pendverify.certify.model_source import load_from_text
from pendverify.numerics.generate import GeneratedSystem
path = Path(sys.argv[1])
cls = load_from_text(path.read_text(encoding="utf-8"), path.name)  # as recheck loads it
params = load_parameter_file(path.with_suffix(".toml"), {cls.name: cls.params_type})[2]
print(json.dumps(GeneratedSystem.from_model(cls(params)).kernel.origin))
"""


def test_an_embedded_model_reuses_the_code_generated_for_its_file(fresh_cache, tmp_path):
    """``recheck`` imports a certificate's model from a temporary copy that is deleted at
    once; its generated code is keyed by the text, so it is the code generated when the
    file was certified, in any process, and an edited text is never given that code."""
    from pendverify.certify.model_source import load_from_text
    from pendverify.numerics.codegen.cache import model_key

    example = REPO / "examples" / "cart_pole.py"
    text = example.read_text(encoding="utf-8")
    from_file, from_text = load_model_class(example), load_from_text(text, example.name)
    assert from_text is not from_file and model_key(from_text) is not None
    assert model_key(from_text) == model_key(from_file)
    edited = text.replace("p.I + p.mp * p.r**2", "p.I + 2 * p.mp * p.r**2")
    assert edited != text and model_key(load_from_text(edited, example.name)) != model_key(from_file)
    assert GeneratedSystem.from_model(_example(example)).kernel.origin == "generated"  # at certify
    env = dict(os.environ, PENDVERIFY_CACHE=str(fresh_cache.parent))
    argv = [sys.executable, "-c", _EMBEDDED_CHILD, str(example)]
    done = subprocess.run(argv, env=env, capture_output=True, text=True, check=True)
    assert json.loads(done.stdout.strip().splitlines()[-1]) == "disk"  # at recheck, a new process
