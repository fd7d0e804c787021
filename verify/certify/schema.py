"""What ``recheck`` verifies before it re-runs anything: the schema and the derived fields.

``check_schema`` rejects a certificate that lacks a required key, has an unknown one,
or holds a value of the wrong type, naming the field (``checks[3].error``); the schema is written
as ``pendverify.documents`` tables (``TOP``, ``NESTED``, ``ITEM``), the style of every document.
``check_derived`` computes again every field that is derived from others — the
``summary`` from the items, ``derived`` from the parameters through the model's
``derived_constants`` — and rejects a certificate whose recorded values differ.
"""

from __future__ import annotations

import re
from datetime import datetime

from pendverify.certify.certificate import OLD_SCHEMAS, SCHEMA, figures_agree, summary_of
from pendverify.certify.model_source import MODEL_FILE_RULE, model_file_problem
from pendverify.certify.names import check_name
from pendverify.certify.settings_rules import settings_problem
from pendverify.certify.simulations import BATTERY_ENGINES
from pendverify.documents import MISSING, Key, Table, check_table, is_finite, is_integer, is_string, is_table
from pendverify.errors import CertificateError, PendverifyError

NONFINITE = ("inf", "-inf", "nan")  # how pendverify.jsonio writes non-finite numbers


def _as_float(v) -> float | None:
    """A JSON number as a float (an integer beyond float's range is none); None for anything else."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    try:
        return float(v)
    except OverflowError:
        return None


def _number(v) -> bool:
    if isinstance(v, str):
        return v in NONFINITE
    return _as_float(v) is not None


def _model_file(v) -> bool:
    return isinstance(v, str) and not model_file_problem(v)


def _table_of(test):
    return lambda v: isinstance(v, dict) and all(isinstance(k, str) and test(x) for k, x in v.items())


def _hex64(v) -> bool:
    return isinstance(v, str) and re.fullmatch(r"[0-9a-f]{64}", v) is not None


def _date(v) -> bool:
    try:
        return isinstance(v, str) and datetime.fromisoformat(v).tzinfo is not None
    except ValueError:
        return False


def _engine(v) -> bool:
    return isinstance(v, str) and v in BATTERY_ENGINES


def _key(test, what: str, required: bool = True) -> Key:
    """A certificate key: ``test`` passes, else "expected ``what``"."""
    return Key(((test, f"expected {what}"),), required)


def _table(keys: dict[str, Key]) -> Table:
    return Table(keys, unknown="unknown key; expected {keys}", missing="is missing: {rule}")


STRING, TABLE = _key(is_string, "a string"), _key(is_table, "a table")
HEX64 = _key(_hex64, "64 hex digits")
TOP = _table(
    {
        "schema": STRING,
        "name": STRING,
        "model": STRING,
        "model_source": _key(is_table, "a table", required=False),
        "parameters": _key(_table_of(is_finite), "a table of finite numbers"),
        "derived": _key(_table_of(_number), "a table of numbers"),
        "urdf": TABLE,
        "settings": TABLE,
        "versions": _key(_table_of(is_string), "a table of strings"),
        "checks": _key(lambda v: isinstance(v, list) and bool(v), "a non-empty list of items"),
        "summary": TABLE,
        "notes": _key(lambda v: isinstance(v, list) and all(map(is_string, v)), "a list of strings"),
        "date": _key(_date, "an ISO 8601 time with its UTC offset"),
        "signature": _key(is_table, "a table", required=False),
        "digest": TABLE,
    }
)
NESTED = {
    "urdf": _table({"text": STRING, "sha256": HEX64}),
    "model_source": _table(
        {
            "file": _key(_model_file, f"a model file's name ({MODEL_FILE_RULE})"),
            "text": STRING,
            "sha256": HEX64,
            "companions": _key(lambda v: isinstance(v, list), "a list of the files it reads", required=False),
        }
    ),
    "settings": _table(
        {
            "samples": _key(is_integer, "an integer"),
            "seed": _key(is_integer, "an integer"),
            "sim_duration": _key(_number, "a number"),
            "sim_rtol": _key(_number, "a number"),
        }
    ),
    "digest": _table({"algorithm": STRING, "value": STRING}),
    "signature": _table(
        {
            "envelope": _key(is_string, "a file name"),
            "keyid": _key(_hex64, "64 hex digits (a key fingerprint)"),
            "format": STRING,
        }
    ),
}
FIGURES = ("error", "tolerance", "max_error")  # an item's figures
ITEM = _table(
    {
        "name": STRING,
        "kind": _key(lambda v: v in ("check", "stress", "invariant"), "check, stress or invariant"),
        "error": _key(_number, "a number"),
        "tolerance": _key(_number, "a number"),
        "at": STRING,
        "max_error": _key(lambda v: v is None or _number(v), "a number or null"),
        "max_error_at": STRING,
        "samples": _key(is_integer, "an integer"),
        "seed": _key(is_integer, "an integer"),
        "passed": _key(lambda v: isinstance(v, bool), "true or false"),
        "detail": STRING,
        "engine": _key(_engine, f"one of {', '.join(BATTERY_ENGINES)} (invariant items)", False),
    }
)


def _bad(source: str, key: str, value, rule: str) -> CertificateError:
    shown = repr(value) if len(repr(value)) <= 80 else repr(value)[:77] + "..."
    return CertificateError(f"{source}: key '{key}' = {shown}: {rule}")


def _check_table(table: dict, schema: Table, source: str, prefix: str) -> None:
    def fail(key, value, rule):
        if value is MISSING:
            raise CertificateError(f"{source}: key '{key}' {rule}")
        raise _bad(source, key, value, rule)

    check_table(table, schema, fail, prefix)


def check_schema(cert, source: str) -> None:
    """Raise CertificateError naming the first field that breaks schema /2."""
    if not isinstance(cert, dict):
        raise CertificateError(f"{source}: not a certificate: expected a JSON object")
    schema = cert.get("schema")
    if isinstance(schema, str) and schema in OLD_SCHEMAS:
        raise CertificateError(f"{source}: schema {schema!r} is no longer rechecked: {OLD_SCHEMAS[schema]}")
    if schema != SCHEMA:
        raise _bad(source, "schema", schema, f"expected {SCHEMA!r}")
    _check_table(cert, TOP, source, "")
    for key, spec in NESTED.items():
        if key in cert:
            _check_table(cert[key], spec, source, f"{key}.")
    for key, value in cert["settings"].items():
        problem = settings_problem(key, value)
        if problem:
            raise _bad(source, f"settings.{key}", value, problem + " (as certify's options)")
    for i, item in enumerate(cert["checks"]):
        if not isinstance(item, dict):
            raise _bad(source, f"checks[{i}]", item, "expected a table")
        _check_table(item, ITEM, source, f"checks[{i}].")
        if item["passed"]:
            for key in FIGURES:
                if item[key] is not None and not is_finite(item[key]):
                    rule = "a passed item's figures are finite numbers"
                    raise _bad(source, f"checks[{i}].{key}", item[key], rule)
    try:
        check_name(cert["name"], source, "name")
        if "signature" in cert:
            check_name(cert["signature"]["envelope"], source, "signature.envelope")
    except PendverifyError as exc:
        raise CertificateError(str(exc)) from None


def check_derived(cert: dict, derived: dict[str, float], source: str) -> None:
    """Raise CertificateError naming a derived field whose recorded value is not what it derives to.

    ``derived`` is the model's ``derived_constants`` computed from the recorded parameters.
    """
    summary = summary_of(cert["checks"])
    for key in sorted(set(summary) | set(cert["summary"])):
        if cert["summary"].get(key) != summary.get(key):
            raise CertificateError(
                f"{source}: key 'summary.{key}': recorded {cert['summary'].get(key)!r}, derived from the "
                f"items {summary.get(key)!r}: the certificate was edited after it was issued"
            )
    for key in sorted(set(derived) | set(cert["derived"])):
        recorded, computed = cert["derived"].get(key), derived.get(key)
        if recorded is None or computed is None or not figures_agree(recorded, computed, 1e-12):
            raise CertificateError(
                f"{source}: key 'derived.{key}': recorded {recorded!r}, computed from the parameters "
                f"{computed!r}: the certificate was edited after it was issued"
            )
