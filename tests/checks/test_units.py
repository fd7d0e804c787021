"""The ``units`` check: one dimension per entry of the closed forms, its place's, from the parameters'
kinds (``pendverify.checks.dimensions``, ``pendverify.checks.units``), before any robot file.

No false alarm: every shipped model (the built-in reference systems, every worked example in
Python, LaTeX and text), every system of the conformance generator in every format SymPy reads
(and against every description: an MJCF twin adds armatures) and every one-coordinate form is
read with no finding, and with a decided dimension for some entries; the formats SymPy cannot
read are not run, with the reason.  Planted errors that change a dimension are named with both
dimensions; planted errors that keep it (a sign, a factor 2, sin ↔ cos) get no claim; a symbol of
no declared kind, a decimal number, a damping coefficient and a number standing alone make their
term undecided.  Through ``check``: the row comes first, fails with exit status 1 (also when every
check against Pinocchio passes at these values), is carried by JSON and JUnit, runs on a model
given without a robot description, and a warm code cache answers it without importing SymPy.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp

import pendverify
from pendverify.analytic import MODELS
from pendverify.checks.dimensions import KIND_DIMENSIONS, DimensionReader, read_units, required, unit_text
from pendverify.checks.junit import to_junit
from pendverify.cli import main
from pendverify.worked_examples import EXAMPLES
from tests.analytic.one_coordinate_models import FORMS, PEND_PARAMS, PEND_URDF
from tests.conformance.formats import FORMATS, Model, write_model
from tests.conformance.systems import SYSTEMS, descriptions

REPO = Path(__file__).resolve().parents[2]
CART_POLE = REPO / "examples" / "cart_pole.py"
CART_POLE_URDF = REPO / "examples" / "cart_pole.urdf"
CART_POLE_PARAMS = REPO / "examples" / "cart_pole.toml"
SAMPLES = 20  # the checks against Pinocchio run beside the row; their states do not matter here

#: every shipped model file: the worked examples' Python, LaTeX and text models
SHIPPED = sorted({f.source for example in EXAMPLES for f in example.models})


def _kg(kg=0, m=0, s=0):
    return (Fraction(kg), Fraction(m), Fraction(s))


def _findings(model) -> dict[str, str]:
    reading = read_units(pendverify.load_model(model))
    assert "not_run" not in reading, reading
    return {f["label"]: f["message"] for f in reading["findings"]}


# --- no false alarm ------------------------------------------------------------------------------
@pytest.mark.parametrize("model", [*MODELS, *SHIPPED], ids=str)
def test_no_shipped_model_gets_a_claim(model):
    reading = read_units(pendverify.load_model(model))
    assert reading["findings"] == [] and reading["unread"] == {}, f"{model=} {reading}"
    assert reading["decided"] > reading["entries"] / 2, f"{model=}: too little decided: {reading}"


@pytest.mark.slow
@pytest.mark.parametrize(
    ("system", "description"),
    [(name, d) for name, system in SYSTEMS.items() for d in descriptions(system)],
)
def test_no_conformance_system_gets_a_claim_in_any_format(tmp_path, system, description):
    """Every format the generator writes: those SymPy reads have decided entries and no finding; the
    dynamics as code and NumPy functions are not run, with the reason."""
    model = Model(SYSTEMS[system], description)
    for name, fmt in FORMATS.items():
        if fmt.missing():
            continue
        reading = read_units(pendverify.load_model(write_model(model, name, tmp_path)))
        case = f"{system=} {description=} format={name}"
        if not fmt.symbolic:
            assert reading["not_run"].startswith("SymPy cannot read the model ("), f"{case}: {reading}"
            continue
        assert reading["findings"] == [], f"{case}: {reading['findings']}"
        assert reading["decided"] > 0 and reading["unread"] == {}, f"{case}: {reading}"


#: the one-coordinate forms whose planted error changes a dimension → the entries named; every other
#: planted error keeps its entry's dimension (a sign, a factor, sin ↔ cos) and gets no claim
DIMENSIONAL_PLANTS = {
    "text, every key": {"Minv[1,1]"},  # 1/(m l³)
    "text, W": {"M[1,1]"},  # m l² + m
    "text, C_plus_D": {"C[1,1]"},  # b + m θ̇: C = m θ̇ is kg/s
    "text, f": {"H[1]", "V"},  # m g sin θ; V is integrated from it
    "text, whole equations": {"M[1,1]"},  # m l θ̈
    "text, qddot and B": {"M[1,1]"},  # q̈ over m l: M = B (∂q̈/∂u)⁻¹ = m l
    "LaTeX, every key as a bmatrix": {"M[1,1]"},
    "LaTeX, each entry alone": {"H[1]", "V"},
    "LaTeX, C_plus_D": {"C[1,1]"},
    "LaTeX, f": {"H[1]", "V"},
    "LaTeX, whole equations": {"M[1,1]"},
    "LaTeX, qddot and B": {"M[1,1]"},
    "mechanics, (M, forcing)": {"M[1,1]"},
}


@pytest.mark.parametrize("form", list(FORMS))
def test_one_coordinate_forms_true_and_planted(tmp_path, form):
    suffix, text, (old, new, _, _) = FORMS[form]
    true, planted = tmp_path / f"true{suffix}", tmp_path / f"planted{suffix}"
    true.write_text(text)
    planted.write_text(text.replace(old, new))
    readings = [read_units(pendverify.load_model(path)) for path in (true, planted)]
    if "DYNAMICS" in form:
        assert all("its q̈ is Python code" in r["not_run"] for r in readings), f"{form=} {readings}"
        return
    assert readings[0]["findings"] == [], f"{form=}: {readings[0]}"
    named = {f["label"] for f in readings[1]["findings"]}
    assert named == DIMENSIONAL_PLANTS.get(form, set()), f"{form=}: {readings[1]['findings']}"


# --- what each entry must be -----------------------------------------------------------------------
def test_each_place_of_a_cart_pole_has_its_mixed_units():
    """x a position, θ an angle: [τ_x] = N, [τ_θ] = N·m, and each entry follows (module docstring)."""
    angular = (False, True)
    expected = {
        ("mass_matrix", (0, 0)): "kg",
        ("mass_matrix", (0, 1)): "kg·m",
        ("mass_matrix", (1, 0)): "kg·m",
        ("mass_matrix", (1, 1)): "kg·m²",
        ("coriolis_matrix", (0, 1)): "kg·m/s",
        ("damping_matrix", (0, 0)): "kg/s",
        ("damping_matrix", (1, 1)): "kg·m²/s",
        ("gravity", (0,)): "kg·m/s²",
        ("gravity", (1,)): "kg·m²/s²",
        ("coriolis_force", (1,)): "kg·m²/s²",
        ("inverse_mass_matrix", (0, 0)): "1/kg",
        ("inverse_mass_matrix", (0, 1)): "1/(kg·m)",
        ("inverse_mass_matrix", (1, 1)): "1/(kg·m²)",
        ("acceleration", (0,)): "m/s²",
        ("acceleration", (1,)): "1/s²",
        ("potential_energy", ()): "kg·m²/s²",
        ("det_mass_matrix", ()): "kg²·m²",
    }
    for (method, position), unit in expected.items():
        dim, _ = required(method, position, angular)
        assert unit_text(dim) == unit, f"{method=} {position=}"
    for method in ("input_matrix", "disturbance_matrix", "f"):  # the inputs' units are not declared
        assert required(method, (0, 0), angular) == (None, "")


# --- what is decided and what is not ---------------------------------------------------------------
m, l, g, b, k, theta = sp.symbols("m l g b k theta", positive=True)  # noqa: E741 (l: a length)
DIMS = {m: KIND_DIMENSIONS["mass"], l: KIND_DIMENSIONS["length"], g: KIND_DIMENSIONS["gravity"]}
DIMS.update({b: KIND_DIMENSIONS["damping"], theta: _kg()})  # k: no declared kind


def _clashes(expr, symbols=DIMS) -> list[str]:
    reader = DimensionReader(dict(symbols))
    reader.agree(expr, sp.Add.make_args(expr), top=True)
    return reader.clashes


@pytest.mark.parametrize(
    ("expr", "named"),
    [
        (m * l**2 + m * l, ("l*m has kg·m", "l**2*m has kg·m²")),
        (m * l**2 / 12 + 2 * m * l, ("2*l*m has kg·m", "l**2*m/12 has kg·m²")),  # pure coefficients
        (m * g * l * sp.sin(theta) + m * g, ("g*m has kg·m/s²", "g*l*m*sin(theta) has kg·m²/s²")),
        (m * (l**2 + l), ("in l**2 + l, the term ", "l has m", "l**2 has m²")),
        (m * g * l * sp.sin(l * theta), ("the argument of sin, l*theta, has m: it must be dimensionless",)),
        (sp.atan2(m, l * sp.cos(theta)), ("atan2's arguments m and l*cos(theta) have kg and m: they",)),
        (sp.atan2(l, m), ("the argument of atan, l/m, has m/kg",)),  # SymPy's own atan(l/m) for m > 0
        (m * l**2 + m * sp.sqrt(l), ("sqrt(l)*m has kg·m^(1/2)", "l**2*m has kg·m²")),
        # the larger group is the reference: the odd term is the one named as "the term"
        (m * l**2 + m * l**2 * sp.cos(theta) + m * l, ("the term l*m has kg·m but ", "has kg·m²")),
    ],
)
def test_terms_of_other_dimensions_are_named_with_both(expr, named):
    (said,) = _clashes(expr)
    assert all(part in said for part in named), said


@pytest.mark.parametrize(
    "expr",
    [
        m * l**2 + k * l,  # k has no declared kind
        m * l**2 + sp.Float(9.81) * m * l,  # a decimal may be a quantity written by its value
        m * l**2 + 10 * m * l,  # so may an integer beyond a derivation's coefficients (g = 10 m/s²)
        m * l**2 + b * l,  # a damping coefficient's unit depends on its joint
        m * l**2 + sp.Float(0.01),  # a number standing alone as a term
        m * l**2 + 1,
        m * l**2 + sp.Function("f")(l) * m,  # a function of the model's own
        m * l**2 * sp.sqrt(g / (l * g)) ** 2 * l,  # powers map dimensions: kg·m² throughout
        m * l**2 + m * l * sp.sqrt(k),
    ],
    ids=str,
)
def test_what_cannot_be_decided_is_not_claimed(expr):
    assert _clashes(expr) == [], expr


def test_the_same_term_with_a_declared_kind_is_claimed():
    """k's term gets no claim undeclared, and one once k is declared a mass (it is the rule's
    decision to abstain, not its blindness)."""
    assert _clashes(m * l**2 + k * l) == []
    assert _clashes(m * l**2 + k * l, {**DIMS, k: KIND_DIMENSIONS["mass"]}) != []


# --- planted errors in a shipped model with mixed units ----------------------------------------------
def _planted(tmp_path: Path, *edits: tuple[str, str], name="cart_pole.py", count=1) -> Path:
    text = CART_POLE.read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, count)
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_cart_pole_planted_in_m_is_named_with_both_units(tmp_path):
    findings = _findings(_planted(tmp_path, ("p.mc + p.mp", "p.mc + p.mp * p.r**2")))
    assert set(findings) == {"M[1,1]"}, findings
    assert findings["M[1,1]"] == (
        "M[1,1]: the term mp*r**2 has kg·m² but mc has kg (an entry of M for the position x alone is kg)"
    )
    # mass_matrix's k (inverse_mass_matrix has its own): the entries agree with each other, not their place
    findings = _findings(_planted(tmp_path, ("k = p.mp * p.r * self", "k = p.mp * p.r**2 * self")))
    assert set(findings) == {"M[1,2]", "M[2,1]"}, findings
    assert findings["M[1,2]"].endswith(
        "has kg·m² but an entry of M for the position x and the angle theta is kg·m"
    )


def _cart_pole_check(model: Path, **kwargs):
    return pendverify.check(model, CART_POLE_URDF, CART_POLE_PARAMS, samples=SAMPLES, **kwargs)


def test_the_row_comes_first_fails_and_is_carried_by_json_and_junit(tmp_path):
    model = _planted(tmp_path, ("p.I + p.mp * p.r**2]", "p.I + p.mp * p.r]"))
    report = _cart_pole_check(model, explain=False)
    assert report.results[0].check == "units" and report.status == "fail"
    row = report["units"][0]
    assert row.status == "fail" and row.max_error == 1.0 and row.worst_state["label"] == "M[2,2]"
    (note,) = row.notes
    assert note == (
        "M[2,2]: the term mp*r has kg·m but I has kg·m² (an entry of M for the angle theta alone is kg·m²) "
        f"({model}, CartPole.mass_matrix, entry M[2,2])"
    )
    assert f"fail [cart_pole:cart_pole units]: {note}" in report.table()
    (entry,) = [r for r in json.loads(report.to_json())["results"] if r["check"] == "units"]
    assert entry["status"] == "fail" and entry["notes"] == [note]
    junit = to_junit(report)
    assert 'name="units"' in junit
    assert "units: error 1.000e+00, tolerance 0.000e+00, worst state M[2,2]" in junit


def test_a_dimension_error_fails_where_every_value_agrees(tmp_path):
    """r = 1 m: m·r for m·r² gives the same numbers, and every check against Pinocchio passes; the
    units row alone fails the model (exit status 1), with no diagnosis to search (nothing differs)."""
    import importlib

    module = importlib.import_module(pendverify.load_model(CART_POLE).__module__)
    values = {"mc": 1.0, "mp": 0.4, "r": 1.0, "I": 0.05, "bx": 0.1, "bt": 0.02, "g": 9.81}
    urdf = module.cart_pole_urdf(module.CartPoleParams(**values))
    model = _planted(tmp_path, ("p.I + p.mp * p.r**2", "p.I + p.mp * p.r"), count=-1)
    report = pendverify.check(model, urdf, values, samples=SAMPLES)
    others = [r for r in report.results if r.check != "units"]
    assert others and all(r.status == "pass" for r in others), report.table()
    assert report["units"][0].status == "fail" and report.status == "fail" and not report.diagnoses
    assert report.passed is False


def test_sound_model_gets_a_passing_first_row(tmp_path):
    report = _cart_pole_check(CART_POLE)
    row = report.results[0]
    assert (row.check, row.status, row.max_error, row.worst_state["label"]) == (
        "units", "pass", 0.0, "14 of 18 entries"
    )  # fmt: skip
    assert report.passed


# --- a model alone, the command line, models SymPy cannot read --------------------------------------
def _pendulum_files(tmp_path: Path, form: str, planted: bool) -> Path:
    suffix, text, (old, new, _, _) = FORMS[form]
    path = tmp_path / f"pend{suffix}"
    path.write_text(text.replace(old, new) if planted else text)
    return path


def test_a_model_alone_runs_the_units_check(tmp_path, capsys):
    form = "LaTeX, every key as a bmatrix"
    # units that agree verify nothing against a robot: exit status 2, so a script that forgot --urdf fails
    assert main(["check", "--analytic", str(_pendulum_files(tmp_path, form, planted=False))]) == 2
    out = capsys.readouterr().out
    assert "pend   units  0.00e+00  0.00e+00   5 of 7 entries  pass" in out, out
    assert "give --urdf FILE (urdf= in the Python API)" in out
    assert out.rstrip().endswith("nothing was compared with a robot: NOT verified (give --urdf FILE)"), out
    path = _pendulum_files(tmp_path, form, planted=True)
    assert main(["check", "--analytic", str(path)]) == 1
    out = capsys.readouterr().out
    assert (
        "fail [pend units]: M[1,1]: l m has kg·m but an entry of M for the angle \\theta alone is kg·m² "
        f"({path}, key M, entry M[1,1])"
    ) in out, out


def test_a_model_sympy_cannot_read_is_not_run_and_alone_needs_a_urdf(tmp_path, capsys):
    path = _pendulum_files(tmp_path, "DYNAMICS qddot(q, v, u)", planted=False)
    assert main(["check", "--analytic", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}: give --urdf (urdf= in the Python API)" in err and "units not run: SymPy cannot" in err
    (tmp_path / "pend.urdf").write_text(PEND_URDF)
    (tmp_path / "pend_params.toml").write_text(PEND_PARAMS)
    report = pendverify.check(path, tmp_path / "pend.urdf", tmp_path / "pend_params.toml", samples=SAMPLES)
    assert "units" not in report.checks
    (note,) = [n for n in report.notes["pend:pend"] if n.startswith("units")]
    assert note.startswith("units not run: SymPy cannot read the model (Pend: its q̈ is Python code"), note


def test_a_warm_code_cache_answers_without_sympy(tmp_path):
    """The reading is cached with the generated code: a second process reads it, imports no SymPy,
    and reports the same row."""
    code = (  # the built-in model: a plug-in leaving a tolerance scale to be derived loads SymPy for it
        "import sys, pendverify; "
        "r = pendverify.check('double_pendulum', erd=False, samples=5); "
        "print(r.results[0].check, r.results[0].worst_state['label'], 'sympy' in sys.modules)"
    )
    env = {**os.environ, "PENDVERIFY_CACHE": str(tmp_path / "cache")}
    runs = [
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env)
        for _ in range(2)
    ]
    assert [r.stdout.split() for r in runs] == [
        ["units", "15", "of", "20", "entries", "True"],
        ["units", "15", "of", "20", "entries", "False"],
    ], [r.stdout + r.stderr for r in runs]


def test_a_term_m_g_added_to_h_of_a_hinge_is_named(tmp_path):
    """The shipped text double pendulum with g·m1 (kg·m/s², a force) added to H[1] (a torque)."""
    text = (REPO / "examples" / "minimal_double_pendulum_text.toml").read_text()
    old = '"g*((m1*r1 + m2*l1)*cos(theta1) + m2*r2*cos(theta1 + theta2))",'
    path = tmp_path / "minimal_double_pendulum_text.toml"
    path.write_text(text.replace(old, old[:-2] + ' + g*m1",'))
    findings = _findings(path)
    assert set(findings) == {"H[1]"}, findings
    assert findings["H[1]"].startswith("H[1]: the term g*m1 has kg·m/s² but ")
    assert findings["H[1]"].endswith("has kg·m²/s² (an entry of H for the angle theta1 is kg·m²/s²)")


def test_a_model_alone_still_reads_its_parameter_file(tmp_path, capsys):
    """--params with a model alone is read and refused when bad, not ignored."""
    bad = tmp_path / "bad.toml"
    bad.write_text(CART_POLE_PARAMS.read_text().replace("mc = ", "mc = -"))
    assert main(["check", "--analytic", str(CART_POLE), "--params", str(bad)]) == 2
    assert "parameters.mc" in capsys.readouterr().err
    assert main(["check", "--analytic", str(CART_POLE), "--params", str(CART_POLE_PARAMS)]) == 2
    captured = capsys.readouterr()
    assert "parameters.mc" not in captured.err and "NOT verified (give --urdf FILE)" in captured.out


#: the corpus's operators that keep every term's dimension
KEEPS = ("sign", "drop", "duplicate", "factor 2", "factor ½", "parameter", "sin↔cos", "pivot", "swap θ")


@pytest.mark.slow
def test_no_claim_on_the_explain_corpus_but_where_a_plant_changes_a_dimension():
    """``bench explain``'s planted errors in every shipped model: every operator but a rate swap keeps
    each term's dimension (a sign, a dropped or doubled term, a factor, a parameter of the same kind,
    sin ↔ cos, an angle swap, ± m·r² in M) and gets no claim; a swap of a position's rate with an
    angle's (ẋ ↔ θ̇) changes it, and only there is a claim made (not where the rate multiplies an
    undecided damping coefficient: ẋ·b_x → θ̇·b_x); 9 of the 1734 plants (the worked examples' files,
    none in a key the model derives) are named."""
    from pendverify.analytic.forms import entry_position
    from pendverify.analytic.symbolic_reading import SymbolicModel
    from pendverify.bench.explain import shipped_targets
    from pendverify.checks.dimensions import entry_dimension, symbol_dimensions
    from pendverify.diagnosis.corpus import plants

    caught, planted = 0, 0
    for label, model, _, _ in shipped_targets():
        sm = SymbolicModel.of(type(model))
        reader, forms = DimensionReader(symbol_dimensions(sm), kinds=dict(sm.kinds)), sm.closed_forms
        position_rates = {f"d{c}" for c, a in zip(model.coordinates, model.angular, strict=True) if not a}
        for plant in plants(sm):
            shape = getattr(forms[plant.method], "shape", None)
            position = entry_position(plant.method, shape, plant.index) if shape else ()
            _, clashes = entry_dimension(reader, plant.new, *required(plant.method, position, model.angular))
            if plant.operator not in KEEPS and plant.operator != "swap θ̇":
                continue  # an operator added to the corpus since: its dimensions are not known here
            swapped = set(plant.what.split(" in ", 1)[0].split(" ↔ "))
            changes = plant.operator == "swap θ̇" and len(swapped & position_rates) == 1
            assert changes or not clashes, f"{label=} {plant.operator=} {plant.what=} {clashes=}"
            caught, planted = caught + bool(clashes), planted + 1
    assert planted >= 1734 and caught >= 9, (planted, caught)  # measured: 1734 and 9


def test_every_kind_has_the_dimension_of_its_declared_unit():
    """One table of kinds' dimensions (``parameter_set.KIND_DIMENSIONS``) agrees with the units the
    kinds declare (``KIND_RULES``); damping's two units leave its dimension undecided."""
    from pendverify.analytic.parameter_set import KIND_RULES

    assert set(KIND_DIMENSIONS) == set(KIND_RULES)
    for kind, (_, unit) in KIND_RULES.items():
        d = KIND_DIMENSIONS[kind]
        assert (unit_text(d) if d is not None else None) == (None if kind == "damping" else unit), kind
