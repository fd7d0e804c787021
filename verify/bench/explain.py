"""``pendverify bench explain``: how well the diagnosis names and repairs planted errors, and its cost.

The corpus of ``pendverify.diagnosis.corpus`` on every model file the worked examples ship
(the Python class, and the same model as LaTeX or text where one is shipped) and on the models
of ``examples/diagnosis_corpus.toml`` (one per class of model the examples do not cover), each against
its URDF and parameter set: per model, how many planted errors the checks detect, how many
the diagnosis names at the right entry, repairs (every check passes) and restores (the planted
edit or an equivalent one), how many of those are printed as confirmed (they held at perturbed
parameter sets too) or with the ambiguity stated (they hold at these values only, and the
message says so), how many wrong repairs are printed as confirmed (never any, by design),
whether the untouched model is clean, and the time a diagnosis takes (mean and largest, per
planted error, on one core).  ``quick`` draws up to
``QUICK_PER_OPERATOR`` planted errors of each operator per model (seeded) instead of all.  A
catalogue entry with ``pairs = N`` is planted N pairs of errors in two different keys instead
(``QUICK_PAIRS`` with ``quick``): the class of two errors at once.  A model SymPy cannot read
(dynamics as code) is planted parameters read wrongly instead (``pendverify.diagnosis.code_corpus``).
"""

from __future__ import annotations

from dataclasses import dataclass

from pendverify.diagnosis.code_corpus import (
    code_plants,
    reads_parameters_in_one_place,
    sample_code_plants,
    score_code_model,
)
from pendverify.diagnosis.corpus import (
    CORPUS_SEED,
    ModelScores,
    pair_plants,
    plants,
    sample_plants,
    score_model,
)
from pendverify.display import REPR_LIMIT, html_table, shortened

QUICK_PER_OPERATOR = 2
#: pairs of planted errors drawn per paired model with ``quick`` (``paired_classes``)
QUICK_PAIRS = 6
#: what is counted per model (``pendverify.diagnosis.corpus.Score``)
SCORED = ("detected", "named", "repaired", "restored", "confirmed", "ambiguity_stated", "wrong_confirmed")
#: the diagnosis's bound on a model of up to 3 degrees of freedom on this project's 2-core machine
BOUND_S = 10.0


@dataclass
class ExplainBench:
    """The corpus's scores per model file, and the degrees of freedom of each."""

    models: list[ModelScores]
    dof: dict[str, int]
    quick: bool

    def __repr__(self) -> str:
        totals = ", ".join(f"{k} {v}" for k, v in self.totals().items())
        head = f"<ExplainBench {'quick' if self.quick else 'full'}: {len(self.models)} model(s), "
        return f"{head}{shortened(totals, REPR_LIMIT - len(head) - 1)}>"

    def _repr_html_(self) -> str:
        whats = SCORED
        cells = [(m.label, len(m.scores), *(m.count(w) for w in whats)) for m in self.models]
        return html_table(
            ("model", "planted", *whats), cells, f"bench explain ({'quick' if self.quick else 'full'})"
        )

    def totals(self) -> dict[str, int]:
        return {what: sum(m.count(what) for m in self.models) for what in SCORED} | {
            "planted": sum(len(m.scores) for m in self.models)
        }


#: the shipped list of the corpus's models besides the worked examples, one per class of model
CORPUS_CATALOGUE = "diagnosis_corpus.toml"


def _target(model_file, urdf, params):
    """(model, system) of a model file checked against ``urdf`` with ``params`` (a parameter file,
    a mapping of values or a parameter set, as ``targets.parameter_values`` takes them)."""
    from pendverify.targets import plugin_target

    target = plugin_target(str(model_file), str(urdf), params)
    return target.model, target.system


def shipped_targets():
    """(label, model, system, degrees of freedom) of every model file the worked examples ship."""
    from pendverify.worked_examples import EXAMPLES

    for example in EXAMPLES:
        for file in example.models:
            model, system = _target(file.source, example.urdf.source, example.params.source)
            yield f"{example.name}, {file.role}", model, system, example.dof


def _shipped(spec: str):
    from pendverify.shipped import shipped_file

    kind, _, name = spec.partition("/")
    return shipped_file(kind, name)


def _catalogue() -> list[dict]:
    """The entries of ``CORPUS_CATALOGUE``, each with its ``label``: ``"acrobot_tedrake
    (non-Christoffel C)"``."""
    from pendverify.documents import parse_toml

    path = _shipped("examples/" + CORPUS_CATALOGUE)
    catalogue = parse_toml(path.read_text(encoding="utf-8"), str(path))
    return [entry | {"label": f"{entry['name']} ({entry['class']})"} for entry in catalogue.get("model", ())]


def class_targets():
    """(label, model, system, degrees of freedom) of every model of ``CORPUS_CATALOGUE``; the label
    names its class: ``"acrobot_tedrake (non-Christoffel C)"``."""
    for entry in _catalogue():
        model, system = _target(_shipped(entry["model"]), _shipped(entry["urdf"]), _shipped(entry["params"]))
        yield entry["label"], model, system, entry["dof"]


def paired_classes() -> dict[str, int]:
    """{label: how many pairs} of the catalogue's models whose corpus is pairs of planted errors in
    two different keys (``pairs = N``: the class of two errors at once), not single errors."""
    return {entry["label"]: entry["pairs"] for entry in _catalogue() if "pairs" in entry}


def corpus_targets():
    """Every model the corpus plants errors in: the worked examples' files, then the classes'."""
    yield from shipped_targets()
    yield from class_targets()


def run_explain_bench(quick: bool = False) -> ExplainBench:
    """The corpus on every shipped model file (module docstring)."""
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.progress import bar

    targets = list(corpus_targets())
    paired = paired_classes()
    chosen = {}
    code = {label for label, model, _, _ in targets if reads_parameters_in_one_place(type(model))}
    for label, model, _, _ in targets:
        if label in code:  # SymPy cannot read it: parameters read wrongly (``code_corpus``)
            chosen[label] = sample_code_plants(model, QUICK_PER_OPERATOR) if quick else code_plants(model)
            continue
        sm = SymbolicModel.of(type(model))
        if label in paired:
            chosen[label] = pair_plants(sm, min(paired[label], QUICK_PAIRS) if quick else paired[label])
        else:
            chosen[label] = sample_plants(sm, QUICK_PER_OPERATOR, CORPUS_SEED) if quick else plants(sm)
    out = ExplainBench([], {}, quick)
    with bar(sum(len(c) for c in chosen.values()), "explain", "error") as progress:
        for label, model, system, dof in targets:
            score = score_code_model if label in code else score_model
            out.models.append(score(label, model, system, chosen[label], progress=progress))
            out.dof[label] = dof
    return out
