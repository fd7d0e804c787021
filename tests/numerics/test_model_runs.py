"""The model runs of ``pendverify.numerics.integrators.model_runs`` (RK4, backward Euler, Störmer–Verlet)
converge at their orders, report a blow-up, and refuse what they cannot integrate; the stress suite's
energy and momentum read-outs of a run (``pendverify.stress.sim_cases``)."""

from __future__ import annotations

import numpy as np
import pytest

from pendverify.analytic import DoublePendulum
from pendverify.numerics.integrators import model_runs
from pendverify.stress import sim_cases

from ..conftest import default_params


def test_integrators_converge_at_their_order():
    model = DoublePendulum(default_params("double_pendulum").replace(b1=0.0, b2=0.0))
    q0, v0 = np.array([-1.0, 0.4]), np.zeros(2)
    reference = model_runs.rk4(model, q0, v0, 0.001, 3000).q[-1]

    def error(method, h):
        traj = method(model, q0, v0, h, round(3 / h))
        assert traj.blew_up_at is None
        return np.max(np.abs(traj.q[-1] - reference))

    assert (
        3.6 < error(model_runs.stormer_verlet, 0.02) / error(model_runs.stormer_verlet, 0.01) < 4.4
    )  # order 2
    assert 12 < error(model_runs.rk4, 0.02) / error(model_runs.rk4, 0.01) < 20  # order 4
    sv = model_runs.stormer_verlet(model, q0, v0, 0.01, 300)
    E0 = sim_cases.energy(model, q0, v0)
    assert np.max(np.abs(sim_cases.energies(model, sv) - E0)) < 1e-3 * abs(E0)
    assert sim_cases.momenta(model, sv).shape == (len(sv.t), 2)


def test_rk4_reports_a_blow_up_and_backward_euler_does_not():
    model = DoublePendulum(default_params("double_pendulum").replace(b1=1e4, b2=1e4))
    q0, v0 = np.array([-1.0, 0.3]), np.zeros(2)
    blown = model_runs.rk4(model, q0, v0, 0.05, 50)
    assert blown.blew_up_at is not None and blown.note.startswith("non-finite after")
    stable = model_runs.implicit_euler(model, q0, v0, 0.05, 20)
    assert stable.blew_up_at is None
    assert np.all(np.diff(sim_cases.energies(model, stable)) <= 0)


def test_stormer_verlet_refuses_damped_models():
    with pytest.raises(ValueError, match="conservative models only"):
        model_runs.stormer_verlet(
            DoublePendulum(default_params("double_pendulum")), np.zeros(2), np.zeros(2), 0.1, 1
        )


def test_fit_slope():
    t = np.linspace(0, 10, 11)
    slope, r2 = sim_cases.fit_slope(t, 3 * t + 1)
    assert slope == pytest.approx(3.0) and r2 == pytest.approx(1.0)
