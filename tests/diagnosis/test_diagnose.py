"""Diagnoses: each known trap is planted, and the report names it in words.

Every test plants exactly one error and asserts the sentence; a failure that
matches no trap gets no diagnosis, and a passing model none at all.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import CartDoublePendulum, DoublePendulum
from pendverify.checks.catalogue import run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.diagnosis.diagnose import diagnose
from pendverify.diagnosis.traps.inertia import SIDE_MARGIN, turning_axes
from pendverify.robot.coordinates import CoordinateMap
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for

from ..conftest import SEED, default_params

REPO = Path(__file__).resolve().parents[2]


def _diagnoses(model, system, planted: bool = True):
    results = run_checks("planted", model, system, sample_states(model, 30, SEED), SEED)
    assert all(r.passed for r in results) is not planted, "a planted error must fail, the seed pass"
    return [finding.message for finding in diagnose(model, system, results)]


def _dp_system(params):
    return PinocchioSystem.for_model(DoublePendulum, urdf_for(params), params.g)


# --- inertia about the pivot -----------------------------------------------------------------
def test_urdf_inertia_about_the_pivot_is_named_in_the_report(tmp_path, capsys):
    params = default_params("double_pendulum")
    pivot = params.replace(I1=params.I1 + params.m1 * params.r1**2, I2=params.I2 + params.m2 * params.r2**2)
    urdf, toml, out_json = tmp_path / "pivot.urdf", tmp_path / "params.toml", tmp_path / "r.json"
    urdf.write_text(urdf_for(pivot))
    toml.write_text(params.to_toml())
    assert (
        main(
            ["check", "--urdf", str(urdf), "--params", str(toml), "--samples", "20", "--json", str(out_json)]
        )
        == 1
    )
    out = capsys.readouterr().out
    both = "your M misses the parallel-axis term, or the URDF's <inertia> of {} is about the pivot"
    sentence = (
        "diagnosis [double_pendulum:pivot]: M[1,1] lacks the parallel-axis term m·r² = 0.0625 kg·m² of "
        "link1 (joint joint1) (M_urdf − M_hand is exactly that term): " + both.format("link1")
    )
    assert sentence in out
    link2 = "M[1,1], M[1,2], M[2,2] lack the parallel-axis term m·r² = 0.03872 kg·m² of link2 (joint joint2)"
    assert link2 in out
    assert both.format("link2") in out
    report = json.loads(out_json.read_text())
    (trap,) = [d for d in report["diagnoses"]["double_pendulum:pivot"] if d["kind"] == "convention"]
    assert both.format("link1") in trap["message"]


class ParallelAxisMissing(DoublePendulum):
    """M without link 2's m2·r2²: I2 used where the inertia about joint 2 is due."""

    @property
    def alpha(self):
        return super().alpha - self.params.m2 * self.params.r2**2

    @property
    def delta(self):
        return super().delta - self.params.m2 * self.params.r2**2


BOTH_SIDES = "your M misses the parallel-axis term, or the URDF's <inertia> of link2 is about the pivot"


def test_a_missing_parallel_axis_term_and_a_urdf_inertia_about_the_pivot_get_the_same_two_sided_words():
    """The two situations M cannot tell apart: the hand's M lacks m2·r2² against a right URDF, and a
    right hand model against a URDF whose <inertia> of link 2 is about the pivot.  Link 2 is wide
    (I2 = 0.05 kg·m² > m2·r2² = 0.0387 kg·m²), so the URDF's inertia can be about the pivot."""
    params = default_params("double_pendulum").replace(I2=0.05)
    (hand_wrong,) = _diagnoses(ParallelAxisMissing(params), _dp_system(params))
    pivot = params.replace(I2=params.I2 + params.m2 * params.r2**2)
    (urdf_wrong,) = _diagnoses(DoublePendulum(params), _dp_system(pivot))
    assert hand_wrong == urdf_wrong
    assert hand_wrong.startswith(
        "M[1,1], M[1,2], M[2,2] lack the parallel-axis term m·r² = 0.03872 kg·m² of link2 (joint joint2) "
        "(M_urdf − M_hand is exactly that term): " + BOTH_SIDES
    )


def test_a_urdf_inertia_about_the_pivot_of_a_rod_keeps_both_sides():
    """The reference rods (I2 = 0.0135 < m2·r2²): with the pivot inertia really in the URDF, the
    centre-of-mass inertia it implies is I2 itself, a possible one: both sides are named."""
    params = default_params("double_pendulum")
    pivot = params.replace(I2=params.I2 + params.m2 * params.r2**2)
    (sentence,) = _diagnoses(DoublePendulum(params), _dp_system(pivot))
    assert BOTH_SIDES in sentence


def test_a_rod_whose_urdf_inertia_cannot_be_about_the_pivot_names_the_hand_model_alone():
    """The reference rods against their right URDF: read as about the pivot, link 2's <inertia>
    (0.0135 kg·m²) would leave it 0.0135 − 0.03872 = −0.02522 kg·m² about its centre of mass, which
    no body has: only the hand model can be wrong."""
    params = default_params("double_pendulum")
    (sentence,) = _diagnoses(ParallelAxisMissing(params), _dp_system(params))
    assert sentence.endswith(
        ": your M misses the parallel-axis term (the URDF's <inertia> of link2 cannot be about the pivot: "
        "about the centre of mass it would leave link2 a moment of inertia of -0.02522 kg·m² about the axis "
        "it turns about, and no body has one below zero)"
    )
    assert "or the URDF" not in sentence


@pytest.mark.parametrize("ratio", [1.0, 1.0 - SIDE_MARGIN / 2])
def test_a_body_on_the_boundary_keeps_both_sides(ratio):
    """A hoop hung from its rim: I_c = m·r², so the URDF's inertia read about the pivot leaves zero
    about the centre of mass, a limit a body reaches; within the rounding margin below it too."""
    params = default_params("double_pendulum")
    params = params.replace(I2=ratio * params.m2 * params.r2**2)
    (sentence,) = _diagnoses(ParallelAxisMissing(params), _dp_system(params))
    assert BOTH_SIDES in sentence


def test_a_planar_link_turns_about_its_joint_axis_alone():
    system = _dp_system(default_params("double_pendulum"))
    axes = turning_axes(system.model, 2)
    assert axes.shape == (3, 1)
    assert np.allclose(np.abs(axes[:, 0]), [1.0, 0.0, 0.0])  # the URDF's joint axis: x


class PivotCountedTwice(DoublePendulum):
    """I2 is already about joint 2, yet m2·r2² is added again."""

    @property
    def alpha(self):
        return super().alpha + self.params.m2 * self.params.r2**2

    @property
    def delta(self):
        return super().delta + self.params.m2 * self.params.r2**2


def test_hand_model_adding_m_r2_twice_is_named_with_both_sides():
    params = default_params("double_pendulum")
    (sentence,) = _diagnoses(PivotCountedTwice(params), _dp_system(params))
    assert sentence == (
        "M[1,1], M[1,2], M[2,2] have the parallel-axis term m·r² = 0.03872 kg·m² of link2 (joint joint2) "
        "too many (M_hand − M_urdf is exactly that term): your M adds the parallel-axis term to an inertia "
        "already about the pivot (counted twice), or the URDF's <inertia> of link2 is m·r² short (the term "
        "taken off an inertia already about the centre of mass)"
    )


# --- absolute vs relative angles -------------------------------------------------------------
def test_absolute_angles_against_a_relative_map_are_named():
    params = default_params("cart_double_pendulum")
    right = PinocchioSystem.for_model(CartDoublePendulum, urdf_for(params), params.g)
    identity = CoordinateMap(np.eye(3), np.zeros(3), right.cmap.joint_nq)  # forgot: joint 2 is relative
    wrong = PinocchioSystem(
        right.model.copy(), dataclasses.replace(right.geometry, cmap=identity), params.g, "x"
    )
    (sentence,) = _diagnoses(CartDoublePendulum(params), wrong)
    assert sentence.startswith(
        "absolute vs relative angles: the hand model's angles are absolute (all from one reference) where "
        "the coordinate map takes them as relative"
    )
    assert "T → T·A = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 1.0]], every check passes" in sentence


# --- a missing damping term ------------------------------------------------------------------
class FrictionMissing(DoublePendulum):
    def seed_coriolis_matrix(self, q, v):
        return super().seed_coriolis_matrix(q, v) - self.damping_matrix()


def test_missing_damping_is_named():
    params = default_params("double_pendulum")
    (sentence,) = _diagnoses(FrictionMissing(params), _dp_system(params))
    assert sentence == (
        "a missing damping term: M·(q̈_hand − q̈_pin) = D·q̇ exactly (0.05·dtheta1/dt on theta1, "
        "0.03·dtheta2/dt on theta2): the hand model's q̈ leaves out the friction −D·q̇ that "
        "damping_matrix() declares"
    )


# --- degrees vs radians ----------------------------------------------------------------------
def test_offsets_in_degrees_are_named(tmp_path, capsys):
    source = (REPO / "examples" / "hanging_double_pendulum.py").read_text()
    wrong = source.replace("joint_offset = (math.pi / 2, math.pi / 2)", "joint_offset = (90.0, 90.0)")
    assert wrong != source
    model_file = tmp_path / "degrees.py"
    model_file.write_text(wrong)
    examples = REPO / "examples"
    argv = [
        "check",
        "--analytic",
        str(model_file),
        "--urdf",
        str(examples / "hanging_double_pendulum.urdf"),
        "--params",
        str(examples / "hanging_double_pendulum.toml"),
        "--samples",
        "20",
    ]
    assert main(argv) == 1
    out = capsys.readouterr().out
    assert (
        "degrees vs radians: the offsets θ0 = (90, 90) look like degrees; read as degrees, "
        "θ0 = (1.5708, 1.5708) rad, and every check passes"
    ) in out


# --- an angle measured from the vertical instead of the horizontal -----------------------------
class FromVertical(DoublePendulum):
    """θ1 measured from the upward vertical: every formula sees θ1 + π/2 where the seed has θ1."""

    shift = np.array([math.pi / 2, 0.0])

    def mass_matrix(self, q):
        return super().mass_matrix(q + self.shift)

    def seed_coriolis_matrix(self, q, v):
        return super().seed_coriolis_matrix(q + self.shift, v)

    def gravity(self, q):
        return super().gravity(q + self.shift)

    def potential_energy(self, q):
        return super().potential_energy(q + self.shift)

    def det_mass_matrix(self, q):
        return super().det_mass_matrix(q + self.shift)

    def inverse_mass_matrix(self, q):
        return super().inverse_mass_matrix(q + self.shift)


def test_vertical_instead_of_horizontal_zero_is_named():
    params = default_params("double_pendulum")
    (sentence,) = _diagnoses(FromVertical(params), _dp_system(params))
    assert sentence.startswith(
        "vertical vs horizontal zero: theta1 is measured from the vertical where the map measures from the "
        "horizontal, or the reverse; with θ0 shifted by −π/2 on theta1 every check passes "
        "(an exact fit: residual "
    )


# --- no diagnosis without a matching trap ----------------------------------------------------
class BetaOff(DoublePendulum):
    @property
    def beta(self):
        return super().beta * (1 + 1e-6)


@pytest.mark.parametrize(("cls", "planted"), [(BetaOff, True), (DoublePendulum, False)])
def test_no_diagnosis_without_a_known_trap(cls, planted):
    params = default_params("double_pendulum")
    assert _diagnoses(cls(params), _dp_system(params), planted) == []
