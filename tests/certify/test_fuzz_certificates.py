"""Fuzzed certificates: ``recheck`` answers 0, 1 or 2 with one line, never 3, never a traceback, runs nothing.

A valid certificate (``tests.certify.forged_bundles``: tiny settings, so a battery that does
run takes a fraction of a second) has one of its fields replaced — any key at any
depth, by a value of another type, an out-of-range or non-finite number, a
path-like or control-character string, a deep nesting — and is written with or
without its summary and digest recomputed (a forger recomputes them).  One variant
embeds a Python model that writes a marker file when imported: whatever is
mutated, it is never run (no ``--trust``, no ``--run-embedded-code``).
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pendverify.cli import main

from .forged_bundles import embed_model, make_certificate, redigest

SCALARS = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0, -1, -5, 10**7, 2**64, 10**400]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(["nan", "inf", "-inf", "", "..", "../outside.txt", "/etc/passwd", "a\0b.py", "x" * 300]),
    st.text(max_size=20),
)
VALUES = st.recursive(
    SCALARS,
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=8), inner, max_size=3),
    max_leaves=6,
) | st.integers(min_value=2, max_value=500).map(lambda n: _nested(n))


def _nested(depth: int) -> list:
    value: list = []
    for _ in range(depth - 1):
        value = [value]
    return value


def _paths(value, prefix=()):
    """Every (key, ..., key) path into a JSON value, the value itself included."""
    yield prefix
    if isinstance(value, dict):
        for key, child in value.items():
            yield from _paths(child, (*prefix, key))
    elif isinstance(value, list):
        for i, child in enumerate(value):
            yield from _paths(child, (*prefix, i))


def _replace(document, path, value):
    if not path:
        return value
    target = document
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return document


def _recheck(path) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        status = main(["recheck", str(path), "--quiet"])
    return status, err.getvalue()


@pytest.mark.slow
@settings(
    max_examples=150,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data(), embedded=st.booleans(), recompute=st.booleans())
def test_a_mutated_certificate_is_answered_in_one_line(tmp_path, monkeypatch, data, embedded, recompute):
    monkeypatch.setenv("PENDVERIFY_MAX_SAMPLES", "1000")  # a mutated sample count re-runs in a moment
    marker = tmp_path / "ran.txt"
    cert = make_certificate()
    if embedded:
        embed_model(cert, f"from pathlib import Path\nPath({str(marker)!r}).write_text('ran')\n")
    paths = [p for p in _paths(cert) if p[:1] != ("digest",) or not recompute]
    where = data.draw(st.sampled_from(paths), label="path")
    value = data.draw(VALUES, label="value")
    mutated = _replace(copy.deepcopy(cert), where, value)
    if recompute and isinstance(mutated, dict) and isinstance(mutated.get("checks"), list):
        with contextlib.suppress(Exception):  # a forger's tools may fail on what it broke
            redigest(mutated)
    path = tmp_path / "double_pendulum.cert.json"
    path.write_text(json.dumps(mutated, allow_nan=True), encoding="utf-8")
    status, err = _recheck(path)
    assert status in (0, 1, 2), (where, value, err)
    assert "Traceback" not in err and "internal error" not in err, (where, value, err)
    assert len(err.strip().splitlines()) <= 1, err
    assert not marker.exists(), (where, value)
    marker.unlink(missing_ok=True)


@settings(max_examples=3, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(number=st.sampled_from([math.nan, math.inf, -math.inf]))
def test_a_non_finite_figure_never_reproduces(tmp_path, number):
    cert = make_certificate()
    for key in ("error", "tolerance", "max_error"):
        forged = copy.deepcopy(cert)
        forged["checks"][0][key] = "nan" if math.isnan(number) else ("inf" if number > 0 else "-inf")
        path = tmp_path / "double_pendulum.cert.json"
        path.write_text(json.dumps(redigest(forged)), encoding="utf-8")
        status, err = _recheck(path)
        assert status == 2 and f"checks[0].{key}" in err, err
