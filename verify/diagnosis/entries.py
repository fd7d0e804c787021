"""The entries that differ: for each failing check, which entries of its quantity, where and how much.

Each check compares one quantity (``COMPARED``): ``crba`` M, ``gravity`` H, ``coriolis`` C,
``rnea`` C·q̇ (the bias minus H, so that an error in H alone is not blamed on C·q̇),
``minverse`` M⁻¹, ``aba`` q̈, ``damping`` D, ``det`` det M and ``energy`` V (as V(q) − V(0)).
An entry differs at a state when its own error, scaled as the check's measure scales it
(``Measure.entries``, ``pendverify.checks.quantities``), exceeds the check's tolerance there
(relative tolerance × the measure's scale, ``pendverify.checks.judge.collect``): the entry
alone would fail the check at that state.  Entries are named 1-based as a derivation writes
them, by the model's own name of the quantity (``ClosedFormModel.written_names``: G where a
model file writes the gravity vector G), with the coordinates they pair (``M[2,2] (theta2,
theta2)``), the hand value and Pinocchio's at the state where the entry is worst, and on how many
states it differs.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from pendverify.checks.catalogue import CHECKS
from pendverify.checks.judge import collect
from pendverify.diagnosis.finding import Finding

_BY_NAME = {c.name: c for c in CHECKS}


@dataclass(frozen=True)
class Compared:
    """A check's quantity: the hand values, Pinocchio's, and each entry's scaled error."""

    quantity: str
    check: str
    hand: Callable
    pin: Callable
    #: (terms, the check's measure) → each entry's error as the measure scales it
    errors: Callable = lambda t, m: m.entries


def _cqdot_errors(t, m):
    return t.weights * np.abs((t.bias_pin - t.H_pin) - (t.bias_hand - t.H_hand))


def _every_state(t, constant):
    """A constant matrix (D) at every state of the batch."""
    return np.broadcast_to(constant, (len(t.q), *np.shape(constant)))


def _potential(t, which: str):
    return getattr(t, f"V_{which}") - getattr(t, f"V_{which}0")


COMPARED = (
    Compared("M", "crba", lambda t: t.M_hand, lambda t: t.M_pin),
    Compared("H", "gravity", lambda t: t.H_hand, lambda t: t.H_pin),
    Compared("C", "coriolis", lambda t: t.C_hand, lambda t: t.C_pin),
    Compared(
        "Cqdot", "rnea", lambda t: t.bias_hand - t.H_hand, lambda t: t.bias_pin - t.H_pin, _cqdot_errors
    ),
    Compared("Minv", "minverse", lambda t: t.Minv_hand, lambda t: t.Minv_pin),
    Compared("qddot", "aba", lambda t: t.a_hand, lambda t: t.a_pin),
    Compared("D", "damping", lambda t: _every_state(t, t.D), lambda t: _every_state(t, t.D_urdf)),
    Compared("detM", "det", lambda t: t.det_hand, lambda t: t.det_pin, lambda t, m: np.abs(m.error)),
    Compared(
        "V",
        "energy",
        lambda t: _potential(t, "hand"),
        lambda t: _potential(t, "pin"),
        lambda t, m: np.abs(_potential(t, "pin") - _potential(t, "hand")),
    ),
)


@dataclass(frozen=True)
class EntryDifference:
    """One entry that differs: its values at every judged state (``states``: indices into the batch)."""

    quantity: str
    index: tuple[int, ...]  # 0-based
    check: str
    states: np.ndarray
    hand: np.ndarray
    pin: np.ndarray
    differs: np.ndarray  # bool per judged state
    worst: int  # position in ``states`` where the entry is furthest beyond its tolerance
    #: the quantity as the model's source names it (``ClosedFormModel.written_names``: G for H)
    written: str = ""

    def label(self, coordinates) -> str:
        """``M[2,2] (theta2, theta2)``: 1-based, in the model's own name of the quantity, with the
        coordinates the entry pairs."""
        name = self.written or self.quantity
        if not self.index:
            return name
        one_based = ",".join(str(i + 1) for i in self.index)
        names = ", ".join(coordinates[i] for i in self.index)
        return f"{name}[{one_based}] ({names})"


def differing_entries(batch, failing: set[str]) -> list[EntryDifference]:
    """Every entry of every failing check's quantity that alone would fail that check somewhere."""
    terms, n = batch.terms, len(batch)
    out = []
    for compared in COMPARED:
        if compared.check not in failing:
            continue
        check = _BY_NAME[compared.check]
        with np.errstate(all="ignore"):
            measure = check.measure(terms)
            evidence = collect(check, batch)
            errors = np.asarray(compared.errors(terms, measure), dtype=float)
            hand = np.asarray(compared.hand(terms), dtype=float)
            pin = np.asarray(compared.pin(terms), dtype=float)
        judged = evidence.judged
        if judged.size == 0:
            continue
        scale = np.broadcast_to(np.asarray(measure.scale, dtype=float), (n,))[judged]
        limit = evidence.rel_tol * np.where(scale > 0, scale, 1.0)
        errors = errors[judged]
        shape = errors.shape[1:]
        with np.errstate(all="ignore"):
            ratio = errors / limit.reshape((-1,) + (1,) * len(shape))
        ratio = np.where(np.isnan(ratio), np.inf, ratio)
        for index in np.ndindex(*shape):
            column = ratio[(slice(None), *index)]
            differs = column > 1.0
            if not differs.any():
                continue
            out.append(
                EntryDifference(
                    compared.quantity,
                    tuple(int(i) for i in index),
                    compared.check,
                    judged,
                    hand[(judged, *index)],
                    pin[(judged, *index)],
                    differs,
                    int(np.argmax(column)),
                    batch.model.written_name(compared.quantity),
                )
            )
    return out


def entry_finding(entry: EntryDifference, batch) -> Finding:
    """The ``entry`` finding: the entry, its values at its worst state, on how many states it differs."""
    k = entry.worst
    state = batch.states[int(entry.states[k])]
    label = entry.label(batch.model.coordinates)
    message = (
        f"{label}: hand {entry.hand[k]:.6g}, Pinocchio {entry.pin[k]:.6g} at {state.label} "
        f"(fails {entry.check}); differs on {int(entry.differs.sum())} of {len(entry.differs)} states"
    )
    return Finding("entry", message, entry.quantity, tuple(i + 1 for i in entry.index))
