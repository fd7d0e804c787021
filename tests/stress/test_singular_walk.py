"""The near-singular walk stops where Pinocchio's inertia sums clamp a mass (``stress.singular``).

The one-joint pendulum (``tests/robot/one_joint.py``, a 2 kg point mass at 0.5 m) was walked
to m = 2e-16 kg, below ε, where Pinocchio put the bob at 0.406 m and failed a correct model.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from pendverify.checks.trust import EPS
from pendverify.stress.framework import QUICK
from pendverify.stress.generic import run_generic
from pendverify.stress.singular import LIMIT_MARGIN, MASS_FLOOR, lightest_changed, link_masses

from ..robot.one_joint import PENDULUM_URDF, write_one_joint

CASE = "near-singular M"


def _lever_and_m(mass: float) -> tuple[float, float]:
    """Pinocchio's centre of mass (z) and M of the pendulum URDF with the bob's mass set."""
    urdf = PENDULUM_URDF.replace('<mass value="2.0"/>', f'<mass value="{mass!r}"/>')
    model = pin.buildModelFromXML(urdf)
    M = pin.crba(model, model.createData(), pin.neutral(model))
    return float(model.inertias[1].lever[2]), float(M[0, 0])


@pytest.mark.parametrize("mass", [MASS_FLOOR, LIMIT_MARGIN * MASS_FLOOR, 1e-12, 2.0])
def test_pinocchio_keeps_the_centre_of_mass_down_to_the_floor(mass):
    lever, M = _lever_and_m(mass)
    assert lever == -0.5 and abs(M - mass * 0.25) <= 4 * EPS * mass * 0.25, f"{mass=} {lever=} {M=}"


@pytest.mark.parametrize("mass", [0.9 * MASS_FLOOR, 2e-16, 1e-16])
def test_below_the_floor_pinocchio_moves_the_centre_of_mass(mass):
    """The clamp the limit is derived from: the lever comes out scaled by (m/ε)² (two sums)."""
    lever, M = _lever_and_m(mass)
    assert lever == pytest.approx(-0.5 * (mass / EPS) ** 2, rel=1e-12), f"{mass=} {lever=}"
    assert M < 0.99 * mass * 0.25


def test_the_floor_applies_to_the_masses_the_walk_changes():
    """A link the walk leaves as given is the nominal case's to judge; a massless link adds nothing."""
    nominal = link_masses(PENDULUM_URDF)
    assert nominal == [2.0]
    assert lightest_changed(PENDULUM_URDF, nominal) == float("inf")
    assert lightest_changed(PENDULUM_URDF.replace('value="2.0"', 'value="2e-16"'), nominal) == 2e-16
    assert lightest_changed(PENDULUM_URDF.replace('value="2.0"', 'value="0"'), nominal) == float("inf")


def _walk(tmp_path, model_text=None):
    r = write_one_joint("pendulum", tmp_path)
    if model_text is not None:
        r.model.write_text(model_text(r.model.read_text()))
    (case,) = run_generic(str(r.model), str(r.robot), str(r.params), QUICK, names=(CASE,)).results
    return case


def test_a_correct_pendulum_is_walked_to_the_floor_and_passes(tmp_path):
    case = _walk(tmp_path)
    assert case.passed, case.notes
    # m = 2 kg × 10^-k down to k = 14, then the step that puts the bob at 2ε kg
    k_last = -np.log10(LIMIT_MARGIN * MASS_FLOOR / 2.0)
    walk = case.extras["invariant"]
    assert f"verified at k = 0, 2, 4, 6, 8, 10, 12, 14, {k_last:.3g};" in walk
    assert "stopped at" in walk and "Pinocchio's inertia sums clamp" in walk


def test_an_error_seen_only_deep_in_the_walk_still_fails(tmp_path):
    """M off by 1e-25 kg·m² (a stray constant): 2e-26 of M at 2 kg, invisible to nominal; at
    m = 2e-12 kg (M = 5e-13) it is 2e-13 of M, far above the tolerance: the walk must fail."""
    old = "return np.array([[(p.I + p.m * p.r**2)]])"

    def planted(text):
        assert text.count(old) == 1
        return text.replace(old, "return np.array([[(p.I + p.m * p.r**2) + 1e-25]])")

    case = _walk(tmp_path, planted)
    assert case.failed and "FAIL crba" in "; ".join(case.notes)
    r = write_one_joint("pendulum", tmp_path / "nominal")
    r.model.write_text(planted(r.model.read_text()))
    (nominal,) = run_generic(str(r.model), str(r.robot), str(r.params), QUICK, names=("nominal",)).results
    assert nominal.passed, nominal.notes
