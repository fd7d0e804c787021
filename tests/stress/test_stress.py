"""The stress catalogue: every case passes (quick settings), and every case can fail.

Each planted error is a wrong model, a disabled guard or a garbage value; the
case that looks at it must report a failure, never a silent pass.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS, CartDoublePendulum, DoublePendulum
from pendverify.checks import trust as near_singular
from pendverify.checks import verification
from pendverify.checks.batch import world_lever
from pendverify.checks.trust import Conditioning, check_conditioning
from pendverify.cli import main
from pendverify.errors import IllConditionedError, InputError
from pendverify.stress import catalogue as stress
from pendverify.stress import framework, reference_cases, trust_study
from pendverify.stress.catalogue import CART, DP, HardSet, hard_set_case
from pendverify.validate import finite_state, model_state

from ..conftest import default_params, system_for


@pytest.fixture(scope="module")
def ctx():
    """One context for the module, so the trust study runs once."""
    return framework.Context(framework.QUICK)


def _case(name):
    return next(c for c in stress.catalogue() if c.name == name)


# --- the catalogue passes ----------------------------------------------------------------------
@pytest.mark.parametrize("name", stress.CASE_NAMES)
def test_case_passes(ctx, name):
    result = stress.run_case(_case(name), ctx)
    assert result.passed, f"{name}: {result.quantity} {result.error} > {result.tolerance}; {result.note}"
    if result.error is not None:
        assert result.error <= result.tolerance, name
    assert result.seed == framework.SEED


def test_catalogue_covers_the_issue():
    groups = {c.group for c in stress.catalogue()}
    assert groups == {
        "mass ratio",
        "length",
        "near singular",
        "point mass",
        "large angle",
        "high speed",
        "stiff damping",
        "long horizon",
        "zero gravity",
        "invalid input",
    }
    assert len(set(stress.CASE_NAMES)) == len(stress.CASE_NAMES)


BUILT_IN_CASES = ["cart g = 0", "cart m1 → 0: trust study", "double pendulum l1 1e3 m, l2 1e-3 m"]
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.parametrize(
    ("argv", "texts", "cases", "trust_limit_kg"),
    [
        pytest.param(
            [arg for name in BUILT_IN_CASES for arg in ("--case", name)],
            ("3 stress cases", "measured trust limit (every quantity): m1 ≥ 1e-08 kg"),
            BUILT_IN_CASES,
            1e-8,
            id="built-in",
        ),
        pytest.param(
            [
                "--analytic",
                str(EXAMPLES / "cart_pole.py"),
                "--urdf",
                str(EXAMPLES / "cart_pole.urdf"),
                "--params",
                str(EXAMPLES / "cart_pole.toml"),
            ],
            ("mc ×1e-6", "near-singular M", "not varied:", "parameter bx (damping)"),
            None,
            None,
            id="plug-in",
        ),
    ],
)
def test_cli_quick_table_json_and_exit_status(tmp_path, capsys, argv, texts, cases, trust_limit_kg):
    """The table, its notes and the JSON: of catalogue cases, or of a model file's generic cases."""
    out_json = tmp_path / "stress.json"
    assert main(["stress", "--quick", *argv, "--json", str(out_json)]) == 0
    out = capsys.readouterr().out
    for text in (
        "case",
        "error",
        "tolerance",
        "ratio",
        "κ̃(M)",
        "result",
        "refused",
        "worst error/tolerance",
        "all cases pass",
        *texts,
    ):
        assert text in out
    report = json.loads(out_json.read_text())
    assert report["passed"] is True and report["seed"] == framework.SEED
    if cases is not None:
        assert sorted(r["case"] for r in report["results"]) == sorted(cases)  # in catalogue order
    for r in report["results"]:
        assert {"error", "tolerance", "kappa_raw", "kappa_scaled", "invariant", "passed", "verdict"} <= set(r)
    if trust_limit_kg is not None:
        assert report["near_singular"]["measured_limit_kg"] == trust_limit_kg


def test_cli_unknown_case_is_exit_2(capsys):
    assert main(["stress", "--case", "nope"]) == 2
    assert "unknown stress case 'nope'; known: cart/bobs mass 1e-6" in capsys.readouterr().err


def test_cli_failure_is_exit_1(monkeypatch, capsys):
    monkeypatch.setattr(reference_cases, "model_state", lambda *a, **k: None)  # the NaN guard is gone
    assert main(["stress", "--quick", "--case", "NaN, inf, negative, zero"]) == 1
    out = capsys.readouterr().out
    assert "FAIL" in out and "1 case(s) FAIL" in out
    assert "accepted silently: NaN state, infinite rate" in out


# --- planted errors: each case can fail ---------------------------------------------------------
class BetaOff(DoublePendulum):
    @property
    def beta(self):
        return super().beta * (1 + 1e-6)


class CartCoriolisSignFlip(CartDoublePendulum):
    def coriolis_matrix(self, y, yd):
        C = super().coriolis_matrix(y, yd)
        C[0, 2] = -C[0, 2]
        return C


class NotPeriodic(DoublePendulum):
    """Gravity with a term that is not 2π-periodic: below the (1 + |θ|)·ε tolerance up to |θ| = 100."""

    def gravity(self, q):
        return super().gravity(q) * (1 + 1e-18 * q[0] ** 2)


class NaNAtHighSpeed(DoublePendulum):
    def acceleration(self, q, v, u, w):
        return np.full(2, np.nan) if np.max(np.abs(v)) > 500 else super().acceleration(q, v, u, w)


class EnergyPump(CartDoublePendulum):
    """Friction with the wrong sign in q̈: energy rises."""

    def f(self, y, yd, u, w):
        return super().f(y, yd, u, w) + 2 * self.damping_matrix() @ yd


class WrongCoriolis(DoublePendulum):
    """One Coriolis term flipped in C and in ``seed_coriolis_matrix`` (C + D): q̈ disagrees with E."""

    def seed_coriolis_matrix(self, q, v):
        C = super().seed_coriolis_matrix(q, v)
        C[1, 0] = -C[1, 0]
        return C


class CartPushed(CartDoublePendulum):
    """A spurious constant force on the cart: its momentum is no longer conserved."""

    def gravity(self, y):
        return super().gravity(y) + np.array([1e-6, 0.0, 0.0])


def _entry(name: str) -> HardSet:
    return next(e for e in stress.CATALOGUE if e.name == name)


@pytest.mark.parametrize(
    ("entry", "planted"),
    [
        (_entry("link1/link2 mass 1e-6"), BetaOff),
        (_entry("cart rods 1e3 m"), CartCoriolisSignFlip),
        (_entry("double pendulum lengths ×1e3 (km)"), BetaOff),
        (_entry("double pendulum |θ| ≈ 1e6 rad"), NotPeriodic),
        (_entry("double pendulum |q̇| ≤ 1e3"), NaNAtHighSpeed),
        (
            HardSet(
                "planted pump",
                "stiff damping",
                CART,
                {"d1": 1e4, "d2": 1e4, "d3": 1e4},
                kind="stiff",
                start=((0.0, 3.0, 3.4),),
            ),
            EnergyPump,
        ),
        (_entry("double pendulum 1e4 s, conservative"), WrongCoriolis),
        (_entry("cart g = 0: simulate"), CartPushed),
    ],
    ids=lambda x: getattr(x, "name", getattr(x, "__name__", "")),
)
def test_planted_error_fails_its_case(ctx, entry, planted):
    """The catalogue's hard set (through the same entry point as the catalogue) on a planted model."""
    result = stress.run_case(hard_set_case(entry, planted), ctx)
    assert not result.passed, f"{entry.name} passed: {result}"
    assert result.verdict == "FAIL"


def test_planted_large_angle_passes_at_small_angles(ctx):
    """The non-periodic term is invisible in the ordinary check: only the 2πk invariance sees it."""
    case = hard_set_case(HardSet("small angles", "large angle", DP), NotPeriodic)
    assert stress.run_case(case, ctx).passed


def test_without_the_guard_the_singular_cases_fail(monkeypatch, ctx):
    """Refusal is what keeps a 1e12-conditioned case from passing garbage: disable it, and it fails."""
    monkeypatch.setattr(
        verification, "check_conditioning", lambda *a, **k: Conditioning(1.0, 1.0, 0.0, "ok", 1.0)
    )
    for name in ("double pendulum l1 1e3 m, l2 1e-3 m", "cart rods 1e-3 m / 1e3 m"):
        result = stress.run_case(_case(name), ctx)
        assert not result.passed, name
        assert "FAIL" in result.note


def test_trust_study_fails_without_the_guard(monkeypatch):
    monkeypatch.setattr(near_singular, "assess", lambda *a, **k: Conditioning(1.0, 1.0, 1e-15, "ok", 1.0))
    ctx = framework.Context(framework.QUICK)
    result = stress.run_case(_case("cart m1 → 0: trust study"), ctx)
    assert not result.passed
    assert "m1 = 0: NOT refused" in result.invariant


def test_trust_study_fails_on_garbage_aba(monkeypatch):
    from pendverify.robot.system import PinocchioSystem

    real = PinocchioSystem.acceleration
    monkeypatch.setattr(PinocchioSystem, "acceleration", lambda self, *a: real(self, *a) * (1 + 1e-9))
    result = stress.run_case(_case("cart m1 → 0: trust study"), framework.Context(framework.QUICK))
    assert not result.passed
    assert "measured" in result.note and "> bound" in result.note


def test_det_case_fails_on_a_cancelling_det(monkeypatch):
    monkeypatch.setattr(
        CartDoublePendulum, "det_mass_matrix", lambda self, y: float(np.linalg.det(self.mass_matrix(y)))
    )
    result = stress.run_case(_case("cart det M: closed form vs LU"), framework.Context(framework.QUICK))
    assert not result.passed and result.error > 1e-10


# --- the trust rule -------------------------------------------------------------------------------
def test_check_conditioning_refuses_with_a_message():
    params = default_params("cart_double_pendulum").replace(m1=1e-12)
    with pytest.raises(IllConditionedError) as info:
        check_conditioning(CartDoublePendulum(params), np.zeros(3), what="cart")
    assert str(info.value).startswith("cart at q = (0, 0, 0): too ill-conditioned to verify: κ̃(M) = 3.69e+12")
    assert str(info.value).endswith("> 1e-06 (the trust limit); refused")


def test_conditioning_levels_and_scaling():
    model = CartDoublePendulum(default_params("cart_double_pendulum"))
    ok = check_conditioning(model, np.zeros(3))
    assert ok.level == "ok" and ok.note == ""
    assert ok.kappa_raw > ok.kappa_scaled  # raw κ overstates what comes from units
    warn = check_conditioning(CartDoublePendulum(model.params.replace(m1=1e-5)), np.zeros(3))
    assert warn.level == "warn" and warn.note.startswith("warn: κ̃(M) = 3.69e+05")
    big = near_singular.conditioning(np.eye(2), angle=1e9)
    assert big.level == "refuse"  # an angle of 1e9 rad is only known to ε·1e9


def test_term_amplification_grows_with_the_square_of_the_lever_arm():
    params = default_params("cart_double_pendulum").replace(l1=1e-3, l2=1e-3)
    model, system = CartDoublePendulum(params), system_for(params)
    near, one, eight = (world_lever(model, system, np.array([x, 0.7, 0.7])) for x in (0.0, 1.0, 8.0))
    assert 1 <= near < 20  # a 1 mm pendulum at the origin: terms as large as the result
    assert 60 < eight / one < 68  # 1 mm rods 1 m and 8 m from the origin: (8/1)²


def test_zero_mass_aba_is_finite_nonsense_and_refused():
    accel, refused = trust_study.zero_mass_demo(default_params("cart_double_pendulum"))
    assert np.all(np.isfinite(accel)) and np.max(np.abs(accel)) > 1e9
    assert refused


def test_reference_matches_the_closed_form():
    """The 50-digit M and q̈ (the generated generic code on mpf) are the closed form's, to its rounding."""
    import mpmath as mp

    for name, q in (("cart_double_pendulum", [0.1, 0.7, -1.2]), ("double_pendulum", [0.3, 1.1])):
        model = MODELS[name](default_params(name))
        v, u, w = np.linspace(0.4, -0.9, model.nv), np.full(len(model.inputs), 0.5), np.ones(model.nv)
        numbers = trust_study.reference_numbers(model, u, w[: len(model.disturbances)])
        with mp.workdps(trust_study.REFERENCE_DIGITS):
            M = trust_study.reference_mass_matrix(numbers, q)
            ref = np.array([[float(M[i, j]) for j in range(M.cols)] for i in range(M.rows)])
            accel = np.array([float(a) for a in trust_study.reference_acceleration(numbers, q, v)])
        np.testing.assert_allclose(model.mass_matrix(np.array(q)), ref, rtol=2e-15, atol=1e-16)
        # the double q̈ is an LU solve with κ(M) ≤ 50 at these states: within ~50·ε of its terms
        expected = model.acceleration(np.array(q), v, u, w[: len(model.disturbances)])
        np.testing.assert_allclose(expected, accel, rtol=1e-13, atol=1e-13)


def test_reference_acceleration_sees_the_input_and_the_disturbance():
    """Planted: u and w left out of the reference (zero) move q̈ by M⁻¹ (B u + W w), far above rounding."""
    import mpmath as mp

    model = MODELS["cart_double_pendulum"](default_params("cart_double_pendulum"))
    y, v, u, w = trust_study.study_states()["theta1=theta2=0, torque on rod 1"]
    with mp.workdps(trust_study.REFERENCE_DIGITS):
        right = trust_study.reference_acceleration(trust_study.reference_numbers(model, u, w), y, v)
        wrong = trust_study.reference_acceleration(trust_study.reference_numbers(model), y, v)
    assert trust_study._rel([float(a) for a in wrong], right) > 1e-3


# --- validation -----------------------------------------------------------------------------------
def test_finite_state_names_the_entry():
    with pytest.raises(InputError) as info:
        finite_state("q", [0.0, math.nan])
    assert str(info.value) == "<state>: key 'q[1]' = nan: a state entry must be a finite number"
    with pytest.raises(InputError, match=r"key 'v\[0\]' = inf: a state entry must be a finite number"):
        finite_state("v", [math.inf])
    with pytest.raises(InputError, match="must have 3 entries; got 2"):
        finite_state("q", [1.0, 2.0], size=3)
    with pytest.raises(InputError, match="must be a vector of numbers; got a str"):
        finite_state("q", "0 0")
    assert finite_state("q", 1.5).tolist() == [1.5]


def test_model_state_fills_zeros_and_checks_sizes():
    model = CartDoublePendulum(default_params("cart_double_pendulum"))
    _, v, u, w = model_state(model, [0, 0, 0])
    assert v.shape == (3,) and u.shape == (1,) and w.shape == (3,)
    with pytest.raises(InputError, match=r"<src>: key 'w\[2\]' = -inf"):
        model_state(model, [0, 0, 0], w=[0, 0, -math.inf], source="<src>")


@pytest.mark.parametrize(
    "bad, key, rule",
    [
        ({"v": np.array([0.0, math.nan])}, "v[1]", "finite"),
        ({"q": np.array([0.0, 1.0, 2.0])}, "q", "must have 2 entries"),
        ({"q": [0.0, math.inf]}, "q[1]", "finite"),  # a list, not an array: checked one by one
    ],
)
def test_compare_refuses_a_bad_state_by_name_among_good_ones(bad, key, rule):
    """The states are checked all at once when they are clean; a bad one still raises its
    own error, naming the case, the state, the key and the rule."""
    import dataclasses

    from pendverify.checks.sampling import sample_states

    model = DoublePendulum(default_params("double_pendulum"))
    states = sample_states(model, 8, 1)
    states[5] = dataclasses.replace(states[5], **bad)
    with pytest.raises(InputError) as exc:
        framework.compare("case", model, system_for(model.params), states, 1)
    text = str(exc.value)
    assert f"<case: {states[5].label}>" in text and f"'{key}'" in text and rule in text, text
