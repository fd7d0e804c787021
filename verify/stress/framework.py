"""The stress framework: results, settings, the guarded comparison, and a case on a description.

The comparison guards every state with the trust rule and then runs the core
checks exactly as ``pendverify check`` does: one tolerance model
(``pendverify.checks.catalogue``).  Every case that compares with Pinocchio runs on a
model class, its robot description and a parameter set (``on_description``), whatever
the model: a model file's (``pendverify.stress.generic``) or a reference system's
(``pendverify.stress.catalogue``).

The cases live in ``pendverify.stress.cases`` (states and parameters),
``pendverify.stress.sim_cases`` (simulations), ``pendverify.stress.singular`` (near-singular
M) and ``pendverify.stress.reference_cases`` (the reference systems' own studies).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import DEFAULT_SEED, State, sample_states
from pendverify.checks.trust import WARN_REL
from pendverify.checks.verdict import REFUSED, WARN
from pendverify.checks.verification import trusted
from pendverify.errors import PendverifyError
from pendverify.robot.description import LoadedDescription, load_description
from pendverify.robot.system import PinocchioSystem
from pendverify.stress.trust_study import StudyResult, trust_study
from pendverify.validate import model_states

SEED = DEFAULT_SEED
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
    #: the robot description (URDF text, path, or as read by ``load_description``) the cases
    #: compare with (``on_description`` sets it per case)
    urdf: str | LoadedDescription | None = None
    #: the model class of the sets (``on_description`` sets it per case)
    model_cls: type | None = None
    #: the system of ``urdf`` at one g, if the caller has it (the battery's): the cases' systems at
    #: other g derive from it (``PinocchioSystem.with_gravity``) instead of reading ``urdf`` again
    urdf_system: PinocchioSystem | None = field(default=None, repr=False, compare=False)
    #: the systems made so far, by parameter set (cases on the same set share one)
    systems: dict = field(default_factory=dict, repr=False, compare=False)

    def system(self, params):
        """Pinocchio's side for a parameter set: ``urdf`` seen through ``model_cls``."""
        try:
            return self.systems[params]
        except (KeyError, TypeError):
            pass
        g = getattr(params, "g", None)
        given = self.urdf_system
        if given is not None:  # the URDF's system, built once: the cases' sets differ in g only
            system = given if g is None or g == given.g else given.with_gravity(g)
        else:
            if not isinstance(self.urdf, LoadedDescription):  # read once: the cases' sets differ in g only
                self.urdf = load_description(self.urdf, "<URDF being compared>")
            system = PinocchioSystem.for_model(self.model_cls, self.urdf, g)
        with contextlib.suppress(TypeError):  # a set that cannot be a key is not kept
            self.systems[params] = system
        return system

    def trust_study(self, base) -> StudyResult:
        """The m1 → 0 study of the set ``base`` (``pendverify.stress.trust_study``), run once per context:
        the catalogue's cases that read it ask for the same set."""
        if self.study is None:
            self.study = trust_study(base, self.settings.study_masses)
        return self.study


@dataclass(frozen=True)
class Case:
    name: str
    group: str
    run: Callable[[Context, str], StressResult]


def on_description(case: Case, urdf, model_cls) -> Case:
    """``case`` compared with the robot description ``urdf`` seen through ``model_cls``; a case
    that cannot run there (a PendverifyError) fails, saying why."""

    def run(ctx: Context, name: str) -> StressResult:
        try:
            return case.run(dataclasses.replace(ctx, urdf=urdf, model_cls=model_cls), name)
        except PendverifyError as exc:
            return StressResult(name, "not run", None, None, None, None, None, False, f"FAIL {exc}")

    return Case(case.name, case.group, run)


# --- comparing closed form and Pinocchio --------------------------------------------------------
def error_ratio(r) -> float:
    return r.max_error / r.tolerance if r.tolerance > 0 else math.inf


def judged_ratio(r) -> float:
    """``error_ratio``, or −inf for a check refused at every state (no error judged, NaN): the
    worst of a case's checks is a judged one, whose figures are numbers."""
    ratio = error_ratio(r)
    return -math.inf if math.isnan(ratio) else ratio


@dataclass
class GuardedComparison:
    """The core checks' results on the states the trust rule accepted, and what it refused."""

    results: list
    kept: int
    refused: list[str]
    kappa_raw: float
    kappa_scaled: float
    amplification: float
    level: str


def compare(
    name: str, model, system, states: list[State], seed: int, pinocchio_angles=None
) -> GuardedComparison:
    """Guard every state (validity, conditioning), then run the checks on the accepted ones.

    ``pinocchio_angles``: the map of the states' angles to those Pinocchio is evaluated at
    (``CheckBatch``), for the 2πk-invariance case.
    """
    model_states(model, states, lambda s: f"<{name}: {s.label}>")
    batch = CheckBatch(model, system, states, pinocchio_angles)
    kept, refused, verdicts = trusted(name, batch)

    def largest(name: str) -> float:
        return float(np.max(verdicts.worst(name)[kept], initial=0.0))

    kappa_raw, kappa_scaled, amplification = (
        largest("kappa_raw"),
        largest("kappa_scaled"),
        largest("amplification"),
    )
    level = "warn" if largest("bound") > WARN_REL else "ok"
    if not kept:
        return GuardedComparison([], 0, refused, kappa_raw, kappa_scaled, amplification, level)
    if refused:
        batch = batch.subset(kept)
    names = applicable_checks(model, system)
    results = run_checks(name, model, system, batch.states, seed, names, batch)
    return GuardedComparison(results, len(kept), refused, kappa_raw, kappa_scaled, amplification, level)


#: What a case expects of the trust rule: no refusal, some states refused (and some
#: verified), every state refused, whatever (at least one state verified), or not known
#: beforehand ("allowed": a generic case on a model file; refusals are counted, not failed).
EXPECT = ("none", "some", "all", "any", "allowed")


def refusals_as_expected(comp: GuardedComparison, expect: str) -> bool:
    refused, kept = len(comp.refused), comp.kept
    return {
        "none": refused == 0,
        "some": refused > 0 and kept > 0,
        "all": kept == 0 and refused > 0,
        "any": kept > 0,
        "allowed": True,
    }[expect]


def verified(result, expect: str) -> bool:
    """A check's result is what the case accepts: passed, or refused by the check's own rounding
    bound (forms derived from q̈ carry a wider one than the trust rule's) in a case whose refusals
    are counted, not failed: a generic case (``expect`` "allowed") and one that accepts refusals at
    whatever states (``expect`` "any", as the battery's large angles).  A refused result's judged
    states all passed (``judge.conclude``): a failing state makes it a failure."""
    return result.passed or (result.status == REFUSED and expect in ("any", "allowed"))


def stress_result(
    name, comp: GuardedComparison, expect: str = "none", invariant=None, extra_ok=True, note=""
):
    notes = [note] if note else []
    failed = [r for r in comp.results if not verified(r, expect)]
    refused = [r.check for r in comp.results if r.status == REFUSED]
    if refused:
        notes.append(
            f"{', '.join(refused)} refused at some states (the check's rounding bound above the trust limit)"
        )
    if comp.results:
        worst = max(comp.results, key=judged_ratio)
        error, tolerance = worst.max_error, worst.tolerance
        quantity = f"{worst.check} (worst of {len(comp.results)} checks, {comp.kept} states)"
        if failed:
            notes.append(
                "FAIL "
                + ", ".join(
                    f"{r.check} refused"
                    if r.status == REFUSED
                    else f"{r.check} {r.max_error:.2g} > {r.tolerance:.2g} at {r.worst_state['label']}"
                    for r in failed
                )
            )
        warned = [r for r in comp.results if r.status == WARN]
        if warned:
            first = next((r.notes[0] for r in warned if r.notes), "")
            notes.append(f"warn {', '.join(r.check for r in warned)}: {first}")
    else:
        error = tolerance = None
        quantity = "no state verified"
        warned = []
    if comp.refused:
        notes.append(
            f"refused {len(comp.refused)} of {len(comp.refused) + comp.kept} states, e.g. {comp.refused[0]}"
        )
    refusals_ok = refusals_as_expected(comp, expect)
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
        level="refuse" if comp.kept == 0 else ("warn" if warned else comp.level),
        refused=len(comp.refused),
    )


def model_of(params, model_cls, ctx: Context):
    """The closed-form model of a parameter set: ``model_cls``'s, or the context's model class."""
    return (model_cls or ctx.model_cls)(params)


def sampled_states(model, ctx: Context) -> list[State]:
    return sample_states(model, ctx.settings.random_states, ctx.seed)


def checks_case(
    name: str, group: str, params_fn, expect: str = "none", extra_states=None, model_cls=None
) -> Case:
    if expect not in EXPECT:
        raise ValueError(f"expect must be one of {EXPECT}")

    def run(ctx: Context, name: str) -> StressResult:
        params = params_fn()
        model = model_of(params, model_cls, ctx)
        states = sampled_states(model, ctx) + (extra_states(model) if extra_states else [])
        comp = compare(name, model, ctx.system(params), states, ctx.seed)
        return stress_result(name, comp, expect)

    return Case(name, group, run)
