"""Convention traps searched jointly: two at once are named with all their traps, one as before.

Each test plants its traps in the coordinate map the URDF is seen through (the hand model
is the shipped one, and right), so the map that undoes them is known.  The finding must
name every planted trap with an exact fit, and the map it reports (with the inertias it
takes about the centres of mass) must make every check pass on states it has not seen.
"""

from __future__ import annotations

import json
import math
import re
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from pendverify.analytic import DoublePendulum
from pendverify.analytic.params import load_parameter_file
from pendverify.checks.catalogue import run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.diagnose import diagnose
from pendverify.diagnosis.traps import convention_screen
from pendverify.diagnosis.traps.convention_maps import (
    ABSOLUTE_RELATIVE,
    DEGREES,
    HALF,
    MAX_CANDIDATES,
    PIVOT,
    QUARTER,
    SIGN,
    candidates,
    left_out,
    most_touched,
)
from pendverify.diagnosis.traps.conventions import SCREEN_STATES, coordinate_conventions
from pendverify.diagnosis.traps.fit import EXACT_RESIDUAL, diagnosis_states
from pendverify.diagnosis.traps.inertia import corrected_system
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for

from ..conftest import SEED, default_params, example_module

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CLASSES = {
    "triple_pendulum": "TriplePendulum",
    "hanging_double_pendulum": "HangingDoublePendulum",
    "furuta_pendulum": "FurutaPendulum",
}
#: A with θ_rel = A θ_abs for two angles
A2 = np.array([[1.0, 0.0], [-1.0, 1.0]])


def _setup(stem: str, urdf_params=None):
    """(model, its system) of a shipped model; ``urdf_params`` (params → params) alters its URDF."""
    if stem == "double_pendulum":
        params = default_params(stem)
        urdf = urdf_for(urdf_params(params) if urdf_params else params)
        return DoublePendulum(params), PinocchioSystem.for_model(DoublePendulum, urdf, params.g)
    module = example_module(stem)
    cls = getattr(module, CLASSES[stem])
    _, _, params = load_parameter_file(EXAMPLES / f"{stem}.toml", {cls.name: cls.params_type})
    urdf = str(EXAMPLES / f"{stem}.urdf")
    if urdf_params:
        urdf = getattr(module, f"{stem}_urdf")(urdf_params(params))
    return cls(params), PinocchioSystem.for_model(cls, urdf, params.g)


def _planted(system, T, theta0):
    """``system`` seen through the map (T, θ0) instead of its own."""
    return system.with_map(CoordinateMap(np.array(T, float), np.array(theta0, float), system.cmap.joint_nq))


def _failing(model, system) -> set[str]:
    results = run_checks("planted", model, system, sample_states(model, 30, SEED), SEED)
    return {r.name for r in results if not r.passed}


def _finding(model, system):
    failing = _failing(model, system)
    assert failing, "a planted trap must fail a check"
    return coordinate_conventions(model, system, failing, diagnosis_states(model))


def _every_check_passes(model, system, details) -> bool:
    """Whether every check passes, on states the diagnosis did not see, with the map the finding reports."""
    cmap = CoordinateMap(np.array(details["T"]), np.array(details["theta0"]), system.cmap.joint_nq)
    fixed = corrected_system(system, details["links"], cmap)
    unseen = sample_states(model, 30, SEED + 1)
    return all(r.passed for r in run_checks("fixed", model, fixed, unseen, SEED + 1))


# --- two traps at once ----------------------------------------------------------------------------
TWO_TRAPS = {
    # the map takes the hand's relative θ2 as absolute (T·A), and θ2 turns the other way
    "double pendulum: sign flip + absolute/relative": ("double_pendulum", A2 @ np.diag([1.0, -1.0]), (0, 0)),
    # the triple pendulum's relative joints declared as absolute (identity), φ2 turning the other way
    "triple pendulum: sign flip + absolute/relative": (
        "triple_pendulum",
        np.diag([1.0, -1.0, 1.0]),
        (0, 0, 0),
    ),
    # θ1 turns the other way and its zero is a quarter turn off
    "double pendulum: offset π/2 + sign flip": ("double_pendulum", np.diag([-1.0, 1.0]), (math.pi / 2, 0)),
    # the hanging pendulum's relative second joint declared absolute, its offsets written in degrees
    "hanging pendulum: degrees + absolute/relative": ("hanging_double_pendulum", np.eye(2), (90.0, 90.0)),
}
EXPECTED = {
    "double pendulum: sign flip + absolute/relative": {SIGN, ABSOLUTE_RELATIVE},
    "triple pendulum: sign flip + absolute/relative": {SIGN, ABSOLUTE_RELATIVE},
    "double pendulum: offset π/2 + sign flip": {SIGN, QUARTER},
    "hanging pendulum: degrees + absolute/relative": {DEGREES, ABSOLUTE_RELATIVE},
}


@pytest.mark.parametrize("case", list(TWO_TRAPS))
def test_two_traps_at_once_are_named_with_an_exact_fit(case):
    stem, T, theta0 = TWO_TRAPS[case]
    model, right = _setup(stem)
    system = _planted(right, T, theta0)
    finding = _finding(model, system)
    assert finding is not None, case
    assert finding.kind == "convention" and finding.quantity is None and finding.index == ()
    assert set(finding.details["traps"]) == EXPECTED[case], finding.message
    assert finding.message.startswith("two convention traps at once — ")
    assert "every check passes (an exact fit: residual " in finding.message
    assert finding.details["residual"] <= EXACT_RESIDUAL
    assert _every_check_passes(model, system, finding.details)
    json.dumps(finding.as_dict())  # the JSON report carries it as it is


def test_a_map_trap_with_an_inertia_about_the_pivot_is_named_with_both():
    # the triple pendulum's URDF with link 3's inertia about its pivot, seen through an identity map
    model, right = _setup("triple_pendulum", lambda p: p.replace(I3=p.I3 + p.m3 * p.r3**2))
    system = _planted(right, np.eye(3), (0, 0, 0))
    finding = _finding(model, system)
    assert set(finding.details["traps"]) == {ABSOLUTE_RELATIVE, PIVOT}
    assert finding.details["links"] == {"link3 (joint joint3)": 1}
    assert (
        "the URDF's inertia of link3 (joint joint3) is about the pivot instead of the centre of mass, "
        "or your M misses the parallel-axis term"
    ) in finding.message
    assert finding.details["residual"] <= EXACT_RESIDUAL
    assert _every_check_passes(model, system, finding.details)
    # the pivot trap alone does not explain it: the joint finding is the only one
    results = run_checks("planted", model, system, sample_states(model, 30, SEED), SEED)
    assert [f.details["traps"] for f in diagnose(model, system, results)] == [[ABSOLUTE_RELATIVE, PIVOT]]


def test_the_pivot_fits_beyond_the_work_bound_are_not_run_and_said_so(monkeypatch):
    """The case above with room for the declared map's fit alone: the candidate that explains it is
    not fitted, so nothing is named, and what was left out is said."""
    model, right = _setup("triple_pendulum", lambda p: p.replace(I3=p.I3 + p.m3 * p.r3**2))
    system = _planted(right, np.eye(3), (0, 0, 0))
    failing, states = _failing(model, system), diagnosis_states(model)
    monkeypatch.setattr(convention_screen, "MAX_FIT_WORK", convention_screen.fit_work(SCREEN_STATES, 3, 3))
    unsearched = []
    assert coordinate_conventions(model, system, failing, states, unsearched) is None
    (said,) = unsearched
    found = re.fullmatch(r"the pivot-inertia fit of (\d+) coordinate convention maps whose H agrees", said)
    assert found and int(found.group(1)) >= 1, said


def test_a_joint_fit_that_leaves_a_small_difference_says_so():
    # as above, with the URDF's inertia 1e-5 larger than I_com + m·r²: the two traps explain all but that
    model, right = _setup("triple_pendulum", lambda p: p.replace(I3=(p.I3 + p.m3 * p.r3**2) * (1 + 1e-5)))
    finding = _finding(model, _planted(right, np.eye(3), (0, 0, 0)))
    assert set(finding.details["traps"]) == {ABSOLUTE_RELATIVE, PIVOT}
    match = re.search(
        r"all but ([0-9.e+-]+) of the discrepancy goes; a smaller difference remains as well$",
        finding.message,
    )
    assert match, finding.message
    # the 1e-5 of I3 + m3 r3² against the whole discrepancy, M's of order one: between 1e-7 and 1e-4
    residual = float(match.group(1))
    assert 1e-7 < residual < 1e-4
    assert residual == pytest.approx(finding.details["residual"], rel=0.05)  # printed to two digits


# --- one trap, named as before ------------------------------------------------------------------------
def test_one_trap_keeps_its_sentence():
    model, right = _setup("triple_pendulum")
    finding = _finding(model, _planted(right, np.eye(3), (0, 0, 0)))
    assert finding.details["traps"] == [ABSOLUTE_RELATIVE]
    assert finding.message.startswith(
        "absolute vs relative angles: the hand model's angles are absolute (all from one reference) where "
        "the coordinate map takes them as relative (each from the previous link); with θ_rel = A·θ_abs, "
        "T → T·A = [[1.0, 0.0, 0.0], [-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]], every check passes "
        "(an exact fit: residual "
    )


def test_one_sign_flip_is_named():
    model, right = _setup("double_pendulum")
    system = _planted(right, np.diag([1.0, -1.0]), (0, 0))
    finding = _finding(model, system)
    assert finding.details["traps"] == [SIGN]
    assert finding.message.startswith(
        "axis sign flip: theta2 turns the other way round; with T → T·S = [[1.0, 0.0], [0.0, 1.0]], "
        "every check passes (an exact fit: residual "
    )
    assert _every_check_passes(model, system, finding.details)


def test_equally_simple_explanations_are_listed_and_each_makes_every_check_pass():
    # the Furuta pendulum mirrored through the arm's vertical plane is itself: a flip of the arm's
    # angle and a flip of the pendulum's are one map to the URDF
    model, right = _setup("furuta_pendulum")
    system = _planted(right, np.diag([-1.0, 1.0]) @ right.cmap.T, right.cmap.theta0)
    finding = _finding(model, system)
    assert finding.details["traps"] == [SIGN]
    (other,) = finding.details["alternatives"]
    assert other["traps"] == [SIGN]
    assert "so that the URDF cannot tell them apart: axis sign flip: alpha turns" in finding.message
    assert _every_check_passes(model, system, finding.details)
    assert _every_check_passes(model, system, other)


def test_a_half_turn_and_a_sign_flip_are_named():
    model, right = _setup("furuta_pendulum")
    system = _planted(right, np.diag([-1.0, 1.0]) @ right.cmap.T, (0, 0))  # α's zero hanging, not upright
    finding = _finding(model, system)
    assert set(finding.details["traps"]) == {SIGN, HALF}
    assert _every_check_passes(model, system, finding.details)


# --- nothing claimed where no convention explains the failure --------------------------------------
def test_a_correct_model_gets_nothing():
    model, system = _setup("triple_pendulum")
    assert not _failing(model, system)
    assert coordinate_conventions(model, system, set(), diagnosis_states(model)) is None
    results = run_checks("right", model, system, sample_states(model, 30, SEED), SEED)
    assert diagnose(model, system, results) == []


class TypoInM22(DoublePendulum):
    """M[2,2] written 10 % too large: an entry typo, not a convention."""

    def mass_matrix(self, q):
        M = super().mass_matrix(q).copy()
        M[1, 1] *= 1.1
        return M


def test_an_entry_typo_is_not_blamed_on_a_convention():
    params = default_params("double_pendulum")
    model = TypoInM22(params)
    system = PinocchioSystem.for_model(DoublePendulum, urdf_for(params), params.g)
    assert "crba" in _failing(model, system)
    assert _finding(model, system) is None
    results = run_checks("typo", model, system, sample_states(model, 30, SEED), SEED)
    assert all(f.kind != "convention" for f in diagnose(model, system, results))


def test_an_inertia_about_the_pivot_alone_is_left_to_the_inertia_trap():
    # the simplest explanation changes no map: the conventions name nothing, the inertia trap names it
    model, system = _setup("triple_pendulum", lambda p: p.replace(I3=p.I3 + p.m3 * p.r3**2))
    assert _finding(model, system) is None
    results = run_checks("pivot", model, system, sample_states(model, 30, SEED), SEED)
    (finding,) = diagnose(model, system, results)
    assert finding.quantity == "M" and finding.kind == "convention"
    assert finding.message.startswith("M[3,3] lacks the parallel-axis term m·r² = 0.009 kg·m² of link3")


# --- bounded work --------------------------------------------------------------------------------------
@pytest.mark.parametrize("n", [3, 4, 5, 6, 7])
def test_the_candidates_stay_within_the_budget_and_keep_every_single_trap(n):
    model = SimpleNamespace(nv=n, angular=(True,) * n)
    found = candidates(model, np.eye(n), np.zeros(n), [True] * n)
    assert len(found) <= MAX_CANDIDATES * min(1.0, 3 / n)
    flips = {c.flips for c in found if c.traps == (SIGN,)}
    shifts = {c.shifts for c in found if c.traps == (QUARTER,)}
    for i in range(n):
        assert (i,) in flips
        assert tuple(1 if j == i else 0 for j in range(n)) in shifts
    if n <= 3:  # every combination: each non-empty set of flips, each pattern of k ∈ {0, 1, 3} but none
        assert len(flips) == 2**n - 1
        assert len(shifts) == 3**n - 1


def test_forty_coordinates_are_screened_only_alike_and_said_so():
    n = 40
    model = SimpleNamespace(nv=n, angular=(True,) * n)
    assert most_touched(model, np.zeros(n)) == 0  # even one coordinate at a time is beyond the budget
    found = candidates(model, np.eye(n), np.zeros(n), [True] * n)
    assert len(found) <= MAX_CANDIDATES * 3 / n
    assert {c.flips for c in found} == {(), tuple(range(n))}
    assert {len(set(c.shifts)) for c in found} == {1}  # every angle shifted alike (or none)
    assert (
        left_out(model, 0)
        == "coordinate conventions on some of the 40 coordinates (only on all of them alike)"
    )
    assert left_out(model, n) == ""


# --- how long the search takes -------------------------------------------------------------------------
def test_search_time_for_the_triple_pendulum():
    stem, T, theta0 = TWO_TRAPS["triple pendulum: sign flip + absolute/relative"]
    model, right = _setup(stem)
    system = _planted(right, T, theta0)
    failing, states = _failing(model, system), diagnosis_states(model)
    coordinate_conventions(model, system, failing, states)  # the hand model's code generated and loaded
    start = time.perf_counter()
    finding = coordinate_conventions(model, system, failing, states)
    elapsed = time.perf_counter() - start
    print(f"\njoint convention search, triple pendulum (3 dof), two traps: {elapsed:.3f} s")
    assert finding is not None


def test_a_pivot_correction_that_leaves_no_physical_inertia_is_not_an_explanation():
    """Taking m·r² off link 1 of the reference double pendulum, whose I1 = 0.0208 kg·m² is less
    than m1·r1² = 0.0625 kg·m², leaves an inertia no body has: the correction is refused (None),
    not passed on to Pinocchio (which raised); taking it off an inertia about the pivot works."""
    params = default_params("double_pendulum")
    system = PinocchioSystem.for_params(params)
    assert params.I1 < params.m1 * params.r1**2
    assert corrected_system(system, {"link1 (joint joint1)": 1.0}) is None
    pivot = params.replace(I1=params.I1 + params.m1 * params.r1**2)
    assert corrected_system(PinocchioSystem.for_params(pivot), {"link1 (joint joint1)": 1.0}) is not None
