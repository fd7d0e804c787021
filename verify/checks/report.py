"""The verification report: one table for people, one JSON document for machines.

``Report`` is what ``build_report`` returns; ``CheckReport``, what ``pendverify.check``
returns, is the same report printing as the CLI's table (``format_table``).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from pendverify.checks.catalogue import CheckResult
from pendverify.checks.verdict import FAIL, LABELS, PASS, REFUSED, WARN, worst
from pendverify.jsonio import to_json, versions


@dataclass
class Report:
    seed: int
    states: dict[str, int]
    results: list[CheckResult]
    notes: dict[str, list[str]] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)
    elapsed_s: float = 0.0
    #: Known traps that explain a target's failures (``pendverify.checks.diagnose``), in words.
    diagnoses: dict[str, list[str]] = field(default_factory=dict)
    #: What a user must know although the checks pass (``pendverify.checks.verdict``), per target.
    warnings: dict[str, list[str]] = field(default_factory=dict)
    #: --strict: warnings count as failures.
    strict: bool = False

    @property
    def status(self) -> str:
        """pass, warn, fail or refused: the worst of the results and the warnings."""
        level = worst([r.status for r in self.results] + ([WARN] if self.warnings else []))
        return FAIL if self.strict and level == WARN else level

    @property
    def passed(self) -> bool:
        """True for pass and pass with warnings (without ``strict``)."""
        return self.status in (PASS, WARN)

    def failures(self) -> list[CheckResult]:
        return [r for r in self.results if r.status == FAIL]

    def refusals(self) -> list[CheckResult]:
        return [r for r in self.results if r.status == REFUSED]

    def as_dict(self) -> dict:
        return {
            **versions(),
            "seed": self.seed,
            "states": self.states,
            "elapsed_s": round(self.elapsed_s, 3),
            "passed": self.passed,
            "status": self.status,
            "strict": self.strict,
            "sources": self.sources,
            "notes": self.notes,
            "diagnoses": self.diagnoses,
            "warnings": self.warnings,
            "results": [r.as_dict() for r in self.results],
        }

    def to_json(self) -> str:
        return to_json(self.as_dict())


def text_table(header: tuple[str, ...], rows: list[tuple[str, ...]]) -> list[str]:
    """Left-aligned columns under a ruled header, as lines."""
    widths = [max(len(h), *(len(row[i]) for row in rows)) for i, h in enumerate(header)]
    line = "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))
    body = ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in rows]
    return [line, "-" * len(line), *body]


def _state_text(state: dict) -> str:
    if not state.get("q"):
        return state["label"]
    q = ", ".join(f"{x:.3g}" for x in state["q"])
    return f"{state['label']} q=({q})"


def format_table(report: Report) -> str:
    header = ("model", "check", "error", "tolerance", "worst state", "result")
    rows = [
        (
            r.model,
            r.check,
            f"{r.max_error:.2e}",
            f"{r.tolerance:.2e}",
            _state_text(r.worst_state),
            LABELS[r.status],
        )
        for r in report.results
    ]
    out = text_table(header, rows)
    out.append("")
    out.append(
        "error and tolerance are relative, in diagonally scaled coordinates: "
        "tolerance = K·ε·((1 + |θ|max)·cond(T)² + (A − 1)) (+ model-form allowance)."
    )
    for model, notes in report.notes.items():
        for note in notes:
            out.append(f"note [{model}]: {note}")
    for model, sentences in report.warnings.items():
        for sentence in sentences:
            out.append(f"warning [{model}]: {sentence}")
    for r in report.failures():
        for note in r.notes:
            out.append(f"fail [{r.model} {r.check}]: {note}")
    for model, sentences in report.diagnoses.items():
        for sentence in sentences:
            out.append(f"diagnosis [{model}]: {sentence}")
    judged = [r for r in report.results if r.largest_error == r.largest_error]  # not NaN
    if judged:
        top = max(judged, key=lambda r: r.largest_error)
        out.append(
            f"largest relative error: {top.largest_error:.2e} ({top.model} {top.check} at "
            f"{_state_text(top.largest_state)}, where its tolerance is {top.largest_tolerance:.2e}); "
            "the table's error is at each check's worst error/tolerance"
        )
    total = sum(report.states.values())
    out.append(
        f"{len(report.results)} checks on {len(report.states)} model(s), {total} states "
        f"(seed {report.seed}), {report.elapsed_s:.2f} s: {verdict_sentence(report)}"
    )
    return "\n".join(out)


def verdict_sentence(report: Report) -> str:
    """The report's verdict in words: pass, pass with warnings, FAIL or refused."""
    warned = sum(len(w) for w in report.warnings.values())
    parts = []
    if report.failures():
        parts.append(f"{len(report.failures())} check(s) FAIL")
    if report.refusals():
        parts.append(f"{len(report.refusals())} check(s) refused (beyond the trust limit: not verified)")
    if parts:
        if warned:
            parts.append(f"{warned} warning(s)")
        return ", ".join(parts)
    if warned:
        if report.strict:
            return f"FAIL: {warned} warning(s), which --strict counts as failures"
        return f"pass with {warned} warning(s)"
    return "all checks pass"


class CheckReport(Report):
    """The report of ``check``: a ``pendverify.checks.report.Report`` that prints as the CLI's table.

    The evidence is in the fields of ``Report``: ``results`` (one ``CheckResult`` per model and
    check: ``max_error``, ``tolerance``, ``max_abs_error``, ``worst_state``, ``status``, ``notes``),
    ``notes``, ``warnings`` and ``diagnoses`` (per model label), ``states``, ``sources``, ``seed``,
    ``strict``, ``elapsed_s``; ``passed``, ``status``, ``failures()``, ``refusals()``, ``as_dict()``
    and ``to_json()`` (the document ``check --json`` writes).
    """

    def table(self) -> str:
        """The text ``pendverify check`` prints: the table, notes, warnings, diagnoses, the verdict."""
        return format_table(self)

    def __str__(self) -> str:
        return self.table()

    def __repr__(self) -> str:
        models = ", ".join(self.states)
        return f"<CheckReport {self.status}: {len(self.results)} checks on {models}, seed {self.seed}>"

    def _repr_pretty_(self, printer, cycle: bool) -> None:  # IPython / Jupyter: show the table
        printer.text(repr(self) if cycle else self.table())

    @classmethod
    def from_report(cls, report: Report) -> CheckReport:
        return cls(**{f.name: getattr(report, f.name) for f in dataclasses.fields(Report)})
