"""The stress catalogue: hard cases that must stay numerically stable, or be refused.

Each case is a named function returning a ``StressResult``: the achieved
relative error next to the tolerance used, κ(M) raw and after diagonal scaling
(the worst over the case's states), the simulation invariant where the case
simulates, and pass/fail.  Seeds are fixed (``SEED``) and recorded.

Groups and what passes
----------------------
``mass ratio``, ``length``, ``point mass``, ``stiff damping`` (closed form),
``zero gravity`` (closed form), ``near singular`` (single m1)
    The nine checks of ``pendverify.checks.catalogue`` (closed form vs Pinocchio, tolerance
    K·ε·(1 + |θ|max)·scale in diagonally scaled coordinates) on seeded states,
    after ``check_conditioning``: a state the trust rule refuses is not compared.
    ``guarded`` adds to each check's scale what the core checks leave out (see
    there).  Passes when every check passes on the accepted states and the
    refusals match what the case expects (``EXPECT``): none; some (aligned states
    of a near-singular cart); all (a 1e6 length ratio in one chain, singular to
    working precision); or any (a 1 mm pendulum on a cart up to 10 m from the
    origin, where Pinocchio's world-frame terms are 1e8 times the result).
``large angle``
    The same at |θ| ≈ 1e6 rad, plus the 2πk invariance: the closed form at θ
    against Pinocchio at θ reduced to (−π, π], with the same tolerance.
``high speed``
    The same with rates up to 1e3 rad/s; every quantity must stay finite.
``near singular`` (study)
    ``pendverify.stress.trust_study``: m1 = 1 … 1e-16 kg against a
    50-digit reference.  Passes when every state the guard accepts is within its
    predicted rounding bound and within 1e-6, the guard refuses below the
    measured trust limit, and m1 = 0 (where ABA returns finite nonsense) is refused.
``stiff damping`` (simulation)
    b = 1e4 from rest: backward Euler at a coarse step stays finite and E never
    increases by more than ``ENERGY_INCREASE_TOL``; RK4 at that step blows up
    exactly when its stability function predicts it; RK45's step count is reported.
``long horizon``
    A mild (1 km) conservative double pendulum for 1e4 s: the Störmer–Verlet
    energy error stays bounded (late maximum ≤ ``BOUNDED_GROWTH`` × early
    maximum); RK4's drift is roughly linear (R² ≥ ``MIN_R2``) and shrinks with the
    step as a 4th-order method's should (slope ratio ≥ ``MIN_ORDER_RATIO`` when h
    halves), which a model whose q̈ disagrees with its energy cannot fake.
``zero gravity`` (simulation)
    g = 0: the cyclic coordinate's momentum (θ1 of the double pendulum, the cart
    position) is conserved by Störmer–Verlet to ``MOMENTUM_K``·ε per step.
``invalid input``
    NaN or infinite states and parameters, negative masses, zero lengths and a
    singular parameter set each raise a PendverifyError naming key and value.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from pendverify.analytic import MODELS, CartDoublePendulumParams, DoublePendulumParams
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.checks.catalogue import CHECKS, EPS, Check, Sample, applicable_checks, run_check
from pendverify.checks.sampling import DEFAULT_SEED, State, sample_states
from pendverify.checks.trust import REFUSE_REL, IllConditionedError, check_conditioning
from pendverify.errors import PendverifyError
from pendverify.robot.system import PinocchioSystem
from pendverify.stress.trust_study import StudyResult, study_states, trust_study
from pendverify.validate import model_state

SEED = DEFAULT_SEED
TINY = float(np.finfo(float).tiny)
ANGLE_SHIFT = 1e6  # rad: large-angle states sit near ±ANGLE_SHIFT
HIGH_RATE = 1e3  # rad/s (m/s for the cart): the largest rate of the high-speed states
STIFF_DAMPING = 1e4  # N·m·s/rad (N·s/m on the cart)
ENERGY_INCREASE_TOL = 1e-12  # largest allowed per-step energy rise, relative to the energy scale
BOUNDED_GROWTH = 1.5  # symplectic: late-half max |ΔE| ≤ this × early-half max |ΔE|
MIN_R2 = 0.9  # RK4's energy error must be this close to a straight line in t
MIN_ORDER_RATIO = 10.0  # RK4 drift slope at h over slope at h/2 (2⁴ = 16 for order 4)
MOMENTUM_K = 64  # cyclic momentum: allowed drift per step, in ε times |p|scale
RK4_UNSTABLE = 2.0  # |R(hλ)| above this predicts an RK4 blow-up
DP_DET_MASSES = (1e-3, 1e-6, 1e-9)  # kg, m1 of the point-mass double pendulum in the det comparison
ORDER_FRACTION = 0.2  # share of the long horizon over which RK4 at h/2 measures its slope


@dataclass
class StressResult:
    """One row of the catalogue: the evidence of one hard case."""

    case: str
    quantity: str
    error: float | None
    tolerance: float | None
    kappa_raw: float | None
    kappa_scaled: float | None
    invariant: str | None
    passed: bool
    note: str = ""
    #: worst conditioning verdict over the accepted states: ok, warn (fewer digits)
    level: str = "ok"
    refused: int = 0
    seed: int = SEED
    seconds: float = 0.0

    @property
    def verdict(self) -> str:
        """FAIL; refused (as the case expects: no state could be verified); or pass, with qualifiers."""
        if not self.passed:
            return "FAIL"
        if self.level == "refuse":
            return "refused"
        extra = (["warn"] if self.level == "warn" else []) + (
            [f"{self.refused} refused"] if self.refused else []
        )
        return f"pass ({', '.join(extra)})" if extra else "pass"

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["verdict"] = self.verdict
        return d


@dataclass(frozen=True)
class Settings:
    """Sizes of the catalogue; ``QUICK`` keeps every case but shortens the work."""

    random_states: int = 24
    long_horizon: float = 1e4  # s
    long_step: float = 2.0  # s
    stiff_horizon: float = 10.0  # s
    stiff_step: float = 0.05  # s
    explicit_horizon: float = 2e-3  # s of RK45 on the stiff system
    zero_g_steps: int = 1000
    zero_g_step: float = 0.01  # s
    study_masses: tuple[float, ...] = tuple(10.0**-k for k in range(17))


FULL = Settings()
QUICK = Settings(
    random_states=6,
    long_horizon=2e3,
    stiff_horizon=2.0,
    explicit_horizon=5e-4,
    zero_g_steps=300,
    study_masses=(1.0, 1e-4, 1e-7, 1e-8, 1e-12, 1e-16),
)


@dataclass
class Context:
    settings: Settings = FULL
    seed: int = SEED
    study: StudyResult | None = None
    #: the URDF (text or path) the cases compare with; None: the one the project writes for each set
    urdf: str | None = None

    def system(self, params):
        """Pinocchio's side for a parameter set: ``urdf`` if given (the battery's), else the project's."""
        if self.urdf is None:
            return system_for(params)
        return PinocchioSystem.for_model(MODELS[params.model], self.urdf, params.g, "<URDF being certified>")

    def trust_study(self) -> StudyResult:
        if self.study is None:
            self.study = trust_study(default("cart_double_pendulum"), self.settings.study_masses)
        return self.study


@dataclass(frozen=True)
class Case:
    name: str
    group: str
    run: Callable[[Context, str], StressResult]


# --- parameter sets --------------------------------------------------------------------------
def default(model: str):
    return load_parameter_file(default_parameter_file(model))[2]


def dp_scaled(length: float = 1.0, **changes) -> DoublePendulumParams:
    """The default double pendulum with every length × ``length`` (inertias × length²)."""
    p = default("double_pendulum")
    s = length
    p = p.replace(l1=p.l1 * s, l2=p.l2 * s, r1=p.r1 * s, r2=p.r2 * s, I1=p.I1 * s * s, I2=p.I2 * s * s)
    return p.replace(**changes)


def dp_link_mass_ratio(ratio: float) -> DoublePendulumParams:
    """m1/m2 = ratio (m2 kept); link 1's inertia scales with its mass."""
    p = default("double_pendulum")
    return p.replace(m1=ratio * p.m2, I1=p.I1 * ratio * p.m2 / p.m1)


def dp_link_lengths(s1: float, s2: float) -> DoublePendulumParams:
    p = default("double_pendulum")
    return p.replace(l1=p.l1 * s1, r1=p.r1 * s1, I1=p.I1 * s1**2, l2=p.l2 * s2, r2=p.r2 * s2, I2=p.I2 * s2**2)


def cart(**changes) -> CartDoublePendulumParams:
    return default("cart_double_pendulum").replace(**changes)


# --- comparing closed form and Pinocchio --------------------------------------------------------
def system_for(params):
    return PinocchioSystem.for_params(params)


# Terms the core checks' scales leave out (to be moved into ``pendverify.checks.catalogue``):
#  * the closed forms may build the friction-free C as (seed's C) − D, so C, C·q̇ and Ṁ − 2C
#    carry rounding of size ε·|D̃| (the double pendulum at b = 1e4, or at b = 0.05 on a 1 mm
#    scale, where β·θ̇ ≪ b);
#  * Pinocchio's rounding is ε times its world-frame terms, A times the result
#    (``pendverify.checks.trust.term_amplification``), added as an allowance K·ε·(A − 1)·scale,
#    so that it adds to the angle's rounding rather than multiplying it;
#  * a scale of 0 (g = 0 at rest): the quantity must then be exactly 0.
_FRICTION_TERMS = {"coriolis": "matrix", "skew": "matrix", "rnea": "force"}


def _friction_scale(model, state, kind: str) -> float:
    w = 1.0 / np.sqrt(model.diagonal_scale(state.q))
    D = np.abs(model.damping_matrix()) * np.outer(w, w)
    if kind == "matrix":
        return float(np.max(D))
    return float(np.max(D @ np.abs(state.v / w)))


def guarded(check: Check, amplification: Callable[[State], float]) -> Check:
    """A core check with the scale terms above added; ``amplification(state)`` gives A."""
    kind = _FRICTION_TERMS.get(check.name)

    def evaluate(model, system, state):
        s = check.evaluate(model, system, state)
        scale = s.scale + (_friction_scale(model, state, kind) if kind else 0.0)
        if not scale > 0:
            return Sample(s.error, 1.0 if s.error == 0 else TINY, s.allowance, s.note)
        extra = check.K * EPS * (amplification(state) - 1.0) * scale
        return Sample(s.error, scale, s.allowance + extra, s.note)

    return dataclasses.replace(check, evaluate=evaluate)


def _ratio(r) -> float:
    return r.max_error / r.tolerance if r.tolerance > 0 else math.inf


@dataclass
class _Comparison:
    results: list
    kept: int
    refused: list[str]
    kappa_raw: float
    kappa_scaled: float
    amplification: float
    level: str


def compare(name: str, model, system, states: list[State], seed: int) -> _Comparison:
    """Guard every state (validity, conditioning), then run the nine checks on the accepted ones."""
    kept, refused, factor = [], [], {}
    kappa_raw = kappa_scaled = amplification = 0.0
    level = "ok"
    for s in states:
        model_state(model, s.q, s.v, s.u, s.w, source=f"<{name}: {s.label}>")
        try:
            c = check_conditioning(model, s.q, system, what=name)
        except IllConditionedError as exc:
            refused.append(str(exc))
            continue
        kept.append(s)
        factor[id(s)] = c.amplification
        kappa_raw, kappa_scaled = max(kappa_raw, c.kappa_raw), max(kappa_scaled, c.kappa_scaled)
        amplification = max(amplification, c.amplification)
        level = "warn" if c.level == "warn" else level
    names = applicable_checks(model, system)
    checks = [guarded(c, lambda state: factor[id(state)]) for c in CHECKS if c.name in names]
    with np.errstate(all="ignore"):
        results = [run_check(c, name, model, system, kept, seed) for c in checks] if kept else []
    return _Comparison(results, len(kept), refused, kappa_raw, kappa_scaled, amplification, level)


#: What a case expects of the trust rule: no refusal, some states refused (and some
#: verified), every state refused, or whatever (at least one state verified).
EXPECT = ("none", "some", "all", "any")


def _refusals_ok(comp: _Comparison, expect: str) -> bool:
    refused, kept = len(comp.refused), comp.kept
    return {
        "none": refused == 0,
        "some": refused > 0 and kept > 0,
        "all": kept == 0 and refused > 0,
        "any": kept > 0,
    }[expect]


def _result_from(name, comp: _Comparison, expect: str = "none", invariant=None, extra_ok=True, note=""):
    notes = [note] if note else []
    failed = [r for r in comp.results if not r.passed]
    if comp.results:
        worst = max(comp.results, key=_ratio)
        error, tolerance = worst.max_error, worst.tolerance
        quantity = f"{worst.check} (worst of {len(comp.results)} checks, {comp.kept} states)"
        if failed:
            notes.append(
                "FAIL "
                + ", ".join(
                    f"{r.check} {r.max_error:.2g} > {r.tolerance:.2g} at {r.worst_state['label']}"
                    for r in failed
                )
            )
    else:
        error = tolerance = None
        quantity = "no state verified"
    if comp.refused:
        notes.append(
            f"refused {len(comp.refused)} of {len(comp.refused) + comp.kept} states, e.g. {comp.refused[0]}"
        )
    refusals_ok = _refusals_ok(comp, expect)
    if not refusals_ok:
        notes.append(
            f"refusals: expected {expect!r}, got {len(comp.refused)} of {len(comp.refused) + comp.kept}"
        )
    return StressResult(
        case=name,
        quantity=quantity,
        error=error,
        tolerance=tolerance,
        kappa_raw=comp.kappa_raw if comp.kept else None,
        kappa_scaled=comp.kappa_scaled if comp.kept else None,
        invariant=invariant,
        passed=not failed and refusals_ok and extra_ok,
        note="; ".join(notes),
        level="refuse" if comp.kept == 0 else comp.level,
        refused=len(comp.refused),
    )


def _model(params, model_cls=None):
    """The closed-form model of a parameter set (``model_cls`` plants a different one, for tests)."""
    return (model_cls or MODELS[params.model])(params)


def _states(model, ctx: Context) -> list[State]:
    return sample_states(model, ctx.settings.random_states, ctx.seed)


def checks_case(
    name: str, group: str, params_fn, expect: str = "none", extra_states=None, model_cls=None
) -> Case:
    if expect not in EXPECT:
        raise ValueError(f"expect must be one of {EXPECT}")

    def run(ctx: Context, name: str) -> StressResult:
        params = params_fn()
        model = _model(params, model_cls)
        states = _states(model, ctx) + (extra_states(model) if extra_states else [])
        comp = compare(name, model, ctx.system(params), states, ctx.seed)
        return _result_from(name, comp, expect)

    return Case(name, group, run)


# --- large angles and high speeds -------------------------------------------------------------
class ReducedAngleSystem:
    """A Pinocchio system evaluated at θ reduced to (−π, π] (angular coordinates only).

    Checking a closed form at θ against this system at θ mod 2π tests that results
    are invariant under θ + 2πk (to the rounding of θ itself, ε·|θ|).
    """

    _METHODS = (
        "mass_matrix",
        "det_mass_matrix",
        "inverse_mass_matrix",
        "bias",
        "gravity",
        "coriolis_matrix",
        "mass_matrix_derivative",
        "acceleration",
        "kinetic_energy",
        "potential_energy",
    )

    def __init__(self, system, angular):
        self._system, self._angular = system, np.asarray(angular)

    def reduce(self, theta) -> np.ndarray:
        theta = np.asarray(theta, dtype=float)
        turns = np.where(self._angular, np.round(theta / (2 * math.pi)), 0.0)
        return theta - turns * (2 * math.pi)

    def __getattr__(self, name):
        attribute = getattr(self._system, name)
        if name not in self._METHODS:
            return attribute
        return lambda theta, *rest: attribute(self.reduce(theta), *rest)


def shifted_states(model, states: list[State]) -> list[State]:
    """Each state with its angles moved by ±2πk, |2πk| ≈ ``ANGLE_SHIFT``, alternating sign."""
    k = round(ANGLE_SHIFT / (2 * math.pi))
    angular = np.array(model.angular)
    out = []
    for i, s in enumerate(states):
        shift = np.where(angular, (1 if i % 2 == 0 else -1) * k * 2 * math.pi, 0.0)
        out.append(dataclasses.replace(s, label=f"{s.label} +2πk", q=s.q + shift))
    return out


def large_angle_case(name: str, params_fn, model_cls=None, expect: str = "none") -> Case:
    """|θ| ≈ 1e6 rad; ``expect`` says which refusals by the trust rule are acceptable (see EXPECT)."""

    def run(ctx: Context, name: str) -> StressResult:
        params = params_fn()
        model = _model(params, model_cls)
        system = ctx.system(params)
        states = shifted_states(model, _states(model, ctx))
        direct = compare(name, model, system, states, ctx.seed)
        invariance = compare(name, model, ReducedAngleSystem(system, model.angular), states, ctx.seed)
        inv_worst = max(invariance.results, key=_ratio)
        inv_ok = all(r.passed for r in invariance.results) and _refusals_ok(invariance, expect)
        angle = max(float(np.max(np.abs(s.q[np.array(model.angular)]))) for s in states)
        invariant = (
            f"2πk invariance (closed form at θ vs Pinocchio at θ mod 2π): {inv_worst.max_error:.2g} "
            f"≤ {inv_worst.tolerance:.2g} ({inv_worst.check}); |θ| up to {angle:.3g} rad"
        )
        note = "" if inv_ok else f"FAIL invariance {inv_worst.check} at {inv_worst.worst_state['label']}"
        return _result_from(name, direct, expect, invariant, inv_ok, note)

    return Case(name, "large angle", run)


def high_speed_case(name: str, params_fn, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> StressResult:
        from pendverify.checks.sampling import RATE_RANGE

        params = params_fn()
        model = _model(params, model_cls)
        system = ctx.system(params)
        states = [dataclasses.replace(s, v=s.v * (HIGH_RATE / RATE_RANGE)) for s in _states(model, ctx)]
        comp = compare(name, model, system, states, ctx.seed)
        finite = all(np.isfinite(r.max_abs_error) for r in comp.results)
        rate = max(float(np.max(np.abs(s.v))) for s in states)
        invariant = f"|q̇| up to {rate:.3g}; all quantities finite: {'yes' if finite else 'NO'}"
        return _result_from(name, comp, "none", invariant, finite)

    return Case(name, "high speed", run)


# --- the near-singular cart ---------------------------------------------------------------------
def _aligned_states(model) -> list[State]:
    zero_u, zero_w = np.zeros(len(model.inputs)), np.zeros(len(model.disturbances))
    return [State(label, y, v, u, w) for label, (y, v, u, w) in study_states().items()] + [
        State("theta1=theta2=0 at rest", np.zeros(3), np.zeros(3), zero_u, zero_w)
    ]


def trust_case(ctx: Context, name: str) -> StressResult:
    study = ctx.trust_study()
    accepted = [r for r in study.rows if r.level != "refuse"]
    worst = max(accepted, key=lambda r: r.worst / r.bound)
    within = all(r.worst <= REFUSE_REL for r in accepted)
    conservative = study.accepted_limit >= study.measured_limit
    passed = not study.violations and within and conservative and study.zero_mass_refused
    invariant = (
        f"measured trust (all quantities ≤ {REFUSE_REL:g} vs 50 digits) down to m1 = "
        f"{study.measured_limit:.0e} kg; guard accepts m1 ≥ {study.accepted_limit:.0e} kg; "
        f"m1 = 0: {'refused' if study.zero_mass_refused else 'NOT refused'}"
    )
    notes = [study.zero_mass_note, *study.violations]
    if not conservative:
        notes.append("the guard accepts m1 below the measured trust limit")
    return StressResult(
        case=name,
        quantity=f"det, q̈, M⁻¹ vs 50-digit mpmath ({len(study.rows)} rows), worst accepted",
        error=worst.worst,
        tolerance=worst.bound,
        kappa_raw=max(r.kappa_raw for r in accepted),
        kappa_scaled=max(r.kappa_scaled for r in accepted),
        invariant=invariant,
        passed=passed,
        note="; ".join(notes),
        level="warn" if any(r.level == "warn" for r in accepted) else "ok",
        refused=sum(r.level == "refuse" for r in study.rows),
    )


def det_case(ctx: Context, name: str) -> StressResult:
    """The cart's closed-form det (non-negative terms) stays at ε level even where LU fails."""
    from pendverify.checks.trust import KAPPA_K

    study = ctx.trust_study()
    finite_m = [r for r in study.rows if r.kappa_scaled < 1 / EPS]  # M itself representable
    worst_cf = max(r.det_closed_form for r in finite_m)
    worst_lu = max(finite_m, key=lambda r: r.det_lu)
    tol = KAPPA_K * EPS
    return StressResult(
        case=name,
        quantity="closed-form det M vs 50 digits (LU of CRBA alongside)",
        error=worst_cf,
        tolerance=tol,
        kappa_raw=max(r.kappa_raw for r in finite_m),
        kappa_scaled=max(r.kappa_scaled for r in finite_m),
        invariant=(
            f"closed form ≤ {worst_cf:.1e} for all m1 ≥ {min(r.m1 for r in finite_m):.0e} kg; "
            f"LU reaches {worst_lu.det_lu:.1e} at m1 = {worst_lu.m1:.0e} kg (≈ ε·κ̃)"
        ),
        passed=worst_cf <= tol,
    )


def dp_det_case(ctx: Context, name: str) -> StressResult:
    """The double pendulum's closed-form det, αδ − δ² − β²cos²θ2, is a difference: no better than LU."""
    from pendverify.checks.trust import KAPPA_K, assess
    from pendverify.stress.trust_study import det_accuracy

    base = default("double_pendulum").replace(I1=0.0, I2=0.0)  # point masses: det → m1 r1² m2 r2² at θ2 = 0
    rows = []
    for m1 in DP_DET_MASSES:
        params = base.replace(m1=m1)
        model = MODELS[params.model](params)
        for theta2 in (0.0, math.pi):
            q = np.array([0.3, theta2])
            closed, lu = det_accuracy(params, q)
            rows.append((m1, theta2, closed, lu, assess(model, q)))
    ratio = max(max(c, lu) / (KAPPA_K * EPS * v.kappa_scaled) for _, _, c, lu, v in rows)
    worst = max(rows, key=lambda r: max(r[2], r[3]) / r[4].kappa_scaled)
    better = ", ".join(
        f"m1 = {m1:.0e} θ2 = {'π' if t2 else '0'}: {'closed' if c < lu else 'LU'} ({c:.1e} vs {lu:.1e})"
        for m1, t2, c, lu, _ in rows
        if m1 <= 1e-6
    )
    return StressResult(
        case=name,
        quantity="max(closed-form det, LU det) error vs 50 digits, over K·ε·κ̃",
        error=max(worst[2], worst[3]),
        tolerance=KAPPA_K * EPS * worst[4].kappa_scaled,
        kappa_raw=max(r[4].kappa_raw for r in rows),
        kappa_scaled=max(r[4].kappa_scaled for r in rows),
        invariant=f"both within K·ε·κ̃ (worst ratio {ratio:.2g}); more accurate: {better}",
        passed=ratio <= 1.0,
    )


# --- simulations --------------------------------------------------------------------------------
def energy_scale(model, q, v) -> float:
    """½ q̇ᵀ M q̇ + Σ gravity_scale: a bound on |T| + |V| (J)."""
    return model.kinetic_energy(q, v) + float(np.sum(model.gravity_scale()))


def _kappa(model, q):
    from pendverify.checks.trust import conditioning

    return conditioning(model.mass_matrix(q), model.diagonal_scale(q))


def stiff_sim_case(name: str, params_fn, q0, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> StressResult:
        from pendverify.stress import integrators as si

        st = ctx.settings
        params = params_fn()
        model = _model(params, model_cls)
        q0_, v0 = np.asarray(q0, dtype=float), np.zeros(model.nv)
        n = round(st.stiff_horizon / st.stiff_step)
        implicit = si.implicit_euler(model, q0_, v0, st.stiff_step, n)
        E = si.energies(model, implicit)
        rise = float(np.max(np.diff(E))) / energy_scale(model, q0_, v0) if len(E) > 1 else 0.0
        stable = implicit.blew_up_at is None and bool(np.all(np.isfinite(E)))
        monotone = stable and rise <= ENERGY_INCREASE_TOL
        c = _kappa(model, q0_)
        result = StressResult(
            case=name,
            quantity="per-step energy rise, backward Euler (relative to |T|+|V| bound)",
            error=max(rise, 0.0) if stable else math.inf,
            tolerance=ENERGY_INCREASE_TOL,
            kappa_raw=c.kappa_raw,
            kappa_scaled=c.kappa_scaled,
            invariant=(
                f"backward Euler h={st.stiff_step:g} s, {n} steps over {st.stiff_horizon:g} s: "
                + (f"E never rises (largest step change {rise:+.1e} of scale)" if monotone else "E RISES")
            ),
            passed=False,
            note="" if stable else f"implicit method failed: {implicit.note}",
            level=c.level,
        )
        if not monotone:
            result.note = "; ".join(filter(None, [result.note, "explicit methods skipped"]))
            return result
        growth = si.rk4_growth(si.jacobian(si._accel(model), np.concatenate([q0_, v0])), st.stiff_step)
        explicit = si.rk4(model, q0_, v0, st.stiff_step, n)
        predicted, observed = growth > RK4_UNSTABLE, explicit.blew_up_at is not None
        adaptive = si.rk45(model, q0_, v0, st.explicit_horizon)
        light = si.rk45(MODELS[params.model](default(params.model)), q0_, v0, st.explicit_horizon)
        per_horizon = adaptive.steps * st.stiff_horizon / st.explicit_horizon
        result.invariant += (
            f"; RK4 at h={st.stiff_step:g}: "
            + (f"blows up after {explicit.blew_up_at} steps" if observed else "stays finite")
            + f" (predicted growth ×{growth:.1e}/step); RK45 needs {adaptive.steps} steps for "
            f"{st.explicit_horizon:g} s (≈{per_horizon:.1e} for {st.stiff_horizon:g} s) vs "
            f"{light.steps} at default damping"
        )
        result.passed = predicted == observed and adaptive.blew_up_at is None and adaptive.steps > 0
        if predicted != observed:
            result.note = (
                f"RK4 stability predicted {'a blow-up' if predicted else 'none'}, observed the opposite"
            )
        return result

    return Case(name, "stiff damping", run)


def long_horizon_params() -> DoublePendulumParams:
    """A mild, conservative double pendulum: the default scaled to l1 = 1 km (period ≈ 1 min)."""
    return dp_scaled(2000.0, b1=0.0, b2=0.0)


LONG_HORIZON_Q0 = (-math.pi / 2 + 0.5, 0.3)  # 0.5 rad from hanging, link 2 bent by 0.3 rad


def long_horizon_case(name: str, params_fn=long_horizon_params, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> StressResult:
        from pendverify.stress import integrators as si

        st = ctx.settings
        params = params_fn()
        model = _model(params, model_cls)
        q0, v0 = np.array(LONG_HORIZON_Q0), np.zeros(2)
        h, T = st.long_step, st.long_horizon
        n = round(T / h)
        record = max(1, n // 500)
        scale = energy_scale(model, q0, v0)

        def drift(traj):
            dE = (si.energies(model, traj) - si.energy(model, q0, v0)) / scale
            slope, r2 = si.fit_slope(traj.t, dE)
            return dE, slope, r2

        sv = si.stormer_verlet(model, q0, v0, h, n, record)
        # the order test needs a slope, not the whole horizon: RK4 at h/2 runs ORDER_FRACTION of it
        n_half = 2 * max(1, round(n * ORDER_FRACTION))
        rk, rk_half = si.rk4(model, q0, v0, h, n, record), si.rk4(model, q0, v0, h / 2, n_half, 2 * record)
        finite = all(t.blew_up_at is None for t in (sv, rk, rk_half))
        dE_sv, slope_sv, _ = drift(sv)
        _, slope_rk, r2_rk = drift(rk)
        _, slope_half, r2_half = drift(rk_half)
        half = len(dE_sv) // 2
        early, late = float(np.max(np.abs(dE_sv[:half]))), float(np.max(np.abs(dE_sv[half:])))
        ratio = abs(slope_rk) / abs(slope_half) if slope_half != 0 else math.inf
        bounded = late <= BOUNDED_GROWTH * early + 4 * EPS
        linear = min(r2_rk, r2_half) >= MIN_R2 and ratio >= MIN_ORDER_RATIO
        invariant = (
            f"E drift slope (relative, per s): RK4 h={h:g} s {slope_rk:+.2e} (R² {r2_rk:.3f}), "
            f"h={h / 2:g} s {slope_half:+.2e} (R² {r2_half:.3f}, first {n_half * h / 2:g} s), "
            f"ratio {ratio:.1f}; "
            f"Störmer–Verlet h={h:g} s {slope_sv:+.2e}, |ΔE| ≤ {max(early, late):.1e} "
            f"(first half {early:.1e}, second half {late:.1e})"
        )
        c = _kappa(model, q0)
        notes = []
        if not bounded:
            notes.append("symplectic energy error grows")
        if not linear:
            notes.append(
                f"RK4 drift not a clean order-4 line (R² {min(r2_rk, r2_half):.2f}, ratio {ratio:.1f})"
            )
        return StressResult(
            case=name,
            quantity=f"Störmer–Verlet |ΔE|/E over {T:g} s: second half vs first half",
            error=late,
            tolerance=BOUNDED_GROWTH * early + 4 * EPS,
            kappa_raw=c.kappa_raw,
            kappa_scaled=c.kappa_scaled,
            invariant=invariant,
            passed=finite and bounded and linear,
            note="; ".join(notes),
        )

    return Case(name, "long horizon", run)


def zero_gravity_sim_case(name: str, params_fn, q0, v0, cyclic: int, label: str, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> StressResult:
        from pendverify.stress import integrators as si

        st = ctx.settings
        params = params_fn()
        model = _model(params, model_cls)
        q0_, v0_ = np.asarray(q0, dtype=float), np.asarray(v0, dtype=float)
        traj = si.stormer_verlet(model, q0_, v0_, st.zero_g_step, st.zero_g_steps, record=10)
        p = si.momenta(model, traj)[:, cyclic]
        p_scale = float(np.max(np.abs(si.momenta(model, traj))))
        drift = float(np.max(np.abs(p - p[0]))) / p_scale
        tol = MOMENTUM_K * EPS * st.zero_g_steps
        dE = si.energies(model, traj)
        e_rel = float(np.max(np.abs(dE - dE[0]))) / energy_scale(model, q0_, v0_)
        c = _kappa(model, q0_)
        return StressResult(
            case=name,
            quantity=f"momentum {label} drift / |p|, Störmer–Verlet",
            error=drift,
            tolerance=tol,
            kappa_raw=c.kappa_raw,
            kappa_scaled=c.kappa_scaled,
            invariant=(
                f"{label} conserved to {drift:.1e} over {st.zero_g_steps} steps of "
                f"{st.zero_g_step:g} s; energy error ≤ {e_rel:.1e} (bounded)"
            ),
            passed=traj.blew_up_at is None and drift <= tol,
        )

    return Case(name, "zero gravity", run)


# --- invalid input ----------------------------------------------------------------------------
def invalid_input_case(ctx: Context, name: str) -> StressResult:
    from pendverify.validate import finite_state

    dp, cp = default("double_pendulum"), default("cart_double_pendulum")
    model = MODELS["double_pendulum"](dp)
    attempts: dict[str, Callable[[], object]] = {
        "NaN state": lambda: model_state(model, [math.nan, 0.0]),
        "infinite rate": lambda: model_state(model, [0.0, 0.0], [0.0, math.inf]),
        "NaN input": lambda: finite_state("u", [0.0, math.nan]),
        "NaN parameter": lambda: dp.replace(m1=math.nan),
        "infinite parameter": lambda: cp.replace(l2=math.inf),
        "negative mass": lambda: cp.replace(m=-1.0),
        "zero length": lambda: dp.replace(l1=0.0),
        "I2 = r2 = 0 (singular M)": lambda: dp.replace(I2=0.0, r2=0.0),
        "m1 = 0 on the cart": lambda: cp.replace(m1=0.0),
    }
    messages, silent = [], []
    for label, attempt in attempts.items():
        try:
            attempt()
        except PendverifyError as exc:
            messages.append(f"{label}: {exc}")
        else:
            silent.append(label)
    return StressResult(
        case=name,
        quantity=f"{len(attempts)} bad inputs, each must raise a PendverifyError",
        error=float(len(silent)),
        tolerance=0.0,
        kappa_raw=None,
        kappa_scaled=None,
        invariant=f"{len(messages)} rejected with key, value and rule",
        passed=not silent,
        note=("accepted silently: " + ", ".join(silent)) if silent else messages[0],
    )


# --- the catalogue ------------------------------------------------------------------------------
def _const(fn, *args, **kw):
    return lambda: fn(*args, **kw)


def catalogue() -> list[Case]:
    dp_default = default("double_pendulum")
    cases = [
        checks_case("cart/bobs mass 1e-6", "mass ratio", _const(cart, m=1.25e-6)),
        checks_case("cart/bobs mass 1e6", "mass ratio", _const(cart, m=1.25e6)),
        checks_case("cart bob1/bob2 mass 1e-6", "mass ratio", _const(cart, m1=0.75e-6), "any"),
        checks_case("cart bob1/bob2 mass 1e6", "mass ratio", _const(cart, m1=0.75e6)),
        checks_case("link1/link2 mass 1e-6", "mass ratio", _const(dp_link_mass_ratio, 1e-6)),
        checks_case("link1/link2 mass 1e6", "mass ratio", _const(dp_link_mass_ratio, 1e6)),
        checks_case("double pendulum lengths ×1e-3 (mm)", "length", _const(dp_scaled, 1e-3)),
        checks_case("double pendulum lengths ×1e3 (km)", "length", _const(dp_scaled, 1e3)),
        checks_case("double pendulum l1 1e-2 m, l2 10 m", "length", _const(dp_link_lengths, 0.02, 10 / 0.45)),
        checks_case(
            "double pendulum l1 10 m, l2 1e-2 m", "length", _const(dp_link_lengths, 20.0, 0.01 / 0.45)
        ),
        checks_case(
            "double pendulum l1 1e-3 m, l2 1e3 m", "length", _const(dp_link_lengths, 2e-3, 1e3 / 0.45), "all"
        ),
        checks_case(
            "double pendulum l1 1e3 m, l2 1e-3 m", "length", _const(dp_link_lengths, 2e3, 1e-3 / 0.45), "all"
        ),
        checks_case("cart rods 1e-3 m", "length", _const(cart, l1=1e-3, l2=1e-3), "any"),
        checks_case("cart rods 1e3 m", "length", _const(cart, l1=1e3, l2=1e3)),
        checks_case("cart rods 1e-2 m / 10 m", "length", _const(cart, l1=1e-2, l2=10.0)),
        checks_case("cart rods 10 m / 1e-2 m", "length", _const(cart, l1=10.0, l2=1e-2)),
        checks_case("cart rods 1e-3 m / 1e3 m", "length", _const(cart, l1=1e-3, l2=1e3), "all"),
        checks_case("cart rods 1e3 m / 1e-3 m", "length", _const(cart, l1=1e3, l2=1e-3), "all"),
        Case("cart m1 → 0: trust study", "near singular", trust_case),
        Case("cart det M: closed form vs LU", "near singular", det_case),
        Case("double pendulum det M: closed form vs LU", "near singular", dp_det_case),
        checks_case(
            "cart m1 = 1e-6 kg (warn)", "near singular", _const(cart, m1=1e-6), "any", _aligned_states
        ),
        checks_case(
            "cart m1 = 1e-12 kg (refuse aligned)",
            "near singular",
            _const(cart, m1=1e-12),
            "some",
            _aligned_states,
        ),
        checks_case("point masses (I1 = I2 = 0)", "point mass", _const(dp_default.replace, I1=0.0, I2=0.0)),
        checks_case(
            "centres of mass at the joints (r = 0)", "point mass", _const(dp_default.replace, r1=0.0, r2=0.0)
        ),
        checks_case("point mass link 1, r2 = 0", "point mass", _const(dp_default.replace, I1=0.0, r2=0.0)),
        large_angle_case("double pendulum |θ| ≈ 1e6 rad", _const(default, "double_pendulum")),
        large_angle_case("cart |θ| ≈ 1e6 rad", _const(default, "cart_double_pendulum")),
        high_speed_case("double pendulum |q̇| ≤ 1e3", _const(default, "double_pendulum")),
        high_speed_case("cart |q̇| ≤ 1e3", _const(default, "cart_double_pendulum")),
        checks_case("double pendulum b = 1e4", "stiff damping", _const(dp_default.replace, b1=1e4, b2=1e4)),
        checks_case("cart d = 1e4", "stiff damping", _const(cart, d1=1e4, d2=1e4, d3=1e4)),
        stiff_sim_case(
            "double pendulum b = 1e4: simulate",
            _const(dp_default.replace, b1=STIFF_DAMPING, b2=STIFF_DAMPING),
            (-math.pi / 2 + 0.5, 0.3),
        ),
        stiff_sim_case(
            "cart d = 1e4: simulate",
            _const(cart, d1=STIFF_DAMPING, d2=STIFF_DAMPING, d3=STIFF_DAMPING),
            (0.0, math.pi - 0.5, math.pi + 0.3),
        ),
        long_horizon_case("double pendulum 1e4 s, conservative"),
        checks_case("double pendulum g = 0", "zero gravity", _const(dp_default.replace, g=0.0)),
        checks_case("cart g = 0", "zero gravity", _const(cart, g=0.0)),
        zero_gravity_sim_case(
            "double pendulum g = 0: simulate",
            _const(dp_default.replace, g=0.0, b1=0.0, b2=0.0),
            (0.3, 0.5),
            (1.0, -2.0),
            0,
            "p_θ1",
        ),
        zero_gravity_sim_case(
            "cart g = 0: simulate",
            _const(cart, g=0.0, d1=0.0, d2=0.0, d3=0.0),
            (0.0, 0.3, -0.4),
            (0.5, 1.0, -2.0),
            0,
            "p_q",
        ),
        Case("NaN, inf, negative, zero", "invalid input", invalid_input_case),
    ]
    return cases


CASE_NAMES = tuple(c.name for c in catalogue())


@dataclass
class StressReport:
    settings: Settings
    seed: int
    results: list[StressResult] = field(default_factory=list)
    study: StudyResult | None = None
    elapsed_s: float = 0.0

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.results)


def run_case(case: Case, ctx: Context) -> StressResult:
    started = time.perf_counter()
    result = case.run(ctx, case.name)
    result.seconds = time.perf_counter() - started
    result.seed = ctx.seed
    return result


def run_catalogue(settings: Settings = FULL, names=None, seed: int = SEED) -> StressReport:
    """Run the catalogue (or the named cases) and keep the evidence."""
    started = time.perf_counter()
    ctx = Context(settings, seed)
    cases = [c for c in catalogue() if names is None or c.name in names]
    report = StressReport(settings, seed, [run_case(c, ctx) for c in cases], ctx.study)
    report.elapsed_s = time.perf_counter() - started
    return report
