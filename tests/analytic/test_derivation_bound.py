"""The derivation's rounding bound (``analytic.numeric_derivation.rounding_bounds``) on 3 and 5 links.

The conformance matrix's triple pendulum of point masses and 5-link chain, as dynamics code
(ẋ = f(x, u), torques on every joint: M, H and C·q̇ derived from q̈), have κ̃(M) up to a few
hundred at angles up to 100 rad.  A bound that put the angles' rounding into every call of the
derivation and took ‖M̃⁻¹‖·F for every acceleration refused crba, gravity and rnea on them
(exit 1) although their errors are a few ε; they verify, no state refused.  A 1 % error in one
link's mass, planted in the code's M only, still fails crba on each.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import pendverify
from tests.conformance.formats import Model
from tests.conformance.runner import Files
from tests.conformance.systems import SYSTEMS

SAMPLES = 60
#: system → the mass whose terms in the code's M are planted 1 % off (the last link's)
LAST_MASS = {"triple_pendulum": "m3", "chain5": "m5"}


def _files(tmp_path: Path, system: str, mass: str = "") -> Files:
    """The system's dynamics-code model, URDF and parameters; ``mass`` × 1.01 in the code's M."""
    files = Files(tmp_path, SYSTEMS[system], "dynamics_f", "urdf", Model(SYSTEMS[system], "urdf", None))
    if mass:
        text = files.model.read_text()
        (line,) = [x for x in text.splitlines() if "M = np.array(" in x]
        planted = re.sub(rf"\b{mass}\b", f"1.01*{mass}", line)
        assert planted != line
        files.model.write_text(text.replace(line, planted))
    return files


def _check(files: Files):
    return pendverify.check(files.model, files.robot, files.params, samples=SAMPLES, explain=False)


@pytest.mark.parametrize("system", sorted(LAST_MASS))
def test_true_dynamics_code_on_three_and_five_links_verifies(system, tmp_path):
    report = _check(_files(tmp_path, system))
    statuses = {check: report[check].status for check in report.checks}
    assert {"crba", "gravity", "rnea", "aba"} <= set(statuses), statuses
    assert all(s == "pass" for s in statuses.values()), statuses
    notes = " ".join(n for ns in report.notes.values() for n in ns)
    assert "refused" not in notes, notes


@pytest.mark.parametrize("system", sorted(LAST_MASS))
def test_a_one_percent_mass_error_in_the_code_still_fails(system, tmp_path):
    report = _check(_files(tmp_path, system, LAST_MASS[system]))
    assert report["crba"].status == "fail", {check: report[check].status for check in report.checks}
