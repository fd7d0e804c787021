"""Name the known trap behind a failure, in words next to the numbers.

When checks fail, each hypothesis (``HYPOTHESES``, one module each in
``pendverify.diagnosis.traps``) is tested against the model and the URDF, and the
ones that explain the failure become a ``Finding`` (``pendverify.diagnosis.finding``)
whose message says how well they fit: the *residual*, the part of the discrepancy the hypothesis leaves
unexplained, relative to the whole (``pendverify.diagnosis.traps.fit``: an exact fit at
rounding level, named with its residual up to 1e-3, not named beyond).

Never a wrong diagnosis: a trap of these kinds changes M or H by a relative
amount of order one (a degree is 1.7e-2), so a failure smaller than
``TRAP_MIN_ERROR`` (1e-6, relative) is never blamed on one — and states
beyond the trust limit (``pendverify.checks.trust``) are refused before any
check or diagnosis sees them.

pivot inertia (``crba`` fails)
    the m·r² of an inertia about the pivot instead of the centre of mass, or
    counted twice (``pendverify.diagnosis.traps.inertia``).
missing damping (``aba`` fails)
    friction missing from the hand q̈, of the wrong sign, or not declared in D
    (``pendverify.diagnosis.traps.damping``).
coordinate conventions (``crba`` or ``gravity`` fails)
    an axis sign flip, absolute vs relative angles, degrees vs radians, a zero from
    the vertical or from hanging, and an inertia about the pivot with them, searched
    jointly: two at once are named as well as one
    (``pendverify.diagnosis.traps.conventions``).
"""

from __future__ import annotations

import numpy as np

from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.traps.conventions import coordinate_conventions
from pendverify.diagnosis.traps.damping import missing_damping
from pendverify.diagnosis.traps.fit import diagnosis_states
from pendverify.diagnosis.traps.inertia import pivot_inertia

TRAP_MIN_ERROR = 1e-6  # smallest relative failure a convention or inertia trap can cause


def _largest_failure(results) -> float:
    return max((r.error for r in results if not r.passed), default=0.0)


HYPOTHESES = (pivot_inertia, missing_damping, coordinate_conventions)
#: the hypotheses whose search is bounded by its work: each says what it left out (``unsearched``)
BOUNDED = (coordinate_conventions,)


def diagnose(model, system, results, unsearched: list | None = None) -> list[Finding]:
    """One finding per known trap that explains the failing checks; its message says how well it fits.
    What a bounded search left out is added to ``unsearched``, in words."""
    failing = {r.name for r in results if not r.passed}
    if not failing or not model.has_mass_matrix:  # every trap compares M or H: q̈ alone gives neither
        return []
    # a convention or inertia trap changes M or H by O(1): never blame one for a rounding-size failure
    hypotheses = HYPOTHESES if _largest_failure(results) >= TRAP_MIN_ERROR else (missing_damping,)
    states = diagnosis_states(model)
    out = []
    with np.errstate(all="ignore"):
        for hypothesis in hypotheses:
            if hypothesis in BOUNDED:
                finding = hypothesis(model, system, failing, states, unsearched)
            else:
                finding = hypothesis(model, system, failing, states)
            if finding is not None:
                out.append(finding)
    return out
