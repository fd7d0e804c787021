"""The fast path's time-varying forcing: a sine input and seeded noise, compiled as sums of sinusoids.

The compiled right-hand side with forcing is the simulator's closed form at every (t, x); the
compiled DOP853 evaluates each stage at its own time (a stage at the wrong time would move the
final state by ≈ h·ω·|f|, far beyond the integrators' accuracy); the scene invariants hold on
its steps; laws that jump (step, impulse) are still refused by name.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pendverify.errors import FastPathError, PendverifyError
from pendverify.numerics.generate import GeneratedSystem
from pendverify.numerics.integrators import dop853_runner, fixedstep_runner, taylor
from pendverify.simulation import compiled_scene
from pendverify.simulation.dynamics import build_dynamics
from pendverify.simulation.scene import load_scene, parse_scene

from ..conftest import SEED, assert_close

REPO = Path(__file__).resolve().parents[2]
RHS_RTOL = 1e-12  # the same closed form, summed in another order (as tests/numerics/test_dop853_runner.py)
ACCURACY_FACTOR = 100.0  # the fast path's stated accuracy: ≤ 100 · rtol · (1 + ‖x‖∞), T ≤ 2 s

NOISY_CART = {
    "model": "cart_double_pendulum",
    "initial": {"q": [0.0, 0.3, -0.2], "v": [0.1, 0.0, 0.2]},
    "time": {"duration": 1.0, "sample_rate": 50.0},
    "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
    "effects": {
        "gravity": True,
        "damping": True,
        "actuation": {"type": "sine", "amplitude": [2.0], "frequency": 1.3, "phase": 0.4, "offset": [0.5]},
        "disturbance": {"type": "noise", "std": [0.5, 0.2, 0.1], "bandwidth": 4.0, "seed": 11},
    },
}


def _scenes():
    sine = load_scene(REPO / "scenes" / "torque_driven_double_pendulum.toml")
    return {"sine": sine, "sine+noise": parse_scene(NOISY_CART, "<noisy cart>")}


@pytest.mark.parametrize("which", ["sine", "sine+noise"])
def test_compiled_forcing_is_the_simulators_closed_form(which):
    dyn = build_dynamics(_scenes()[which], "closed_form")
    system = GeneratedSystem.from_dynamics(dyn)
    assert system.forcing and not system.conservative
    rng = np.random.default_rng(SEED)
    for _ in range(30):
        t = rng.uniform(0.0, 8.0)
        x = np.append(rng.uniform(-2, 2, 2 * dyn.nv), [0.0, 0.0])
        assert_close(system.rhs(x, t), dyn.rhs(t, x), RHS_RTOL, f"{which} {t=} {x=}")
        tau_in, _ = dyn.generalized_force(t, x[: dyn.nv], x[dyn.nv : 2 * dyn.nv])
        tau_fixed = system.B @ system.u0
        assert_close(system.forcing.at(t) + tau_fixed, tau_in, RHS_RTOL, f"{which} forcing at {t=}")


@pytest.mark.slow
@pytest.mark.parametrize("which", ["sine", "sine+noise"])
def test_each_stage_is_evaluated_at_its_own_time(which):
    """scipy's DOP853 on the compiled field fun(t, x) and the compiled DOP853 end together."""
    scene = _scenes()[which]
    system = GeneratedSystem.from_dynamics(build_dynamics(scene, "closed_form"))
    x0 = np.concatenate([scene.q0, scene.v0, [0.0, 0.0]])
    rtol = 1e-10
    ours = dop853_runner.integrate(system, x0, 1.0, rtol, rtol)
    theirs = solve_ivp(system.scipy_rhs(), (0.0, 1.0), x0, method="DOP853", rtol=rtol, atol=rtol)
    assert ours.steps == len(theirs.t) - 1 and ours.nfev == theirs.nfev
    bound = ACCURACY_FACTOR * rtol * (1 + np.max(np.abs(theirs.y[:, -1])))
    assert np.max(np.abs(ours.x - theirs.y[:, -1])) <= bound
    # the same run with every stage at t = 0 (the autonomous field) ends elsewhere by far more
    frozen = solve_ivp(lambda t, x: system.rhs(x), (0.0, 1.0), x0, method="DOP853", rtol=rtol, atol=rtol)
    assert np.max(np.abs(ours.x - frozen.y[:, -1])) > 1e3 * bound


@pytest.mark.parametrize("which", ["sine", "sine+noise"])
def test_the_work_energy_balance_holds_on_the_fast_path(which):
    run = compiled_scene.simulate_compiled(_scenes()[which])
    assert [i.name.split(" ")[0] for i in run.invariants] == ["work–energy"]
    assert run.passed, [(i.name, i.error, i.tolerance) for i in run.invariants]


@pytest.mark.parametrize(
    ("effect", "law"),
    [
        ("actuation", {"type": "step", "time": 0.2, "after": [1.0, 0.0]}),
        ("actuation", {"type": "table", "times": [0.0, 1.0], "values": [[0.0, 0.0], [1.0, 1.0]]}),
        ("disturbance", {"type": "impulse", "time": 0.5, "impulse": [0.1, 0.0, 0.0]}),
    ],
)
def test_laws_that_jump_are_refused_by_name(effect, law):
    doc = {**NOISY_CART, "effects": {"gravity": True, effect: law}}
    if effect == "actuation":
        doc["model"], doc["initial"] = "double_pendulum", {"q": [0.3, 0.2]}
    with pytest.raises(FastPathError, match=f"effects.{effect}"):
        compiled_scene.simulate_compiled(parse_scene(doc, "<jumps>"))


def test_the_time_invariant_back_ends_refuse_forcing():
    system = GeneratedSystem.from_dynamics(build_dynamics(_scenes()["sine+noise"], "closed_form"))
    with pytest.raises(PendverifyError, match="time-invariant"):
        fixedstep_runner.integrate_fixed("rk4", system, np.zeros(6), 0.1, 2)
    with pytest.raises(PendverifyError, match="time-invariant"):
        taylor.float_system(system)
