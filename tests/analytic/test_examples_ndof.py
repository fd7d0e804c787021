"""Two plug-ins beyond two planar coordinates: a triple pendulum and a Furuta pendulum.

``examples/triple_pendulum.py`` (3 DOF, absolute angles against relative URDF
joints) and ``examples/furuta_pendulum.py`` (2 DOF, not planar, full inertia
tensors) go through the public entry points only: the CLI's ``check``,
``sympy`` and ``mutate`` on the model files, and the parameter loader of
``pendverify.analytic.params``.  Planted errors — the Furuta pendulum with the
pendulum's third principal moment dropped (the slender-pendulum derivations) or
its product of inertia in the arm's frame dropped, the triple pendulum declared
with a relative-angle map — must fail the check that looks at them.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from pendverify.analytic.params import load_parameter_file
from pendverify.cli import main

from ..conftest import example_module

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
STEMS = ("triple_pendulum", "furuta_pendulum")
#: every check of ``pendverify check``; ``damping`` runs because both URDFs declare <dynamics damping>
ALL_CHECKS = {
    "units",
    "crba",
    "rnea",
    "gravity",
    "coriolis",
    "skew",
    "det",
    "minverse",
    "aba",
    "energy",
    "damping",
}


def _files(stem: str) -> tuple[str, str, str]:
    return tuple(str(EXAMPLES / f"{stem}.{ext}") for ext in ("py", "urdf", "toml"))


def _check(model_file: str, stem: str, tmp_path: Path, samples: str) -> tuple[int, dict]:
    _, urdf, params = _files(stem)
    out = tmp_path / "check.json"
    argv = ["check", "--analytic", model_file, "--urdf", urdf, "--params", params, "--samples", samples]
    status = main([*argv, "--json", str(out)])
    return status, json.loads(out.read_text())


def _planted(tmp_path: Path, stem: str, old: str, new: str) -> str:
    source = (EXAMPLES / f"{stem}.py").read_text()
    assert source.count(old) == 1, f"the planted error's anchor is not unique in {stem}.py: {old!r}"
    path = tmp_path / f"{stem}_planted.py"
    path.write_text(source.replace(old, new))
    return str(path)


def _statuses(report: dict) -> dict[str, str]:
    return {r["check"]: r["status"] for r in report["results"]}


# --- the three tools on the committed examples -----------------------------------------------------
@pytest.mark.parametrize("stem", STEMS)
def test_check_passes_every_check(tmp_path, capsys, stem):
    status, report = _check(_files(stem)[0], stem, tmp_path, "100")
    out = capsys.readouterr().out
    assert status == 0, out
    assert "all checks pass" in out
    assert report["passed"] is True
    assert not report["diagnoses"] and not report["warnings"]
    assert set(_statuses(report)) == ALL_CHECKS
    for r in report["results"]:
        assert r["status"] == "pass", r
        assert r["max_error"] <= r["tolerance"] < 1e-11, r  # ε-level, not a loose tolerance
        # 100 random states, 5 special configurations at rest and moving; the units row reads none
        assert r["samples"] == (0 if r["check"] == "units" else 110)


@pytest.mark.slow
@pytest.mark.parametrize(("stem", "entries"), [("triple_pendulum", 58), ("furuta_pendulum", 29)])
def test_sympy_derives_every_closed_form(tmp_path, capsys, stem, entries):
    out = tmp_path / "sympy.json"
    assert main(["sympy", "--analytic", _files(stem)[0], "--json", str(out)]) == 0
    assert "every closed form equals its derivation" in capsys.readouterr().out
    (report,) = json.loads(out.read_text())
    assert report["passed"] is True
    comparisons = {c["method"]: c for c in report["comparisons"]}
    assert all(c["status"] == "equal" for c in comparisons.values()), comparisons
    # acceleration is read symbolically (adjugate / det, not a numerical solve), and f is declared
    assert {"acceleration", "generalized_force", "det_mass_matrix", "inverse_mass_matrix"} <= set(comparisons)
    assert sum(c["entries"] for c in comparisons.values()) == entries


@pytest.mark.slow
@pytest.mark.parametrize("stem", STEMS)
def test_mutate_detects_every_non_equivalent_mutant(tmp_path, capsys, stem):
    model, urdf, params = _files(stem)
    out = tmp_path / "mutate.json"
    assert main(["mutate", "--analytic", model, "--urdf", urdf, "--params", params, "--json", str(out)]) == 0
    assert "detection rate 100.0%" in capsys.readouterr().out
    (report,) = json.loads(out.read_text())
    assert report["survived"] == 0
    assert report["detection_rate"] == 1.0
    assert report["detected"] > 400
    # every declared closed form was mutated, and its control passed
    assert {o["method"] for o in report["outcomes"]} == set(report["controls"])


# --- planted errors -----------------------------------------------------------------------------
def test_furuta_slender_pendulum_error_fails_crba(tmp_path, capsys):
    """The published-derivation error: the pendulum's long-axis moment Jpzz cos²α left out of M11."""
    planted = _planted(tmp_path, "furuta_pendulum", "            p.Jpzz * c**2,\n", "")
    status, report = _check(planted, "furuta_pendulum", tmp_path, "20")
    assert status == 1
    statuses = _statuses(report)
    assert statuses["crba"] == "fail"
    # M is wrong everywhere it enters; C, H and D are untouched
    assert {c for c, s in statuses.items() if s == "fail"} == {"crba", "det", "minverse", "aba", "energy"}
    assert "FAIL" in capsys.readouterr().out


def test_furuta_product_of_inertia_dropped_from_c_fails_coriolis(tmp_path):
    """The arm-frame product of inertia (Jpyy − Jpzz) sin α cos α losing its Jpzz in C only."""
    planted = _planted(
        tmp_path,
        "furuta_pendulum",
        "ksc = (p.Jpyy + p.mp * p.lp**2 - p.Jpzz) * s * c\n        return np.array(\n            [\n"
        "                [ksc * v[1]",
        "ksc = (p.Jpyy + p.mp * p.lp**2) * s * c\n        return np.array(\n            [\n"
        "                [ksc * v[1]",
    )
    status, report = _check(planted, "furuta_pendulum", tmp_path, "20")
    assert status == 1
    statuses = _statuses(report)
    assert statuses["crba"] == "pass"
    assert {c for c, s in statuses.items() if s == "fail"} == {"rnea", "coriolis", "skew"}


@pytest.mark.slow
def test_triple_pendulum_with_a_relative_angle_map_is_diagnosed(tmp_path, capsys):
    planted = _planted(
        tmp_path,
        "triple_pendulum",
        "joint_transform = ((1.0, 0.0, 0.0), (-1.0, 1.0, 0.0), (0.0, -1.0, 1.0))",
        "joint_transform = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))",
    )
    status, report = _check(planted, "triple_pendulum", tmp_path, "20")
    out = capsys.readouterr().out
    assert status == 1
    assert _statuses(report)["crba"] == "fail"
    assert "absolute vs relative angles" in out
    (sentence,) = [
        d["message"]
        for found in report["diagnoses"].values()
        for d in found
        if d["message"].startswith("absolute vs relative angles")
    ]
    assert "the hand model's angles are absolute" in sentence
    assert "T → T·A = [[1.0, 0.0, 0.0], [-1.0, 1.0, 0.0], [0.0, -1.0, 1.0]]" in sentence
    assert "an exact fit" in sentence


# --- the committed URDFs ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("stem", "model_class", "generator"),
    [
        ("triple_pendulum", "TriplePendulum", "triple_pendulum_urdf"),
        ("furuta_pendulum", "FurutaPendulum", "furuta_pendulum_urdf"),
    ],
)
def test_committed_urdfs_match_their_generators(stem, model_class, generator):
    module = example_module(stem)
    cls = getattr(module, model_class)
    _, _, params = load_parameter_file(EXAMPLES / f"{stem}.toml", {cls.name: cls.params_type})
    assert (EXAMPLES / f"{stem}.urdf").read_text() == getattr(module, generator)(params), (
        f"examples/{stem}.urdf is stale: regenerate it with python examples/{stem}.py"
    )
