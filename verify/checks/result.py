"""What a check is and what it reports: ``Check`` (one comparison and its constant K) and ``CheckResult``.

The checks themselves are listed in ``pendverify.checks.catalogue``; what one measures at
a state is in ``pendverify.checks.quantities``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from pendverify.checks.verdict import FAIL, PASS

if TYPE_CHECKING:
    from pendverify.analytic import ClosedFormModel
    from pendverify.checks.quantities import Measure, Terms
    from pendverify.robot.system import PinocchioSystem


@dataclass(frozen=True)
class Check:
    name: str
    pinocchio: str
    closed_form: str
    K: float
    #: the check's measure at every state of a batch (``pendverify.checks.quantities``)
    measure: Callable[[Terms], Measure]
    #: "" when the check applies to this model and system, else why it is not run
    requires: Callable[[ClosedFormModel, PinocchioSystem | None], str] = lambda model, system: ""
    #: whether the Pinocchio side is computed by its world-frame recursions (then A counts)
    world_frame: bool = True


@dataclass
class CheckResult:
    """The evidence of one check on one model: errors, tolerance, where it was worst."""

    model: str
    check: str
    description: str
    max_error: float
    tolerance: float
    max_abs_error: float
    samples: int
    seed: int
    worst_state: dict
    passed: bool
    #: the largest relative error over the judged states, and where (the worst *ratio* is above)
    largest_error: float = float("nan")
    largest_tolerance: float = float("nan")  # the tolerance at that state
    largest_state: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    #: pass, warn, fail or refused (``pendverify.checks.verdict``); ``passed`` is pass or warn
    status: str = ""

    def __post_init__(self) -> None:
        if not self.status:
            self.status = PASS if self.passed else FAIL

    def as_dict(self) -> dict:
        """Every field, as the JSON report's entry for this result."""
        return dict(self.__dict__)

    def __repr__(self) -> str:
        where = str(self.worst_state.get("label", ""))[:60]
        return (
            f"<CheckResult {self.model[:80]} {self.check}: {self.status}, error {self.max_error:.2e} "
            f"vs tolerance {self.tolerance:.2e} at {where}>"
        )

    def _repr_html_(self) -> str:
        """The result's row of the check table, its description and notes (a notebook's view)."""
        from pendverify.display import html_fields

        fields = [
            ("status", self.status),
            ("error", f"{self.max_error:.3e}"),
            ("tolerance", f"{self.tolerance:.3e}"),
            ("worst state", self.worst_state.get("label", "")),
            ("states", f"{self.samples} (seed {self.seed})"),
            *(("note", note) for note in self.notes),
        ]
        return html_fields(f"{self.model} {self.check}: {self.description}", fields)
