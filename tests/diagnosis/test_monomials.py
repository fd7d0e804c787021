"""A pattern's coefficients written as products of the parameters (``pendverify.diagnosis.monomials``).

Each test plants a known difference in the reference double pendulum's H[1] and reads the pattern
finding: a planted −2·g·l1·m2·cos θ1 is written so; a coefficient no product fits, or one two
products fit (l1 = 2·r1 in the reference parameters), keeps its number.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from pendverify.analytic import CartDoublePendulum, DoublePendulum
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.monomials import coefficient_dimension, written_coefficient
from pendverify.robot.system import PinocchioSystem

from ..conftest import SEED, default_params


class DoubledTerm(DoublePendulum):
    """H[1] with g·l1·m2·cos θ1 of the wrong sign: hand − Pinocchio = −2·g·l1·m2·cos θ1."""

    def gravity(self, q):
        H = np.array(super().gravity(q), dtype=object)
        p = self.params
        H[0] = H[0] - 2 * p.g * p.l1 * p.m2 * self.math.cos(q[0])
        return H


class OddNumber(DoublePendulum):
    """H[1] off by 0.1234567·cos θ1, which no product of the parameters is."""

    def gravity(self, q):
        H = np.array(super().gravity(q), dtype=object)
        H[0] = H[0] - 0.1234567 * self.math.cos(q[0])
        return H


def _h1_pattern(cls, params):
    system = PinocchioSystem.for_params(params)
    model = cls(params)
    states = sample_states(model, 30, SEED)
    batch = CheckBatch(model, system, states)
    results = run_checks("t", model, system, states, SEED, applicable_checks(model, system), batch)
    assert not all(r.passed for r in results)
    (pattern,) = [f for f in explain(batch, results) if f.kind == "pattern" and f.quantity == "H"]
    return pattern


#: the reference parameters with lengths in no simple ratio (m1 = 1 kg kept: units tell m1·m2 from m2)
GENERIC = {"l1": 0.53, "r1": 0.27, "r2": 0.23, "l2": 0.47}


def test_a_planted_doubled_term_is_written_as_its_product_of_parameters():
    params = default_params("double_pendulum").replace(**GENERIC)
    assert params.m1 == 1.0
    pattern = _h1_pattern(DoubledTerm, params)
    assert "H[1]: hand − Pinocchio = −2·g·l1·m2·cos(theta1) (1 term, residual" in pattern.message
    assert pattern.details["coefficients"] == ["2·g·l1·m2"]
    assert pattern.details["terms"][0][0] == pytest.approx(-2 * params.g * params.l1 * params.m2, rel=1e-12)


def test_a_coefficient_no_product_fits_stays_a_number():
    params = default_params("double_pendulum").replace(**GENERIC)
    pattern = _h1_pattern(OddNumber, params)
    assert "H[1]: hand − Pinocchio = −0.123457·cos(theta1) (1 term" in pattern.message
    assert "coefficients" not in pattern.details


def test_a_coefficient_two_products_fit_stays_a_number():
    """The reference lengths: l1 = 0.5 = 2·r1, so 2·g·l1·m2 = 4·g·m2·r1 — the values cannot say which."""
    params = default_params("double_pendulum")
    assert params.l1 == 2 * params.r1
    pattern = _h1_pattern(DoubledTerm, params)
    assert "H[1]: hand − Pinocchio = −7.848·cos(theta1) (1 term" in pattern.message


def test_the_coefficients_units_follow_the_coordinates():
    """The cart double pendulum: x a length, θ1 and θ2 angles; dimensions in (kg, m, s)."""
    model = CartDoublePendulum(default_params("cart_double_pendulum"))
    x, t1, _ = model.coordinates
    dx, dt1 = sp.Symbol(f"d{x}"), sp.Symbol(f"d{t1}")
    assert coefficient_dimension("M", (0, 0), 1, model) == (1, 0, 0)  # kg
    assert coefficient_dimension("M", (0, 1), 1, model) == (1, 1, 0)  # kg·m
    assert coefficient_dimension("M", (1, 2), 1, model) == (1, 2, 0)  # kg·m²
    assert coefficient_dimension("H", (0,), 1, model) == (1, 1, -2)  # N
    assert coefficient_dimension("H", (1,), 1, model) == (1, 2, -2)  # N·m
    assert coefficient_dimension("Cqdot", (0,), dt1**2, model) == (1, 1, 0)  # as m·l: N per (rad/s)²
    assert coefficient_dimension("Cqdot", (0,), dx, model) is None  # friction: no fixed unit
    assert coefficient_dimension("C", (0, 1), dt1, model) == (1, 1, 0)
    assert coefficient_dimension("C", (0, 0), 1, model) is None


def test_a_coefficient_is_matched_in_its_units_only_and_exactly():
    mass, length = ("m", 1.0, (1, 0, 0)), ("l", 2.0, (0, 1, 0))
    assert written_coefficient(4.0, 0.0, (1, 2, 0), (mass, length)) == "l²·m"  # not 4·m: kg, not kg·m²
    assert written_coefficient(4.0 * (1 + 1e-9), 0.0, (1, 2, 0), (mass, length)) is None  # beyond rounding
    assert written_coefficient(4.0 * (1 + 1e-9), 1e-8, (1, 2, 0), (mass, length)) == "l²·m"  # a looser fit
    assert written_coefficient(1e300, 0.0, (1, 2, 0), (mass, length)) is None  # no product, no overflow
    assert written_coefficient(3.0, 0.0, (1, 2, 0), (mass, length)) == "3·l²·m/4"
