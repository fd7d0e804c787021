"""The one evidence type: what a check, an invariant, a stress case or a battery item found.

Every comparison the package makes ends in an ``Evidence``: "this error against this
tolerance, here, with this verdict".  One verdict field, ``status``, holds one of the
``pendverify.checks.verdict`` values (``pass``, ``warn``, ``fail``, ``refused``, ``not run``);
``passed`` is derived from it (pass or warn), so the two cannot disagree.

Two figures, never one for the other:

``error``, ``tolerance``, ``at``
    the error and the tolerance where the ratio error/tolerance is largest, and that
    place: the ratio decides the verdict.
``largest_error``, ``largest_tolerance``, ``largest_at``
    the largest error and the tolerance at its place, and that place.

Errors and tolerances are relative (to the quantity's scale; the invariants' to the energy
scale).  ``error`` is None where nothing was compared (a stress case whose states were all
refused); ``largest_error`` is NaN (a check) or None (a battery item) where nothing was judged.
A place, ``at`` or ``largest_at``, is a dict with a ``label``: a state's (``State.as_dict``:
``label``, ``q``, ``v``, …) or a time's (``label`` "t = … s" and ``t`` in s).

``kind`` is what made it: ``check``, ``invariant`` or ``stress`` (a battery item keeps the
kind of what it reports).  ``detail`` is one line on what was measured (a check's description,
a stress case's quantity, an invariant's steps, a battery item's label); ``notes`` are the
sentences the user must read.  ``model``, ``samples`` and ``seed`` say what it ran on.
``extras`` holds what one kind has and the others do not:

* check: ``max_abs_error``, the absolute error at the worst ratio;
* invariant: ``scale``, the energy scale in J (NaN: each state's error is relative to its own);
  on a battery item, ``engine``, what ran the simulation (``pendverify.certify.simulations``);
* stress: ``kappa_raw``, ``kappa_scaled`` (κ(M) and κ̃(M), worst over the states, or None),
  ``invariant`` (a sentence, or None), ``refused`` (states refused), ``seconds``.

The reports and certificates users read keep their own key names; ``check_record``,
``invariant_record``, ``stress_record`` and ``item_record`` write them (``stress_verdict`` and
``item_verdict`` the result columns of the stress and battery tables).  There the key
``max_error`` of a check's JSON entry is the error at the worst ratio, while in an
invariant's entry and a certificate item it is the largest error (``largest_error`` here).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from pendverify.checks.verdict import FAIL, NOT_RUN, PASS, REFUSED, VERDICTS, WARN


@dataclass
class Evidence:
    """One comparison's evidence: its verdict, its worst error/tolerance ratio and, apart, its largest
    error (module docstring)."""

    kind: str
    name: str
    status: str
    error: float | None = math.nan
    tolerance: float | None = math.nan
    at: dict = field(default_factory=dict)
    largest_error: float | None = math.nan
    largest_tolerance: float = math.nan
    largest_at: dict = field(default_factory=dict)
    detail: str = ""
    notes: list[str] = field(default_factory=list)
    model: str = ""
    samples: int = 0
    seed: int = 0
    extras: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.status not in VERDICTS:
            raise ValueError(f"evidence {self.name!r}: status {self.status!r} is not one of {VERDICTS}")

    @property
    def passed(self) -> bool:
        """pass or warn: the comparison holds."""
        return self.status in (PASS, WARN)

    @property
    def failed(self) -> bool:
        """fail: the comparison does not hold (refused and not run are neither passed nor failed)."""
        return self.status == FAIL

    @property
    def ratio(self) -> float:
        """error / tolerance at the worst place (inf for no positive tolerance, NaN for no error)."""
        if self.error is None or self.tolerance is None:
            return math.nan
        return self.error / self.tolerance if self.tolerance > 0 else math.inf

    @property
    def label(self) -> str:
        """Where the worst ratio is, in words ("" when nowhere)."""
        return str(self.at.get("label", ""))

    def __repr__(self) -> str:
        model = f"{self.model[:80]} " if self.model else ""
        figures = f"error {_figure(self.error)} vs tolerance {_figure(self.tolerance)}"
        at = f" at {self.label[:60]}" if self.label else ""
        return f"<Evidence {self.kind} {model}{self.name[:60]}: {self.status}, {figures}{at}>"

    def _repr_html_(self) -> str:
        """The evidence as a table of its figures, where they are and its notes (a notebook's view)."""
        from pendverify.display import html_fields

        fields = [
            ("status", self.status),
            ("error", _figure(self.error)),
            ("tolerance", _figure(self.tolerance)),
            ("at", self.label),
            ("largest error", _figure(self.largest_error)),
            ("largest at", str(self.largest_at.get("label", ""))),
            ("states", f"{self.samples} (seed {self.seed})"),
            *(("note", note) for note in self.notes),
        ]
        model = f"{self.model} " if self.model else ""
        return html_fields(f"{model}{self.name}: {self.detail}", fields)


def _figure(x) -> str:
    return "-" if x is None else f"{x:.2e}"


def check_record(e: Evidence) -> dict:
    """A check's entry in the JSON report (``max_error``: the error at the worst ratio)."""
    return {
        "model": e.model,
        "check": e.name,
        "description": e.detail,
        "max_error": e.error,
        "tolerance": e.tolerance,
        "max_abs_error": e.extras.get("max_abs_error", math.nan),
        "samples": e.samples,
        "seed": e.seed,
        "worst_state": e.at,
        "passed": e.passed,
        "largest_error": e.largest_error,
        "largest_tolerance": e.largest_tolerance,
        "largest_state": e.largest_at,
        "notes": e.notes,
        "status": e.status,
    }


def invariant_record(e: Evidence) -> dict:
    """An invariant's entry in ``simulate --json`` (``max_error``: the largest error)."""
    return {
        "name": e.name,
        "error": e.error,
        "tolerance": e.tolerance,
        "passed": e.passed,
        "detail": e.detail,
        "max_error": e.largest_error,
        "max_error_t": e.largest_at.get("t", 0.0),
        "worst_t": e.at.get("t", 0.0),
        "scale": e.extras.get("scale", 1.0),
        "max_error_abs": largest_abs(e),
    }


def largest_abs(e: Evidence) -> float:
    """An invariant's largest error in J (NaN when each state's error is relative to its own scale)."""
    return e.largest_error * e.extras.get("scale", 1.0)


def stress_verdict(e: Evidence) -> str:
    """A stress case's result column: FAIL; refused (as the case expects: no state could be
    verified); not run; or pass, with qualifiers (warn: fewer digits; states refused)."""
    if e.status in (FAIL, REFUSED, NOT_RUN):
        return "FAIL" if e.status == FAIL else e.status
    refused = e.extras.get("refused", 0)
    extra = (["warn"] if e.status == WARN else []) + ([f"{refused} refused"] if refused else [])
    return f"pass ({', '.join(extra)})" if extra else "pass"


def stress_record(e: Evidence) -> dict:
    """A stress case's entry in ``stress --json`` (``passed``: the case did not fail)."""
    x = e.extras
    return {
        "case": e.name,
        "quantity": e.detail,
        "error": e.error,
        "tolerance": e.tolerance,
        "kappa_raw": x.get("kappa_raw"),
        "kappa_scaled": x.get("kappa_scaled"),
        "invariant": x.get("invariant"),
        "passed": not e.failed,
        "note": "; ".join(e.notes),
        "status": e.status,
        "refused": x.get("refused", 0),
        "seed": e.seed,
        "seconds": x.get("seconds", 0.0),
        "verdict": stress_verdict(e),
    }


def item_verdict(e: Evidence) -> str:
    """A battery item's result in a table: pass (a warning included), refused or FAIL."""
    return "pass" if e.passed else ("refused" if e.status == REFUSED else "FAIL")


def item_record(e: Evidence) -> dict:
    """A battery item as a certificate records it (``max_error``: the largest error, or None)."""
    record = {
        "name": e.name,
        "kind": e.kind,
        "error": e.error,
        "tolerance": e.tolerance,
        "samples": e.samples,
        "seed": e.seed,
        "passed": e.passed,
        "detail": e.detail,
        "at": e.label,
        "max_error": e.largest_error,
        "max_error_at": str(e.largest_at.get("label", "")),
    }
    if e.extras.get("engine"):  # checks and stress cases run no simulation
        record["engine"] = e.extras["engine"]
    return record
