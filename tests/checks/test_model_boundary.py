"""The model boundary (``pendverify.analytic.numeric_values``): what a model returns, as the checks
and the diagnosis read it, and the overflow refusals.

The shipped minimal double pendulum is rewritten to return object arrays (as SymPy-derived code
does) or nested lists: the true model passes, one planted entry fails with the diagnosis naming it
(it ended in exit 3 inside the damping trap), and what is not real numbers of the right shape is
refused in one line.  Values beyond double's range, in a URDF read for its parameters, in a
parameter file or from the model itself, are refused naming the value; a large value that
stays in range is still judged (a planted error caught).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from pendverify.cli import main

REPO = Path(__file__).resolve().parents[2]
MINIMAL = REPO / "examples" / "minimal_double_pendulum.py"
MINIMAL_PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
URDF = REPO / "urdf" / "double_pendulum.urdf"
PARAMS = REPO / "analytic" / "params" / "double_pendulum.toml"

M_RETURN = "np.array([[alpha + 2 * beta * c2, delta + beta * c2], [delta + beta * c2, delta]])"
#: each method's return expression in the example, and the same numbers as an object array
AS_OBJECTS = {
    M_RETURN: M_RETURN[:-1] + ", dtype=object)",
    "np.array([[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]])": (
        "np.array([[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]], dtype=object)"
    ),
    "p.m2 * p.r2 * c12])": "p.m2 * p.r2 * c12], dtype=object)",
    "np.diag([self.params.b1, self.params.b2])": (
        "np.array(np.diag([self.params.b1, self.params.b2]), dtype=object)"
    ),
    "return np.eye(2)": "return np.eye(2).astype(object)",
}
#: the same numbers as nested lists, tuples and NumPy scalars
AS_LISTS = {
    M_RETURN: "[[alpha + 2 * beta * c2, delta + beta * c2], (delta + beta * c2, np.float64(delta))]",
    "np.array([[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]])": (
        "[[-h * v[1], -h * (v[0] + v[1])], [h * v[0], 0.0]]"
    ),
    "return np.eye(2)": "return [[1, 0], [0, 1]]",
}
#: M[2,2] written 2δ for δ, in each container
PLANTED = {
    "object arrays": ("[delta + beta * c2, delta]]", "[delta + beta * c2, 2 * delta]]"),
    "lists": ("np.float64(delta)", "np.float64(2 * delta)"),
}
CONTAINERS = {"object arrays": AS_OBJECTS, "lists": AS_LISTS}


def _model(tmp_path: Path, replacements: dict, name: str = "mine.py") -> str:
    source = MINIMAL.read_text()
    for old, new in replacements.items():
        assert source.count(old) == 1, f"anchor not unique in the example: {old!r}"
        source = source.replace(old, new)
    path = tmp_path / name
    path.write_text(source)
    return str(path)


def _check(capsys, tmp_path, model: str, *extra: str, params: str = str(MINIMAL_PARAMS), urdf=URDF):
    out = tmp_path / "report.json"
    argv = ["check", "--analytic", model, "--urdf", str(urdf), "--params", params, "--samples", "60"]
    status = main([*argv, "--json", str(out), *extra])
    captured = capsys.readouterr()
    report = json.loads(out.read_text()) if out.exists() else None
    return status, captured.out, captured.err, report


def _error(err: str) -> str:
    lines = [line for line in err.splitlines() if line.startswith("pendverify")]
    assert len(lines) == 1, err
    return lines[0]


# --- 1. object arrays and lists: converted at the boundary -------------------------------------------
@pytest.mark.parametrize("kind", CONTAINERS)
def test_a_true_model_returning_other_containers_passes(tmp_path, capsys, kind):
    status, out, err, _ = _check(capsys, tmp_path, _model(tmp_path, CONTAINERS[kind]))
    assert status == 0, out + err


@pytest.mark.parametrize("kind", CONTAINERS)
def test_a_planted_entry_in_other_containers_fails_and_is_diagnosed(tmp_path, capsys, kind):
    replacements = dict(CONTAINERS[kind])
    old, new = PLANTED[kind]
    assert replacements[M_RETURN].count(old) == 1
    replacements[M_RETURN] = replacements[M_RETURN].replace(old, new)
    status, out, err, report = _check(capsys, tmp_path, _model(tmp_path, replacements))
    assert status == 1, out + err  # it ended in exit 3 in the damping trap (np.linalg.solve on objects)
    assert "internal error" not in err
    label = "minimal_double_pendulum:double_pendulum"
    entries = [f for f in report["diagnoses"][label] if f["kind"] == "entry"]
    assert {"quantity": "M", "index": [2, 2]}.items() <= entries[0].items(), entries
    if kind == "object arrays":  # SymPy reads it (np.float64(δ) in the lists it does not: no repair)
        repairs = [f for f in report["diagnoses"][label] if f["kind"] == "repair" and f["checks_pass"]]
        assert repairs and repairs[0]["index"] == [2, 2]


def test_sympy_numbers_are_read_as_floats(tmp_path, capsys):
    replacements = {M_RETURN: f"np.array(sympy.Matrix({M_RETURN[9:-1]}).evalf().tolist(), dtype=object)"}
    model = _model(tmp_path, {**replacements, "import numpy as np\n": "import numpy as np\nimport sympy\n"})
    status, out, err, _ = _check(capsys, tmp_path, model)
    assert status == 0, out + err


@pytest.mark.parametrize(
    ("returned", "says"),
    [
        ("np.array([[1j, 0], [0, 1]])", "mass_matrix: [1,1] is complex (1j): must be a real number"),
        ("np.array([[1.0, 0], [0, complex(1, 2)]], dtype=object)", "[2,2] is complex"),
        ("[[1.0, '0'], [0, 1.0]]", "[1,2] is str '0': must be a real number"),
        ("np.array([[1.0, None], [0, 1.0]], dtype=object)", "[1,2] is None: must be a real number"),
        ("np.eye(3)", "returned an array of shape (3, 3); expected (2, 2)"),
        ("[[1.0, 0.0], [0.0]]", "must return numbers of shape (2, 2)"),
        ("np.array([[np.nan, 0], [0, 1.0]])", "[1,1] is nan at the zero state: must be a finite number"),
    ],
)
def test_what_is_not_real_numbers_of_its_shape_is_refused_in_one_line(tmp_path, capsys, returned, says):
    model = _model(tmp_path, {M_RETURN: returned})
    status, out, err, _ = _check(capsys, tmp_path, model)
    assert status == 2, out + err
    line = _error(err)
    assert f"{model}: MinimalDoublePendulum.mass_matrix" in line and says in line, line


def test_a_symbol_left_in_a_value_is_refused(tmp_path, capsys):
    model = _model(tmp_path, {M_RETURN: M_RETURN.replace("delta]]", "sympy.Symbol('x')]], dtype=object")})
    model_text = Path(model).read_text().replace("import numpy as np\n", "import numpy as np\nimport sympy\n")
    Path(model).write_text(model_text)
    status, out, err, _ = _check(capsys, tmp_path, model)
    assert status == 2, out + err
    assert "[2,2] is Symbol x: must be a real number" in _error(err)


def test_the_checks_and_the_derived_methods_read_the_same_floats():
    from pendverify.analytic.numeric_values import model_value
    from pendverify.analytic.plugin import load_model_class, plugin_parameters

    cls = load_model_class(MINIMAL)
    model = cls(plugin_parameters(cls, str(MINIMAL), str(MINIMAL_PARAMS)))
    q = np.array([0.3, -1.1])
    M = model_value(model, "mass_matrix", q)
    assert M.dtype == float and M.shape == (2, 2)
    assert model_value(model, "potential_energy", q).shape == ()
    assert model.det_mass_matrix(q) == pytest.approx(np.linalg.det(M), rel=1e-15)


# --- 2. overflow: refused naming the value ----------------------------------------------------------------
def _urdf(tmp_path: Path, old: str, new: str) -> str:
    text = URDF.read_text()
    assert text.count(old) == 1
    path = tmp_path / "huge.urdf"
    path.write_text(text.replace(old, new))
    return str(path)


@pytest.mark.parametrize(
    ("old", "new", "key"),
    [
        ('<mass value="0.8"/>', '<mass value="1e300"/>', "m2"),
        ('ixx="0.0135"', 'ixx="1e300"', "I2"),
    ],
)
def test_a_urdf_value_whose_terms_overflow_is_refused_naming_it(tmp_path, capsys, old, new, key):
    urdf = _urdf(tmp_path, old, new)
    status = main(["check", "--model", "double_pendulum", "--urdf", urdf, "--samples", "5"])
    line = _error(capsys.readouterr().err)
    assert status == 2, line  # it was exit 3 (OverflowError in det_mass_matrix)
    assert line.startswith(f"pendverify: error: {urdf}: key '{key}' = 1e+300: too large or too small: ")
    assert "overflow double precision" in line and line.endswith("(as read off the URDF)")


@pytest.mark.parametrize("urdf", [None, URDF], ids=["its own URDF", "a URDF"])
def test_a_parameter_whose_terms_overflow_is_refused_naming_it(tmp_path, capsys, urdf):
    params = tmp_path / "huge.toml"
    params.write_text(PARAMS.read_text().replace("\nm2 = 0.8 ", "\nm2 = 1e300 "))
    assert "m2 = 1e300" in params.read_text()
    extra = [] if urdf is None else ["--urdf", str(urdf)]
    status = main(["check", "--params", str(params), "--samples", "5", *extra])
    line = _error(capsys.readouterr().err)
    assert status == 2, line  # it was exit 3 (OverflowError in det_mass_matrix)
    assert line.startswith(
        f"pendverify: error: {params}: key 'parameters.m2' = 1e+300: too large or too small"
    )


def test_a_large_parameter_without_overflow_is_judged(tmp_path, capsys):
    # m2 = 1e300 in the minimal model's file: its terms stay finite, the URDF's link 2 is 0.8 kg:
    # the checks fail (or refuse), they do not refuse the input
    params = tmp_path / "huge.toml"
    params.write_text(MINIMAL_PARAMS.read_text().replace("m2 = 0.8", "m2 = 1e300"))
    status, out, err, report = _check(capsys, tmp_path, str(MINIMAL), "--no-explain", params=str(params))
    assert status == 1, out + err
    assert "fail" in {r["status"] for r in report["results"]}


def test_a_model_returning_infinity_is_refused(tmp_path, capsys):
    model = _model(tmp_path, {M_RETURN: M_RETURN.replace("delta]]", "np.inf]]")})
    status, out, err, _ = _check(capsys, tmp_path, model)
    assert status == 2, out + err
    assert "MinimalDoublePendulum.mass_matrix: [2,2] is inf at the zero state: must be a finite number" in (
        _error(err)
    )


def test_a_large_value_in_range_is_still_judged(tmp_path, capsys):
    # 1e6 kg on link 2 in both files: no overflow, and a planted M[2,2] still fails crba
    params = tmp_path / "heavy.toml"
    params.write_text(MINIMAL_PARAMS.read_text().replace("m2 = 0.8", "m2 = 1e6"))
    urdf = _urdf(tmp_path, '<mass value="0.8"/>', '<mass value="1e6"/>')
    status, out, err, _ = _check(capsys, tmp_path, str(MINIMAL), params=str(params), urdf=urdf)
    assert status == 0, out + err
    wrong = _model(tmp_path, {M_RETURN: M_RETURN.replace(*PLANTED["object arrays"])})
    status, out, err, report = _check(capsys, tmp_path, wrong, "--no-explain", params=str(params), urdf=urdf)
    assert status == 1, out + err
    assert {r["check"]: r["status"] for r in report["results"]}["crba"] == "fail"
