"""One battery item's evidence (``pendverify.certify.battery`` makes the checks' and stress
cases', ``pendverify.certify.simulations`` the invariants'); a certificate records each as
``as_dict`` writes it (``pendverify.certify.certificate``)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

from pendverify.display import html_table, shortened

#: the columns of a notebook's table of battery items (``items_html``)
ITEM_HEADER = ("item", "kind", "error", "tolerance", "at", "result")


def items_html(items, caption: str) -> str:
    """Battery items as an HTML table under ``caption``, failing ones in red."""
    rows = [
        (i.name, i.kind, f"{i.error:.2e}", f"{i.tolerance:.2e}", i.at, "pass" if i.passed else "FAIL")
        for i in items
    ]
    return html_table(ITEM_HEADER, rows, caption, [not i.passed for i in items])


@dataclass(frozen=True)
class BatteryItem:
    """One battery item's evidence: the worst error/tolerance ratio and, apart, the largest error.

    ``error`` and ``tolerance`` are relative (as in the tables) and belong to the same
    state or step, ``at``: the one with the worst ratio, which decides ``passed``.
    ``max_error`` is the largest error over the item, at ``max_error_at`` (checks and
    invariants); the stress cases keep only their worst ratio, so it is None there.
    """

    name: str
    kind: str  # check | stress | invariant
    error: float
    tolerance: float
    samples: int
    seed: int
    passed: bool
    detail: str = ""
    at: str = ""
    max_error: float | None = None
    max_error_at: str = ""
    engine: str = ""  # invariant items: what ran the simulation (pendverify.certify.simulations)

    def __repr__(self) -> str:
        verdict = "pass" if self.passed else "FAIL"
        at = f" at {shortened(self.at, 80)}" if self.at else ""
        return (
            f"<BatteryItem {shortened(self.name, 60)} ({self.kind}): {verdict}, error {self.error:.2e} "
            f"vs tolerance {self.tolerance:.2e}{at}>"
        )

    def _repr_html_(self) -> str:
        return items_html([self], f"battery item {self.name}: {self.detail}" if self.detail else self.name)

    def as_dict(self) -> dict:
        record = asdict(self)
        if not record["engine"]:
            del record["engine"]  # checks and stress cases run no simulation
        return record

    @property
    def margin(self) -> float:
        """error / tolerance: below 1 passes."""
        return self.error / self.tolerance if self.tolerance > 0 else float("inf")
