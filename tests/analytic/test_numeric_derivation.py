"""M, H and C·q̇ derived numerically from q̈ as code where B is square (``analytic.numeric_derivation``).

No false alarm: gymnasium's acrobot with a torque on BOTH joints (B = I; its ``_dsdt`` with
φ1 − τ1 in place of φ1), the double pendulum's "q̈ as code" form (``np.linalg.solve``) and that
pendulum with link 2 tiny (r2, I2 small: κ(M) ~ 1e4) pass crba, gravity, rnea and aba.  A
planted 1 % error in one inertia term fails crba, in one gravity term fails gravity, in one
velocity term fails rnea.  Code not affine in u is refused in one line naming the state; the
checks that need V, a matrix C, det M or M⁻¹ say why they did not run.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import tomllib

import pendverify
from pendverify.analytic.double_pendulum import DoublePendulumParams
from pendverify.api import stress
from pendverify.errors import PendverifyError
from pendverify.robot.writer import urdf_for
from tests.analytic.test_same_verdicts import CODE, MINIMAL_PARAMS, URDF
from tests.error_message import one_error

gymnasium = pytest.importorskip("gymnasium")
from gymnasium.envs.classic_control.acrobot import AcrobotEnv  # noqa: E402

from tests.analytic.gym_robots import acrobot_urdf  # noqa: E402
from tests.analytic.test_python_dynamics import ACROBOT, acrobot_values  # noqa: E402

SAMPLES = 40
DERIVED_CHECKS = {"crba", "rnea", "gravity", "aba", "damping"}

# gymnasium's _dsdt with a torque on joint 1 too: d1 θ̈1 + d2 θ̈2 + φ1 = τ1, so φ1 − τ1 in place of φ1
BOTH_TORQUES = (
    ACROBOT.replace("    a = u[0]\n", "    tau1, a = u[0], u[1]\n")
    .replace("        + phi2\n    )\n", "        + phi2\n        - tau1\n    )\n")
    .replace('"inputs": ["a"],', '"inputs": ["tau1", "a"],')
    .replace('"B": [["0"], ["1"]],', '"B": [["1", "0"], ["0", "1"]],')
)


def _code(tmp_path: Path, old: str = "", new: str = "") -> Path:
    """The double pendulum's q̈ as code (test_same_verdicts' form), ``old`` replaced by ``new``."""
    assert old in CODE and CODE.count(old) == (1 if old else len(CODE) + 1)
    path = tmp_path / "double_pendulum_code.py"
    head = "from tests.analytic.mechanics_double_pendulum import DECLARATION\n"
    path.write_text(head + CODE.replace(old, new))
    return path


def _statuses(report) -> dict[str, str]:
    return {check: report[check].status for check in report.checks}


def _notes(report) -> str:
    return " ".join(n for ns in report.notes.values() for n in ns)


def test_the_acrobot_with_torques_on_both_joints_passes_crba_gravity_rnea(tmp_path):
    assert BOTH_TORQUES.count("tau1") == 3
    model = tmp_path / "acrobot_both.py"
    model.write_text(BOTH_TORQUES)
    urdf = tmp_path / "acrobot.urdf"
    urdf.write_text(acrobot_urdf(AcrobotEnv()))
    report = pendverify.check(model, urdf, acrobot_values(), samples=SAMPLES, explain=False)
    statuses = _statuses(report)
    assert set(statuses) == {"crba", "rnea", "gravity", "aba"}, statuses
    assert all(s == "pass" for s in statuses.values()), statuses
    notes = _notes(report)
    assert "derived from the code's q̈" in notes
    assert "energy not run" in notes and "not V" in notes
    assert "coriolis, skew not run" in notes
    assert "det not run" in notes and "minverse not run" in notes
    for check in ("crba", "gravity", "rnea"):
        (result,) = report[check]
        assert any("derived numerically from the model's q̈" in n for n in result.notes), result.notes


def test_the_double_pendulum_code_passes_and_names_what_is_derived(tmp_path):
    report = pendverify.check(_code(tmp_path), URDF, MINIMAL_PARAMS, samples=SAMPLES, explain=False)
    statuses = _statuses(report)
    assert set(statuses) == DERIVED_CHECKS and all(s == "pass" for s in statuses.values()), statuses


def _badly_conditioned(tmp_path: Path) -> tuple[Path, dict]:
    """The minimal double pendulum with link 2 tiny: r2 = 5 mm, I2 = 1e-7 kg·m²."""
    values = {**tomllib.loads(MINIMAL_PARAMS.read_text())["parameters"], "r2": 0.005, "I2": 1e-7}
    urdf = tmp_path / "tiny_link2.urdf"
    urdf.write_text(urdf_for(DoublePendulumParams(**{**values, "l2": 0.5})))
    return urdf, values


def test_a_badly_conditioned_double_pendulum_passes(tmp_path):
    urdf, values = _badly_conditioned(tmp_path)
    m2, l1, r2, I2 = values["m2"], values["l1"], values["r2"], values["I2"]
    m11 = values["I1"] + I2 + values["m1"] * values["r1"] ** 2 + m2 * (l1**2 + r2**2) + 2 * m2 * l1 * r2
    m12, m22 = I2 + m2 * r2**2 + m2 * l1 * r2, I2 + m2 * r2**2
    assert np.linalg.cond(np.array([[m11, m12], [m12, m22]])) > 1e4  # at θ2 = 0
    report = pendverify.check(_code(tmp_path), urdf, values, samples=SAMPLES, explain=False)
    statuses = _statuses(report)
    assert set(statuses) == DERIVED_CHECKS and all(s == "pass" for s in statuses.values()), statuses
    # and a planted 1 % error in its tiny link's inertia still fails crba there
    wrong = _code(tmp_path, ", (I2 + m2*r2**2)]])", ", (1.01*I2 + 1.01*m2*r2**2)]])")
    assert pendverify.check(wrong, urdf, values, samples=SAMPLES, explain=False)["crba"].status == "fail"


@pytest.mark.parametrize(
    "old, new, check",
    [
        (", (I2 + m2*r2**2)]])", ", (1.01*I2 + m2*r2**2)]])", "crba"),  # an inertia term of M
        ("- g*m2*r2*cos(theta1 + theta2))", "- 1.01*g*m2*r2*cos(theta1 + theta2))", "gravity"),
        ("- m2*l1*r2*sin(theta2)*dtheta1**2", "- 1.01*m2*l1*r2*sin(theta2)*dtheta1**2", "rnea"),
    ],
)
def test_a_planted_one_percent_error_fails_its_check(old, new, check, tmp_path):
    report = pendverify.check(_code(tmp_path, old, new), URDF, MINIMAL_PARAMS, samples=SAMPLES, explain=False)
    assert report[check].status == "fail", _statuses(report)


def test_code_not_affine_in_the_inputs_is_refused_naming_the_state(tmp_path):
    model = _code(tmp_path, "(tau2 - b2*dtheta2", "(tau2 + 1e-3*tau2**2 - b2*dtheta2")
    with pytest.raises(PendverifyError) as caught:
        pendverify.check(model, URDF, MINIMAL_PARAMS, samples=SAMPLES, explain=False)
    message, _, _ = one_error(str(caught.value))
    assert "q̈ is not affine in the inputs at q = [" in message, message
    assert "double_pendulum_code.py" in message


def test_stress_counts_the_derived_checks_refusals_as_refusals_not_failures(tmp_path):
    """Extreme conditioning (r2 × 1e3, m2 × 1e6) widens the derivation's bound past the trust limit
    at some states: those checks are refused there, and every case still passes.  |θ| ≈ 1e6 rad
    does not: the angles' rounding is the same in every call of the derivation at a state, so it
    reaches the derived M as a hand-written M's (the check's own tolerance), not amplified."""
    report = stress(_code(tmp_path), URDF, MINIMAL_PARAMS, quick=True)
    assert all(r.passed for r in report.results), [(r.name, r.notes) for r in report.results if not r.passed]
    extreme = next(r for r in report.results if r.name == "r2 ×1e3")
    assert "crba, rnea, gravity refused at some states" in "; ".join(extreme.notes), extreme.notes
    large = next(r for r in report.results if r.name.startswith("|θ| ≈ 1e+06"))
    assert "refused" not in "; ".join(large.notes), large.notes
    nominal = next(r for r in report.results if r.name == "nominal")
    assert not nominal.extras["refused"] and "refused" not in "; ".join(nominal.notes), nominal.notes
