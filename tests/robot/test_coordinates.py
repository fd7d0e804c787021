"""The coordinate map: absolute vs relative angles, offsets, continuous joints."""

from __future__ import annotations

import numpy as np

from pendverify.analytic import CartDoublePendulum
from pendverify.robot.coordinates import CoordinateMap

from ..conftest import assert_close, default_params, system_for

RNG = np.random.default_rng(7)
T_CART = np.array([[1.0, 0, 0], [0, 1, 0], [0, -1, 1]])


def test_cart_uses_relative_second_joint():
    system = system_for(default_params("cart_double_pendulum"))
    assert_close(system.cmap.T, T_CART, 0)
    theta = np.array([0.3, 0.2, -0.5])
    assert_close(system.cmap.configuration(theta), [0.3, 0.2, -0.7], 1e-15)


def test_transforms_preserve_power_and_energy():
    cmap = CoordinateMap(T_CART, np.array([0.0, 0.1, -0.2]), (1, 1, 1))
    A = RNG.normal(size=(3, 3))
    M_q = A @ A.T + 3 * np.eye(3)
    thetadot, tau_theta = RNG.normal(size=3), RNG.normal(size=3)
    v = cmap.velocity(thetadot)
    # kinetic energy is the same in both coordinates
    assert_close(thetadot @ cmap.matrix_to_model(M_q) @ thetadot, v @ M_q @ v, 1e-14)
    # power is the same
    assert_close(cmap.force_to_joints(tau_theta) @ v, tau_theta @ thetadot, 1e-14)
    assert_close(cmap.force_to_model(cmap.force_to_joints(tau_theta)), tau_theta, 1e-14)
    # the inverse maps to the inverse
    assert_close(cmap.inverse_to_model(np.linalg.inv(M_q)), np.linalg.inv(cmap.matrix_to_model(M_q)), 1e-13)
    assert_close(cmap.det_factor * np.linalg.det(M_q), np.linalg.det(cmap.matrix_to_model(M_q)), 1e-13)
    # accelerations: q̈ = T θ̈
    a_theta = RNG.normal(size=3)
    assert_close(cmap.acceleration_to_model(cmap.T @ a_theta), a_theta, 1e-14)
    # states: θ → q → θ
    theta = RNG.normal(size=3)
    assert_close(cmap.T_inv @ cmap.joint_positions(theta) + cmap.theta0, theta, 1e-15)


def test_continuous_joints_get_cos_sin():
    cmap = CoordinateMap(np.eye(2), np.array([np.pi / 2, 0.0]), (2, 1))
    assert_close(cmap.configuration(np.array([np.pi / 2 + 0.3, 1.0])), [np.cos(0.3), np.sin(0.3), 1.0], 1e-15)


def test_cart_mass_matrix_is_the_kinetic_energy_hessian():
    """M's third row (lost in the source derivation) equals ∂²K/∂ẏ² of the cart's kinetic energy."""
    model = CartDoublePendulum(default_params("cart_double_pendulum"))
    p = model.params
    y = np.array([0.4, 0.9, -1.3])

    def kinetic(yd):
        _, t1, t2 = y
        v0 = np.array([yd[0], 0.0])
        v1 = v0 + p.l1 * yd[1] * np.array([np.cos(t1), -np.sin(t1)])
        v2 = v1 + p.l2 * yd[2] * np.array([np.cos(t2), -np.sin(t2)])
        return 0.5 * (p.m * v0 @ v0 + p.m1 * v1 @ v1 + p.m2 * v2 @ v2)

    # K is quadratic in ẏ: M_ij = K(e_i + e_j) − K(e_i) − K(e_j) exactly
    E = np.eye(3)
    hessian = np.array(
        [[kinetic(E[i] + E[j]) - kinetic(E[i]) - kinetic(E[j]) for j in range(3)] for i in range(3)]
    )
    np.fill_diagonal(hessian, [2 * kinetic(E[i]) for i in range(3)])
    assert_close(model.mass_matrix(y), hessian, 1e-14)
