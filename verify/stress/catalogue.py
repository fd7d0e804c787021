"""The reference systems' stress catalogue: hard cases that must stay numerically stable, or be refused.

These cases are about the two seed models (``pendverify stress`` without ``--analytic``);
any model file gets the generic cases of ``pendverify.stress.generic``.

Each case is a named function returning an ``Evidence`` (``pendverify.checks.evidence``): the
achieved relative error next to the tolerance used, κ(M) raw and after diagonal scaling
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
from dataclasses import dataclass, field

from pendverify.checks.evidence import Evidence
from pendverify.display import html_table, listed
from pendverify.stress.cases import (
    _aligned_states,
    det_case,
    dp_det_case,
    high_speed_case,
    invalid_input_case,
    large_angle_case,
    trust_case,
)
from pendverify.stress.framework import (
    FULL,
    SEED,
    STIFF_DAMPING,
    Case,
    Context,
    Settings,
    checks_case,
)
from pendverify.stress.seed_params import cart, default, dp_link_lengths, dp_link_mass_ratio, dp_scaled
from pendverify.stress.sim_cases import long_horizon_case, stiff_sim_case, zero_gravity_sim_case
from pendverify.stress.trust_study import StudyResult


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
    results: list[Evidence] = field(default_factory=list)
    study: StudyResult | None = None
    elapsed_s: float = 0.0
    #: what the cases did not vary, and why (generic cases on a model file)
    notes: list[str] = field(default_factory=list)
    #: which closed forms are hand-written and checked, which derived and so not evidence (model files)
    evidence: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """Whether no case failed (a case refused or not run, as it expects, does not fail)."""
        return not any(r.failed for r in self.results)

    def __repr__(self) -> str:
        failed = [r.name for r in self.results if r.failed]
        head = (
            f"<StressReport {'pass' if self.passed else 'FAIL'}: {len(self.results)} cases, seed {self.seed}"
        )
        return f"{head}{f'; failing: {listed(failed, 150)}' if failed else ''}>"

    def _repr_html_(self) -> str:
        """One row per case: its quantity, error, tolerance and verdict."""
        rows = [
            (r.name, r.detail, _figure(r.error), _figure(r.tolerance), "FAIL" if r.failed else "pass")
            for r in self.results
        ]
        caption = f"stress: {'pass' if self.passed else 'FAIL'}, seed {self.seed}"
        header = ("case", "quantity", "error", "tolerance", "result")
        return html_table(header, rows, caption, [r.failed for r in self.results])


def _figure(value: float | None) -> str:
    return "—" if value is None else f"{value:.2e}"


def run_case(case: Case, ctx: Context) -> Evidence:
    started = time.perf_counter()
    result = case.run(ctx, case.name)
    result.extras["seconds"] = time.perf_counter() - started
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
