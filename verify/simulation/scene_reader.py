"""Typed access to one table of a scene file, with errors that name the file and the dotted key.

The rules are ``pendverify.documents``'s, the one reader of every document
(``SceneError(source, key, value, rule)``): numbers are ints or floats but not booleans, and
finite; vectors are lists of exactly the expected length; ``positive`` means > 0, ``minimum`` is
inclusive; a sub-table's keys are reported with its prefix (``effects.actuation.amplitude``).  A
scene's tables are read in the order their values depend on each other (the model's size fixes
a vector's length), so each is read key by key here rather than as one ``Table``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pendverify.documents import (
    Key,
    Table,
    check_keys,
    check_value,
    choice_rules,
    is_string,
    number_rules,
    vector_rules,
)
from pendverify.errors import SceneError


class TableReader:
    """Typed access to one table of a scene, with errors that name the key."""

    def __init__(self, table: dict, source: str, prefix: str = ""):
        self.table, self.source, self.prefix = table, source, prefix

    def fail(self, key: str, value: object, rule: str):
        raise SceneError(self.source, self.prefix + key, value, rule)

    def only(self, allowed: tuple[str, ...]) -> None:
        check_keys(self.table, Table(dict.fromkeys(allowed, Key())), self.fail)

    def has(self, key: str) -> bool:
        return key in self.table

    def get(self, key: str, default: Any = ...):
        if key not in self.table:
            if default is ...:
                self.fail(key, None, "missing key")
            return default
        return self.table[key]

    def sub(self, key: str, required: bool = True) -> TableReader | None:
        value = self.get(key, ... if required else None)
        if value is None:
            return None
        if not isinstance(value, dict):
            self.fail(key, value, "expected a table")
        return TableReader(value, self.source, f"{self.prefix}{key}.")

    def string(self, key: str, choices: tuple[str, ...] | None = None, default: Any = ...) -> str:
        rules = choice_rules(choices) if choices else ((is_string, "expected a string"),)
        return check_value(key, self.get(key, default), Key(rules), self.fail)

    def number(self, key: str, default: Any = ..., positive: bool = False, minimum: float | None = None):
        value = check_value(key, self.get(key, default), Key(number_rules(positive, minimum)), self.fail)
        return float(value)

    def vector(self, key: str, length: int, default: Any = ..., minimum: float | None = None) -> np.ndarray:
        value = self.get(key, default)
        if isinstance(value, (int, float)) and not isinstance(value, bool) and length == 1:
            value = [value]
        return np.array(check_value(key, value, Key(vector_rules(length, minimum)), self.fail), dtype=float)

    def boolean_or_number(self, key: str, default: Any = False):
        value = self.get(key, default)
        if isinstance(value, bool):
            return value
        return self.number(key, minimum=0.0)
