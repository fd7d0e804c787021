"""Signed certificates: Ed25519 keys, an in-toto Statement in a DSSE envelope.

The digest a certificate carries is an unkeyed SHA-256: anyone can edit a field and
recompute it, so it detects accidents, not forgery.  A signature adds who issued the
certificate, and makes any edit detectable by anyone holding the public key.

* ``pendverify keygen -o DIR`` writes ``DIR/pendverify-signing.key.pem`` (the Ed25519
  private key, PKCS#8 PEM, mode 0600) and ``DIR/pendverify-signing.pub.pem`` (the
  public key, SubjectPublicKeyInfo PEM).  A key's *fingerprint* is the SHA-256 (hex) of
  its 32 raw public-key bytes; it is the envelope's ``keyid``.
* ``certify --key KEY.pem`` writes ``NAME.intoto.jsonl`` beside the certificate: one
  line, a DSSE envelope ``{"payloadType": "application/vnd.in-toto+json", "payload":
  base64(statement), "signatures": [{"keyid": fingerprint, "sig": base64(Ed25519
  signature of PAE(payloadType, payload))}]}``.  The statement is an in-toto Statement
  v1 whose subjects are the bundle's files with their SHA-256 (the certificate file
  itself included) and whose predicate is a test result
  (``https://in-toto.io/attestation/test-result/v0.1``): ``result`` PASSED or FAILED,
  ``configuration`` (the battery's settings), ``passedTests`` and ``failedTests`` (the
  battery's items).  DSSE signs the payload bytes, so nothing depends on how JSON is
  canonicalised.
* ``recheck CERT --trust PUB.pem`` accepts only a certificate whose envelope verifies
  with that key and whose statement (its shape checked: ``statement_subjects``) names
  files of the certificate's own bundle and records the certificate file's SHA-256.

PAE(type, body) = "DSSEv1" SP LEN(type) SP type SP LEN(body) SP body, lengths in ASCII
decimal (the DSSE v1 protocol).
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
import tempfile
from pathlib import Path

from cryptography.exceptions import InvalidSignature
from cryptography.hazmat.primitives import serialization
from cryptography.hazmat.primitives.asymmetric.ed25519 import Ed25519PrivateKey, Ed25519PublicKey

from pendverify.certify.names import NAME_RULE, check_name
from pendverify.errors import PendverifyError, SigningError

PAYLOAD_TYPE = "application/vnd.in-toto+json"
STATEMENT_TYPE = "https://in-toto.io/Statement/v1"
PREDICATE_TYPE = "https://in-toto.io/attestation/test-result/v0.1"
PRIVATE_NAME = "pendverify-signing.key.pem"
PUBLIC_NAME = "pendverify-signing.pub.pem"


def pae(payload_type: str, payload: bytes) -> bytes:
    """DSSE's pre-authentication encoding of (payloadType, payload)."""
    kind = payload_type.encode()
    return b"DSSEv1 %d %s %d %s" % (len(kind), kind, len(payload), payload)


def fingerprint(public_key: Ed25519PublicKey) -> str:
    """SHA-256 (hex) of the key's 32 raw bytes: the envelope's keyid."""
    raw = public_key.public_bytes(serialization.Encoding.Raw, serialization.PublicFormat.Raw)
    return hashlib.sha256(raw).hexdigest()


def _write_private(path: Path, data: bytes) -> None:
    """Atomically, and readable by the owner only (0600) from the first byte."""
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)  # mode 0600
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def generate_keys(directory: str | Path, force: bool = False) -> tuple[Path, Path, str]:
    """Write a new Ed25519 key pair into ``directory``: (private path, public path, fingerprint)."""
    from pendverify.atomic import write_atomic

    folder = Path(directory)
    private, public = folder / PRIVATE_NAME, folder / PUBLIC_NAME
    for path in (private, public):
        if path.is_dir() or (path.exists() and not path.is_file()):
            raise SigningError(f"{path}: is a folder (or not a file); --force replaces only a key file")
        if path.exists() and not force:
            raise SigningError(f"{path} exists; pass --force to replace the key pair")
    folder.mkdir(parents=True, exist_ok=True)
    key = Ed25519PrivateKey.generate()
    _write_private(
        private,
        key.private_bytes(
            serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
        ),
    )
    pem = key.public_key().public_bytes(
        serialization.Encoding.PEM, serialization.PublicFormat.SubjectPublicKeyInfo
    )
    write_atomic(public, pem)
    return private, public, fingerprint(key.public_key())


MAX_KEY_BYTES = 64 * 1024  # a PEM key is a few hundred bytes
MAX_ENVELOPE_BYTES = 16 * 1024 * 1024


def _read(path: str | Path, what: str) -> bytes:
    """At most ``MAX_KEY_BYTES`` of a key file (a pipe is fine: ``--key <(...)``)."""
    if Path(path).is_dir():
        raise SigningError(f"{path}: is a directory; give the {what} file (PEM)")
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_KEY_BYTES + 1)
    except OSError as exc:
        raise SigningError(f"{path}: cannot read the {what}: {exc.strerror or exc}") from None
    if len(data) > MAX_KEY_BYTES:
        raise SigningError(f"{path}: larger than the limit of {MAX_KEY_BYTES:,} bytes for a {what} (PEM)")
    return data


def load_private_key(path: str | Path) -> Ed25519PrivateKey:
    try:
        key = serialization.load_pem_private_key(_read(path, "private key"), password=None)
    except (ValueError, TypeError) as exc:
        raise SigningError(f"{path}: not an unencrypted PEM private key: {exc}") from None
    if not isinstance(key, Ed25519PrivateKey):
        raise SigningError(f"{path}: not an Ed25519 private key (pendverify keygen writes one)")
    return key


def load_public_key(path: str | Path) -> Ed25519PublicKey:
    try:
        key = serialization.load_pem_public_key(_read(path, "public key"))
    except (ValueError, TypeError) as exc:
        raise SigningError(f"{path}: not a PEM public key: {exc}") from None
    if not isinstance(key, Ed25519PublicKey):
        raise SigningError(f"{path}: not an Ed25519 public key (pendverify keygen writes one)")
    return key


def sha256_bytes(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def statement(files: dict[str, bytes], checks: list[dict], configuration: dict) -> dict:
    """The in-toto Statement v1: subjects = the bundle's files; a test-result predicate."""
    failed = [c["name"] for c in checks if not c["passed"]]
    return {
        "_type": STATEMENT_TYPE,
        "subject": [{"name": n, "digest": {"sha256": sha256_bytes(b)}} for n, b in sorted(files.items())],
        "predicateType": PREDICATE_TYPE,
        "predicate": {
            "result": "FAILED" if failed else "PASSED",
            "configuration": [{"name": "pendverify battery", "annotations": configuration}],
            "passedTests": [c["name"] for c in checks if c["passed"]],
            "failedTests": failed,
        },
    }


def envelope_line(stmt: dict, key: Ed25519PrivateKey) -> str:
    """The DSSE envelope of ``stmt``, signed by ``key``, as one line of JSON (the .intoto.jsonl)."""
    payload = json.dumps(stmt, sort_keys=True, separators=(",", ":"), ensure_ascii=False).encode()
    signature = key.sign(pae(PAYLOAD_TYPE, payload))
    envelope = {
        "payloadType": PAYLOAD_TYPE,
        "payload": base64.b64encode(payload).decode(),
        "signatures": [{"keyid": fingerprint(key.public_key()), "sig": base64.b64encode(signature).decode()}],
    }
    return json.dumps(envelope, sort_keys=True, separators=(",", ":")) + "\n"


def open_envelope(text: str, trusted: Ed25519PublicKey, source: str, trusted_name: str) -> dict:
    """The statement of a DSSE envelope that the ``trusted`` key signed; SigningError otherwise."""
    try:
        envelope = json.loads(text)
        payload = base64.b64decode(envelope["payload"], validate=True)
        signatures = [(s["keyid"], base64.b64decode(s["sig"], validate=True)) for s in envelope["signatures"]]
        payload_type = envelope["payloadType"]
    except (ValueError, KeyError, TypeError, RecursionError) as exc:  # binascii.Error is a ValueError
        raise SigningError(
            f"{source}: not a DSSE envelope (payloadType, payload, signatures): {exc}"
        ) from exc
    if payload_type != PAYLOAD_TYPE:
        raise SigningError(f"{source}: payloadType {payload_type!r}, expected {PAYLOAD_TYPE!r}")
    want = fingerprint(trusted)
    mine = [sig for keyid, sig in signatures if keyid == want]
    if not mine:
        others = ", ".join(keyid for keyid, _ in signatures) or "no key"
        raise SigningError(
            f"{source}: signed by key {others}, not by the trusted key {want} ({trusted_name}); rejected"
        )
    for sig in mine:
        try:
            trusted.verify(sig, pae(payload_type, payload))
            break
        except InvalidSignature:
            continue
    else:
        raise SigningError(
            f"{source}: the signature does not verify with the trusted key {want} ({trusted_name}): "
            "the envelope was altered after signing, or another key signed it under this keyid; rejected"
        )
    try:
        stmt = json.loads(payload)
    except (ValueError, RecursionError) as exc:
        raise SigningError(f"{source}: the signed payload is not JSON: {exc}") from None
    if not isinstance(stmt, dict) or stmt.get("_type") != STATEMENT_TYPE:
        raise SigningError(f"{source}: the signed payload is not an in-toto Statement v1")
    if stmt.get("predicateType") != PREDICATE_TYPE:
        found = stmt.get("predicateType")
        raise SigningError(f"{source}: predicateType {found!r}, expected {PREDICATE_TYPE}")
    return stmt


def _hex64(value) -> bool:
    return isinstance(value, str) and len(value) == 64 and all(c in "0123456789abcdef" for c in value)


def statement_subjects(stmt: dict, source: str) -> dict[str, str]:
    """A signed statement's subjects, name → SHA-256, once its shape is checked: ``subject`` a
    non-empty list of {"name": a bundle file's name, "digest": {"sha256": 64 hex digits}}, each
    name once; ``predicate`` a test result (``result`` PASSED or FAILED, lists of test names).

    A subject's name is a file beside the certificate (``pendverify.certify.names``): no
    folder, no ``..``, not absolute.  Anything else raises SigningError naming the key."""

    def bad(key: str, value, rule: str) -> SigningError:
        shown = repr(value) if len(repr(value)) <= 80 else repr(value)[:77] + "..."
        return SigningError(f"{source}: the signed statement's key '{key}' = {shown}: {rule}; rejected")

    subjects = stmt.get("subject")
    if not isinstance(subjects, list) or not subjects:
        raise bad("subject", subjects, "expected a non-empty list of {name, digest}")
    found: dict[str, str] = {}
    for i, subject in enumerate(subjects):
        if not isinstance(subject, dict) or set(subject) != {"name", "digest"}:
            raise bad(f"subject[{i}]", subject, "expected a table of name and digest")
        name, digest = subject["name"], subject["digest"]
        try:
            check_name(name, source, f"subject[{i}].name")
        except PendverifyError:
            rule = f"expected a file name beside the certificate ({NAME_RULE})"
            raise bad(f"subject[{i}].name", name, rule) from None
        if not isinstance(digest, dict) or set(digest) != {"sha256"} or not _hex64(digest["sha256"]):
            raise bad(f"subject[{i}].digest", digest, 'expected {"sha256": 64 hex digits}')
        if name in found:
            raise bad(f"subject[{i}].name", name, "named twice: each file is a subject once")
        found[name] = digest["sha256"]
    predicate = stmt.get("predicate")
    if not isinstance(predicate, dict):
        raise bad("predicate", predicate, "expected a table (a test result)")
    if predicate.get("result") not in ("PASSED", "FAILED"):
        raise bad("predicate.result", predicate.get("result"), "expected PASSED or FAILED")
    for key in ("passedTests", "failedTests"):
        tests = predicate.get(key)
        if not isinstance(tests, list) or not all(isinstance(t, str) for t in tests):
            raise bad(f"predicate.{key}", tests, "expected a list of test names")
    if not isinstance(predicate.get("configuration"), list):
        raise bad("predicate.configuration", predicate.get("configuration"), "expected a list")
    return found
