"""The verification report: one table for people, one JSON document for machines.

``Report`` is what ``build_report`` returns; ``CheckReport``, what ``pendverify.check``
returns, is the same report printing as the CLI's table (``format_table``).  A report reads
like a mapping from check name to that check's rows: ``report["crba"]`` is a ``CheckRows``
(one ``Evidence`` per model), ``report["crba"]["double_pendulum"]`` or
``report["double_pendulum", "crba"]`` one result; a model is named by its label
(``cart_pole:cart_pole``) or, when that names one, by the model's name or the URDF's alone.
In a notebook a report shows as an HTML table with the CLI table's rows (``_repr_html_``).
"""

from __future__ import annotations

import dataclasses
import html
from collections.abc import Iterator
from dataclasses import dataclass, field

from pendverify.checks.evidence import Evidence, check_record
from pendverify.checks.verdict import FAIL, LABELS, PASS, REFUSED, WARN, worst
from pendverify.diagnosis.finding import text_lines
from pendverify.display import REPR_LIMIT, html_lines, html_table, listed
from pendverify.jsonio import to_json, versions

#: the columns of the check table, in the CLI and in a notebook
HEADER = ("model", "check", "error", "tolerance", "worst state", "result")


def _ratio(result: Evidence) -> float:
    """error/tolerance of a row (NaN, a refused row, sorts below every number)."""
    ratio = result.ratio
    return ratio if ratio == ratio else -1.0


def model_label(labels: tuple[str, ...], key: str, where: str) -> str:
    """The one label of ``labels`` that ``key`` names: the label itself, or either part of a
    ``model:name`` label alone (the model's name, or the URDF's or parameter set's name).  A key that
    names none, or several, is a KeyError that lists the labels (``where``: what holds them)."""
    if key in labels:
        return key
    named = [label for label in labels if key in label.split(":", 1)]
    if len(named) == 1:
        return named[0]
    if named:
        raise KeyError(f"{key!r} names {len(named)} models of {where}: {', '.join(named)}; give one label")
    raise KeyError(f"{where} has no model {key!r}; its models: {', '.join(labels) or 'none'}")


@dataclass(frozen=True)
class CheckRows:
    """The rows of one check in a report: one ``Evidence`` per model, in the table's order.

    ``report["crba"]`` gives it.  ``rows["double_pendulum"]`` (a model's label) or ``rows[0]``
    is one result; ``len``, iteration, ``models``; ``status`` and ``passed`` are the worst
    row's verdict; ``worst`` is the row with the largest error/tolerance (its ``error`` and
    ``tolerance`` are the check's figures).
    """

    check: str
    results: tuple[Evidence, ...]

    @property
    def models(self) -> tuple[str, ...]:
        """The labels of the models that ran this check, in the table's order."""
        return tuple(r.model for r in self.results)

    @property
    def status(self) -> str:
        """pass, warn, fail or refused: the worst of the rows."""
        return worst([r.status for r in self.results])

    @property
    def passed(self) -> bool:
        """Whether every row passes (pass, or pass with warnings)."""
        return all(r.passed for r in self.results)

    @property
    def worst(self) -> Evidence:
        """The row whose error is the largest fraction of its tolerance."""
        return max(self.results, key=_ratio)

    def __len__(self) -> int:
        return len(self.results)

    def __iter__(self) -> Iterator[Evidence]:
        return iter(self.results)

    def __getitem__(self, key: str | int) -> Evidence:
        """``rows[0]``; ``rows["cart_pole:cart_pole"]`` (a label), or the model's name or the URDF's
        (parameter set's) name alone when it names one row: ``rows["cart_pole"]``."""
        if isinstance(key, int):
            return self.results[key]
        label = model_label(self.models, key, f"check {self.check!r}")
        return next(r for r in self.results if r.model == label)

    def __repr__(self) -> str:
        top = self.worst
        return (
            f"<CheckRows {self.check}: {self.status} on {len(self)} model(s) "
            f"({listed(self.models, 120)}); worst {top.error:.2e} vs tolerance {top.tolerance:.2e} "
            f"({top.model})>"
        )

    def _repr_html_(self) -> str:
        rows = [table_row(r) for r in self.results]
        return html_table(
            HEADER, rows, f"check {self.check}: {self.status}", [not r.passed for r in self.results]
        )


@dataclass
class Report:
    seed: int
    states: dict[str, int]
    results: list[Evidence]
    notes: dict[str, list[str]] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)
    elapsed_s: float = 0.0
    #: What is wrong in a failing target and how to fix it (``pendverify.diagnosis.explain``):
    #: ``pendverify.diagnosis.finding.Finding`` objects per model label.
    diagnoses: dict[str, list] = field(default_factory=dict)
    #: What a user must know although the checks pass (``pendverify.checks.verdict``), per target.
    warnings: dict[str, list[str]] = field(default_factory=dict)
    #: --strict: warnings count as failures.
    strict: bool = False
    #: What was left out of the report and why, one sentence each (example-robot-data not installed).
    skipped: list[str] = field(default_factory=list)
    #: diagnose failing models (``--no-explain`` turns it off)
    explain: bool = True

    @property
    def status(self) -> str:
        """pass, warn, fail or refused: the worst of the results and the warnings."""
        level = worst([r.status for r in self.results] + ([WARN] if self.warnings else []))
        return FAIL if self.strict and level == WARN else level

    @property
    def passed(self) -> bool:
        """True for pass and pass with warnings (without ``strict``)."""
        return self.status in (PASS, WARN)

    @property
    def robot_compared(self) -> bool:
        """Whether any check compared the model with a robot (a model alone gets its ``units`` row only)."""
        return any(r.name != "units" for r in self.results)

    def failures(self) -> list[Evidence]:
        """The results that fail."""
        return [r for r in self.results if r.status == FAIL]

    def refusals(self) -> list[Evidence]:
        """The results refused by the trust rule (states beyond double precision's reach: not verified)."""
        return [r for r in self.results if r.status == REFUSED]

    @property
    def checks(self) -> tuple[str, ...]:
        """The names of the checks in the report, in the table's order of first appearance."""
        return tuple(dict.fromkeys(r.name for r in self.results))

    @property
    def models(self) -> tuple[str, ...]:
        """The labels of the models (targets) in the report, in the table's order."""
        return tuple(dict.fromkeys([*self.states, *(r.model for r in self.results)]))

    def __getitem__(self, key: str | tuple[str, str]) -> CheckRows | Evidence:
        """``report["crba"]``: that check's rows (``CheckRows``, one per model);
        ``report["double_pendulum", "crba"]``: one model's result.  An unknown name is a
        ``KeyError`` listing the valid ones."""
        if isinstance(key, tuple):
            if len(key) != 2:
                raise KeyError(f"a report's key is a check name or (model, check); got {key!r}")
            model, check = key
            return self[check][model]
        rows = tuple(r for r in self.results if r.name == key)
        if not rows:
            model = (
                ""
                if not any(key in label.split(":", 1) for label in self.models)
                else (f"; {key!r} is a model: report[CHECK][{key!r}] or report[{key!r}, CHECK] is its result")
            )
            raise KeyError(
                f"no check {key!r} in this report; its checks: {', '.join(self.checks) or 'none'}{model}"
            )
        return CheckRows(key, rows)

    def __contains__(self, key: object) -> bool:
        return key in self.checks

    def __iter__(self) -> Iterator[str]:
        """The check names, as a mapping's keys."""
        return iter(self.checks)

    def keys(self) -> tuple[str, ...]:
        """The check names (``checks``): ``dict(report)`` maps each to its ``CheckRows``."""
        return self.checks

    def __repr__(self) -> str:
        total = sum(self.states.values())
        head = (
            f"<{type(self).__name__} {self.status}: {len(self.results)} checks on "
            f"{len(self.models)} model(s), {total} states, seed {self.seed}"
        )
        if not self.models:
            return f"{head}>"
        return f"{head}: {listed(self.models, REPR_LIMIT - len(head) - 4)}>"

    def _repr_html_(self) -> str:
        """The check table as HTML, then its notes, warnings, diagnoses and verdict (as the CLI's)."""
        lines = trailing_lines(self)
        rows = [table_row(r) for r in self.results]
        failing = [r.status in (FAIL, REFUSED) for r in self.results]
        verdict = f"<p><strong>{html.escape(lines[-1])}</strong></p>"
        return html_table(HEADER, rows, failing=failing) + html_lines(lines[:-1]) + verdict

    def as_dict(self) -> dict:
        """The report as the JSON document's mapping (versions, seed, states, verdict, notes, results)."""
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
            "diagnoses": {label: [f.as_dict() for f in found] for label, found in self.diagnoses.items()},
            "warnings": self.warnings,
            "skipped": self.skipped,
            "results": [check_record(r) for r in self.results],
        }

    def to_json(self) -> str:
        """The JSON document ``pendverify check --json`` writes."""
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


def table_row(r: Evidence) -> tuple[str, ...]:
    """One row of the check table: ``HEADER``'s cells as text."""
    return (
        r.model,
        r.name,
        f"{r.error:.2e}",
        f"{r.tolerance:.2e}",
        _state_text(r.at),
        LABELS[r.status],
    )


def trailing_lines(report: Report) -> list[str]:
    """The lines under the table: the notes, warnings, failures' notes, diagnoses, what was
    skipped, the largest relative error and, last, the verdict line."""
    out = []
    for model, notes in report.notes.items():
        for note in notes:
            out.append(f"note [{model}]: {note}")
    for sentence in report.skipped:
        out.append(f"note: {sentence}")
    for model, sentences in report.warnings.items():
        for sentence in sentences:
            out.append(f"warning [{model}]: {sentence}")
    for r in report.failures():
        for note in r.notes:
            out.append(f"fail [{r.model} {r.name}]: {note}")
    for model, findings in report.diagnoses.items():
        for line in text_lines(findings):
            out.append(f"diagnosis [{model}]: {line}")
    judged = [r for r in report.results if r.largest_error == r.largest_error]  # not NaN
    if judged:
        top = max(judged, key=lambda r: r.largest_error)
        out.append(
            f"largest relative error: {top.largest_error:.2e} ({top.model} {top.name} at "
            f"{_state_text(top.largest_at)}, where its tolerance is {top.largest_tolerance:.2e}); "
            "the table's error is at each check's worst error/tolerance"
        )
    total = sum(report.states.values())
    out.append(
        f"{len(report.results)} checks on {len(report.states)} model(s), {total} states "
        f"(seed {report.seed}), {report.elapsed_s:.2f} s: {verdict_sentence(report)}"
    )
    return out


def format_table(report: Report) -> str:
    """The text ``pendverify check`` prints: the table, the tolerance's formula, ``trailing_lines``."""
    out = text_table(HEADER, [table_row(r) for r in report.results]) if report.results else []
    out.append("")
    out.append(
        "error and tolerance are relative, in diagonally scaled coordinates: "
        "tolerance = K·ε·((1 + |θ|max)·cond(T)² + (A − 1)) (+ model-form allowance)."
    )
    return "\n".join(out + trailing_lines(report))


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
    if report.results and not report.robot_compared:
        return "the units agree; nothing was compared with a robot: NOT verified (give --urdf FILE)"
    return "all checks pass"


class CheckReport(Report):
    """The report of ``check``: a ``pendverify.checks.report.Report`` that prints as the CLI's table.

    The evidence is in the fields of ``Report``: ``results`` (one ``Evidence`` per model and
    check: ``error``, ``tolerance``, ``at``, ``largest_error``, ``status``, ``notes``),
    ``notes``, ``warnings`` and ``diagnoses`` (per model label), ``states``, ``sources``, ``seed``,
    ``strict``, ``elapsed_s``, ``skipped``; ``passed``, ``status``, ``failures()``, ``refusals()``,
    ``as_dict()`` and ``to_json()`` (the document ``check --json`` writes).  ``report["crba"]``
    gives one check's rows (``CheckRows``), ``report["double_pendulum", "crba"]`` one result;
    ``checks`` and ``models`` name what is there.
    """

    def table(self) -> str:
        """The text ``pendverify check`` prints: the table, notes, warnings, diagnoses, the verdict."""
        return format_table(self)

    def __str__(self) -> str:
        return self.table()

    def _repr_pretty_(self, printer, cycle: bool) -> None:  # IPython / Jupyter: show the table
        printer.text(repr(self) if cycle else self.table())

    @classmethod
    def from_report(cls, report: Report) -> CheckReport:
        """The same report, as a ``CheckReport``."""
        return cls(**{f.name: getattr(report, f.name) for f in dataclasses.fields(Report)})
