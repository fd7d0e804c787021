"""Whether an edited model passes every check: on a batch of states, and at each perturbed set.

The one test both repair searches apply to a candidate (``pendverify.diagnosis.repair``: an edit
of the model's expressions; ``pendverify.diagnosis.parameter_repair``: an edit of the parameter
set the model's code is given).  ``passes_checks`` runs every applicable check on the states;
``holds_at`` runs them again at each perturbed parameter set (``pendverify.diagnosis.perturbed``),
on the first ``PERTURBED_STATES`` states, with the model the search makes for that set.

Tolerance scales at a perturbed set.  A model whose scales are derived from its closed forms
(``ClosedFormModel.derived_scales``) is judged first with the scales of the model as given at
that set, as ``pendverify mutate`` judges a mutant with the original's; where those are
degenerate (an H planted as 0 has a gravity scale 0, which the rounding at the file's values may
meet and other values not), the edited model's own decide.
"""

from __future__ import annotations

import numpy as np

from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.diagnosis.slots import SCREEN_STATES
from pendverify.errors import PendverifyError

#: states a candidate is checked on at each perturbed set: the screening states.  The candidate
#: already matched Pinocchio on every state at the file's values, so it is the right function of
#: the state there; what a perturbed set tests is the parameters, and a wrong edit's difference
#: (a trigonometric polynomial of a few terms in the state, not zero as a function at the moved
#: parameters) is non-zero at almost every state: 24 states, the special ones first, find it.
PERTURBED_STATES = SCREEN_STATES


def passes_checks(model, system, states, accept=None) -> bool:
    """Whether ``model`` passes every applicable check on every state of ``states`` against ``system``
    (``accept``: a judge of the results other than "every check passes", ``acceptance``)."""
    names = applicable_checks(model, system)
    with np.errstate(all="ignore"):
        try:
            results = run_checks("repair", model, system, states, 0, names)
        except (ArithmeticError, ValueError, np.linalg.LinAlgError, PendverifyError):
            return False  # a scale that cannot be derived too: what is not shown to pass does not
    return accept(results) if accept is not None else all(r.passed for r in results)


def derives_scales(model) -> bool:
    """Whether ``model``'s tolerance scales are derived from its closed forms (not written by hand)."""
    return bool({"gravity_scale", "diagonal_scale"} - set(type(model).hand_written()))


def holds_at(make, sets, states, accept=None, derived: bool = False) -> bool:
    """Whether ``make(moved)``, the edited model at each perturbed set of ``sets``
    (``perturbed.MovedSet``), passes every check on ``states`` against that set's system;
    ``derived``: the model as given derives its tolerance scales (``derives_scales``; module
    docstring)."""
    for moved in sets:
        model = make(moved)
        if derived:  # the tolerance scales of the model as given, at these values
            model.use_derived_scales(moved.model.derived_scales())
        if passes_checks(model, moved.system, states, accept):
            continue
        if not derived or not passes_checks(make(moved), moved.system, states, accept):
            return False
    return True
