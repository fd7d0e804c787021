"""Mutation sensitivity: every non-equivalent single-term mutant of a seed is detected.

Also: equivalent mutants carry their reason, a method no check looks at leaves
survivors (the report says so and the command fails), and a mutant changes only
its own entry.
"""

from __future__ import annotations

import json
from collections import Counter

import numpy as np
import pytest

from pendverify.analytic import DoublePendulum
from pendverify.analytic.forms import ClosedForm
from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.checks.verdict import CHRISTOFFEL_CONSISTENT, NON_CHRISTOFFEL
from pendverify.cli import main
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for
from pendverify.symbolic.mutants import OPERATORS, generate
from pendverify.symbolic.mutate import numeric_model, run_mutation
from pendverify.symbolic.mutation_report import DETECTED, EQUIVALENT, SURVIVED
from pendverify.targets import Target

from ..conftest import default_params


def test_every_double_pendulum_mutant_is_detected_or_proved_equivalent(tmp_path, capsys):
    out_json = tmp_path / "mutants.json"
    assert main(["mutate", "--model", "double_pendulum", "--json", str(out_json)]) == 0
    out = capsys.readouterr().out
    assert "detection rate 100.0% (417/417 non-equivalent mutants), 6 equivalent" in out
    (report,) = json.loads(out_json.read_text())
    assert report["detection_rate"] == 1.0 and report["survived"] == 0
    assert report["mutants"] == 423 and report["detected"] == 417
    assert set(report["controls"]) == set(DoublePendulum.closed_forms) - {"disturbance_matrix"}  # W is 2×0
    equivalent = [o for o in report["outcomes"] if o["verdict"] == EQUIVALENT]
    reasons = Counter(o["operator"] for o in equivalent)
    assert reasons == {"swap θ": 3, "swap θ̇": 1, "move": 2}
    for o in equivalent:
        if o["operator"] == "move":  # a different C factorisation: same C·q̇, flagged, a warning
            assert o["reason"].startswith(NON_CHRISTOFFEL)
            assert "flagged by coriolis, skew (warning)" in o["reason"]
        else:
            assert o["reason"] == "identical expression after SymPy's canonical ordering"
    for o in report["outcomes"]:
        if o["verdict"] == DETECTED:
            assert o["checks"], o


def test_cart_mutants_of_m_c_and_f_are_all_detected(capsys):
    argv = ["mutate", "--model", "cart_double_pendulum"]
    for method in ("mass_matrix", "coriolis_matrix", "f"):
        argv += ["--method", method]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "detection rate 100.0% (202/202 non-equivalent mutants), 2 equivalent" in out
    assert "mass_matrix[1,2]: theta1 ↔ theta2 in cos(theta1 - theta2) — identical expression" in out


def test_generation_covers_every_operator():
    mutants = generate(SymbolicModel.of(DoublePendulum))
    assert set(OPERATORS) == {m.operator for m in mutants}
    assert len(
        {(m.method, tuple(c[0] for c in m.changes), tuple(c[2] for c in m.changes)) for m in mutants}
    ) == len(mutants)
    drop = next(m for m in mutants if m.description == "mass_matrix[0,0]: drop m1*r1**2")
    assert drop.operator == "drop" and len(drop.changes) == 1


def test_a_mutant_changes_only_its_own_entry():
    params = default_params("double_pendulum")
    model = DoublePendulum(params)
    sm = SymbolicModel.of(DoublePendulum)
    drop = next(m for m in generate(sm) if m.description == "mass_matrix[0,0]: drop m1*r1**2")
    mutated = numeric_model(model, sm, drop.method, drop.changes)
    q = np.array([0.3, -1.1])
    diff = model.mass_matrix(q) - mutated.mass_matrix(q)
    assert diff[0, 0] == pytest.approx(params.m1 * params.r1**2, rel=1e-14)
    assert np.all(diff.ravel()[1:] == 0)
    assert np.array_equal(model.gravity(q), mutated.gravity(q))


# --- what the verdicts look like when the checks cannot see a change ---------------------------
class WithDrawing(DoublePendulum):
    """Declares a closed form that no check reads: its mutants must survive."""

    closed_forms = {**DoublePendulum.closed_forms, "drawing_length": ClosedForm("")}  # noqa: RUF012

    def drawing_length(self):
        return np.array([self.params.l2])


def _target(cls, params):
    return Target(
        cls.name, cls(params), PinocchioSystem.for_model(DoublePendulum, urdf_for(params), params.g), "<test>"
    )


def test_survivors_are_reported_as_a_gap():
    report = run_mutation(
        _target(WithDrawing, default_params("double_pendulum")), 4, methods=("drawing_length",)
    )
    assert [o.verdict for o in report.outcomes] == [SURVIVED] * 3
    assert not report.passed and report.rate == 0.0
    assert all("not zero: a gap in the checks" in o.reason for o in report.outcomes)


def test_equivalence_for_one_parameter_set_is_named():
    params = default_params("double_pendulum").replace(b2=0.0)
    report = run_mutation(_target(DoublePendulum, params), 4, methods=("damping_matrix",))
    verdicts = {o.description: (o.verdict, o.reason) for o in report.outcomes}
    assert verdicts["damping_matrix[0,0]: drop b1"][0] == DETECTED
    verdict, reason = verdicts["damping_matrix[1,1]: drop b2"]
    assert verdict == EQUIVALENT
    assert reason == "equivalent for this parameter set only (the change vanishes at b2 as given)"
    assert report.passed


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--model", "triple"], "unknown model 'triple'"),
        (["--urdf", "x.urdf"], "--urdf and --params go with --analytic"),
        (["--model", "double_pendulum", "--method", "nosuch"], "unknown closed form 'nosuch'"),
        (["--model", "double_pendulum", "--analytic", "x.py"], "not both"),
    ],
)
def test_bad_mutate_command_lines_are_errors(capsys, argv, message):
    assert main(["mutate", *argv]) == 2
    assert message in capsys.readouterr().err


def test_a_christoffel_consistent_refactoring_is_an_equivalent_mutant():
    """C + m1·[q̇]× keeps C·q̇ and the skew property: reported as Christoffel-consistent, a warning."""
    import sympy as sp

    from pendverify.analytic import CartDoublePendulum
    from pendverify.checks.sampling import sample_states
    from pendverify.symbolic.mutants import Mutant
    from pendverify.symbolic.mutate import classify

    params = default_params("cart_double_pendulum")
    model = CartDoublePendulum(params)
    system = PinocchioSystem.for_model(CartDoublePendulum, urdf_for(params), params.g)
    sm = SymbolicModel.of(CartDoublePendulum)
    C = sm.closed_forms["coriolis_matrix"]
    v, m1 = sm.symbols["v"], sm.parameters["m1"]
    cross = sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    changes = tuple((i, C[i], C[i] + m1 * cross[i]) for i in range(9) if cross[i] != 0)
    mutant = Mutant("coriolis_matrix", "move", "C + m1·[q̇]×", changes)
    outcome = classify(model, system, sm, mutant, [sample_states(model, 4, 1)], 1)
    assert outcome.verdict == EQUIVALENT
    assert outcome.reason.startswith(CHRISTOFFEL_CONSISTENT)
    assert "flagged by coriolis (warning)" in outcome.reason  # Pinocchio's C is another one


# --- the bounds: mutants per closed form, and the wall-clock backstop ---------------------------
def test_a_form_above_the_mutant_bound_runs_a_seeded_sample_and_says_what_it_left(monkeypatch, capsys):
    """The double pendulum's M has 51 mutants; at a bound of 10, ten run (the same ten for the same
    seed), every one detected, and the report names the 41 not run; exit 0 (none survived)."""
    monkeypatch.setenv("PENDVERIFY_MAX_MUTANTS", "10")
    argv = ["mutate", "--model", "double_pendulum", "--method", "mass_matrix", "--samples", "8"]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "detection rate 100.0% (10/10 non-equivalent mutants)" in out
    assert "drawn with the seed: mass_matrix 10 of 51; not run: 41" in out
    target = _target(DoublePendulum, default_params("double_pendulum"))
    first, again = (run_mutation(target, 4, methods=("mass_matrix",)) for _ in range(2))
    assert [o.description for o in first.outcomes] == [o.description for o in again.outcomes]
    assert first.bounds.as_dict()["sampled"] == {"mass_matrix": 51}
    other = run_mutation(target, 4, seed=7, methods=("mass_matrix",))
    assert [o.description for o in other.outcomes] != [o.description for o in first.outcomes]


def test_a_sampled_run_still_fails_on_a_gap(monkeypatch, capsys):
    """The bound does not hide a survivor among the mutants it runs: exit 1."""
    monkeypatch.setenv("PENDVERIFY_MAX_MUTANTS", "2")
    report = run_mutation(
        _target(WithDrawing, default_params("double_pendulum")), 4, methods=("drawing_length",)
    )
    assert [o.verdict for o in report.outcomes] == [SURVIVED] * 2 and not report.passed
    assert report.bounds.sampled() == {"drawing_length": 3}


class _Clock:
    """A clock that advances ``step`` seconds each time it is read: the wall-clock bound is reached
    after a fixed number of mutants whatever the machine's speed."""

    def __init__(self, step: float):
        self.now, self.step = 0.0, step

    def perf_counter(self) -> float:
        self.now += self.step
        return self.now


def test_the_run_stops_at_its_wall_clock_bound_and_names_what_it_did_not_run(monkeypatch):
    import pendverify.symbolic.mutate as mutate_module
    from pendverify.symbolic.mutation_report import format_report

    monkeypatch.setenv("PENDVERIFY_MUTATE_SECONDS", "120")
    # started at 50; 50 s elapsed before the first mutant, 100 s before the second, 150 s: two run
    monkeypatch.setattr(mutate_module, "time", _Clock(50.0))
    report = run_mutation(
        _target(DoublePendulum, default_params("double_pendulum")), 4, methods=("gravity", "mass_matrix")
    )
    # the methods take turns: one mutant of each ran
    assert [o.method for o in report.outcomes] == ["mass_matrix", "gravity"] and report.passed
    assert report.bounds.not_run == {"mass_matrix": 50, "gravity": 32}
    text = format_report(report)
    assert "stopped at its bound of 120 s (PENDVERIFY_MUTATE_SECONDS): 2 of 84 mutants run; not run: " in text


def test_a_mutant_uses_its_models_generated_code_except_for_the_mutated_method():
    from pendverify.numerics.codegen.vectorised import generated

    params = default_params("double_pendulum")
    sm = SymbolicModel.of(DoublePendulum)
    drop = next(m for m in generate(sm) if m.description == "mass_matrix[0,0]: drop m1*r1**2")
    mutated = numeric_model(DoublePendulum(params), sm, drop.method, drop.changes)
    base, module = generated(DoublePendulum), generated(type(mutated))
    assert "mass_matrix" not in module.FUNCTIONS and "mass_matrix" in base.FUNCTIONS
    assert "edited numerically" in module.MISSING["mass_matrix"]
    assert module.FUNCTIONS == {m: f for m, f in base.FUNCTIONS.items() if m != "mass_matrix"}


def test_a_method_that_reads_the_mutated_one_is_not_taken_from_the_models_generated_code():
    """The triple pendulum's hand-written q̈ calls its generalized_force: a mutant of that force must
    reach q̈, so q̈ runs the mutant's own Python (its generated code holds the original force)."""
    from pathlib import Path

    from pendverify.analytic.params import load_parameter_file
    from pendverify.api import load_model
    from pendverify.numerics.codegen.vectorised import generated

    examples = Path(__file__).resolve().parents[2] / "examples"
    cls = load_model(examples / "triple_pendulum.py")
    params = load_parameter_file(examples / "triple_pendulum.toml", {cls.name: cls.params_type})[2]
    sm = SymbolicModel.of(cls)
    mutant = next(m for m in generate(sm) if m.method == "generalized_force" and m.operator == "scale")
    module = generated(type(numeric_model(cls(params), sm, mutant.method, mutant.changes)))
    assert "acceleration" in generated(cls).FUNCTIONS and "acceleration" not in module.FUNCTIONS
    assert "mass_matrix" in module.FUNCTIONS  # M does not read the force: shared
