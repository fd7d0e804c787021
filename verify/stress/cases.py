"""The reference systems' stress cases on states and parameters.

Large angles, high speeds, the near-singular cart and the trust study, bad input.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable

import numpy as np

from pendverify.analytic import MODELS
from pendverify.checks.evidence import Evidence
from pendverify.checks.sampling import RATE_RANGE, State
from pendverify.checks.trust import EPS, KAPPA_K, REFUSE_REL, assess
from pendverify.checks.verdict import NOT_RUN
from pendverify.errors import PendverifyError
from pendverify.stress.framework import (
    ANGLE_SHIFT,
    DP_DET_MASSES,
    HIGH_RATE,
    Case,
    Context,
    compare,
    judged_ratio,
    model_of,
    refusals_as_expected,
    sampled_states,
    stress_evidence,
    stress_result,
    verified,
)
from pendverify.stress.seed_params import default
from pendverify.stress.trust_study import det_accuracy, study_states
from pendverify.validate import finite_state, model_state


# --- large angles and high speeds -------------------------------------------------------------
def reduced_angles(angular):
    """The map of states' angles θ (N, n) to θ mod 2π in (−π, π] (the coordinates in ``angular`` only).

    Checking a closed form at θ against Pinocchio at θ mod 2π tests that results are
    invariant under θ + 2πk (to the rounding of θ itself, ε·|θ|).
    """
    angular = np.asarray(angular, dtype=bool)

    def reduce(theta: np.ndarray) -> np.ndarray:
        theta = np.asarray(theta, dtype=float)
        turns = np.where(angular, np.round(theta / (2 * math.pi)), 0.0)
        return theta - turns * (2 * math.pi)

    return reduce


def shifted_states(model, states: list[State], shift: float = ANGLE_SHIFT) -> list[State]:
    """Each state with its angles moved by ±2πk, |2πk| ≈ ``shift``, alternating sign."""
    k = round(shift / (2 * math.pi))
    angular = np.array(model.angular)
    out = []
    for i, s in enumerate(states):
        shift = np.where(angular, (1 if i % 2 == 0 else -1) * k * 2 * math.pi, 0.0)
        out.append(dataclasses.replace(s, label=f"{s.label} +2πk", q=s.q + shift))
    return out


def large_angle_case(
    name: str, params_fn, model_cls=None, expect: str = "none", shift: float = ANGLE_SHIFT
) -> Case:
    """|θ| ≈ ``shift`` (1e6 rad); ``expect`` says which refusals by the trust rule are acceptable (EXPECT).

    A model without an angular coordinate has no angle to shift: the case is not run (its
    result says so) rather than compare unshifted states and call that an invariance.
    """

    def run(ctx: Context, name: str) -> Evidence:
        params = params_fn()
        model = model_of(params, model_cls)
        if not any(model.angular):
            return stress_evidence(
                name,
                "no angular coordinate",
                None,
                None,
                None,
                None,
                None,
                True,
                "not run: no angle to shift",
                level=NOT_RUN,
            )
        system = ctx.system(params)
        states = shifted_states(model, sampled_states(model, ctx), shift)
        direct = compare(name, model, system, states, ctx.seed)
        invariance = compare(name, model, system, states, ctx.seed, reduced_angles(model.angular))
        inv_ok = all(verified(r, expect) for r in invariance.results)
        inv_ok = inv_ok and refusals_as_expected(invariance, expect)
        angle = max(float(np.max(np.abs(s.q[np.array(model.angular)]))) for s in states)
        if not invariance.results:  # every state refused by the trust rule
            invariant = f"2πk invariance: no state could be verified; |θ| up to {angle:.3g} rad"
            note = "" if inv_ok else "FAIL invariance: every state refused"
            return stress_result(name, direct, expect, invariant, inv_ok, note)
        inv_worst = max(invariance.results, key=judged_ratio)
        invariant = (
            f"2πk invariance (closed form at θ vs Pinocchio at θ mod 2π): {inv_worst.error:.2g} "
            f"≤ {inv_worst.tolerance:.2g} ({inv_worst.name}); |θ| up to {angle:.3g} rad"
        )
        note = "" if inv_ok else f"FAIL invariance {inv_worst.name} at {inv_worst.label}"
        return stress_result(name, direct, expect, invariant, inv_ok, note)

    return Case(name, "large angle", run)


def high_speed_case(name: str, params_fn, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> Evidence:

        params = params_fn()
        model = model_of(params, model_cls)
        system = ctx.system(params)
        states = [
            dataclasses.replace(s, v=s.v * (HIGH_RATE / RATE_RANGE)) for s in sampled_states(model, ctx)
        ]
        comp = compare(name, model, system, states, ctx.seed)
        finite = all(np.isfinite(r.extras["max_abs_error"]) for r in comp.results)
        rate = max(float(np.max(np.abs(s.v))) for s in states)
        invariant = f"|q̇| up to {rate:.3g}; all quantities finite: {'yes' if finite else 'NO'}"
        return stress_result(name, comp, "none", invariant, finite)

    return Case(name, "high speed", run)


# --- the near-singular cart ---------------------------------------------------------------------
def _aligned_states(model) -> list[State]:
    zero_u, zero_w = np.zeros(len(model.inputs)), np.zeros(len(model.disturbances))
    return [State(label, y, v, u, w) for label, (y, v, u, w) in study_states().items()] + [
        State("theta1=theta2=0 at rest", np.zeros(3), np.zeros(3), zero_u, zero_w)
    ]


def trust_case(ctx: Context, name: str) -> Evidence:
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
    return stress_evidence(
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


def det_case(ctx: Context, name: str) -> Evidence:
    """The cart's closed-form det (non-negative terms) stays at ε level even where LU fails."""
    study = ctx.trust_study()
    finite_m = [r for r in study.rows if r.kappa_scaled < 1 / EPS]  # M itself representable
    worst_cf = max(r.det_closed_form for r in finite_m)
    worst_lu = max(finite_m, key=lambda r: r.det_lu)
    tol = KAPPA_K * EPS
    return stress_evidence(
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


def dp_det_case(ctx: Context, name: str) -> Evidence:
    """The double pendulum's closed-form det, αδ − δ² − β²cos²θ2, is a difference: no better than LU."""
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
    return stress_evidence(
        case=name,
        quantity="max(closed-form det, LU det) error vs 50 digits, over K·ε·κ̃",
        error=max(worst[2], worst[3]),
        tolerance=KAPPA_K * EPS * worst[4].kappa_scaled,
        kappa_raw=max(r[4].kappa_raw for r in rows),
        kappa_scaled=max(r[4].kappa_scaled for r in rows),
        invariant=f"both within K·ε·κ̃ (worst ratio {ratio:.2g}); more accurate: {better}",
        passed=ratio <= 1.0,
    )


# --- invalid input ----------------------------------------------------------------------------
def invalid_input_case(ctx: Context, name: str) -> Evidence:

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
    return stress_evidence(
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
