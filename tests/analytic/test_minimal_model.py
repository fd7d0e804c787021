"""A model that writes only what a hand derivation has: M, C, H, V, D, B.

``examples/minimal_double_pendulum.py`` leaves det M, M⁻¹, q̈, the special states
and the tolerance scales to the interface's derived defaults: the checks that
would compare a derived quantity with Pinocchio are not run, with the reason in
the report; ``sympy`` and ``mutate`` leave them out and say so.  The derived
tolerance scales equal the seeds' hand-written ones.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pendverify
from pendverify.analytic import MODELS, ClosedFormModel
from pendverify.analytic.derived_scales import term_bound
from pendverify.analytic.plugin import load_model_class
from pendverify.cli import main

from ..conftest import default_params

REPO = Path(__file__).resolve().parents[2]
MODEL = REPO / "examples" / "minimal_double_pendulum.py"
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
ARGS = ["--analytic", str(MODEL), "--urdf", str(URDF), "--params", str(PARAMS)]
DERIVED = {"det_mass_matrix", "inverse_mass_matrix", "acceleration", "gravity_scale", "diagonal_scale"}


def test_the_minimal_model_writes_only_the_hand_derivation():
    cls = load_model_class(MODEL)
    assert cls.hand_written() == (
        "mass_matrix",
        "coriolis_matrix",
        "gravity",
        "potential_energy",
        "damping_matrix",
        "input_matrix",
    )
    assert set(cls.written_closed_forms()).isdisjoint(DERIVED)
    # the seeds write (and keep) their own
    assert DERIVED <= set(MODELS["double_pendulum"].hand_written())
    # the cart writes its constant diagonal (to skip SymPy at run time): the derived one agrees
    cart = MODELS["cart_double_pendulum"](default_params("cart_double_pendulum"))
    assert "diagonal_scale" in cart.hand_written()
    for q in ([0.0, 0.0, 0.0], [0.3, 1.1, -2.0]):
        derived = ClosedFormModel.diagonal_scale(cart, np.array(q))
        assert np.array_equal(cart.diagonal_scale(np.array(q)), derived)


def test_the_minimal_model_passes_and_the_report_says_what_was_derived(capsys):
    assert main(["check", *ARGS, "--samples", "60"]) == 0
    out = capsys.readouterr().out
    assert "all checks pass" in out
    assert "det not run: det M is derived from M (LU), not hand-written: nothing to check" in out
    assert "minverse not run: M⁻¹ is derived from M (solving with M), not hand-written" in out
    assert "aba: q̈ is derived from the model's M, C, H, D, B, W, not hand-written" in out
    report = pendverify.check(MODEL, URDF, PARAMS, samples=60)
    assert report.passed
    checks = {r.name for r in report.results}
    assert {"units", "crba", "rnea", "gravity", "coriolis", "skew", "aba", "energy", "damping"} == checks


def test_sympy_and_mutate_pass_on_the_minimal_model(capsys):
    assert main(["sympy", "--analytic", str(MODEL)]) == 0
    out = capsys.readouterr().out
    assert "skipped [det M]: not hand-written" in out
    assert "every closed form equals its derivation" in out
    assert main(["mutate", *ARGS]) == 0
    out = capsys.readouterr().out
    derived = "det_mass_matrix, inverse_mass_matrix, acceleration"
    assert f"not mutated (derived, not hand-written): {derived}" in out
    assert "input_matrix" in out.splitlines()[-2]  # B: no Pinocchio check sees it with a derived q̈
    assert "detection rate 100.0%" in out


def test_a_planted_error_in_the_minimal_m_still_fails_crba():
    cls = load_model_class(MODEL)

    class Planted(cls):
        def mass_matrix(self, q):
            M = super().mass_matrix(q)
            return M + np.array([[0.0, 0.0], [0.0, 1e-4 * self.params.m2]])  # a stray m2·(0.01)²

    report = pendverify.check(Planted, URDF, PARAMS, samples=20)
    failed = {r.name for r in report.failures()}
    assert "crba" in failed


@pytest.mark.parametrize("name", ["double_pendulum", "cart_double_pendulum"])
def test_the_derived_gravity_scale_equals_the_seeds_hand_written_one(name):
    model = MODELS[name](default_params(name))
    derived = ClosedFormModel.gravity_scale(model)
    np.testing.assert_allclose(derived, model.gravity_scale(), rtol=1e-14, atol=0)


def test_the_derived_diagonal_scale_equals_the_double_pendulums_alpha_plus_2_beta():
    model = MODELS["double_pendulum"](default_params("double_pendulum"))
    expected = np.array([model.alpha + 2 * abs(model.beta), model.delta])
    for q in ([0.0, 0.0], [0.3, np.pi], [-2.0, 1.7]):
        np.testing.assert_allclose(ClosedFormModel.diagonal_scale(model, np.array(q)), expected, rtol=1e-14)
    # the cart seed does not write one: its constant M_ii are their own scale
    cart = MODELS["cart_double_pendulum"](default_params("cart_double_pendulum"))
    q = np.array([1.0, 0.2, -0.3])
    np.testing.assert_allclose(cart.diagonal_scale(q), np.abs(np.diag(cart.mass_matrix(q))), rtol=1e-14)


def test_term_bound_keeps_cancelling_terms_apart():
    import sympy as sp

    a, b, t = sp.symbols("a b t", positive=True)
    assert term_bound(a * sp.cos(t) - b * sp.cos(t)) == a + b
    assert term_bound(a + 2 * b * sp.cos(t) ** 2 - b * sp.sin(t)) == a + 3 * b


def test_derived_defaults_agree_with_the_seeds_closed_forms():
    model = MODELS["double_pendulum"](default_params("double_pendulum"))
    q, v, u, w = np.array([0.4, -1.2]), np.array([1.5, -0.7]), np.array([0.3, -0.2]), np.zeros(0)
    det = ClosedFormModel.det_mass_matrix(model, q)
    np.testing.assert_allclose(det, model.det_mass_matrix(q), rtol=1e-13)
    np.testing.assert_allclose(
        ClosedFormModel.inverse_mass_matrix(model, q), model.inverse_mass_matrix(q), rtol=1e-13
    )
    np.testing.assert_allclose(
        ClosedFormModel.acceleration(model, q, v, u, w), model.acceleration(q, v, u, w), rtol=1e-12
    )


EXAMPLES = ["cart_pole", "furuta_pendulum", "hanging_double_pendulum", "triple_pendulum"]


@pytest.mark.parametrize("name", EXAMPLES)
def test_the_derived_gravity_scale_equals_the_examples_hand_written_ones(name):
    from pendverify.analytic.params import load_parameter_file

    cls = load_model_class(REPO / "examples" / f"{name}.py")
    params = load_parameter_file(REPO / "examples" / f"{name}.toml", {cls.name: cls.params_type})[2]
    model = cls(params)
    derived = ClosedFormModel.gravity_scale(model)
    np.testing.assert_allclose(derived, model.gravity_scale(), rtol=1e-14, atol=0)
