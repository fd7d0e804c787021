"""One ranking of a diagnosis's findings (``pendverify.diagnosis.ranking``): the most likely fix first.

A one-character sign error in the cart-pole's H, which two convention traps at once also explain
exactly, gets its one-entry repair first; a real two-convention error (no single edit repairs it)
still gets the conventions first.  The rule itself is checked on findings made by hand.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pendverify import api
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.corpus import plants
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.finding import Finding
from pendverify.diagnosis.ranking import WHAT_DIFFERS, explanations_first, ranked
from pendverify.symbolic.edited import edited_model

from ..conftest import SEED
from .test_conventions_jointly import A2, _planted, _setup

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _explained(model, system):
    states = sample_states(model, 30, SEED)
    batch = CheckBatch(model, system, states)
    results = run_checks("t", model, system, states, SEED, applicable_checks(model, system), batch)
    assert not all(r.passed for r in results), "the planted error must fail"
    return explain(batch, results)


def _explanations(findings):
    return [f for f in findings if f.kind not in WHAT_DIFFERS]


def test_a_sign_error_in_h_gets_its_one_entry_repair_before_two_conventions():
    cls = api.load_model(EXAMPLES / "cart_pole.py")
    params = api.load_params(cls, EXAMPLES / "cart_pole.toml")
    system = api.load_urdf(cls, EXAMPLES / "cart_pole.urdf")
    model = cls(params)
    sm = SymbolicModel.of(cls)
    (plant,) = [p for p in plants(sm) if (p.method, p.index, p.operator) == ("gravity", 1, "sign")]
    planted = edited_model(model, sm, {plant.method: [(plant.index, plant.original, plant.new)]}, "Planted")
    findings = _explained(planted, system)
    explanations = _explanations(findings)
    kinds = [f.kind for f in explanations]
    assert "convention" in kinds, "the case needs the two-convention explanation as well"
    conventions = next(f for f in explanations if f.kind == "convention")
    assert len(conventions.details["traps"]) == 2 and conventions.details["residual"] <= 1e-9
    first = explanations[0]
    assert first.kind == "repair" and first.details["checks_pass"] is True, first.message
    assert first.quantity == "H" and first.index == (2,)
    assert kinds.index("repair") < kinds.index("convention")
    # what differs stays first
    assert [f.kind for f in findings[: len(findings) - len(explanations)]] == [
        f.kind for f in findings if f.kind in WHAT_DIFFERS
    ]


def test_a_real_two_convention_error_gets_the_conventions_first():
    """The map takes the hand's relative θ2 as absolute and θ2 turns the other way: no edit of one
    entry repairs that, and the joint convention finding leads."""
    model, right = _setup("double_pendulum")
    system = _planted(right, A2 @ np.diag([1.0, -1.0]), (0, 0))
    explanations = _explanations(_explained(model, system))
    assert not any(f.kind == "repair" and f.details["checks_pass"] for f in explanations)
    first = explanations[0]
    assert first.kind == "convention" and len(first.details["traps"]) == 2, first.message


def _repair(ok: bool) -> Finding:
    return Finding("repair", "r", "H", (1,), {"checks_pass": ok})


def test_the_rule_exact_first_then_by_how_much_changes_statements_last():
    entry = Finding("entry", "e", "H", (1,))
    pattern = Finding("pattern", "p", "H", (1,))
    two = Finding("convention", "two", details={"traps": ["sign", "half"], "residual": 1e-15})
    one = Finding("convention", "one", details={"traps": ["sign"], "residual": 1e-15})
    pivot = Finding("convention", "pivot", "M", details={"links": {"l": 1}, "residual": 1e-15})
    rough = Finding("convention", "rough", details={"traps": ["sign"], "residual": 1e-5})
    mass = Finding("parameters", "mass", details={"parameter": "mass"})
    combos = Finding("parameters", "combos", details={"parameter": "identifiable combinations"})
    structural = Finding("structural", "s")
    found, none = _repair(True), _repair(False)
    given = [two, rough, entry, none, structural, one, mass, pattern, combos, pivot, found]
    order = ranked(given)
    assert order == [entry, pattern, found, mass, one, pivot, two, rough, none, structural, combos]
    explanations = [found, mass, one, pivot, two, rough, none, structural, combos]
    assert explanations_first(given) == [*explanations, entry, pattern]
