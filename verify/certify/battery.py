"""The full battery a parameter set must pass before it is certified.

1. every core check (``pendverify.checks.catalogue``) on a large seeded sample of states;
2. the stress cases that apply to any set, run on these parameters: large
   angles, high speeds, zero gravity, and the conditioning guard (a set whose
   M is too near singular to compare is refused, not certified);
3. one simulation invariant per effect: a short run with gravity alone
   (energy drift), with damping (dissipation balance, energy never rises),
   with actuation (work–energy balance) and, for the cart, with a seeded noise
   disturbance (work–energy balance).

The battery runs on the URDF being certified, whether the project wrote it or
the user brought it.  Everything is deterministic in (parameters, URDF, seed,
settings), so ``recheck`` can run it again and compare figures.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from pendverify.analytic import MODELS, ParameterSet
from pendverify.checks.catalogue import run_checks
from pendverify.checks.sampling import sample_states
from pendverify.errors import PendverifyError
from pendverify.robot.system import PinocchioSystem


@dataclass(frozen=True)
class BatterySettings:
    samples: int = 2000  # random states for the core checks
    seed: int = 20260301
    sim_duration: float = 2.0  # s, per effect
    sim_rtol: float = 1e-10

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class BatteryItem:
    name: str
    kind: str  # check | stress | invariant
    max_error: float
    tolerance: float
    samples: int
    seed: int
    passed: bool
    detail: str = ""

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def margin(self) -> float:
        """error / tolerance: below 1 passes."""
        return self.max_error / self.tolerance if self.tolerance > 0 else float("inf")


def check_items(model, system, settings: BatterySettings) -> list[BatteryItem]:
    states = sample_states(model, settings.samples, settings.seed)
    return [
        BatteryItem(
            f"check:{r.check}",
            "check",
            r.max_error,
            r.tolerance,
            r.samples,
            r.seed,
            r.passed,
            r.worst_state["label"],
        )
        for r in run_checks(model.name, model, system, states, settings.seed)
    ]


def _effect_scenes(model_name: str, params: ParameterSet, settings: BatterySettings) -> dict[str, dict]:
    """One short scene per effect, as scene documents (see pendverify.simulation.scene)."""
    if model_name == "double_pendulum":
        q0, v0 = [0.4, 1.1], [0.5, -0.5]
        actuation = {"type": "sine", "amplitude": [1.0, 0.4], "frequency": 0.7}
        disturbance = None
    else:
        q0, v0 = [0.0, 0.15, -0.1], [0.1, 0.0, 0.2]
        actuation = {"type": "sine", "amplitude": [2.0], "frequency": 0.5}
        disturbance = {"type": "noise", "std": [0.5, 0.05, 0.05], "bandwidth": 4.0, "seed": settings.seed}
    base = {
        "model": model_name,
        "parameters": params.as_dict(),
        "initial": {"q": q0, "v": v0},
        "time": {"duration": settings.sim_duration, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": settings.sim_rtol, "atol": settings.sim_rtol},
    }
    scenes = {
        "gravity": {"gravity": True},
        "damping": {"gravity": True, "damping": [max(d, 0.05) for d in _damping(model_name, params)]},
        "actuation": {"gravity": True, "actuation": actuation},
    }
    if disturbance:
        scenes["disturbance"] = {"gravity": True, "disturbance": disturbance}
    return {name: {**base, "name": f"battery:{name}", "effects": effects} for name, effects in scenes.items()}


def _damping(model_name: str, params: ParameterSet) -> list[float]:
    return list(np.diag(MODELS[model_name](params).damping_matrix()))


def invariant_items(model_name, params, urdf: str, settings: BatterySettings) -> list[BatteryItem]:
    from pendverify.simulation.scene import parse_scene
    from pendverify.simulation.simulate import simulate

    items = []
    for effect, doc in _effect_scenes(model_name, params, settings).items():
        try:
            with np.errstate(over="ignore", invalid="ignore"):  # a diverging run is judged below
                run = simulate(parse_scene(doc, f"<battery {effect}>"), "aba", urdf)
        except (PendverifyError, RuntimeError, FloatingPointError) as exc:
            # a run that diverges or dies is a failed item, not a crash of the battery
            items.append(
                BatteryItem(
                    f"invariant:{effect}", "invariant", np.inf, 0.0, 0, settings.seed, False, str(exc)
                )
            )
            continue
        steps = len(run.integration.steps_t) - 1
        for inv in run.invariants:
            items.append(
                BatteryItem(
                    f"invariant:{effect}:{inv.name.split(' ')[0]}"
                    + (":no-increase" if inv.name.startswith("energy never") else ""),
                    "invariant",
                    inv.error,
                    inv.tolerance,
                    steps,
                    settings.seed,
                    inv.passed,
                    inv.name,
                )
            )
    return items


def stress_items(model_name, params, settings: BatterySettings, urdf: str | None = None) -> list[BatteryItem]:
    """The stress cases that apply to any parameter set, run on this one.

    Large angles (|θ| ≈ 1e6 rad, with the θ + 2πk invariance; states beyond the
    trust rule there are refused and recorded, not failed), high speeds
    (|q̇| ≤ 1e3), zero gravity, and the conditioning guard of
    ``pendverify.checks.trust`` over the sampled states: a set whose
    comparisons would need refusing (near-singular M) is not certified.  They run
    on ``urdf``, the URDF being certified (the project's own for the set if None).
    """
    from pendverify.stress import cases, framework
    from pendverify.stress import catalogue as stress

    ctx = framework.Context(framework.FULL, settings.seed, urdf=urdf)
    cases = [
        # at |θ| ≈ 1e6 rad a set with κ̃ in the hundreds is beyond the trust rule: such
        # states are refused and recorded, and every state that is compared must pass
        cases.large_angle_case("large angles", lambda: params, expect="any"),
        cases.high_speed_case("high speeds", lambda: params),
        framework.checks_case("zero gravity", "gravity", lambda: params.replace(g=0.0)),
        framework.checks_case("conditioning", "conditioning", lambda: params),
    ]
    items = []
    for case in cases:
        r = stress.run_case(case, ctx)
        refusals_allowed = case.name == "large angles"
        passed = r.passed and (refusals_allowed or r.refused == 0) and r.level != "refuse"
        items.append(
            BatteryItem(
                f"stress:{case.name.replace(' ', '-')}",
                "stress",
                float(r.error or 0.0),
                float(r.tolerance or 1.0),
                ctx.settings.random_states,
                settings.seed,
                bool(passed),
                r.verdict + (f"; {r.invariant}" if r.invariant else "") + (f"; {r.note}" if r.note else ""),
            )
        )
    return items


def run_battery(
    model_name: str, params: ParameterSet, urdf: str, settings: BatterySettings
) -> list[BatteryItem]:
    model = MODELS[model_name](params)
    system = PinocchioSystem.from_urdf(model_name, urdf, params.g, f"<URDF being certified: {model_name}>")
    return (
        check_items(model, system, settings)
        + stress_items(model_name, params, settings, urdf)
        + invariant_items(model_name, params, urdf, settings)
    )
