"""The one reader of pendverify's TOML documents: parsing, and checking a document against a schema.

Every document kind (a parameter file, a scene, a sweep, a text model, the shipped catalogues; a
certificate's JSON once parsed) is read here: ``read_toml`` opens and parses a file, ``parse_toml``
parses shipped text, and ``check_table`` checks one table of a parsed document against a ``Table``
— a schema written as data.  Nothing else in the package imports ``tomllib`` (a test greps for it).
Reading never executes code: TOML is data, and a schema's tests are predicates on parsed values.

A schema:

* ``Key(rules, required, default, missing)``: ``rules`` is a sequence of ``(test, rule)`` pairs,
  checked in order; the first ``test(value)`` that is false makes the error, with ``rule`` (or
  ``rule(value)``) as its rule sentence.  A missing key is an error when ``required`` (its rule
  ``missing``, else the table's); else the key takes ``default`` (a key with neither stays
  absent: no silent default).
* ``Table(keys, unknown, missing)``: ``keys`` maps each allowed key to its ``Key`` (in the order
  errors list them); ``unknown`` is the rule for a key not among them, with ``{keys}`` replaced by
  the allowed keys joined by ", " (or a function of the key: a "did you mean"); ``missing`` the
  rule for a missing required key, with ``{rule}`` replaced by the key's last rule.

A reader whose keys depend on each other (a vector's length on the model, one key's rule on
another's value) checks them one at a time with ``check_value``, in the order it reads them.

Errors are raised by the document kind's ``fail(key, value, rule)`` (``raising``: its
``InputError`` subclass, ``FILE: key 'KEY' = VALUE: RULE``), so every kind keeps its sentence; a
missing key's value is ``MISSING``.  ``number_rules``, ``vector_rules`` and ``choice_rules`` hold
the sentences the readers share.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pendverify.errors import (
    ParameterError,
    PendverifyError,
    folder_given,
    missing_file,
    unreadable_file,
    wrong_kind,
)
from pendverify.file_kinds import KINDS, suffix_kind, toml_kind

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib


class _Missing:
    """The value of a key a document does not hold (``fail`` is given it for a missing key)."""

    def __repr__(self) -> str:
        return "MISSING"


MISSING: Any = _Missing()

#: (test, rule): the value passes ``test``, else the error's rule is ``rule`` (or ``rule(value)``)
Rule = tuple[Callable[[Any], bool], "str | Callable[[Any], str]"]
Fail = Callable[[str, Any, str], Any]


@dataclass(frozen=True)
class Key:
    """One key of a table: its rules in order, whether it must be there, and its default if not."""

    rules: Sequence[Rule] = ()
    required: bool = True
    default: Any = MISSING
    #: the rule when this key is missing (else the table's ``missing``)
    missing: str = ""


@dataclass(frozen=True)
class Table:
    """One table of a document: its keys, and the rules for an unknown and a missing key."""

    keys: Mapping[str, Key]
    #: the rule for an unknown key: a template, or a function of the key (a "did you mean")
    unknown: str | Callable[[str], str] = "unknown key; expected one of {keys}"
    missing: str = "missing key"


def raising(error: type[PendverifyError], source: str) -> Fail:
    """The ``fail`` that raises ``error(source, key, value, rule)`` (a missing key's value: None)."""

    def fail(key: str, value: Any, rule: str):
        raise error(source, key, None if value is MISSING else value, rule)

    return fail


def check_value(key: str, value: Any, spec: Key, fail: Fail) -> Any:
    """``value`` if it passes every rule of ``spec``; else ``fail(key, value, rule)`` of the first
    rule it breaks."""
    for test, rule in spec.rules:
        if not test(value):
            fail(key, value, rule(value) if callable(rule) else rule)
    return value


def check_table(table: Mapping, schema: Table, fail: Fail, prefix: str = "") -> dict[str, Any]:
    """``check_keys`` then ``check_values``: the values of ``table`` checked against ``schema``.

    ``fail(prefix + key, value, rule)`` raises the document's error; ``prefix`` names a nested
    table (``"ranges.m1."``)."""
    check_keys(table, schema, fail, prefix)
    return check_values(table, schema, fail, prefix)


def check_keys(table: Mapping, schema: Table, fail: Fail, prefix: str = "") -> None:
    """Fail on the first key of ``table`` that ``schema`` does not have."""
    for key, value in table.items():
        if key not in schema.keys:
            if callable(schema.unknown):
                fail(prefix + key, value, schema.unknown(key))
            fail(prefix + key, value, schema.unknown.format(keys=", ".join(schema.keys)))


def check_values(table: Mapping, schema: Table, fail: Fail, prefix: str = "") -> dict[str, Any]:
    """The values of ``schema``'s keys in ``table``, each checked by its rules in the schema's order
    (a missing required key fails), with each absent optional key that has a default set to it.

    A reader whose keys need more than rules (a file they name, one key's rule depending on
    another's value) checks those after, from the values returned."""
    values = {}
    for key, spec in schema.keys.items():
        if key in table:
            values[key] = check_value(prefix + key, table[key], spec, fail)
        elif spec.required:
            last = spec.rules[-1][1] if spec.rules else ""
            fail(
                prefix + key,
                MISSING,
                spec.missing or schema.missing.format(rule="" if callable(last) else last),
            )
        elif spec.default is not MISSING:
            values[key] = spec.default
    return values


# --- rules the readers share ------------------------------------------------------------------


def is_number(v: Any) -> bool:
    """An int or a float, not a boolean."""
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def as_float(v: Any) -> float:
    """A number as a float; a TOML integer beyond a double is infinite."""
    try:
        return float(v)
    except OverflowError:
        return math.inf


def is_finite(v: Any) -> bool:
    """A number that is finite as a float."""
    return is_number(v) and math.isfinite(as_float(v))


def is_integer(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def is_string(v: Any) -> bool:
    return isinstance(v, str)


def is_table(v: Any) -> bool:
    return isinstance(v, dict)


def number_rules(positive: bool = False, minimum: float | None = None) -> tuple[Rule, ...]:
    """A finite number (not a boolean); ``positive``: > 0; ``minimum``: at least it."""
    rules: list[Rule] = [(is_number, "expected a number"), (is_finite, "expected a finite number")]
    if positive:
        rules.append((lambda v: as_float(v) > 0, "expected a number > 0"))
    if minimum is not None:
        rules.append((lambda v: as_float(v) >= minimum, f"expected a number >= {minimum:g}"))
    return tuple(rules)


def vector_rules(length: int, minimum: float | None = None) -> tuple[Rule, ...]:
    """A list of exactly ``length`` finite numbers (not booleans); ``minimum``: each at least it.
    (The second rule names the length found.)"""
    rules: list[Rule] = [
        (lambda v: isinstance(v, list) and all(map(is_number, v)), f"expected a list of {length} numbers"),
        (lambda v: len(v) == length, lambda v: f"expected a list of {length} numbers, got {len(v)}"),
        (lambda v: all(map(is_finite, v)), "expected finite numbers"),
    ]
    if minimum is not None:
        rules.append((lambda v: all(as_float(x) >= minimum for x in v), f"expected numbers >= {minimum:g}"))
    return tuple(rules)


def choice_rules(choices: Sequence[str]) -> tuple[Rule, ...]:
    """A string, one of ``choices``."""
    listed = ", ".join(choices)
    return (is_string, f"expected a string: one of {listed}"), (
        lambda v: v in choices,
        f"expected one of {listed}",
    )


# --- parsing ----------------------------------------------------------------------------------


def parse_toml(text: str, source: str) -> dict[str, Any]:
    """A TOML text's document; a syntax error is a ``ParameterError`` naming ``source``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(source, "<file>", source, f"not valid TOML: {exc}") from None
    except RecursionError:
        raise ParameterError(source, "<file>", source, "not valid TOML: nested too deeply") from None


def read_toml(path: Path, what: str = "TOML file") -> dict[str, Any]:
    """Parse a TOML file (a ``what``: "parameter file", "scene file", ... in messages).

    A missing, unreadable or folder path is a ``UserFileError`` naming the file and the next
    step, as is a file whose name says it is another kind (``model.py``, ``robot.urdf``); a
    syntax error, a ParameterError that names the file."""
    if not path.name.lower().endswith(".toml"):
        kind = suffix_kind(path)
        if kind is not None:
            raise wrong_kind(path, what, KINDS[kind].noun, KINDS[kind].given_as)
    try:
        with open(path, "rb") as fh:
            raw = fh.read()
    except FileNotFoundError:
        raise missing_file(path, what) from None
    except IsADirectoryError:
        raise folder_given(path, what) from None
    except OSError as exc:
        raise unreadable_file(path, what, exc.strerror or str(exc)) from None
    try:
        text = raw.decode("utf-8-sig")  # a byte-order mark is allowed, as in URDFs
    except UnicodeDecodeError as exc:
        raise ParameterError(
            str(path), "<file>", str(path), f"not UTF-8 text (byte {exc.start}: {exc.reason}); TOML is UTF-8"
        ) from None
    return parse_toml(text, str(path))


def file_kind(path: str | Path) -> str | None:
    """The kind of the file at ``path`` (its suffix; a TOML file's keys: ``file_kinds``), or None
    when unknown or unreadable: a guess for a hint, never an error of its own."""
    kind = suffix_kind(path)
    if kind is not None or not str(path).lower().endswith(".toml"):
        return kind
    try:
        with open(path, "rb") as handle:
            return toml_kind(parse_toml(handle.read().decode("utf-8-sig"), str(path)))
    except (OSError, UnicodeDecodeError, PendverifyError):
        return None
