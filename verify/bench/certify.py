"""``pendverify bench certify``: what the certification battery costs per parameter set on one core.

For each built-in parameter set (``analytic/params``; or the sets given), measured in one
run as process time (CPU seconds of this process, BLAS held to one thread), the least of
``repeats`` runs taken in rounds over every figure (``least_in_rounds``: on a shared
machine a slow spell lasts seconds, and rounds spread each figure's runs over the
whole measurement instead of putting them all into one spell):

* the battery (``certify.battery.run_battery``) and its parts: ``checks`` (the trust
  guard and every check on the sampled states), ``stress`` (the four generic cases) and
  ``invariants`` (one simulation per effect);
* their floor: the bare Pinocchio calls and closed-form evaluations the parts contain,
  timed alone on the same states — each Pinocchio function called once per state in a
  plain loop with the configurations already mapped, and the closed forms evaluated as
  the checks evaluate them (``pendverify.checks.closed_forms``: the generated NumPy
  functions over all states, the model's own Python where SymPy cannot read a method).

The battery's floor counts the invariants at their own cost (their simulations are not
split further here).  Nothing here is asserted on time: ``tests/bench/test_bench_certify.py``
runs ``--quick`` and checks the table's shape and that the ratios are finite.
"""

from __future__ import annotations

import gc
import time
from dataclasses import dataclass, field, replace

import numpy as np

from pendverify.analytic import MODELS
from pendverify.analytic.params import default_parameter_file
from pendverify.certify.battery import (
    BatterySettings,
    check_items,
    run_battery,
    stress_items,
)
from pendverify.certify.issue import certification_input
from pendverify.certify.simulations import invariant_items
from pendverify.checks.batch import recording_batches
from pendverify.checks.closed_forms import ClosedForms
from pendverify.display import html_table, shortened
from pendverify.robot.batch import configurations
from pendverify.robot.system import PinocchioSystem

PARTS = ("checks", "stress", "invariants")


@dataclass
class SetCost:
    """One parameter set's seconds: the battery, its parts and their floor."""

    name: str
    battery: float
    parts: dict[str, float]
    floor: dict[str, float]
    states: int
    contexts: dict[str, int] = field(default_factory=dict)

    def as_dict(self) -> dict:
        return dict(self.__dict__)

    def __repr__(self) -> str:
        parts = ", ".join(f"{k} {v:.3f}" for k, v in self.parts.items())
        return f"<SetCost {shortened(self.name, 60)}: battery {self.battery:.3f} s ({shortened(parts, 150)})>"

    def _repr_html_(self) -> str:
        from pendverify.bench.certify_report import rows

        cells = [(r["part"], f"{r['seconds']:.3f}", "—" if r["floor_s"] is None else f"{r['floor_s']:.3f}")
                 for r in rows(self)]  # fmt: skip
        return html_table(("part", "seconds", "floor s"), cells, f"the battery's cost on {self.name}")


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


def least_in_rounds(figures: dict, repeats: int) -> dict:
    """{key: the least process time of ``figures[key]()``}, each timed once per round, ``repeats`` rounds.

    On a shared machine a slow spell lasts seconds: ``repeats`` calls in a row can all
    fall into one, while rounds over every figure spread each figure's calls across the
    whole run.
    """
    for fn in figures.values():
        fn()  # untimed: caches, generated code
    best = dict.fromkeys(figures, float("inf"))
    rounds = max(1, repeats)
    for _ in range(rounds):
        for key, fn in figures.items():
            best[key] = min(best[key], cpu_once(fn))
    return best


def _pinocchio_floor(ctx) -> list:
    """(function, argument rows…) for each bare Pinocchio loop the batch ``ctx`` ran."""
    import pinocchio as pin

    if "pin" not in ctx.__dict__:
        return []
    pb = ctx.pin
    system, n = pb.system, pb.system.model.nv
    zero, unit = np.zeros(n), np.eye(n)
    m0, d0 = system.model_without_gravity, system.data_without_gravity
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
        configs = configurations(system.cmap, ctx.Q)
        loops.append((pin.forwardKinematics, configs))
        if ctx.pinocchio_angles is not None:
            loops.append((pin.crba, configs))
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
                forms = ClosedForms(ctx.model, ctx.Q, ctx.V, ctx.U, ctx.W, ctx.python_only)
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
        with recording_batches() as recorded:
            parts[part]()
        floors[part], contexts[part] = floor_work(recorded), len(recorded)
    return _SetRun(source.name, parts, lambda: run_battery(cls, params, urdf, settings), floors, contexts)


def measure(params_files=None, settings: BatterySettings | None = None, repeats: int = 7):
    """``SetCost`` for each parameter file (default: every built-in model's own set).

    Each battery, part and floor figure is the least of ``repeats`` rounds over every
    set and figure (``least_in_rounds``).
    """
    files = params_files or [str(default_parameter_file(name)) for name in MODELS]
    settings = settings or BatterySettings()
    runs = [_prepare(f, settings) for f in files]
    figures = {}
    for i, run in enumerate(runs):
        figures.update({(i, "part", part): fn for part, fn in run.parts.items()})
        figures[(i, "battery")] = run.battery
        figures.update({(i, "floor", part): fn for part, fn in run.floors.items()})
    best = least_in_rounds(figures, repeats)
    return [
        SetCost(
            run.name,
            best[(i, "battery")],
            {part: best[(i, "part", part)] for part in PARTS},
            {part: best[(i, "floor", part)] for part in ("checks", "stress")},
            settings.samples,
            run.contexts,
        )
        for i, run in enumerate(runs)
    ]


def quick_settings() -> BatterySettings:
    return replace(BatterySettings(), samples=100, sim_duration=0.5)
