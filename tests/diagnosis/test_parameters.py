"""The inertial parameters a hand model implies: planted parameter errors are named, structural ones not.

Each shipped model is checked against the URDF of its true parameters (the reference
systems' ``urdf_for(params)``, the examples' shipped URDFs) with one inertial parameter of
the hand model planted wrong — a mass, a centre of mass (an offset parameter), an inertia
about the pivot (I replaced by I + m·r²) — where its parameters have one: the cart double
pendulum's point masses have no inertia to plant.  The planted model must fail the checks
and ``identify_parameters`` must name the link, the parameter and both values; a wrong trig
argument is ``structural``; the correct model gives [].  ``-s`` prints the figures.

Values are compared within their own rounding (``details["rounding"]``: the bound on a solved
value's error the rows' rounding allows, ``pendverify.diagnosis.parameters``) and the few
roundings of forming either side (m + x, I_c ± m·r², the test's own I + m·r²): at most five of
half an ulp each, of sums of positive terms, so 4ε relative (``_close``).
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest

from pendverify.analytic import MODELS, DoublePendulum
from pendverify.analytic.interface import BiasOnlyModel
from pendverify.analytic.plugin import load_model_class, plugin_parameters
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis import parameters
from pendverify.diagnosis.implied import implied_parameters
from pendverify.diagnosis.parameters import identify_parameters
from pendverify.robot.system import PinocchioSystem

from ..conftest import SEED, default_params

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
STATES = 40
EPS = float(np.finfo(float).eps)


# --- the models and their systems ------------------------------------------------------------
def _builtin(name: str):
    """(model class, true parameters, system on the URDF of the true parameters)."""
    params = default_params(name)
    return MODELS[name], params, PinocchioSystem.for_params(params)


def _example(stem: str):
    """(model class, true parameters, system on the shipped URDF) of examples/<stem>.py."""
    model_file = EXAMPLES / f"{stem}.py"
    cls = load_model_class(model_file)
    params = plugin_parameters(cls, str(model_file), str(EXAMPLES / f"{stem}.toml"))
    return cls, params, PinocchioSystem.for_model(cls, str(EXAMPLES / f"{stem}.urdf"), params.g)


SOURCES = {
    "double_pendulum": lambda: _builtin("double_pendulum"),
    "cart_double_pendulum": lambda: _builtin("cart_double_pendulum"),
    "cart_pole": lambda: _example("cart_pole"),
    "furuta_pendulum": lambda: _example("furuta_pendulum"),
    "triple_pendulum": lambda: _example("triple_pendulum"),
    "hanging_double_pendulum": lambda: _example("hanging_double_pendulum"),
}


def _batch(model, system) -> CheckBatch:
    return CheckBatch(model, system, sample_states(model, STATES, SEED))


def _failing(model, system, batch) -> bool:
    results = run_checks("planted", model, system, batch.states, SEED, batch=batch)
    return not all(r.passed for r in results)


def _close(value, expected, rounding=0.0) -> bool:
    """|value − expected| within the value's rounding and 4ε of forming either side (module docstring)."""
    return abs(value - expected) <= rounding + 4 * EPS * abs(expected)


# --- the planted cases ---------------------------------------------------------------------------
def _pivot(inertia: str, mass: str, offset: str):
    """I replaced by I + m·r²: the inertia about the pivot written where the centre of mass's is meant."""
    return lambda p: {inertia: getattr(p, inertia) + getattr(p, mass) * getattr(p, offset) ** 2}


#: (model, link, kind, planted parameter, its new value (or a function of the true parameters giving
#: the changes); for an inertia the component about the joint axis and the other planted moments)
PLANTS = [
    ("double_pendulum", "link2", "mass", "m2", 1.5),
    ("double_pendulum", "link2", "centre of mass", "r2", 0.3),
    ("double_pendulum", "link1", "inertia about the pivot", "I1", _pivot("I1", "m1", "r1")),
    ("cart_double_pendulum", "cart", "mass", "m", 2.0),
    ("cart_double_pendulum", "rod1", "mass", "m1", 0.7),
    ("cart_double_pendulum", "rod2", "centre of mass", "l2", 0.8),
    ("cart_pole", "pole", "mass", "mp", 0.6),
    ("cart_pole", "cart", "mass", "mc", 2.0),
    ("cart_pole", "pole", "centre of mass", "r", 0.35),
    ("cart_pole", "pole", "inertia about the pivot", "I", _pivot("I", "mp", "r")),
    ("furuta_pendulum", "pendulum", "mass", "mp", 0.15),
    ("furuta_pendulum", "pendulum", "centre of mass", "lp", 0.12),
    (
        "furuta_pendulum",
        "pendulum",
        "inertia about the pivot",
        "Jpxx",
        lambda p: {**_pivot("Jpxx", "mp", "lp")(p), **_pivot("Jpyy", "mp", "lp")(p)},
    ),
    ("furuta_pendulum", "arm", "inertia about the pivot", "Jrzz", _pivot("Jrzz", "mr", "cr")),
    ("triple_pendulum", "link2", "mass", "m2", 0.8),
    ("triple_pendulum", "link3", "centre of mass", "r3", 0.12),
    ("triple_pendulum", "link1", "inertia about the pivot", "I1", _pivot("I1", "m1", "r1")),
    ("hanging_double_pendulum", "link1", "mass", "m1", 1.3),
    ("hanging_double_pendulum", "link2", "centre of mass", "r2", 0.3),
    ("hanging_double_pendulum", "link2", "inertia about the pivot", "I2", _pivot("I2", "m2", "r2")),
]
#: the joint axis of each inertia planted, in its link frame (the URDFs' joint axes: x, −y for the pole)
AXIS = {"double_pendulum": 0, "cart_pole": 1, "triple_pendulum": 0, "hanging_double_pendulum": 0}
#: the moments each inertia parameter is about (Furuta's pendulum: x the hinge, y across its face;
#: its arm: z the vertical)
MOMENT = {"Jpxx": 0, "Jpyy": 1, "Jrzz": 2}


def _case_id(case) -> str:
    return f"{case[0]}:{case[3]}"


def _planted(case):
    name, _, _, parameter, value = case
    cls, params, system = SOURCES[name]()
    changes = value(params) if callable(value) else {parameter: value}
    return cls(params.replace(**changes)), params, changes, system


def _check_case(case) -> None:
    """Assert that the planted case fails the checks and is named with its link, parameter and values."""
    name, link, kind, parameter, _ = case
    model, true, changes, system = _planted(case)
    batch = _batch(model, system)
    assert _failing(model, system, batch), "the planted error must fail the checks"
    (finding,) = identify_parameters(batch)
    d = finding.details
    assert finding.kind == "parameters"
    assert (d["link"], d["parameter"]) == (link, kind), finding.message
    assert "alternatives" not in d
    assert finding.message.startswith(f"your equations are this URDF with {link}'s ")
    new, old = changes[parameter], getattr(true, parameter)
    if kind == "mass":
        assert _close(d["model_value"], new, d["rounding"]), (d["model_value"], new)
        assert _close(d["urdf_value"], old)
    elif kind == "centre of mass":
        # the offset parameter is the centre of mass's distance along the link, whichever its sign
        assert _close(abs(d["urdf_value"]), old)
        assert _close(d["model_value"], d["urdf_value"] * new / old, d["rounding"]), (d["model_value"], new)
    else:
        assert d["rounding"] == 0.0  # no unknown: I_c ± m·r² is the URDF's own
        model_I, urdf_I = np.array(d["model_value"]), np.array(d["urdf_value"])
        for moment, value in changes.items():
            k = MOMENT[moment] if moment in MOMENT else AXIS[name]
            assert _close(model_I[k, k], value), (moment, model_I[k, k], value)
            assert _close(urdf_I[k, k], getattr(true, moment)), moment
        assert "counted twice" in finding.message


def test_every_planted_parameter_is_named_with_its_values():
    named, problems = [], []
    for case in PLANTS:
        try:
            _check_case(case)
        except AssertionError as error:
            problems.append(f"{_case_id(case)}: {error}")
        else:
            named.append(_case_id(case))
    models = len({case[0] for case in PLANTS})
    print(f"\nparameters: {len(named)} of {len(PLANTS)} planted cases named ({models} models):")
    print("  " + ", ".join(named))
    assert not problems, "\n".join(problems)


# --- the correct models, and a structural error -------------------------------------------------
@pytest.mark.parametrize("name", list(SOURCES))
def test_the_correct_model_gives_nothing(name):
    cls, params, system = SOURCES[name]()
    batch = _batch(cls(params), system)
    implied = implied_parameters(batch)
    print(f"\n{name}: the URDF's residual {implied.urdf_residual / implied.tolerance:.3g} of the tolerance")
    assert implied.agrees
    assert identify_parameters(batch) == []


class GravityMinus(DoublePendulum):
    """cos(θ1 − θ2) where the gravity has cos(θ1 + θ2): no mass distribution gives it."""

    def gravity(self, q):
        p = self.params
        c1, c12 = self.math.cos(q[0]), self.math.cos(q[0] - q[1])
        return np.array(
            [p.m1 * p.g * p.r1 * c1 + p.m2 * p.g * (p.l1 * c1 + p.r2 * c12), p.m2 * p.g * p.r2 * c12]
        )


def test_a_wrong_trig_argument_is_structural():
    params = default_params("double_pendulum")
    model, system = GravityMinus(params), PinocchioSystem.for_params(params)
    batch = _batch(model, system)
    assert _failing(model, system, batch)
    (finding,) = identify_parameters(batch)
    assert finding.kind == "structural"
    assert finding.message.startswith(
        "no mass distribution of this robot produces your equations: the difference is structural: "
        "H on its own is not this robot's for any inertial parameters; leaving out H[1], H[2], "
        "parameters reproduce the rest"
    )
    assert finding.details["entries"] == ["H[1]", "H[2]"]
    assert finding.details["residual"] > 1e-2  # cos(θ1 − θ2) against cos(θ1 + θ2): an O(1) difference


class BetaOff(DoublePendulum):
    """β = m2·l1·r2 off by 1e-6 alone: M and C·q̇ imply another m2·r2 than H does (a length, not a mass)."""

    @property
    def beta(self):
        return super().beta * (1 + 1e-6)


def test_a_small_structural_difference_is_not_taken_for_parameters():
    """The guard of rounding-level fits: 1e-6 of one constant is far beyond it."""
    params = default_params("double_pendulum")
    batch = _batch(BetaOff(params), PinocchioSystem.for_params(params))
    (finding,) = identify_parameters(batch)
    assert finding.kind == "structural"
    assert "M, C·q̇, H are each this robot's with some inertial parameters" in finding.message
    assert "(M and C·q̇ together are)" in finding.message
    assert 1e-8 < finding.details["residual"] < 1e-6


def test_a_small_parameter_difference_is_still_found():
    """The real case under the same guard: a mass off by 1e-9 is a mass, named with digits enough."""
    cls, params, system = _builtin("double_pendulum")
    heavier = params.m2 * (1 + 1e-9)
    (finding,) = identify_parameters(_batch(cls(params.replace(m2=heavier)), system))
    assert (finding.details["link"], finding.details["parameter"]) == ("link2", "mass")
    assert _close(finding.details["model_value"], heavier, finding.details["rounding"])
    assert "link2's mass 0.800000001 kg instead of 0.8 kg" in finding.message


class ForceOnly(BiasOnlyModel, DoublePendulum):
    """The double pendulum giving C·q̇ as a force, ``factor`` times the true one."""

    factor = 1.0

    def coriolis_force(self, q, v):
        return self.factor * (DoublePendulum.coriolis_matrix(self, q, v) @ v)


class ForceDoubled(ForceOnly):
    factor = 2.0


def test_a_model_without_a_matrix_c_is_read_by_its_force():
    _, params, system = _builtin("double_pendulum")
    assert identify_parameters(_batch(ForceOnly(params), system)) == []
    batch = _batch(ForceDoubled(params), system)
    assert _failing(ForceDoubled(params), system, batch)
    (finding,) = identify_parameters(batch)
    assert finding.kind == "structural"
    assert finding.details["entries"] == ["C·q̇[1]", "C·q̇[2]"]
    assert "(M and H together are); leaving out C·q̇[1], C·q̇[2], parameters reproduce the rest" in (
        finding.message
    )


# --- two changes, more, and changes the equations cannot tell apart ------------------------------
def test_two_changes_are_named_together():
    cls, params, system = _builtin("double_pendulum")
    findings = identify_parameters(_batch(cls(params.replace(m1=1.2, r2=0.3)), system))
    assert [(f.details["link"], f.details["parameter"]) for f in findings] == [
        ("link1", "mass"),
        ("link2", "centre of mass"),
    ]
    for finding, value in zip(findings, (1.2, 0.3), strict=True):
        assert _close(finding.details["model_value"], value, finding.details["rounding"])
    assert findings[0].message == findings[1].message
    assert " and link2's centre of mass at y = 0.3 m instead of 0.22 m" in findings[0].message


def test_pairs_beyond_the_bound_are_not_tried_and_said_so(monkeypatch):
    """With fewer groups allowed than a double pendulum's singles and pairs, the pair of changes
    named above is not searched: the combinations are listed instead, and ``unsearched`` says so."""
    cls, params, system = _builtin("double_pendulum")
    monkeypatch.setattr(parameters, "MAX_GROUPS", 10)
    unsearched = []
    (finding,) = identify_parameters(_batch(cls(params.replace(m1=1.2, r2=0.3)), system), unsearched)
    assert finding.details["parameter"] == "identifiable combinations"
    (said,) = unsearched
    assert said.startswith("pairs of changes of the inertial parameters (") and said.endswith(
        " pairs, beyond 10)"
    )


def test_a_fit_beyond_its_work_bound_is_not_run_and_said_so(monkeypatch):
    cls, params, system = _builtin("double_pendulum")
    batch = _batch(cls(params.replace(m1=1.2)), system)
    assert identify_parameters(batch)  # within the bound: the heavier link is named
    rows = len(batch) * (2 * 2 + 2 * 2)
    monkeypatch.setattr(parameters, "MAX_FIT_WORK", rows * 20**2 - 1)
    unsearched = []
    assert identify_parameters(batch, unsearched) == []
    assert unsearched == [
        f"the inertial parameters (a fit of 20 parameters to {rows} rows, beyond the bound of "
        f"{rows * 400 - 1:.0e} on its work)"
    ]


def test_three_changes_list_the_identifiable_combinations():
    """The base parameters of a planar double pendulum, α − δ, m1·r1 + m2·l1, δ, m2·r2, from the hand's
    own parameters: what the listed combinations must be."""
    cls, params, system = _builtin("double_pendulum")
    hand = params.replace(m1=1.2, r2=0.3, I1=0.03)
    (finding,) = identify_parameters(_batch(cls(hand), system))
    d = finding.details
    assert (d["link"], d["parameter"]) == (["link1", "link2"], "identifiable combinations")
    expected = {
        "I_xx(link1) + 0.25·m(link2)": hand.I1 + hand.m1 * hand.r1**2 + hand.m2 * hand.l1**2,
        "m·c_y(link1) + 0.5·m(link2)": hand.m1 * hand.r1 + hand.m2 * hand.l1,
        "I_xx(link2)": hand.I2 + hand.m2 * hand.r2**2,
        "m·c_y(link2)": hand.m2 * hand.r2,
    }
    assert d["combinations"] == list(expected)
    for value, rounding, want in zip(d["model_value"], d["rounding"], expected.values(), strict=True):
        assert _close(value, want, rounding), (value, want)
    assert "no one or two changes" in finding.message


def test_changes_the_equations_cannot_tell_apart_are_all_reported():
    """A Furuta arm turns about the vertical only: its mass, centre of mass and I_zz enter only as one
    combination, so each explanation is reported as one of several (the real one among them)."""
    cls, params, system = _example("furuta_pendulum")
    findings = identify_parameters(_batch(cls(params.replace(mr=0.3)), system))
    named = {(f.details["link"], f.details["parameter"]) for f in findings}
    assert ("arm", "mass") in named and ("arm", "centre of mass") in named
    assert {f.details["alternatives"] for f in findings} == {len(findings)}
    assert len(findings) > 1
    for f in findings:
        assert f"one of {len(findings)} explanations your M, C·q̇ and H cannot tell apart" in f.message
        assert "they fix only I_zz(arm) + I_zz(pendulum)" in f.message
    (mass,) = [f for f in findings if f.details["parameter"] == "mass"]
    assert _close(mass.details["model_value"], 0.3, mass.details["rounding"])


def test_an_inertia_that_is_not_the_pivot_s_is_one_component():
    """The guard that prefers the pivot explanation: an I off by other than m·r² is its own component."""
    cls, params, system = _builtin("double_pendulum")
    (finding,) = identify_parameters(_batch(cls(params.replace(I2=params.I2 + 0.01)), system))
    d = finding.details
    assert (d["link"], d["parameter"], d["component"]) == ("link2", "inertia about the centre of mass", "xx")
    assert _close(d["model_value"], params.I2 + 0.01, d["rounding"])


def test_a_first_moment_with_the_inertia_about_the_joint_kept_is_named():
    """r2 changed in β and H only: I2 + m2·r2² (the inertia about joint 2) kept, so m·c_y alone moves."""
    cls, params, system = _builtin("double_pendulum")
    r2 = 0.25
    hand = params.replace(r2=r2, I2=params.I2 + params.m2 * (params.r2**2 - r2**2))
    (finding,) = identify_parameters(_batch(cls(hand), system))
    d = finding.details
    assert (d["link"], d["parameter"], d["axis"]) == ("link2", "first moment", "y")
    assert _close(d["model_value"], params.m2 * r2, d["rounding"])
    assert _close(d["urdf_value"], params.m2 * params.r2)
    assert "(its centre of mass at y = 0.25 m, with its inertia about the joint kept?)" in finding.message


def test_a_urdf_inertia_about_the_pivot_is_named():
    """The other sign: the URDF's <inertia> of link1 is about the pivot, the hand model's about the centre."""
    cls, params, _ = _builtin("double_pendulum")
    pivot = params.I1 + params.m1 * params.r1**2
    system = PinocchioSystem.for_params(params.replace(I1=pivot))
    model = cls(params)
    batch = _batch(model, system)
    assert _failing(model, system, batch)
    (finding,) = identify_parameters(batch)
    d = finding.details
    assert (d["link"], d["parameter"]) == ("link1", "inertia about the pivot")
    assert (
        "link1's inertia smaller than the URDF's by the parallel-axis term m·|c|² = 0.0625 kg·m²: your M "
        "misses the parallel-axis term, or the URDF's <inertia> of link1 is about the pivot"
    ) in finding.message
    assert _close(d["model_value"][0][0], params.I1) and _close(d["urdf_value"][0][0], pivot)


def test_a_rod_missing_its_parallel_axis_term_is_blamed_on_the_hand_model_alone():
    """Against a right URDF, link 1's <inertia> (0.0208 kg·m² < m1·r1² = 0.0625 kg·m²) cannot be
    about the pivot: the parameters finding names the hand model's side only."""
    cls, params, system = _builtin("double_pendulum")

    class Missing(cls):
        @property
        def alpha(self):
            return super().alpha - self.params.m1 * self.params.r1**2

    model = Missing(params)
    batch = _batch(model, system)
    assert _failing(model, system, batch)
    (finding,) = identify_parameters(batch)
    assert finding.details["parameter"] == "inertia about the pivot"
    assert "link1's inertia smaller than the URDF's by the parallel-axis term" in finding.message
    one_side = "your M misses the parallel-axis term (the URDF's <inertia> of link1 cannot be about"
    assert one_side in finding.message
    assert "or the URDF" not in finding.message


def test_the_identifiable_combinations_of_a_planar_chain():
    """Two links turning about x: each has I_xx and the first moments in its plane; link 2's mass folds
    into link 1's with l1² and l1."""
    cls, params, system = _builtin("double_pendulum")
    implied = implied_parameters(_batch(cls(params), system))
    assert [c.name for c in implied.combinations] == [
        "I_xx(link1) + 0.25·m(link2)",
        "m·c_y(link1) + 0.5·m(link2)",
        "m·c_z(link1)",
        "I_xx(link2)",
        "m·c_y(link2)",
        "m·c_z(link2)",
    ]
    assert not any(c.differs for c in implied.combinations)


# --- bounded ---------------------------------------------------------------------------------------
def test_two_changes_of_a_three_dof_model_are_both_named():
    """Two changes of the triple pendulum: every single and every pair of hypotheses is tried.
    The time is printed (``-s``), not asserted: tests never assert wall times."""
    cls, params, system = _example("triple_pendulum")
    model = cls(params.replace(m1=1.0, r2=0.2))
    batch = _batch(model, system)
    _ = batch.terms.M_hand, batch.terms.C_hand, batch.terms.H_hand, batch.lever  # the hand model's own work
    start = time.perf_counter()
    findings = identify_parameters(batch)
    elapsed = time.perf_counter() - start
    print(f"\ntriple pendulum, {len(batch)} states, two changes: identify_parameters {elapsed * 1e3:.0f} ms")
    assert [(f.details["link"], f.details["parameter"]) for f in findings] == [
        ("link1", "mass"),
        ("link2", "centre of mass"),
    ]
    assert math.isfinite(findings[0].details["residual"])
