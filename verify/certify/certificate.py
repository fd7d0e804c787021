"""Certificates: a parameter set, its URDF and the evidence that the battery passed.

Format (schema ``pendverify-certificate/1``), one JSON object:

=================  ===========================================================
key                content
=================  ===========================================================
schema             "pendverify-certificate/1"
name               the set's name (file stem or sweep index)
model              the model's name: double_pendulum | cart_double_pendulum, or a
                   plug-in's (its class's ``name``)
model_source       plug-ins only: {"file": the model file's name, "text": its source
                   verbatim, "sha256": of that text (UTF-8)}; ``recheck`` runs
                   the battery on this text, never on the file at that path now
parameters         the physical parameters, SI units (as the parameter file)
derived            the model's ``derived_constants()``: α, β, δ (double pendulum);
                   m + m1 + m2, l1 (m1 + m2), m2 l2 and det M at upright (cart);
                   whatever a plug-in names (none by default)
urdf               {"text": the URDF verbatim, "sha256": of that text (UTF-8)}
settings           the battery's settings: samples, seed, simulation length, rtol
versions           pendverify, pinocchio, numpy, python
checks             every battery item: name, kind (check | stress | invariant),
                   max_error, tolerance, samples, seed, passed, detail
notes              what the URDF reader noticed (angle offsets, a centre of mass
                   off the seed's family and the allowance it implies)
date               UTC time of certification, ISO 8601
digest             {"algorithm": "sha256", "value": hex digest of the canonical
                   JSON of every other field}
=================  ===========================================================

Canonical JSON: keys sorted, separators "," and ":", UTF-8, floats as Python's
shortest round-trip repr — so any edit to any field changes the digest.
"""

from __future__ import annotations

import hashlib
from datetime import datetime, timezone

from pendverify.analytic import ParameterSet
from pendverify.certify.battery import BatteryItem, BatterySettings
from pendverify.certify.model_source import ModelSource, source_problem
from pendverify.errors import CertificateError
from pendverify.jsonio import to_json, versions

SCHEMA = "pendverify-certificate/1"


def canonical_json(obj: dict) -> str:
    return to_json(obj, canonical=True)


def digest_of(cert: dict) -> str:
    body = {k: v for k, v in cert.items() if k != "digest"}
    return hashlib.sha256(canonical_json(body).encode()).hexdigest()


def derived_constants(model: ModelSource, params: ParameterSet) -> dict[str, float]:
    """The model's own derived constants (``ClosedFormModel.derived_constants``)."""
    return {k: float(v) for k, v in model.load()(params).derived_constants().items()}


def build_certificate(
    name: str,
    model: ModelSource,
    params: ParameterSet,
    urdf: str,
    settings: BatterySettings,
    items: list[BatteryItem],
    date: datetime | None = None,
    notes: list[str] | None = None,
) -> dict:
    cert = {
        "schema": SCHEMA,
        "name": name,
        "model": model.name,
        **({} if model.builtin else {"model_source": model.as_record()}),
        "parameters": params.as_dict(),
        "derived": derived_constants(model, params),
        "urdf": {"text": urdf, "sha256": hashlib.sha256(urdf.encode()).hexdigest()},
        "settings": settings.as_dict(),
        "versions": versions(),
        "checks": [item.as_dict() for item in items],
        "notes": list(notes or []),
        "date": (date or datetime.now(timezone.utc)).isoformat(timespec="seconds"),
    }
    cert["digest"] = {"algorithm": "sha256", "value": digest_of(cert)}
    return cert


def certificate_text(cert: dict) -> str:
    return to_json(cert)


def verify_digest(cert: dict, source: str) -> None:
    """Raise CertificateError unless the recorded digest matches the content."""
    recorded = cert.get("digest", {})
    if not isinstance(recorded, dict) or recorded.get("algorithm") != "sha256" or "value" not in recorded:
        raise CertificateError(f"{source}: no sha256 digest recorded")
    computed = digest_of(cert)
    model_problem = source_problem(cert["model_source"]) if "model_source" in cert else ""
    if computed != recorded["value"]:
        raise CertificateError(
            f"{source}: digest mismatch: recorded {recorded['value']}, computed {computed}; "
            "the certificate was edited after it was issued" + (f"; {model_problem}" if model_problem else "")
        )
    urdf = cert.get("urdf", {})
    if hashlib.sha256(urdf.get("text", "").encode()).hexdigest() != urdf.get("sha256"):
        raise CertificateError(f"{source}: the embedded URDF does not match its sha256")
    if model_problem:
        raise CertificateError(f"{source}: {model_problem}")


FIGURE_RTOL = 1e-6  # rounding-level errors may shift in their last digits across library builds


def compare_items(recorded: list[dict], fresh: list[BatteryItem]) -> list[str]:
    """Names of the fields whose values differ between a certificate and a re-run."""
    differences = []
    by_name = {item.name: item for item in fresh}
    for old in recorded:
        new = by_name.pop(old["name"], None)
        if new is None:
            differences.append(f"{old['name']}: not produced by the re-run")
            continue
        for key in ("kind", "samples", "seed", "passed"):
            if old[key] != getattr(new, key):
                differences.append(f"{old['name']}.{key}: recorded {old[key]!r}, now {getattr(new, key)!r}")
        for key in ("max_error", "tolerance"):
            a, b = float(old[key]), float(getattr(new, key))
            if abs(a - b) > FIGURE_RTOL * max(abs(a), abs(b)):
                differences.append(f"{old['name']}.{key}: recorded {a:.6g}, now {b:.6g}")
    differences += [f"{name}: new in the re-run, not in the certificate" for name in by_name]
    return differences


def bundle_paths(directory, name: str):
    """NAME.urdf, NAME.params.toml, NAME.cert.json (and, for a plug-in, ``model_path``)."""
    from pathlib import Path

    d = Path(directory)
    return d / f"{name}.urdf", d / f"{name}.params.toml", d / f"{name}.cert.json"


def model_path(directory, name: str):
    """Where a plug-in's bundle keeps a copy of the certified model file: NAME.model.py."""
    from pathlib import Path

    return Path(directory) / f"{name}.model.py"


def refuse_existing(directory, name: str, force: bool) -> None:
    """Raise unless ``force`` when any file of the bundle already exists."""
    if force:
        return
    for path in (*reversed(bundle_paths(directory, name)), model_path(directory, name)):
        if path.exists():
            raise CertificateError(f"{path} exists; pass --force to replace it")


def write_bundle(
    directory, name: str, params: ParameterSet, urdf: str, cert: dict, force: bool = False, model=None
):
    """Write NAME.urdf, NAME.params.toml (NAME.model.py for a plug-in ``model``) and, last,
    NAME.cert.json, each atomically.

    An existing certificate is never replaced unless ``force``: the refusal names
    the file.  A failure at any point leaves no certificate (the certificate is
    the last file, written to a temporary name and renamed into place).
    """
    from pendverify.atomic import write_atomic

    refuse_existing(directory, name, force)
    urdf_path, params_path, cert_path = bundle_paths(directory, name)
    write_atomic(urdf_path, urdf)
    write_atomic(params_path, params.to_toml(name))
    if model is not None and not model.builtin:
        write_atomic(model_path(directory, name), model.text)
    write_atomic(cert_path, certificate_text(cert))
    return cert_path
