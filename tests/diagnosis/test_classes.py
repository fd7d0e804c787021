"""Classes of model the repair search used to leave without a repair, each with a model of the
diagnosis corpus (``examples/diagnosis_corpus.toml``): one error of the class is planted in a copy
of the corpus file and the exact repair is asserted; the untouched model gets none.

* **A C that is a valid C·q̇ but not the Christoffel C** (Tedrake's acrobot,
  ``examples/corpus_acrobot_tedrake.toml``): ``coriolis`` and ``skew`` warn on the untouched
  model; a repair brings the edited model back there (``pendverify.diagnosis.acceptance``).
* **A model given by q̈ alone** (gymnasium's book acrobot written out,
  ``examples/corpus_acrobot_gym_qddot.toml``, one torque for two coordinates: only ``aba``
  runs): repairs are searched in the ``qddot`` entries, compared with Pinocchio's ABA.
* **det M** (``examples/corpus_acrobot_detm.toml``, det M and M⁻¹ written out; the shipped
  cart-pole): a term missing from det M is restored from the determinant of the written M, in
  M⁻¹ too where it is written over the same det M.
* **Two errors in different keys** (``examples/corpus_acrobot_two_keys.toml``): one edit of each
  of two entries, one in M and one in C.
* **Conventions named with the file key that fixes them**: joints listed in the other order,
  and absolute vs relative angles, each as the ``[urdf]`` key to write.
* **A key the model derives** (H = ∂V/∂q of a file that writes V, or V integrated from H): the
  repair is of the key written, confirmed with the other derived again; the derived key is
  never repaired.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic.symbolic_reading import SymbolicModel
from pendverify.bench.explain import _target as load_target
from pendverify.bench.explain import class_targets
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.cli import main
from pendverify.diagnosis.acceptance import passes
from pendverify.diagnosis.corpus import pair_plants
from pendverify.diagnosis.repair import search_repair

from ..conftest import SEED, default_params

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
TEDRAKE = EXAMPLES / "corpus_acrobot_tedrake.toml"
DETM = EXAMPLES / "corpus_acrobot_detm.toml"
DETM_ARGS = (
    "--urdf",
    str(EXAMPLES / "corpus_acrobot_tedrake.urdf"),
    "--params",
    str(EXAMPLES / "corpus_acrobot_detm_params.toml"),
)
GYM = EXAMPLES / "corpus_acrobot_gym_qddot.toml"
GYM_ARGS = (
    "--urdf",
    str(EXAMPLES / "corpus_acrobot_tedrake.urdf"),
    "--params",
    str(EXAMPLES / "corpus_acrobot_gym_qddot_params.toml"),
)
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
            "C[2,1]: -m2*l1*lc2*sin(q2)*dq1 → m2*l1*lc2*sin(q2)*dq1",
        ),
        (
            '"m2*g*lc2*sin(q1 + q2)"',
            '"m2*g*lc2*cos(q1 + q2)"',
            "H[2]: m2*g*lc2*cos(q1 + q2) → m2*g*lc2*sin(q1 + q2)",
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


def test_a_christoffel_c_with_an_error_is_repaired_back_to_the_christoffel_c(tmp_path, capsys):
    """C[1,1] dropped from a Christoffel C: doubling q̇1 in C[1,2] would give a valid C·q̇ too (and
    pass with the warning); the edit that makes every check pass is the one printed."""
    planted = _planted(tmp_path, DETM, '["-m2*l1*lc2*sin(q2)*dq2", ', '["0", ')
    _, (found,) = _repairs(tmp_path, capsys, planted, *DETM_ARGS)
    assert found["message"].startswith("C[1,1]: 0 → -dq2*l1*lc2*m2*sin(q2) makes every check pass")
    assert "warns" not in found


def test_the_untouched_non_christoffel_model_passes_with_its_warning_and_gets_no_repair():
    model, system = _target("acrobot_tedrake")
    batch, results = _results(model, system)
    assert {r.name for r in results if not r.passed} == {"coriolis", "skew"}  # before the verdict
    assert passes(results)
    assert {r.name: r.status for r in results}["coriolis"] == "warn"
    repairs, why = search_repair(batch, 10.0)
    assert repairs == [] and "no single entry" in why


def test_a_wrong_c_qdot_is_not_accepted_as_the_non_christoffel_warning(tmp_path):
    """The rule demotes coriolis and skew only when C·q̇ is right: a C row that is wrong fails rnea."""
    planted = _planted(tmp_path, TEDRAKE, '["m2*l1*lc2*sin(q2)*dq1", "0"]', '["m2*l1*lc2*sin(q2)*dq2", "0"]')
    model, system = load_target(planted, *TEDRAKE_ARGS[1::2])
    _, results = _results(model, system)
    assert not passes(results)
    assert {r.name for r in results if not r.passed} >= {"rnea", "coriolis", "skew"}


# --- q̈ alone -----------------------------------------------------------------------------------
def _qddot_planted(tmp_path, entry: int, right: str, wrong: str, last: bool = False) -> Path:
    """The q̈ file with ``right`` made ``wrong`` once in q̈'s ``entry`` (0-based; its first
    occurrence there, or its ``last``)."""
    lines = GYM.read_text().split("\n")
    k = [i for i, line in enumerate(lines) if line.startswith("  '''")][entry]
    at = lines[k].rfind(right) if last else lines[k].find(right)
    assert at >= 0, right
    lines[k] = lines[k][:at] + wrong + lines[k][at + len(right) :]
    path = tmp_path / "planted_qddot.toml"
    path.write_text("\n".join(lines))
    return path


PHI1_TERM = " - 2*m2*l1*lc2*dtheta2*dtheta1*sin(theta2)"


# each case reads, checks and repairs the whole q̈ (≈ 10 to 50 s of SymPy on one core): slow
@pytest.mark.slow
@pytest.mark.parametrize(
    ("entry", "right", "wrong", "last", "repair", "exact"),
    [
        (1, "((a + ", "((2*a + ", False, "qddot[2]: 2*a → a in qddot[2]", False),
        # I1 → I2 in d1 reads as 2*I2: the parameter edit SymPy folded is undone
        (1, "+ I1 + I2)", "+ I2 + I2)", False, "qddot[2]: 2*I2 → I1 + I2 in qddot[2]", False),
        # a term of φ1 dropped where φ1 is a part of a longer sum (−(d2·θ̈2 + φ1)/d1): restored
        # from φ1 as it stands alone inside θ̈2, and exactly: the repaired entry is the one written,
        # term for term
        (
            0,
            PHI1_TERM,
            "",
            True,
            "qddot[1]: -dtheta2**2*l1*lc2*m2*sin(theta2) + g*lc2*m2*sin(theta1 + theta2)",
            True,
        ),
    ],
)
def test_an_error_in_a_model_given_by_qddot_is_repaired_in_its_qddot(
    tmp_path, capsys, entry, right, wrong, last, repair, exact
):
    planted = _qddot_planted(tmp_path, entry, right, wrong, last)
    out, (found,) = _repairs(tmp_path, capsys, planted, *GYM_ARGS)
    assert found["checks_pass"] and found["message"].startswith(repair), found["message"]
    assert "key qddot" in found["location"]
    assert "not explained" not in out
    if exact:
        model, _ = _target("acrobot_gym_qddot")
        assert found["suggested"] == str(SymbolicModel.of(type(model)).closed_forms["acceleration"][entry])


def test_the_untouched_qddot_model_passes_and_gets_no_repair():
    model, system = _target("acrobot_gym_qddot")
    batch, results = _results(model, system)
    assert [r.name for r in results] == ["aba"] and passes(results)
    repairs, why = search_repair(batch, 10.0)
    assert repairs == [] and "no single entry" in why


# --- det M -----------------------------------------------------------------------------------------
DET = "I1*I2 + m2*l1**2*I2 - m2**2*l1**2*lc2**2*cos(q2)**2"


def test_a_term_missing_from_det_m_is_restored_in_det_m_and_in_m_inverse(tmp_path, capsys):
    text = DETM.read_text()
    assert text.count(DET) == 5  # det_M and the four entries of M_inv over it
    planted = tmp_path / "planted_detm.toml"
    planted.write_text(text.replace(DET, DET.replace("I1*I2 + ", "")))
    _, found = _repairs(tmp_path, capsys, planted, *DETM_ARGS)
    assert [f["location"].split(", ", 1)[1] for f in found] == [
        "key det_M, entry detM",
        "key M_inv, entry Minv[1,1]",
        "key M_inv, entry Minv[1,2]",
        "key M_inv, entry Minv[2,1]",
        "key M_inv, entry Minv[2,2]",
    ]
    assert found[0]["suggested"] == "I1*I2 + I2*l1**2*m2 - l1**2*lc2**2*m2**2*cos(q2)**2"
    assert all(f["checks_pass"] for f in found)


def test_a_product_dropped_from_a_python_det_m_is_restored():
    """The shipped cart-pole's det M = (I + mp·r²)(mc + mp) − mp²·r²·cos²θ without its product."""
    from pendverify.bench.explain import shipped_targets
    from pendverify.symbolic.edited import edited_model

    model, system = next(
        (m, s) for label, m, s, _ in shipped_targets() if label == "cart_pole, model (Python)"
    )
    sm = SymbolicModel.of(type(model))
    written = sm.closed_forms["det_mass_matrix"]
    (product,) = [t for t in written.args if t.is_Mul and t.args[0] != -1]
    planted = edited_model(model, sm, {"det_mass_matrix": [(0, written, written - product)]}, "Planted")
    batch, results = _results(planted, system)
    assert not passes(results)
    repairs, _ = search_repair(batch, 10.0)
    assert repairs and repairs[0].details["suggested"] == str(written), [f.message for f in repairs]


# --- two errors in different keys ------------------------------------------------------------------
TWO_KEYS = EXAMPLES / "corpus_acrobot_two_keys.toml"
TWO_KEYS_ARGS = (
    "--urdf",
    str(EXAMPLES / "corpus_acrobot_tedrake.urdf"),
    "--params",
    str(EXAMPLES / "corpus_acrobot_two_keys_params.toml"),
)
M22, M22_WRONG = '"I2"],\n]', '"2*I2"],\n]'
C21, C21_WRONG = '["m2*l1*lc2*sin(q2)*dq1", "0"]', '["-m2*l1*lc2*sin(q2)*dq1", "0"]'


@pytest.mark.parametrize(
    ("source", "args", "warns"), [(TWO_KEYS, TWO_KEYS_ARGS, False), (TEDRAKE, TEDRAKE_ARGS, True)]
)
def test_one_error_in_m_and_one_in_c_are_repaired_together(tmp_path, capsys, source, args, warns):
    """Neither edit alone makes the checks pass; the two together do (the non-Christoffel model:
    back to its warning)."""
    text = source.read_text()
    assert text.count(M22) == 1 and text.count(C21) == 1
    planted = tmp_path / "planted_two.toml"
    planted.write_text(text.replace(M22, M22_WRONG).replace(C21, C21_WRONG))
    _, found = _repairs(tmp_path, capsys, planted, *args)
    assert sorted(f["message"].split(" makes")[0] for f in found) == [
        "C[2,1]: -m2*l1*lc2*sin(q2)*dq1 → m2*l1*lc2*sin(q2)*dq1",
        "M[2,2]: 2*I2 → I2",
    ]
    assert all(("warns" in f) is warns for f in found)
    by_entry = {f["message"].split(":", 1)[0]: f["message"] for f in found}
    assert "; together with the edit of M[2,2]" in by_entry["C[2,1]"]
    assert "; together with the edit of C[2,1]" in by_entry["M[2,2]"]


def test_the_untouched_two_key_model_passes_and_its_pairs_are_drawn_from_two_keys():
    model, system = _target("acrobot_two_keys")
    batch, results = _results(model, system)
    assert all(r.status == "pass" for r in results)
    repairs, why = search_repair(batch, 10.0)
    assert repairs == [] and "no single entry" in why
    pairs = pair_plants(SymbolicModel.of(type(model)), 30)
    assert len(pairs) == 30 and all(a.method != b.method for a, b in pairs)


# --- conventions, named with the key that declares them ---------------------------------------------
JOINTS = 'joints = ["shoulder", "elbow"]'


def _convention(tmp_path, capsys, declared: str) -> str:
    text = TWO_KEYS.read_text()
    assert text.count(JOINTS) == 1
    planted = tmp_path / "planted_map.toml"
    planted.write_text(text.replace(JOINTS, declared))
    out_json = tmp_path / "report.json"
    assert main(["check", "--analytic", str(planted), *TWO_KEYS_ARGS, "--json", str(out_json)]) == 1
    capsys.readouterr()
    (findings,) = json.loads(out_json.read_text())["diagnoses"].values()
    (convention,) = [f for f in findings if f["kind"] == "convention"]
    assert convention["exact"]
    # the convention is the fix: no sentence that no edit was found, no fit in the declared coordinates
    assert not [f for f in findings if f["kind"] in ("repair", "parameters")], findings
    return convention["message"]


def test_joints_listed_in_the_other_order_are_named_with_the_joints_key(tmp_path, capsys):
    message = _convention(tmp_path, capsys, 'joints = ["elbow", "shoulder"]')
    assert message.startswith(
        "joint order: the hand model's coordinates are the joints in another order than the map's "
        "(q1 is shoulder's coordinate, q2 is elbow's coordinate); with the joints in that order every "
        "check passes"
    )
    where = tmp_path / "planted_map.toml"
    assert message.endswith(f"; declare it as joints = ['shoulder', 'elbow'] under [urdf] in {where}")


def test_relative_angles_declared_absolute_are_named_with_the_transform_key(tmp_path, capsys):
    message = _convention(tmp_path, capsys, JOINTS + "\ntransform = [[1, 0], [-1, 1]]")
    assert message.startswith("absolute vs relative angles: the hand model's angles are relative")
    where = tmp_path / "planted_map.toml"
    assert message.endswith(f"; declare it as transform = [[1, 0], [0, 1]] under [urdf] in {where}")


def test_a_python_class_is_told_its_class_attribute():
    """The same trap in a Python class: the attribute ``joint_transform`` of the class."""
    from pendverify.analytic import DoublePendulum
    from pendverify.diagnosis.traps.convention_maps import Candidate
    from pendverify.diagnosis.traps.convention_words import declared_as

    model = DoublePendulum(default_params("double_pendulum"))
    c = Candidate(relative=1, shifts=(0, 0), T=np.array([[1.0, 0.0], [-1.0, 1.0]]), theta0=np.zeros(2))
    words = declared_as(model, c, np.zeros(2))
    assert words.startswith("declare it as DoublePendulum.joint_transform = [[1, 0], [-1, 1]] in ")
    assert words.endswith("double_pendulum.py")


# --- a key derived from another -----------------------------------------------------------------------
V_LINE = 'V = "-m1*g*lc1*cos(q1) - m2*g*(l1*cos(q1) + lc2*cos(q1 + q2))"\n'
H_BLOCK = """H = [
  "m1*g*lc1*sin(q1) + m2*g*(l1*sin(q1) + lc2*sin(q1 + q2))",
  "m2*g*lc2*sin(q1 + q2)",
]
"""


@pytest.mark.parametrize(
    ("dropped", "right", "wrong", "repair"),
    [
        # V written, H = ∂V/∂q derived: lc1 typed for lc2 in V
        (
            H_BLOCK,
            "l1*cos(q1) + lc2*cos(q1 + q2)",
            "l1*cos(q1) + lc1*cos(q1 + q2)",
            "V: -m1*g*lc1*cos(q1) - m2*g*(l1*cos(q1) + lc1*cos(q1 + q2)) → "
            "-m1*g*lc1*cos(q1) - m2*g*(l1*cos(q1) + lc2*cos(q1 + q2))",
        ),
        # H written, V integrated from H: m2 typed for m1 in H[1] (still a gradient)
        (
            V_LINE,
            '"m1*g*lc1*sin(q1) + m2*g*',
            '"m2*g*lc1*sin(q1) + m2*g*',
            "H[1]: m2*g*lc1*sin(q1) + m2*g*(l1*sin(q1) + lc2*sin(q1 + q2)) → "
            "m1*g*lc1*sin(q1) + m2*g*(l1*sin(q1) + lc2*sin(q1 + q2))",
        ),
    ],
)
def test_the_written_key_is_repaired_never_the_one_derived_from_it(
    tmp_path, capsys, dropped, right, wrong, repair
):
    text = TWO_KEYS.read_text()
    assert text.count(dropped) == 1 and text.count(right) == 1
    planted = tmp_path / "planted_derived.toml"
    planted.write_text(text.replace(dropped, "").replace(right, wrong))
    _, (found,) = _repairs(tmp_path, capsys, planted, *TWO_KEYS_ARGS)
    assert found["checks_pass"] and found["message"].startswith(repair + " makes every check pass")
