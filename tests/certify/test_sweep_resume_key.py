"""``certify --sweep --resume --key KEY`` keeps only the certificates that KEY signed: an unsigned
one, one signed by another key, and one claiming KEY without KEY's envelope are recomputed and
signed, and the command says how many."""

from __future__ import annotations

import json
import shutil

import pytest

from pendverify.certify import sweep_run
from pendverify.certify.bundle import verify_signature
from pendverify.certify.certificate import canonical_json, digest_of
from pendverify.certify.signing import fingerprint, load_public_key
from pendverify.cli import main

pytestmark = pytest.mark.sweep  # every test certifies a sweep's sets (signed) and resumes it

SWEEP = """
model = "double_pendulum"
count = 3
seed = 5
samples = 5
duration = 0.05
[ranges]
m1 = [0.5, 2.0]
"""
NAMES = [f"double_pendulum-{i}" for i in range(3)]


def _sweep(folder, out, *extra):
    sweep = folder / "sweep.toml"
    sweep.write_text(SWEEP)
    return main(["certify", "--sweep", str(sweep), "-o", str(out), "--workers", "1", *extra])


@pytest.fixture(scope="module")
def folders(tmp_path_factory):
    """Keys A and B; the sweep unsigned, and signed by B."""
    root = tmp_path_factory.mktemp("resume-key")
    for who in ("a", "b"):
        assert main(["keygen", "-o", str(root / who)]) == 0
    assert _sweep(root, root / "unsigned") == 0
    assert _sweep(root, root / "by-b", "--key", str(root / "b" / "pendverify-signing.key.pem")) == 0
    return root


def _copy_bundle(source, name, target):
    for path in source.glob(f"{name}.*"):
        shutil.copy(path, target / path.name)


def _key(root, who):
    return str(root / who / "pendverify-signing.key.pem")


def _public(root, who):
    return root / who / "pendverify-signing.pub.pem"


def test_resume_with_a_key_redoes_unsigned_and_other_key_certificates(folders, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    _copy_bundle(folders / "unsigned", NAMES[0], out)  # unsigned
    _copy_bundle(folders / "by-b", NAMES[1], out)  # signed by B
    _copy_bundle(folders / "by-b", NAMES[2], out)  # signed by B, edited to claim A (digest recomputed)
    claimed = out / f"{NAMES[2]}.cert.json"
    cert = json.loads(claimed.read_text())
    cert["signature"]["keyid"] = fingerprint(load_public_key(_public(folders, "a")))
    cert["digest"]["value"] = digest_of(cert)
    claimed.write_text(canonical_json(cert))
    capsys.readouterr()

    assert _sweep(tmp_path, out, "--resume", "--key", _key(folders, "a")) == 0
    printed = capsys.readouterr().out
    assert "3 set(s) certified in" in printed and "not signed by --key" in printed, printed
    assert "0 set(s) already certified" in printed
    for name in NAMES:
        path = out / f"{name}.cert.json"
        data = path.read_bytes()
        line = verify_signature(path, json.loads(data), _public(folders, "a"), data)
        assert line.startswith("signature ok"), line


def test_resume_with_the_same_key_keeps_its_certificates(folders, tmp_path, capsys, monkeypatch):
    out = tmp_path / "out"
    shutil.copytree(folders / "by-b", out)
    monkeypatch.setattr(sweep_run, "Workers", _no_work)
    capsys.readouterr()
    assert _sweep(tmp_path, out, "--resume", "--key", _key(folders, "b")) == 0
    printed = capsys.readouterr().out
    assert "3 set(s) already certified" in printed and "not signed by --key" not in printed, printed


def _no_work(*args, **kw):
    class Idle:
        count = 1

        def submit(self, *args):
            raise AssertionError("a set was computed")

        def close(self, cancel=False):
            pass

    return Idle()
