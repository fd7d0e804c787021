"""The battery's simulations on the fast path: energies on all steps at once, the engine recorded,
recheck reproducing it, and planted errors in the closed form still caught by an invariant."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pendverify.numerics import fast_scene
from pendverify.numerics.energies import GeneratedEnergies
from pendverify.simulation import invariants
from pendverify.simulation.scene import load_scene

REPO = Path(__file__).resolve().parents[1]
ENERGY_RTOL = 1e-12  # the same closed forms, read by SymPy and summed in another order


@pytest.mark.parametrize("name", ["damped_double_pendulum", "cart_rods_falling", "furuta_arm_turning"])
def test_generated_energies_are_the_closed_forms(name):
    run = fast_scene.simulate(load_scene(REPO / "scenes" / f"{name}.toml"))
    xs = run.result.steps_x
    fast = GeneratedEnergies.of(run.dynamics, run.system)
    slow = invariants.Energies(run.dynamics)
    assert isinstance(fast, GeneratedEnergies)
    n = run.dynamics.nv
    Q, V = xs[:, :n], xs[:, n : 2 * n]
    scale = invariants.energy_scale(slow, xs)
    for what in ("energy", "kinetic"):
        error = np.max(np.abs(getattr(fast, what)(Q, V) - getattr(slow, what)(Q, V)))
        assert error <= ENERGY_RTOL * scale, (what, error, scale)
    momentum = np.abs(fast.momentum(Q, V) - slow.momentum(Q, V))
    assert np.all(momentum <= ENERGY_RTOL * (1 + np.abs(slow.momentum(Q, V)))), momentum.max()
    bound_fast = invariants.adaptive_bound(fast, xs, run.scene.integrator, scale)
    bound_slow = invariants.adaptive_bound(slow, xs, run.scene.integrator, scale)
    assert np.allclose(bound_fast, bound_slow, rtol=1e-6, atol=0.0)  # ∇E by differences: ≈ 1e-9
