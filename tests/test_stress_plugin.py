"""stress on model files: generic hard cases from the parameters' kinds and the coordinates."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pendverify.cli import main
from pendverify.stress.framework import QUICK
from pendverify.stress.generic import run_generic

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def files(name: str, model: Path | None = None) -> tuple[str, str, str]:
    return (
        str(model or EXAMPLES / f"{name}.py"),
        str(EXAMPLES / f"{name}.urdf"),
        str(EXAMPLES / f"{name}.toml"),
    )


@pytest.mark.parametrize("name", ("cart_pole", "hanging_double_pendulum", "furuta_pendulum"))
def test_stress_passes_on_the_example(name):
    report = run_generic(*files(name), QUICK)
    assert report.passed, [(r.case, r.note) for r in report.results if not r.passed]
    groups = {r.case.split(" ")[0] for r in report.results}
    assert {"nominal", "|θ|", "|q̇|", "g", "near-singular"} <= groups
    singular = next(r for r in report.results if r.case == "near-singular M")
    assert singular.refused > 0 and "verified at k = 0" in singular.invariant  # verified, then refused


def test_triple_pendulum_fails_only_where_its_hand_written_inverse_loses_digits():
    """m3 × 1e6: κ̃ ≈ 1e7, and the adjugate/det M⁻¹ of the example loses digits as ε·κ̃²
    (3.9e-4 against the LU inverse of the same M), which the minverse and aba checks see."""
    report = run_generic(*files("triple_pendulum"), QUICK)
    failed = [r for r in report.results if not r.passed]
    assert [r.case for r in failed] == ["m3 ×1e6"]
    assert "minverse" in failed[0].note
    assert any("l3 (length): not varied" in note for note in report.notes)


def test_a_planted_error_fails_a_generic_case(tmp_path):
    text = (EXAMPLES / "furuta_pendulum.py").read_text()
    planted = tmp_path / "furuta.py"
    planted.write_text(
        text.replace("[b, p.Jpxx + p.mp * p.lp**2]]", "[b, (p.Jpxx + p.mp * p.lp**2) * 1.000001]]")
    )
    assert planted.read_text() != text
    report = run_generic(*files("furuta_pendulum", planted), QUICK)
    assert not report.passed
    assert any(r.case != "nominal" and not r.passed for r in report.results)


def test_cli_table_notes_and_json(tmp_path, capsys):
    out = tmp_path / "stress.json"
    model, urdf, params = files("cart_pole")
    argv = ["stress", "--quick", "--analytic", model, "--urdf", urdf, "--params", params, "--json", str(out)]
    assert main(argv) == 0
    text = capsys.readouterr().out
    for expected in (
        "ratio",
        "refused",
        "mc ×1e-6",
        "near-singular M",
        "worst error/tolerance",
        "not varied:",
    ):
        assert expected in text
    assert "parameter bx (damping)" in text
    report = json.loads(out.read_text())
    assert report["passed"] is True and all("verdict" in r for r in report["results"])


def test_cli_needs_the_three_files(capsys):
    model, urdf, _ = files("cart_pole")
    assert main(["stress", "--analytic", model, "--urdf", urdf]) == 2
    assert "give --urdf and --params with --analytic" in capsys.readouterr().err
