"""A failing model's diagnosis: what is wrong and how to fix it, as a list of ``Finding``.

In order:

1. the entries that differ, each with the shape of its difference over the states
   (``pendverify.diagnosis.entries``, ``pendverify.diagnosis.patterns``);
2. the known traps (``pendverify.diagnosis.diagnose``: coordinate conventions, an inertia
   about the pivot, friction missing from q̈);
3. the inertial parameters the model implies: whether it is this robot's dynamics with other
   masses, centres of mass or inertias, and which; or that no mass distribution explains it
   (``pendverify.diagnosis.parameters``);
4. the repair, a single edit (or a pair) of the model's own expressions confirmed by every
   check on every state, or a sentence saying none was found (``pendverify.diagnosis.repair``).

Only a model with a failing check on trusted states is diagnosed (the caller decides).  The
whole diagnosis is bounded by ``deadline_s``: the repair search gets what the steps before it
left (they are vectorised and bounded themselves: well under a second for 3 degrees of
freedom), and says so when it stops at the bound.
"""

from __future__ import annotations

import time

import numpy as np

from pendverify.diagnosis.diagnose import diagnose
from pendverify.diagnosis.entries import differing_entries, entry_finding
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.parameters import identify_parameters
from pendverify.diagnosis.patterns import entry_pattern, pattern_finding
from pendverify.diagnosis.repair import search_repair

#: the whole diagnosis's bound, 10 s for up to 3 degrees of freedom on a 2-core machine; most
#: take well under a second, a hard case reaches it (``pendverify bench explain`` measures both)
REPAIR_DEADLINE_S = 10.0
#: kept from the repair search's share for what it does after its last step (its findings, in
#: the model's notation) and for the step it is in when the time is up (one screening evaluation)
FINISHING_S = 0.5


def explain(batch, results, deadline_s: float = REPAIR_DEADLINE_S) -> list[Finding]:
    """The diagnosis of a model whose checks ``results`` on ``batch`` fail (module docstring)."""
    start = time.perf_counter()
    failing = {r.check for r in results if not r.passed}
    findings: list[Finding] = []
    # quantities of any size reach here (a damping of 1e300 is valid input): overflow in a fit
    # makes that fit fail, it is not an error
    with np.errstate(all="ignore"):
        for entry in differing_entries(batch, failing):
            findings.append(entry_finding(entry, batch))
            pattern = entry_pattern(entry, batch)
            if pattern is not None:
                findings.append(pattern_finding(entry, pattern, batch.model.coordinates))
        findings += diagnose(batch.model, batch.system, results)
        findings += identify_parameters(batch)
        left = deadline_s - (time.perf_counter() - start) - FINISHING_S
        repairs, why_not = search_repair(batch, max(0.0, left))
    findings += repairs
    if why_not:  # said as a repair that is not one: checks_pass false, nothing suggested
        details = {"written": None, "suggested": None, "suggested_source": None, "location": None}
        findings.append(Finding("repair", why_not, details={**details, "checks_pass": False}))
    return findings
