"""Models given as NumPy functions M(q, p), C(q, v, p) (Cqdot, h), G(q, p), D(p), B(p).

The single pendulum of docs/models.md (``tests/analytic/data/pendulum_functions.py``, shown
there verbatim) and the double pendulum (``examples/minimal_double_pendulum.py``'s formulas,
written as functions) pass against their URDFs; one planted wrong entry in M, in C and in G each
fails, the diagnosis naming the entry; the bias given as C, as C·q̇ and as h = C·q̇ + G passes
alike; malformed files are refused in one line; the commands that read closed forms with SymPy
refuse in one line, and the others (stress, simulate, certify) run, taking the file's PARAMS when
no parameter file is named.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import pendverify
from pendverify.analytic.numpy_model import Parameters
from pendverify.analytic.plugin import load_model_class
from pendverify.api import load_scene, simulate, stress
from pendverify.cli import main
from pendverify.errors import PendverifyError

REPO = Path(__file__).resolve().parents[2]
PENDULUM = REPO / "tests" / "analytic" / "data" / "pendulum_functions.py"
PENDULUM_URDF = REPO / "tests" / "analytic" / "data" / "pendulum_functions.urdf"
DP_URDF = REPO / "urdf" / "double_pendulum.urdf"
DP_PARAMS = REPO / "examples" / "minimal_double_pendulum.toml"
SAMPLES = ["--samples", "60"]

# examples/minimal_double_pendulum.py's M, C, H, D, B as functions: θ1 from the horizontal,
# θ2 relative to link 1, the URDF's joint angles (the shipped corpus model, read as text)
DOUBLE_PENDULUM = (REPO / "examples" / "corpus_double_pendulum_functions.py").read_text()

# the bias written as C·q̇, and as h = C·q̇ + G (with G, and without it: then G = h(q, 0)), the
# matrix C renamed so that the file gives no C
BIAS_FORMS = {
    "Cqdot": ({"def C(": "def matrix_C("}, "def Cqdot(q, v, p):\n    return matrix_C(q, v, p) @ v\n"),
    "h and G": ({"def C(": "def matrix_C("}, "def h(q, v, p):\n    return matrix_C(q, v, p) @ v + G(q, p)\n"),
    "h alone": (
        {"def C(": "def matrix_C(", "def G(": "def gravity_vector("},
        "def h(q, v, p):\n    return matrix_C(q, v, p) @ v + gravity_vector(q, p)\n",
    ),
}


def _file(tmp_path: Path, text: str, name: str = "model.py") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def _changed(text: str, old: str, new: str) -> str:
    assert old in text, old  # the planted change must change something
    return text.replace(old, new)


def _double(tmp_path: Path, text: str = DOUBLE_PENDULUM) -> list[str]:
    return ["--analytic", str(_file(tmp_path, text)), "--urdf", str(DP_URDF), "--params", str(DP_PARAMS)]


def test_the_docs_show_the_tested_pendulum_verbatim():
    docs = (REPO / "docs" / "models.md").read_text(encoding="utf-8")
    assert f'```python title="pendulum.py"\n{PENDULUM.read_text()}```' in docs
    assert f'```xml title="pendulum.urdf"\n{PENDULUM_URDF.read_text()}```' in docs


def test_the_documented_single_pendulum_passes_with_its_own_params(capsys):
    assert main(["check", "--analytic", str(PENDULUM), "--urdf", str(PENDULUM_URDF), *SAMPLES]) == 0
    out = capsys.readouterr().out
    assert "all checks pass" in out and "parameters: the model file's PARAMS" in out
    assert "energy not run: the model gives no potential energy V(q)" in out
    for check in ("crba", "rnea", "gravity", "coriolis", "skew", "aba", "damping"):
        assert f"  {check} " in out, check
    cls = load_model_class(PENDULUM)
    assert cls.numeric_only and cls.hand_written()[:4] == (
        "mass_matrix",
        "coriolis_matrix",
        "gravity",
        "damping_matrix",
    )


def test_the_double_pendulum_as_functions_passes(tmp_path, capsys):
    assert main(["check", *_double(tmp_path), *SAMPLES]) == 0
    assert "all checks pass" in capsys.readouterr().out


@pytest.mark.parametrize("form", BIAS_FORMS)
def test_the_bias_as_c_qdot_or_as_h_passes(form, tmp_path):
    renames, added = BIAS_FORMS[form]
    text = DOUBLE_PENDULUM
    for old, new in renames.items():
        text = _changed(text, old, new)
    report = pendverify.check(_file(tmp_path, text + "\n\n" + added), DP_URDF, DP_PARAMS, samples=60)
    assert report.status == "pass", report
    assert "coriolis" not in report.checks  # no matrix C: coriolis and skew are not run
    assert {"crba", "rnea", "gravity", "aba"} <= set(report.checks)


def test_h_gives_g_and_the_bias(tmp_path):
    """With h alone, G(q) = h(q, 0) and C·q̇ = h(q, q̇) − G(q); the bias is h itself."""
    renames, added = BIAS_FORMS["h alone"]
    text = DOUBLE_PENDULUM
    for old, new in renames.items():
        text = _changed(text, old, new)
    cls = load_model_class(_file(tmp_path, text + "\n\n" + added))
    reference = load_model_class(_file(tmp_path, DOUBLE_PENDULUM, "reference.py"))
    values = _values()
    model, expected = cls(cls.params_type(**values)), reference(reference.params_type(**values))
    q, v = np.array([0.3, -1.2]), np.array([0.7, 2.0])
    written = ("mass_matrix", "coriolis_force", "gravity", "damping_matrix", "input_matrix")
    assert cls.hand_written()[:5] == written
    assert np.array_equal(model.gravity(q), expected.gravity(q))  # h(q, 0) adds C(q, 0)·0 = 0 exactly
    assert np.array_equal(model.bias(q, v), expected.bias(q, v))  # the same arithmetic as C·q̇ + G
    # C·q̇ = (C·q̇ + G) − G: the sum's and the difference's roundings, each at most ε/2 of the
    # larger of |C·q̇ + G| and |G| (C·q̇ itself is the same arithmetic on both sides): within ε; 2ε
    scale = max(np.max(np.abs(expected.bias(q, v))), np.max(np.abs(expected.gravity(q))))
    assert np.allclose(
        model.coriolis_force(q, v),
        expected.coriolis_matrix(q, v) @ v,
        rtol=0,
        atol=2 * np.finfo(float).eps * scale,
    )


@pytest.mark.parametrize(
    "old, new, entry, check",
    [
        ("[delta + beta * c2, delta]])", "[delta + beta * c2, 1.05 * delta]])", "M[2,2]", "crba"),
        ("[h * v[0], 0.0]", "[1.1 * h * v[0], 0.0]", "C[2,1]", "coriolis"),
        ("p.m2 * p.r2 * c12])", "1.02 * p.m2 * p.r2 * c12])", "G[2]", "gravity"),
    ],
    ids=["M", "C", "G"],
)
def test_a_planted_wrong_entry_fails_naming_it(old, new, entry, check, tmp_path, capsys):
    assert main(["check", *_double(tmp_path, _changed(DOUBLE_PENDULUM, old, new)), *SAMPLES]) == 1
    out = capsys.readouterr().out
    assert any(line.split()[1:2] == [check] and line.endswith("FAIL") for line in out.splitlines()), out
    assert f"]: {entry} (" in out, out  # the diagnosis names the entry, by the file's own name (G)
    assert "H[" not in out, out  # the interface's name of G appears nowhere


@pytest.mark.parametrize(("factor", "status"), [("", "pass"), (" * 1.01", "fail")], ids=["right", "wrong"])
def test_a_given_v_is_checked_by_energy(factor, status, tmp_path):
    """V(q, p) = −m g l cos θ makes the energy check run; 1 % off, it fails it alone."""
    v = f"def V(q, p):\n    return -p.m * p.g * p.l * np.cos(q[0]){factor}\n\n\n"
    model = _file(tmp_path, _changed(PENDULUM.read_text(), "def D(p):", v + "def D(p):"))
    report = pendverify.check(model, PENDULUM_URDF, samples=60)
    assert "energy" in report.checks and report.status == status, report
    assert [r.name for r in report.results if r.status == "fail"] == ([] if status == "pass" else ["energy"])


#: det M and q̈ of the double pendulum as a file gives them: det M in closed form, q̈ solved with M
DET_AND_QDDOT = """

def det_M(q, p):
    alpha = p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
    beta, delta = p.m2 * p.l1 * p.r2, p.I2 + p.m2 * p.r2**2
    c2 = np.cos(q[1])
    return (alpha + 2 * beta * c2) * delta - (delta + beta * c2) ** 2


def qddot(q, v, u, w, p):
    return np.linalg.solve(M(q, p), B(p) @ u - D(p) @ v - C(q, v, p) @ v - G(q, p))


DECLARATION ="""


@pytest.mark.parametrize(
    ("old", "new", "failing"),
    [
        ("", "", []),
        ("* delta - (delta", "* delta * 1.001 - (delta", ["det"]),
        ("- G(q, p))", "- 1.001 * G(q, p))", ["aba"]),
    ],
    ids=["right", "det_M wrong", "qddot wrong"],
)
def test_a_given_det_m_and_qddot_are_checked(old, new, failing, tmp_path):
    """det_M(q, p) and qddot(q, v, u, w, p) are the model's own: ``det`` and ``aba`` check them,
    and an error planted in either fails its check alone."""
    text = _changed(DOUBLE_PENDULUM, "\n\nDECLARATION =", DET_AND_QDDOT)
    report = pendverify.check(
        _file(tmp_path, _changed(text, old, new) if old else text), DP_URDF, DP_PARAMS, samples=60
    )
    assert {"det", "aba"} <= set(report.checks), report
    assert [r.name for r in report.results if r.status == "fail"] == failing, report


def test_qddot_alone_is_pointed_to_dynamics(tmp_path):
    declaration = DOUBLE_PENDULUM[DOUBLE_PENDULUM.index("DECLARATION =") :]
    text = f"import numpy as np\n\n\ndef qddot(q, v, u, w, p):\n    return -v\n\n\n{declaration}"
    with pytest.raises(PendverifyError, match=r"no M\(q, p\).*q̈ alone is DYNAMICS"):
        load_model_class(_file(tmp_path, text))


def test_p_gives_the_parameters_by_attribute_and_by_key(tmp_path):
    text = _changed(DOUBLE_PENDULUM, "return p.g * np.array(", 'return p["g"] * np.array(')
    report = pendverify.check(_file(tmp_path, text), DP_URDF, DP_PARAMS, samples=60)
    assert report.status == "pass", report
    p = Parameters({"m": 2.0, "g": 9.81})
    assert p.m == p["m"] == 2.0 and "g" in p and list(p) == ["m", "g"]
    with pytest.raises(AttributeError, match=r"no parameter 'mass'; the declared parameters are m, g"):
        _ = p.mass
    with pytest.raises(AttributeError, match="read-only"):
        p.m = 3.0


PENDULUM_TEXT = PENDULUM.read_text()


@pytest.mark.parametrize(
    "old, new, words",
    [
        ("def M(q, p):", "def M(q):", "M cannot be called as M(q, p): too many positional arguments"),
        ("def G(q, p):", "def G(q, v, p):", "G cannot be called as G(q, p): missing a required argument"),
        ("def M(q, p):", "def mass(q, p):", "defines C, G, D but no M(q, p)"),
        ("return np.array([[p.m * p.l**2]])", "return np.array([p.m * p.l**2])",
         "M(q, p) must return an array of shape (1, 1); it returned an array of shape (1,) at q = [0.0]"),
        ("return np.zeros((1, 1))", "return None",
         "C(q, v, p) must return an array of shape (1, 1); it returned an array of shape ()"),
        ('"g": 9.81}', "}", "key 'PARAMS.g' = None: missing key"),
        ('"g": 9.81}', '"g": 9.81, "k": 1.0}', "key 'PARAMS.k' = 1.0: unknown key"),
        ('"m": 2.0', '"m": -2.0', "key 'PARAMS.m' = -2.0: a mass must be a finite number > 0"),
        ("PARAMS = {", "PARAMS = 3 or {", "PARAMS must be a dict of the parameters' values; got a int"),
        ("def G(q, p):", "def Cqdot(q, v, p):\n    return v\n\n\ndef G(q, p):",
         "define exactly one of C(q, v, p)"),
        ("def G(q, p):", "def gravity(q, p):", "defines no G(q, p), the gravity vector"),
        ('"coordinates"', '"inputs": ["tau"], "coordinates"', "defines no B(p): the declaration declares"),
        ("def D(p):", "D = 0.1\n\n\ndef damping(p):", "D must be a function D(p); got a float"),
        ("DECLARATION = {", "DECLARED = {", "defines M, C, G, D but no DECLARATION"),
        ('"g": {"kind": "gravity"}', '"gee": {"kind": "gravity"}', "key 'parameters.gee': name the gravity"),
        ('"m": {"kind": "mass"}', '"keys": {"kind": "mass"}', "p.keys is taken by the parameter object p"),
        ("* np.sin(q[0])])", "* float(np.sin(q[0])) / int(q[0] > 1)])",
         "G(q, p) raised ZeroDivisionError: float division by zero at q = [0.0]"),
    ],
)  # fmt: skip
def test_a_malformed_file_is_refused_in_one_line(old, new, words, tmp_path, capsys):
    model = _file(tmp_path, _changed(PENDULUM_TEXT, old, new))
    assert main(["check", "--analytic", str(model), "--urdf", str(PENDULUM_URDF), *SAMPLES]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and str(model) in err and words in err, err


def test_an_exception_names_the_line_of_the_function(tmp_path):
    text = _changed(PENDULUM_TEXT, "return np.zeros((1, 1))", "return np.zeros((1, 1)) + q[5]")
    with pytest.raises(PendverifyError) as info:
        pendverify.check(_file(tmp_path, text), PENDULUM_URDF, samples=10)
    line = text.splitlines().index("    return np.zeros((1, 1)) + q[5]") + 1
    assert f"model.py, line {line}: C(q, v, p) raised IndexError" in str(info.value), info.value


def _scene(tmp_path: Path, model: Path, urdf: Path, **extra) -> dict:
    return {
        "name": "functions",
        "model": str(model),
        "urdf": str(urdf),
        "initial": {"q": [1.0, -0.8]},
        "time": {"duration": 0.5, "sample_rate": 50.0},
        "integrator": {"method": "DOP853", "rtol": 1e-10, "atol": 1e-10},
        "effects": {"gravity": True, "damping": True},
        **extra,
    }


def test_commands_that_read_closed_forms_with_sympy_refuse_in_one_line(tmp_path, capsys):
    model = _file(tmp_path, DOUBLE_PENDULUM)
    scene = tmp_path / "scene.toml"
    scene.write_text(
        f'model = "{model}"\nparams = "{DP_PARAMS}"\nurdf = "{DP_URDF}"\n'
        "[initial]\nq = [1.0, -0.8]\n[time]\nduration = 0.5\nsample_rate = 50.0\n"
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
    )
    for argv in (
        ["show", str(model)],
        ["sympy", "--analytic", str(model)],
        ["mutate", "--analytic", str(model), "--urdf", str(DP_URDF), "--params", str(DP_PARAMS)],
        ["bench", "accuracy", "--quick", "--scene", str(scene)],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err.strip()
        assert "\n" not in err and "NumPy functions" in err and "not read by SymPy" in err, (argv, err)


def test_stress_and_simulate_take_the_files_params(tmp_path):
    report = stress(PENDULUM, PENDULUM_URDF, quick=True, cases=["nominal", "g = 0"])
    assert [r.name for r in report.results] == ["nominal", "g = 0"]
    assert all(r.passed for r in report.results), report.results
    dp = _file(tmp_path, DOUBLE_PENDULUM + "PARAMS = " + repr(_values()) + "\n")
    run = simulate(load_scene(_scene(tmp_path, dp, DP_URDF, engine="both")))
    assert run.passed and run.scene.params_source.endswith("(PARAMS)"), run
    assert run.engine_comparison is not None  # the functions' q̈ compared with ABA at the same states


def test_simulating_the_functions_alone_needs_v(tmp_path):
    dp = _file(tmp_path, DOUBLE_PENDULUM + "PARAMS = " + repr(_values()) + "\n")
    with pytest.raises(PendverifyError) as info:
        simulate(load_scene(_scene(tmp_path, dp, DP_URDF, engine="closed_form")))
    message = str(info.value)
    assert "\n" not in message and "the model gives no potential energy V(q)" in message, message


def test_certify_takes_the_files_params(tmp_path, capsys):
    out = tmp_path / "certified"
    assert main(["certify", "--analytic", str(PENDULUM), "--urdf", str(PENDULUM_URDF), "-o", str(out)]) == 0
    assert "certified:" in capsys.readouterr().out
    assert list(out.glob("*.cert.json"))


def _values() -> dict[str, float]:
    from pendverify.documents import read_toml

    return dict(read_toml(DP_PARAMS)["parameters"])


def test_the_scales_are_the_functions_largest_values_on_the_grid(tmp_path):
    """Σ|terms| of the double pendulum's M_ii and G_i is attained at θ = 0, a grid point."""
    cls = load_model_class(_file(tmp_path, DOUBLE_PENDULUM))
    model = cls(cls.params_type(**_values()))
    p = model.params
    beta, delta = p.m2 * p.l1 * p.r2, p.I2 + p.m2 * p.r2**2
    alpha = p.I1 + p.I2 + p.m1 * p.r1**2 + p.m2 * (p.l1**2 + p.r2**2)
    expected_diagonal = [alpha + 2 * beta, delta]
    expected_gravity = [p.g * (p.m1 * p.r1 + p.m2 * p.l1 + p.m2 * p.r2), p.g * p.m2 * p.r2]
    # each is one evaluation of the same arithmetic at θ = 0: a few roundings of its size
    assert np.allclose(model.diagonal_scale(np.array([0.4, 2.0])), expected_diagonal, rtol=1e-14, atol=0)
    assert np.allclose(model.gravity_scale(), expected_gravity, rtol=1e-14, atol=0)


def test_render_and_report_take_the_functions(tmp_path, capsys):
    dp = _file(tmp_path, DOUBLE_PENDULUM + "PARAMS = " + repr(_values()) + "\n")
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    scene = scenes / "swing.toml"
    scene.write_text(
        f'name = "swing"\nmodel = "{dp}"\nurdf = "{DP_URDF}"\nengine = "both"\n'
        "[initial]\nq = [0.4, 0.9]\n[time]\nduration = 0.5\nsample_rate = 20.0\n"
        '[integrator]\nmethod = "DOP853"\nrtol = 1e-10\natol = 1e-10\n'
        "[effects]\ngravity = true\ndamping = true\n"
    )
    assert main(["render", str(scene), "-o", str(tmp_path / "swing.html")]) == 0
    assert (tmp_path / "swing.html").stat().st_size > 0
    review = tmp_path / "review"
    assert main(["report", "-o", str(review), "--scenes", str(scenes), "--samples", "20"]) == 0
    assert (review / "index.html").is_file()
    capsys.readouterr()
