"""``pendverify export``: every worked example written as C, MATLAB and NumPy code, each read back
and checked against its robot before it is reported; a planted error in the written code fails
that check, for every language; no compiler or no robot is one line, the files marked unverified.
"""

from __future__ import annotations

import pytest

from pendverify import api
from pendverify.export import files as export_files
from pendverify.export.verification import FAILED, UNVERIFIED, VERIFIED
from pendverify.worked_examples import EXAMPLES
from tests.cli_run import run_main

LANGS = ("c", "matlab", "numpy")
#: the worked examples whose model writes M (all of them); their Python model files
CASES = [(example, lang) for example in EXAMPLES for lang in LANGS]
#: a planted error in the written code of each language: the first entry of M times 11/10
PLANTS = {
    "c": ("out[0] = ", "out[0] = 1.1*"),
    "matlab": ("M = reshape([", "M = reshape([1.1*"),
    "numpy": ("return numpy.array([[", "return numpy.array([[1.1*"),
}


def _example(name: str):
    return next(e for e in EXAMPLES if e.name == name)


@pytest.mark.slow
@pytest.mark.parametrize(("example", "lang"), CASES, ids=[f"{e.name}-{lang}" for e, lang in CASES])
def test_every_worked_example_exports_verified(tmp_path, example, lang):
    result = api.export(example.model.source, lang, tmp_path, example.urdf.source, example.params.source)
    assert result.verification.status == VERIFIED, result.verification.line
    for path in result.files:
        assert "Verification: pendverify check of the written code: all checks pass" in path.read_text()


@pytest.mark.parametrize("lang", LANGS)
def test_a_planted_error_in_the_written_code_fails_its_check(tmp_path, monkeypatch, lang):
    """The check of the written code can fail: M[1,1] × 11/10 in the code (not in the model)."""
    writer = export_files.WRITERS[lang]
    old, new = PLANTS[lang]

    def planted(forms, banner):
        return {name: text.replace(old, new, 1) for name, text in writer(forms, banner).items()}

    monkeypatch.setitem(export_files.WRITERS, lang, planted)
    example = _example("minimal_double_pendulum")
    result = api.export(example.model.source, lang, tmp_path, example.urdf.source, example.params.source)
    assert result.verification.status == FAILED, result.verification.line
    assert "crba FAIL" in result.verification.line or "crba" in result.verification.line
    assert any(new in path.read_text() for path in result.files)  # written, and marked as failing
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
    result = api.export(example.model.source, "numpy", tmp_path)
    assert result.verification.status == UNVERIFIED and "--urdf" in result.verification.line


def test_exported_files_are_not_replaced_without_force(tmp_path):
    example = _example("minimal_double_pendulum")
    api.export(example.model.source, "numpy", tmp_path)
    done = run_main(["export", str(example.model.source), "--lang", "numpy", "-o", str(tmp_path)])
    assert done.returncode == 2 and "give --force" in done.stderr


def test_certify_export_signs_the_code_and_recheck_catches_an_edited_file(tmp_path):
    """``certify --export c``: the verified C code in the bundle, its banner naming the certificate's
    digest, covered by the signature; a hand-edited .c is refused by ``recheck``, naming it."""
    keys = tmp_path / "keys"
    assert run_main(["keygen", "-o", str(keys)]).returncode == 0
    example = _example("minimal_double_pendulum")
    out = tmp_path / "bundle"
    argv = ["certify", "--analytic", str(example.written_model.source), "--urdf", str(example.urdf.source)]
    argv += ["--params", str(example.params.source), "-o", str(out), "--samples", "30"]
    done = run_main([*argv, "--key", str(keys / "pendverify-signing.key.pem"), "--export", "c"])
    assert done.returncode == 0, done.stdout[-2000:] + done.stderr[-2000:]
    cert = next(out.glob("*.cert.json"))
    source = out / "minimal_double_pendulum.c"
    digest = __import__("json").loads(cert.read_text())["digest"]["value"]
    assert f"Certificate: sha256 {digest}" in source.read_text()
    assert "Verification: pendverify check of the written code: all checks pass" in source.read_text()
    trust = ["--trust", str(keys / "pendverify-signing.pub.pem")]
    assert run_main(["recheck", str(cert), *trust]).returncode == 0
    source.write_text(source.read_text().replace("out[0] = ", "out[0] = 1.1*", 1))
    done = run_main(["recheck", str(cert), *trust])
    assert done.returncode == 2 and "minimal_double_pendulum.c" in done.stderr, done.stderr


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
