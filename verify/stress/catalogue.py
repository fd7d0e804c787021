"""The reference systems' stress catalogue: hard cases that must stay numerically stable, or be refused.

The two reference systems (``pendverify stress`` without ``--analytic``) are two models the
catalogue lists as data (``CATALOGUE``): which model, which parameter sets (the model's
default set with values put in and factors multiplied in) and which hard states.  Each set
runs as any model's does (``pendverify.stress.generic``): the model class, its robot
description (the URDF the project writes for the set, ``robot.writer``) and the set, through
``framework.on_description``.  The studies that are no parameter set (the cart's m1 → 0
study, det M, bad input) are ``pendverify.stress.reference_cases``.

Each case is a named function returning a ``StressResult``: the achieved
relative error next to the tolerance used, κ(M) raw and after diagonal scaling
(the worst over the case's states), the simulation invariant where the case
simulates, and pass/fail.  Seeds are fixed (``SEED``) and recorded.

Groups and what passes
----------------------
``mass ratio``, ``length``, ``point mass``, ``stiff damping`` (closed form),
``zero gravity`` (closed form), ``near singular`` (single m1)
    The checks of ``pendverify.checks.catalogue`` (closed form vs Pinocchio, tolerance
    K·ε·((1 + |θ|max)·c_T + (A − 1))·scale in diagonally scaled coordinates) on seeded states,
    after ``check_conditioning``: a state the trust rule refuses is not compared.
    The tolerances are the core checks' own, A included (one tolerance
    model).  Passes when every check passes on the accepted states and the
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

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file, load_parameter_file
from pendverify.checks.sampling import State
from pendverify.display import html_table, listed
from pendverify.robot.writer import urdf_for
from pendverify.stress.cases import high_speed_case, large_angle_case
from pendverify.stress.framework import (
    FULL,
    SEED,
    STIFF_DAMPING,
    Case,
    Context,
    Settings,
    StressResult,
    checks_case,
    on_description,
)
from pendverify.stress.reference_cases import det_case, dp_det_case, invalid_input_case, trust_case
from pendverify.stress.sim_cases import long_horizon_case, stiff_sim_case, zero_gravity_sim_case
from pendverify.stress.trust_study import StudyResult, study_states

DP, CART = "double_pendulum", "cart_double_pendulum"


def default(model: str):
    """A reference system's default parameter set (its shipped TOML file)."""
    return load_parameter_file(default_parameter_file(model))[2]


# --- the catalogue, as data -----------------------------------------------------------------------
@dataclass(frozen=True)
class HardSet:
    """One hard case of a reference system: a parameter set (``model``'s default set, ``values`` put
    in, then ``factors`` multiplied in; a tuple of factors one after the other, as I·s·s), what is
    run on it (``kind``) and with which states."""

    name: str
    group: str
    model: str  # a reference system: a key of ``pendverify.analytic.MODELS``
    values: Mapping[str, float] = field(default_factory=dict)
    factors: Mapping[str, float | tuple[float, ...]] = field(default_factory=dict)
    kind: str = "checks"  # a key of ``KINDS``
    expect: str = "none"  # what the trust rule may refuse (``framework.EXPECT``)
    states: str = ""  # hard states added to the sampled ones: a key of ``HARD_STATES``
    start: tuple = ()  # a simulation's q0 (and q̇0; from rest without)
    momentum: tuple = ()  # zero gravity: (the cyclic coordinate, its momentum's label)

    def params(self):
        p = default(self.model).replace(**self.values)
        return p.replace(**{k: _times(getattr(p, k), f) for k, f in self.factors.items()})


def _times(value: float, factors) -> float:
    for f in factors if isinstance(factors, tuple) else (factors,):
        value = value * f
    return value


def _dp_lengths(s1: float, s2: float) -> dict:
    """Factors that make the double pendulum's link k s_k times longer: l_k, r_k × s_k, I_k × s_k²."""
    return {"l1": s1, "r1": s1, "I1": s1**2, "l2": s2, "r2": s2, "I2": s2**2}


def _dp_scaled(s: float) -> dict:
    """Every length of the double pendulum × s, its inertias × s·s."""
    return {"l1": s, "l2": s, "r1": s, "r2": s, "I1": (s, s), "I2": (s, s)}


def _dp_mass_ratio(r: float) -> dict:
    """m1/m2 = r: m1 and I1 × r·m2/m1, from the default m1 = 1 kg, m2 = 0.8 kg."""
    return {"m1": r * 0.8, "I1": (r, 0.8)}


def _aligned(model) -> list[State]:
    """The cart's aligned states, where det M ∝ m1 (the trust study's), and θ1 = θ2 = 0 at rest."""
    zero_u, zero_w = np.zeros(len(model.inputs)), np.zeros(len(model.disturbances))
    return [State(label, y, v, u, w) for label, (y, v, u, w) in study_states().items()] + [
        State("theta1=theta2=0 at rest", np.zeros(3), np.zeros(3), zero_u, zero_w)
    ]


#: hard states a set adds to the sampled ones, by name
HARD_STATES = {"aligned": _aligned}
MASS, LENGTH, SINGULAR, POINT = "mass ratio", "length", "near singular", "point mass"
STIFF, ZERO_G, ANGLE, SPEED = "stiff damping", "zero gravity", "large angle", "high speed"
_B, _D = ("b1", "b2"), ("d1", "d2", "d3")
_HANGING = (-math.pi / 2 + 0.5, 0.3)  # 0.5 rad from hanging, link 2 bent by 0.3 rad
_CART_STIFF_Q0 = (0.0, math.pi - 0.5, math.pi + 0.3)
_LONG = _dp_scaled(2000.0)  # a mild double pendulum: the default at l1 = 1 km (period ≈ 1 min)

CATALOGUE: tuple[HardSet | Case, ...] = (
    HardSet("cart/bobs mass 1e-6", MASS, CART, {"m": 1.25e-6}),
    HardSet("cart/bobs mass 1e6", MASS, CART, {"m": 1.25e6}),
    HardSet("cart bob1/bob2 mass 1e-6", MASS, CART, {"m1": 0.75e-6}, expect="any"),
    HardSet("cart bob1/bob2 mass 1e6", MASS, CART, {"m1": 0.75e6}),
    HardSet("link1/link2 mass 1e-6", MASS, DP, {}, _dp_mass_ratio(1e-6)),
    HardSet("link1/link2 mass 1e6", MASS, DP, {}, _dp_mass_ratio(1e6)),
    HardSet("double pendulum lengths ×1e-3 (mm)", LENGTH, DP, {}, _dp_scaled(1e-3)),
    HardSet("double pendulum lengths ×1e3 (km)", LENGTH, DP, {}, _dp_scaled(1e3)),
    HardSet("double pendulum l1 1e-2 m, l2 10 m", LENGTH, DP, {}, _dp_lengths(0.02, 10 / 0.45)),
    HardSet("double pendulum l1 10 m, l2 1e-2 m", LENGTH, DP, {}, _dp_lengths(20.0, 0.01 / 0.45)),
    HardSet("double pendulum l1 1e-3 m, l2 1e3 m", LENGTH, DP, {}, _dp_lengths(2e-3, 1e3 / 0.45), "checks",
            "all"),
    HardSet("double pendulum l1 1e3 m, l2 1e-3 m", LENGTH, DP, {}, _dp_lengths(2e3, 1e-3 / 0.45), "checks",
            "all"),
    HardSet("cart rods 1e-3 m", LENGTH, CART, {"l1": 1e-3, "l2": 1e-3}, expect="any"),
    HardSet("cart rods 1e3 m", LENGTH, CART, {"l1": 1e3, "l2": 1e3}),
    HardSet("cart rods 1e-2 m / 10 m", LENGTH, CART, {"l1": 1e-2, "l2": 10.0}),
    HardSet("cart rods 10 m / 1e-2 m", LENGTH, CART, {"l1": 10.0, "l2": 1e-2}),
    HardSet("cart rods 1e-3 m / 1e3 m", LENGTH, CART, {"l1": 1e-3, "l2": 1e3}, expect="all"),
    HardSet("cart rods 1e3 m / 1e-3 m", LENGTH, CART, {"l1": 1e3, "l2": 1e-3}, expect="all"),
    Case("cart m1 → 0: trust study", SINGULAR, trust_case(lambda: default(CART))),
    Case("cart det M: closed form vs LU", SINGULAR, det_case(lambda: default(CART))),
    # point masses: det → m1 r1² m2 r2² at θ2 = 0
    Case("double pendulum det M: closed form vs LU", SINGULAR,
         dp_det_case(lambda: default(DP).replace(I1=0.0, I2=0.0))),
    HardSet("cart m1 = 1e-6 kg (warn)", SINGULAR, CART, {"m1": 1e-6}, expect="any", states="aligned"),
    HardSet("cart m1 = 1e-12 kg (refuse aligned)", SINGULAR, CART, {"m1": 1e-12}, expect="some",
            states="aligned"),
    HardSet("point masses (I1 = I2 = 0)", POINT, DP, {"I1": 0.0, "I2": 0.0}),
    HardSet("centres of mass at the joints (r = 0)", POINT, DP, {"r1": 0.0, "r2": 0.0}),
    HardSet("point mass link 1, r2 = 0", POINT, DP, {"I1": 0.0, "r2": 0.0}),
    HardSet("double pendulum |θ| ≈ 1e6 rad", ANGLE, DP, kind=ANGLE),
    HardSet("cart |θ| ≈ 1e6 rad", ANGLE, CART, kind=ANGLE),
    HardSet("double pendulum |q̇| ≤ 1e3", SPEED, DP, kind=SPEED),
    HardSet("cart |q̇| ≤ 1e3", SPEED, CART, kind=SPEED),
    HardSet("double pendulum b = 1e4", STIFF, DP, dict.fromkeys(_B, 1e4)),
    HardSet("cart d = 1e4", STIFF, CART, dict.fromkeys(_D, 1e4)),
    HardSet("double pendulum b = 1e4: simulate", STIFF, DP, dict.fromkeys(_B, STIFF_DAMPING), kind="stiff",
            start=(_HANGING,)),
    HardSet("cart d = 1e4: simulate", STIFF, CART, dict.fromkeys(_D, STIFF_DAMPING), kind="stiff",
            start=(_CART_STIFF_Q0,)),
    HardSet("double pendulum 1e4 s, conservative", "long horizon", DP, dict.fromkeys(_B, 0.0), _LONG,
            "long horizon", start=(_HANGING,)),
    HardSet("double pendulum g = 0", ZERO_G, DP, {"g": 0.0}),
    HardSet("cart g = 0", ZERO_G, CART, {"g": 0.0}),
    HardSet("double pendulum g = 0: simulate", ZERO_G, DP, {"g": 0.0, **dict.fromkeys(_B, 0.0)}, kind=ZERO_G,
            start=((0.3, 0.5), (1.0, -2.0)), momentum=(0, "p_θ1")),
    HardSet("cart g = 0: simulate", ZERO_G, CART, {"g": 0.0, **dict.fromkeys(_D, 0.0)}, kind=ZERO_G,
            start=((0.0, 0.3, -0.4), (0.5, 1.0, -2.0)), momentum=(0, "p_q")),
    Case("NaN, inf, negative, zero", "invalid input",
         invalid_input_case(lambda: (default(DP), default(CART)))),
)  # fmt: skip

#: what each kind of hard set runs: (the entry, the set, the model class) → Case
KINDS = {
    "checks": lambda e, params_fn, cls: checks_case(
        e.name, e.group, params_fn, e.expect, HARD_STATES[e.states] if e.states else None, cls
    ),
    ANGLE: lambda e, params_fn, cls: large_angle_case(e.name, params_fn, cls),
    SPEED: lambda e, params_fn, cls: high_speed_case(e.name, params_fn, cls),
    "stiff": lambda e, params_fn, cls: stiff_sim_case(
        e.name, params_fn, *e.start, lambda: default(e.model), cls
    ),
    "long horizon": lambda e, params_fn, cls: long_horizon_case(e.name, params_fn, *e.start, cls),
    ZERO_G: lambda e, params_fn, cls: zero_gravity_sim_case(e.name, params_fn, *e.start, *e.momentum, cls),
}


def hard_set_case(entry: HardSet, model_cls=None) -> Case:
    """The case of a hard set, run as any model's: ``model_cls`` (default: the reference system's
    class; another plants an error) on the set's description and the set."""
    cls = model_cls or MODELS[entry.model]

    def run(ctx: Context, name: str) -> StressResult:
        params = entry.params()
        case = KINDS[entry.kind](entry, lambda: params, cls)
        return on_description(case, urdf_for(params), cls).run(ctx, name)

    return Case(entry.name, entry.group, run)


def catalogue() -> list[Case]:
    return [hard_set_case(e) if isinstance(e, HardSet) else e for e in CATALOGUE]


CASE_NAMES = tuple(c.name for c in catalogue())


@dataclass
class StressReport:
    settings: Settings
    seed: int
    results: list[StressResult] = field(default_factory=list)
    study: StudyResult | None = None
    elapsed_s: float = 0.0
    #: what the cases did not vary, and why (generic cases on a model file)
    notes: list[str] = field(default_factory=list)
    #: which closed forms are hand-written and checked, which derived and so not evidence (model files)
    evidence: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return all(r.passed for r in self.results)

    def __repr__(self) -> str:
        failed = [r.case for r in self.results if not r.passed]
        head = (
            f"<StressReport {'pass' if self.passed else 'FAIL'}: {len(self.results)} cases, seed {self.seed}"
        )
        return f"{head}{f'; failing: {listed(failed, 150)}' if failed else ''}>"

    def _repr_html_(self) -> str:
        """One row per case: its quantity, error, tolerance and verdict."""
        rows = [
            (r.case, r.quantity, _figure(r.error), _figure(r.tolerance), "pass" if r.passed else "FAIL")
            for r in self.results
        ]
        caption = f"stress: {'pass' if self.passed else 'FAIL'}, seed {self.seed}"
        header = ("case", "quantity", "error", "tolerance", "result")
        return html_table(header, rows, caption, [not r.passed for r in self.results])


def _figure(value: float | None) -> str:
    return "—" if value is None else f"{value:.2e}"


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
