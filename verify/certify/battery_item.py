"""Battery items in a notebook: a table of them (``items_html``).

A battery item is an ``Evidence`` (``pendverify.checks.evidence``) with the kind of what it
reports: ``pendverify.certify.battery`` makes the checks' and stress cases',
``pendverify.certify.simulations`` the invariants'; a certificate records each as
``item_record`` writes it (``pendverify.certify.certificate``).  ``error`` and ``tolerance``
belong to the same state or step, ``at``: the one with the worst ratio, which decides the
verdict; ``largest_error`` is the largest error over the item, at ``largest_at`` (checks and
invariants; the stress cases keep only their worst ratio, so it is None there)."""

from __future__ import annotations

from pendverify.checks.evidence import item_verdict
from pendverify.display import html_table

#: the columns of a notebook's table of battery items (``items_html``)
ITEM_HEADER = ("item", "kind", "error", "tolerance", "at", "result")


def items_html(items, caption: str) -> str:
    """Battery items as an HTML table under ``caption``, failing ones in red."""
    rows = [(i.name, i.kind, f"{i.error:.2e}", f"{i.tolerance:.2e}", i.label, item_verdict(i)) for i in items]
    return html_table(ITEM_HEADER, rows, caption, [not i.passed for i in items])
