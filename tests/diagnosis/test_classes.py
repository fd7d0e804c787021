"""Classes of model the repair search used to leave without a repair, each with a model of the
diagnosis corpus (``examples/diagnosis_corpus.toml``): one error of the class is planted in a copy
of the corpus file and the exact repair is asserted; the untouched model gets none.

* **A C that is a valid C·q̇ but not the Christoffel C** (Tedrake's acrobot,
  ``examples/corpus_acrobot_tedrake.toml``): ``coriolis`` and ``skew`` warn on the untouched
  model; a repair brings the edited model back there (``pendverify.diagnosis.acceptance``).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pendverify.bench.explain import _target as load_target
from pendverify.bench.explain import class_targets
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.diagnosis.acceptance import accepted
from pendverify.diagnosis.repair import search_repair

from ..conftest import SEED

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
TEDRAKE = EXAMPLES / "corpus_acrobot_tedrake.toml"
TEDRAKE_ARGS = (
    "--urdf",
    str(EXAMPLES / "corpus_acrobot_tedrake.urdf"),
    "--params",
    str(EXAMPLES / "corpus_acrobot_tedrake_params.toml"),
)


def _planted(tmp_path, source: Path, right: str, wrong: str) -> Path:
    text = source.read_text()
    assert text.count(right) == 1, right
    path = tmp_path / f"planted_{source.name}"
    path.write_text(text.replace(right, wrong))
    return path


def _repairs(tmp_path, capsys, model: Path, *args) -> tuple[str, list[dict]]:
    out_json = tmp_path / "report.json"
    status = main(["check", "--analytic", str(model), *args, "--json", str(out_json)])
    out = capsys.readouterr().out
    assert status == 1, out
    (findings,) = json.loads(out_json.read_text())["diagnoses"].values()
    return out, [f for f in findings if f["kind"] == "repair"]


def _target(name: str):
    return next((m, s) for label, m, s, _ in class_targets() if label.startswith(f"{name} ("))


def _results(model, system):
    states = sample_states(model, 12, SEED)
    batch = CheckBatch(model, system, states)
    return batch, run_checks("t", model, system, states, SEED, applicable_checks(model, system), batch)


# --- a C that is not the Christoffel C ----------------------------------------------------------
@pytest.mark.parametrize(
    ("right", "wrong", "repair"),
    [
        ('"I2"],\n]', '"2*I2"],\n]', "M[2,2]: 2*I2 → I2"),
        (
            '["m2*l1*lc2*sin(q2)*dq1", "0"]',
            '["-m2*l1*lc2*sin(q2)*dq1", "0"]',
            "C[2,1]: -dq1*l1*lc2*m2*sin(q2) → ",
        ),
        (
            '"m2*g*lc2*sin(q1 + q2)"',
            '"m2*g*lc2*cos(q1 + q2)"',
            "H[2]: g*lc2*m2*cos(q1 + q2) → g*lc2*m2*sin(q1 + q2)",
        ),
    ],
)
def test_an_error_in_a_model_whose_c_is_not_christoffel_is_repaired(tmp_path, capsys, right, wrong, repair):
    planted = _planted(tmp_path, TEDRAKE, right, wrong)
    out, (found,) = _repairs(tmp_path, capsys, planted, *TEDRAKE_ARGS)
    assert found["checks_pass"] and found["message"].startswith(repair), found["message"]
    assert found["warns"] == (
        "coriolis and skew still warn, as for the model as written: "
        "its C is a valid C·q̇, not the Christoffel C"
    )
    assert f"{repair}" in out


def test_the_untouched_non_christoffel_model_passes_with_its_warning_and_gets_no_repair():
    model, system = _target("acrobot_tedrake")
    batch, results = _results(model, system)
    assert {r.check for r in results if not r.passed} == {"coriolis", "skew"}  # before the verdict
    assert accepted(results)
    assert {r.check: r.status for r in results}["coriolis"] == "warn"
    repairs, why = search_repair(batch, 10.0)
    assert repairs == [] and "no single entry" in why


def test_a_wrong_c_qdot_is_not_accepted_as_the_non_christoffel_warning(tmp_path):
    """The rule demotes coriolis and skew only when C·q̇ is right: a C row that is wrong fails rnea."""
    planted = _planted(tmp_path, TEDRAKE, '["m2*l1*lc2*sin(q2)*dq1", "0"]', '["m2*l1*lc2*sin(q2)*dq2", "0"]')
    model, system = load_target(planted, *TEDRAKE_ARGS[1::2])
    _, results = _results(model, system)
    assert not accepted(results)
    assert {r.check for r in results if not r.passed} >= {"rnea", "coriolis", "skew"}
