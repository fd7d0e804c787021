"""A scene run on the fast path: the compiled DOP853 of the model's generated back ends, with invariants.

``simulate_compiled(scene)`` integrates any scene whose effects compile (τ = B (u0 − K x) − D q̇
plus a sine input and seeded noise, ``pendverify.numerics.forcing``;
``GeneratedSystem.from_dynamics`` refuses the others with a ``FastPathError``) at the
scene's rtol and atol, samples it at the scene's rate and checks the scene's invariants
(``pendverify.simulation.invariants``) on the accepted steps, with E, ∇E and the energy
scale from the model's generated functions on all steps at once
(``pendverify.numerics.energies``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.errors import FastPathError
from pendverify.numerics.energies import GeneratedEnergies
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators.dop853_runner import FastResult, integrate
from pendverify.simulation.dynamics import build_dynamics
from pendverify.simulation.invariants import adaptive_bound, energy_scale, evaluate


@dataclass
class FastRun:
    """A scene run on the fast path: samples, the integrator's own steps and the invariant results."""

    scene: object
    dynamics: object
    system: GeneratedSystem
    result: FastResult
    t: np.ndarray
    x: np.ndarray  # samples (q, q̇, W_in, W_diss)
    invariants: list

    @property
    def passed(self) -> bool:
        return all(i.passed for i in self.invariants)


def compile_scene(scene):
    """(the scene's closed-form ``Dynamics``, its ``GeneratedSystem``), or a FastPathError naming the key.

    A model whose closed forms SymPy cannot read raises a ``PendverifyError`` here too."""
    if not scene.integrator.adaptive:
        raise FastPathError(
            scene.source, "integrator.method", scene.integrator.method, "an adaptive method (rtol, atol)"
        )
    dyn = build_dynamics(scene, "closed_form")
    return dyn, GeneratedSystem.from_dynamics(dyn, scene.source)


def simulate_compiled(scene, compiled=None) -> FastRun:
    """Run a scene with the compiled DOP853 (at the scene's rtol, atol) and check its invariants.

    Any model a scene names, seed or plug-in file: its module is generated on first use.
    ``compiled``: what ``compile_scene(scene)`` returned, if the caller has it already.

    The invariants are ``pendverify.simulation.invariants``' — the energy drift, dissipation
    or work–energy balance with the bound an adaptive method's tolerance implies —
    evaluated on the fast path's accepted steps, with the model's generated E, M q̇ and T
    (``GeneratedEnergies``; the per-state closed form where the generated energy is missing).
    """
    dyn, system = compiled or compile_scene(scene)
    x0 = np.concatenate([scene.q0, scene.v0, [0.0, 0.0]])
    n_samples = int(np.floor(scene.duration * scene.sample_rate + 1e-9)) + 1
    t = np.arange(n_samples) / scene.sample_rate
    res = integrate(system, x0, scene.duration, scene.integrator.rtol, scene.integrator.atol, t, record=True)
    energies = GeneratedEnergies.of(dyn, system)
    scale = energy_scale(energies, res.steps_x)
    bound = adaptive_bound(energies, res.steps_x, scene.integrator, scale)
    invariants = evaluate(energies, scene, res.steps_t, res.steps_x, bound, scale)
    return FastRun(scene, dyn, system, res, t, res.dense, invariants)
