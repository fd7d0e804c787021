"""``pendverify bench certify``: what the certification battery costs per parameter set on one core.

For each built-in parameter set (``analytic/params``; or the sets given), measured in one
run as process time (CPU seconds of this process, BLAS held to one thread), the least of
``repeats`` runs taken in rounds over every figure (``least_in_rounds``: on a shared
machine a slow spell lasts seconds, and rounds spread each figure's runs over the
whole measurement instead of putting them all into one spell):

* the battery (``certify.battery.run_battery``) and its parts: ``checks`` (the trust
  guard and every check on the sampled states), ``stress`` (the four generic cases) and
  ``invariants`` (one simulation per effect);
* the per-state reference path of the checks and stress parts (``run_check_per_state``
  and ``trust.assess`` state by state, as before the batch; ``reference_repeats`` runs);
* their floor: the bare Pinocchio calls and closed-form evaluations the parts contain,
  timed alone on the same states — each Pinocchio function called once per state in a
  plain loop with the configurations already mapped, and the closed forms evaluated as
  the batch evaluates them (``checks.forms_batch``: once over all states where the
  model's code allows it, state by state where it does not).

The battery's floor counts the invariants at their own cost (their simulations are not
split further here).  Nothing here is asserted on time: ``tests/bench/test_bench_certify.py``
runs ``--quick`` and checks the table's shape and that the ratios are finite.
"""

from __future__ import annotations

import contextlib
import gc
import time
from dataclasses import dataclass, field, replace

import numpy as np

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file
from pendverify.certify.battery import (
    BatterySettings,
    check_items,
    invariant_items,
    run_battery,
    stress_items,
)
from pendverify.certify.issue import certification_input
from pendverify.checks import batch as batch_module
from pendverify.checks.forms_batch import ClosedFormBatch
from pendverify.robot.batch import configurations
from pendverify.robot.system import PinocchioSystem

PARTS = ("checks", "stress", "invariants")


@dataclass
class SetCost:
    """One parameter set's seconds: the battery and its parts, batch, per state and floor."""

    name: str
    battery: float
    batch: dict[str, float]
    per_state: dict[str, float]
    floor: dict[str, float]
    states: int
    contexts: dict[str, int] = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def cpu_once(fn) -> float:
    """The process time of one call of ``fn``, the garbage collector held off meanwhile."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        start = time.process_time()
        fn()
        return time.process_time() - start
    finally:
        if enabled:
            gc.enable()


def cpu_seconds(fn, repeats: int) -> float:
    """The least process time of ``repeats`` calls of ``fn`` in a row (after one untimed call)."""
    fn()
    return min(cpu_once(fn) for _ in range(max(1, repeats)))


def least_in_rounds(figures: dict, repeats: int, between=None) -> dict:
    """{key: the least process time of ``figures[key]()``}, each timed once per round, ``repeats`` rounds.

    On a shared machine a slow spell lasts seconds: ``repeats`` calls in a row can all
    fall into one, while rounds over every figure spread each figure's calls across the
    whole run.  ``between()`` (the slow per-state path) runs after half of the rounds.
    """
    for fn in figures.values():
        fn()  # untimed: caches, generated code
    best = dict.fromkeys(figures, float("inf"))
    rounds = max(1, repeats)
    for r in range(rounds):
        if between is not None and r == rounds // 2:
            between()
        for key, fn in figures.items():
            best[key] = min(best[key], cpu_once(fn))
    return best


@contextlib.contextmanager
def per_state_only():
    """Every check and trust verdict takes the per-state reference path (``BatchContext.of`` → None)."""
    real = batch_module.BatchContext.__dict__["of"]
    batch_module.BatchContext.of = classmethod(lambda cls, *args: None)
    try:
        yield
    finally:
        batch_module.BatchContext.of = real


@contextlib.contextmanager
def recorded_batches(into: list):
    """Every ``BatchContext`` made meanwhile is appended to ``into``."""
    cls = batch_module.BatchContext
    real = cls.__init__

    def record(self, *args, **kwargs):
        real(self, *args, **kwargs)
        into.append(self)

    cls.__init__ = record
    try:
        yield
    finally:
        cls.__init__ = real


def _pinocchio_floor(ctx) -> list:
    """(function, argument rows…) for each bare Pinocchio loop the batch ``ctx`` ran."""
    import pinocchio as pin

    if "pin" not in ctx.__dict__:
        return []
    pb = ctx.pin
    system, n = pb.system, pb.system.model.nv
    zero, unit = np.zeros(n), np.eye(n)
    m0, d0 = system._no_gravity, system._no_gravity_data
    done, loops = pb.computed, []
    table = {
        "crba": (pin.crba, pb.q),
        "Minv": (pin.computeMinverse, pb.q),
        "bias": (lambda m, d, q, v: pin.rnea(m, d, q, v, zero), pb.q, pb.v),
        "H": (pin.computeGeneralizedGravity, pb.q),
        "C": (pin.computeCoriolisMatrix, pb.q, pb.v),
        "KE": (pin.computeKineticEnergy, pb.q, pb.v),
        "V": (pin.computePotentialEnergy, pb.q),
    }
    loops += [table[k] for k in table if k in done]
    if "Mdot" in done:
        loops += [(lambda m, d, q, e=e: pin.computeRNEADerivatives(m0, d0, q, zero, e), pb.q) for e in unit]
    if pb.aba_torques is not None:
        loops.append((pin.aba, pb.q, pb.v, pb.aba_torques))
    if "lever" in ctx.__dict__:  # the term amplification: forward kinematics (and CRBA at θ if reduced)
        if ctx.source[1] is None:
            loops.append((pin.forwardKinematics, pb.q))
        else:
            configs = configurations(system.cmap, ctx.Q)
            loops += [(pin.forwardKinematics, configs), (pin.crba, configs)]
    return loops


def floor_work(contexts):
    """A function running the bare Pinocchio calls and closed-form evaluations of the batches ``contexts``."""
    import pinocchio as pin  # noqa: F401  (loaded before timing)

    work = []
    for ctx in contexts:
        system = ctx.pin.system if "pin" in ctx.__dict__ else None
        for f, *rows in _pinocchio_floor(ctx):
            work.append((f, system.model, system.data, rows))
        names = list(ctx.forms._values) if "forms" in ctx.__dict__ else []
        work.append(("forms", ctx, names))

    def run():
        for item in work:
            if item[0] == "forms":
                _, ctx, names = item
                forms = ClosedFormBatch(ctx.model, ctx.states, ctx.Q, ctx.V, ctx.U, ctx.W)
                for name in names:
                    forms.value(name)
                continue
            f, pm, data, rows = item
            for args in zip(*rows, strict=True):
                f(pm, data, *args)

    return run


@dataclass
class _SetRun:
    """One parameter set's timed callables: its parts, its battery and its parts' floors."""

    name: str
    parts: dict
    battery: object
    floors: dict
    contexts: dict


def _prepare(params_file: str, settings: BatterySettings) -> _SetRun:
    source = certification_input(params_file=params_file)
    cls, params, urdf = source.model.load(), source.params, source.urdf
    system = PinocchioSystem.for_model(cls, urdf, params.g, f"<URDF being certified: {cls.name}>")
    parts = {
        "checks": lambda: check_items(cls(params), system, settings),
        "stress": lambda: stress_items(cls, params, settings, urdf),
        "invariants": lambda: invariant_items(cls, params, urdf, settings),
    }
    floors, contexts = {}, {}
    for part in ("checks", "stress"):
        recorded: list = []
        with recorded_batches(recorded):
            parts[part]()
        floors[part], contexts[part] = floor_work(recorded), len(recorded)
    return _SetRun(source.name, parts, lambda: run_battery(cls, params, urdf, settings), floors, contexts)


def measure(
    params_files=None, settings: BatterySettings | None = None, repeats: int = 7, reference_repeats=1
):
    """``SetCost`` for each parameter file (default: every built-in model's own set).

    Each batch, battery and floor figure is the least of ``repeats`` rounds over every
    set and figure (``least_in_rounds``); the per-state path runs once between the
    rounds, the least of ``reference_repeats`` calls in a row kept.
    """
    files = params_files or [str(default_parameter_file(name)) for name in MODELS]
    settings = settings or BatterySettings()
    runs = [_prepare(f, settings) for f in files]
    figures = {}
    for i, run in enumerate(runs):
        figures.update({(i, "batch", part): fn for part, fn in run.parts.items()})
        figures[(i, "battery")] = run.battery
        figures.update({(i, "floor", part): fn for part, fn in run.floors.items()})
    per_state: dict = {}

    def reference():
        with per_state_only():
            for i, run in enumerate(runs):
                for part in ("checks", "stress"):
                    per_state[(i, part)] = cpu_seconds(run.parts[part], reference_repeats)

    best = least_in_rounds(figures, repeats, reference)
    return [
        SetCost(
            run.name,
            best[(i, "battery")],
            {part: best[(i, "batch", part)] for part in PARTS},
            {part: per_state[(i, part)] for part in ("checks", "stress")},
            {part: best[(i, "floor", part)] for part in ("checks", "stress")},
            settings.samples,
            run.contexts,
        )
        for i, run in enumerate(runs)
    ]


def quick_settings() -> BatterySettings:
    return replace(BatterySettings(), samples=100, sim_duration=0.5)
