"""Signed certificates: keygen, certify --key, recheck --trust, and what each forgery gets."""

from __future__ import annotations

import base64
import json
import shutil
import stat
from pathlib import Path

import pytest

from pendverify.analytic.params import default_parameter_file
from pendverify.certify.certificate import digest_of, summary_of
from pendverify.cli import main

FAST = ["--samples", "30"]
NAME = "double_pendulum"


@pytest.fixture(scope="module")
def keys(tmp_path_factory):
    folder = tmp_path_factory.mktemp("keys")
    assert main(["keygen", "-o", str(folder / "mine")]) == 0
    assert main(["keygen", "-o", str(folder / "other")]) == 0
    return {
        who: (folder / who / "pendverify-signing.key.pem", folder / who / "pendverify-signing.pub.pem")
        for who in ("mine", "other")
    }


@pytest.fixture(scope="module")
def signed(keys, tmp_path_factory):
    out = tmp_path_factory.mktemp("signed")
    params = str(default_parameter_file(NAME))
    assert main(["certify", params, "-o", str(out), *FAST, "--key", str(keys["mine"][0])]) == 0
    return out


def _fingerprint(public: Path) -> str:
    from pendverify.certify.signing import fingerprint, load_public_key

    return fingerprint(load_public_key(public))


def _copy(bundle: Path, tmp_path: Path) -> Path:
    """A copy of the bundle folder to forge in; returns its certificate."""
    shutil.copytree(bundle, tmp_path / "bundle")
    return tmp_path / "bundle" / f"{NAME}.cert.json"


def _forge(cert_path: Path, edit) -> None:
    """Edit the certificate, derive its summary and digest again, as a forger would."""
    cert = json.loads(cert_path.read_text())
    edit(cert)
    cert["summary"] = summary_of(cert["checks"])
    cert["digest"]["value"] = digest_of(cert)
    cert_path.write_text(json.dumps(cert, indent=2))


def test_keygen_writes_a_private_key_only_its_owner_reads(keys, capsys):
    private, public = keys["mine"]
    assert stat.S_IMODE(private.stat().st_mode) == 0o600
    assert private.read_text().startswith("-----BEGIN PRIVATE KEY-----")
    assert public.read_text().startswith("-----BEGIN PUBLIC KEY-----")
    before = private.read_bytes()
    assert main(["keygen", "-o", str(private.parent)]) == 2
    assert f"{private} exists; pass --force to replace the key pair" in capsys.readouterr().err
    assert private.read_bytes() == before


def test_keygen_force_replaces_the_pair(tmp_path, capsys):
    assert main(["keygen", "-o", str(tmp_path)]) == 0
    first = capsys.readouterr().out
    assert main(["keygen", "-o", str(tmp_path), "--force"]) == 0
    assert capsys.readouterr().out.splitlines()[-1] != first.splitlines()[-1]  # a new fingerprint


def test_signed_certificate_names_its_envelope(signed, keys):
    cert = json.loads((signed / f"{NAME}.cert.json").read_text())
    assert cert["signature"]["envelope"] == f"{NAME}.intoto.jsonl"
    assert cert["signature"]["keyid"] == _fingerprint(keys["mine"][1])
    envelope = json.loads((signed / f"{NAME}.intoto.jsonl").read_text())
    assert envelope["payloadType"] == "application/vnd.in-toto+json"
    assert envelope["signatures"][0]["keyid"] == cert["signature"]["keyid"]
    statement = json.loads(base64.b64decode(envelope["payload"]))
    assert statement["_type"] == "https://in-toto.io/Statement/v1"
    assert statement["predicateType"] == "https://in-toto.io/attestation/test-result/v0.1"
    subjects = {s["name"]: s["digest"]["sha256"] for s in statement["subject"]}
    assert set(subjects) == {f"{NAME}.cert.json", f"{NAME}.urdf", f"{NAME}.params.toml"}
    assert subjects[f"{NAME}.urdf"] == cert["urdf"]["sha256"]
    predicate = statement["predicate"]
    assert predicate["result"] == "PASSED" and predicate["failedTests"] == []
    assert predicate["passedTests"] == [c["name"] for c in cert["checks"]]


def test_recheck_with_the_right_key_passes(signed, keys, capsys):
    cert = signed / f"{NAME}.cert.json"
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][1])]) == 0
    out = capsys.readouterr().out
    assert f"signature ok: signed by the trusted key {_fingerprint(keys['mine'][1])}" in out
    assert "recheck passed" in out


@pytest.mark.parametrize(
    "field, edit",
    [
        ("date", lambda c: c.update(date="2020-01-01T00:00:00+00:00")),
        ("derived", lambda c: c["derived"].update(alpha=c["derived"]["alpha"] * 1.01)),
        ("notes", lambda c: c["notes"].append("reviewed by the forger")),
        ("versions", lambda c: c["versions"].update(pinocchio="9.9.9")),
        ("checks", lambda c: c["checks"][0].update(error=c["checks"][0]["error"] / 2)),
    ],
)
def test_an_edit_digested_again_fails_under_trust(signed, keys, tmp_path, capsys, field, edit):
    cert = _copy(signed, tmp_path)
    _forge(cert, edit)
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][1])]) == 2
    err = capsys.readouterr().err  # the signature is checked before anything is derived or loaded
    assert f"{cert}: sha256 " in err and "the file was edited after it was signed; rejected" in err


def test_an_edited_derived_field_fails_even_without_a_key(signed, tmp_path, capsys):
    cert = _copy(signed, tmp_path)
    _forge(cert, lambda c: c["derived"].update(beta=1.0))
    assert main(["recheck", str(cert)]) == 2
    assert "key 'derived.beta': recorded 1.0, computed from the parameters" in capsys.readouterr().err


def test_a_summary_that_does_not_follow_from_the_items_is_rejected(signed, tmp_path, capsys):
    cert_path = _copy(signed, tmp_path)
    cert = json.loads(cert_path.read_text())
    cert["summary"]["worst_ratio"] = 1e-9
    cert["digest"]["value"] = digest_of(cert)
    cert_path.write_text(json.dumps(cert))
    assert main(["recheck", str(cert_path)]) == 2
    assert "key 'summary.worst_ratio': recorded 1e-09, derived from the items" in capsys.readouterr().err


def test_another_key_s_signature_is_rejected_naming_both_fingerprints(signed, keys, capsys):
    cert = signed / f"{NAME}.cert.json"
    assert main(["recheck", str(cert), "--trust", str(keys["other"][1])]) == 2
    err = capsys.readouterr().err
    mine, other = _fingerprint(keys["mine"][1]), _fingerprint(keys["other"][1])
    assert f"signed by key {mine}, not by the trusted key {other}" in err


def test_an_unsigned_certificate_is_rejected_under_trust(keys, tmp_path, capsys):
    out = tmp_path / "unsigned"
    assert main(["certify", str(default_parameter_file(NAME)), "-o", str(out), *FAST]) == 0
    assert "signature" not in json.loads((out / f"{NAME}.cert.json").read_text())
    assert main(["recheck", str(out / f"{NAME}.cert.json"), "--trust", str(keys["mine"][1])]) == 2
    assert "unsigned: it names no envelope (it was issued without --key)" in capsys.readouterr().err


def test_a_tampered_envelope_payload_fails(signed, keys, tmp_path, capsys):
    cert = _copy(signed, tmp_path)
    envelope_path = cert.parent / f"{NAME}.intoto.jsonl"
    envelope = json.loads(envelope_path.read_text())
    statement = json.loads(base64.b64decode(envelope["payload"]))
    statement["predicate"]["failedTests"] = ["check:crba"]
    envelope["payload"] = base64.b64encode(json.dumps(statement).encode()).decode()
    envelope_path.write_text(json.dumps(envelope) + "\n")
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][1])]) == 2
    assert "the signature does not verify with the trusted key" in capsys.readouterr().err


def test_a_signature_made_by_another_key_under_the_trusted_keyid_fails(signed, keys, tmp_path, capsys):
    from pendverify.certify.signing import PAYLOAD_TYPE, load_private_key, pae

    cert = _copy(signed, tmp_path)
    envelope_path = cert.parent / f"{NAME}.intoto.jsonl"
    envelope = json.loads(envelope_path.read_text())
    payload = base64.b64decode(envelope["payload"])
    forged = load_private_key(keys["other"][0]).sign(pae(PAYLOAD_TYPE, payload))
    envelope["signatures"][0]["sig"] = base64.b64encode(forged).decode()
    envelope_path.write_text(json.dumps(envelope) + "\n")
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][1])]) == 2
    assert "the signature does not verify with the trusted key" in capsys.readouterr().err


def test_schema_keys_and_types_are_checked(signed, tmp_path, capsys):
    cert = _copy(signed, tmp_path)
    _forge(cert, lambda c: c.pop("settings"))
    assert main(["recheck", str(cert)]) == 2
    assert "key 'settings' is missing: expected a table" in capsys.readouterr().err
    _forge(
        cert,
        lambda c: c.update(settings={"samples": "30", "seed": 1, "sim_duration": 2.0, "sim_rtol": 1e-10}),
    )
    assert main(["recheck", str(cert)]) == 2
    assert "key 'settings.samples' = '30': expected an integer" in capsys.readouterr().err
    _forge(cert, lambda c: c.update(settings={**c["settings"], "samples": 30, "extra": 1}))
    assert main(["recheck", str(cert)]) == 2
    assert "key 'settings.extra' = 1: unknown key" in capsys.readouterr().err


def test_a_schema_1_certificate_is_rejected_saying_why(signed, tmp_path, capsys):
    cert = _copy(signed, tmp_path)
    _forge(cert, lambda c: c.update(schema="pendverify-certificate/1"))
    assert main(["recheck", str(cert)]) == 2
    err = capsys.readouterr().err
    assert (
        "schema 'pendverify-certificate/1' is no longer rechecked" in err and "certify the set again" in err
    )


@pytest.mark.sweep
def test_a_sweep_signs_each_set(keys, tmp_path, capsys):
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(
        'model = "double_pendulum"\nmode = "random"\ncount = 1\nseed = 3\nsamples = 20\n'
        "duration = 0.3\n[ranges]\nm1 = [0.5, 2.0]\n"
    )
    out = tmp_path / "out"
    args = ["certify", "--sweep", str(sweep), "-o", str(out), "--workers", "1", "--key", str(keys["mine"][0])]
    assert main(args) == 0
    (cert,) = out.glob("*.cert.json")
    assert (out / cert.name.replace(".cert.json", ".intoto.jsonl")).is_file()
    assert main(["recheck", str(cert), "--trust", str(keys["mine"][1])]) == 0
