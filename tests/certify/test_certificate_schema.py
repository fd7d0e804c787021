"""A certificate's schema (``pendverify.certify.schema``, written as ``pendverify.documents`` tables):
each broken rule is one sentence naming the file, the key, the value and the rule."""

from __future__ import annotations

import pytest

from pendverify.certify.schema import TOP, check_schema
from pendverify.errors import CertificateError

from .forged_bundles import make_certificate


def refusal(cert) -> str:
    with pytest.raises(CertificateError) as caught:
        check_schema(cert, "x.cert.json")
    return str(caught.value)


def test_an_issued_certificate_meets_the_schema():
    check_schema(make_certificate(), "x.cert.json")


def test_a_missing_key_is_named_with_what_it_must_be():
    cert = make_certificate()
    del cert["date"]
    assert (
        refusal(cert) == "x.cert.json: key 'date' is missing: expected an ISO 8601 time with its UTC offset"
    )
    cert = make_certificate()
    del cert["urdf"]["sha256"]
    assert refusal(cert) == "x.cert.json: key 'urdf.sha256' is missing: expected 64 hex digits"


def test_an_unknown_key_lists_the_known_ones():
    cert = make_certificate()
    cert["colour"] = "red"
    assert refusal(cert) == f"x.cert.json: key 'colour' = 'red': unknown key; expected {', '.join(TOP.keys)}"


def test_a_value_of_the_wrong_type_is_refused():
    cert = make_certificate()
    cert["checks"][0]["samples"] = 2.5
    assert refusal(cert) == "x.cert.json: key 'checks[0].samples' = 2.5: expected an integer"


def test_an_engine_that_is_not_a_name_is_refused_not_a_crash():
    cert = make_certificate()
    cert["checks"][0]["engine"] = []  # unhashable: a lookup in the engines' table raised TypeError
    assert refusal(cert) == (
        "x.cert.json: key 'checks[0].engine' = []: expected one of compiled, aba (invariant items)"
    )
