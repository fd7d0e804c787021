"""The outcome of a mutation run: one verdict per mutant, and the report ``pendverify mutate`` prints.

Each mutant is *detected* (some check fails), *equivalent* (it does not change the
dynamics, proved symbolically: ``pendverify.symbolic.equivalence``) or *survived* (no
check fails and no equivalence is proved: a gap in the verification).  Detection rate
= detected / (all − equivalent); the target is 100 %.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from pendverify.checks.catalogue import CHECK_NAMES
from pendverify.display import html_text, shortened

DETECTED, EQUIVALENT, SURVIVED = "detected", "equivalent", "survived"


@dataclass
class Outcome:
    method: str
    operator: str
    description: str
    verdict: str
    reason: str = ""
    checks: list[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


@dataclass
class Bounds:
    """The bounds of a run (``pendverify.symbolic.mutate``) and what they left out."""

    #: mutants run per closed form at most (a larger set is sampled)
    max_mutants: int
    #: the wall-clock bound [s]
    seconds: int
    #: mutants generated per method (before sampling)
    generated: dict[str, int] = field(default_factory=dict)
    #: mutants sampled but not run per method, the run having stopped at ``seconds``
    not_run: dict[str, int] = field(default_factory=dict)

    def sampled(self) -> dict[str, int]:
        """Per method cut by ``max_mutants``: how many it had."""
        return {m: n for m, n in self.generated.items() if n > self.max_mutants}

    def as_dict(self) -> dict:
        return {
            "max_mutants": self.max_mutants,
            "seconds": self.seconds,
            "generated": self.generated,
            "sampled": self.sampled(),
            "not_run": self.not_run,
        }


@dataclass
class MutationReport:
    model: str
    source: str
    seed: int
    states: int
    outcomes: list[Outcome]
    controls: list[str]
    elapsed_s: float = 0.0
    all_checks: bool = False
    #: interface methods the model does not write (derived by default): not mutated
    derived: list[str] = field(default_factory=list)
    #: hand-written methods no Pinocchio check sees (B, W with a derived q̈): not mutated
    unseen: list[str] = field(default_factory=list)
    bounds: Bounds | None = None

    def count(self, verdict: str, method: str | None = None) -> int:
        return sum(o.verdict == verdict and (method is None or o.method == method) for o in self.outcomes)

    @property
    def rate(self) -> float:
        relevant = len(self.outcomes) - self.count(EQUIVALENT)
        return self.count(DETECTED) / relevant if relevant else 1.0

    @property
    def passed(self) -> bool:
        return self.count(SURVIVED) == 0

    def __repr__(self) -> str:
        return (
            f"<MutationReport {shortened(self.model, 60)}: {len(self.outcomes)} mutants, "
            f"{self.count(DETECTED)} detected, {self.count(EQUIVALENT)} equivalent, "
            f"{self.count(SURVIVED)} survived (rate {self.rate:.0%}); {self.states} states, seed {self.seed}>"
        )

    def _repr_html_(self) -> str:
        return html_text(format_report(self))

    def as_dict(self) -> dict:
        return {
            "model": self.model,
            "source": self.source,
            "seed": self.seed,
            "states": self.states,
            "mutants": len(self.outcomes),
            "detected": self.count(DETECTED),
            "equivalent": self.count(EQUIVALENT),
            "survived": self.count(SURVIVED),
            "detection_rate": self.rate,
            "controls": self.controls,
            "all_checks": self.all_checks,
            "derived": self.derived,
            "unseen": self.unseen,
            "bounds": self.bounds.as_dict() if self.bounds else None,
            "elapsed_s": round(self.elapsed_s, 3),
            "outcomes": [o.as_dict() for o in self.outcomes],
        }


def format_report(report: MutationReport) -> str:
    methods = list(dict.fromkeys(o.method for o in report.outcomes))
    header = ("method", "mutants", "detected", "equivalent", "survived")
    rows = [
        (
            m,
            str(sum(o.method == m for o in report.outcomes)),
            str(report.count(DETECTED, m)),
            str(report.count(EQUIVALENT, m)),
            str(report.count(SURVIVED, m)),
        )
        for m in methods
    ]
    rows.append(
        (
            "all",
            str(len(report.outcomes)),
            str(report.count(DETECTED)),
            str(report.count(EQUIVALENT)),
            str(report.count(SURVIVED)),
        )
    )
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    line = "  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))
    out = [f"mutate [{report.model}] ({report.source})", line, "-" * len(line)]
    out += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    by_check = {
        c: sum(any(k.split()[0] == c for k in o.checks) for o in report.outcomes if o.verdict == DETECTED)
        for c in CHECK_NAMES
    }
    what = "failing" if report.all_checks else "first failing (aimed check first)"
    out.append(f"detections per {what} check: " + ", ".join(f"{c} {n}" for c, n in by_check.items()))
    for o in report.outcomes:
        if o.verdict == EQUIVALENT:
            out.append(f"equivalent: {o.description} — {o.reason}")
    for o in report.outcomes:
        if o.verdict == SURVIVED:
            out.append(f"SURVIVED: {o.description} — {o.reason}")
    if report.derived:
        out.append(f"not mutated (derived, not hand-written): {', '.join(report.derived)}")
    if report.unseen:
        out.append(
            f"not mutated (no Pinocchio check sees them: the URDF has no input map and q̈ is derived; "
            f"compared by pendverify sympy): {', '.join(report.unseen)}"
        )
    out += bound_lines(report)
    relevant = len(report.outcomes) - report.count(EQUIVALENT)
    out.append(
        f"detection rate {report.rate:.1%} ({report.count(DETECTED)}/{relevant} non-equivalent mutants), "
        f"{report.count(EQUIVALENT)} equivalent, {report.states} states (seed {report.seed}), "
        f"controls pass for {len(report.controls)} methods, {report.elapsed_s:.1f} s"
    )
    return "\n".join(out)


def bound_lines(report: MutationReport) -> list[str]:
    """What the run's bounds left out, in words (nothing when every mutant ran)."""
    b = report.bounds
    if b is None:
        return []
    out = []
    sampled = b.sampled()
    if sampled:
        cut = ", ".join(f"{m} {b.max_mutants} of {n}" for m, n in sampled.items())
        out.append(
            f"sampled at the bound of {b.max_mutants} mutants per closed form (PENDVERIFY_MAX_MUTANTS), "
            f"drawn with the seed: {cut}; not run: {sum(sampled.values()) - b.max_mutants * len(sampled)}"
        )
    if b.not_run:
        total = len(report.outcomes) + sum(b.not_run.values())
        left = ", ".join(f"{m} {n}" for m, n in b.not_run.items())
        out.append(
            f"stopped at its bound of {b.seconds} s (PENDVERIFY_MUTATE_SECONDS): {len(report.outcomes)} of "
            f"{total} mutants run; not run: {left}"
        )
    return out
