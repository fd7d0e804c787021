"""Judging a check at every state of a batch and drawing its verdict.

``collect`` runs a check's measure (``pendverify.checks.quantities``) on a batch
(``pendverify.checks.batch.CheckBatch``) and forms, per state, the rounding tolerance
K·ε·((1 + |θ|max)·c_T + (A − 1)) (plus the rounding of forms the model derives from its q̈,
``Measure.derived``), the relative error e/s and the relative tolerance
rounding + a/s (the argument for them is in ``pendverify.checks.catalogue``): the
``Measured``.  A state whose rounding tolerance exceeds the trust limit is refused, not
judged.  ``conclude`` re-judges failing states with the closed forms in high precision
(``pendverify.checks.precision``), picks the worst and the largest state and writes the
check's ``Evidence`` (``pendverify.checks.evidence``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from pendverify.checks.batch import CheckBatch
from pendverify.checks.evidence import Evidence
from pendverify.checks.sampling import State
from pendverify.checks.trust import EPS, REFUSE_REL
from pendverify.checks.verdict import FAIL, PASS, REFUSED, WARN

if TYPE_CHECKING:
    from pendverify.checks.catalogue import Check


@dataclass(frozen=True)
class Judged:
    """One state judged: relative error and tolerance, the absolute error."""

    rel_err: float
    rel_tol: float
    abs_err: float

    @property
    def ratio(self) -> float:
        return self.rel_err / self.rel_tol if np.isfinite(self.rel_err) else np.inf


@dataclass
class Measured:
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


def rounding_tolerance(check: Check, angle, c_T: float, lever):
    """K·ε·((1 + |θ|max)·c_T + (A − 1)): each state's own rounding (elementwise on arrays)."""
    return check.K * EPS * ((1.0 + angle) * c_T + (lever - 1.0))


def collect(check: Check, batch) -> Measured:
    """The check at every state of ``batch`` (``pendverify.checks.batch.CheckBatch``): its evidence."""
    n = len(batch)
    with np.errstate(all="ignore"):
        lever = batch.lever if check.world_frame else 1.0
        m = check.measure(batch.terms)
        own = rounding_tolerance(check, batch.angle, batch.c_T, lever) + np.asarray(m.derived, dtype=float)
        rounding = np.broadcast_to(own, (n,))
        error, scale, allowance = (
            np.broadcast_to(np.asarray(x, dtype=float), (n,)) for x in (m.error, m.scale, m.allowance)
        )
    # the size of the terms left double's range (parameters of 1e200): nothing can be verified there
    overflow = ~np.isfinite(scale)
    trusted = (rounding <= REFUSE_REL) & ~overflow
    judged = np.flatnonzero(trusted)
    refused = [(int(i), np.inf if overflow[i] else float(rounding[i])) for i in np.flatnonzero(~trusted)]
    notes = [
        f"{batch.states[i].label}: refused: its terms overflow double (their size is {scale[i]:g})"
        for i in np.flatnonzero(overflow)[:3]
    ]
    error, scale, allowance, r = error[judged], scale[judged], allowance[judged], rounding[judged]
    with np.errstate(all="ignore"):
        positive = scale > 0
        rel_tol = np.where(positive, r + allowance / scale, r)
        # nothing acts (at rest with g = 0): any error at all is a failure
        rel_err = np.where(positive, error / scale, np.where(error == 0, 0.0, np.inf))
    noted = np.broadcast_to(np.asarray(m.noted, dtype=bool), (n,))[judged]
    nan = np.isnan(rel_err)
    for k in np.flatnonzero(noted | nan)[: max(0, 3 - len(notes))]:
        i = int(judged[k])
        note = m.describe(i) if noted[k] else "NaN"
        notes.append(f"{batch.states[i].label}: {note}")
    derived = np.broadcast_to(np.asarray(m.derived, dtype=float), (n,))
    if np.any(derived > 0):
        notes.append(
            "derived numerically from the model's q̈ (pendverify.analytic.numeric_derivation): the "
            f"tolerance includes the derivation's rounding bound, at most {np.max(derived):.2g}"
        )
    return Measured(judged, r.copy(), np.where(nan, np.inf, rel_err), rel_tol, error.copy(), refused, notes)


def rejudge_precisely(check: Check, batch, failing: list[int], ev: Measured) -> tuple[dict[int, Judged], str]:
    """Failing states judged again with the closed forms in high precision (``checks.precision``).

    ``failing``: positions in ``ev`` of the failing states.  Worst first; stops at the
    first state that still fails.  Returns {state index: judged} for the states that pass
    so (all of them, or the check still fails) and why not.
    """
    from pendverify.checks import precision  # mpmath, loaded only when a state fails

    try:
        precise = precision.precise_model(batch.model)
    except precision.PrecisionUnavailable as exc:
        return {}, str(exc)
    ratios = _ratios(ev.rel_err, ev.rel_tol)
    passed = {}
    for k in sorted(failing, key=lambda k: -ratios[k]):
        i = int(ev.judged[k])
        one = CheckBatch(precise, batch.system, [batch.states[i]], batch.pinocchio_angles, python_only=True)
        try:
            again = collect(check, one)
        except precision.PrecisionUnavailable as exc:
            return passed, str(exc)
        if again.judged.size == 0:  # its terms overflow in high precision too: it still fails
            return passed, ""
        judged = Judged(float(again.rel_err[0]), float(again.rel_tol[0]), float(again.abs_err[0]))
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


def conclude(check: Check, label: str, batch, seed: int, ev: Measured) -> Evidence:
    """The verdict on one check from its evidence at the states of ``batch``.

    Failing states are judged again in high precision: if all then pass, the check is a
    warning.  Reported: the state with the worst error/tolerance ratio (the first of
    equals), the one with the largest relative error, the largest absolute error.
    """
    states = batch.states
    notes = ev.notes
    rel_err, rel_tol = ev.rel_err.copy(), ev.rel_tol.copy()
    ratio = _ratios(rel_err, rel_tol)
    max_abs = _python_max(ev.abs_err)
    status = ""
    failing = [int(k) for k in np.flatnonzero(~(ratio <= 1.0))]
    if failing:
        precise, why = rejudge_precisely(check, batch, failing, ev)
        if len(precise) == len(failing):
            k = max(failing, key=lambda k: ratio[k])  # the first of equals
            i = int(ev.judged[k])
            double = Judged(float(rel_err[k]), float(rel_tol[k]), float(ev.abs_err[k]))
            notes.insert(0, unstable_note(check, states[i], double, precise[i], len(failing), len(ev.judged)))
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
        lever = batch.lever[i]
        notes.insert(
            0,
            f"{len(ev.refused)} of {len(states)} states refused: at {state.label} the rounding tolerance "
            f"{rounding:.2g} exceeds the trust limit {REFUSE_REL:g} (Pinocchio's terms {lever:.2g}× the "
            "result)",
        )
        if worst is None:
            worst = (state, float("nan"), rounding)
    # a failing state fails the check; else a refused state refuses it; else it passes (or warns)
    status = FAIL if not worst_ratio <= 1.0 else (REFUSED if ev.refused else status or PASS)
    state, worst_err, worst_tol = worst
    return Evidence(
        "check",
        check.name,
        status,
        error=float(worst_err),
        tolerance=float(worst_tol),
        at=state.as_dict(),
        largest_error=float(rel_err[largest]) if largest is not None else float("nan"),
        largest_tolerance=float(rel_tol[largest]) if largest is not None else float("nan"),
        largest_at=states[ev.judged[largest]].as_dict() if largest is not None else {},
        detail=f"{check.pinocchio} vs {check.closed_form}",
        notes=notes,
        model=label,
        samples=len(states),
        seed=seed,
        extras={"max_abs_error": max_abs},
    )


def unstable_note(check: Check, state: State, double: Judged, precise: Judged, n: int, of: int) -> str:
    from pendverify.checks import precision

    return (
        f"{precision.UNSTABLE} at {n} of {of} states: at {state.label} {check.name} is off by "
        f"{double.rel_err:.2g} in double ({double.ratio:.3g}× its tolerance {double.rel_tol:.2g}) and by "
        f"{precise.rel_err:.2g} with the hand-written closed forms evaluated to {precision.DIGITS} digits"
    )
