"""``pendverify export``: every worked example written as C, MATLAB and NumPy code, each read back
and checked against its robot before it is reported; a planted error in the written code fails
that check, for every language; no compiler or no robot is one line, the files marked unverified.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from pendverify import api
from pendverify.export import files as export_files
from pendverify.export.verification import FAILED, UNVERIFIED, VERIFIED
from pendverify.worked_examples import EXAMPLES
from tests.cli_run import run_main

REPO = Path(__file__).resolve().parents[2]
#: the languages, CasADi (``--casadi``) among them: its tests need the casadi package (the test extra)
LANGS = ("c", "matlab", "numpy", "casadi")
#: the worked examples whose model writes M (all of them); their Python model files
CASES = [(example, lang) for example in EXAMPLES for lang in LANGS]
#: a planted error in the written code of each language: the first entry of M times 11/10
PLANTS = {
    "c": ("out[0] = ", "out[0] = 1.1*"),
    "matlab": ("M = reshape([", "M = reshape([1.1*"),
    "numpy": ("return numpy.array([[", "return numpy.array([[1.1*"),
    "casadi": ("out[0, 0] = ", "out[0, 0] = 1.1*"),
}


def _export(model, lang: str, output, *args):
    """``api.export`` of one language (CasADi by ``casadi=True``): its one result."""
    if lang == "casadi":
        pytest.importorskip("casadi", reason="export --casadi needs the casadi package (pendverify[casadi])")
    (result,) = api.export(model, None if lang == "casadi" else lang, output, *args, casadi=lang == "casadi")
    return result


def _plant(monkeypatch, lang: str, edit) -> None:
    """Make ``lang``'s writer plant an error: ``edit`` applied to the text of each file it writes."""
    writer = export_files.WRITERS[lang]

    def planted(forms, banner):
        return {name: edit(text) for name, text in writer(forms, banner).items()}

    monkeypatch.setitem(export_files.WRITERS, lang, planted)


def _example(name: str):
    return next(e for e in EXAMPLES if e.name == name)


@pytest.mark.slow
@pytest.mark.parametrize(("example", "lang"), CASES, ids=[f"{e.name}-{lang}" for e, lang in CASES])
def test_every_worked_example_exports_verified(tmp_path, example, lang):
    result = _export(example.model.source, lang, tmp_path, example.urdf.source, example.params.source)
    assert result.verification.status == VERIFIED, result.verification.line
    for path in result.files:
        assert "Verification: pendverify check of the written code: all checks pass" in path.read_text()


@pytest.mark.parametrize("lang", LANGS)
def test_a_planted_error_in_the_written_code_fails_its_check(tmp_path, monkeypatch, lang):
    """The check of the written code can fail: M[1,1] × 11/10 in the code (not in the model)."""
    _plant(monkeypatch, lang, lambda text: text.replace(*PLANTS[lang], 1))
    example = _example("minimal_double_pendulum")
    result = _export(example.model.source, lang, tmp_path, example.urdf.source, example.params.source)
    assert result.verification.status == FAILED, result.verification.line
    failing = result.verification.line.split("written code: ")[1].split(" FAIL")[0].split(", ")
    assert "crba" in failing, result.verification.line
    assert any(PLANTS[lang][1] in path.read_text() for path in result.files)  # written, and marked as failing
    assert all("FAIL" in path.read_text() for path in result.files)


def test_no_compiler_is_one_line_and_the_files_are_marked_unverified(tmp_path, monkeypatch):
    monkeypatch.setenv("CC", "no-such-compiler-here")
    example = _example("minimal_double_pendulum")
    argv = ["export", str(example.model.source), "--lang", "c", "-o", str(tmp_path)]
    done = run_main([*argv, "--urdf", str(example.urdf.source), "--params", str(example.params.source)])
    assert done.returncode == 0, done.stderr
    last = done.stdout.strip().splitlines()[-1]
    assert last.startswith(f"{UNVERIFIED}: no C compiler (no-such-compiler-here)"), done.stdout
    assert "Verification: no C compiler" in (tmp_path / "minimal_double_pendulum.c").read_text()


def test_without_a_robot_nothing_is_called_verified(tmp_path):
    example = _example("minimal_double_pendulum")
    result = _export(example.model.source, "numpy", tmp_path)
    assert result.verification.status == UNVERIFIED and "--urdf" in result.verification.line


def test_exported_files_are_not_replaced_without_force(tmp_path):
    example = _example("minimal_double_pendulum")
    _export(example.model.source, "numpy", tmp_path)
    done = run_main(["export", str(example.model.source), "--lang", "numpy", "-o", str(tmp_path)])
    assert done.returncode == 2 and "give --force" in done.stderr


@pytest.mark.parametrize(
    ("lang", "name"), [("c", "minimal_double_pendulum.c"), ("casadi", "minimal_double_pendulum_casadi.py")]
)
def test_certify_export_signs_the_code_and_recheck_catches_an_edited_file(tmp_path, lang, name):
    """``certify --export c`` (``casadi``): the verified code in the bundle, its banner naming the
    certificate's digest, covered by the signature; a hand-edited file is refused by ``recheck``,
    naming it."""
    if lang == "casadi":
        pytest.importorskip("casadi", reason="export --casadi needs the casadi package (pendverify[casadi])")
    keys = tmp_path / "keys"
    assert run_main(["keygen", "-o", str(keys)]).returncode == 0
    example = _example("minimal_double_pendulum")
    out = tmp_path / "bundle"
    argv = ["certify", "--analytic", str(example.written_model.source), "--urdf", str(example.urdf.source)]
    argv += ["--params", str(example.params.source), "-o", str(out), "--samples", "30"]
    done = run_main([*argv, "--key", str(keys / "pendverify-signing.key.pem"), "--export", lang])
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    cert = next(out.glob("*.cert.json"))
    source = out / name
    digest = __import__("json").loads(cert.read_text())["digest"]["value"]
    assert f"Certificate: sha256 {digest}" in source.read_text()
    assert "Verification: pendverify check of the written code: all checks pass" in source.read_text()
    trust = ["--trust", str(keys / "pendverify-signing.pub.pem")]
    assert run_main(["recheck", str(cert), *trust]).returncode == 0
    old, new = PLANTS[lang]
    source.write_text(source.read_text().replace(old, new, 1))
    done = run_main(["recheck", str(cert), *trust])
    assert done.returncode == 2 and name in done.stderr, done.stderr


def test_certify_export_needs_a_key(tmp_path):
    example = _example("minimal_double_pendulum")
    argv = ["certify", "--analytic", str(example.written_model.source), "--urdf", str(example.urdf.source)]
    argv += ["--params", str(example.params.source), "-o", str(tmp_path), "--export", "c"]
    done = run_main(argv)
    assert done.returncode == 2 and "give --key as well" in done.stderr, done.stderr


def test_the_file_names_a_bundle_allows_are_those_export_writes():
    from pendverify.export.closed_forms import QUANTITIES
    from pendverify.export.names import METHODS

    assert METHODS == tuple(method for method, _, _ in QUANTITIES.values())


#: where each language's function of a quantity starts: (language, key) → its first line's head
FUNCTION_STARTS = {
    ("c", "qddot"): "void double_pendulum_acceleration(",
    ("c", "det_M"): "void double_pendulum_det_mass_matrix(",
    ("matlab", "qddot"): "function qddot = double_pendulum_acceleration(",
    ("matlab", "det_M"): "function det_M = double_pendulum_det_mass_matrix(",
    ("numpy", "qddot"): "def qddot(",
    ("numpy", "det_M"): "def det_M(",
    ("casadi", "qddot"): "def _acceleration(",
    ("casadi", "det_M"): "def _det_mass_matrix(",
}
#: the first value each language's function writes, and the same × 11/10
FIRST_VALUE = {
    "c": ("out[0] = ", "out[0] = 1.1*"),
    "matlab": ("= reshape([", "= reshape([1.1*"),
    "numpy": ("return ", "return 1.1*"),
    "casadi": ("] = ", "] = 1.1*"),
}


def _planted_in(text: str, start: str, old: str, new: str) -> str:
    """``text`` with the first ``old`` after ``start`` made ``new`` (unchanged where there is none:
    another function's file, a C header)."""
    at = text.find(start)
    end = text.find(old, at) if at >= 0 else -1
    return text if end < 0 else text[:end] + new + text[end + len(old) :]


@pytest.mark.parametrize("lang", LANGS)
@pytest.mark.parametrize(("key", "check"), [(None, None), ("qddot", "aba"), ("det_M", "det")])
def test_the_models_own_qddot_and_det_m_are_written_and_checked(tmp_path, monkeypatch, lang, key, check):
    """The reference double pendulum writes its own q̈ (f + g·u) and det M: both are exported, and
    the check of the written code compares them with Pinocchio: an error planted in either fails
    its check alone."""
    if key is not None:
        _plant(
            monkeypatch, lang, lambda text: _planted_in(text, FUNCTION_STARTS[lang, key], *FIRST_VALUE[lang])
        )
    example = _example("double_pendulum")
    result = _export(example.model.source, lang, tmp_path, example.urdf.source)
    written = "".join(path.read_text() for path in result.files)
    assert FUNCTION_STARTS[lang, "qddot"] in written and FUNCTION_STARTS[lang, "det_M"] in written
    assert "Parameter set: the one the model reads off the robot description" in written
    if key is None:
        assert result.verification.status == VERIFIED, result.verification.line
    else:
        assert result.verification.status == FAILED, result.verification.line
        assert f": {check} FAIL (" in result.verification.line, result.verification.line


ACROBOT_QDDOT = (
    "corpus_acrobot_gym_qddot.toml",
    "corpus_acrobot_tedrake.urdf",
    "corpus_acrobot_gym_qddot_params.toml",
)


@pytest.mark.parametrize("lang", LANGS)
@pytest.mark.parametrize("plant", [False, True], ids=["as written", "planted"])
def test_a_model_of_qddot_alone_exports_its_qddot_verified(tmp_path, monkeypatch, lang, plant):
    """gymnasium's acrobot gives q̈ alone (one input, M not determined): its q̈, D and B are written
    (NumPy as DYNAMICS code) and ``aba`` checks the written q̈; × 11/10 in it, that fails."""
    if plant:
        start = {
            "c": "void acrobot_gym_qddot_acceleration(",
            "matlab": "function qddot",
            "numpy": "def qddot(",
            "casadi": "def _acceleration(",
        }[lang]
        _plant(monkeypatch, lang, lambda text: _planted_in(text, start, *FIRST_VALUE[lang]))
    model, urdf, params = (REPO / "examples" / name for name in ACROBOT_QDDOT)
    result = _export(model, lang, tmp_path, urdf, params)
    names = {path.name for path in result.files}
    assert "M" not in names and not any("mass_matrix" in n for n in names), names
    if lang == "numpy":
        assert "DYNAMICS = qddot" in (tmp_path / "acrobot_gym_qddot_numpy.py").read_text()
    want = (FAILED, "aba FAIL") if plant else (VERIFIED, "all checks pass")
    assert result.verification.status == want[0] and want[1] in result.verification.line, result.verification


def test_a_robot_without_parameter_values_is_refused_before_anything_is_written(tmp_path):
    """The cart reference system reads no parameters off its URDF and has none of its own: export
    with --urdf needs --params, and says so before writing (not a 'failed' written code)."""
    example = _example("cart_double_pendulum")
    argv = ["export", str(example.model.source), "--lang", "numpy", "-o", str(tmp_path / "out")]
    done = run_main([*argv, "--urdf", str(example.urdf.source)])
    assert done.returncode == 2 and "give the parameter set (--params" in done.stderr, done
    assert not (tmp_path / "out").exists()


def test_casadi_without_the_package_is_refused_in_one_line_before_any_work(tmp_path, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "casadi" else real(name, *a)
    )
    example = _example("minimal_double_pendulum")
    done = run_main(["export", str(example.model.source), "--casadi", "-o", str(tmp_path / "out")])
    assert done.returncode == 2, done
    assert (
        "export --casadi: the casadi package is not installed (pip install 'pendverify[casadi]')"
        in done.stderr
    )
    assert not (tmp_path / "out").exists()


def test_a_language_or_casadi_is_required(tmp_path):
    example = _example("minimal_double_pendulum")
    done = run_main(["export", str(example.model.source), "-o", str(tmp_path)])
    assert done.returncode == 2 and "give --lang c|matlab|numpy, --casadi, or both" in done.stderr, done


def test_lang_and_casadi_together_write_both_or_nothing(tmp_path):
    """``--lang c --casadi`` writes both languages' files, each verified; when one of them exists,
    neither language's files are written (without --force)."""
    pytest.importorskip("casadi", reason="export --casadi needs the casadi package (pendverify[casadi])")
    example = _example("minimal_double_pendulum")
    argv = ["export", str(example.model.source), "--lang", "c", "--casadi", "-o", str(tmp_path)]
    argv += ["--urdf", str(example.urdf.source), "--params", str(example.params.source)]
    (tmp_path / "minimal_double_pendulum_casadi.py").write_text("# mine\n")
    done = run_main(argv)
    assert done.returncode == 2 and "give --force" in done.stderr, done
    assert not (tmp_path / "minimal_double_pendulum.c").exists()
    done = run_main([*argv, "--force"])
    assert done.returncode == 0, done
    assert done.stdout.count(f"{VERIFIED}: pendverify check of the written code: all checks pass") == 2, (
        done.stdout
    )
    assert "export --casadi." in (tmp_path / "minimal_double_pendulum_casadi.py").read_text()


#: the simple end: a free 1-DOF pendulum given by q̈ alone (no inputs, no B), the robot of
#: tests/analytic/data/pendulum_functions.urdf (2 kg at 0.5 m, damping 0.1)
FREE_PENDULUM = """name = "free_pendulum"
inputs = []
qddot = ["(-b*dtheta - m*g*l*sin(theta))/(m*l**2)"]
D = [["b"]]

[coordinates]
theta = "angle"

[parameters]
m = { kind = "mass" }
l = { kind = "length" }
b = { kind = "damping" }
g = { kind = "gravity" }

[urdf]
joints = ["hinge"]
"""


@pytest.mark.parametrize("lang", LANGS)
def test_a_one_dof_model_of_qddot_alone_without_inputs_exports_verified(tmp_path, lang):
    """No inputs: the C, MATLAB and CasADi q̈ take no u (an empty argument is left out), the NumPy
    DYNAMICS code unpacks none; each is read back and ``aba`` passes."""
    model, params = tmp_path / "free.toml", tmp_path / "params.toml"
    model.write_text(FREE_PENDULUM)
    params.write_text('model = "free_pendulum"\n[parameters]\nm = 2.0\nl = 0.5\nb = 0.1\ng = 9.81\n')
    urdf = REPO / "tests" / "analytic" / "data" / "pendulum_functions.urdf"
    result = _export(model, lang, tmp_path / "out", urdf, params)
    assert result.verification.status == VERIFIED, result.verification.line
    text = "".join(path.read_text() for path in result.files)
    assert "const double u[" not in text and 'SX.sym("u"' not in text


def test_the_c_header_links_from_cpp(tmp_path):
    """A C++ controller includes the header and links the C object: the declarations are
    ``extern "C"``; its M at one state is the exported NumPy module's."""
    import importlib.util
    import shutil
    import subprocess

    import numpy as np

    cxx, cc = shutil.which("c++"), shutil.which("cc")
    if cxx is None or cc is None:
        pytest.skip("needs a C and a C++ compiler")
    example = _example("minimal_double_pendulum")
    api.export(example.model.source, "c", tmp_path)
    (numpy_code,) = api.export(example.model.source, "numpy", tmp_path)
    spec = importlib.util.spec_from_file_location("exported", numpy_code.files[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    params = api.load_params(example.model.source, example.params.source).as_dict()
    fields = "".join(f"    p.{name} = {params[name]!r};\n" for name in module.DECLARATION["parameters"])
    (tmp_path / "main.cpp").write_text(
        '#include <cstdio>\n#include "minimal_double_pendulum.h"\n'
        "int main() {\n    minimal_double_pendulum_params p;\n"
        f"{fields}"
        "    const double q[2] = {0.3, -0.2};\n    double M[4];\n"
        "    minimal_double_pendulum_mass_matrix(q, &p, M);\n"
        '    std::printf("%.17g %.17g %.17g %.17g\\n", M[0], M[1], M[2], M[3]);\n    return 0;\n}\n'
    )
    subprocess.run(
        [cc, "-std=c99", "-c", "minimal_double_pendulum.c", "-o", "model.o"], cwd=tmp_path, check=True
    )
    subprocess.run([cxx, "main.cpp", "model.o", "-lm", "-o", "main"], cwd=tmp_path, check=True)
    printed = subprocess.run([str(tmp_path / "main")], capture_output=True, text=True, check=True).stdout
    expected = module.M(np.array([0.3, -0.2]), params).ravel()
    # the same expressions, C's pow against NumPy's power: each entry (a sum of a few positive
    # products of the parameters and cos θ2) rounds in under 16 operations, each within ε
    assert np.allclose([float(x) for x in printed.split()], expected, rtol=32 * np.finfo(float).eps, atol=0)


def test_a_robot_given_as_xml_text_is_named_so_in_the_banner(tmp_path):
    """The API takes the URDF's text too: the parameters the reference system reads off it are
    those the code is checked with, and the banner does not take the text for a file name."""
    example = _example("double_pendulum")
    result = _export(example.model.source, "numpy", tmp_path, example.urdf.source.read_text())
    assert result.verification.status == VERIFIED, result.verification.line
    assert "reads off the robot description given;" in result.files[0].read_text()
