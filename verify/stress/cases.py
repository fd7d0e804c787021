"""Stress cases on states, for any model: large angles (with the 2πk invariance) and high speeds."""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from pendverify.checks.sampling import RATE_RANGE, State
from pendverify.stress.framework import (
    ANGLE_SHIFT,
    HIGH_RATE,
    Case,
    Context,
    StressResult,
    compare,
    judged_ratio,
    model_of,
    refusals_as_expected,
    sampled_states,
    stress_result,
    verified,
)


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

    def run(ctx: Context, name: str) -> StressResult:
        params = params_fn()
        model = model_of(params, model_cls, ctx)
        if not any(model.angular):
            return StressResult(
                name,
                "no angular coordinate",
                None,
                None,
                None,
                None,
                None,
                True,
                "not run: no angle to shift",
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
            f"2πk invariance (closed form at θ vs Pinocchio at θ mod 2π): {inv_worst.max_error:.2g} "
            f"≤ {inv_worst.tolerance:.2g} ({inv_worst.check}); |θ| up to {angle:.3g} rad"
        )
        note = "" if inv_ok else f"FAIL invariance {inv_worst.check} at {inv_worst.worst_state['label']}"
        return stress_result(name, direct, expect, invariant, inv_ok, note)

    return Case(name, "large angle", run)


def high_speed_case(name: str, params_fn, model_cls=None) -> Case:
    def run(ctx: Context, name: str) -> StressResult:

        params = params_fn()
        model = model_of(params, model_cls, ctx)
        system = ctx.system(params)
        states = [
            dataclasses.replace(s, v=s.v * (HIGH_RATE / RATE_RANGE)) for s in sampled_states(model, ctx)
        ]
        comp = compare(name, model, system, states, ctx.seed)
        finite = all(np.isfinite(r.max_abs_error) for r in comp.results)
        rate = max(float(np.max(np.abs(s.v))) for s in states)
        invariant = f"|q̇| up to {rate:.3g}; all quantities finite: {'yes' if finite else 'NO'}"
        return stress_result(name, comp, "none", invariant, finite)

    return Case(name, "high speed", run)
