"""Typed access to one table of a scene file, with errors that name the file and the dotted key.

Every rule a scene value must meet is checked here (``SceneError(source, key, value,
rule)``): numbers are ints or floats but not booleans, and finite; vectors are lists of
exactly the expected length; ``positive`` means > 0, ``minimum`` is inclusive; a
sub-table's keys are reported with its prefix (``effects.actuation.amplitude``).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from pendverify.errors import SceneError


class TableReader:
    """Typed access to one table of a scene, with errors that name the key."""

    def __init__(self, table: dict, source: str, prefix: str = ""):
        self.table, self.source, self.prefix = table, source, prefix

    def fail(self, key: str, value: object, rule: str):
        raise SceneError(self.source, self.prefix + key, value, rule)

    def only(self, allowed: tuple[str, ...]) -> None:
        for key, value in self.table.items():
            if key not in allowed:
                self.fail(key, value, f"unknown key; expected one of {', '.join(allowed)}")

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
        value = self.get(key, default)
        if not isinstance(value, str):
            self.fail(key, value, "expected a string" + (f": one of {', '.join(choices)}" if choices else ""))
        if choices and value not in choices:
            self.fail(key, value, f"expected one of {', '.join(choices)}")
        return value

    def number(self, key: str, default: Any = ..., positive: bool = False, minimum: float | None = None):
        value = self.get(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, value, "expected a number")
        try:
            x = float(value)
        except OverflowError:  # a TOML integer beyond a double
            x = math.inf
        if not math.isfinite(x):
            self.fail(key, value, "expected a finite number")
        if positive and not x > 0:
            self.fail(key, value, "expected a number > 0")
        if minimum is not None and x < minimum:
            self.fail(key, value, f"expected a number >= {minimum:g}")
        return x

    def vector(self, key: str, length: int, default: Any = ..., minimum: float | None = None) -> np.ndarray:
        value = self.get(key, default)
        if isinstance(value, (int, float)) and not isinstance(value, bool) and length == 1:
            value = [value]
        if not isinstance(value, list) or any(
            isinstance(x, bool) or not isinstance(x, (int, float)) for x in value
        ):
            self.fail(key, value, f"expected a list of {length} numbers")
        if len(value) != length:
            self.fail(key, value, f"expected a list of {length} numbers, got {len(value)}")
        try:
            arr = np.array(value, dtype=float)
        except OverflowError:  # a TOML integer beyond a double
            self.fail(key, value, "expected finite numbers")
        if not np.all(np.isfinite(arr)):
            self.fail(key, value, "expected finite numbers")
        if minimum is not None and np.any(arr < minimum):
            self.fail(key, value, f"expected numbers >= {minimum:g}")
        return arr

    def boolean_or_number(self, key: str, default: Any = False):
        value = self.get(key, default)
        if isinstance(value, bool):
            return value
        return self.number(key, minimum=0.0)
