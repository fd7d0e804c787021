"""A failing model's diagnosis: what is wrong and how to fix it, as a list of ``Finding``.

In order:

1. the entries that differ, each with the shape of its difference over the states
   (``pendverify.diagnosis.entries``, ``pendverify.diagnosis.patterns``), its coefficients
   written as products of the parameters where one fits (``pendverify.diagnosis.monomials``);
2. the known traps (``pendverify.diagnosis.diagnose``: coordinate conventions, an inertia
   about the pivot, friction missing from q̈);
3. the inertial parameters the model implies: whether it is this robot's dynamics with other
   masses, centres of mass or inertias, and which; or that no mass distribution explains it
   (``pendverify.diagnosis.parameters``), unless a convention explains the failure exactly;
4. the repair, a single edit (or a pair) of the model's own expressions confirmed by every
   check on every state, or a sentence saying none was found (``pendverify.diagnosis.repair``)
   where no convention explains the failure exactly.

Only a model with a failing check on trusted states is diagnosed (the caller decides).  The
whole diagnosis is bounded by ``deadline_s``: each step starts only while time is left (the
entries' shapes one entry at a time), the repair search gets what the steps before it left
(they are vectorised and bounded by counts themselves: well under a second for 3 degrees of
freedom; the convention search and the parameters' fit by the work they count before they
start, and they say what that leaves out), and a ``repair`` finding that is not one says what
was not searched: the shapes of how many entries, the known traps, the inertial parameters, the
repairs, what the work bounds left out, or how many of the entries that disagree the repair
search screened.  A step under way is not interrupted, so the bound is exceeded by at most one
step (one entry's shape, the traps or the parameters: on a 40-link chain, measured, a shape 0.1 s,
the traps 1.6 s, of which the convention search 1.0 s; up to a few seconds when the screen
passes candidates to confirm, each confirmation a run of the checks; the parameters not fitted,
beyond their work bound; ``tests/diagnosis/test_large_model.py``).
"""

from __future__ import annotations

import numpy as np

from pendverify.diagnosis.clock import now
from pendverify.diagnosis.diagnose import diagnose
from pendverify.diagnosis.entries import differing_entries, entry_finding
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.monomials import coefficient_words
from pendverify.diagnosis.parameters import identify_parameters
from pendverify.diagnosis.patterns import entry_pattern, pattern_finding
from pendverify.diagnosis.ranking import ranked
from pendverify.diagnosis.repair import search_repair

#: the whole diagnosis's bound, 10 s of its CPU time (``pendverify.diagnosis.clock``) for up to 3
#: degrees of freedom on a 2-core machine; most
#: take well under a second, a hard case reaches it (``pendverify bench explain`` measures both)
REPAIR_DEADLINE_S = 10.0
#: kept from the repair search's share for what it does after its last step (its findings, in
#: the model's notation) and for the step it is in when the time is up (one screening evaluation)
FINISHING_S = 0.5


def _exact_convention(findings: list[Finding]) -> bool:
    """Whether a convention trap explains the failure exactly: every check passes under it.  Its
    finding names the file key that fixes it; the inertial parameters the model implies in the
    declared coordinates, and a sentence that no edit of the expressions was found, add nothing."""
    return any(f.kind == "convention" and f.details.get("exact") for f in findings)


def explain(batch, results, deadline_s: float = REPAIR_DEADLINE_S) -> list[Finding]:
    """The diagnosis of a model whose checks ``results`` on ``batch`` fail (module docstring)."""
    start = now()

    def late() -> bool:
        return now() - start > deadline_s - FINISHING_S

    failing = {r.name for r in results if not r.passed}
    findings: list[Finding] = []
    skipped: list[str] = []
    # quantities of any size reach here (a damping of 1e300 is valid input): overflow in a fit
    # makes that fit fail, it is not an error
    with np.errstate(all="ignore"):
        entries = differing_entries(batch, failing)
        shaped = 0
        for entry in entries:
            findings.append(entry_finding(entry, batch))
            if late():
                continue
            shaped += 1
            pattern = entry_pattern(entry, batch)
            if pattern is not None:
                written = coefficient_words(pattern, entry, batch.model)
                findings.append(pattern_finding(entry, pattern, batch.model.coordinates, written))
        if shaped < len(entries):
            skipped.append(f"the shape of {len(entries) - shaped} of {len(entries)} differing entries")
        steps = (
            ("the known traps", lambda: diagnose(batch.model, batch.system, results, skipped)),
            ("the inertial parameters", lambda: identify_parameters(batch, skipped)),
        )
        for what, step in steps:
            if late():
                skipped.append(what)
            elif not (what == "the inertial parameters" and _exact_convention(findings)):
                findings += step()
        left = deadline_s - (now() - start) - FINISHING_S
        if left > 0:
            repairs, why_not = search_repair(batch, left)
        else:
            repairs, why_not = [], ""
            skipped.append("repairs")
        if not repairs and _exact_convention(findings):
            why_not = ""  # the convention is the fix, with the file key it edits: no edit is missing
    findings += repairs
    if skipped:
        stopped = f"diagnosis bounded at {deadline_s:g} s; not searched: {', '.join(skipped)}"
        why_not = f"{why_not}; {stopped}" if why_not else stopped
    if why_not:  # said as a repair that is not one: checks_pass false, nothing suggested
        details = {"written": None, "suggested": None, "suggested_source": None, "location": None}
        findings.append(
            Finding("repair", why_not, details={**details, "checks_pass": False, "confirmed": False})
        )
    return ranked(findings)
