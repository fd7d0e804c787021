"""The corpus of planted single-edit errors (``pendverify.diagnosis.corpus``) on every shipped
model file — Python, text and LaTeX; the two reference systems, cart-pole, Furuta, triple and
hanging pendulums — scored as ``pendverify bench explain --quick`` scores it: a seeded sample of
up to two planted errors per operator and model (seed ``CORPUS_SEED``; the bench without
``--quick`` runs every one).

Every detected error's entry must be named; the planted edit (or an equivalent one) must be
the suggested repair for at least 90 % of them; every untouched model must pass, and a repair
search or a parameter identification run on it anyway must find nothing.
"""

from __future__ import annotations

import pytest

from pendverify.bench.explain import corpus_targets, run_explain_bench
from pendverify.bench.explain_report import table
from pendverify.checks.batch import CheckBatch
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.corpus import CORPUS_SAMPLES, CORPUS_SEED
from pendverify.diagnosis.parameters import identify_parameters
from pendverify.diagnosis.repair import search_repair

REPAIR_RATE = 0.9  # the target: the planted edit (or an equivalent one) for ≥ 90 %


@pytest.mark.slow
def test_planted_errors_are_named_and_repaired(capsys):
    bench = run_explain_bench(quick=True)
    with capsys.disabled():
        print("\n" + table(bench))
    totals = bench.totals()
    assert totals["detected"] >= 150, "the corpus must hold errors of every operator in every model"
    assert totals["named"] == totals["detected"]
    assert totals["restored"] >= REPAIR_RATE * totals["detected"]
    assert all(m.clean for m in bench.models)
    operators = {s.plant.operator for m in bench.models for s in m.scores if s.restored}
    assert len(operators) >= 10, f"repairs of only {sorted(operators)}"


def test_untouched_models_get_no_repair_and_no_parameter_claim():
    for label, model, system, _ in corpus_targets():
        batch = CheckBatch(model, system, sample_states(model, CORPUS_SAMPLES, CORPUS_SEED))
        repairs, why = search_repair(batch, 10.0)
        # a model SymPy cannot read: its quantities, not its expressions' entries, are screened
        assert repairs == [] and ("no single entry" in why or "agree with Pinocchio's" in why), label
        assert identify_parameters(batch) == [], label
