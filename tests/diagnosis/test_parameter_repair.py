"""Repairs of models SymPy cannot read, searched in the parameter set their code is given.

Each model is written by the conformance matrix's generators (``tests/conformance/formats.py``)
or is the NumPy-functions double pendulum of ``tests/analytic/test_numpy_model.py``, with one
parameter misuse planted in its code:

* dynamics as code (the acrobot's ẋ = f(x, u)): ``m2 = 2 * parameters['m2']``, the mass doubled
  wherever the code uses it → ``m2 → m2/2``, confirmed;
* NumPy functions (the double pendulum): I2 read as the inertia about joint 2 (δ = I2, and I2
  without m2·r2² in α) → ``I2 → I2 + m2*r2**2``, confirmed;
* a Python class whose methods call ``np.cos`` (the triple pendulum): l1 and l2 read the other's
  value → the exchange ``l1 ↔ l2``, confirmed.

The untouched models get no claim; an error confined to one term (an entry of M times 11/10, the
conformance matrix's ``Plant``) gets no parameter repair, the sentence saying none of the edits
holds, and its entries are still named; a value coincidence (I2 = m2·r2²/3, where 4·I2 and
I2 + m2·r2² are the same number; m1 = m2) is never printed as confirmed.
"""

from __future__ import annotations

import dataclasses
from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp

from pendverify.analytic.derived_scales import term_bound
from pendverify.bench.explain import QUICK_PER_OPERATOR, class_targets
from pendverify.bench.explain import _target as load_target
from pendverify.checks.batch import CheckBatch
from pendverify.checks.catalogue import applicable_checks, run_checks
from pendverify.checks.sampling import sample_states
from pendverify.diagnosis.code_corpus import OPERATORS, code_plants, sample_code_plants, score_code_model
from pendverify.diagnosis.code_parts import read_parameters
from pendverify.diagnosis.explain import explain
from pendverify.diagnosis.parameter_edits import ParameterEdit, parameter_edits
from pendverify.diagnosis.repair import search_repair
from tests.analytic.test_numpy_model import DOUBLE_PENDULUM
from tests.conformance.formats import Model, Plant, write_class, write_model, write_parameters
from tests.conformance.systems import SYSTEMS, write_description

from ..conftest import SEED

REPO = Path(__file__).resolve().parents[2]
DP_URDF = REPO / "urdf" / "double_pendulum.urdf"
DP_PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
SAMPLES = 60
#: the words only a confirmed repair is printed with (as for an expression's repair)
CONFIRMED_WORDS = "at these parameter values and at"


def _planted(text: str, right: str, wrong: str) -> str:
    assert right in text, right  # the planted change must change something
    return text.replace(right, wrong)


def _conformance(
    tmp_path: Path, system: str, fmt: str, plant: Plant | None = None
) -> tuple[Path, Path, Path]:
    """(model file, URDF, parameter file) of a conformance system written in ``fmt``."""
    model = Model(SYSTEMS[system], "urdf", plant)
    path = write_model(model, fmt, tmp_path)
    return path, write_description(model.system, "urdf", tmp_path), write_parameters(model, tmp_path)


def _numeric_class(
    tmp_path: Path, system: str, planted: tuple[str, str] | None = None
) -> tuple[Path, Path, Path]:
    """The conformance class of ``system`` with ``np.cos``/``np.sin`` for ``self.math``'s (SymPy
    cannot read it) and its gravity scale written out (Σ|terms| of H, which SymPy would derive)."""
    path, urdf, params = _conformance(tmp_path, system, "class")
    model = Model(SYSTEMS[system], "urdf")
    names = list(model.kinds)
    bounds = ", ".join(sp.pycode(term_bound(h)) for h in model.forms.H)
    text = _planted(
        write_class(model), "cos, sin = self.math.cos, self.math.sin", "cos, sin = np.cos, np.sin"
    )
    text += (
        "\n    def gravity_scale(self):\n        p = self.params\n"
        f"        {', '.join(names)} = {', '.join('p.' + k for k in names)}\n"
        f"        return np.array([{bounds}])\n"
    )
    if planted is not None:
        text = _planted(text, *planted)
    path = tmp_path / f"numeric_{path.name}"
    path.write_text(text)
    return path, urdf, params


def _batch(model_file, urdf, params):
    model, system = load_target(model_file, urdf, params)
    states = sample_states(model, SAMPLES, SEED)
    batch = CheckBatch(model, system, states)
    results = run_checks("t", model, system, states, SEED, applicable_checks(model, system), batch)
    return batch, results


def _diagnosis(model_file, urdf, params) -> tuple[list, list]:
    """(every finding, the repair findings) of a planted model, which must fail a check."""
    batch, results = _batch(model_file, urdf, params)
    assert not all(r.passed for r in results), "the planted error must fail a check"
    findings = explain(batch, results)
    repairs = [f for f in findings if f.kind == "repair"]
    for f in repairs:  # the confirmed words belong to a confirmed repair only
        assert (CONFIRMED_WORDS in f.message) is bool(f.details.get("confirmed")), f.message
    return findings, repairs


def _count(model) -> int:
    """How many edits the search tries on ``model`` (those of the parameters its code reads)."""
    return len(parameter_edits(model.params, read_parameters(model, sample_states(model, SAMPLES, SEED))))


def _double_pendulum(tmp_path: Path, text: str, name: str = "dp.py") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


#: the double pendulum's code reading I2 as the inertia about joint 2 (where I2 + m2·r2² belongs)
PIVOT_I2 = (
    (
        "p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)",
        "p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * p.l1**2",
    ),
    ("p.I2 + p.m2 * p.r2**2", "p.I2"),
)


def _pivot_i2() -> str:
    text = DOUBLE_PENDULUM
    for right, wrong in PIVOT_I2:
        text = _planted(text, right, wrong)
    return text


# --- one planted parameter misuse per format: the confirmed repair ---------------------------------
def test_dynamics_code_with_a_mass_doubled_everywhere_gets_it_halved(tmp_path):
    path, urdf, params = _conformance(tmp_path, "acrobot", "dynamics_f")
    path.write_text(_planted(path.read_text(), "m2 = parameters['m2']", "m2 = 2 * parameters['m2']"))
    _, (repair,) = _diagnosis(path, urdf, params)
    assert repair.details["confirmed"], repair.message
    assert (repair.details["written"], repair.details["suggested"]) == ("m2", "m2/2")
    assert repair.message.startswith(
        "m2: every check passes on every state when the code is given m2/2 for m2"
    )
    assert "the code uses 2·m2 where the robot has m2 (look where DYNAMICS uses m2)" in repair.message
    assert repair.details["location"] == f"{path.resolve()}, DYNAMICS f"


def test_numpy_functions_reading_an_inertia_about_the_pivot_get_the_parallel_axis_term(tmp_path):
    path = _double_pendulum(tmp_path, _pivot_i2())
    findings, (repair,) = _diagnosis(path, DP_URDF, DP_PARAMS)
    assert repair.details["confirmed"], repair.message
    assert sp.sympify(repair.details["suggested"]) == sp.sympify("I2 + m2*r2**2"), repair.message
    assert "the code uses I2 where I2 + m2·r2² belongs (the parallel-axis term m2·r2²" in repair.message
    assert "(look where M uses I2)" in repair.message  # α and δ: only M has I2
    assert [f.index for f in findings if f.kind == "entry" and f.quantity == "M"] == [
        (1, 1),
        (1, 2),
        (2, 1),
        (2, 2),
    ]


def test_a_numeric_class_reading_l1_and_l2_exchanged_gets_the_exchange(tmp_path):
    unpacked = "p.l1, p.r2, p.b2, p.m3, p.l2"
    path, urdf, params = _numeric_class(
        tmp_path, "triple_pendulum", (unpacked, "p.l2, p.r2, p.b2, p.m3, p.l1")
    )
    _, (repair,) = _diagnosis(path, urdf, params)
    assert repair.details["confirmed"], repair.message
    assert (repair.details["written"], repair.details["suggested"]) == ("l1, l2", "l2, l1")
    assert "the code uses l1 where l2 belongs, and l2 where l1 belongs" in repair.message
    assert repair.details["location"].endswith(", class Model")


def test_numpy_functions_reading_the_length_where_the_centre_of_mass_belongs_get_it(tmp_path):
    """A pendulum whose code reads l (its tip, a frame of the URDF) where lc (its centre of mass)
    belongs, and never reads lc: ``l → lc``, not the exchange (lc is not read: the two are one)."""
    data = REPO / "tests" / "analytic" / "data"
    text = (data / "pendulum_functions.py").read_text()
    text = _planted(text, '"l": {"kind": "length"},', '"l": {"kind": "length"}, "lc": {"kind": "offset"},')
    text = _planted(text, 'PARAMS = {"m": 2.0, "l": 0.5,', 'PARAMS = {"m": 2.0, "l": 0.8, "lc": 0.35,')
    path = _double_pendulum(tmp_path, text, "pendulum.py")
    urdf = tmp_path / "pendulum.urdf"
    tip = '  <joint name="tip" type="fixed">\n    <parent link="bob"/>\n    <child link="tip"/>\n'
    tip += '    <origin xyz="0 0 -0.8"/>\n  </joint>\n  <link name="tip"/>\n</robot>'
    described = _planted((data / "pendulum_functions.urdf").read_text(), '<origin xyz="0 0 -0.5"/>',
                         '<origin xyz="0 0 -0.35"/>')  # fmt: skip
    urdf.write_text(_planted(described, "</robot>", tip))
    _, (repair,) = _diagnosis(path, urdf, {"m": 2.0, "l": 0.8, "lc": 0.35, "b": 0.1, "g": 9.81})
    assert repair.details["confirmed"], repair.message
    assert (repair.details["written"], repair.details["suggested"]) == ("l", "lc")
    assert "the code uses l where lc belongs (look where M, G use l)" in repair.message


# --- no claim where there is nothing to repair, or no parameter edit holds -------------------------
@pytest.mark.parametrize("which", ["dynamics", "numpy", "class"])
def test_a_correct_code_model_gets_no_claim(tmp_path, which):
    if which == "dynamics":
        files = _conformance(tmp_path, "acrobot", "dynamics_f")
    elif which == "numpy":
        files = (_double_pendulum(tmp_path, DOUBLE_PENDULUM), DP_URDF, DP_PARAMS)
    else:
        files = _numeric_class(tmp_path, "triple_pendulum")
    batch, results = _batch(*files)
    assert all(r.passed for r in results)
    repairs, why = search_repair(batch, 10.0)
    assert repairs == [], why
    assert (
        why.startswith("no repair searched: SymPy cannot read the model (")
        and "agree with Pinocchio's" in why
    )


def test_an_error_in_one_term_gets_no_parameter_repair_and_its_entries_are_named(tmp_path):
    """M[1,2] (and its mirror) × 11/10 in the acrobot's NumPy functions: no parameter is used wrongly
    wherever the code uses it, so no edit of the set makes every check pass."""
    files = _conformance(tmp_path, "acrobot", "numpy_functions", Plant("M", 0, 1))
    findings, (repair,) = _diagnosis(*files)
    assert not repair.details["checks_pass"] and not repair.details["confirmed"]
    count = _count(load_target(*files)[0])
    assert repair.message.startswith(f"no repair: none of {count} edits of the parameters the code is given")
    assert "the code's own expressions were not edited: SymPy cannot read the model (" in repair.message
    assert {f.index for f in findings if f.kind == "entry" and f.quantity == "M"} == {(1, 2), (2, 1)}


def test_a_search_out_of_time_says_how_many_edits_it_screened(tmp_path):
    path, urdf, params = _conformance(tmp_path, "acrobot", "dynamics_f")
    path.write_text(_planted(path.read_text(), "m2 = parameters['m2']", "m2 = 2 * parameters['m2']"))
    batch, _ = _batch(path, urdf, params)
    count = _count(batch.model)
    repairs, why = search_repair(batch, 0.0)
    assert repairs == [] and why.startswith(
        f"no repair: none of the first 0 of {count} edits (the search stopped at its time bound) of the "
        "parameters the code is given"
    ), why


# --- coincidences of the values ---------------------------------------------------------------------
def test_a_value_coincidence_is_not_printed_as_confirmed(tmp_path):
    """I2 = m2·r2²/3 in the parameter file and the URDF: the code reading I2 about the pivot is
    repaired as well by I2 → 4·I2 at these values (tried first: a scale), which fails at the perturbed
    sets; the confirmed repair is I2 + m2·r2², and 4·I2 is not among the findings."""
    i2 = 0.8 * 0.22**2 / 3
    urdf = tmp_path / "dp.urdf"
    moments = 'ixx="{0}" ixy="0" ixz="0" iyy="0.0" iyz="0" izz="{0}"'
    urdf.write_text(_planted(DP_URDF.read_text(), moments.format("0.0135"), moments.format(repr(i2))))
    params = tmp_path / "dp.toml"
    params.write_text(_planted(DP_PARAMS.read_text(), "I2 = 0.0135 ", f"I2 = {i2!r} "))
    model, _ = load_target(_double_pendulum(tmp_path, DOUBLE_PENDULUM, "ok.py"), urdf, params)
    order = [(e.kind, e.name, e.suggested()) for e in parameter_edits(model.params)]
    assert order.index(("scale", "I2", "4*I2")) < order.index(("add", "I2", "I2 + m2*r2**2"))
    _, repairs = _diagnosis(_double_pendulum(tmp_path, _pivot_i2()), urdf, params)
    assert repairs[0].details["confirmed"], repairs[0].message
    assert sp.sympify(repairs[0].details["suggested"]) == sp.sympify("I2 + m2*r2**2")
    assert all(f.details["suggested"] != "4*I2" for f in repairs)


def test_a_coincidence_alone_is_named_as_one_not_as_a_repair(tmp_path):
    """The pendulum of NumPy functions (m = 2, l = 0.5) with l dropped from M and from G: m → m/2
    gives the same numbers as M = m·l², G = m·g·l·sin θ at l = 0.5 only.  No edit of the set is
    the repair; the sentence names that one as a coincidence."""
    data = REPO / "tests" / "analytic" / "data"
    text = _planted((data / "pendulum_functions.py").read_text(), "p.m * p.l**2", "p.m * p.l")
    path = _double_pendulum(tmp_path, _planted(text, "p.m * p.g * p.l * np.sin", "p.m * p.g * np.sin"))
    _, (only,) = _diagnosis(path, data / "pendulum_functions.urdf", {"m": 2.0, "l": 0.5, "b": 0.1, "g": 9.81})
    assert not only.details["checks_pass"] and not only.details["confirmed"]
    assert only.message.startswith("no repair: none of ")
    assert only.message.endswith(
        "every check passes when the code is given m/2 for m at these parameter values, but not at other "
        "values (the URDF rewritten for each): a coincidence of the values, not a repair"
    )


def test_equal_masses_leave_a_doubled_mass_unconfirmed(tmp_path):
    """m1 = m2 (moved together by the perturbed sets): m2 → m2/2 holds, but is not confirmed."""
    urdf = tmp_path / "dp.urdf"
    urdf.write_text(_planted(DP_URDF.read_text(), '<mass value="0.8"/>', '<mass value="1.0"/>'))
    params = tmp_path / "dp.toml"
    params.write_text(_planted(DP_PARAMS.read_text(), "m2 = 0.8 ", "m2 = 1.0 "))
    path = _double_pendulum(tmp_path, DOUBLE_PENDULUM.replace("p.m2", "(2 * p.m2)"))
    _, (repair, *_) = _diagnosis(path, urdf, params)
    assert not repair.details["confirmed"] and repair.details["checks_pass"], repair.message
    assert repair.details["suggested"] == "m2/2"
    message = repair.message
    assert "when the code is given m2/2 for m2, at these parameter values: the code uses 2·m2" in message
    assert "; not confirmed: m2 = m1 here and at every set (equal values are moved together)" in message


PIVOT_PENDULUM = """\
import numpy as np


def M(q, p):
    return np.array([[p.J]])


def C(q, v, p):
    return np.zeros((1, 1))


def G(q, p):
    return np.array([2 * p.m * p.g * p.l * np.sin(q[0])])


DECLARATION = {
    "name": "pivot_pendulum",
    "coordinates": {"theta": "angle"},
    "parameters": {
        "m": {"kind": "mass"}, "l": {"kind": "offset"}, "J": {"kind": "inertia"}, "g": {"kind": "gravity"},
    },
    "urdf": {"joints": ["hinge"]},
}
PARAMS = {"m": 1.5, "l": 0.4, "J": 0.26, "g": 9.81}
"""
PIVOT_URDF = """\
<?xml version="1.0"?>
<robot name="pend">
  <link name="base"/>
  <joint name="hinge" type="continuous">
    <parent link="base"/>
    <child link="bob"/>
    <axis xyz="0 1 0"/>
  </joint>
  <link name="bob">
    <inertial>
      <origin xyz="0 0 -0.4"/>
      <mass value="1.5"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/>
    </inertial>
  </link>
</robot>
"""


def test_edits_that_hold_alike_are_all_named_and_none_is_confirmed(tmp_path):
    """A pendulum whose M is its inertia about the pivot J (one parameter) and whose G reads
    2·m·g·l: m, l and g enter the code only there, so m → m/2, l → l/2 and g → g/2 all hold; the
    first is not confirmed, and names the others (J = I + m·l² in the URDF: m is not moved alone)."""
    urdf = tmp_path / "pendulum.urdf"
    urdf.write_text(PIVOT_URDF)
    path = _double_pendulum(tmp_path, PIVOT_PENDULUM, "pendulum.py")
    _, repairs = _diagnosis(path, urdf, {"m": 1.5, "l": 0.4, "J": 0.26, "g": 9.81})
    assert [f.details["suggested"] for f in repairs] == ["m/2", "l/2", "g/2"]
    assert not any(f.details["confirmed"] for f in repairs)
    first, *others = repairs
    assert first.message.endswith(
        "; every check passes as well when the code is given l/2 for l; every check passes as well when "
        f"the code is given g/2 for g ({first.details['location']})"
    ), first.message
    assert all(
        f.message.startswith("or, equally: ") and "not confirmed: like the first" in f.message for f in others
    )


# --- the edits ----------------------------------------------------------------------------------------
def test_the_edits_keep_units_and_come_simplest_first(tmp_path):
    model, _ = load_target(_double_pendulum(tmp_path, DOUBLE_PENDULUM), DP_URDF, DP_PARAMS)
    edits = parameter_edits(model.params)
    kinds = [e.kind for e in edits]
    assert kinds.index("exchange") < kinds.index("other") < kinds.index("add")
    assert kinds[: kinds.index("exchange")] == ["scale"] * kinds.index("exchange")
    added = {(e.name, str(e.term)) for e in edits if e.kind == "add"}
    assert ("I2", "m2*r2**2") in added and ("I2", "-m2*r2**2") in added and ("m1", "m2") in added
    assert not any(name == "I2" and sp.sympify(t).free_symbols <= {sp.Symbol("m2"), sp.Symbol("r2")}
                   and sp.Poly(sp.sympify(t)).total_degree() == 2 for name, t in added)  # fmt: skip
    assert all(len(sp.sympify(t).free_symbols) <= 2 for _, t in added)
    others = {(e.name, e.other) for e in edits if e.kind == "other"}
    assert ("l1", "r2") in others and ("m1", "l1") not in others and ("b1", "b2") in others


def test_an_edit_outside_a_kinds_rule_is_given_to_the_code(tmp_path):
    """g → −g (gravity's rule is ≥ 0): the code gets the set with −g, of the same type."""
    model, _ = load_target(_double_pendulum(tmp_path, DOUBLE_PENDULUM), DP_URDF, DP_PARAMS)
    edited = ParameterEdit("scale", "g", factor=Fraction(-1)).applied(model.params)
    assert type(edited) is type(model.params) and edited.g == -model.params.g
    assert dataclasses.asdict(edited) == {**model.params.as_dict(), "g": -model.params.g}


# --- the corpus's class "dynamics as code" ----------------------------------------------------------
def test_the_code_corpus_plants_parameter_misuses_and_gets_them_back(capsys):
    """The catalogue's NumPy-functions double pendulum (``code_corpus``), a seeded sample of each
    operator: every planted misuse fails a check and is named, the repair gives the parameters back
    for nearly all, and none that does not is printed as confirmed."""
    ((label, model, system, _),) = [t for t in class_targets() if t[0].endswith("(dynamics as code)")]
    chosen = sample_code_plants(model, QUICK_PER_OPERATOR)
    assert {p.operator for p in chosen} == set(OPERATORS)
    scored = score_code_model(label, model, system, chosen)
    assert scored.clean
    detected = scored.count("detected")
    with capsys.disabled():
        confirmed = scored.count("confirmed")
        print(f"\ncode corpus: {len(chosen)} planted, {detected} detected, {confirmed} confirmed")
    assert detected == len(chosen) and scored.count("named") == detected
    assert scored.count("restored") >= 0.9 * detected
    assert scored.count("wrong_confirmed") == 0


def test_a_class_gets_no_code_corpus(tmp_path):
    """A Python class reads its parameters wherever its methods do: no place to plant a misuse."""
    model, _ = load_target(*_numeric_class(tmp_path, "triple_pendulum"))
    assert code_plants(model) == []


def test_dynamics_code_is_planted_where_it_reads_its_keywords(tmp_path):
    """The corpus's plant of a ``DYNAMICS`` model (the acrobot's f(x, u)): the keyword parameters the
    function gets are edited; the untouched model is clean, each plant fails and is given back."""
    model, system = load_target(*_conformance(tmp_path, "acrobot", "dynamics_f"))
    chosen = [p for p in code_plants(model) if p.what in ("m2 read as 2·m2", "g read as −g")]
    assert len(chosen) == 2
    scored = score_code_model("acrobot", model, system, chosen)
    assert scored.clean and scored.count("detected") == 2 and scored.count("confirmed") == 2


def test_code_that_fails_on_an_edited_value_only_fails_that_edit(tmp_path):
    """A class whose code raises a KeyError when given g < 0 (the edit g → −g) and reads m2 doubled:
    that edit does not pass (no traceback), and m2 → m2/2 is found."""
    unpacked = "p.m2, p.l1, p.r2, p.b2, p.m3, p.l2, p.r3, p.b3, p.g"
    wrong = '2 * p.m2, p.l1, p.r2, p.b2, p.m3, p.l2, p.r3, p.b3, {"up": p.g}["up" if p.g > 0 else "down"]'
    files = _numeric_class(tmp_path, "triple_pendulum", (unpacked, wrong))
    _, (repair,) = _diagnosis(*files)
    assert repair.details["confirmed"] and repair.details["suggested"] == "m2/2", repair.message
