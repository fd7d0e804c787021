"""Property-based tests: identities that must hold for any valid parameters and state.

Parameters are drawn log-uniformly (masses 1e-3…1e3 kg, so ratios up to 1e6;
lengths 0.1…10 m; inertias as m·(k·l)² with k 1e-2…0.5; damping 1e-3…10),
states uniformly (angles ±10 rad, cart ±1 m, rates ±10, forces of up to 10
times the inertia scale).  ``derandomize=True`` makes every run draw the same
examples (reproducible in CI); ``deadline=None`` because building a Pinocchio
model takes a variable millisecond.

Tolerances follow the suite's scheme: K·ε·((1 + |θ|max) + (A − 1)) times the
size of the terms involved (A is Pinocchio's term amplification,
``pendverify.checks.trust``).  Residuals (rnea(aba(τ)) − τ, the power balance)
need no κ̃(M); a forward error (aba(rnea(a)) − a) is measured against ‖M̃⁻¹‖
times the terms, and M⁻¹·M − I against ‖M̃⁻¹‖·‖M̃‖.  Measured over 300 random
examples, the largest error is about a tenth of its tolerance.  States the trust
rule refuses are skipped (``assume``), as the suite would refuse them.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from pendverify.analytic import (
    CartDoublePendulum,
    CartDoublePendulumParams,
    DoublePendulum,
    DoublePendulumParams,
)
from pendverify.checks.trust import EPS, assess
from pendverify.robot.system import PinocchioSystem

K = 16
SETTINGS = settings(
    derandomize=True,
    deadline=None,
    max_examples=60,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)


def log_uniform(lo: float, hi: float):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


mass, length, damping = log_uniform(1e-3, 1e3), log_uniform(0.1, 10.0), log_uniform(1e-3, 10.0)
fraction = st.floats(0.0, 1.0)
gyration = log_uniform(1e-2, 0.5)


@st.composite
def double_pendulum(draw):
    m1, m2, l1, l2 = draw(mass), draw(mass), draw(length), draw(length)
    return DoublePendulumParams(
        m1=m1,
        m2=m2,
        l1=l1,
        l2=l2,
        r1=draw(fraction) * l1,
        r2=draw(st.floats(0.05, 1.0)) * l2,
        I1=m1 * (draw(gyration) * l1) ** 2,
        I2=m2 * (draw(gyration) * l2) ** 2,
        b1=draw(damping),
        b2=draw(damping),
        g=draw(st.sampled_from([0.0, 1.62, 9.81])),
    )


@st.composite
def cart(draw):
    return CartDoublePendulumParams(
        m=draw(mass),
        m1=draw(mass),
        m2=draw(mass),
        l1=draw(length),
        l2=draw(length),
        d1=draw(damping),
        d2=draw(damping),
        d3=draw(damping),
        g=draw(st.sampled_from([0.0, 1.62, 9.81])),
    )


@st.composite
def case(draw):
    """(model, system, q, v, u, w, verdict) for a drawn parameter set and state."""
    params = draw(st.one_of(double_pendulum(), cart()))
    model = (DoublePendulum if isinstance(params, DoublePendulumParams) else CartDoublePendulum)(params)
    system = PinocchioSystem.for_params(params)
    angular = np.array(model.angular)
    unit = st.floats(-1.0, 1.0)
    q = np.array([draw(unit) for _ in angular]) * np.where(angular, 10.0, 1.0)
    v = np.array([draw(unit) for _ in angular]) * 10.0
    S0 = model.diagonal_scale(np.zeros(model.nv))
    u = np.array([draw(unit) for _ in model.inputs]) * 10 * float(np.max(np.abs(model.input_matrix()).T @ S0))
    w = np.array([draw(unit) * 10 * S0[i] for i in range(len(model.disturbances))])
    verdict = assess(model, q, system)
    assume(verdict.level != "refuse")
    return model, system, q, v, u, w, verdict


def rounding(model, q, verdict) -> float:
    """K·ε·((1 + |θ|max) + (A − 1)): the relative rounding of one evaluation."""
    angle = float(np.max(np.abs(q[np.array(model.angular)]), initial=0.0))
    return K * EPS * ((1.0 + angle) + (verdict.amplification - 1.0))


def scaled(model, q):
    """w = S^{-½}: multiply forces by w, divide accelerations by w."""
    return 1.0 / np.sqrt(model.diagonal_scale(q))


def relative(error: float, size: float) -> float:
    """error / size, with 0/0 = 0 (everything zero, e.g. at rest with g = 0) and x/0 = inf."""
    if error == 0:
        return 0.0
    return error / size if size > 0 else math.inf


def joint_state(system, q, v):
    return system.cmap.configuration(q), system.cmap.velocity(v)


@SETTINGS
@given(case())
def test_mass_matrix_is_symmetric_positive_definite(c):
    model, system, q, *_ = c
    for label, M in (("closed form", model.mass_matrix(q)), ("crba", system.mass_matrix(q))):
        assert np.array_equal(M, M.T), f"{label} M not symmetric, {model.params}"
        np.linalg.cholesky(M)  # raises LinAlgError unless positive definite


@SETTINGS
@given(case())
def test_aba_and_rnea_invert_each_other(c):
    model, system, q, v, u, w, verdict = c
    qj, vj = joint_state(system, q, v)
    tau = model.input_matrix() @ u + model.disturbance_matrix() @ w - model.damping_matrix() @ v
    tau_j = system.cmap.force_to_joints(tau)
    a_j = pin.aba(system.model, system.data, qj, vj, tau_j)
    back = system.cmap.force_to_model(pin.rnea(system.model, system.data, qj, vj, a_j))
    # and the other way: rnea of an acceleration, then aba
    a = system.cmap.acceleration_to_model(a_j)
    wgt = scaled(model, q)
    Mt = model.mass_matrix(q) * np.outer(wgt, wgt)
    bias = system.bias(q, v)
    terms = (
        np.max(np.abs(wgt * tau))
        + np.max(np.abs(wgt * bias))
        + np.linalg.norm(Mt, 2) * np.max(np.abs(a / wgt))
    )
    err_tau = relative(np.max(np.abs(wgt * (back - tau))), terms)
    tol = rounding(model, q, verdict)  # residuals: no κ̃ (the a-error is measured against ‖M̃⁻¹‖)
    assert err_tau <= tol, f"rnea(aba(τ)) − τ: {err_tau:.3g} > {tol:.3g}, {model.params}, q={q}"
    a2 = system.acceleration(q, v, back)
    err_a = relative(np.max(np.abs((a2 - a) / wgt)), np.linalg.norm(np.linalg.inv(Mt), 2) * terms)
    assert err_a <= tol, f"aba(rnea(a)) − a: {err_a:.3g} > {tol:.3g}, {model.params}, q={q}"


@SETTINGS
@given(case())
def test_minverse_times_crba_is_identity(c):
    model, system, q, *_, verdict = c
    root = np.sqrt(model.diagonal_scale(q))
    X = system.inverse_mass_matrix(q) * np.outer(root, root)  # S^½ M⁻¹ S^½
    M = system.mass_matrix(q) / np.outer(root, root)  # S^-½ M S^-½
    err = np.max(np.abs(X @ M - np.eye(model.nv)))
    tol = rounding(model, q, verdict) * np.linalg.norm(X, 2) * np.linalg.norm(M, 2)
    assert err <= tol, f"computeMinverse·crba − I: {err:.3g} > {tol:.3g}, {model.params}, q={q}"


@SETTINGS
@given(case(), st.sampled_from(["closed form", "pinocchio"]))
def test_energy_rate_is_input_power_minus_friction(c, source):
    """dE/dt = ∂E/∂q·q̇ + ∂E/∂q̇·q̈ = ½q̇ᵀṀq̇ + q̇ᵀH + q̇ᵀMq̈ must equal q̇ᵀ(Bu + Ww) − q̇ᵀDq̇."""
    model, system, q, v, u, w, verdict = c
    applied = model.input_matrix() @ u + model.disturbance_matrix() @ w
    D = model.damping_matrix()
    if source == "closed form":
        M, H, a = model.mass_matrix(q), model.gravity(q), model.acceleration(q, v, u, w)
        C = model.coriolis_matrix(q, v)
        Mdot = C + C.T  # the Christoffel C (the skew check holds this to ε)
    else:
        M, H, Mdot = system.mass_matrix(q), system.gravity(q), system.mass_matrix_derivative(q, v)
        a = system.acceleration(q, v, applied - D @ v)
    rate = v @ M @ a + 0.5 * v @ Mdot @ v + v @ H
    power = v @ applied - v @ D @ v
    av = np.abs(v)
    terms = av @ np.abs(M) @ np.abs(a) + 0.5 * av @ np.abs(Mdot) @ av + av @ np.abs(H)
    terms += av @ np.abs(applied) + av @ np.abs(D) @ av
    tol = rounding(model, q, verdict) * terms  # q̇ᵀ(M q̈) is a residual of the solve: no κ̃
    assert abs(rate - power) <= tol, (
        f"{source}: dE/dt {rate:.6g} vs {power:.6g}, {model.params}, q={q}, v={v}"
    )


def test_a_wrong_energy_rate_is_caught():
    """The property can fail: a closed form with friction of the wrong sign breaks it."""

    class Pump(CartDoublePendulum):
        def f(self, y, yd, u, w):
            return super().f(y, yd, u, w) + 2 * self.damping_matrix() @ yd

    params = CartDoublePendulumParams(
        m=1.5, m1=0.5, m2=0.75, l1=0.5, l2=0.75, d1=0.1, d2=0.01, d3=0.01, g=9.81
    )
    model, system = Pump(params), PinocchioSystem.for_params(params)
    q, v = np.array([0.1, 0.4, -0.3]), np.array([0.5, 1.0, -2.0])
    c = (model, system, q, v, np.zeros(1), np.zeros(3), assess(model, q, system))
    with pytest.raises(AssertionError, match="closed form: dE/dt"):
        test_energy_rate_is_input_power_minus_friction.hypothesis.inner_test(c, "closed form")


def _default_case(model_cls=CartDoublePendulum):
    params = CartDoublePendulumParams(
        m=1.5, m1=0.5, m2=0.75, l1=0.5, l2=0.75, d1=0.1, d2=0.01, d3=0.01, g=9.81
    )
    model, system = model_cls(params), PinocchioSystem.for_params(params)
    q, v = np.array([0.1, 0.4, -0.3]), np.array([0.5, 1.0, -2.0])
    return model, system, q, v, np.array([2.0]), np.array([0.1, -0.2, 0.3]), assess(model, q, system)


def test_a_non_positive_mass_matrix_is_caught():
    class Indefinite(CartDoublePendulum):
        def mass_matrix(self, y):
            M = super().mass_matrix(y)
            M[1, 2] = M[2, 1] = 10 * M[1, 2]
            return M

    with pytest.raises(np.linalg.LinAlgError):
        test_mass_matrix_is_symmetric_positive_definite.hypothesis.inner_test(_default_case(Indefinite))


@pytest.mark.parametrize(
    ("method", "test"),
    [
        ("acceleration", test_aba_and_rnea_invert_each_other),
        ("inverse_mass_matrix", test_minverse_times_crba_is_identity),
    ],
)
def test_a_slightly_wrong_pinocchio_answer_is_caught(monkeypatch, method, test):
    real = getattr(PinocchioSystem, method)
    monkeypatch.setattr(PinocchioSystem, method, lambda self, *a: real(self, *a) * (1 + 1e-9))
    with pytest.raises(AssertionError):
        test.hypothesis.inner_test(_default_case())
