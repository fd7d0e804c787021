"""Certificates and bundles built by hand, fast (no battery runs), for the tests that plant forgeries.

``make_certificate`` is a built-in double pendulum's certificate with one item and tiny
settings; ``write_bundle`` writes it (and, given a private key, the envelope that signs
it) as ``DIR/NAME.cert.json``; ``redigest`` recomputes the summary and digest after an
edit, as a forger would.
"""

from __future__ import annotations

from pathlib import Path

from pendverify.certify.battery import BatteryRun, BatterySettings
from pendverify.certify.certificate import build_certificate, certificate_text, digest_of, summary_of
from pendverify.certify.model_source import ModelSource, sha256_text
from pendverify.certify.names import envelope_name
from pendverify.certify.signing import envelope_line, fingerprint, statement
from pendverify.checks.evidence import Evidence
from pendverify.robot.writer import urdf_for

from ..conftest import default_params

SETTINGS = BatterySettings(samples=2, sim_duration=0.02)


def make_certificate(name: str = "double_pendulum", key=None) -> dict:
    params = default_params("double_pendulum")
    items = [
        Evidence(
            "check", "check:crba", "pass", 1e-15, 1e-9, largest_error=1e-15, samples=2, seed=SETTINGS.seed
        )
    ]
    keyid = fingerprint(key.public_key()) if key is not None else None
    battery = BatteryRun(items, notes=[])
    return build_certificate(
        name, ModelSource("double_pendulum"), params, urdf_for(params), SETTINGS, battery, keyid=keyid
    )


def embed_model(cert: dict, text: str, file: str = "evil.py", model: str = "evil") -> dict:
    """``cert`` made a plug-in's: its model is ``text``, embedded with its sha256."""
    cert["model"] = model
    cert["model_source"] = {"file": file, "text": text, "sha256": sha256_text(text)}
    return redigest(cert)


def redigest(cert: dict) -> dict:
    cert["summary"] = summary_of(cert["checks"])
    cert["digest"] = {"algorithm": "sha256", "value": digest_of(cert)}
    return cert


def write_bundle(
    directory: Path, cert: dict, key=None, subjects: list | None = None, file_name: str = ""
) -> Path:
    """Write ``cert`` as DIR/NAME.cert.json (or ``file_name``); with ``key``, sign it: the envelope's
    statement names the certificate file, or exactly ``subjects`` when given."""
    directory.mkdir(parents=True, exist_ok=True)
    text = certificate_text(cert)
    path = directory / (file_name or f"{cert['name']}.cert.json")
    path.write_text(text, encoding="utf-8")
    if key is not None:
        stmt = statement({f"{cert['name']}.cert.json": text.encode()}, cert["checks"], dict(cert["settings"]))
        if subjects is not None:
            stmt["subject"] = subjects
        (directory / envelope_name(cert["name"])).write_text(envelope_line(stmt, key), encoding="utf-8")
    return path
