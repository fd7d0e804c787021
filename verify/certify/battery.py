"""The full battery a parameter set must pass before it is certified.

1. every core check (``pendverify.checks.catalogue``) on a large seeded sample of states;
2. the stress cases that apply to any set, run on these parameters: large
   angles, high speeds, zero gravity, and the conditioning guard (a set whose
   M is too near singular to compare is refused, not certified);
3. one simulation invariant per effect the model has (``pendverify.certify.scenes``):
   a short run with gravity alone (energy drift), with damping when D is not zero
   (dissipation balance, energy never rises), with actuation when it has inputs
   (work–energy balance) and with a seeded noise disturbance when it has
   disturbances (work–energy balance); on the fast path (the compiled closed form),
   the gravity run's q̈ compared with ABA on the URDF at its own steps
   (``pendverify.certify.simulations``, which says why).

Nothing here depends on which model it is: a plug-in model file runs the same battery.

The battery runs on the URDF being certified, whether the project wrote it or
the user brought it.  Everything is deterministic in (parameters, URDF, seed,
settings), so ``recheck`` can run it again and compare figures.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from pendverify.analytic import MODELS, ClosedFormModel, ParameterSet
from pendverify.certify.simulations import invariant_items, invariants_not_run
from pendverify.checks.evidence import Evidence, stress_verdict
from pendverify.checks.sampling import sample_states
from pendverify.checks.verdict import FAIL, REFUSED
from pendverify.checks.verification import guarded_checks
from pendverify.progress import bar
from pendverify.robot.description import LoadedDescription, load_description
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
class BatteryRun:
    """The battery's evidence on one set: every item, and what reading the URDF being
    certified noticed (``PinocchioSystem.notes``), which its certificate records as ``notes``;
    ``not_run``: one sentence per part of the battery that does not apply to the model, why
    (``invariants_not_run``), also among ``notes``; ``description_format``: the format of the
    description certified (``robot.description.FORMATS``), which names its file in the bundle."""

    items: list[Evidence]
    notes: list[str]
    not_run: tuple[str, ...] = ()
    description_format: str = "urdf"

    @property
    def passed(self) -> bool:
        """Whether every item passed."""
        return all(i.passed for i in self.items)


def check_items(model, system, settings: BatterySettings) -> list[Evidence]:
    states = sample_states(model, settings.samples, settings.seed)
    return [
        Evidence(
            "check",
            f"check:{r.name}",
            r.status,
            error=r.error,
            tolerance=r.tolerance,
            at={"label": r.label},
            largest_error=None if np.isnan(r.largest_error) else r.largest_error,  # nan: nothing judged
            largest_tolerance=r.largest_tolerance,
            largest_at={"label": r.largest_at.get("label", "")},
            detail=f"{REFUSED}: {r.notes[0]}" if r.status == REFUSED else r.label,
            samples=r.samples,
            seed=r.seed,
        )
        for r in guarded_checks(model.name, model, system, states, settings.seed)[0]
    ]


def stress_items(
    model_cls,
    params,
    settings: BatterySettings,
    urdf: str | LoadedDescription | None = None,
    system: PinocchioSystem | None = None,
) -> list[Evidence]:
    """The stress cases that apply to any parameter set, run on this one.

    Large angles (|θ| ≈ 1e6 rad, with the θ + 2πk invariance; states beyond the
    trust rule there are refused and recorded, not failed; only for a model with an
    angular coordinate, a model without has no angle to shift), high speeds
    (|q̇| ≤ 1e3), zero gravity, and the conditioning guard of
    ``pendverify.checks.trust`` over the sampled states: a set whose
    comparisons would need refusing (near-singular M) is not certified.  They run
    on ``urdf``, the URDF being certified (text, path or as read by ``load_description``; the
    project's own for the set if None); ``system``: ``urdf``'s system at the set's g, if the caller
    has it (the cases at another g derive theirs from it).
    """
    from pendverify.robot.writer import urdf_for
    from pendverify.stress import cases, framework
    from pendverify.stress import catalogue as stress

    cls = model_class(model_cls)
    urdf = urdf_for(params) if urdf is None else urdf
    ctx = framework.Context(framework.FULL, settings.seed, urdf=urdf, model_cls=cls, urdf_system=system)
    # at |θ| ≈ 1e6 rad a set with κ̃ in the hundreds is beyond the trust rule: such
    # states are refused and recorded, and every state that is compared must pass
    angles = (
        [cases.large_angle_case("large angles", lambda: params, cls, expect="any")]
        if any(cls.angular)
        else []
    )
    cases = [
        *angles,
        cases.high_speed_case("high speeds", lambda: params, cls),
        framework.checks_case("zero gravity", "gravity", lambda: params.replace(g=0.0), model_cls=cls),
        framework.checks_case("conditioning", "conditioning", lambda: params, model_cls=cls),
    ]
    items = []
    for case in cases:
        r = stress.run_case(case, ctx)
        refusals_allowed = case.name == "large angles"
        refused = r.status == REFUSED or (r.extras["refused"] and not refusals_allowed)
        invariant, note = r.extras.get("invariant"), "; ".join(r.notes)
        items.append(
            Evidence(
                "stress",
                f"stress:{case.name.replace(' ', '-')}",
                FAIL if r.failed else (REFUSED if refused else r.status),
                error=float(r.error or 0.0),
                tolerance=float(r.tolerance or 1.0),
                largest_error=None,  # a stress case keeps its worst ratio only
                detail=stress_verdict(r)
                + (f"; {invariant}" if invariant else "")
                + (f"; {note}" if note else ""),
                samples=ctx.settings.random_states,
                seed=settings.seed,
            )
        )
    return items


def model_class(model) -> type[ClosedFormModel]:
    """A model class, given itself or a built-in model's name."""
    return MODELS[model] if isinstance(model, str) else model


def run_battery(
    model, params: ParameterSet, urdf: str, settings: BatterySettings, engines: dict | None = None
) -> BatteryRun:
    """The battery for a model (a class, or a built-in model's name), its parameters and URDF:
    its items, and the notes of the URDF read once for all of them, with a sentence per part
    that does not apply to the model (``invariants_not_run``).

    ``engines``: effect → the engine its invariant items ran on (``recheck``: the certificate's)."""
    cls = model_class(model)
    loaded = load_description(urdf, f"<URDF being certified: {cls.name}>")  # read once for every part
    system = PinocchioSystem.for_model(cls, loaded, params.g)
    not_run = invariants_not_run(cls)
    parts = (
        lambda: check_items(cls(params), system, settings),
        lambda: stress_items(cls, params, settings, loaded, system),
        (lambda: []) if not_run else (lambda: invariant_items(cls, params, urdf, settings, engines, system)),
    )
    items = []
    with bar(len(parts), "battery", "part") as progress:  # checks, stress cases, simulations
        for part in parts:
            items += part()
            progress.update(1)
    skipped = (not_run,) if not_run else ()
    return BatteryRun(items, [*system.notes, *skipped], skipped, loaded.format)
