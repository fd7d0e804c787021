"""The battery's invariant items: one short run per effect (``pendverify.certify.scenes``), on the fast path.

Engines, recorded in each invariant item's ``engine`` (``BATTERY_ENGINES``):

* ``compiled`` — the compiled DOP853 on the model's generated closed form
  (``pendverify.simulation.compiled_scene``), the invariants evaluated on its own accepted steps
  with the model's generated energy (``pendverify.numerics.energies``).  Every battery
  scene compiles: gravity, damping, the sine input and the seeded noise
  (``pendverify.numerics.forcing``).  It is the engine of every item the battery issues,
  unless the fast path cannot take the model (its closed forms unreadable by SymPy) —
  never because of the code cache: one that cannot be used is replaced by a temporary
  folder, and when no folder can be written the battery stops with that one line;
* ``aba`` — scipy's DOP853 on Pinocchio's ABA on the URDF being certified, with
  Pinocchio's energy (``pendverify.simulation.simulate``).  An invariant item that records
  no engine ran on it (``UNRECORDED``).

``recheck`` runs each item on the engine its certificate records, so it reproduces the
figures of an item whatever engine ran it.

What the items judge.  On ``compiled`` the run and the energy are both the closed form's:
the items judge the derivation's own consistency — a C that is not Christoffel-consistent
with M, or an H that is not ∇V, makes the closed form gain or lose energy, and the drift or
balance fails (``tests/certify/test_fast_battery.py`` plants both).  On ``aba`` they are both
Pinocchio's: the items judge the integrator and Pinocchio's physics, which conserve
Pinocchio's energy whatever the hand derivation says.  That the closed form is the URDF's
dynamics is what the core checks establish (ε-level, 2000 states).

Cross-check.  ``invariant:gravity:engines`` compares the compiled q̈ with Pinocchio's ABA
on the URDF being certified at ``CROSS_CHECK_STATES`` of the gravity run's own accepted
steps (evenly spread, first and last included), each state judged as the core ``aba``
check judges one (``cross_check``): it ties the very trajectory the invariants judged — the
generated code, not only the Python closed form the core checks read — to the URDF, at the
cost of a few ABA calls.  A full ABA run of the gravity scene would cost as much as the
rest of a set's battery and would compare two chaotic trajectories, which separate for
reasons that are not model errors.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from pendverify.certify.scenes import effect_scenes
from pendverify.checks.evidence import Evidence
from pendverify.checks.verdict import FAIL
from pendverify.errors import FastPathError, FileAccessError, PendverifyError

COMPILED, ABA = "compiled", "aba"
BATTERY_ENGINES = {  # what may run a battery invariant item → its description in the item
    COMPILED: "compiled DOP853 on the generated closed form",
    ABA: "scipy DOP853 on Pinocchio's ABA",
}
UNRECORDED = ABA  # the engine of an invariant item that records none
CROSS_CHECK_STATES = 8


def invariants_not_run(model_cls) -> str:
    """Why the battery's invariant items are not run for the model; "" when its simulations apply.

    A model that gives q̈ alone (``has_mass_matrix`` False: dynamics as code, a q̈ with fewer
    inputs than coordinates) has no closed-form M, H or V: a scene refuses it
    (``pendverify.simulation.scene.parse_scene``), the compiled path has nothing to generate, and
    the invariants judge the model's energy, which it does not give.  On ABA alone they would judge
    Pinocchio, not the model.  Its q̈ is judged by the core checks (``aba``; ``crba``, ``gravity``
    and ``rnea`` on a derived M).
    """
    if model_cls.has_mass_matrix:
        return ""
    return (
        f"invariant items not run: {model_cls.__name__} gives q̈ alone, without the closed-form M, H "
        "and V that the battery's simulations (energy drift and balances) judge; its q̈ is judged "
        "by the core checks"
    )


def invariant_items(model_cls, params, urdf: str, settings, engines=None, system=None) -> list:
    """One simulation per effect the model has, on the fast path where it compiles, else ABA on ``urdf``.

    ``engines``: effect → engine, to run each on a given engine (``recheck``: the certificate's);
    ``system``: the ``PinocchioSystem`` of ``urdf`` at the set's g, if the caller has it.
    """
    from pendverify.simulation.scene import parse_scene

    items = []
    scenes = effect_scenes(model_cls, params, settings.sim_duration, settings.sim_rtol, settings.seed)
    for effect, doc in scenes.items():
        scene = parse_scene(doc, f"<battery {effect}>")
        engine, run, steps, failure = run_battery_scene(scene, urdf, (engines or {}).get(effect))
        if run is None:  # a run that diverges or dies is a failed item, not a crash of the battery
            items.append(_item(f"invariant:{effect}", None, 0, settings, engine, failure))
            continue
        for inv in run.invariants:
            name = f"invariant:{effect}:{inv.name.split(' ')[0]}"
            name += ":no-increase" if inv.name.startswith("energy never") else ""
            items.append(_item(name, inv, steps, settings, engine))
        if effect == "gravity" and engine == COMPILED:
            if system is None:
                from pendverify.robot.system import PinocchioSystem

                system = PinocchioSystem.for_model(model_cls, urdf, params.g)
            name, states = f"invariant:{effect}:engines", min(CROSS_CHECK_STATES, steps + 1)
            try:
                with np.errstate(over="ignore", invalid="ignore"):
                    items.append(_item(name, cross_check(run, system), states, settings, engine))
            except (PendverifyError, ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
                items.append(_item(name, None, 0, settings, engine, f"{type(exc).__name__}: {exc}"))
    return items


def run_battery_scene(scene, urdf: str, engine: str | None):
    """(engine, run or None, accepted steps, why it failed): on the fast path unless ``engine`` says aba
    or (``engine`` None) the scene does not compile."""
    from pendverify.simulation import compiled_scene
    from pendverify.simulation.simulate import run_scene

    if engine not in (None, *BATTERY_ENGINES):
        expected = ", ".join(BATTERY_ENGINES)
        return engine, None, 0, f"unknown battery engine {engine!r}; expected one of {expected}"
    compiled = None
    if engine in (None, COMPILED):
        try:
            compiled = compiled_scene.compile_scene(scene)
        except FileAccessError:
            # the code cache cannot be written, not even a temporary folder (``codegen.folder``):
            # the item's engine must not change because of where code is cached; stop with the line
            raise
        except (FastPathError, PendverifyError) as exc:
            if engine == COMPILED:
                return COMPILED, None, 0, str(exc)
    try:
        with np.errstate(over="ignore", invalid="ignore"):  # a diverging run is judged by its items
            if compiled is not None:
                run = compiled_scene.simulate_compiled(scene, compiled)
                return COMPILED, run, len(run.result.steps_t) - 1, ""
            run = run_scene(scene, "aba", urdf)
            return ABA, run, len(run.integration.steps_t) - 1, ""
    except (PendverifyError, RuntimeError, FloatingPointError) as exc:
        return (ABA if compiled is None else COMPILED), None, 0, str(exc)


def compiled_accelerations(model, states) -> np.ndarray:
    """q̈ from the model's generated code (friction and inputs included) at each state (no disturbance)."""
    from pendverify.numerics.generate import GeneratedSystem

    compiled = GeneratedSystem.from_model(model, D=model.damping_matrix(), B=model.input_matrix())
    out = np.empty((len(states), model.nv))
    for i, s in enumerate(states):
        if np.any(s.w):  # the gravity run's states have none
            raise ValueError("the compiled cross-check takes states without disturbance")
        at = replace(compiled, u0=np.asarray(s.u, float).reshape(-1))
        out[i] = at.rhs(np.concatenate([s.q, s.v]))[model.nv :]
    return out


def cross_check(run, system):
    """The compiled q̈ against ABA on ``system`` at ``CROSS_CHECK_STATES`` of the run's accepted steps.

    The states are judged by the core ``aba`` check itself (``pendverify.checks``: its
    quantity, scale, K, c_T, world-frame amplification A and model-form allowance), with
    the generated code's q̈ in place of the hand-written one; a state beyond the trust
    limit fails.
    """
    from pendverify.checks.batch import CheckBatch
    from pendverify.checks.catalogue import CHECKS
    from pendverify.checks.judge import collect
    from pendverify.checks.sampling import State
    from pendverify.simulation.invariants import figures_of

    steps_t, steps_x = run.result.steps_t, run.result.steps_x
    rows = np.unique(np.linspace(0, len(steps_t) - 1, CROSS_CHECK_STATES).round().astype(int))
    model = run.dynamics.model
    n, zeros = model.nv, (np.zeros(len(model.inputs)), np.zeros(len(model.disturbances)))
    states = [
        State(f"t = {t:.6g} s", x[:n], x[n : 2 * n], *zeros)
        for t, x in zip(steps_t[rows], steps_x[rows], strict=True)
    ]
    replaced = {"acceleration": compiled_accelerations(model, states)}
    aba = next(c for c in CHECKS if c.name == "aba")
    evidence = collect(aba, CheckBatch(model, system, states, replaced=replaced))
    errors, tolerances = np.full(len(states), np.inf), np.full(len(states), np.nan)
    errors[evidence.judged], tolerances[evidence.judged] = evidence.rel_err, evidence.rel_tol
    for i, rounding in evidence.refused:
        tolerances[i] = rounding
    name = f"engines agree: compiled q̈ vs ABA on the URDF at {len(rows)} of the run's {len(steps_t)} states"
    # each state's error is relative to its own scale: no common one
    return figures_of(name, errors, tolerances, steps_t[rows], float("nan"), "as the aba check")


def _item(name: str, inv, samples: int, settings, engine: str, failure: str = ""):
    """A battery item from an invariant's ``Evidence`` (or a failed run's message, ``inv`` None)."""
    if inv is None:
        return Evidence(
            "invariant",
            name,
            FAIL,
            error=np.inf,
            tolerance=0.0,
            largest_error=np.inf,
            detail=failure,
            seed=settings.seed,
            extras={"engine": engine},
        )
    return replace(
        inv,
        name=name,
        detail=f"{inv.name} [{BATTERY_ENGINES[engine]}]",
        samples=samples,
        seed=settings.seed,
        extras={**inv.extras, "engine": engine},
    )


def recorded_engines(items: list[dict]) -> dict[str, str]:
    """effect → engine of a certificate's invariant items (``UNRECORDED`` where an item names none)."""
    return {
        item["name"].split(":")[1]: item.get("engine", UNRECORDED)
        for item in items
        if item.get("kind") == "invariant"
    }
