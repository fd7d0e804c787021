"""``certify`` on dynamics as code (a q̈ given as Python, ``pendverify.analytic.python_dynamics``).

Such a model has no closed-form M, H or V, so the battery's simulations (which judge a closed
form's energy) do not apply: the battery is its core checks (crba, gravity, rnea on the M, H
and C·q̇ derived from the code's q̈, and aba) and the stress cases, and the certificate says
in its notes why no invariant item ran.  The double pendulum's q̈ as code is certified and
rechecked; the same code with a 1 % error planted in one mass term of its M is not.
"""

from __future__ import annotations

from pathlib import Path

import pendverify
from pendverify.api import recheck
from pendverify.certify.simulations import invariants_not_run
from tests.analytic.test_same_verdicts import CODE, M22, MINIMAL_PARAMS, URDF

SAMPLES = 40  # the battery's random states (its special states come on top)


def _code(tmp_path: Path, old: str = "", new: str = "") -> Path:
    """The double pendulum's q̈ as code (``test_same_verdicts``), ``old`` replaced by ``new``."""
    assert CODE.count(old) == (1 if old else len(CODE) + 1)
    path = tmp_path / "double_pendulum_code.py"
    head = "from tests.analytic.mechanics_double_pendulum import DECLARATION\n"
    path.write_text(head + CODE.replace(old, new))
    return path


def _certify(tmp_path: Path, model: Path):
    return pendverify.certify_set(
        tmp_path / "certificates", urdf=URDF, urdf_params=MINIMAL_PARAMS, analytic=model, samples=SAMPLES
    )


def test_dynamics_code_is_certified_without_simulations_and_says_why(tmp_path):
    issued = _certify(tmp_path, _code(tmp_path))
    assert issued.certified, [i for i in issued.items if not i.passed]
    names = {i.name for i in issued.items}
    assert {"check:crba", "check:gravity", "check:rnea", "check:aba"} <= names, names
    assert not any(i.kind == "invariant" for i in issued.items), names
    (sentence,) = issued.not_run
    assert sentence.startswith("invariant items not run: ") and "gives q̈ alone" in sentence
    assert sentence in issued.certificate["notes"]
    rechecked = recheck(issued.path, run_embedded_code=True)
    assert rechecked.passed, (rechecked.differences, [i for i in rechecked.items if not i.passed])


def test_a_one_percent_mass_error_in_the_code_is_not_certified(tmp_path):
    assert M22 == "(I2 + m2*r2**2)"
    issued = _certify(tmp_path, _code(tmp_path, f", {M22}]])", ", (I2 + 1.01*m2*r2**2)]])"))
    assert not issued.certified and issued.path is None
    failed = {i.name for i in issued.items if not i.passed}
    assert "check:crba" in failed, failed


def test_a_model_with_a_closed_form_M_runs_its_simulations():
    from pendverify.analytic import MODELS

    assert invariants_not_run(MODELS["double_pendulum"]) == ""
