"""SymPy mechanics models: a LagrangesMethod, a KanesMethod or (mass_matrix, forcing), with a declaration.

The double pendulum reference system derived in ``tests/analytic/mechanics_double_pendulum.py``
verifies against its URDF through the API and as a Python model file (``METHOD`` and
``DECLARATION``); a doubled link inertia fails; names the declaration does not give, a
coordinate mismatch and a missing declaration are refused in one line.
"""

from __future__ import annotations

from pathlib import Path

import pytest
import sympy as sp

import pendverify
from pendverify.api import load_model, read_model
from pendverify.errors import PendverifyError
from tests.analytic.mechanics_double_pendulum import DECLARATION, kane, lagrange

REPO = Path(__file__).resolve().parents[2]
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
SAMPLES = 60  # the special states plus 60 random ones
CHECKS = {"units", "crba", "rnea", "gravity", "aba", "energy", "damping"}


def _check(model, declaration=DECLARATION):
    return pendverify.check(model, URDF, PARAMS, samples=SAMPLES, explain=False, declaration=declaration)


@pytest.mark.parametrize("build", [lagrange, kane, lambda: (lagrange().mass_matrix, lagrange().forcing)])
def test_a_mechanics_double_pendulum_verifies_through_the_api(build):
    report = _check(build())
    assert report.status == "pass", report
    assert set(report.checks) == CHECKS


def test_a_doubled_link_inertia_fails():
    report = _check(lagrange(factor=2))
    assert report["crba"].status == "fail" and report["aba"].status == "fail"


def test_show_says_the_parts_come_from_the_method():
    derived = {e.method: e.derived for e in read_model_of(lagrange()).equations}
    assert derived["mass_matrix"] == "the LagrangesMethod's mass matrix"
    assert derived["gravity"].startswith("from the LagrangesMethod's forcing")


def read_model_of(method):
    return read_model(load_model(method, DECLARATION))


def test_a_model_file_exposing_METHOD_and_DECLARATION(tmp_path):
    path = tmp_path / "lagrange_model.py"
    path.write_text(
        "from tests.analytic.mechanics_double_pendulum import DECLARATION, lagrange\n\nMETHOD = lagrange()\n"
    )
    report = pendverify.check(path, URDF, PARAMS, samples=SAMPLES, explain=False)
    assert report.status == "pass", report
    assert load_model(path).__module__ != "tests.analytic.mechanics_double_pendulum"


def test_a_model_file_with_METHOD_and_no_DECLARATION_is_refused(tmp_path):
    path = tmp_path / "bare.py"
    path.write_text("from tests.analytic.mechanics_double_pendulum import lagrange\n\nMETHOD = lagrange()\n")
    with pytest.raises(PendverifyError, match=r"bare\.py: defines METHOD but no DECLARATION"):
        load_model(path)


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda d: d["parameters"].pop("b2"), "uses b2, which the declaration does not name"),
        (lambda d: d.update(inputs=["tau1"]), "dynamic symbol tau2, which the declaration does not name"),
        (
            lambda d: d.update(coordinates={"theta1": "angle", "phi": "angle"}),
            "has coordinates theta1, theta2",
        ),
        (lambda d: d["parameters"].update(b2={"kind": "weight"}), "key 'parameters.b2': must be"),
        (lambda d: d.update(M=[["1"]]), "key 'M': unknown key"),
    ],
)
def test_what_the_declaration_does_not_match_is_refused_in_one_line(change, words):
    declaration = {k: (dict(v) if isinstance(v, dict) else v) for k, v in DECLARATION.items()}
    change(declaration)
    with pytest.raises(PendverifyError) as info:
        load_model(lagrange(), declaration)
    assert "\n" not in str(info.value) and words in str(info.value), str(info.value)


def test_a_method_without_a_declaration_and_a_declaration_without_a_method_are_refused():
    with pytest.raises(PendverifyError, match="needs a declaration"):
        load_model(lagrange())
    with pytest.raises(PendverifyError, match="a declaration goes with a LagrangesMethod"):
        load_model("double_pendulum", DECLARATION)


def test_a_mass_matrix_holding_accelerations_is_refused():
    method = lagrange()
    t = sp.Symbol("t")
    M = method.mass_matrix.copy()
    M[0, 0] += method.q[0].diff(t, 2)
    with pytest.raises(PendverifyError, match="mass matrix': holds accelerations"):
        load_model((M, method.forcing), DECLARATION)
