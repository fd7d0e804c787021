"""A repair is confirmed only when it is the same function of the parameters, not the same numbers.

The coincident corpus (``examples/diagnosis_corpus.toml``, class "coincident parameter
values": a uniform-rod pendulum, a point pendulum with l = 0.5 and m = 1, the classic cart-pole
with I = mp·l²/3, a double pendulum of two equal rods) has parameter values at which wrong edits
make every check pass.  Each test plants one error and asserts what the repair says: no wrong
edit printed as confirmed, the exact edit confirmed where the URDF lets its parameters move, and
the ambiguity stated, with the relation under which the alternatives agree, where it does not.
"""

from __future__ import annotations

import sys

import pytest
import sympy as sp

from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.bench.explain import QUICK_PER_OPERATOR, class_targets, shipped_targets
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.diagnosis.alternatives import relation
from pendverify.diagnosis.corpus import CORPUS_SAMPLES, CORPUS_SEED, sample_plants, score_model
from pendverify.diagnosis.explain import explain
from pendverify.shipped import shipped_file
from pendverify.symbolic.edited import edited_model

COINCIDENT = "coincident parameter values"
#: the issue's target on the coincident corpus: the exact edit confirmed, or the ambiguity stated
STATED_RATE = 0.9
#: the words only a confirmed repair is printed with
CONFIRMED_WORDS = "at these parameter values and at"


def _targets(start: str):
    return [t for t in class_targets() if t[0].startswith(start)]


def _repairs(label: str, method: str, index: int, planted: str, system=None):
    """The repair findings of the coincident model ``label`` with entry ``index`` of ``method``
    replaced by ``planted`` (SymPy syntax over the model's names)."""
    ((_, model, own, _),) = _targets(label)
    sm = SymbolicModel.of(type(model))
    names = {s.name: s for group in sm.symbols.values() for s in group}
    names |= {p.name: p for p in sm.parameters.values()}
    value = sm.closed_forms[method]
    original = value[index] if isinstance(value, sp.MatrixBase) else value
    new = sp.sympify(planted, locals=names)
    model = edited_model(model, sm, {method: [(index, original, new)]}, "Planted")
    system = system or own
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    batch = CheckBatch(model, system, states)
    results = run_checks(label, model, system, states, CORPUS_SEED, applicable_checks(model, system), batch)
    assert not all(r.passed for r in results), "the planted error must fail a check"
    findings = [f for f in explain(batch, results) if f.kind == "repair"]
    for f in findings:  # the confirmed words belong to a confirmed repair only
        assert (CONFIRMED_WORDS in f.message) is bool(f.details.get("confirmed")), f.message
    return findings, sm


def _confirmed(findings) -> list:
    return [f for f in findings if f.details.get("confirmed")]


@pytest.mark.parametrize(
    ("label", "method", "index", "planted", "exact", "coincidence"),
    [
        # M = m·l for m·l² with l = 0.5: l*m/2 gives the same numbers (l² = l/2)
        ("corpus_pendulum (", "mass_matrix", 0, "l*m", "l**2*m", "l*m/2"),
        # the cart-pole's M[2,2] without mp·l², I = mp·l²/3: 4·I gives the same numbers
        ("corpus_cart_pole", "mass_matrix", 3, "I", "I + l**2*mp", "4*I"),
        # the rod pendulum's M without m·lc², I = m·lc²/3
        ("corpus_pendulum_rod", "mass_matrix", 0, "I", "I + lc**2*m", "4*I"),
    ],
)
def test_a_coincidence_is_not_confirmed_and_the_exact_repair_is(
    label, method, index, planted, exact, coincidence
):
    findings, _ = _repairs(label, method, index, planted)
    first = findings[0]
    assert first.details["confirmed"], first.message
    assert sp.expand(sp.sympify(first.details["suggested"]) - sp.sympify(exact)) == 0, first.message
    assert "(the URDF rewritten for each)" in first.message
    assert all(
        sp.sympify(f.details["suggested"]) != sp.sympify(coincidence)
        for f in findings
        if f.details["suggested"]
    )


def test_a_coincidence_alone_is_named_as_one_not_as_a_repair():
    """V of the equal-rods double pendulum planted as 0: its difference, fitted, has the number
    3/4 = m1·lc1 + m2·l1 in it (m = 1, lc1 = 0.25, l1 = 0.5); that edit passes at the file's
    values only.  It is not printed as a repair: the sentence names it as a coincidence."""
    findings, _ = _repairs("corpus_double_pendulum", "potential_energy", 0, "0")
    (only,) = findings
    assert not only.details["checks_pass"] and not only.details["confirmed"]
    assert only.message.startswith("no repair")
    assert "V: 0 → -g*lc2*m2*cos(theta1 + theta2) - 3*g*cos(theta1)/4" in only.message
    assert "make(s) every check pass at these parameter values, but not at other values" in only.message
    assert "(the URDF rewritten for each): a coincidence of the values, not a repair" in only.message


def test_equal_parameters_moved_together_state_the_exchange():
    """m1 = m2, I1 = I2: I1 dropped from M[1,1] is put back as I2 (its twin), never confirmed, and
    the exchange that gives the planted edit is named with "the two agree where I1 = I2"."""
    entry = "I2 + m1*lc1**2 + m2*(l1**2 + lc2**2 + 2*l1*lc2*cos(theta2))"
    findings, _ = _repairs("corpus_double_pendulum", "mass_matrix", 0, entry)
    assert not _confirmed(findings)
    assert "I2 = I1 here and at every set (equal values are moved together)" in findings[0].message
    assert "the two agree where I1 = I2" in findings[0].message
    planted = sp.sympify("I1 + " + entry)
    assert any(sp.expand(sp.sympify(f.details["suggested"]) - planted) == 0 for f in findings)


def test_the_relation_two_edits_agree_under_is_one_equation_of_the_parameters():
    ((_, model, _, _),) = _targets("corpus_cart_pole")
    sm = SymbolicModel.of(type(model))
    inertia, mp, half = (sm.parameters[n] for n in ("I", "mp", "l"))
    theta = sm.angles[0]
    found = relation((3 * inertia - mp * half**2) * sp.cos(theta), sm)
    assert sp.cancel(found / (3 * inertia - mp * half**2)) in (1, -1)  # up to its sign
    two = (inertia - mp) * sp.cos(theta) + (inertia - half) * sp.sin(theta)  # two relations, not one
    assert relation(two, sm) is None


@pytest.mark.parametrize(
    ("start", "method", "index", "original_to_planted"),
    [
        ("cart_pole, model (Python)", "mass_matrix", 3, lambda e, p: p["I"]),  # mp·r² dropped
        ("triple_pendulum, model (Python)", "gravity", 1, lambda e, p: -e),  # a sign
        ("furuta_pendulum, model (Python)", "mass_matrix", 0, lambda e, p: 2 * e),  # a factor 2
    ],
)
def test_a_model_whose_parameters_all_move_keeps_its_exact_confirmed_repair(
    start, method, index, original_to_planted
):
    ((label, model, system, _),) = [t for t in shipped_targets() if t[0].startswith(start)]
    sm = SymbolicModel.of(type(model))
    value = sm.closed_forms[method]
    original = value[index] if isinstance(value, sp.MatrixBase) else value
    planted = original_to_planted(original, sm.parameters)
    edited = edited_model(model, sm, {method: [(index, original, planted)]}, "Planted")
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    batch = CheckBatch(edited, system, states)
    results = run_checks(label, edited, system, states, CORPUS_SEED, applicable_checks(edited, system), batch)
    first = next(f for f in explain(batch, results) if f.kind == "repair")
    assert first.details["confirmed"], first.message
    names = {p.name: p for p in sm.parameters.values()} | {s.name: s for g in sm.symbols.values() for s in g}
    restored = sp.sympify(first.details["suggested"], locals=names)
    assert sp.simplify(restored - original) == 0, first.message


def test_an_edit_of_what_no_check_compares_is_never_confirmed():
    """The cart-pole's f lost its input u: B[1,1] = 0 passes every check as well (aba takes B from
    the model on both sides), so it is printed, but not as confirmed."""
    ((label, model, system, _),) = [t for t in shipped_targets() if t[0].startswith("cart_pole, model (P")]
    sm = SymbolicModel.of(type(model))
    original = sm.closed_forms["f"][0]
    planted = original.subs(sm.symbols["u"][0], 0)
    edited = edited_model(model, sm, {"f": [(0, original, planted)]}, "Planted")
    states = sample_states(model, CORPUS_SAMPLES, CORPUS_SEED)
    batch = CheckBatch(edited, system, states)
    results = run_checks(label, edited, system, states, CORPUS_SEED, applicable_checks(edited, system), batch)
    repairs = [f for f in explain(batch, results) if f.kind == "repair"]
    assert repairs and not _confirmed(repairs)
    assert "no check compares B with the robot" in repairs[0].message


@pytest.mark.slow
def test_coincident_corpus_no_wrong_repair_confirmed_and_the_rest_stated(capsys):
    targets = [t for t in class_targets() if t[0].endswith(f"({COINCIDENT})")]
    assert len(targets) >= 4
    scores = []
    for label, model, system, _ in targets:
        chosen = sample_plants(SymbolicModel.of(type(model)), QUICK_PER_OPERATOR, CORPUS_SEED)
        scored = score_model(label, model, system, chosen)
        assert scored.clean, label
        scores += [s for s in scored.scores if s.detected]
    with capsys.disabled():
        confirmed = sum(s.confirmed for s in scores)
        stated = sum(s.ambiguity_stated for s in scores)
        print(
            f"\ncoincident corpus: {len(scores)} detected, {confirmed} confirmed, {stated} ambiguity stated"
        )
    assert len(scores) >= 40
    assert sum(s.wrong_confirmed for s in scores) == 0
    assert sum(s.confirmed or s.ambiguity_stated for s in scores) >= STATED_RATE * len(scores)
    assert sum(s.confirmed for s in scores) > 0 and sum(s.ambiguity_stated for s in scores) > 0


def _catalogue_entries() -> list[dict]:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - exercised on Python 3.10 only
        import tomli as tomllib
    text = shipped_file("examples", "diagnosis_corpus.toml").read_text(encoding="utf-8")
    return [m for m in tomllib.loads(text)["model"] if m["class"] == COINCIDENT]


def _shipped(spec: str):
    kind, _, name = spec.partition("/")
    return str(shipped_file(kind, name))


@pytest.mark.parametrize("entry", _catalogue_entries(), ids=lambda e: e["name"])
def test_the_untouched_coincident_models_pass_check(entry, capsys):
    args = ["--analytic", _shipped(entry["model"]), "--urdf", _shipped(entry["urdf"])]
    status = main(["check", *args, "--params", _shipped(entry["params"]), "--no-explain"])
    assert status == 0, capsys.readouterr().out


def test_a_repair_accepted_with_coriolis_and_skew_warning_is_never_confirmed():
    """The Furuta pendulum's C[1,2] with a term dropped: putting it, doubled, into C[1,1] gives the
    same C·q̇, and the repair accepted against the model's own warning (coriolis and skew warn) holds
    at every perturbed set — but C itself is not compared, so it is not printed as confirmed
    (the full corpus once printed this wrong edit as confirmed)."""
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.bench.explain import shipped_targets
    from pendverify.diagnosis.corpus import plants, score_model

    label, model, system, _ = next(t for t in shipped_targets() if t[0].startswith("furuta_pendulum"))
    chosen = [
        p
        for p in plants(SymbolicModel.of(type(model)))
        if (p.method, p.index, p.operator) == ("coriolis_matrix", 1, "drop")
    ]
    assert chosen, "the planted error of this test"
    (score,) = score_model(label, model, system, chosen).scores
    assert score.detected and not score.wrong_confirmed, score.message
    if score.repaired and not score.restored:  # a C with the same C·q̇: held, not confirmed
        assert "not confirmed" in score.message and "only C·q̇ is compared" in score.message, score.message


@pytest.mark.parametrize("planted", ["1.1*(I + lc**2*m)", "11*I/10 + 11*lc**2*m/10", "3*I + 3*lc**2*m/2"])
def test_a_wrong_number_written_in_an_entry_is_put_right_and_confirmed(planted):
    """A decimal factor (which SymPy spreads over the sum: 1.1·I + 1.1·lc²·m, so no one-term
    coefficient undoes it) or a wrong number on two terms: the number solved for, confirmed."""
    findings, _ = _repairs("corpus_pendulum_rod", "mass_matrix", 0, planted)
    first = findings[0]
    assert first.details["confirmed"], first.message
    assert sp.expand(sp.sympify(first.details["suggested"]) - sp.sympify("I + lc**2*m")) == 0, first.message


def test_a_decimal_factor_is_removed_from_the_users_own_text(tmp_path, capsys):
    """The repair as an edit of the string the user wrote, the whole number written as one."""
    text = shipped_file("examples", "corpus_pendulum_rod.toml").read_text()
    assert text.count('M = [["I + m*lc**2"]]') == 1
    planted = tmp_path / "decimal.toml"
    planted.write_text(text.replace('M = [["I + m*lc**2"]]', 'M = [["1.1*(I + m*lc**2)"]]'))
    urdf, params = (shipped_file("examples", f"corpus_pendulum_rod{s}") for s in (".urdf", "_params.toml"))
    assert main(["check", "--analytic", str(planted), "--urdf", str(urdf), "--params", str(params)]) == 1
    out = capsys.readouterr().out
    assert "M[1,1]: 1.1*(I + m*lc**2) → I + lc**2*m makes every check pass on every state, at these" in out
