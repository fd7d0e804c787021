"""Judging a check's states and drawing its verdict: one ``conclude`` for both ways of evaluating.

A check's states are evaluated either one at a time (``collect_per_state``, the reference)
or all at once (``pendverify.checks.batch``); both hand the same ``Evidence`` — which
states were judged, their rounding tolerance, relative error, relative tolerance and
absolute error, which were refused and the notes so far — to ``conclude``, which
re-judges failing states in high precision, picks the worst and the largest state and
writes the ``CheckResult``.  The tolerance argument is in ``pendverify.checks.catalogue``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pendverify.checks.result import Check, CheckResult
from pendverify.checks.sampling import State
from pendverify.checks.scaling import world_lever
from pendverify.checks.trust import EPS, REFUSE_REL
from pendverify.checks.verdict import REFUSED, WARN

#: what evaluating a state raises when its numbers leave double's range (parameters of 1e200)
OUT_OF_RANGE = (OverflowError, FloatingPointError, np.linalg.LinAlgError)


@dataclass(frozen=True)
class Judged:
    """One state judged: relative error and tolerance, the absolute error, a note."""

    rel_err: float
    rel_tol: float
    abs_err: float
    note: str = ""

    @property
    def ratio(self) -> float:
        return self.rel_err / self.rel_tol if np.isfinite(self.rel_err) else np.inf


@dataclass
class Evidence:
    """What a check found, state by state, before its verdict.

    ``judged`` holds the indices (into the states) of the judged states in order, with
    their rounding tolerance, relative error, relative tolerance and absolute error in
    the parallel arrays; ``refused`` the (index, rounding) of the states not judged, in
    order; ``notes`` the notes so far, in order.
    """

    judged: np.ndarray
    rounding: np.ndarray
    rel_err: np.ndarray
    rel_tol: np.ndarray
    abs_err: np.ndarray
    refused: list[tuple[int, float]]
    notes: list[str]


def rounding_tolerance(check: Check, angle: float, c_T: float, lever: float) -> float:
    """K·ε·((1 + |θ|max)·c_T + (A − 1)): the state's own rounding (on arrays too, elementwise)."""
    return check.K * EPS * ((1.0 + angle) * c_T + (lever - 1.0))


def judge_state(check: Check, model, system, state: State, rounding: float) -> Judged:
    """One state: the check's error and scale (``quantities``) as relative error and tolerance."""
    sample = check.evaluate(model, system, state)
    if sample.scale > 0:
        rel_tol = rounding + sample.allowance / sample.scale
        rel_err = sample.error / sample.scale
    else:  # nothing acts (at rest with g = 0): any error at all is a failure
        rel_tol = rounding
        rel_err = 0.0 if sample.error == 0 else np.inf
    note = sample.note or ("NaN" if np.isnan(rel_err) else "")
    return Judged(np.inf if np.isnan(rel_err) else float(rel_err), float(rel_tol), float(sample.error), note)


def collect_per_state(check: Check, model, system, states) -> Evidence:
    """Evaluate the check at each state in turn: the reference way (``catalogue.run_check_per_state``)."""
    c_T = system.cmap.amplification
    notes: list[str] = []
    refused: list[tuple[int, float]] = []
    judged: list[tuple[int, float, Judged]] = []
    for i, state in enumerate(states):
        angle = float(np.max(np.abs(state.q[np.array(model.angular)]), initial=0.0))
        lever = world_lever(model, system, state.q) if check.world_frame else 1.0
        rounding = rounding_tolerance(check, angle, c_T, lever)
        if not rounding <= REFUSE_REL:
            refused.append((i, rounding))
            continue
        try:
            j = judge_state(check, model, system, state, rounding)
        except OUT_OF_RANGE as exc:  # terms beyond double's range: nothing can be verified there
            refused.append((i, np.inf))
            notes.append(f"{state.label}: refused: its terms overflow double ({type(exc).__name__}: {exc})")
            continue
        if j.note and len(notes) < 3:
            notes.append(f"{state.label}: {j.note}")
        judged.append((i, rounding, j))
    return Evidence(
        np.array([i for i, _, _ in judged], dtype=int),
        np.array([r for _, r, _ in judged], dtype=float),
        np.array([j.rel_err for *_, j in judged], dtype=float),
        np.array([j.rel_tol for *_, j in judged], dtype=float),
        np.array([j.abs_err for *_, j in judged], dtype=float),
        refused,
        notes,
    )


def rejudge_precisely(check: Check, model, system, failing) -> tuple[dict[int, Judged], str]:
    """Failing states judged again with the closed forms in high precision (``checks.precision``).

    ``failing``: (index, state, rounding, judged) in the order of the states.  Worst
    first; stops at the first state that still fails.  Returns {index: judged} for the
    states that pass so (all of them, or the check still fails) and why not.
    """
    from pendverify.checks import precision  # mpmath, loaded only when a state fails

    try:
        precise = precision.precise_model(model)
    except precision.PrecisionUnavailable as exc:
        return {}, str(exc)
    passed = {}
    for i, state, rounding, _ in sorted(failing, key=lambda f: -f[3].ratio):
        try:
            judged = judge_state(check, precise, system, state, rounding)
        except precision.PrecisionUnavailable as exc:
            return passed, str(exc)
        if not judged.ratio <= 1.0:
            return passed, ""
        passed[i] = judged
    return passed, ""


def _ratios(rel_err: np.ndarray, rel_tol: np.ndarray) -> np.ndarray:
    """``Judged.ratio`` of every judged state (a judged state's tolerance is positive)."""
    with np.errstate(all="ignore"):
        return np.where(np.isfinite(rel_err), rel_err / rel_tol, np.inf)


def _python_max(values: np.ndarray) -> float:
    """``max(values, default=0.0)`` as Python takes it: a NaN first stays, later NaNs are passed over."""
    if values.size == 0:
        return 0.0
    if math.isnan(values[0]):
        return float(values[0])
    return float(np.nanmax(values))


def conclude(check: Check, label: str, model, system, states, seed: int, ev: Evidence) -> CheckResult:
    """The verdict on one check from its evidence (both paths of ``run_check`` end here).

    Failing states are judged again in high precision: if all then pass, the check is a
    warning.  Reported: the state with the worst error/tolerance ratio (the first of
    equals), the one with the largest relative error, the largest absolute error.
    """
    notes = ev.notes
    rel_err, rel_tol = ev.rel_err.copy(), ev.rel_tol.copy()
    ratio = _ratios(rel_err, rel_tol)
    max_abs = _python_max(ev.abs_err)
    status = ""
    failing = [int(k) for k in np.flatnonzero(~(ratio <= 1.0))]
    if failing:
        items = [
            (
                int(ev.judged[k]),
                states[ev.judged[k]],
                float(ev.rounding[k]),
                Judged(float(rel_err[k]), float(rel_tol[k]), float(ev.abs_err[k])),
            )
            for k in failing
        ]
        precise, why = rejudge_precisely(check, model, system, items)
        if len(precise) == len(failing):
            i, state, _, double = max(items, key=lambda f: f[3].ratio)
            notes.insert(0, unstable_note(check, state, double, precise[i], len(failing), len(ev.judged)))
            position = {int(i): k for k, i in enumerate(ev.judged)}
            for i, j in precise.items():
                rel_err[position[i]], rel_tol[position[i]] = j.rel_err, j.rel_tol
            ratio = _ratios(rel_err, rel_tol)
            status = WARN
        elif why:
            notes.append(f"not judged in high precision: {why}")
    worst_ratio, worst = -1.0, None
    valid = ratio > -1.0
    if np.any(valid):
        k = int(np.argmax(np.where(valid, ratio, -np.inf)))
        worst_ratio, worst = float(ratio[k]), (states[ev.judged[k]], rel_err[k], rel_tol[k])
    largest = int(np.argmax(rel_err)) if rel_err.size else None
    if ev.refused:
        i, rounding = ev.refused[0]
        state = states[i]
        lever = world_lever(model, system, state.q)
        notes.insert(
            0,
            f"{len(ev.refused)} of {len(states)} states refused: at {state.label} the rounding tolerance "
            f"{rounding:.2g} exceeds the trust limit {REFUSE_REL:g} (Pinocchio's terms {lever:.2g}× the "
            "result)",
        )
        if worst is None:
            worst = (state, float("nan"), rounding)
        if worst_ratio <= 1.0:
            status = REFUSED
    state, worst_err, worst_tol = worst
    return CheckResult(
        model=label,
        check=check.name,
        description=f"{check.pinocchio} vs {check.closed_form}",
        max_error=float(worst_err),
        tolerance=float(worst_tol),
        max_abs_error=max_abs,
        samples=len(states),
        seed=seed,
        worst_state=state.as_dict(),
        largest_error=float(rel_err[largest]) if largest is not None else float("nan"),
        largest_tolerance=float(rel_tol[largest]) if largest is not None else float("nan"),
        largest_state=states[ev.judged[largest]].as_dict() if largest is not None else {},
        passed=bool(worst_ratio <= 1.0) and not ev.refused,
        notes=notes,
        status=status,
    )


def unstable_note(check: Check, state: State, double: Judged, precise: Judged, n: int, of: int) -> str:
    from pendverify.checks import precision

    return (
        f"{precision.UNSTABLE} at {n} of {of} states: at {state.label} {check.name} is off by "
        f"{double.rel_err:.2g} in double ({double.ratio:.3g}× its tolerance {double.rel_tol:.2g}) and by "
        f"{precise.rel_err:.2g} with the hand-written closed forms evaluated to {precision.DIGITS} digits"
    )
