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
    sentence = (
        "diagnosis [double_pendulum:pivot]: M_urdf − M_hand is exactly the parallel-axis term m·r² of "
        "link1 (joint joint1), link2 (joint joint2) (m·r² = 0.0625 kg·m², 0.03872 kg·m²): inertia given "
        "about the pivot instead of the centre of mass"
    )
    assert sentence in out
    report = json.loads(out_json.read_text())
    (trap,) = [d for d in report["diagnoses"]["double_pendulum:pivot"] if d["kind"] == "convention"]
    assert "inertia given about the pivot" in trap["message"]


class PivotCountedTwice(DoublePendulum):
    """I2 is already about joint 2, yet m2·r2² is added again."""

    @property
    def alpha(self):
        return super().alpha + self.params.m2 * self.params.r2**2

    @property
    def delta(self):
        return super().delta + self.params.m2 * self.params.r2**2


def test_hand_model_adding_m_r2_twice_is_named():
    params = default_params("double_pendulum")
    (sentence,) = _diagnoses(PivotCountedTwice(params), _dp_system(params))
    assert sentence.startswith(
        "M_hand − M_urdf is exactly the parallel-axis term m·r² of link2 (joint joint2)"
    )
    assert "counted twice" in sentence


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
