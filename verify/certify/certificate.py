"""Certificates: a parameter set, its URDF and the evidence that the battery passed.

Format (schema ``pendverify-certificate/2``), one JSON object:

=================  ===========================================================
key                content
=================  ===========================================================
schema             "pendverify-certificate/2"
name               the set's name (file stem or sweep index)
model              the model's name: double_pendulum | cart_double_pendulum, or a
                   plug-in's (its class's ``name``)
model_source       plug-ins only: {"file": the model file's name, "text": its source
                   verbatim, "sha256": of that text (UTF-8), and for a declaration of
                   .m files "companions": a list of {"file": its name (beside the
                   model file), "text", "sha256"}}; ``recheck`` runs
                   the battery on this text, never on the file at that path now
                   (Python text only when a trusted key signed it, or when told
                   to run embedded code: ``pendverify.certify.issue.recheck``)
parameters         the physical parameters, SI units (as the parameter file)
derived            the model's ``derived_constants()``: α, β, δ (double pendulum);
                   m + m1 + m2, l1 (m1 + m2), m2 l2 and det M at upright (cart);
                   whatever a plug-in names (none by default)
urdf               {"text": the URDF verbatim, "sha256": of that text (UTF-8)}
settings           the battery's settings: samples, seed, simulation length, rtol
versions           pendverify, pinocchio, numpy, python
checks             every battery item: name, kind (check | stress | invariant);
                   error, tolerance, at: the worst error/tolerance ratio (the
                   figures at that state or step, and where it is); max_error,
                   max_error_at: the largest error and where (checks and invariants; null
                   for stress cases, which keep only the worst ratio);
                   samples, seed, passed, detail; invariant items also engine
                   (compiled | aba: what ran the simulation,
                   ``pendverify.certify.simulations``; an invariant item without one
                   ran on aba)
summary            derived from ``checks``: items, passed, failed (names),
                   result (PASSED | FAILED), worst_item, worst_ratio
notes              what the URDF reader noticed (angle offsets, a centre of mass
                   off the closed form's family and the allowance it implies), and
                   why a part of the battery does not apply to the model (a model
                   giving q̈ alone runs no simulation: ``simulations.invariants_not_run``)
date               UTC time of certification, ISO 8601
signature          signed certificates only (``certify --key``): envelope (the
                   NAME.intoto.jsonl beside it), keyid (the key's fingerprint),
                   format (``pendverify.certify.signing``)
digest             {"algorithm": "sha256", "value": hex digest of the canonical
                   JSON of every other field}
=================  ===========================================================

Canonical JSON: keys sorted, separators "," and ":", UTF-8, floats as Python's
shortest round-trip repr — so any edit to any field changes the digest.  The digest
detects accidental corruption only: anyone can recompute it after an edit.  The
signature (``pendverify.certify.signing``) is what detects a deliberate edit.

Schema /1 certificates (one figure per item, the error at the worst ratio, under
the name ``max_error``) are rejected by ``recheck`` with a message saying so: their
figures cannot be compared with /2's; certify the set again.
"""

from __future__ import annotations

import hashlib
import math
from datetime import datetime, timezone

from pendverify.analytic import ParameterSet
from pendverify.certify.battery import BatteryRun, BatterySettings
from pendverify.certify.model_source import ModelSource, source_problem
from pendverify.certify.names import envelope_name
from pendverify.certify.simulations import UNRECORDED
from pendverify.checks.evidence import Evidence, item_record
from pendverify.errors import CertificateError
from pendverify.jsonio import plain, to_json, versions

SCHEMA = "pendverify-certificate/2"
OLD_SCHEMAS = {
    "pendverify-certificate/1": (
        "its items record one figure, the error at the worst error/tolerance ratio, under the "
        "name max_error; schema /2 records the largest error and the worst ratio apart, so the "
        "figures cannot be compared: certify the set again (its NAME.params.toml and NAME.urdf)"
    )
}
SIGNATURE_FORMAT = "DSSE envelope of an in-toto Statement v1, test-result v0.1 predicate, Ed25519"


def canonical_json(obj: dict) -> str:
    return to_json(obj, canonical=True)


def digest_of(cert: dict) -> str:
    body = {k: v for k, v in cert.items() if k != "digest"}
    return hashlib.sha256(canonical_json(body).encode()).hexdigest()


def derived_constants(model: ModelSource, params: ParameterSet) -> dict[str, float]:
    """The model's own derived constants (``ClosedFormModel.derived_constants``)."""
    return {k: float(v) for k, v in model.load()(params).derived_constants().items()}


def summary_of(checks: list[dict]) -> dict:
    """The certificate's ``summary``, derived from its items (``recheck`` derives it again)."""
    failed = [c["name"] for c in checks if not c["passed"]]
    ratios = [(plain_ratio(c), c["name"]) for c in checks]
    worst_ratio, worst_item = max(ratios, default=(0.0, ""))
    return plain(
        {
            "items": len(checks),
            "passed": len(checks) - len(failed),
            "failed": failed,
            "result": "FAILED" if failed or not checks else "PASSED",
            "worst_item": worst_item,
            "worst_ratio": worst_ratio,
        }
    )


def plain_ratio(item: dict) -> float:
    """error / tolerance of an item as recorded (non-finite numbers are written as strings)."""
    error, tolerance = float(item["error"]), float(item["tolerance"])
    return error / tolerance if tolerance > 0 else float("inf")


def build_certificate(
    name: str,
    model: ModelSource,
    params: ParameterSet,
    urdf: str,
    settings: BatterySettings,
    battery: BatteryRun,
    date: datetime | None = None,
    keyid: str | None = None,
) -> dict:
    """The certificate of a set and its battery's evidence (items and notes, made dicts here,
    once); with ``keyid`` (the signing key's fingerprint) it names its envelope."""
    checks = [item_record(item) for item in battery.items]
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
        "checks": checks,
        "summary": summary_of(checks),
        "notes": list(battery.notes),
        "date": (date or datetime.now(timezone.utc)).isoformat(timespec="seconds"),
    }
    if keyid is not None:
        cert["signature"] = {"envelope": envelope_name(name), "keyid": keyid, "format": SIGNATURE_FORMAT}
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


def figures_agree(a: float, b: float, rtol: float) -> bool:
    """Whether two figures agree to ``rtol``: a finite figure agrees only with a finite one, an
    infinite one only with the same infinity, NaN only with NaN."""
    a, b = float(a), float(b)
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= rtol * max(abs(a), abs(b))


def compare_items(recorded: list[dict], fresh: list[Evidence]) -> list[str]:
    """Names of the fields whose values differ between a certificate and a re-run (each fresh
    item as the certificate would record it, ``item_record``)."""
    differences = []
    by_name = {item.name: item_record(item) for item in fresh}
    for old in recorded:
        new = by_name.pop(old["name"], None)
        if new is None:
            differences.append(f"{old['name']}: not produced by the re-run")
            continue
        for key in ("kind", "samples", "seed", "passed"):
            if old[key] != new[key]:
                differences.append(f"{old['name']}.{key}: recorded {old[key]!r}, now {new[key]!r}")
        engine = old.get("engine", UNRECORDED if old["kind"] == "invariant" else "")
        if engine != new.get("engine", ""):
            differences.append(f"{old['name']}.engine: recorded {engine!r}, now {new.get('engine', '')!r}")
        for key in ("error", "tolerance", "max_error"):
            a, b = old[key], new[key]
            if a is None or b is None:
                if (a is None) != (b is None):
                    differences.append(f"{old['name']}.{key}: recorded {a!r}, now {b!r}")
                continue
            if not figures_agree(a, b, FIGURE_RTOL):
                a, b = float(a), float(b)
                differences.append(f"{old['name']}.{key}: recorded {a:.6g}, now {b:.6g}")
    differences += [f"{name}: new in the re-run, not in the certificate" for name in by_name]
    return differences
