"""The reference systems' own studies: the cart's m1 → 0 trust study, the det M accuracy of both
closed forms, and bad input.

They are cases of the catalogue (``pendverify.stress.catalogue``) that are not a parameter set
on a description: each measures one property of one reference system's closed form (the
study's 50-digit reference is the model's generated code, ``pendverify.stress.trust_study``).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from pendverify.analytic import MODELS
from pendverify.checks.trust import EPS, KAPPA_K, REFUSE_REL, assess
from pendverify.errors import PendverifyError
from pendverify.stress.framework import DP_DET_MASSES, Context, StressResult
from pendverify.stress.trust_study import det_accuracy
from pendverify.validate import finite_state, model_state


def trust_case(base_fn) -> Callable[[Context, str], StressResult]:
    """The trust study of the set ``base_fn()`` (m1 → 0) judged: the guard is conservative."""
    return lambda ctx, name: _trust_result(ctx.trust_study(base_fn()), name)


def _trust_result(study, name: str) -> StressResult:
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


def det_case(base_fn) -> Callable[[Context, str], StressResult]:
    """The cart's closed-form det (non-negative terms) stays at ε level even where LU fails (the trust
    study of ``base_fn()``)."""
    return lambda ctx, name: _det_result(ctx.trust_study(base_fn()), name)


def _det_result(study, name: str) -> StressResult:
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


def dp_det_case(base_fn) -> Callable[[Context, str], StressResult]:
    """The double pendulum's closed-form det, αδ − δ² − β²cos²θ2, is a difference: no better than LU
    (on ``base_fn()`` with m1 of ``DP_DET_MASSES``)."""
    return lambda ctx, name: _dp_det_result(base_fn(), name)


def _dp_det_result(base, name: str) -> StressResult:
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


# --- invalid input ----------------------------------------------------------------------------
def invalid_input_case(sets_fn) -> Callable[[Context, str], StressResult]:
    """Bad states, inputs and parameters of the two sets ``sets_fn()`` (the double pendulum's, the
    cart's) each raise a PendverifyError."""
    return lambda ctx, name: _invalid_input_result(*sets_fn(), name)


def _invalid_input_result(dp, cp, name: str) -> StressResult:
    model = MODELS[dp.model](dp)
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
