"""Verdicts at the edges: each class of false alarm and miss seen on URDFs written elsewhere.

Every class is planted here and its verdict and sentence asserted; every fix of a
false alarm comes with a test that a real error of the same kind is still caught.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from pendverify.cli import main
from pendverify.robot.writer import urdf_for

from ..conftest import default_params

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
SAMPLES = "40"


def _check(capsys, *args: str) -> tuple[int, str, dict]:
    """Run ``pendverify check ARGS JSON``, the last argument the report's path: (status, stdout, report)."""
    *args, out_json = args
    status = main(["check", "--samples", SAMPLES, *args, "--json", out_json])
    out = capsys.readouterr().out
    path = Path(out_json)
    return status, out, json.loads(path.read_text()) if path.exists() else {}


def _results(report: dict) -> dict[str, dict]:
    return {r["check"]: r for r in report["results"]}


def _shifted(text: str, offset: float) -> str:
    """The same robot with its base fixed ``offset`` m from the world origin, off every axis."""
    root = re.search(r'<link name="([^"]+)"', text).group(1)
    world = (
        '<link name="world"/>\n  <joint name="world_to_base" type="fixed">'
        f'<parent link="world"/><child link="{root}"/>'
        f'<origin xyz="{0.48 * offset!r} {0.6 * offset!r} {0.64 * offset!r}" rpy="0 0 0"/></joint>\n  '
    )
    return text.replace(f'<link name="{root}"', world + f'<link name="{root}"', 1)


def _write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text)
    return str(path)


# --- 1. a base away from the world origin -----------------------------------------------------
@pytest.mark.parametrize(
    ("model", "how"),
    [
        ("double_pendulum", "read off the URDF"),
        ("double_pendulum", "against the parameter set"),
        ("cart_double_pendulum", "against the parameter set"),
    ],
)
def test_a_base_1_km_away_verifies_exactly_as_at_the_origin(tmp_path, capsys, model, how):
    params = default_params(model)
    toml = _write(tmp_path, "set.toml", params.to_toml())
    reports = {}
    for offset in (0.0, 5.0, 50.0, 100.0, 1000.0):
        urdf = _write(tmp_path, f"robot_{offset:g}.urdf", _shifted(urdf_for(params), offset))
        given = ["--model", model] if how == "read off the URDF" else ["--params", toml]
        status, out, report = _check(capsys, *given, "--urdf", urdf, str(tmp_path / "x.json"))
        assert status == 0, out
        reports[offset] = _results(report)
    origin = reports[0.0]
    for offset, results in reports.items():
        for name, r in results.items():
            # the same evaluation: the base is anchored at the origin before Pinocchio sees it
            assert r["max_error"] == pytest.approx(origin[name]["max_error"], rel=0, abs=4 * 2.2e-16), (
                offset,
                name,
            )
            assert r["status"] == origin[name]["status"] == "pass"
    assert "stands 1000 m from the world origin" in out


def test_a_wrong_inertia_on_a_base_1_km_away_still_fails(tmp_path, capsys):
    params = default_params("double_pendulum")
    toml = _write(tmp_path, "dp.toml", params.to_toml())
    wrong = params.replace(I2=params.I2 * 1.01)
    urdf = _write(tmp_path, "far.urdf", _shifted(urdf_for(wrong), 1000.0))
    status, out, report = _check(capsys, "--params", toml, "--urdf", urdf, str(tmp_path / "x.json"))
    assert status == 1
    assert _results(report)["crba"]["status"] == "fail"
    assert "the URDF gives I2 = 0.013635, the parameter set 0.0135 (+1.000%)" in out


# --- 2. a valid C·q̇ with a C that is not the Christoffel one ----------------------------------
NOT_CHRISTOFFEL = '''
import math
import numpy as np
from pendverify.analytic import DoublePendulum, DoublePendulumParams


class TextbookC(DoublePendulum):
    """The seed with a published C: same C·q̇, but Ṁ − 2C is not skew-symmetric."""

    name = "textbook_c"
    urdf_joints = ("joint1", "joint2")
    joint_offset = (0.0, 0.0)

    def seed_coriolis_matrix(self, q, v):
        b, s = self.beta, self.math.sin(q[1])
        return np.array(
            [[-2 * b * s * v[1] + self.params.b1, {c01}], [b * s * v[0], self.params.b2]]
        )


class Params(DoublePendulumParams):
    model = "textbook_c"


TextbookC.params_type = Params
'''


def _textbook(tmp_path, c01: str) -> list[str]:
    model = _write(tmp_path, "textbook.py", NOT_CHRISTOFFEL.format(c01=c01))
    params = default_params("double_pendulum")
    toml = _write(tmp_path, "textbook.toml", params.to_toml().replace("double_pendulum", "textbook_c"))
    urdf = _write(tmp_path, "dp.urdf", urdf_for(params))
    return ["--analytic", model, "--urdf", urdf, "--params", toml]


def test_a_valid_c_qdot_that_is_not_christoffel_passes_with_a_warning(tmp_path, capsys):
    args = _textbook(tmp_path, "-b * s * v[1]")
    status, out, report = _check(capsys, *args, str(tmp_path / "x.json"))
    assert status == 0, out
    results = _results(report)
    assert results["coriolis"]["status"] == results["skew"]["status"] == "warn"
    assert all(r["status"] == "pass" for n, r in results.items() if n not in ("coriolis", "skew"))
    assert report["status"] == "warn"
    assert "warning [textbook_c:dp]: a valid C·q̇, not the Christoffel C: Ṁ − 2C is not skew-symmetric" in out
    assert re.search(r"coriolis: [0-9.e+-]+ relative \([0-9.e+-]+× its tolerance", out)
    assert "(seed 20260301), " in out and ": pass with 1 warning(s)\n" in out
    status, out, _ = _check(capsys, *args, "--strict", str(tmp_path / "y.json"))
    assert status == 1
    assert ": 2 check(s) FAIL, 1 warning(s)\n" in out


def test_a_wrong_c_qdot_still_fails(tmp_path, capsys):
    # the same published form with the sign of one term flipped: C·q̇ is wrong now
    status, out, report = _check(capsys, *_textbook(tmp_path, "b * s * v[1]"), str(tmp_path / "x.json"))
    assert status == 1
    results = _results(report)
    assert results["rnea"]["status"] == results["coriolis"]["status"] == "fail"
    assert "Christoffel" not in out


# --- 3. an unbounded model-form allowance -----------------------------------------------------
def _off_line(text: str, offset: float) -> str:
    """Link 1's centre of mass moved ``offset`` m off the joint-1→joint-2 line (along z)."""
    return text.replace(
        '<origin xyz="0 0.25 0" rpy="0 0 0"/>\n      <mass',
        f'<origin xyz="0 0.25 {offset!r}" rpy="0 0 0"/>\n      <mass',
        1,
    )


def test_a_centre_of_mass_2_cm_off_the_line_fails_as_outside_the_family(tmp_path, capsys):
    text = _off_line(urdf_for(default_params("double_pendulum")), 0.02)
    urdf = _write(tmp_path, "off.urdf", text)
    status, out, report = _check(
        capsys, "--model", "double_pendulum", "--urdf", urdf, str(tmp_path / "x.json")
    )
    assert status == 1
    row = _results(report)["model-form"]
    assert row["status"] == "fail" and row["max_error"] > 1e-2 and row["tolerance"] == 1e-4
    assert "link 1's centre of mass is 0.02 m off the joint-1→joint-2 line" in out
    assert "above the model-form threshold 0.0001 (--model-form-rtol): the URDF lies outside" in out
    assert _results(report)["gravity"]["status"] == "fail"  # no allowance is made
    # the threshold is the user's to set
    status, out, report = _check(
        capsys,
        "--model",
        "double_pendulum",
        "--urdf",
        urdf,
        "--model-form-rtol",
        "0.1",
        str(tmp_path / "y.json"),
    )
    assert status == 0, out
    assert "within the model-form threshold 0.1: the checks allow for it" in out


def test_a_bracket_of_extra_mass_off_the_line_fails(tmp_path, capsys):
    bracket = (
        '<joint name="bracket_mount" type="fixed"><parent link="link1"/><child link="bracket"/>'
        '<origin xyz="0 0.1 0.05" rpy="0 0 0"/></joint>\n  <link name="bracket"><inertial>'
        '<origin xyz="0 0 0" rpy="0 0 0"/><mass value="0.2"/>'
        '<inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>\n</robot>'
    )
    text = urdf_for(default_params("double_pendulum")).replace("</robot>", bracket)
    urdf = _write(tmp_path, "bracket.urdf", text)
    status, out, report = _check(
        capsys, "--model", "double_pendulum", "--urdf", urdf, str(tmp_path / "x.json")
    )
    assert status == 1
    assert _results(report)["model-form"]["status"] == "fail"
    assert "the URDF lies outside the closed form's family" in out


def test_a_rounding_size_offset_is_allowed_and_reported(tmp_path, capsys):
    text = _off_line(urdf_for(default_params("double_pendulum")), 2e-6)
    urdf = _write(tmp_path, "tiny.urdf", text)
    status, out, report = _check(
        capsys, "--model", "double_pendulum", "--urdf", urdf, str(tmp_path / "x.json")
    )
    assert status == 0, out
    row = _results(report)["model-form"]
    assert row["status"] == "warn" and 1e-6 < row["max_error"] < 1e-5  # allowed for: pass (warn)
    assert "within the model-form threshold 0.0001" in out


# --- 4. damping and Coulomb friction in the URDF ----------------------------------------------
def test_urdf_damping_ten_times_the_parameter_set_fails_naming_it(tmp_path, capsys):
    params = default_params("double_pendulum")
    toml = _write(tmp_path, "dp.toml", params.to_toml())
    urdf = _write(tmp_path, "damped.urdf", urdf_for(params.replace(b1=10 * params.b1)))
    status, out, report = _check(capsys, "--params", toml, "--urdf", urdf, str(tmp_path / "x.json"))
    assert status == 1
    results = _results(report)
    assert results["damping"]["status"] == "fail"
    assert [n for n, r in results.items() if r["status"] == "fail"] == ["damping"]
    assert "the URDF gives b1 = 0.5, the parameter set 0.05 (+900.000%)" in out
    assert "D[theta1,theta1]: the URDF's <dynamics damping> gives 0.5, the hand model 0.05" in out


def test_a_plug_in_with_relative_damping_matches_its_urdf(tmp_path, capsys):
    # absolute angles, damping on the relative rate: D = Tᵀ·diag(b)·T must be recognised
    args = [
        "--analytic",
        str(EXAMPLES / "hanging_double_pendulum.py"),
        "--urdf",
        str(EXAMPLES / "hanging_double_pendulum.urdf"),
        "--params",
        str(EXAMPLES / "hanging_double_pendulum.toml"),
    ]
    status, out, report = _check(capsys, *args, str(tmp_path / "x.json"))
    assert status == 0, out
    assert _results(report)["damping"]["status"] == "pass"


def test_a_urdf_without_damping_is_not_compared_and_says_so(tmp_path, capsys):
    params = default_params("double_pendulum")
    toml = _write(tmp_path, "dp.toml", params.to_toml())
    text = re.sub(r"\s*<dynamics damping=\"[^\"]*\"/>", "", urdf_for(params))
    urdf = _write(tmp_path, "bare.urdf", text)
    _, out, report = _check(capsys, "--params", toml, "--urdf", urdf, str(tmp_path / "x.json"))
    assert "damping" not in _results(report)
    assert "damping not run: the URDF declares no <dynamics damping>" in out


def test_coulomb_friction_in_the_urdf_is_a_stated_warning(tmp_path, capsys):
    params = default_params("double_pendulum")
    toml = _write(tmp_path, "dp.toml", params.to_toml())
    text = urdf_for(params).replace('<dynamics damping="0.03"/>', '<dynamics damping="0.03" friction="0.2"/>')
    urdf = _write(tmp_path, "coulomb.urdf", text)
    status, out, report = _check(capsys, "--params", toml, "--urdf", urdf, str(tmp_path / "x.json"))
    assert status == 0, out
    assert (
        "warning [double_pendulum:coulomb]: joint joint2: the URDF's <dynamics friction> = 0.2 (Coulomb) "
        "has no term in the hand model" in out
    )
    assert report["status"] == "warn"
    status, _, _ = _check(capsys, "--params", toml, "--urdf", urdf, "--strict", str(tmp_path / "y.json"))
    assert status == 1


# --- 5. malformed numbers in the URDF ----------------------------------------------------------
@pytest.mark.parametrize("value", ["np.float64(0.0135)", "0,0135", "1e400", "nan"])
def test_a_malformed_inertia_is_an_error_naming_file_link_element_attribute(tmp_path, capsys, value):
    text = urdf_for(default_params("double_pendulum")).replace('ixx="0.0135"', f'ixx="{value}"')
    urdf = _write(tmp_path, "bad.urdf", text)
    assert main(["check", "--model", "double_pendulum", "--urdf", urdf]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert err.startswith(f"pendverify: error: {urdf}: link 'link2'")
    assert f"ixx = {value!r}" in err and "<inertia>" in err


def test_pinocchio_s_refusal_carries_its_reason(tmp_path, capsys):
    text = urdf_for(default_params("double_pendulum")).replace(
        '<parent link="link1"/>', '<parent link="nowhere"/>'
    )
    urdf = _write(tmp_path, "orphan.urdf", text)
    assert main(["check", "--model", "double_pendulum", "--urdf", urdf]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "nowhere" in err
    assert "does not contain a valid URDF model" not in err


# --- 6. diagnoses that fit approximately --------------------------------------------------------
def test_pivot_inertia_is_named_with_its_residual_despite_a_rounded_pi(tmp_path, capsys):
    # a cart-pole URDF that turns the pole up with rpy = 3.1416 (7.3e-6 rad short of π) and gives
    # the pole's inertia about the pivot; the model's map says the pole is up at joint angle 0
    model = (EXAMPLES / "cart_pole.py").read_text()
    up = model.replace("joint_offset = (0.0, math.pi)", "joint_offset = (0.0, 0.0)")
    urdf = (EXAMPLES / "cart_pole.urdf").read_text()
    flipped = urdf.replace(
        '<parent link="cart"/>\n    <child link="pole"/>\n    <origin xyz="0 0 0" rpy="0 0 0"/>',
        '<parent link="cart"/>\n    <child link="pole"/>\n    <origin xyz="0 0 0" rpy="0 -3.1416 0"/>',
    ).replace('ixx="0.012" ixy="0" ixz="0" iyy="0.012"', 'ixx="0.048" ixy="0" ixz="0" iyy="0.048"')
    assert up != model and flipped.count("3.1416") == 1 and flipped.count("0.048") == 2
    args = [
        "--analytic",
        _write(tmp_path, "cart_pole_up.py", up),
        "--urdf",
        _write(tmp_path, "pole_up.urdf", flipped),
        "--params",
        str(EXAMPLES / "cart_pole.toml"),
    ]
    status, out, _ = _check(capsys, *args, str(tmp_path / "x.json"))
    assert status == 1
    match = re.search(
        r"the parallel-axis term m·r² = [0-9.]+ kg·m² of pole \(joint pole_hinge\) \(M_urdf − M_hand is up "
        r"to a relative residual of ([0-9.e+-]+) \(a smaller difference remains as well\) that term\)",
        out,
    )
    assert match, out
    assert 1e-7 < float(match.group(1)) < 1e-4  # the 7.3e-6 rad of the rounded π


def test_one_offset_in_degrees_is_named(tmp_path, capsys):
    model = (EXAMPLES / "hanging_double_pendulum.py").read_text()
    planted = model.replace("joint_offset = (math.pi / 2, math.pi / 2)", "joint_offset = (90.0, math.pi / 2)")
    assert planted != model
    path = _write(tmp_path, "hanging_deg.py", planted)
    args = [
        "--analytic",
        path,
        "--urdf",
        str(EXAMPLES / "hanging_double_pendulum.urdf"),
        "--params",
        str(EXAMPLES / "hanging_double_pendulum.toml"),
    ]
    status, out, _ = _check(capsys, *args, str(tmp_path / "x.json"))
    assert status == 1
    assert "degrees vs radians: the offset of phi1, 90, is in degrees while the others are in radians" in out


# --- 7. never a wrong diagnosis: values beyond the trust limit are refused --------------------
def test_a_link_of_1e30_kg_is_refused_not_misdiagnosed(tmp_path, capsys):
    params = default_params("double_pendulum").replace(m1=1e30)
    toml = _write(tmp_path, "heavy.toml", params.to_toml())
    status, out, report = _check(capsys, "--params", toml, str(tmp_path / "x.json"))
    assert status == 1
    # the units row reads the model's expressions, not its values: judged at no state, it passes
    assert {r["status"] for r in report["results"] if r["check"] != "units"} == {"refused"}
    assert {r["status"] for r in report["results"] if r["check"] == "units"} == {"pass"}
    assert "diagnosis" not in out
    assert "> 1e-06, the trust limit); refused" in out
    assert "M's diagonal scales span a factor" in out
    assert report["status"] == "refused"


def test_a_heavy_link_within_the_trust_limit_still_catches_a_planted_error(tmp_path, capsys):
    params = default_params("double_pendulum").replace(m1=1e6)
    toml = _write(tmp_path, "heavy.toml", params.to_toml())
    status, out, report = _check(capsys, "--params", toml, str(tmp_path / "x.json"))
    assert status == 0, out
    wrong = _write(tmp_path, "wrong.urdf", urdf_for(params.replace(I2=params.I2 * 1.001)))
    status, out, report = _check(capsys, "--params", toml, "--urdf", wrong, str(tmp_path / "y.json"))
    assert status == 1
    assert _results(report)["crba"]["status"] == "fail"


def test_the_model_form_row_is_judged_even_when_states_are_refused(tmp_path, capsys):
    # a link 1 of 1e30 kg refuses every state, but the off-line centre of mass is a URDF fact
    params = default_params("double_pendulum").replace(m1=1e30)
    text = _off_line(urdf_for(params), 0.02)
    toml = _write(tmp_path, "heavy.toml", params.to_toml())
    urdf = _write(tmp_path, "heavy_off.urdf", text)
    status, out, report = _check(capsys, "--params", toml, "--urdf", urdf, str(tmp_path / "x.json"))
    assert status == 1
    results = _results(report)
    assert results["model-form"]["status"] == "fail"
    assert "the URDF lies outside the closed form's family" in out
    assert {r["status"] for n, r in results.items() if n not in ("model-form", "units")} == {"refused"}
