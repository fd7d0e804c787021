"""stress on model files (``pendverify.stress.generic``): hard cases from the parameters' kinds and
the coordinates.  The command's table and JSON on a model file: ``test_stress.py``."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pendverify.checks.evidence import stress_verdict
from pendverify.checks.precision import UNSTABLE
from pendverify.cli import main
from pendverify.stress.framework import QUICK
from pendverify.stress.generic import run_generic

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def files(name: str, model: Path | None = None) -> tuple[str, str, str]:
    return (
        str(model or EXAMPLES / f"{name}.py"),
        str(EXAMPLES / f"{name}.urdf"),
        str(EXAMPLES / f"{name}.toml"),
    )


@pytest.mark.parametrize(
    "name", ("cart_pole", "hanging_double_pendulum", "furuta_pendulum", "triple_pendulum")
)
def test_stress_passes_on_the_example(name):
    report = run_generic(*files(name), QUICK)
    assert report.passed, [(r.name, r.notes) for r in report.results if r.failed]
    groups = {r.name.split(" ")[0] for r in report.results}
    assert {"nominal", "|θ|", "|q̇|", "g", "near-singular"} <= groups
    singular = next(r for r in report.results if r.name == "near-singular M")
    assert (
        singular.extras["refused"] > 0 and "verified at k = 0" in singular.extras["invariant"]
    )  # verified, then refused


def _m3_case(model: Path | None = None):
    report = run_generic(*files("triple_pendulum", model), QUICK, names=("m3 ×1e6",))
    (case,) = report.results
    return case


def test_triple_pendulum_inverse_that_loses_digits_is_a_warning_not_a_failure():
    """m3 × 1e6: the example's M⁻¹, adj(M)/det M expanded, cancels six digits (checks.precision);
    evaluated in 40 digits it agrees with Pinocchio, so minverse and aba warn."""
    case = _m3_case()
    note = "; ".join(case.notes)
    assert case.passed and stress_verdict(case).startswith("pass (warn")
    assert UNSTABLE in note and "minverse" in note
    double, precise = (
        float(x) for x in re.search(r"off by (\S+) in double .* and by (\S+) with", note).groups()
    )
    assert double > 1e-12 and precise < 1e-15  # six digits lost in double; none at 40 digits


def test_a_planted_error_in_the_same_inverse_still_fails(tmp_path):
    """A wrong M⁻¹ is wrong at any precision: M⁻¹ off by a relative 1e-4 fails minverse.

    (The case's states that are judged reach κ̃ ≈ 1e6, where minverse resolves about
    K·ε·((1 + |θ|)·c_T + (A − 1))·κ̃ ≈ 1.5e-13·κ̃ ≈ 1e-7 of ‖M̃⁻¹‖; 1e-6 would already hide at the
    refused states' κ̃ ≈ 1.2e7, which is why the trust rule refuses them.)"""
    text = (EXAMPLES / "triple_pendulum.py").read_text()
    old = "return adj / self.det_mass_matrix(q)"
    assert text.count(old) == 1
    planted = tmp_path / "triple.py"
    planted.write_text(text.replace(old, "return adj / (self.det_mass_matrix(q) * (1 + 1e-4))"))
    case = _m3_case(planted)
    note = "; ".join(case.notes)
    assert case.failed and "minverse" in note.split(";")[0] and "FAIL" in note
    assert UNSTABLE not in note


def test_a_closed_form_that_cannot_run_in_high_precision_is_judged_in_double(tmp_path):
    """np.cos on an array of mpmath numbers fails: no second judgement, the failure stands, and says why."""
    text = (EXAMPLES / "triple_pendulum.py").read_text()
    planted = tmp_path / "triple.py"
    planted.write_text(text.replace("cos = self.math.cos\n", "cos = np.cos\n"))
    assert planted.read_text() != text
    case = _m3_case(planted)
    assert case.failed and "FAIL minverse" in "; ".join(case.notes)


def test_a_planted_error_fails_a_generic_case(tmp_path):
    text = (EXAMPLES / "furuta_pendulum.py").read_text()
    planted = tmp_path / "furuta.py"
    planted.write_text(
        text.replace("[b, p.Jpxx + p.mp * p.lp**2]]", "[b, (p.Jpxx + p.mp * p.lp**2) * 1.000001]]")
    )
    assert planted.read_text() != text
    report = run_generic(*files("furuta_pendulum", planted), QUICK)
    assert not report.passed
    assert any(r.name != "nominal" and r.failed for r in report.results)


def test_cli_needs_the_three_files(capsys):
    """The parameters may be left out only when the model file gives PARAMS (cart_pole.py does not)."""
    model, urdf, _ = files("cart_pole")
    assert main(["stress", "--analytic", model, "--urdf", urdf]) == 2
    assert "give the parameter set (--params on the command line" in capsys.readouterr().err
    assert main(["stress", "--analytic", model]) == 2
    assert "give --urdf (and --params, unless the model file gives PARAMS) with --analytic" in (
        capsys.readouterr().err
    )


def test_the_report_says_what_is_derived_and_so_not_evidence(tmp_path, capsys):
    out = tmp_path / "stress.json"
    argv = ["stress", "--quick", "--analytic", str(EXAMPLES / "minimal_double_pendulum.py")]
    argv += ["--urdf", str(EXAMPLES.parent / "urdf" / "double_pendulum.urdf")]
    argv += ["--params", str(EXAMPLES / "minimal_double_pendulum.toml"), "--case", "nominal"]
    argv += ["--json", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "evidence:" in text and "det not run: det M is derived from M" in text
    evidence = json.loads(out.read_text())["evidence"]
    assert any("minverse not run" in line for line in evidence)
    assert any(line.startswith("derived, not hand-written: the gravity scale") for line in evidence)
