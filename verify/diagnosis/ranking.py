"""The order of a diagnosis's findings: what differs first, then the explanations, the most likely fix first.

One rule, used by every report (text, ``--json``, JUnit, the review page):

1. ``entry`` and ``pattern`` findings, in the order they were found: they say what differs,
   not why, and each pattern follows its entry.
2. The explanations, exact ones before approximate ones, and among each by how much of the
   model they change (``LEVELS``):

   ======  ======================  ==============================================================
   level   what changes            findings
   ======  ======================  ==============================================================
   0       one term, one entry     a confirmed ``repair``; the repairs keep the search's order,
                                   simplest first (one term before two edits of one entry before
                                   edits of two entries: ``pendverify.diagnosis.candidates.RANK``)
   1       several entries         a ``parameters`` explanation: a link's mass, centre of mass or
                                   inertia enters every entry that it feeds
   2       a convention            a ``convention`` finding of one trap (the inertia trap, or one
                                   coordinate convention)
   3       two conventions         a ``convention`` finding of two traps or more
   ======  ======================  ==============================================================

   Exact: a repair under which every check passes, a parameters explanation (accepted only
   when it reproduces the hand model within its tolerance), a convention whose residual is at
   rounding level (``EXACT_RESIDUAL``).  Equal ranks keep the order they were found in.
3. Statements that explain without a fix: ``structural`` (no mass distribution produces the
   equations), a ``parameters`` finding that lists the combinations that differ, and a
   ``repair`` that is not one (``checks_pass`` false: what the search tried).

So the first explanation is the most likely fix: a one-character sign error in H that two
convention traps at once also explain exactly (a cart-pole's gravity term flipped is an axis
flip with a zero from hanging) is shown as its one-entry repair first.
"""

from __future__ import annotations

from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.traps.fit import EXACT_RESIDUAL

#: the findings that say what differs, not why
WHAT_DIFFERS = ("entry", "pattern")
LEVELS = {"one entry": 0, "several entries": 1, "a convention": 2, "two conventions": 3}


def _statement(f: Finding) -> bool:
    """Whether a finding explains without a fix (module docstring, 3)."""
    if f.kind == "structural":
        return True
    if f.kind == "parameters":
        return f.details.get("parameter") == "identifiable combinations"
    return f.kind == "repair" and not f.details.get("checks_pass")


def _level(f: Finding) -> int:
    if f.kind == "repair":
        return LEVELS["one entry"]
    if f.kind == "parameters":
        return LEVELS["several entries"]
    traps = f.details.get("traps", [None])  # the inertia trap names no "traps": it is one
    return LEVELS["a convention"] if len(traps) <= 1 else LEVELS["two conventions"]


def _exact(f: Finding) -> bool:
    if f.kind == "convention":
        return f.details.get("residual", 0.0) <= EXACT_RESIDUAL
    return True  # a confirmed repair, an accepted parameters explanation


def rank_key(f: Finding) -> tuple:
    """Where a finding goes (module docstring); ties keep the order they were found in."""
    if f.kind in WHAT_DIFFERS:
        return (0, 0, 0)
    if _statement(f):
        return (2, 0, 0)
    return (1, not _exact(f), _level(f))


def ranked(findings: list[Finding]) -> list[Finding]:
    """The findings in the order of the module docstring (a stable sort)."""
    return sorted(findings, key=rank_key)


def explanations_first(findings: list[Finding]) -> list[Finding]:
    """The same order with what differs after the explanations, for a page that leads with the fix."""
    order = ranked(findings)
    return [f for f in order if f.kind not in WHAT_DIFFERS] + [f for f in order if f.kind in WHAT_DIFFERS]
