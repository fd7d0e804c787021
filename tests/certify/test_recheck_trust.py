"""What recheck runs and when: embedded Python only when trusted; every check before the model.

Each test plants one problem: a certificate whose embedded model writes a marker file at
import, non-finite figures, another set's certificate under a bundle's name, subjects
outside the bundle, settings out of bounds, malformed files.  Certificates are built by hand
(``tests.certify.forged_bundles``), so nothing here runs a battery.
"""

from __future__ import annotations

import hashlib
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from pendverify.certify.bundle import verify_signature
from pendverify.certify.certificate import certificate_text, figures_agree
from pendverify.certify.reading import MAX_DEPTH
from pendverify.certify.settings_rules import settings_problem
from pendverify.certify.signing import load_private_key
from pendverify.cli import main

from .forged_bundles import embed_model, make_certificate, redigest, write_bundle


@pytest.fixture(scope="module")
def keys(tmp_path_factory):
    folder = tmp_path_factory.mktemp("keys")
    found = {}
    for who in ("mine", "other"):
        assert main(["keygen", "-o", str(folder / who), "--quiet"]) == 0
        private = folder / who / "pendverify-signing.key.pem"
        found[who] = (load_private_key(private), private, folder / who / "pendverify-signing.pub.pem")
    return found


def _marker_model(marker: Path) -> str:
    """A model file that writes ``marker`` when imported (and defines no model)."""
    return f"from pathlib import Path\nPath({str(marker)!r}).write_text('ran')\n"


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    return err


# item 1: embedded Python runs only when a trusted key vouches for it (or the user says so)


def test_an_unsigned_python_model_is_refused_without_running(tmp_path, capsys):
    marker = tmp_path / "ran.txt"
    cert = write_bundle(tmp_path / "b", embed_model(make_certificate(), _marker_model(marker)))
    assert main(["recheck", str(cert)]) == 2
    err = _one_line_error(capsys)
    assert "embedded Python source (evil.py)" in err and "--trust" in err and "--run-embedded-code" in err
    assert not marker.exists()


def test_a_python_model_signed_by_another_key_is_refused_without_running(tmp_path, capsys, keys):
    marker = tmp_path / "ran.txt"
    other = keys["other"][0]
    cert = write_bundle(
        tmp_path / "b", embed_model(make_certificate(key=other), _marker_model(marker)), other
    )
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][2])]) == 2
    assert "not by the trusted key" in _one_line_error(capsys)
    assert not marker.exists()


def test_a_signed_python_model_whose_text_was_swapped_is_refused_without_running(tmp_path, capsys, keys):
    marker = tmp_path / "ran.txt"
    mine = keys["mine"][0]
    cert = embed_model(make_certificate(key=mine), "# the model as it was signed\n")
    path = write_bundle(tmp_path / "b", cert, mine)
    embed_model(cert, _marker_model(marker))  # swapped, sha256 and digest recomputed
    path.write_text(certificate_text(cert), encoding="utf-8")
    assert main(["recheck", str(path), "--trust", str(keys["mine"][2])]) == 2
    assert "the file was edited after it was signed" in _one_line_error(capsys)
    assert not marker.exists()


def test_a_python_model_runs_when_signed_by_the_trusted_key_or_when_the_user_says_so(tmp_path, capsys, keys):
    mine = keys["mine"][0]
    marker = tmp_path / "signed.txt"
    cert = write_bundle(tmp_path / "s", embed_model(make_certificate(key=mine), _marker_model(marker)), mine)
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][2])]) == 2  # it defines no model
    assert marker.exists()
    marker = tmp_path / "flag.txt"
    cert = write_bundle(tmp_path / "f", embed_model(make_certificate(), _marker_model(marker)))
    assert main(["recheck", str(cert), "--run-embedded-code"]) == 2
    assert marker.exists()
    capsys.readouterr()


def test_a_text_model_is_data_and_is_read_without_trust(tmp_path, capsys):
    """An embedded .toml model is parsed, never run: no key is asked for (its text is read as a model)."""
    cert = write_bundle(tmp_path / "b", embed_model(make_certificate(), "not a [model", file="evil.toml"))
    assert main(["recheck", str(cert)]) == 2
    err = _one_line_error(capsys)
    assert "embedded Python" not in err and "evil.toml" in err


# item 5: a non-finite figure never reproduces a finite one


@pytest.mark.parametrize("key", ["error", "tolerance", "max_error"])
@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_a_non_finite_figure_of_a_passed_item_is_refused(tmp_path, capsys, key, value):
    cert = make_certificate()
    cert["checks"][0][key] = value
    path = write_bundle(tmp_path, redigest(cert))
    assert main(["recheck", str(path)]) == 2
    assert f"key 'checks[0].{key}' = {value!r}: a passed item's figures are finite" in _one_line_error(capsys)


def test_a_nan_literal_is_not_json(tmp_path, capsys):
    path = tmp_path / "double_pendulum.cert.json"
    path.write_text(certificate_text(make_certificate()).replace('"error": 1e-15', '"error": NaN', 1))
    assert "NaN" in path.read_text()
    assert main(["recheck", str(path)]) == 2
    assert "the literal NaN is not JSON" in _one_line_error(capsys)


def test_a_non_finite_derived_constant_is_refused(tmp_path, capsys):
    cert = make_certificate()
    cert["derived"]["alpha"] = "nan"
    path = write_bundle(tmp_path, redigest(cert))
    assert main(["recheck", str(path)]) == 2
    assert "key 'derived.alpha': recorded 'nan', computed from the parameters" in _one_line_error(capsys)


def test_figures_agree_only_finite_with_finite():
    nan, inf = math.nan, math.inf
    assert (
        figures_agree(1.0, 1.0 + 1e-9, 1e-6)
        and figures_agree(inf, inf, 1e-6)
        and figures_agree(nan, nan, 1e-6)
    )
    for a, b in ((nan, 1.0), (1.0, nan), (inf, 1.0), (1.0, inf), (-inf, inf), (1.0, 2.0)):
        assert not figures_agree(a, b, 1e-6), (a, b)


# item 6: a bundle's NAME.cert.json holds set NAME's certificate


def test_another_sets_certificate_under_a_bundles_name_is_refused(tmp_path, capsys, keys):
    mine = keys["mine"][0]
    folder = tmp_path / "bundle"
    write_bundle(folder, make_certificate("alpha", mine), mine)
    beta = write_bundle(folder, make_certificate("beta", mine), mine)
    assert verify_signature(
        beta, json.loads(beta.read_text()), keys["mine"][2], beta.read_bytes()
    ).startswith("signature ok")  # the real one still holds
    (folder / "alpha.cert.json").write_bytes(beta.read_bytes())
    assert main(["recheck", str(folder / "alpha.cert.json"), "--trust", str(keys["mine"][2])]) == 2
    assert "holds the certificate of set 'beta'" in _one_line_error(capsys)


def test_a_statement_naming_another_sets_file_is_refused(tmp_path, capsys, keys):
    mine = keys["mine"][0]
    cert = make_certificate("alpha", mine)
    text = certificate_text(cert).encode()
    subjects = [
        {"name": "alpha.cert.json", "digest": {"sha256": hashlib.sha256(text).hexdigest()}},
        {"name": "beta.urdf", "digest": {"sha256": "0" * 64}},
    ]
    path = write_bundle(tmp_path, cert, mine, subjects)
    assert main(["recheck", str(path), "--trust", str(keys["mine"][2])]) == 2
    assert "names 'beta.urdf', not a file of set 'alpha''s bundle" in _one_line_error(capsys)


# item 8: subjects are names inside the bundle, once each; the statement's shape is checked


@pytest.mark.parametrize(
    "subjects, expected",
    [
        ([{"name": "../outside.txt", "digest": {"sha256": "0" * 64}}], "subject[1].name' = '../outside.txt'"),
        ([{"name": "/etc/passwd", "digest": {"sha256": "0" * 64}}], "subject[1].name' = '/etc/passwd'"),
        ("CERT", "subject[1].name' = 'double_pendulum.cert.json': named twice"),
        ("STRING", "key 'subject' = 'double_pendulum.cert.json': expected a non-empty list"),
        ([{"name": "double_pendulum.urdf", "digest": "abc"}], "subject[1].digest' = 'abc'"),
        ([["not", "a", "table"]], "subject[1]' = ['not', 'a', 'table']: expected a table"),
    ],
)
def test_a_subject_outside_the_bundle_or_twice_or_malformed_is_refused(
    tmp_path, capsys, keys, subjects, expected
):
    mine = keys["mine"][0]
    cert = make_certificate(key=mine)
    own = {
        "name": "double_pendulum.cert.json",
        "digest": {"sha256": hashlib.sha256(certificate_text(cert).encode()).hexdigest()},
    }
    if subjects == "STRING":
        stmt_subjects = "double_pendulum.cert.json"
    else:
        stmt_subjects = [own, *([own] if subjects == "CERT" else subjects)]
    (tmp_path / "outside.txt").write_text("outside")
    path = write_bundle(tmp_path / "b", cert, mine, stmt_subjects)
    assert main(["recheck", str(path), "--trust", str(keys["mine"][2])]) == 2
    err = _one_line_error(capsys)
    assert expected in err and "rejected" in err


# item 9 and the settings.seed of item 14: the settings within certify's bounds


@pytest.mark.parametrize(
    "key, value",
    [
        *[("samples", -5), ("samples", 10**7), ("samples", 0), ("samples", 2.5), ("seed", -1)],
        *[("seed", 2**64), ("sim_duration", "inf"), ("sim_duration", 0), ("sim_rtol", "nan")],
        ("sim_rtol", -1e-9),
    ],
)
def test_settings_out_of_bounds_are_refused(tmp_path, capsys, key, value):
    cert = make_certificate()
    cert["settings"][key] = value
    path = write_bundle(tmp_path, redigest(cert))
    assert main(["recheck", str(path)]) == 2
    err = _one_line_error(capsys)
    assert f"key 'settings.{key}' = {value!r}: expected" in err


def test_the_sample_limit_is_certifys_and_overridable(monkeypatch, tmp_path, capsys):
    assert "1,000,000" in settings_problem("samples", 10**7)
    with pytest.raises(SystemExit) as exit_:
        main(["certify", "x.toml", "-o", str(tmp_path), "--samples", str(10**7)])
    assert exit_.value.code == 2 and "PENDVERIFY_MAX_SAMPLES" in capsys.readouterr().err
    monkeypatch.setenv("PENDVERIFY_MAX_SAMPLES", "2e7")
    assert settings_problem("samples", 10**7) == ""
    assert settings_problem("samples", 2 * 10**7 + 1) != ""


# the other exit-3 cases of item 14


def test_a_folder_given_as_the_certificate(tmp_path, capsys):
    assert main(["recheck", str(tmp_path)]) == 2
    assert "is a directory; give the certificate (NAME.cert.json) file" in _one_line_error(capsys)


def _cli(*argv: str, timeout: int = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "pendverify.cli", *argv], capture_output=True, text=True, timeout=timeout
    )


def test_a_deeply_nested_certificate_is_refused_with_the_limit(tmp_path):
    path = tmp_path / "deep.cert.json"
    path.write_text("[" * 100_000 + "]" * 100_000)
    done = _cli("recheck", str(path))
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert f"nested deeper than the limit of {MAX_DEPTH} levels" in done.stderr
    path.write_text('{"schema": "' + "[" * 100_000 + '"}')  # brackets in a string do not nest
    assert main(["recheck", str(path)]) == 2


@pytest.mark.parametrize("file", ["a\0b.py", "..", "x" * 300 + ".py", "dir/evil.py", "evil.sh", ".py"])
def test_an_embedded_models_file_name_must_be_a_plain_model_file_name(tmp_path, capsys, file):
    marker = tmp_path / "ran.txt"
    cert = embed_model(make_certificate(), _marker_model(marker), file=file)
    path = write_bundle(tmp_path / "b", cert)
    assert main(["recheck", str(path), "--run-embedded-code"]) == 2
    err = _one_line_error(capsys)
    assert "key 'model_source.file'" in err and "a plain file name ending in .py or .toml" in err
    assert not marker.exists()


def test_keygen_force_onto_a_folder_at_the_key_path(tmp_path, capsys):
    (tmp_path / "pendverify-signing.key.pem").mkdir()
    assert main(["keygen", "-o", str(tmp_path), "--force"]) == 2
    assert "pendverify-signing.key.pem: is a folder" in _one_line_error(capsys)


def test_an_endless_key_file_is_read_only_up_to_its_limit(tmp_path):
    params = tmp_path / "p.toml"
    from pendverify.analytic.params import default_parameter_file

    params.write_text(Path(default_parameter_file("double_pendulum")).read_text())
    done = _cli("certify", str(params), "-o", str(tmp_path / "out"), "--samples", "2", "--key", "/dev/zero")
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert "/dev/zero: larger than the limit of 65,536 bytes for a private key" in done.stderr
    done = _cli("recheck", str(write_bundle(tmp_path, make_certificate())), "--trust", "/dev/zero")
    assert done.returncode == 2 and "larger than the limit" in done.stderr


def test_a_deeply_nested_envelope_is_refused(tmp_path, keys):
    mine = keys["mine"][0]
    path = write_bundle(tmp_path, make_certificate(key=mine), mine)
    (tmp_path / "double_pendulum.intoto.jsonl").write_text("[" * 100_000 + "]" * 100_000 + "\n")
    done = _cli("recheck", str(path), "--trust", str(keys["mine"][2]))
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert "not a DSSE envelope" in done.stderr


def test_a_bundle_file_beside_that_is_not_the_embedded_text_is_refused(tmp_path, capsys):
    cert = make_certificate()
    path = write_bundle(tmp_path, cert)
    (tmp_path / "double_pendulum.urdf").write_text(cert["urdf"]["text"])  # the real one: fine
    (tmp_path / "double_pendulum.model.py").write_text("raise SystemExit('not this bundle's file')\n")
    from pendverify.certify.bundle import check_files_beside

    check_files_beside(path, cert)  # a built-in model's bundle has no model file to compare
    (tmp_path / "double_pendulum.urdf").write_text(cert["urdf"]["text"].replace("double_pendulum", "other"))
    assert main(["recheck", str(path)]) == 2
    assert "double_pendulum.urdf: not the text double_pendulum.cert.json embeds" in _one_line_error(capsys)


def test_a_folder_given_as_the_trusted_key(tmp_path, capsys):
    path = write_bundle(tmp_path / "b", make_certificate())
    assert main(["recheck", str(path), "--trust", str(tmp_path)]) == 2
    assert "is a directory; give the public key file (PEM)" in _one_line_error(capsys)
