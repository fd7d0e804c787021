"""The diagnosis of a failing model, end to end: the entries, the shape, the repair in the model's
own notation, everywhere the verdict goes (text, --json, JUnit, the review page, assert_verified),
and nothing on a model that passes.

Each test plants one error in a shipped model file (LaTeX, text or a Python class) and asserts
what the report says; the seeds are the project's (``SEED``) and the CLI's default.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pendverify import api
from pendverify.analytic import DoublePendulum
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.finding import KINDS, QUANTITIES
from pendverify.diagnosis.parameters import identify_parameters
from pendverify.diagnosis.repair import search_repair
from pendverify.robot.system import PinocchioSystem
from pendverify.robot.writer import urdf_for
from pendverify.testing import assert_verified
from pendverify.viz.review import diagnosis_block

from ..conftest import SEED, default_params

REPO = Path(__file__).resolve().parents[2]
DP_URDF = REPO / "urdf" / "double_pendulum.urdf"
DP_PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"


def _latex_with_2delta(tmp_path) -> Path:
    """The reference double pendulum's LaTeX with ``2\\delta`` typed for ``\\delta`` in M's last entry."""
    text = (REPO / "examples" / "double_pendulum_latex.toml").read_text()
    for x in ("\\theta_2", "x_2"):
        right = f"\\\\ \\delta + \\beta\\cos({x}) & \\delta \\end{{bmatrix}}"
        assert right in text
        text = text.replace(right, right.replace("& \\delta", "& 2\\delta"))
    path = tmp_path / "typo.toml"
    path.write_text(text)
    return path


def _check(tmp_path, capsys, *args) -> tuple[int, str, dict]:
    out_json = tmp_path / "report.json"
    status = main(["check", *args, "--json", str(out_json)])
    return status, capsys.readouterr().out, json.loads(out_json.read_text())


def test_a_latex_typo_is_named_shaped_and_repaired_in_latex(tmp_path, capsys):
    typo = _latex_with_2delta(tmp_path)
    status, out, report = _check(
        tmp_path, capsys, "--analytic", str(typo), "--urdf", str(DP_URDF), "--params", str(DP_PARAMS)
    )
    assert status == 1
    assert "M[2,2] (theta2, theta2): hand 0.10444, Pinocchio 0.05222" in out
    assert "hand − Pinocchio = 0.05222 (constant, residual" in out
    assert "M[2,2]: 2\\delta → \\delta makes every check pass on every state" in out
    (findings,) = report["diagnoses"].values()
    assert {f["kind"] for f in findings} <= set(KINDS)
    assert {f["quantity"] for f in findings} - {None} <= set(QUANTITIES)
    (repair,) = [f for f in findings if f["kind"] == "repair"]
    assert repair["quantity"] == "M" and repair["index"] == [2, 2] and repair["checks_pass"] is True
    assert repair["written"] == "2*I2 + 2*m2*r2**2" and repair["suggested"] == "I2 + m2*r2**2"
    assert repair["suggested_source"] == "\\delta"
    assert str(typo) in repair["location"] and "key M" in repair["location"]
    entry = next(f for f in findings if f["kind"] == "entry" and f["quantity"] == "M")
    assert entry["index"] == [2, 2]


def test_the_repair_it_prints_is_the_one_that_passes(tmp_path, capsys):
    """The suggested entry, written back into the file, passes every check (the confirmation is real)."""
    typo = _latex_with_2delta(tmp_path)
    fixed = tmp_path / "fixed.toml"
    fixed.write_text(typo.read_text().replace("& 2\\delta", "& \\delta"))
    status, _, _ = _check(
        tmp_path, capsys, "--analytic", str(fixed), "--urdf", str(DP_URDF), "--params", str(DP_PARAMS)
    )
    assert status == 0


def test_no_explain_skips_the_diagnosis_and_keeps_the_verdict(tmp_path, capsys):
    typo = _latex_with_2delta(tmp_path)
    args = ("--analytic", str(typo), "--urdf", str(DP_URDF), "--params", str(DP_PARAMS))
    status, out, report = _check(tmp_path, capsys, *args, "--no-explain")
    assert status == 1 and "diagnosis" not in out and report["diagnoses"] == {}


def test_a_text_model_typo_is_repaired_in_sympy_syntax(tmp_path, capsys):
    text = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
    good = '"g*m2*r2*cos(theta1 + theta2)",'
    assert good in text
    path = tmp_path / "typo_text.toml"
    path.write_text(text.replace(good, '"g*m2*r2*sin(theta1 + theta2)",'))
    params = REPO / "examples" / "minimal_double_pendulum.toml"
    status, out, report = _check(
        tmp_path, capsys, "--analytic", str(path), "--urdf", str(DP_URDF), "--params", str(params)
    )
    assert status == 1
    assert "H[2] (theta2): hand" in out
    assert "H[2]: g*m2*r2*sin(theta1 + theta2) → g*m2*r2*cos(theta1 + theta2) makes every check pass" in out
    (repair,) = [f for f in next(iter(report["diagnoses"].values())) if f["kind"] == "repair"]
    assert "key H" in repair["location"] and repair["suggested_source"] == "g*m2*r2*cos(theta1 + theta2)"


class SignFlipped(DoublePendulum):
    """A sign flipped in one C entry (the issue's example): −β sin θ2 θ̇1 for β sin θ2 θ̇1."""

    def seed_coriolis_matrix(self, q, v):
        C = np.array(super().seed_coriolis_matrix(q, v), dtype=object)
        C[1, 0] = -C[1, 0]
        return C


def _batch(model, params, samples=30):
    system = PinocchioSystem.for_params(params)
    states = sample_states(model, samples, SEED)
    batch = CheckBatch(model, system, states)
    results = run_checks("t", model, system, states, SEED, applicable_checks(model, system), batch)
    return batch, results


def test_a_python_class_is_repaired_as_a_python_expression_with_its_method():
    params = default_params("double_pendulum")
    batch, results = _batch(SignFlipped(params), params)
    assert not all(r.passed for r in results)
    findings = explain(batch, results)
    repair = next(f for f in findings if f.kind == "repair")
    assert repair.details["checks_pass"] is True
    assert repair.details["suggested"] == "dtheta1*l1*m2*r2*sin(theta2)"
    assert repair.details["written"] == "-dtheta1*l1*m2*r2*sin(theta2)"
    assert "SignFlipped.seed_coriolis_matrix, entry seed_coriolis_matrix[2,1]" in repair.details["location"]
    assert "Cqdot" in {f.quantity for f in findings if f.kind == "entry"}


def test_every_missing_damper_is_named_not_only_the_first(tmp_path, capsys):
    params = default_params("double_pendulum")
    toml = tmp_path / "undamped.toml"
    toml.write_text(params.replace(b1=0.0, b2=0.0).to_toml())
    urdf = tmp_path / "damped.urdf"
    urdf.write_text(DP_URDF.read_text())
    status, _, report = _check(tmp_path, capsys, "--params", str(toml), "--urdf", str(urdf))
    assert status == 1
    named = {tuple(f["index"]) for f in next(iter(report["diagnoses"].values())) if f["quantity"] == "D"}
    assert {(1, 1), (2, 2)} <= named


def test_a_passing_model_has_no_diagnosis_and_no_repair_is_searched_on_it():
    params = default_params("double_pendulum")
    model = DoublePendulum(params)
    batch, results = _batch(model, params)
    assert all(r.passed for r in results)
    assert api.check("double_pendulum", params=params, erd=False, samples=10).diagnoses == {}
    # called directly on the correct model anyway: nothing disagrees, nothing is claimed
    repairs, why = search_repair(batch, 10.0)
    assert repairs == [] and "no single entry" in why
    assert identify_parameters(batch) == []


def test_the_diagnosis_reaches_junit_the_review_page_and_assert_verified(tmp_path, capsys):
    typo = _latex_with_2delta(tmp_path)
    junit = tmp_path / "report.xml"
    args = ["check", "--analytic", str(typo), "--urdf", str(DP_URDF), "--params", str(DP_PARAMS)]
    assert main([*args, "--junit", str(junit)]) == 1
    capsys.readouterr()
    xml = junit.read_text()
    assert "diagnosis: M[2,2]: 2\\delta → \\delta makes every check pass" in xml
    report = api.check(typo, DP_URDF, DP_PARAMS)
    page = diagnosis_block(report)
    assert "<strong>repair</strong> M[2,2]: 2\\delta → \\delta" in page
    with pytest.raises(AssertionError, match=r"M\[2,2\]: 2\\delta → \\delta makes every check pass"):
        assert_verified(typo, DP_URDF, DP_PARAMS)


@pytest.mark.parametrize(
    ("planted", "pair"),
    [
        # a wrong number (a sign and a factor 2 at once): one edit of the number, not two
        ("- 4*m2*l1*r2*cos(theta2)", False),
        # sin for cos and 6 for 2 in the same term: no single edit passes, the pair does; an added
        # term that fits the numbers but not the units (m2·r2 in M[1,1], kg·m where kg·m² is due)
        # is not offered instead
        ("+ 6*m2*l1*r2*sin(theta2)", True),
    ],
)
def test_two_edits_in_one_entry_are_found_when_no_single_edit_is_enough(tmp_path, capsys, planted, pair):
    text = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
    good = '"I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2) + 2*m2*l1*r2*cos(theta2)"'
    path = tmp_path / "two.toml"
    path.write_text(text.replace(good, good.replace("+ 2*m2*l1*r2*cos(theta2)", planted)))
    params = REPO / "examples" / "minimal_double_pendulum.toml"
    status, _, report = _check(
        tmp_path, capsys, "--analytic", str(path), "--urdf", str(DP_URDF), "--params", str(params)
    )
    assert status == 1
    (repair,) = [f for f in next(iter(report["diagnoses"].values())) if f["kind"] == "repair"]
    assert repair["checks_pass"] is True and repair["confirmed"] is True
    assert ("(two edits: " in repair["message"]) is pair, repair["message"]
    assert repair["suggested"] == "I1 + I2 + 2*l1*m2*r2*cos(theta2) + m1*r1**2 + m2*(l1**2 + r2**2)"


def test_the_diagnosis_is_loaded_only_when_a_model_fails():
    """Importing the check path does not load SymPy or the searches: a passing run starts as fast
    as before the diagnosis existed (they are imported when a model fails)."""
    code = (
        "import sys, pendverify.cli, pendverify.checks.verification; "
        "print(sorted(m for m in ('sympy', 'pendverify.diagnosis.explain') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def test_which_inertial_parameters_a_model_assumes(tmp_path):
    """``api.implied_parameters``: the reference model against a URDF whose link 2 weighs half as
    much again is this robot with other parameters (exact), not the URDF's own (agrees false),
    and every combination that differs involves link 2; against its own URDF, all agree."""
    params = default_params("double_pendulum")
    heavy = tmp_path / "heavy.urdf"
    heavy.write_text(urdf_for(params.replace(m2=1.5 * params.m2)))
    implied = api.implied_parameters("double_pendulum", heavy, DP_PARAMS, samples=20)
    assert implied.exact and not implied.agrees
    differing = [c.name for c in implied.combinations if c.differs]
    assert differing and all("link2" in name for name in differing), differing
    own = api.implied_parameters("double_pendulum", DP_URDF, DP_PARAMS, samples=20)
    assert own.exact and own.agrees and not any(c.differs for c in own.combinations)


# --- the repair in the user's own text ------------------------------------------------------------
def _latex_planted(tmp_path, good: str, bad: str) -> Path:
    """The reference double pendulum's LaTeX with ``good`` typed as ``bad`` in both of its displays
    (θ and x notation: ``good`` is written with θ, and x_k stands for θ_k in the second)."""
    text = (REPO / "examples" / "double_pendulum_latex.toml").read_text()
    for old, new in ((good, bad), (good.replace("\\theta_", "x_"), bad.replace("\\theta_", "x_"))):
        assert text.count(old) == 1, old
        text = text.replace(old, new)
    path = tmp_path / "planted.toml"
    path.write_text(text)
    return path


def _repair_of(tmp_path, capsys, path, urdf=DP_URDF, params=DP_PARAMS) -> dict:
    status, _, report = _check(
        tmp_path, capsys, "--analytic", str(path), "--urdf", str(urdf), "--params", str(params)
    )
    assert status == 1
    repair = next(f for f in next(iter(report["diagnoses"].values())) if f["kind"] == "repair")
    assert repair["checks_pass"] is True, repair["message"]
    return repair


def test_a_latex_sign_error_is_repaired_as_the_users_string_with_one_sign_changed(tmp_path, capsys):
    good = "\\alpha + 2\\beta\\cos(\\theta_2) & "
    path = _latex_planted(tmp_path, good, good.replace("+", "-"))
    repair = _repair_of(tmp_path, capsys, path)
    assert repair["index"] == [1, 1]
    assert repair["suggested_source"] == "\\alpha + 2\\beta\\cos(\\theta_2)"  # the user's own text
    assert (
        "M[1,1]: \\alpha - 2\\beta\\cos(\\theta_2) → \\alpha + 2\\beta\\cos(\\theta_2) makes"
        in repair["message"]
    )


def test_a_latex_term_rewritten_keeps_every_other_term_as_the_user_wrote_it(tmp_path, capsys):
    """sin typed for cos in H[1]'s first term: that one word of the user's text is replaced (never
    SymPy's ``\\cos{\\left(\\theta_{1} \\right)}``), the rest of the entry is the user's text."""
    good = "m_1gr_1\\cos(\\theta_1) + m_2g(l_1\\cos(\\theta_1)"
    path = _latex_planted(tmp_path, good, good.replace("\\cos", "\\sin", 1))
    repair = _repair_of(tmp_path, capsys, path)
    rest = " + m_2g(l_1\\cos(\\theta_1) + r_2\\cos(\\theta_1 + \\theta_2))"
    source = repair["suggested_source"]
    assert source.endswith(rest) and "\\left" not in source, source
    assert source[: -len(rest)] == "m_1gr_1\\cos(\\theta_1)", source
    assert repair["message"].startswith(f"H[1]: m_1gr_1\\sin(\\theta_1){rest} → {source} makes")


def test_a_text_model_repair_is_the_users_text_as_written(tmp_path, capsys):
    """The user's order of terms and factors is kept (SymPy would print 2*l1*m2*r2*cos(theta2) first)."""
    text = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
    good = "I1 + I2 + m1*r1**2 + m2*(l1**2 + r2**2) + 2*m2*l1*r2*cos(theta2)"
    path = tmp_path / "sign.toml"
    path.write_text(text.replace(good, good.replace("+ 2*m2", "- 2*m2")))
    params = REPO / "examples" / "minimal_double_pendulum.toml"
    repair = _repair_of(tmp_path, capsys, path, params=params)
    assert repair["suggested_source"] == good
    assert repair["suggested"] == "I1 + I2 + 2*l1*m2*r2*cos(theta2) + m1*r1**2 + m2*(l1**2 + r2**2)"
