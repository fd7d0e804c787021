"""``pendverify bench explain``: how well the diagnosis names and repairs planted errors, and its cost.

The corpus of ``pendverify.diagnosis.corpus`` on every model file the worked examples ship
(the Python class, and the same model as LaTeX or text where one is shipped), each against
its URDF and parameter set: per model, how many planted errors the checks detect, how many
the diagnosis names at the right entry, repairs (confirmed by every check) and restores (the
planted edit or an equivalent one), whether the untouched model is clean, and the time a
diagnosis takes (mean and largest, per planted error, on one core).  ``quick`` draws up to
``QUICK_PER_OPERATOR`` planted errors of each operator per model (seeded) instead of all.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pendverify.diagnosis.corpus import CORPUS_SEED, ModelScores, plants, sample_plants, score_model

QUICK_PER_OPERATOR = 2
#: the diagnosis's bound on a model of up to 3 degrees of freedom on this project's 2-core machine
BOUND_S = 10.0


@dataclass
class ExplainBench:
    """The corpus's scores per model file, and the degrees of freedom of each."""

    models: list[ModelScores]
    dof: dict[str, int]
    quick: bool

    def totals(self) -> dict[str, int]:
        return {
            what: sum(m.count(what) for m in self.models)
            for what in ("detected", "named", "repaired", "restored")
        } | {"planted": sum(len(m.scores) for m in self.models)}


def shipped_targets():
    """(label, model, system, degrees of freedom) of every model file the worked examples ship."""
    from pendverify.analytic.plugin import load_model_class
    from pendverify.robot.system import PinocchioSystem
    from pendverify.targets import parameter_values
    from pendverify.worked_examples import EXAMPLES

    for example in EXAMPLES:
        for file in example.models:
            cls = load_model_class(str(file.source))
            params = parameter_values(cls, example.params.source)
            system = PinocchioSystem.for_model(cls, example.urdf.source, getattr(params, "g", None))
            yield f"{example.name}, {file.role}", cls(params), system, example.dof


def run_explain_bench(quick: bool = False) -> ExplainBench:
    """The corpus on every shipped model file (module docstring)."""
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.progress import bar

    targets = list(shipped_targets())
    chosen = {}
    for label, model, _, _ in targets:
        sm = SymbolicModel.of(type(model))
        chosen[label] = sample_plants(sm, QUICK_PER_OPERATOR, CORPUS_SEED) if quick else plants(sm)
    out = ExplainBench([], {}, quick)
    with bar(sum(len(c) for c in chosen.values()), "explain", "error") as progress:
        for label, model, system, dof in targets:
            out.models.append(score_model(label, model, system, chosen[label], progress=progress))
            out.dof[label] = dof
    return out


def _rate(part: int, whole: int) -> str:
    return f"{part}/{whole} ({100 * part / whole:.1f} %)" if whole else "–"


def table(bench: ExplainBench) -> str:
    """The figures as text: one row per model file, the totals, the time against the bound."""
    header = (
        "model file",
        "dof",
        "planted",
        "detected",
        "named",
        "repaired",
        "restored",
        "clean",
        "mean s",
        "max s",
    )
    rows = []
    for m in bench.models:
        seconds = [s.seconds for s in m.scores if s.detected] or [0.0]
        detected = m.count("detected")
        rows.append(
            (
                m.label,
                str(bench.dof[m.label]),
                str(len(m.scores)),
                str(detected),
                _rate(m.count("named"), detected),
                _rate(m.count("repaired"), detected),
                _rate(m.count("restored"), detected),
                "yes" if m.clean else "NO",
                f"{np.mean(seconds):.2f}",
                f"{max(seconds):.2f}",
            )
        )
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
    lines = ["  ".join(h.ljust(w) for h, w in zip(header, widths, strict=True))]
    lines.append("-" * len(lines[0]))
    lines += ["  ".join(c.ljust(w) for c, w in zip(r, widths, strict=True)).rstrip() for r in rows]
    t = bench.totals()
    slowest = max((s.seconds for m in bench.models for s in m.scores if s.detected), default=0.0)
    lines += [
        "",
        f"{'a seeded sample' if bench.quick else 'every'} planted error ({t['planted']}), "
        f"{t['detected']} detected by the checks: entry named {_rate(t['named'], t['detected'])}, "
        f"repaired {_rate(t['repaired'], t['detected'])}, the planted edit or an equivalent one "
        f"{_rate(t['restored'], t['detected'])} (target ≥ 90 %: "
        f"{'met' if t['detected'] and t['restored'] >= 0.9 * t['detected'] else 'NOT met'})",
        f"untouched models clean: {sum(m.clean for m in bench.models)}/{len(bench.models)}; "
        f"largest diagnosis {slowest:.2f} s (bound {BOUND_S:g} s for up to 3 degrees of freedom: "
        f"{'met' if slowest <= BOUND_S else 'NOT met'})",
    ]
    return "\n".join(lines)
